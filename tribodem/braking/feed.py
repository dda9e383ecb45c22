"""Feed of fresh body behind the worn one: slides longer than the bodies are thick.

With debris leaving the cell (``outlet``) the wear does not saturate and the bodies are
consumed at the wear rate (~18 um of pad and 1-8 um of disc per mm slid at condition 5,
docs/braking.md "Bodies worn through"). A steady-state test to +-15 % needs slides of
~50-150 mm (the rate of a 4-mm window scatters 12 % within one run), i.e. 1-3 mm of pad.
A real pad is that thick: the cell models only its surface zone. The feed keeps that
zone's thickness: whenever a body's remaining thickness (``measure``) has fallen by one
slab (``FEED_SLAB_DIAMETERS`` mean particle diameters) below its value at the start of
sliding, a slab of fresh body is added behind the body's anchored layer, which moves to
the slab's outer face -- as the pad's back plate and the disc's hub stay behind a
surface zone that the wear moves through the material.

No seam: the bodies are cut from a block compacted periodic in x *and* y
(``build_interface(block="periodic")``), so the pad's top face and the disc's bottom
face are one plane of that block. Slab k of the pad is the band ``[H + k s, H + (k + 1)
s)`` of the block's periodic continuation above the pad (H the block's height, s the
slab thickness), slab k of the disc the band ``[-(k + 1) s, -k s)`` below it: each slab
continues its body exactly as a taller block would have (the same packing across the
seam, the same bonds: every same-body pair within the bond gap, found in the block's
coordinates). A slab is placed by the mean displacement of the body's anchored layer
from its place in the block (the disc's layer moves rigidly; the pad's by the plate and
a strain ~1e-5), takes the anchored layer's mean velocity, and its bonds start at zero
force on the geometry they are made on. The former anchored particles become ordinary
body particles; the pressure plate (pad) moves out by the new face's offset, so it
meets the new face as it met the old; the outlet's store (below the disc) moves down
with the disc's face. Particles are appended (``Simulation.append_particles``); the run
records the order of the feeds so that a resume replays them before loading its
checkpoint.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from tribodem.braking.measure import Reference
from tribodem.braking.model import DISC, EJECTED, PAD, Interface, pairs_periodic
from tribodem.braking.outlet import Outlet
from tribodem.dem import ParallelBonds
from tribodem.dem.state import FIX_X, FIX_Y

#: slab thickness of one feed, in mean particle diameters of the cell
FEED_SLAB_DIAMETERS = 3.0
BODIES = {"disc": DISC, "pad": PAD}


class Feed:
    """The feed's state: slab thickness (m), slabs fed per body, the order of the feeds,
    each body's remaining thickness at the start (m) and its anchored layer's offset
    from the block at the reference (m)."""

    def __init__(self, iface: Interface, ref: Reference) -> None:
        if iface.block is None or iface.block_pos is None:
            raise ValueError("feed: the interface must be cut from a periodic block "
                             "(build_interface(block='periodic'))")
        self.slab = FEED_SLAB_DIAMETERS * iface.anchor_depth
        self.fed = {"disc": 0, "pad": 0}
        self.events: list[str] = []
        self.start: dict[str, float] = {}
        self.ref_offset = {name: _offset(iface, name) for name in BODIES}
        self.ref = ref

    def begin(self, row: dict[str, float]) -> None:
        """Take each body's remaining thickness (m) from the run's first row."""
        self.start = {k: row[f"remaining_thickness_{k}_m"] for k in BODIES}

    def due(self, row: dict[str, float]) -> dict[str, int]:
        """Slabs to add per body after a measurement row: as many as whole slabs its
        remaining thickness (``measure``) has fallen below its value at the start."""
        out = {}
        for k in BODIES:
            lost = self.start[k] - row[f"remaining_thickness_{k}_m"]
            if lost >= self.slab:
                out[k] = int(lost // self.slab)
        return out

    def apply(self, iface: Interface, body: str, outlet: Outlet | None = None) -> int:
        """Add one slab behind ``body`` ("disc" or "pad"); returns the particles added."""
        blk, bpos = iface.block, iface.block_pos
        assert blk is not None and bpos is not None
        sim = iface.sim
        p = sim.p
        grp = BODIES[body]
        k = self.fed[body]
        s, h, w = self.slab, blk.height, blk.width
        lo, hi = (h + k * s, h + (k + 1) * s) if grp == PAD else (-(k + 1) * s, -k * s)
        ext, rad = _band(blk.pos, blk.radius, h, lo, hi)
        bi, bj, keep = self._pairs(iface, ext, rad, grp, lo if grp == PAD else hi)
        ext, rad = ext[keep], rad[keep]  # particles without a bond are dropped (as built)
        n0 = p.n  # the kept ones will take the indices n0, n0 + 1, ...
        renum = np.cumsum(keep) - 1 + n0
        bi = np.where(bi >= n0, renum[np.maximum(bi - n0, 0)], bi)
        bj = np.where(bj >= n0, renum[np.maximum(bj - n0, 0)], bj)
        dm = iface.anchor_depth
        if grp == PAD:
            new_anchor = ext[:, 1] + rad > (ext[:, 1] + rad).max() - dm
        else:
            new_anchor = ext[:, 1] - rad < (ext[:, 1] - rad).min() + dm
        old_anchor = (iface.anchor_pad if grp == PAD else iface.anchor_disc).copy()
        lab = ext + _offset(iface, body)  # the slab as one piece: its own pairs exact
        lab[:, 1] += _clearance(iface, lab, ext, rad, bi, bj, 1.0 if grp == PAD else -1.0)
        lab[:, 0] = np.mod(lab[:, 0], w)
        if grp == DISC and outlet is not None:  # the store stays below the disc's face
            drop = float((p.pos[old_anchor, 1] - p.radius[old_anchor]).min()
                         - (lab[:, 1] - rad).min())
            gone = p.group == EJECTED
            p.pos[gone, 1] -= drop
            outlet.shelf[1] -= drop
        spec = iface.pad if grp == PAD else iface.disc
        m = rad.size
        vel = np.tile(p.vel[old_anchor].mean(axis=0), (m, 1))
        # the new layer is held as the old one was (disc: x and y; pad: as its backing)
        held = int(np.bitwise_or.reduce(p.fixed[old_anchor] & (FIX_X | FIX_Y)))
        fix = np.where(new_anchor, held, 0)
        if grp == PAD:  # the plate meets the new face as it met the old one
            top_old = float((p.pos[old_anchor, 1] + p.radius[old_anchor]).max())
            top_new = float((lab[new_anchor, 1] + rad[new_anchor]).max())
            iface.wall.point[1] += top_new - top_old
        idx = sim.append_particles(lab, rad, np.full(m, spec.density), vel,
                                   np.full(m, 1 if grp == PAD else 0),
                                   np.full(m, grp), fix.astype(np.uint8))
        p = sim.p
        # the former anchored layer is body now
        p.fixed[np.flatnonzero(old_anchor)] &= np.uint8(~(FIX_X | FIX_Y) & 0xFF)
        anchors = np.zeros(p.n, dtype=bool)
        anchors[idx[new_anchor]] = True
        none = np.zeros(m, dtype=bool)
        iface.anchor_pad = anchors if grp == PAD else np.concatenate([iface.anchor_pad, none])
        iface.anchor_disc = anchors if grp == DISC else np.concatenate(
            [iface.anchor_disc, none])
        iface.block_pos = np.concatenate([bpos, ext])
        iface.bonds.extend(ParallelBonds(sim, bi, bj, iface.disc.bond_lambda, spec.bond_E,
                                         spec.bond_kr, spec.tensile_strength, spec.cohesion))
        if grp == PAD and iface.backing is not None:
            iface.backing.set_anchors(np.flatnonzero(anchors))
        r = self.ref
        r.pos = np.concatenate([r.pos, ext + self.ref_offset[body]])
        r.radius = np.concatenate([r.radius, rad])
        r.group = np.concatenate([r.group, np.full(m, grp, dtype=r.group.dtype)])
        if outlet is not None:
            outlet.grow(iface)
        self.fed[body] += 1
        self.events.append(body)
        return m

    def _pairs(self, iface: Interface, ext: np.ndarray, rad: np.ndarray, grp: int,
               seam: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The slab's bonds, found in block coordinates (the pairs a taller block would
        have had): every pair within the bond gap among the slab (``ext``, ``rad``,
        numbered from ``n``, the particle count now) and the body's particles near the
        seam (block ordinate ``seam``), at least one end in the slab; and the mask of
        the slab's particles that have a bond."""
        p = iface.sim.p
        bpos = iface.block_pos
        assert bpos is not None and iface.block is not None
        gap = max(iface.disc.bond_gap, iface.pad.bond_gap)
        reach = 2.0 * float(max(p.radius.max(), rad.max())) + gap
        old = np.flatnonzero((p.group == grp) & (np.abs(bpos[:, 1] - seam) < 2 * reach))
        ids = np.concatenate([old, p.n + np.arange(rad.size)])
        i, j, _ = pairs_periodic(np.concatenate([bpos[old], ext]),
                                  np.concatenate([p.radius[old], rad]), iface.block.width, gap)
        i, j = ids[i], ids[j]
        new = (i >= p.n) | (j >= p.n)
        i, j = i[new], j[new]
        ends = np.concatenate([i, j])
        keep = np.zeros(rad.size, dtype=bool)
        keep[ends[ends >= p.n] - p.n] = True
        return i, j, keep

    def state(self) -> dict[str, Any]:
        """JSON-able record (the loop's checkpoint record)."""
        return {"events": list(self.events), "start": dict(self.start)}

    def replay(self, iface: Interface, rec: dict[str, Any], outlet: Outlet | None) -> None:
        """Repeat the recorded feeds (``state``) on a freshly built interface, before its
        checkpoint is loaded: the particle and bond counts then match it."""
        for body in rec["events"]:
            self.apply(iface, str(body), outlet)
        self.start = {str(k): float(v) for k, v in rec["start"].items()}

    def summary(self) -> dict[str, object]:
        """What the summary reports about the feed."""
        return {"slab_thickness_m": self.slab, "slab_diameters": FEED_SLAB_DIAMETERS,
                "slabs_fed": dict(self.fed),
                "remaining_thickness_start_m": dict(self.start)}


