"""Braking interface model (Sha et al. (2022) sections 3.2-5, table 4)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tribodem.braking.compare import (
    change_with_error,
    packings_for,
    step_verdict,
    trend_verdict,
)
from tribodem.braking.conditions import (
    CONDITIONS,
    FRICTION_RADIUS_M,
    PAD_AREA_M2,
    get_condition,
    load_to_pressure,
    pressure_to_load,
    rpm_to_speed,
    speed_to_rpm,
)
from tribodem.braking.measure import classify, measure, reference, spanning
from tribodem.braking.model import (
    DISC,
    LOOSE_MAX,
    PAD,
    Geometry,
    build_interface,
    compact_periodic,
    materials,
    pairs_periodic,
    plate_force,
    profile_height,
    rough_profile,
    start_sliding,
)
from tribodem.braking.setup import RunSetup
from tribodem.braking.simulate import run_braking
from tribodem.braking.steady import wear_extrapolation
from tribodem.dem.bonds import TENSILE
from tribodem.dem.state import FIX_X, FIX_Y

SMALL = Geometry(width=100e-6, disc_height=36e-6, pad_height=36e-6, amplitude=4e-6, modes=2,
                 seed=3)
REQUIRED = ("condition", "pressure_Pa", "sliding_speed_m_s", "simulated_sliding_distance_m",
            "simulated_time_s", "equivalent_braking_time_s", "wear_depth_mean_m",
            "wear_depth_max_m", "broken_bonds", "broken_bonds_tensile", "broken_bonds_shear",
            "debris_particles", "force_chains", "strong_force_chains",
            "transfer_layer_thickness_m", "particles_initial", "particles_final")


def test_table4_conversions() -> None:
    assert load_to_pressure(13.0) == pytest.approx(0.33e6, rel=1e-9)
    for c in CONDITIONS.values():  # every row of table 4 after the table's rounding
        assert round(c.pressure_Pa / 1e6, 2) == c.table_pressure_MPa
        assert c.speed_m_s == pytest.approx(c.table_speed_m_s, abs=0.01)
    assert rpm_to_speed(1200) == pytest.approx(47.12, abs=0.005)
    assert rpm_to_speed(800) == pytest.approx(31.416, abs=1e-3)
    assert PAD_AREA_M2 == pytest.approx(0.03939, rel=1e-3) and FRICTION_RADIUS_M == 0.375
    assert pressure_to_load(load_to_pressure(17.0)) == pytest.approx(17.0)
    assert speed_to_rpm(rpm_to_speed(1000.0)) == pytest.approx(1000.0)
    with pytest.raises(ValueError, match=r"condition = 6: must be one of \[1, 2, 3, 4, 5\]"):
        get_condition(6)
    with pytest.raises(ValueError, match="load_kN"):
        load_to_pressure(-1.0)


def test_rough_profile_wide_cell_keeps_the_asperities() -> None:
    """A cell 16x the default width with modes k = 16..64 has the default cell's
    wavelengths (216..54 um) and rms slope within a factor 0.4-1.2 of it (the peak, not
    each asperity, is scaled to the amplitude); with k = 1..64 its slopes are < 0.35 x
    (the amplitude goes to the 3.5 mm waves). max |h| = amplitude in every case."""
    w, amp = 216e-6, 8e-6

    def rms_slope(width: float, prof: tuple[np.ndarray, ...]) -> float:
        x = np.linspace(0.0, width, 20001)
        h = profile_height(x, width, prof)
        assert np.abs(h).max() == pytest.approx(amp, rel=0.01)
        return float(np.sqrt(np.mean(np.gradient(h, x) ** 2)))

    for seed in range(5):
        narrow = rough_profile(np.random.default_rng(seed), w, amp, 4)
        kept = rough_profile(np.random.default_rng(seed), 16 * w, amp, 64, 16)
        long = rough_profile(np.random.default_rng(seed), 16 * w, amp, 64)
        assert kept[0][0] == 16 and kept[0][-1] == 64 and kept[0].size == 49
        s1 = rms_slope(w, narrow)
        assert 0.4 < rms_slope(16 * w, kept) / s1 < 1.2
        assert rms_slope(16 * w, long) / s1 < 0.35
    with pytest.raises(ValueError, match="first_mode"):
        Geometry(modes=4, first_mode=5).check(1e-6)


def test_interface_geometry_and_boundary_conditions() -> None:
    it = build_interface(SMALL, 0.33e6)
    p = it.sim.p
    disc, pad = p.group == DISC, p.group == PAD
    assert disc.any() and pad.any() and it.sim.box.periodic[0]
    # pad above disc, its lowest point a clearance above the disc's highest point
    gap = (p.pos[pad, 1] - p.radius[pad]).min() - (p.pos[disc, 1] + p.radius[disc]).max()
    assert gap == pytest.approx(SMALL.clearance, abs=1e-12)
    # rough: the disc is cut by its profile (eq: rough_profile from the geometry's seed) and
    # its surface follows it: in each 10 um bin the highest centre lies between the lowest
    # profile height of the bin less one particle diameter and the highest (a flat cut at
    # the mean height would break the upper bound where the profile dips 3 um below it)
    prof = rough_profile(np.random.default_rng(SMALL.seed + 7919), SMALL.width,
                         SMALL.amplitude, SMALL.modes)
    xd, yd = np.mod(p.pos[disc, 0], SMALL.width), p.pos[disc, 1]
    y_mid = SMALL.disc_height + SMALL.amplitude
    assert np.all(yd < y_mid + profile_height(xd, SMALL.width, prof))
    nb, dmax = 10, 2 * p.radius.max()
    xs = np.linspace(0.0, SMALL.width, 1001)
    hs = y_mid + profile_height(xs, SMALL.width, prof)
    assert np.ptp(hs) > dmax * 0.8  # the relief is a particle diameter or more
    for k in range(nb):
        lo, hi = k * SMALL.width / nb, (k + 1) * SMALL.width / nb
        top = yd[(xd >= lo) & (xd < hi)].max()
        hb = hs[(xs >= lo) & (xs <= hi)]
        assert hb.min() - dmax <= top <= hb.max(), k
    assert np.all(p.fixed[it.anchor_disc] & (FIX_X | FIX_Y) == (FIX_X | FIX_Y))
    # absorbing backing (default): the pad's top layer is free, held by dashpots
    assert not np.any(p.fixed[it.anchor_pad] & (FIX_X | FIX_Y)) and it.backing is not None
    assert it.backing.c_n > it.backing.c_t > 0
    held = build_interface(SMALL, 0.33e6, backing="support")
    assert np.all(held.sim.p.fixed[held.anchor_pad] & FIX_X) and held.backing is None
    assert not np.any(held.sim.p.fixed[held.anchor_pad] & FIX_Y)
    assert it.anchor_disc.sum() >= 5 and it.anchor_pad.sum() >= 5
    # bonds only inside each body; the target force is p W t
    b = it.bonds
    assert np.all(p.group[b.i] == p.group[b.j])
    assert it.target_force == pytest.approx(0.33e6 * SMALL.width * 1.0)
    matrix, _ = classify(it)
    assert matrix.all()  # intact: everything is matrix
    start_sliding(it, 30.0)
    assert np.all(p.vel[disc, 0] == -30.0) and np.all(p.vel[pad, 0] == 0.0)
    ref = reference(it)
    it.sim.step(100)
    m = measure(it, ref, 30.0 * it.sim.time)
    assert m["debris_particles"] == 0 and m["wear_depth_mean_m"] == 0.0
    assert m["force_chains"] >= 0.9 * b.n_bonds  # every loaded intact bond is a chain
    with pytest.raises(ValueError, match="width"):
        build_interface(Geometry(width=1e-6), 0.33e6)


def _pad_vibration(backing: str, steps: int) -> float:
    """Internal kinetic energy (J) of the pad ``steps`` after kicking its lowest layer up
    at 1 m/s (pad clear of the disc)."""
    geo = Geometry(width=100e-6, disc_height=36e-6, pad_height=36e-6, amplitude=4e-6,
                   modes=2, seed=3, clearance=2e-6)
    it = build_interface(geo, 0.33e6, backing=backing)
    p = it.sim.p
    pad = p.group == PAD
    low = pad & (p.pos[:, 1] - p.radius < (p.pos[pad, 1] - p.radius[pad]).min()
                 + 2 * p.radius.mean())
    p.vel[low, 1] = 1.0
    it.sim.step(steps)
    v, m = p.vel[pad], p.mass[pad]
    vm = (m[:, None] * v).sum(0) / m.sum()
    return 0.5 * float((m[:, None] * (v - vm) ** 2).sum())


def test_spanning_intervals_round_the_periodic_cell() -> None:
    """A component spans the cell when its x-extents leave no gap of a diameter, the
    gap round x = W counted."""
    w = 10.0
    x = np.arange(10) + 0.5 + 0.3  # radius 0.5: touching disks, the row crossing x = W
    r = np.full(10, 0.5)
    lab = np.zeros(10, dtype=int)
    assert spanning(x, r, lab, w, np.array([0]))[0]
    x2 = x.copy()
    x2[4] += 0.95  # a gap of 0.95 < one diameter: still spans
    assert spanning(x2, r, lab, w, np.array([0]))[0]
    assert not spanning(x[:-1], r[:-1], lab[:-1], w, np.array([0]))[0]  # gap of 1.0
    assert not spanning(x, r, lab, w, np.array([], dtype=int))[0]  # not a candidate
    # a large disk round x = 0 ([8.9, 12.1] = [8.9, W) + [0, 2.1)) bridges the 1.5 gap
    # between the small disk [0.2, 0.5] and the row [2, 9]: it spans; without it, not
    x3 = np.array([0.35, 2.5, 3.5, 4.5, 5.5, 6.5, 7.5, 8.5, 0.5])
    r3 = np.array([0.15, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 1.6])
    lab3 = np.zeros(9, dtype=int)
    assert spanning(x3, r3, lab3, w, np.array([0]))[0]
    assert not spanning(x3[:-1], r3[:-1], lab3[:-1], w, np.array([0]))[0]


def test_a_slab_as_wide_as_the_cell_is_delamination_not_wear() -> None:
    """Cut every pad bond crossing the pad's mid-plane and move the freed slab by 3 mean
    radii: it spans the cell, so it is reported as delaminated and the wear depth stays
    0. Cut the slab across at x = W/4 and 3W/4 as well: its two halves are debris and
    the wear depth is their solid area over phi W (module measure's definition)."""
    it = build_interface(SMALL, 0.33e6)
    p, b = it.sim.p, it.bonds
    ref = reference(it)
    pad = p.group == PAD
    below = pad & (p.pos[:, 1] < np.median(p.pos[pad, 1]))
    inpad = p.group[b.i] == PAD
    b.mode[inpad & (below[b.i] != below[b.j])] = TENSILE
    matrix, _ = classify(it)
    slab = pad & ~matrix
    assert slab.sum() > 0.3 * pad.sum()
    p.pos[slab, 1] -= 3.0 * float(p.radius.mean())
    m = measure(it, ref, 0.0)
    assert m["delaminated_particles_pad"] == slab.sum()
    assert m["worn_particles_pad"] == 0 and m["wear_depth_mean_pad_m"] == 0.0
    area = float((np.pi * p.radius[slab] ** 2).sum())
    assert m["delaminated_depth_pad_m"] == pytest.approx(area / (it.phi[PAD] * it.width),
                                                         rel=1e-12)
    w = it.width
    xm = np.mod(p.pos[:, 0], w)
    for xc in (0.25 * w, 0.75 * w):
        left = xm < xc
        crosses = (left[b.i] != left[b.j]) & (np.abs(xm[b.i] - xm[b.j]) < 0.5 * w)
        b.mode[inpad & crosses] = TENSILE
    m = measure(it, ref, 0.0)
    assert m["delaminated_particles_pad"] == 0
    assert m["worn_particles_pad"] == slab.sum()
    assert m["wear_depth_mean_pad_m"] == pytest.approx(area / (it.phi[PAD] * w), rel=1e-12)



def test_breaks_by_place_counts_the_surface_layer_and_the_bulk() -> None:
    """``breaks_by_place``: every broken bond is counted once (by body, mode and place:
    the sums are the mode counts); bonds broken by hand in the pad's lowest particle row
    (on its rough face) count as surface-layer breaks, bonds broken more than 2.6 mean
    diameters above the face as bulk; the layer is two mean diameters."""
    from tribodem.braking.measure import SURFACE_LAYER_DIAMETERS, breaks_by_place
    from tribodem.dem.bonds import SHEAR

    it = build_interface(SMALL, 0.33e6)
    p, b = it.sim.p, it.bonds
    ref = reference(it)
    dm = 2.0 * float(p.radius.mean())
    w = it.width
    nbin = max(1, int(w // (2.0 * float(p.radius.max()))))
    k = np.minimum((np.mod(p.pos[:, 0], w) / w * nbin).astype(int), nbin - 1)
    pad = p.group == PAD
    low = np.full(nbin, np.inf)
    np.minimum.at(low, k[pad], p.pos[pad, 1] - p.radius[pad])
    depth = p.pos[:, 1] - low[k]  # centre height above the pad's local face
    inpad = p.group[b.i] == PAD
    face = inpad & (depth[b.i] < 0.6 * dm) & (depth[b.j] < 0.6 * dm)
    deep = inpad & (depth[b.i] > 2.6 * dm) & (depth[b.j] > 2.6 * dm)
    assert face.sum() > 3 and deep.sum() > 3
    b.mode[face] = TENSILE
    b.mode[deep] = SHEAR
    out = breaks_by_place(it, ref)
    assert out["broken_bonds_surface_layer_m"] == pytest.approx(SURFACE_LAYER_DIAMETERS * dm)
    assert out["broken_bonds_pad_surface_tensile"] == face.sum()
    assert out["broken_bonds_pad_bulk_shear"] == deep.sum()
    assert out["broken_bonds_pad_bulk_tensile"] == out["broken_bonds_pad_surface_shear"] == 0
    total = sum(v for key, v in out.items() if key.startswith("broken_bonds_") and
                key != "broken_bonds_surface_layer_m")
    assert total == b.broken_count() == face.sum() + deep.sum()


def _free_chunk(it, xc: float, n: int) -> np.ndarray:
    """Cut the bonds round the ``n`` pad particles nearest to (xc, pad surface): a debris
    component of the pad; returns its mask."""
    p, b = it.sim.p, it.bonds
    pad = np.flatnonzero(p.group == PAD)
    w = it.width
    dx = p.pos[pad, 0] - xc
    dx -= w * np.rint(dx / w)
    dy = p.pos[pad, 1] - (p.pos[pad, 1] - p.radius[pad]).min()
    chunk = np.zeros(p.n, dtype=bool)
    chunk[pad[np.argsort(dx**2 + dy**2)[:n]]] = True
    b.mode[chunk[b.i] != chunk[b.j]] = TENSILE
    return chunk


@pytest.mark.parametrize("body", ["pad", "disc"])
def test_feed_continues_a_body_without_a_seam(body: str) -> None:
    """One feed on the periodic-block cell at rest: the slab is the block's next band
    placed exactly where a taller block would have it (the pad's rigid lowering), so its
    bonds across the seam are exactly the block's y-periodic bonded pairs across its
    period boundary (counted independently on the periodic block) and no pair overlaps
    more than the block's own pairs do; the body's remaining thickness rises by exactly
    the solid area of the slab outside its new anchored layer plus the former anchored
    layer, over phi W (rel 1e-12); the plate moves out by the new face's offset."""
    from tribodem.braking.feed import Feed
    from tribodem.braking.measure import classify, measure, reference

    iface = build_interface(SMALL, 0.53e6, block="periodic")
    blk = iface.block
    ref = reference(iface)
    feed = Feed(iface, ref)
    p = iface.sim.p
    grp = PAD if body == "pad" else DISC
    n0, nb0 = p.n, iface.bonds.n_bonds
    old_anchor = (iface.anchor_pad if grp == PAD else iface.anchor_disc).copy()
    top0 = float((p.pos[old_anchor, 1] + p.radius[old_anchor]).max())
    wall0 = float(iface.wall.point[1])
    before = measure(iface, ref, 0.0)[f"remaining_thickness_{body}_m"]
    m = feed.apply(iface, body)
    p = iface.sim.p
    assert p.n == n0 + m and m > 10
    # the block's own bonded pairs, periodic in y: those across its period boundary
    # between the body's particles in the cell and the band the slab came from
    gap = max(iface.disc.bond_gap, iface.pad.bond_gap)
    i, j, _ = pairs_periodic(blk.pos, blk.radius, blk.width, gap, height=blk.height)
    cross = np.abs(blk.pos[j, 1] - blk.pos[i, 1]) > 0.5 * blk.height
    ids = {tuple(q): k for k, q in enumerate(blk.pos)}
    in_body = np.zeros(blk.radius.size, dtype=bool)
    in_body[[ids[tuple(q)] for q in iface.block_pos[:n0][p.group[:n0] == grp]]] = True
    band = (blk.pos[:, 1] < feed.slab) if grp == PAD else (
        blk.pos[:, 1] >= blk.height - feed.slab)
    expect = np.count_nonzero(cross & ((in_body[i] & band[j]) | (in_body[j] & band[i])))
    b = iface.bonds
    new_b = np.arange(nb0, b.n_bonds)
    seam = new_b[(b.i[new_b] < n0) & (b.j[new_b] >= n0)]
    assert seam.size == expect > 5
    # overlaps across the seam: no larger than the block's
    d = p.pos[b.j[new_b], :2] - p.pos[b.i[new_b], :2]
    d[:, 0] -= blk.width * np.rint(d[:, 0] / blk.width)
    ov = p.radius[b.i[new_b]] + p.radius[b.j[new_b]] - np.linalg.norm(d, axis=1)
    d = blk.pos[j, :2] - blk.pos[i, :2]
    d -= [blk.width, blk.height] * np.rint(d / [blk.width, blk.height])
    assert ov.max() <= (blk.radius[i] + blk.radius[j] - np.linalg.norm(d, axis=1)).max() + 1e-15
    # the remaining thickness, exactly
    matrix, _ = classify(iface)
    new = np.arange(n0, p.n)
    anchors = iface.anchor_pad if grp == PAD else iface.anchor_disc
    assert matrix[new].all() and not anchors[:n0].any() and anchors[new].any()
    area = np.pi * p.radius**2
    gain = (area[new[~anchors[new]]].sum() + area[:n0][old_anchor].sum()) / (iface.phi[grp]
                                                                        * blk.width)
    after = measure(iface, ref, 0.0)[f"remaining_thickness_{body}_m"]
    assert after - before == pytest.approx(gain, rel=1e-12)
    assert gain == pytest.approx(feed.slab, rel=0.3)
    top1 = float((p.pos[anchors, 1] + p.radius[anchors]).max())
    assert float(iface.wall.point[1]) - wall0 == (top1 - top0 if grp == PAD else 0.0)
    if grp == PAD:
        assert np.array_equal(iface.backing.idx, np.flatnonzero(anchors))
    assert np.all(p.fixed[:n0][old_anchor] & (FIX_X | FIX_Y) == 0)


def test_outlet_ejects_debris_after_its_residence_length() -> None:
    """Two pad chunks are freed and carried in -x in steps of W/8 (as the disc carries
    debris); with the residence length L = 0.6 W the chunk that moves leaves at the first
    check where its travel reaches L (5 steps: 0.625 W), the chunk that stays (lodged in a
    pit) never does. Ejected: group EJECTED, frozen, moved rigidly (pair distances kept to
    1e-12 relative) below the disc's anchored layer, farther than a contact from every
    live particle and from each other; counted as worn, depth = area / (phi W)."""
    from tribodem.braking.model import EJECTED
    from tribodem.braking.outlet import Outlet

    it = build_interface(SMALL, 0.33e6)
    p = it.sim.p
    w = it.width
    ref = reference(it)
    moving = _free_chunk(it, 0.25 * w, 4)
    lodged = _free_chunk(it, 0.75 * w, 3)
    out = Outlet(it, 0.6 * w)
    assert out.check(it) == 0
    idx = np.flatnonzero(moving)
    d0 = np.linalg.norm(p.pos[idx[:, None], :2] - p.pos[idx[None, :], :2], axis=2)
    for k in range(1, 7):
        before = p.group[idx].copy()
        if (before != EJECTED).all():
            p.pos[moving, 0] = np.mod(p.pos[moving, 0] - w / 8, w)
        n = out.check(it)
        if k < 5:
            assert n == 0 and (p.group[moving] == PAD).all(), k
        elif k == 5:
            assert n == moving.sum() and (p.group[moving] == EJECTED).all()
    assert (p.group[lodged] == PAD).all()
    gone = p.group == EJECTED
    assert (p.vel[gone] == 0).all() and (p.omega[gone] == 0).all()
    assert (p.fixed[gone] & (FIX_X | FIX_Y)).all()
    x = p.pos[idx, 0]
    d = p.pos[idx[:, None], :2] - p.pos[idx[None, :], :2]
    d[..., 0] -= w * np.rint(d[..., 0] / w)
    np.testing.assert_allclose(np.linalg.norm(d, axis=2), d0, rtol=1e-12, atol=1e-18)
    assert (x >= 0).all() and (x < w).all()
    live = ~gone
    rmax = float(p.radius.max())
    assert p.pos[gone, 1].max() + rmax < p.pos[live, 1].min() - rmax
    m = measure(it, ref, 0.0)
    area = float((np.pi * p.radius[moving] ** 2).sum())
    assert m["ejected_particles_pad"] == moving.sum() and m["ejected_particles_disc"] == 0
    assert m["ejected_depth_pad_m"] == pytest.approx(area / (it.phi[PAD] * w), rel=1e-12)
    assert m["worn_particles_pad"] == moving.sum()  # the lodged chunk has not moved
    assert m["debris_particles"] == lodged.sum()
    # a second ejection goes beside the first in the store, never onto it
    p.pos[lodged, 0] = np.mod(p.pos[lodged, 0] + 0.3 * w, w)
    out.length = 0.25 * w
    assert out.check(it) == lodged.sum()
    g = np.flatnonzero(p.group == EJECTED)
    dd = p.pos[g[:, None], :2] - p.pos[g[None, :], :2]
    dd[..., 0] -= w * np.rint(dd[..., 0] / w)
    gap = np.linalg.norm(dd, axis=2) - (p.radius[g][:, None] + p.radius[g][None, :])
    other = moving[g][:, None] != moving[g][None, :]
    assert gap[other].min() > 0.0


def test_remaining_thickness_falls_by_what_the_body_loses() -> None:
    """Remaining thickness = intact matrix outside the anchored layer, solid area over
    phi W: at the start it lies between the body's height and that height less the
    roughness amplitude and twice the anchored layer's largest thickness (two diameters:
    centres within one diameter of the face); a pad chunk of area A freed and carried
    off lowers the pad's by exactly A / (phi W) (rel 1e-12) and raises its wear depth by
    the same; the disc's does not move."""
    it = build_interface(SMALL, 0.33e6)
    p = it.sim.p
    w = it.width
    ref = reference(it)
    m0 = measure(it, ref, 0.0)
    layer = 4.0 * float(p.radius.mean())
    for name, h in (("disc", SMALL.disc_height), ("pad", SMALL.pad_height)):
        assert h - 2 * layer - SMALL.amplitude < m0[f"remaining_thickness_{name}_m"] < h, name
    chunk = _free_chunk(it, 0.5 * w, 6)
    p.pos[chunk, 0] = np.mod(p.pos[chunk, 0] - 0.25 * w, w)
    m1 = measure(it, ref, 0.0)
    lost = float((np.pi * p.radius[chunk] ** 2).sum()) / (it.phi[PAD] * w)
    assert m0["remaining_thickness_pad_m"] - m1["remaining_thickness_pad_m"] == \
        pytest.approx(lost, rel=1e-12)
    assert m1["wear_depth_mean_pad_m"] - m0["wear_depth_mean_pad_m"] == \
        pytest.approx(lost, rel=1e-12)
    assert m1["remaining_thickness_disc_m"] == m0["remaining_thickness_disc_m"]


def test_absorbing_backing_lets_waves_leave_the_pad() -> None:
    """The Lysmer backing (rest of the pad) absorbs the waves a free back face reflects:
    measured 1.1e-9 J vs 1.1e-8 J after 1000 steps (~15 pad transits)."""
    ab, held = _pad_vibration("absorbing", 1000), _pad_vibration("support", 1000)
    assert ab < 0.25 * held


def test_a_wide_cell_is_compacted_as_densely_as_the_default_one() -> None:
    """A 4x-wide cell (864 x 196 um, packing 1): at most LOOSE_MAX (5 %) of its particles
    without a neighbour within the bond gap, as a jammed 2D packing and the default cell
    (2.9-4.0 %); with the relaxations of the default cell's length it was 24.6 % (837 of
    3,401 particles dropped as unbonded)."""
    disc, _ = materials("calibrated")
    w = 864e-6
    _, _, stats = compact_periodic(disc, w, 196e-6, seed=1)
    assert stats["relax_scale"] == 4.0
    assert stats["loose_fraction"] <= LOOSE_MAX, stats


def test_a_tall_cell_is_compacted_until_jammed() -> None:
    """A cell 3x taller than wide (100 x 300 um) closes slowly too: packing 4 at the
    nominal relaxations leaves 17 % of its particles without a neighbour within the bond
    gap; ``compact_periodic`` makes it again with longer relaxations until at most
    LOOSE_MAX are. A packing jammed at once (packing 0) is the one-pass packing, bitwise."""
    from tribodem.braking.model import compact_once

    disc, _ = materials("calibrated")
    loose = compact_once(disc, 100e-6, 300e-6, 4, 1e6, 40, disc.bond_gap, 1)[2]
    assert loose["loose_fraction"] > 3 * LOOSE_MAX
    _, _, stats = compact_periodic(disc, 100e-6, 300e-6, seed=4)
    assert stats["loose_fraction"] <= LOOSE_MAX and stats["relax_scale"] >= 2, stats
    pos, r, st0 = compact_periodic(disc, 100e-6, 300e-6, seed=0)
    once = compact_once(disc, 100e-6, 300e-6, 0, 1e6, 40, disc.bond_gap, 1)
    assert st0["relax_scale"] == 1 and np.array_equal(pos, once[0])
    assert np.array_equal(r, once[1])


def test_plate_force_includes_backing_reaction() -> None:
    it = build_interface(SMALL, 0.33e6)
    start_sliding(it, 30.0)
    it.sim.step(50)
    assert plate_force(it) == pytest.approx(it.wall.normal_force + it.backing.reaction)
    # the plate is driven by the target minus the dashpots' reaction (momentum balance)
    assert it.wall.target_force == pytest.approx(it.target_force - it.backing.reaction)


def test_change_errors_and_verdicts() -> None:
    a, b = np.array([1.0, 1.1, 0.9]), np.array([1.5, 1.6, 1.4])
    pct, se = change_with_error(a, b, paired=False)
    assert pct == pytest.approx(50.0) and se == pytest.approx(10.408, rel=1e-3)
    assert change_with_error(a, b) == (pytest.approx(50.0), pytest.approx(0.0, abs=1e-9))
    pct, se = change_with_error(a, np.array([1.5, 1.5, 1.5]))  # paired: sd(b - a) = 0.1
    assert se == pytest.approx(100 * 0.1 / np.sqrt(3), rel=1e-6)
    assert step_verdict(pct, se) == "up"
    assert step_verdict(5.0, 4.0) == "not resolved" and step_verdict(-9.0, 4.0) == "down"
    assert np.isnan(change_with_error(np.array([1.0]), np.array([2.0]))[1])
    assert trend_verdict([(10, 2), (10, 2)], (20, 3), "up").startswith("reproduced")
    assert trend_verdict([(10, 2), (-10, 2)], (1, 3), "up").startswith("not resolved")
    assert trend_verdict([(-10, 2), (-10, 2)], (-20, 3), "up").startswith("not reproduced")
    assert trend_verdict([(-10, 2), (-10, 2)], (-20, 3), "down").startswith("reproduced")
    # with 3 seeds a change must exceed t(0.975, 2) = 4.30 standard errors
    assert step_verdict(10.0, 4.0) == "up" and step_verdict(10.0, 4.0, 3) == "not resolved"
    assert step_verdict(10.0, 2.0, 3) == "up"


def test_packings_for_a_target_interval() -> None:
    """The smallest m with t(0.975, m - 1) sd / sqrt(m) <= 10 pp, sd = se sqrt(n) kept."""
    from scipy.stats import t

    sd = 52.0  # pp: the 13 -> 21 kN per-packing change measured over 60 packings
    m = packings_for(sd / np.sqrt(60), 60)
    assert t.ppf(0.975, m - 1) * sd / np.sqrt(m) <= 10.0 < t.ppf(0.975, m - 2) * sd / np.sqrt(m - 1)
    assert 100 <= m <= 110  # (1.96 x 52 / 10)^2 = 104 for large m
    assert packings_for(0.1, 20) == 2  # far inside: the fewest that measure a scatter
    assert packings_for(1.0, 20) == 4  # t(0.975, 3) = 3.18: 3.18 x 4.47 / 2 = 7.1 pp
    assert packings_for(float("nan"), 1) is None


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict, Path]:
    out = tmp_path_factory.mktemp("braking")
    setup = RunSetup(pressure_Pa=0.53e6, speed_m_s=47.12, duration_s=4e-6, geometry=SMALL,
                     condition=5, samples=40, vtk_snapshots=2,
                     worn_through_diameters=0.0)  # as in _tiny
    return run_braking(setup, out), out


def test_quick_run_conserves_particles_and_accounts_debris(quick_run: tuple[dict, Path]
                                                           ) -> None:
    s, out = quick_run
    assert s["particles_final"] == s["particles_initial"] > 100
    assert s["matrix_particles"] + s["debris_particles"] == s["particles_initial"]
    assert s["debris_particles"] == s["debris_particles_disc"] + s["debris_particles_pad"]
    assert s["broken_bonds"] > 0  # asperities at 47 m/s do break bonds
    assert s["broken_bonds"] == s["broken_bonds_tensile"] + s["broken_bonds_shear"]
    assert s["strong_force_chains"] + s["weak_force_chains"] == s["force_chains"]
    assert s["simulated_sliding_distance_m"] == pytest.approx(47.12 * s["simulated_time_s"])
    ts = np.genfromtxt(out / "timeseries.csv", delimiter=",", names=True)
    assert np.all(np.diff(ts["broken_bonds"]) >= 0)  # bonds never heal
    assert np.all(ts["matrix_particles"] + ts["debris_particles"] == s["particles_initial"])
    assert ts["wear_depth_mean_m"][0] == 0.0


def test_pressure_wall_holds_target_on_average(quick_run: tuple[dict, Path]) -> None:
    s, _ = quick_run
    assert s["mean_wall_pressure_ratio"] == pytest.approx(1.0, abs=0.05)
    assert s["mean_wall_pressure_Pa"] == pytest.approx(0.53e6, rel=0.05)


def test_summary_keys_and_outputs(quick_run: tuple[dict, Path]) -> None:
    s, out = quick_run
    on_disk = json.loads((out / "summary.json").read_text())
    for k in REQUIRED:
        assert k in on_disk, k
    assert on_disk["condition"] == 5 and on_disk["equivalent_braking_time_s"] > 0
    for f in ("displacement.png", "velocity.png", "force_chains.png", "wear_history.png",
              "vtk/particles.pvd", "vtk/chains.pvd"):
        assert (out / f).stat().st_size > 0, f
    assert any("time mapping" in a for a in on_disk["assumptions"])


def test_wear_extrapolation_rule() -> None:
    t = np.linspace(0, 1e-5, 11)
    rate, h8 = wear_extrapolation(t, 2.0 * t, 8.0)
    assert rate == pytest.approx(2.0) and h8 == pytest.approx(16.0)


def _cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "tribodem.cli", "braking", *args],
                          capture_output=True, text=True, timeout=120)


