"""Cell-list broad phase building a Verlet half list (CSR), periodic axes supported.

A pair (i, j), i < j, is listed when the centre distance (minimum image) is below
``r_i + r_j + skin``. The list is rebuilt when any particle has moved more than half
the skin (or grown, for thermal expansion). Contact history (shear spring) lives per
listed pair and is carried over to the new list on rebuild.

Layout: ``start[i]:start[i+1]`` are the pairs owned by i (``pair_i``, ``pair_j``);
the reverse index ``rev_start``/``rev_pair`` lists, for each particle, the pairs in
which it is the second member, so forces are gathered per particle without races.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit, prange

from tribodem.dem.jit import kernel, serial_run
from tribodem.dem.space import min_image


@dataclass
class NeighborList:
    """Verlet half list with reverse index and the reference state of the last build."""

    start: np.ndarray
    pair_i: np.ndarray
    pair_j: np.ndarray
    rev_start: np.ndarray
    rev_pair: np.ndarray
    ref_pos: np.ndarray
    ref_radius: np.ndarray
    skin: float
    builds: int = 0

    @property
    def n_pairs(self) -> int:
        """Number of listed (candidate) pairs."""
        return int(self.pair_i.size)


@njit(cache=True)
def _grid(pos, radius, lo_box, hi_box, periodic, cell_min):
    n = pos.shape[0]
    lo = np.empty(3)
    ncell = np.ones(3, dtype=np.int64)
    csize = np.ones(3)
    for k in range(3):
        if periodic[k]:
            lo[k] = lo_box[k]
            length = hi_box[k] - lo_box[k]
        else:
            mn = np.inf
            mx = -np.inf
            for i in range(n):
                if pos[i, k] < mn:
                    mn = pos[i, k]
                if pos[i, k] > mx:
                    mx = pos[i, k]
            lo[k] = mn
            length = mx - mn
        nc = int(np.floor(length / cell_min)) if length > 0 else 1
        if nc < 1:
            nc = 1
        if nc > 1024:
            nc = 1024
        ncell[k] = nc
        csize[k] = length / nc if length > 0 else 1.0
    return lo, csize, ncell


@njit(cache=True)
def _bin(pos, lo, csize, ncell, periodic):
    """Cell of every particle and the particles of each cell (counting sort)."""
    n = pos.shape[0]
    cell = np.empty(n, dtype=np.int64)
    for i in range(n):
        c = 0
        mult = 1
        for k in range(3):
            ck = int(np.floor((pos[i, k] - lo[k]) / csize[k]))
            if periodic[k]:
                ck = ck % ncell[k]
            if ck < 0:
                ck = 0
            if ck >= ncell[k]:
                ck = ncell[k] - 1
            c += ck * mult
            mult *= ncell[k]
        cell[i] = c
    cstart, order = _bucket(cell, ncell[0] * ncell[1] * ncell[2])
    return cell, cstart, order


@njit(cache=True, inline="always")
def _axis_neighbor(c, o, n, periodic):
    """Neighbour cell index along one axis for offset o, or -1 (skip)."""
    if periodic:
        if n == 1 and o != 0:
            return -1
        if n == 2 and o == -1:
            return -1
        return (c + o) % n
    c2 = c + o
    if c2 < 0 or c2 >= n:
        return -1
    return c2


@kernel
def _scan(pos, radius, skin, length, periodic, cell, cstart, order, ncell, start, pj, fill):
    """Count (fill=False) or write (fill=True) the pairs j > i of each particle i."""
    n = pos.shape[0]
    for i in prange(n):
        c = cell[i]
        cx = c % ncell[0]
        cy = (c // ncell[0]) % ncell[1]
        cz = c // (ncell[0] * ncell[1])
        cnt = 0
        w = start[i] if fill else 0
        for oz in range(-1, 2):
            z2 = _axis_neighbor(cz, oz, ncell[2], periodic[2])
            if z2 < 0:
                continue
            for oy in range(-1, 2):
                y2 = _axis_neighbor(cy, oy, ncell[1], periodic[1])
                if y2 < 0:
                    continue
                for ox in range(-1, 2):
                    x2 = _axis_neighbor(cx, ox, ncell[0], periodic[0])
                    if x2 < 0:
                        continue
                    c2 = x2 + ncell[0] * (y2 + ncell[1] * z2)
                    for q in range(cstart[c2], cstart[c2 + 1]):
                        j = order[q]
                        if j <= i:
                            continue
                        dx = min_image(pos[j, 0] - pos[i, 0], length[0], periodic[0])
                        dy = min_image(pos[j, 1] - pos[i, 1], length[1], periodic[1])
                        dz = min_image(pos[j, 2] - pos[i, 2], length[2], periodic[2])
                        cut = radius[i] + radius[j] + skin
                        if dx * dx + dy * dy + dz * dz < cut * cut:
                            if fill:
                                pj[w] = j
                                w += 1
                            else:
                                cnt += 1
        if not fill:
            start[i + 1] = cnt


@njit(cache=True, inline="always")
def _insertion_sort(pj, a, b):
    """Sort ``pj[a:b]`` in place (rows hold a few entries: no allocation, no recursion)."""
    for q in range(a + 1, b):
        v = pj[q]
        r = q - 1
        while r >= a and pj[r] > v:
            pj[r + 1] = pj[r]
            r -= 1
        pj[r + 1] = v


@kernel
def _sort_rows(start, pj):
    """Sort each row by j so the list does not depend on the cell traversal order."""
    n = start.shape[0] - 1
    for i in prange(n):
        _insertion_sort(pj, start[i], start[i + 1])


@njit(cache=True)
def _scan_serial(pos, radius, skin, length, periodic, cell, cstart, order, ncell):
    """One serial pass of ``_scan``: the rows (CSR ``start``, ``pj``) found, written and
    sorted by j as they come (the threaded build counts first, then fills)."""
    n = pos.shape[0]
    start = np.zeros(n + 1, dtype=np.int64)
    cap = 8 * n + 16
    pj = np.empty(cap, dtype=np.int64)
    w = 0
    for i in range(n):
        c = cell[i]
        cx = c % ncell[0]
        cy = (c // ncell[0]) % ncell[1]
        cz = c // (ncell[0] * ncell[1])
        a = w
        for oz in range(-1, 2):
            z2 = _axis_neighbor(cz, oz, ncell[2], periodic[2])
            if z2 < 0:
                continue
            for oy in range(-1, 2):
                y2 = _axis_neighbor(cy, oy, ncell[1], periodic[1])
                if y2 < 0:
                    continue
                for ox in range(-1, 2):
                    x2 = _axis_neighbor(cx, ox, ncell[0], periodic[0])
                    if x2 < 0:
                        continue
                    c2 = x2 + ncell[0] * (y2 + ncell[1] * z2)
                    for q in range(cstart[c2], cstart[c2 + 1]):
                        j = order[q]
                        if j <= i:
                            continue
                        dx = min_image(pos[j, 0] - pos[i, 0], length[0], periodic[0])
                        dy = min_image(pos[j, 1] - pos[i, 1], length[1], periodic[1])
                        dz = min_image(pos[j, 2] - pos[i, 2], length[2], periodic[2])
                        cut = radius[i] + radius[j] + skin
                        if dx * dx + dy * dy + dz * dz < cut * cut:
                            if w == cap:
                                cap *= 2
                                grown = np.empty(cap, dtype=np.int64)
                                grown[:w] = pj[:w]
                                pj = grown
                            pj[w] = j
                            w += 1
        _insertion_sort(pj, a, w)
        start[i + 1] = w
    return start, pj[:w].copy()


@njit(cache=True)
def _bucket(keys, nkeys):
    """Counting sort: ``start[k]:start[k+1]`` are the positions in ``order`` of the items
    whose key is k, in increasing item order (stable, no comparisons)."""
    m = keys.shape[0]
    start = np.zeros(nkeys + 1, dtype=np.int64)
    for p in range(m):
        start[keys[p] + 1] += 1
    for k in range(nkeys):
        start[k + 1] += start[k]
    fill = start[:-1].copy()
    order = np.empty(m, dtype=np.int64)
    for p in range(m):
        order[fill[keys[p]]] = p
        fill[keys[p]] += 1
    return start, order


@njit(cache=True)
def reverse_index(n, pj):
    """Reverse index of a half list: for each particle, the pairs in which it is second."""
    return _bucket(pj, n)


@njit(cache=True)
def _owner(start, m):
    n = start.shape[0] - 1
    pi = np.empty(m, dtype=np.int64)
    for i in range(n):
        for p in range(start[i], start[i + 1]):
            pi[p] = i
    return pi


def build(pos: np.ndarray, radius: np.ndarray, skin: float, box_lo: np.ndarray,
          box_hi: np.ndarray, periodic: np.ndarray, builds: int = 0) -> NeighborList:
    """Build the Verlet half list of all pairs closer than ``r_i + r_j + skin``."""
    n = pos.shape[0]
    cell_min = 2.0 * float(radius.max()) + skin if n else 1.0
    length = box_hi - box_lo
    lo, csize, ncell = _grid(pos, radius, box_lo, box_hi, periodic, cell_min)
    cell, cstart, order = _bin(pos, lo, csize, ncell, periodic)
    if serial_run(n):
        start, pj = _scan_serial(pos, radius, skin, length, periodic, cell, cstart, order,
                                 ncell)
    else:
        start = np.zeros(n + 1, dtype=np.int64)
        dummy = np.empty(0, dtype=np.int64)
        scan = _scan.pick(n)
        scan(pos, radius, skin, length, periodic, cell, cstart, order, ncell, start, dummy,
             False)
        np.cumsum(start, out=start)
        pj = np.empty(int(start[-1]), dtype=np.int64)
        scan(pos, radius, skin, length, periodic, cell, cstart, order, ncell, start, pj, True)
        _sort_rows.pick(n)(start, pj)
    pi = _owner(start, pj.size)
    rs, rp = reverse_index(n, pj)
    return NeighborList(start, pi, pj, rs, rp, pos.copy(), radius.copy(), float(skin),
                        builds + 1)


@kernel
def transfer_history(old_start, old_j, old_hist, new_start, new_j, new_hist):
    """Copy per-pair history rows from the old list to the new one (same pairs)."""
    n = new_start.shape[0] - 1
    for i in prange(n):
        a0, b0 = old_start[i], old_start[i + 1]
        for p in range(new_start[i], new_start[i + 1]):
            j = new_j[p]
            # rows are sorted by j: binary search
            lo, hi = a0, b0
            while lo < hi:
                mid = (lo + hi) // 2
                if old_j[mid] < j:
                    lo = mid + 1
                else:
                    hi = mid
            if lo < b0 and old_j[lo] == j:
                for k in range(new_hist.shape[1]):
                    new_hist[p, k] = old_hist[lo, k]