def _band(pos: np.ndarray, radius: np.ndarray, height: float, lo: float, hi: float
          ) -> tuple[np.ndarray, np.ndarray]:
    """Centres (m) and radii of the block's periodic continuation (period ``height`` in
    y) with y in [lo, hi), ordered by image then block index."""
    out, rad = [], []
    for j in range(int(np.floor(lo / height)), int(np.floor(hi / height)) + 1):
        y = pos[:, 1] + j * height
        sel = (y >= lo) & (y < hi)
        q = pos[sel].copy()
        q[:, 1] += j * height
        out.append(q)
        rad.append(radius[sel])
    return np.concatenate(out), np.concatenate(rad)


def _clearance(iface: Interface, lab: np.ndarray, ext: np.ndarray, rad: np.ndarray,
               bi: np.ndarray, bj: np.ndarray, out: float) -> float:
    """Shift (m, signed ``out``: +y for the pad, -y for the disc) that sets the slab out
    until no pair across the seam overlaps more than it does in the block. The slab is
    placed as one piece by its body's anchored layer's mean displacement; the layer's
    own deformation over a pair (tens of nm under the impacts, measured: seam overlaps
    up to 54 nm where the body's own were <= 12 nm) would otherwise press new and old
    particles into each other, and their repulsion would load the seam's new bonds in
    tension from their first step; a gap of that size instead closes under the load.
    (Offsets per particle, from each one's partners across the seam, moved the mismatch
    into the slab: 23 nm between two new particles.)"""
    p = iface.sim.p
    n = p.n
    assert iface.block_pos is not None
    w = iface.width
    cross = (bi < n) & (bj >= n)  # (body, slab) pairs; slab particles numbered from n
    o, q = bi[cross], bj[cross] - n
    if o.size == 0:
        return 0.0
    shift = 0.0
    for _ in range(3):
        d = lab[q, :2] + [0.0, out * shift] - p.pos[o, :2]
        d[:, 0] -= w * np.rint(d[:, 0] / w)
        db = ext[q, :2] - iface.block_pos[o, :2]
        db[:, 0] -= w * np.rint(db[:, 0] / w)
        excess = np.linalg.norm(db, axis=1) - np.linalg.norm(d, axis=1)  # extra overlap
        ny = np.maximum(np.abs(d[:, 1]) / np.linalg.norm(d, axis=1), 0.3)
        more = float(np.max(excess / ny, initial=0.0))
        if more <= 1e-12 * float(rad.mean()):
            break
        shift += more
    return out * shift


def _offset(iface: Interface, body: str) -> np.ndarray:
    """Mean displacement (m, (3,)) of the body's anchored layer from its place in the
    block (x by minimum image round the first anchored particle)."""
    assert iface.block_pos is not None
    a = np.flatnonzero(iface.anchor_pad if BODIES[body] == PAD else iface.anchor_disc)
    u = iface.sim.p.pos[a] - iface.block_pos[a]
    w = iface.width
    u[:, 0] = u[0, 0] + (u[:, 0] - u[0, 0]) - w * np.rint((u[:, 0] - u[0, 0]) / w)
    return u.mean(axis=0)