def test_cli_refuses_bad_input(tmp_path: Path) -> None:
    r = _cli("run", "--condition", "7", "--out", str(tmp_path / "x"))
    assert r.returncode == 2 and "condition" in r.stderr and "Traceback" not in r.stderr
    assert not (tmp_path / "x").exists()
    bad = tmp_path / "bad.toml"
    bad.write_text("[geometry]\nwidth_m = -1.0\n")
    r = _cli("run", "--config", str(bad), "--out", str(tmp_path / "y"))
    assert r.returncode == 2 and "width_m" in r.stderr
    bad.write_text("[condition]\nindex = 1\n[geometry]\nwidth_m = 1e-6\n")  # too narrow
    r = _cli("run", "--config", str(bad), "--out", str(tmp_path / "w"))
    assert r.returncode == 2 and "width" in r.stderr and "Traceback" not in r.stderr
    bad.write_text("[condition]\nload_kN = 13.0\n")  # no speed
    r = _cli("run", "--config", str(bad), "--out", str(tmp_path / "z"))
    assert r.returncode == 2 and "speed" in r.stderr
    bad.write_text("[run]\nduration_s = 1e-5\ndistance_m = 1e-3\n")  # two run lengths
    r = _cli("run", "--condition", "5", "--config", str(bad), "--out", str(tmp_path / "v"))
    assert r.returncode == 2 and "distance_m" in r.stderr and "duration_s" in r.stderr
    assert "Traceback" not in r.stderr and not (tmp_path / "v").exists()
    bad.write_text("[run]\noutlet_length_m = -2e-4\n")
    r = _cli("run", "--condition", "5", "--config", str(bad), "--out", str(tmp_path / "u"))
    assert r.returncode == 2 and "outlet_length_m" in r.stderr and "-0.0002" in r.stderr
    assert "Traceback" not in r.stderr and not (tmp_path / "u").exists()
    bad.write_text("[run]\nworn_through_diameters = -1\n")
    r = _cli("run", "--condition", "5", "--config", str(bad), "--out", str(tmp_path / "t"))
    assert r.returncode == 2 and "worn_through_diameters" in r.stderr and "-1" in r.stderr
    assert "Traceback" not in r.stderr and not (tmp_path / "t").exists()
    curve = tmp_path / "curve.csv"
    curve.write_text("time_s,temperature_K\n0,300\n1,400\n")
    bad.write_text(f"[run]\nfeed = true\n[thermal]\ncurve = '{curve}'\n")
    r = _cli("run", "--condition", "5", "--config", str(bad), "--out", str(tmp_path / "s"))
    assert r.returncode == 2 and "run.feed" in r.stderr and "thermal.curve" in r.stderr
    assert "Traceback" not in r.stderr and not (tmp_path / "s").exists()


