"""A volume-conserving slope limit on the worn depth of a node-column surface.

A threshold criterion (von Mises, S22, shear) wears pits whose walls step by several
micrometres between neighbouring node columns; on the seed's shear run at h = a/3 the
surfaces stepped by up to 10.6 um between columns 44 um apart (slope 0.24) after two
cycles, and ccx's node-to-surface contact no longer converged on them (docs/fe3d.md
"Worn geometry"). The seed itself, for its FDEM comparison, replaced the worn and
irregular surface "with a smoothed profile of the same wear depth" (Lu (2018) section 5).

:func:`limit_slope` relaxes the nodal worn depths until no step between neighbouring
columns (along x or along y) is steeper than ``slope``: every edge whose step exceeds
``slope`` x its length moves volume from the deeper to the shallower node, just enough to
bring the step to the limit, with the tributary areas as weights, so the worn volume
sum(w A) is unchanged (to rounding). The edges are updated together (Jacobi, a quarter of
each excess per sweep: a node has at most four edges, so no step overshoots), so a depth
field symmetric about a grid line stays symmetric. Depths stay >= 0 (a node only gives up
depth towards a shallower neighbour, never below it). The surface the mesh then carries
is not the criterion's: the run states the limit, the steepest step it relaxed and the
volume it moved.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit
from numpy.typing import NDArray

#: relative overshoot of the limit left when the relaxation stops (0.1 %)
TOLERANCE = 1e-3
#: sweeps after which the relaxation gives up (its result is then still volume-exact)
MAX_SWEEPS = 200_000


@dataclass(frozen=True)
class SlopeLimit:
    """What :func:`limit_slope` did: ``steepest_before`` / ``steepest_after`` (the largest
    |step| / edge length over the x and y edges), ``moved_volume`` (m^3 on the grid's
    areas: half the L1 change of w x A, the volume carried from pits to their
    surroundings), ``sweeps``, ``converged``."""

    steepest_before: float
    steepest_after: float
    moved_volume: float
    sweeps: int
    converged: bool


@njit(cache=True)
def _steepest(w, xs, ys):  # pragma: no cover - numba
    ny, nx = w.shape
    s = 0.0
    for j in range(ny):
        for i in range(nx):
            if i + 1 < nx:
                s = max(s, abs(w[j, i + 1] - w[j, i]) / (xs[i + 1] - xs[i]))
            if j + 1 < ny:
                s = max(s, abs(w[j + 1, i] - w[j, i]) / (ys[j + 1] - ys[j]))
    return s


@njit(cache=True)
def _relax(w, xs, ys, area, slope, tol, max_sweeps):  # pragma: no cover - numba
    """Jacobi sweeps of the edge transfers on ``w`` in place; the sweeps done, or -1."""
    ny, nx = w.shape
    dw = np.zeros_like(w)
    for sweep in range(max_sweeps):
        worst = 0.0
        dw[:, :] = 0.0
        for j in range(ny):
            for i in range(nx):
                for e in range(2):
                    if e == 0:
                        if i + 1 >= nx:
                            continue
                        jj, ii, d = j, i + 1, xs[i + 1] - xs[i]
                    else:
                        if j + 1 >= ny:
                            continue
                        jj, ii, d = j + 1, i, ys[j + 1] - ys[j]
                    diff = w[j, i] - w[jj, ii]
                    excess = abs(diff) - slope * d
                    if excess <= 0.0:
                        continue
                    worst = max(worst, excess / d)
                    # volume dv from the deeper to the shallower node closes the excess
                    dv = 0.25 * excess / (1.0 / area[j, i] + 1.0 / area[jj, ii])
                    if diff > 0.0:
                        dw[j, i] -= dv / area[j, i]
                        dw[jj, ii] += dv / area[jj, ii]
                    else:
                        dw[j, i] += dv / area[j, i]
                        dw[jj, ii] -= dv / area[jj, ii]
        if worst <= tol * slope:
            return sweep
        for j in range(ny):
            for i in range(nx):
                w[j, i] += dw[j, i]
    return -1


def steepest(depth: NDArray[np.float64], xs: NDArray[np.float64], ys: NDArray[np.float64]
             ) -> float:
    """The largest |step| of ``depth`` ([ny, nx], m) between neighbouring columns of the grid
    ``xs`` x ``ys`` (m) along x or y, divided by their spacing (dimensionless)."""
    return float(_steepest(np.ascontiguousarray(depth, dtype=float),
                           np.ascontiguousarray(xs, dtype=float),
                           np.ascontiguousarray(ys, dtype=float)))


def _surface_arrays(depth: NDArray[np.float64], xs: NDArray[np.float64],
                    ys: NDArray[np.float64], area: NDArray[np.float64]
                    ) -> tuple[NDArray[np.float64], ...]:
    """``depth`` [ny, nx], ``xs`` [nx], ``ys`` [ny] and ``area`` [ny, nx] as contiguous
    float arrays (``ValueError`` if the shapes do not fit)."""
    w0, xs, ys, area = (np.ascontiguousarray(a, dtype=float) for a in (depth, xs, ys, area))
    if w0.shape != (ys.size, xs.size) or area.shape != w0.shape:
        raise ValueError(f"depth {w0.shape} and area {area.shape} must be (ny, nx) = "
                         f"({ys.size}, {xs.size})")
    return w0, xs, ys, area


def limit_slope(depth: NDArray[np.float64], xs: NDArray[np.float64], ys: NDArray[np.float64],
                area: NDArray[np.float64], slope: float) -> tuple[NDArray[np.float64], SlopeLimit]:
    """``depth`` (m, [ny, nx], >= 0: the worn depth of each column of the grid ``xs`` x
    ``ys``, m, increasing) relaxed so that no step between neighbouring columns exceeds
    ``slope`` (dimensionless, > 0) x the edge length, within :data:`TOLERANCE`; ``area``
    (m^2, [ny, nx]) the columns' tributary areas, whose weighted sum of the depths (the worn
    volume) is kept. Returns the relaxed copy and a :class:`SlopeLimit`."""
    w0, xs, ys, area = _surface_arrays(depth, xs, ys, area)
    if not (np.isfinite(slope) and slope > 0.0):
        raise ValueError(f"slope = {slope!r} is not allowed: a number > 0")
    if np.any(np.diff(xs) <= 0) or np.any(np.diff(ys) <= 0) or np.any(area <= 0):
        raise ValueError("xs and ys must increase and the areas be > 0")
    before = steepest(w0, xs, ys)
    w = w0.copy()
    sweeps = int(_relax(w, xs, ys, area, float(slope), TOLERANCE, MAX_SWEEPS))
    moved = 0.5 * float(np.abs((w - w0) * area).sum())
    return w, SlopeLimit(steepest_before=before, steepest_after=steepest(w, xs, ys),
                         moved_volume=moved, sweeps=sweeps if sweeps >= 0 else MAX_SWEEPS,
                         converged=sweeps >= 0)


@dataclass(frozen=True)
class KinkLimit:
    """What :func:`limit_kink` did: ``kink_before`` / ``kink_after`` (the largest change of
    slope at a node between its two edges along x or y, dimensionless), ``steepest_after``
    (the largest |step| / edge length after it), ``moved_volume`` (m^3 on the grid's areas:
    half the L1 change of w x A), ``sweeps``, ``converged``."""

    kink_before: float
    kink_after: float
    steepest_after: float
    moved_volume: float
    sweeps: int
    converged: bool


@njit(cache=True)
def _kinks(w, xs, ys, mirror_y0):  # pragma: no cover - numba
    """The largest |change of slope| at a node along x and y (with ``mirror_y0`` the row
    j = 0 is a symmetry line: its slope towards the mirror image is minus the one to j = 1)."""
    ny, nx = w.shape
    k = 0.0
    for j in range(ny):
        for i in range(nx):
            if 0 < i < nx - 1:
                sl = (w[j, i] - w[j, i - 1]) / (xs[i] - xs[i - 1])
                sr = (w[j, i + 1] - w[j, i]) / (xs[i + 1] - xs[i])
                k = max(k, abs(sr - sl))
            if 0 < j < ny - 1:
                sl = (w[j, i] - w[j - 1, i]) / (ys[j] - ys[j - 1])
                sr = (w[j + 1, i] - w[j, i]) / (ys[j + 1] - ys[j])
                k = max(k, abs(sr - sl))
            elif j == 0 and mirror_y0 and ny > 1:
                k = max(k, 2.0 * abs(w[1, i] - w[0, i]) / (ys[1] - ys[0]))
    return k


@njit(cache=True)
def _smooth(w, xs, ys, area, kink, slope, tol, max_sweeps, mirror_y0):  # pragma: no cover
    """Jacobi sweeps of a conservative diffusion on the edges next to a node whose kink
    exceeds ``kink`` or steeper than ``slope`` (``w`` in place); the sweeps done, or -1."""
    ny, nx = w.shape
    dw = np.zeros_like(w)
    ax = np.zeros((ny, nx), dtype=np.bool_)  # edge (j, i)-(j, i + 1) active
    ay = np.zeros((ny, nx), dtype=np.bool_)  # edge (j, i)-(j + 1, i) active
    for sweep in range(max_sweeps):
        ax[:, :] = False
        ay[:, :] = False
        found = False
        for j in range(ny):
            for i in range(nx):
                if 0 < i < nx - 1:
                    sl = (w[j, i] - w[j, i - 1]) / (xs[i] - xs[i - 1])
                    sr = (w[j, i + 1] - w[j, i]) / (xs[i + 1] - xs[i])
                    if abs(sr - sl) > kink * (1.0 + tol):
                        ax[j, i - 1] = True
                        ax[j, i] = True
                        found = True
                if i + 1 < nx and abs(w[j, i + 1] - w[j, i]) > (
                        slope * (1.0 + tol) * (xs[i + 1] - xs[i])):
                    ax[j, i] = True
                    found = True
                if 0 < j < ny - 1:
                    sl = (w[j, i] - w[j - 1, i]) / (ys[j] - ys[j - 1])
                    sr = (w[j + 1, i] - w[j, i]) / (ys[j + 1] - ys[j])
                    if abs(sr - sl) > kink * (1.0 + tol):
                        ay[j - 1, i] = True
                        ay[j, i] = True
                        found = True
                elif j == 0 and mirror_y0 and ny > 1:
                    if 2.0 * abs(w[1, i] - w[0, i]) / (ys[1] - ys[0]) > kink * (1.0 + tol):
                        ay[0, i] = True
                        found = True
                if j + 1 < ny and abs(w[j + 1, i] - w[j, i]) > (
                        slope * (1.0 + tol) * (ys[j + 1] - ys[j])):
                    ay[j, i] = True
                    found = True
        if not found:
            return sweep
        dw[:, :] = 0.0
        for j in range(ny):
            for i in range(nx):
                for e in range(2):
                    if e == 0:
                        if i + 1 >= nx or not ax[j, i]:
                            continue
                        jj, ii = j, i + 1
                    else:
                        if j + 1 >= ny or not ay[j, i]:
                            continue
                        jj, ii = j + 1, i
                    # a quarter of the volume that would level the edge, from the deeper
                    # node to the shallower: four edges a node at most, so every new depth
                    # is a convex combination of the old ones (>= 0, no overshoot)
                    dv = 0.25 * (w[j, i] - w[jj, ii]) / (1.0 / area[j, i] + 1.0 / area[jj, ii])
                    dw[j, i] -= dv / area[j, i]
                    dw[jj, ii] += dv / area[jj, ii]
        for j in range(ny):
            for i in range(nx):
                w[j, i] += dw[j, i]
    return -1


def kinks(depth: NDArray[np.float64], xs: NDArray[np.float64], ys: NDArray[np.float64],
          mirror_y0: bool = False) -> float:
    """The largest change of slope of ``depth`` ([ny, nx], m) at a node of the grid ``xs``
    x ``ys`` (m) between its two edges along x or along y, |s_right - s_left| with s the
    step / spacing (dimensionless: the angle by which the facets of a column surface turn
    there, for small slopes); ``mirror_y0``: row 0 lies on a symmetry plane (its edge to
    the mirror image has minus the slope of its edge to row 1)."""
    return float(_kinks(np.ascontiguousarray(depth, dtype=float),
                        np.ascontiguousarray(xs, dtype=float),
                        np.ascontiguousarray(ys, dtype=float), bool(mirror_y0)))


def limit_kink(depth: NDArray[np.float64], xs: NDArray[np.float64], ys: NDArray[np.float64],
               area: NDArray[np.float64], kink: float, slope: float = np.inf,
               mirror_y0: bool = False) -> tuple[NDArray[np.float64], KinkLimit]:
    """``depth`` (m, [ny, nx], >= 0, on the grid ``xs`` x ``ys``, m) smoothed, volume for
    volume, until no node's change of slope (:func:`kinks`) exceeds ``kink`` and no step
    exceeds ``slope`` x its spacing (dimensionless, > 0), within :data:`TOLERANCE`.

    A conservative diffusion on the offending edges only: in each Jacobi sweep every edge
    next to a node kinked beyond ``kink`` (or itself steeper than ``slope``) carries a
    quarter of the volume that would level it, dv = (w_i - w_j) / (4 (1 / A_i + 1 / A_j)),
    from the deeper node to the shallower (``area`` the tributary areas A, m^2), so
    sum(w A), the worn volume, is unchanged to rounding, every new depth is a convex
    combination of old ones (>= 0, never deeper than the deepest), and a surface within
    both limits is returned bit for bit. The sweeps stop when nothing exceeds the limits
    (``converged``) or after :data:`MAX_SWEEPS` (still volume-exact)."""
    w0, xs, ys, area = _surface_arrays(depth, xs, ys, area)
    for name, v in (("kink", kink), ("slope", slope)):
        if not (v > 0.0) or np.isnan(v):
            raise ValueError(f"{name} = {v!r} is not allowed: a number > 0")
    if np.any(np.diff(xs) <= 0) or np.any(np.diff(ys) <= 0) or np.any(area <= 0):
        raise ValueError("xs and ys must increase and the areas be > 0")
    before = kinks(w0, xs, ys, mirror_y0)
    w = w0.copy()
    sweeps = int(_smooth(w, xs, ys, area, float(kink), float(slope), TOLERANCE, MAX_SWEEPS,
                         bool(mirror_y0)))
    moved = 0.5 * float(np.abs((w - w0) * area).sum())
    return w, KinkLimit(kink_before=before, kink_after=kinks(w, xs, ys, mirror_y0),
                        steepest_after=steepest(w, xs, ys), moved_volume=moved,
                        sweeps=sweeps if sweeps >= 0 else MAX_SWEEPS, converged=sweeps >= 0)