def _tiny(change: dict | None = None) -> RunSetup:
    # SMALL's bodies are ~3 grains thick outside their anchored layers and one impact can
    # take one: the worn-through guard is off in these mechanics tests (tested on its own)
    kw = dict(pressure_Pa=0.53e6, speed_m_s=47.12, duration_s=1e-6, geometry=SMALL,
              condition=5, samples=12, vtk_snapshots=3, figures=False,
              worn_through_diameters=0.0)
    return RunSetup(**{**kw, **(change or {})})


OUTLET = {"outlet_length_m": 10e-6, "duration_s": 2e-6}


@pytest.mark.parametrize("change", [{}, OUTLET, {**OUTLET, "feed": True}],
                         ids=["closed", "outlet", "feed"])
def test_resume_in_process_equals_the_uninterrupted_run(tmp_path: Path,
                                                        monkeypatch: pytest.MonkeyPatch,
                                                        change: dict) -> None:
    """Interrupted at the 8th sample (after the checkpoint of sample 6), then resumed:
    rows, pvd indexes, snapshots and summary are bitwise the uninterrupted run's; with
    the debris outlet too (its travel and store state are in the checkpoint); with the
    feed (slabs of one diameter, so that the tiny cell is fed once, after sample 8) the
    run is interrupted at sample 12, after the feed's checkpoint, and the resume replays
    the feed before loading it."""
    import tribodem.braking.feed as feed_mod
    import tribodem.braking.loop as loop_mod
    from tribodem.braking.checkpoint import read_checkpoint

    monkeypatch.setattr(feed_mod, "FEED_SLAB_DIAMETERS", 1.0)
    full = run_braking(_tiny(change), tmp_path / "a")
    if change:
        assert full["ejected_particles_disc"] + full["ejected_particles_pad"] > 0
    stop = 12 if change.get("feed") else 8
    real = loop_mod.measure
    calls = [0]

    def interrupted(*a: object, **k: object) -> dict:
        calls[0] += 1
        if calls[0] == stop:
            raise KeyboardInterrupt
        return real(*a, **k)

    monkeypatch.setattr(loop_mod, "measure", interrupted)
    with pytest.raises(KeyboardInterrupt):
        run_braking(_tiny(change), tmp_path / "b")
    monkeypatch.setattr(loop_mod, "measure", real)
    rec = read_checkpoint(tmp_path / "b" / "checkpoint.npz")
    assert 0 < rec["done"] < rec["total_steps"] and not rec["finished"]
    if change.get("feed"):
        assert rec["feed"]["events"] == ["pad"] == [k for k, v in full["feed"][
            "slabs_fed"].items() if v], rec["feed"]
    # checkpoint_every and figures may change on resume; the physics may not
    res = run_braking(_tiny({**change, "checkpoint_every": 5}), tmp_path / "b", resume=True)
    for k, v in full.items():
        if not k.startswith("wall_time"):
            assert repr(res[k]) == repr(v), k
    for f in ("timeseries.csv", "vtk/particles.pvd", "vtk/chains.pvd",
              "vtk/particles_0002.vtu", "vtk/chains_0001.vtu"):
        assert (tmp_path / "a" / f).read_bytes() == (tmp_path / "b" / f).read_bytes(), f
    from tribodem.io.config import ConfigError

    with pytest.raises(ConfigError, match=r"samples = 13 differs .* 12"):
        run_braking(_tiny({**change, "samples": 13}), tmp_path / "b", resume=True)


def test_instability_keeps_rows_and_a_stopped_summary(tmp_path: Path,
                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    from tribodem.braking.drive import SlidingDrive
    from tribodem.dem import Simulation, SimulationUnstable

    real = Simulation.step
    calls = [0]

    def unstable(self: Simulation, n: int = 1) -> None:
        sliding = any(isinstance(x, SlidingDrive) for x in self.interactions)
        calls[0] += sliding
        if sliding and calls[0] == 4:
            raise SimulationUnstable("particle 7 moved more than its radius in one step")
        real(self, n)

    monkeypatch.setattr(Simulation, "step", unstable)
    with pytest.raises(SimulationUnstable):
        run_braking(_tiny(), tmp_path)
    s = json.loads((tmp_path / "summary.json").read_text())
    assert s["status"] == "stopped" and "particle 7" in s["stopped_reason"]
    ts = np.genfromtxt(tmp_path / "timeseries.csv", delimiter=",", names=True)
    assert ts.size == s["steps"] // (s["steps_planned"] // 12) + 1 >= 3
    assert s["last_checkpoint"] is not None


def test_a_worn_through_body_stops_the_run(tmp_path: Path) -> None:
    """A floor above the bodies (``worn_through_diameters`` = 100: 720 um against the
    36-um disc) stops the run at its first sliding sample: ``RunStopped`` naming the
    disc, every output written with status ``worn_through`` and the floor; a resume
    reports the same stop with the same summary (wall times aside). Floor 0: never."""
    from tribodem.io.runs import RunStopped

    setup = _tiny({"worn_through_diameters": 100.0})
    with pytest.raises(RunStopped, match="disc was worn through"):
        run_braking(setup, tmp_path)
    s = json.loads((tmp_path / "summary.json").read_text())
    assert s["status"] == "worn_through" and s["worn_through"]["body"] == "disc"
    ts = np.genfromtxt(tmp_path / "timeseries.csv", delimiter=",", names=True)
    assert 0 < ts["remaining_thickness_disc_m"][0] < s["worn_through"]["floor_m"]
    assert s["worn_through"]["floor_m"] == s["worn_through_floor_m"]["disc"]
    assert ts.size == 2 and s["steps"] < setup.duration_s / s["dt_s"] / 5
    with pytest.raises(RunStopped, match="disc was worn through"):
        run_braking(setup, tmp_path, resume=True)
    again = json.loads((tmp_path / "summary.json").read_text())
    assert {k: v for k, v in again.items() if not k.startswith("wall_time")} == \
        {k: v for k, v in s.items() if not k.startswith("wall_time")}
    never = run_braking(_tiny({"worn_through_diameters": 0.0}), None)
    assert never["status"] == "finished" and never["worn_through"] is None
    from tribodem.braking.config import RunCfg
    from tribodem.braking.setup import WORN_THROUGH

    assert RunCfg().worn_through_diameters == WORN_THROUGH  # the command's default


def test_quick_preset_overrides_the_config_file(tmp_path: Path) -> None:
    from tribodem.braking.config import BrakingConfig, resolve_config

    quick = BrakingConfig.quick()
    cfg = tmp_path / "c.toml"
    cfg.write_text("[run]\nduration_s = 1e-6\nsamples = 7\n[condition]\nindex = 2\n")
    c = resolve_config(cfg)
    assert c.run.duration_s == 1e-6 and c.run.samples == 7
    q = resolve_config(cfg, condition=4, quick=True)  # defaults < file < quick < condition
    assert q.run.duration_s == quick["run"]["duration_s"]
    assert q.run.samples == quick["run"]["samples"] and q.condition.index == 4
    assert resolve_config(quick=True).run.samples == quick["run"]["samples"]
    # a dict and a model resolve as the file does
    assert resolve_config({"run": {"duration_s": 1e-6, "samples": 7},
                           "condition": {"index": 2}}) == c
    assert resolve_config(c, quick=True, condition=4) == q



def test_default_cell_is_the_trend_study_cell_and_quick_one_junction() -> None:
    """The default cell is 16 one-junction cells wide with the one-junction cell's
    wavelengths (modes 16..64 of 3,456 um = 216..54 um), ~12,500 disks by the packing's
    area fraction; ``--quick`` is one junction (144 um, modes 1..3). roughness_first_mode
    0 (auto) is ceil(modes / 4) (the band of modes 1..4 scaled), resolved in the model so
    a recorded config holds the number; an explicit first mode is kept."""
    from tribodem.braking.config import (
        JUNCTION_WIDTH_M,
        WIDE_FACTOR,
        BrakingConfig,
        cell_particles,
        resolve_config,
    )

    d = resolve_config()
    assert d.geometry.width_m == WIDE_FACTOR * JUNCTION_WIDTH_M == pytest.approx(3456e-6)
    assert (d.geometry.roughness_first_mode, d.geometry.roughness_modes) == (16, 64)
    # the longest and shortest wavelengths: the one-junction cell's 216 and 54 um
    assert d.geometry.width_m / 16 == pytest.approx(JUNCTION_WIDTH_M)
    assert d.geometry.width_m / 64 == pytest.approx(JUNCTION_WIDTH_M / 4)
    assert 11_000 < cell_particles(d) < 14_000
    q = resolve_config(quick=True)
    assert q.geometry.width_m == 144e-6 and q.geometry.roughness_first_mode == 1
    assert cell_particles(q) < cell_particles(d) / 20
    q16 = resolve_config({"geometry": {"roughness_first_mode": 16}}, quick=True)
    assert q16.geometry.roughness_first_mode == 1  # the preset's auto, not the file's 16
    for modes, first in ((2, 1), (4, 1), (6, 2), (64, 16)):
        g = resolve_config({"geometry": {"roughness_modes": modes}}).geometry
        assert g.roughness_first_mode == first, modes
    assert resolve_config({"geometry": {"roughness_first_mode": 1}}).geometry \
        .roughness_first_mode == 1
    assert BrakingConfig.model_validate(d.model_dump()) == d


def test_steady_state_rule() -> None:
    from tribodem.braking.steady import STEADY_CUTS, steady_state

    s = np.linspace(0.0, 3e-4, 31)
    h = np.where(s < 1e-4, 0.2 * s, 2e-5 + 0.05 * (s - 1e-4))  # fast run-in, then steady
    st = steady_state(s, h)
    assert st["steady"] and st["rate"] == pytest.approx(0.05)
    assert st["run_in_distance"] == pytest.approx(1e-4) and st["run_in_depth"] == \
        pytest.approx(2e-5)
    h2 = np.where(s < 2e-4, 0.05 * s, 1e-5 + 0.1 * (s - 2e-4))  # last third twice as fast
    assert not steady_state(s, h2)["steady"]
    assert not steady_state(s, np.zeros_like(s))["steady"]  # no wear: no steady rate
    # a single pass by luck: run-in at 10 um/mm to 1 mm, then 2 um/mm; at 3 mm the thirds
    # (1-2, 2-3 mm) agree, cut to 90 % (2.7 mm) the middle third still holds run-in (2.9
    # against 2 um/mm): the test alone passes, with the cuts it does not
    s3 = np.linspace(0.0, 3e-3, 301)
    h3 = np.where(s3 < 1e-3, 0.01 * s3, 1e-5 + 0.002 * (s3 - 1e-3))
    assert steady_state(s3, h3)["steady"]
    assert not steady_state(s3, h3, cuts=STEADY_CUTS)["steady"]
    # slid on at 2 um/mm to 4.2 mm: cut to 3.78 and 3.36 mm the thirds start past the
    # run-in too: steady, at 2 um/mm
    s4 = np.linspace(0.0, 4.2e-3, 421)
    h4 = np.where(s4 < 1e-3, 0.01 * s4, 1e-5 + 0.002 * (s4 - 1e-3))
    st = steady_state(s4, h4, cuts=STEADY_CUTS)
    assert st["steady"] and st["rate"] == pytest.approx(0.002)


def test_until_steady_with_a_load_ramp_resumes_bitwise(tmp_path: Path,
                                                       monkeypatch: pytest.MonkeyPatch
                                                       ) -> None:
    """A run that slides past its duration (never steady at a 1e-9 tolerance, so up to its
    distance cap) under a load ramp and a sliding-speed ramp, interrupted inside both ramps
    after its first extension
    and resumed: bitwise the uninterrupted run; the summary reports the steady-state and
    contact fields."""
    import tribodem.braking.loop as loop_mod
    import tribodem.braking.summary as summary_mod
    from tribodem.braking.checkpoint import read_checkpoint

    change = {"duration_s": 0.5e-6, "samples": 10, "vtk_snapshots": 0, "until_steady": True,
              "steady_tolerance": 1e-9, "max_distance_m": 47.12 * 0.8e-6, "ramp_s": 0.75e-6,
              "speed_ramp_s": 0.7e-6}
    full = run_braking(_tiny(change), tmp_path / "a")
    assert full["simulated_sliding_distance_m"] == pytest.approx(47.12 * 0.8e-6, rel=0.02)
    assert full["steady_reached"] is False and 0 <= full["contact_fraction"] <= 1
    # the assumptions say what that outcome means for the rates
    notes = full["assumptions"]
    assert any(a.startswith("steady-state rule not passed") for a in notes)
    assert any(a.startswith("interface in contact") for a in notes) == (
        full["contact_fraction"] < summary_mod.CLOSED_CONTACT)
    for k in ("wear_rate_steady_m_per_m", "run_in_distance_m", "run_in_depth_m",
              "interface_load_ratio_mean", "sliding_distance_cap_m"):
        assert k in full
    real = loop_mod.measure
    calls = [0]

    def interrupted(*a: object, **k: object) -> dict:
        calls[0] += 1
        if calls[0] == 14:
            raise KeyboardInterrupt
        return real(*a, **k)

    monkeypatch.setattr(loop_mod, "measure", interrupted)
    with pytest.raises(KeyboardInterrupt):
        run_braking(_tiny(change), tmp_path / "b")
    monkeypatch.setattr(loop_mod, "measure", real)
    rec = read_checkpoint(tmp_path / "b" / "checkpoint.npz")
    assert rec["min_steps"] < rec["done"] < rec["cap_steps"] and not rec["finished"]
    res = run_braking(_tiny(change), tmp_path / "b", resume=True)
    for k, v in full.items():
        if not k.startswith("wall_time"):
            assert repr(res[k]) == repr(v), k
    assert (tmp_path / "a" / "timeseries.csv").read_bytes() == \
        (tmp_path / "b" / "timeseries.csv").read_bytes()


def test_braking_example_configs_resolve() -> None:
    from tribodem.braking.config import resolve_config, setup_from_config

    root = Path(__file__).resolve().parents[1] / "examples"
    for name in ("braking_steady.toml", "braking_wide.toml", "braking_outlet.toml",
                 "braking_feed.toml"):
        s = setup_from_config(resolve_config(root / name, condition=5))
        assert s.until_steady and s.max_distance_m > 0, name
    assert setup_from_config(resolve_config(root / "braking_feed.toml", condition=5)).feed
    assert setup_from_config(resolve_config(root / "braking_outlet.toml", condition=5)
                             ).outlet_length_m == pytest.approx(216e-6)
    # a fixed sliding distance: each condition slides 12 mm at its own speed (table 4)
    for cond, speed in ((5, 47.12), (3, 31.41)):
        s = setup_from_config(resolve_config(root / "braking_saturated.toml", condition=cond))
        assert s.duration_s * s.speed_m_s == pytest.approx(12e-3, rel=1e-12)
        assert s.speed_m_s == pytest.approx(speed, rel=1e-3)
    # --quick overrides the file's distance (the quick preset's own duration)
    q = setup_from_config(resolve_config(root / "braking_saturated.toml", condition=5, quick=True))
    assert q.duration_s == pytest.approx(20e-6)


def test_comparison_says_whether_time_or_distance_was_fixed() -> None:
    """A sweep at a fixed time says so (the seed's way); one at a fixed distance
    (``[run] distance_m``, so the times differ with the speed) says that instead."""
    from tribodem.braking.compare import length_text

    same_t = {1: {"simulated_time_s": 4e-5, "simulated_sliding_distance_m": 1.885e-3},
              3: {"simulated_time_s": 4e-5, "simulated_sliding_distance_m": 1.256e-3}}
    assert "same braking time" in length_text(same_t, 4e-5)
    same_d = {1: {"simulated_time_s": 2.55e-4, "simulated_sliding_distance_m": 12e-3},
              3: {"simulated_time_s": 3.82e-4, "simulated_sliding_distance_m": 12e-3}}
    text = length_text(same_d, 2.55e-4)
    assert "12 mm" in text and "same sliding distance" in text and "255-382 us" in text


def test_fixed_distance_run_through_the_installed_command(tmp_path: Path) -> None:
    """``[run] distance_m``: the installed command slides that distance at the condition's
    speed (condition 3: 31.41 m/s), the resolved config keeps it, and the run resumes."""
    from conftest import run_tribodem

    cfg = tmp_path / "d.toml"
    cfg.write_text("[geometry]\nwidth_m = 144e-6\ndisc_height_m = 50e-6\npad_height_m = 108e-6\n"
                   "roughness_amplitude_m = 6e-6\nroughness_modes = 3\n"
                   "[run]\ndistance_m = 0.2e-3\nsamples = 20\nvtk_snapshots = 0\n"
                   "figures = false\n")
    out = tmp_path / "run"
    r = run_tribodem("braking", "run", "--condition", "3", "--config", str(cfg), "--out",
                     str(out), "--no-progress")
    assert r.returncode == 0, r.stderr[-800:]
    s = json.loads((out / "summary.json").read_text())
    assert s["simulated_sliding_distance_m"] == pytest.approx(0.2e-3, rel=2e-3)
    assert s["simulated_time_s"] == pytest.approx(0.2e-3 / s["sliding_speed_m_s"], rel=2e-3)
    assert "distance_m = 0.0002" in (out / "config.toml").read_text()
    r = run_tribodem("braking", "run", "--out", str(out), "--resume", "--no-progress")
    assert r.returncode == 0 and "already finished" in r.stderr, r.stderr[-800:]
    # a body worn through: exit 3, the body, the field to change, outputs kept
    cfg.write_text(cfg.read_text() + "worn_through_diameters = 100\n")
    r = run_tribodem("braking", "run", "--condition", "3", "--config", str(cfg), "--out",
                     str(out), "--no-progress")
    assert r.returncode == 3 and "disc was worn through" in r.stderr, r.stderr[-800:]
    assert "disc_height_m" in r.stderr and "Traceback" not in r.stderr
    assert json.loads((out / "summary.json").read_text())["status"] == "worn_through"


def test_contact_after_run_in_counts_the_loaded_samples_past_the_first_third() -> None:
    """``contact_after_run_in`` on a made-up series of 31 samples over 3 mm: the pad
    applied at sample 3 (the first load, 3 us), open again at samples 12-14 and 20; past
    the run-in (a third of the distance, 1 mm) lie samples 11..30 (20), 16 of them loaded;
    a series never loaded has no first contact and a fraction of 0."""
    from tribodem.braking.summary import contact_after_run_in

    rows = []
    for k in range(31):
        loaded = k >= 3 and k not in (12, 13, 14, 20)
        rows.append({"time_s": 1e-6 * k, "sliding_distance_m": 1e-4 * k,
                     "interface_force_N": 5.0 if loaded else 0.0})
    out = contact_after_run_in(rows)
    assert out["first_contact_time_s"] == pytest.approx(3e-6)
    assert out["contact_fraction_after_run_in_samples"] == 20
    assert out["contact_fraction_after_run_in"] == pytest.approx(16 / 20)
    none = contact_after_run_in([{**r, "interface_force_N": 0.0} for r in rows])
    assert none["first_contact_time_s"] is None and none["contact_fraction_after_run_in"] == 0
    assert contact_after_run_in(rows[:1])["contact_fraction_after_run_in"] is None
