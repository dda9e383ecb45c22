"""Linear parallel bond: elastic response and breakage at the closed-form loads (Sha et al. (2022)
eq 11, Potyondy & Cundall 2004), 2D disks and 3D spheres driven by prescribed motion."""

from __future__ import annotations

import numpy as np
import pytest

from tribodem.dem import Box, Material, ParticleState, Simulation
from tribodem.dem.bonds import (
    ParallelBonds,
    bond_consts_2d,
    bond_consts_3d,
    bond_csr,
    bond_forces,
    bond_forces_2d,
    bond_forces_2d_lanes,
    bond_forces_3d,
    bond_screen,
    gather_bonds,
    install_bonds_by_gap,
)
from tribodem.dem.state import FIX_ROTATION, FIX_TRANSLATION

R = 1.0e-3  # particle radius (m)
GAP = 1.0e-5  # surface gap between the bonded particles (m): no contact force
E_BOND = 1.0e9  # Pa
KRATIO = 1.75  # Sha et al. (2022) table 3
SIGMA_T = 1.0e6  # tensile strength (Pa)
COH = 1.5e6  # cohesion (Pa)
LAM = 0.8  # bond radius multiplier
DT = 1.0e-6


def pair(dim: int, tensile: float = SIGMA_T, cohesion: float = COH
         ) -> tuple[Simulation, ParallelBonds]:
    """Two bonded particles along x, all DOFs prescribed (velocities set by the test)."""
    p = ParticleState(dim=dim, pos=[[0, 0, 0], [2 * R + GAP, 0, 0]], radius=R,
                      density=2500.0, thickness=2 * R, fixed=FIX_TRANSLATION | FIX_ROTATION)
    mat = Material(law="linear", young=E_BOND, density=2500.0)
    hi = 0.0 if dim == 2 else 0.1
    sim = Simulation(p, [mat], Box([-0.1, -0.1, -hi], [0.1, 0.1, hi]), dt=DT, force_dt=True)
    bonds = install_bonds_by_gap(sim, 2 * GAP, LAM, E_BOND, KRATIO, tensile, cohesion)
    assert bonds.n_bonds == 1
    return sim, bonds


def run_to_break(sim: Simulation, bonds: ParallelBonds, measure, max_steps: int = 20_000
                 ) -> float:
    """Step until the bond breaks; returns the largest ``measure(bonds)`` while intact."""
    best = 0.0
    for _ in range(max_steps):
        sim.step(1)
        if not bonds.intact[0]:
            return best
        best = max(best, measure(bonds))
    raise AssertionError("the bond did not break")


def geometry(dim: int) -> tuple[float, float, float]:
    rb = LAM * R
    if dim == 2:
        t = 2 * R
        return 2 * rb * t, 2 / 3 * t * rb**3, 0.0
    return np.pi * rb**2, np.pi * rb**4 / 4, np.pi * rb**4 / 2


@pytest.mark.parametrize("dim", [2, 3])
def test_tension_breaks_at_sigma_t_times_area(dim: int) -> None:
    sim, bonds = pair(dim)
    area, _, _ = geometry(dim)
    x0 = sim.p.pos.copy()
    v = 1.0e-3  # 1 nm per step; the break needs ~1600 steps
    sim.p.vel[0, 0], sim.p.vel[1, 0] = -v / 2, v / 2
    fmax = run_to_break(sim, bonds, lambda b: -b.fn[0])  # tension = -Fn
    expect = SIGMA_T * area
    assert abs(fmax - expect) / expect < 0.005, (fmax, expect)
    rec = bonds.log[0]
    assert rec.mode == "tensile" and (rec.i, rec.j) == (0, 1)
    assert rec.sigma >= SIGMA_T and abs(-rec.fn - expect) / expect < 0.005
    assert abs(rec.position[0] - (R + GAP / 2 + sim.p.pos[1, 0] - x0[1, 0])) < 2 * R
    assert bonds.broken_count() == 1 and bonds.broken_count("tensile") == 1
    assert bonds.broken_count("shear") == 0
    # move back to the initial gap: a broken bond carries nothing (no contact either)
    n_back = sim.step_count
    sim.p.vel[0, 0], sim.p.vel[1, 0] = v / 2, -v / 2
    for _ in range(n_back):
        sim.step(1)
        assert not sim.ext_force.any() and not sim.ext_torque.any()
        assert not sim.force.any()
    assert np.allclose(sim.p.pos, x0, atol=1e-12)
    assert bonds.broken_count() == 1 and len(bonds.log) == 1


@pytest.mark.parametrize("dim", [2, 3])
def test_shear_breaks_at_cohesion_times_area(dim: int) -> None:
    sim, bonds = pair(dim)
    area, _, _ = geometry(dim)
    sim.p.vel[1, 1] = 1.0e-3  # tangential relative motion of j
    fmax = run_to_break(sim, bonds, lambda b: float(np.linalg.norm(b.fs[0])))
    expect = COH * area
    assert abs(fmax - expect) / expect < 0.005, (fmax, expect)
    assert bonds.log[0].mode == "shear" and bonds.broken_count("shear") == 1
    # the sheared bond's normal stress stayed far below the tensile strength
    assert bonds.log[0].sigma < 0.01 * SIGMA_T


@pytest.mark.parametrize("dim", [2, 3])
def test_bending_breaks_at_sigma_t_i_over_rb(dim: int) -> None:
    sim, bonds = pair(dim)
    _, inertia, _ = geometry(dim)
    w = 1.0  # rad/s opposite spins, no translation (equal radii: no contact-point slip)
    axis = 2 if dim == 2 else 1
    sim.p.omega[0, axis], sim.p.omega[1, axis] = -w, w
    mmax = run_to_break(sim, bonds, lambda b: float(np.linalg.norm(b.mb[0])))
    expect = SIGMA_T * inertia / (LAM * R)
    assert abs(mmax - expect) / expect < 0.01, (mmax, expect)
    rec = bonds.log[0]
    assert rec.mode == "tensile" and abs(rec.fn) < 1e-9 * expect / R and rec.fs < 1e-12
    sim.step(10)
    assert not sim.ext_torque.any() and not sim.ext_force.any()


def test_twist_breaks_at_cohesion_j_over_rb_3d() -> None:
    sim, bonds = pair(3)
    _, _, polar = geometry(3)
    w = 1.0
    sim.p.omega[0, 0], sim.p.omega[1, 0] = -w, w  # opposite spins about the bond axis
    mmax = run_to_break(sim, bonds, lambda b: abs(float(b.mt[0])))
    expect = COH * polar / (LAM * R)
    assert abs(mmax - expect) / expect < 0.01, (mmax, expect)
    assert bonds.log[0].mode == "shear"


@pytest.mark.parametrize("dim", [2, 3])
def test_elastic_response_is_exact(dim: int) -> None:
    """Small displacements: Fn = kn A delta, Fs = ks A delta_s, Mb = kn I theta."""
    area, inertia, _ = geometry(dim)
    kn = E_BOND / (2 * R)
    ks = kn / KRATIO
    steps = 100
    sim, bonds = pair(dim)
    sim.p.vel[1, 0] = 1.0e-4  # delta = 1e-8 m
    sim.step(steps)
    delta = 1.0e-4 * DT * steps
    assert abs(-bonds.fn[0] - kn * area * delta) / (kn * area * delta) < 1e-9
    f = sim.ext_force
    assert np.allclose(f[1], [-kn * area * delta, 0, 0], rtol=1e-9, atol=0)
    assert np.array_equal(f[0], -f[1])
    sim, bonds = pair(dim)
    sim.p.vel[1, 1] = 1.0e-4
    sim.step(steps)
    fs = float(np.linalg.norm(bonds.fs[0]))
    assert abs(fs - ks * area * delta) / (ks * area * delta) < 1e-6
    # moment balance about the origin (force on j at x_j, moments included)
    tot = np.cross(sim.p.pos, sim.ext_force).sum(axis=0) + sim.ext_torque.sum(axis=0)
    assert np.allclose(tot, 0.0, atol=1e-12 * fs * R)
    sim, bonds = pair(dim)
    axis = 2 if dim == 2 else 1
    sim.p.omega[1, axis] = 1.0e-2
    sim.step(steps)
    theta = 1.0e-2 * DT * steps
    mb = float(np.linalg.norm(bonds.mb[0]))
    assert abs(mb - kn * inertia * theta) / (kn * inertia * theta) < 1e-9


def chain(n: int = 6) -> tuple[Simulation, ParallelBonds]:
    """A free bonded chain of disks pulled at both ends (checkpoint/threads checks)."""
    x = np.arange(n) * (2 * R + GAP)
    fixed = np.zeros(n, dtype=np.uint8)
    fixed[[0, -1]] = FIX_TRANSLATION
    p = ParticleState(dim=2, pos=np.c_[x, np.zeros(n), np.zeros(n)], radius=R,
                      density=2500.0, thickness=2 * R, fixed=fixed)
    p.vel[0, 0], p.vel[-1, 0] = -0.1, 0.1
    p.vel[1:-1, 1] = 1e-3 * np.sin(np.arange(n - 2))  # some shear too
    mat = Material(law="linear", young=E_BOND, density=2500.0)
    sim = Simulation(p, [mat], Box([-0.1, -0.1, 0], [0.1, 0.1, 0]), dt=DT / 4,
                     force_dt=True, local_damping=0.3)
    strength = SIGMA_T * (1 + 0.05 * np.arange(n - 1))
    bonds = install_bonds_by_gap(sim, 2 * GAP, LAM, E_BOND, KRATIO, strength, COH)
    assert sim.dt < 0.3 * bonds.critical_step(sim)
    return sim, bonds


def test_checkpoint_restores_bonds_and_log(tmp_path) -> None:
    straight, sb = chain()
    straight.step(500)
    assert 0 < sb.broken_count() < sb.n_bonds
    first, fb = chain()
    first.step(150)
    assert fb.broken_count() == 0  # one checkpoint before the breaks, one after
    first.save_checkpoint(tmp_path / "ck1.npz")
    first.step(150)
    assert fb.broken_count() == sb.broken_count()
    first.save_checkpoint(tmp_path / "ck2.npz")
    for name, steps in (("ck1.npz", 350), ("ck2.npz", 200)):
        resumed, rb = chain()
        resumed.load_checkpoint(tmp_path / name)
        if name == "ck2.npz":
            assert rb.log == fb.log and rb.broken_count() == fb.broken_count()
        resumed.step(steps)
        for arr in ("pos", "vel", "omega"):
            assert np.array_equal(getattr(straight.p, arr), getattr(resumed.p, arr)), arr
        assert np.array_equal(sb.fn, rb.fn) and np.array_equal(sb.fs, rb.fs)
        assert sb.log == rb.log


def test_appended_particles_and_bonds_leave_the_others_bitwise() -> None:
    """``Simulation.append_particles`` + ``ParallelBonds.extend`` between steps: two held
    particles appended far from the chain and bonded to each other leave the chain's run
    bitwise as without them (indices, bond lists and the rebuilt neighbour list keep
    every existing particle's order), and their bond starts at zero force and stays there
    (no relative motion). An interaction that does not declare ``particles_appended``
    refuses the growth."""
    straight, sb = chain()
    straight.step(500)
    grown, gb = chain()
    grown.step(150)
    x = 0.05 + np.array([0.0, 2 * R + GAP])
    idx = grown.append_particles(np.c_[x, np.zeros(2), np.zeros(2)], np.full(2, R),
                                 np.full(2, 2500.0), np.zeros((2, 3)), np.zeros(2),
                                 np.full(2, 7), np.full(2, FIX_TRANSLATION))
    new = gb.extend(ParallelBonds(grown, idx[:1], idx[1:], LAM, E_BOND, KRATIO, SIGMA_T, COH))
    assert list(idx) == [6, 7] and list(new) == [5] and grown.p.group[7] == 7
    grown.step(350)
    for arr in ("pos", "vel", "omega"):
        assert np.array_equal(getattr(straight.p, arr), getattr(grown.p, arr)[:6]), arr
    assert np.array_equal(sb.fn, gb.fn[:5]) and np.array_equal(sb.mode, gb.mode[:5])
    assert gb.fn[5] == 0.0 and gb.intact[5] and sb.log == gb.log

    class NoHook:
        def compute(self, sim: Simulation) -> None:
            pass

    grown.add_interaction(NoHook())
    with pytest.raises(ValueError, match="NoHook"):
        grown.append_particles(np.zeros((1, 3)), [R], [2500.0], np.zeros((1, 3)), [0], [0],
                               [0])


def test_threaded_and_serial_kernels_agree_bitwise() -> None:
    """The serial pass sums each bond into its particles (Newton pairs); the threaded one
    stores the bonds and ``gather_bonds`` adds them in bond order: the same bits."""
    rng = np.random.default_rng(3)
    n, nb = 3000, 5000
    pos = rng.uniform(0, 0.1, (n, 3))
    vel = rng.normal(0, 1e-3, (n, 3))
    omega = rng.normal(0, 1e-1, (n, 3))
    radius = np.full(n, R)
    i = rng.integers(0, n // 2, nb)
    j = rng.integers(n // 2, n, nb)
    d = pos[j] - pos[i]
    nrm = d / np.linalg.norm(d, axis=1)[:, None]
    one = np.ones(nb)
    gstart, gbond = bond_csr(i, j, n, by_bond=True)
    outs = []
    for build, summed in ((bond_forces.serial, True), (bond_forces.parallel, False)):
        arrays = [np.zeros(nb), np.full((nb, 3), 1e-3), np.zeros((nb, 3)), np.zeros(nb),
                  nrm.copy(), np.zeros(nb, np.int8), np.zeros(nb, np.int8),
                  np.zeros((nb, 9)), np.zeros((nb, 3)), np.zeros((nb, 3)), np.zeros((nb, 3))]
        ext = [np.full((n, 3), 0.25), np.full((n, 3), -0.5)]  # summed onto what is there
        nnew = build(pos, vel, omega, radius, i, j, R * one, 1e-6 * one, 1e-13 * one,
                     2e-13 * one, 5e11 * one, 3e11 * one, 2e3 * one, 3e3 * one, 0.1 * one,
                     *arrays, 3, 1e-4, np.zeros(3), np.zeros(3, dtype=np.bool_), summed,
                     *ext)
        if not summed:
            gather_bonds.parallel(gstart, gbond, i, arrays[5], *arrays[8:], *ext)
        outs.append((nnew, arrays[:8] + ext))
    assert 0 < outs[0][0] == outs[1][0] < nb
    for a, b in zip(outs[0][1], outs[1][1], strict=True):
        assert np.array_equal(a, b)
    assert np.any(outs[0][1][-2] != 0.25)


def test_3d_batch_kernel_matches_the_general_one() -> None:
    """Spheres: ``bond_forces_3d`` (batches, SIMD lanes, screened strength test) gives
    ``bond_forces``'s bits on serial summed and threaded stored passes, over several
    steps with breaks in both modes, bonds broken before, a periodic axis, turned
    normals and a few spins beyond the series (the general kernel's fallback)."""
    rng = np.random.default_rng(11)
    n, nb = 3000, 5000
    pos = rng.uniform(0, 0.1, (n, 3))
    vel = rng.normal(0, 1e-3, (n, 3))
    omega = rng.normal(0, 1e-1, (n, 3))
    omega[:20] = rng.normal(0, 1e2, (20, 3))  # |omega| dt ~ 1e-2 > WS_SERIES
    radius = rng.uniform(0.8, 1.2, n) * R
    i = rng.integers(0, n // 2, nb)
    j = rng.integers(n // 2, n, nb)
    d = pos[j] - pos[i]
    d[:, 0] -= 0.1 * np.rint(d[:, 0] / 0.1)
    nrm = d / np.linalg.norm(d, axis=1)[:, None] + rng.normal(0, 1e-3, (nb, 3))
    nrm /= np.linalg.norm(nrm, axis=1)[:, None]
    one = np.ones(nb)
    rb, area, ib, jb = R * one, 1e-6 * one, 1e-13 * one, 2e-13 * one
    kn, ks, tens, coh, tanphi = 5e11 * one, 3e11 * one, 2e3 * one, 3e3 * one, 0.1 * one
    kc = bond_consts_3d(rb, area, ib, jb, kn, ks, tens, coh, tanphi)
    length, periodic = np.array([0.1, 0.0, 0.0]), np.array([True, False, False])
    gstart, gbond = bond_csr(i, j, n, by_bond=True)
    mode0 = np.zeros(nb, np.int8)
    mode0[::97] = 1
    fs0 = rng.normal(0, 1e-4, (nb, 3))
    mb0 = rng.normal(0, 1e-9, (nb, 3))
    for summed in (True, False):
        outs = []
        for fast in (False, True):
            arrays = [np.zeros(nb), fs0.copy(), mb0.copy(), np.zeros(nb), nrm.copy(),
                      mode0.copy(), np.zeros(nb, np.int8), np.zeros((nb, 9)),
                      np.zeros((nb, 3)), np.zeros((nb, 3)), np.zeros((nb, 3))]
            ext = [np.full((n, 3), 0.25), np.full((n, 3), -0.5)]
            nnew = 0
            for _ in range(3):
                if fast:
                    build = bond_forces_3d.serial if summed else bond_forces_3d.parallel
                    nnew += build(pos, vel, omega, radius, i, j, rb, area, ib, jb, kn, ks,
                                  tens, coh, tanphi, *arrays, 1e-4, length, periodic, summed,
                                  *ext, kc)
                else:
                    build = bond_forces.serial if summed else bond_forces.parallel
                    nnew += build(pos, vel, omega, radius, i, j, rb, area, ib, jb, kn, ks,
                                  tens, coh, tanphi, *arrays, 3, 1e-4, length, periodic,
                                  summed, *ext)
                if not summed:
                    gather_bonds.parallel(gstart, gbond, i, arrays[5], *arrays[8:], *ext)
            outs.append((nnew, arrays, ext))
        (n1, a1, e1), (n2, a2, e2) = outs
        modes = a1[5]
        assert 0 < n1 == n2 < nb
        assert np.any(modes == 1) and np.any(modes == 2)
        for x, y in zip(a1 + e1, a2 + e2, strict=True):
            assert np.array_equal(x, y)
            assert np.array_equal(np.signbit(x), np.signbit(y))


def _disk_bonds(rng: np.random.Generator, n: int, nb: int, box: float) -> tuple:
    """``n`` random disks in a ``box`` (m) square moving and spinning, ``nb`` random bonds
    (i in the first half, j in the second) and their unit normals: (pos, vel, omega,
    radius, i, j, normal)."""
    pos = np.c_[rng.uniform(0, box, (n, 2)), np.zeros(n)]
    vel = np.c_[rng.normal(0, 1e-3, (n, 2)), np.zeros(n)]
    omega = np.c_[np.zeros((n, 2)), rng.normal(0, 1e-1, n)]
    radius = rng.uniform(0.8, 1.2, n) * R
    i = rng.integers(0, n // 2, nb)
    j = rng.integers(n // 2, n, nb)
    d = pos[j] - pos[i]
    return pos, vel, omega, radius, i, j, d / np.linalg.norm(d, axis=1)[:, None]


def test_2d_kernel_matches_the_general_one() -> None:
    """Disks: ``bond_forces_2d`` gives the general kernel's values (== equality, so only
    the sign of zeros may differ) on serial summed and threaded stored passes, over
    several steps with breaks."""
    rng = np.random.default_rng(5)
    n, nb = 2000, 4500
    pos, vel, omega, radius, i, j, nrm = _disk_bonds(rng, n, nb, 0.1)
    nrm[:, :2] += rng.normal(0, 1e-3, (nb, 2))  # the normal turned since the last step
    one = np.ones(nb)
    length, periodic = np.array([0.1, 0.0, 0.0]), np.array([True, False, False])
    gstart, gbond = bond_csr(i, j, n, by_bond=True)
    fs = np.c_[rng.normal(0, 1e-3, (nb, 2)), np.zeros(nb)]
    mb = np.c_[np.zeros((nb, 2)), rng.normal(0, 1e-9, nb)]
    for summed in (True, False):
        outs = []
        for two in (False, True):
            arrays = [np.zeros(nb), fs.copy(), mb.copy(), np.zeros(nb), nrm.copy(),
                      np.zeros(nb, np.int8), np.zeros(nb, np.int8), np.zeros((nb, 9)),
                      np.zeros((nb, 3)), np.zeros((nb, 3)), np.zeros((nb, 3))]
            ext = [np.zeros((n, 3)), np.zeros((n, 3))]
            props = (R * one, 1e-6 * one, 1e-13 * one, 5e11 * one, 3e11 * one,
                     2e3 * one, 3e3 * one, 0.1 * one)
            nnew = 0
            for _ in range(3):
                for e in ext:
                    e[:] = 0.0
                if two:
                    build = bond_forces_2d.serial if summed else bond_forces_2d.parallel
                    nnew += build(pos, vel, omega, radius, i, j, *props, arrays[0], arrays[1],
                                  arrays[2], *arrays[4:], 1e-4, length, periodic, summed,
                                  *ext)
                else:
                    build = bond_forces.serial if summed else bond_forces.parallel
                    nnew += build(pos, vel, omega, radius, i, j, *props[:3], 2e-13 * one,
                                  *props[3:], *arrays, 2, 1e-4, length, periodic, summed,
                                  *ext)
                if not summed:
                    gather_bonds.parallel(gstart, gbond, i, arrays[5], *arrays[8:], *ext)
            outs.append((nnew, arrays, ext))
        (n1, a1, e1), (n2, a2, e2) = outs
        assert 0 < n1 == n2 < nb
        for x, y in zip(a1 + e1, a2 + e2, strict=True):
            assert np.array_equal(x, y)


def test_2d_screen_gives_the_same_bits() -> None:
    """``bond_forces_2d`` with its strength screen (reciprocals first, the divisions only
    near a limit) decides every bond as without it: the same arrays, the same breaks."""
    rng = np.random.default_rng(8)
    n, nb = 600, 1500
    pos, vel, omega, radius, i, j, nrm = _disk_bonds(rng, n, nb, 0.05)
    one = np.ones(nb)
    rb, area, ib = R * rng.uniform(0.5, 1.0, nb), 1e-6 * one, 1e-13 * rng.uniform(1, 2, nb)
    screen = bond_screen(area, rb, ib)
    outs = []
    for scr in (None, screen):
        fs = np.zeros((nb, 3))
        fs[:, :2] = 1e-3
        arrays = [np.zeros(nb), fs, np.zeros((nb, 3)), nrm.copy(), np.zeros(nb, np.int8),
                  np.zeros(nb, np.int8), np.zeros((nb, 9)), np.zeros((nb, 3)),
                  np.zeros((nb, 3)), np.zeros((nb, 3))]
        ext = [np.zeros((n, 3)), np.zeros((n, 3))]
        nnew = 0
        for _ in range(4):
            extra = () if scr is None else (scr,)
            nnew += bond_forces_2d.serial(pos, vel, omega, radius, i, j, rb, area, ib,
                                          5e11 * one, 3e11 * one, 2e3 * one, 3e3 * one,
                                          0.1 * one, *arrays, 1e-4, np.array([0.05, 0, 0]),
                                          np.array([True, False, False]), True, *ext, *extra)
        outs.append((nnew, arrays + ext))
    (n1, a1), (n2, a2) = outs
    assert 0 < n1 == n2 < nb
    for x, y in zip(a1, a2, strict=True):
        assert np.array_equal(x, y)



def test_2d_batch_kernel_matches_the_scalar_one() -> None:
    """Disks: ``bond_forces_2d_lanes`` (batches, SIMD lanes) gives ``bond_forces_2d``'s
    bits (with its screen) on serial summed and threaded stored passes, over several steps
    with breaks in both modes, bonds broken before, a periodic axis, turned and nearly
    reversed normals, a partial last batch (nb not a multiple of the batch width) and
    varied bond sizes; signs of zeros included."""
    rng = np.random.default_rng(21)
    n, nb = 2000, 4501
    pos, vel, omega, radius, i, j, nrm = _disk_bonds(rng, n, nb, 0.1)
    nrm[:, :2] += rng.normal(0, 1e-3, (nb, 2))
    nrm[::301, :2] *= -1.0  # c ~ -1: the rotation's other branch
    nrm /= np.linalg.norm(nrm, axis=1)[:, None]
    one = np.ones(nb)
    rb, area, ib = R * rng.uniform(0.5, 1.0, nb), 1e-6 * one, 1e-13 * rng.uniform(1, 2, nb)
    kn, ks, tens, coh, tanphi = 5e11 * one, 3e11 * one, 2e3 * one, 3e3 * one, 0.1 * one
    screen = bond_screen(area, rb, ib)
    kc = bond_consts_2d(rb, area, ib, kn, ks, tens, coh, tanphi)
    length, periodic = np.array([0.1, 0.0, 0.0]), np.array([True, False, False])
    gstart, gbond = bond_csr(i, j, n, by_bond=True)
    mode0 = np.zeros(nb, np.int8)
    mode0[::97] = 2
    fs0 = np.c_[rng.normal(0, 1e-3, (nb, 2)), np.zeros(nb)]
    mb0 = np.c_[np.zeros((nb, 2)), rng.normal(0, 1e-9, nb)]
    for summed in (True, False):
        outs = []
        for lanes in (False, True):
            arrays = [np.zeros(nb), fs0.copy(), mb0.copy(), nrm.copy(), mode0.copy(),
                      np.zeros(nb, np.int8), np.zeros((nb, 9)), np.zeros((nb, 3)),
                      np.zeros((nb, 3)), np.zeros((nb, 3))]
            ext = [np.full((n, 3), 0.25), np.full((n, 3), -0.5)]
            nnew = 0
            for _ in range(3):
                if lanes:
                    k = bond_forces_2d_lanes.serial if summed else bond_forces_2d_lanes.parallel
                    nnew += k(pos, vel, omega, radius, i, j, rb, area, ib, tens, coh, tanphi,
                              *arrays, 1e-4, length, periodic, summed, *ext, kc)
                else:
                    k = bond_forces_2d.serial if summed else bond_forces_2d.parallel
                    nnew += k(pos, vel, omega, radius, i, j, rb, area, ib, kn, ks, tens, coh,
                              tanphi, *arrays, 1e-4, length, periodic, summed, *ext, screen)
                if not summed:
                    gather_bonds.parallel(gstart, gbond, i, arrays[4], *arrays[7:], *ext)
            outs.append((nnew, arrays, ext))
        (n1, a1, e1), (n2, a2, e2) = outs
        modes = a1[4]
        assert 0 < n1 == n2 < nb
        assert np.any((modes == 1) & (mode0 == 0)) and np.any((modes == 2) & (mode0 == 0))
        for x, y in zip(a1 + e1, a2 + e2, strict=True):
            assert np.array_equal(x, y)
            assert np.array_equal(np.signbit(x), np.signbit(y))


def test_bad_input_is_refused() -> None:
    sim, _ = pair(2)
    with pytest.raises(ValueError, match="tensile_strength = -1.0"):
        install_bonds_by_gap(sim, 2 * GAP, LAM, E_BOND, KRATIO, -1.0, COH)
    with pytest.raises(ValueError, match="gap = -1"):
        install_bonds_by_gap(sim, -1, LAM, E_BOND, KRATIO, SIGMA_T, COH)
    with pytest.raises(ValueError, match="friction_angle = 90.0"):
        install_bonds_by_gap(sim, 2 * GAP, LAM, E_BOND, KRATIO, SIGMA_T, COH, 90.0)
    with pytest.raises(ValueError, match="lambda_ = 0"):
        ParallelBonds(sim, [0], [1], 0, E_BOND, KRATIO, SIGMA_T, COH)
    with pytest.raises(ValueError, match="itself"):
        ParallelBonds(sim, [1], [1], LAM, E_BOND, KRATIO, SIGMA_T, COH)
    _, bonds = pair(2)
    with pytest.raises(ValueError, match="mode = 'bend'"):
        bonds.broken_count("bend")


def test_groups_and_gap_select_pairs() -> None:
    n = 4
    x = np.arange(n) * (2 * R + GAP)
    p = ParticleState(dim=2, pos=np.c_[x, np.zeros(n), np.zeros(n)], radius=R,
                      density=2500.0, group=[1, 1, 2, 2])
    sim = Simulation(p, [Material(law="linear")], Box([-0.1, -0.1, 0], [0.1, 0.1, 0]))
    assert install_bonds_by_gap(sim, 0.5 * GAP, LAM, E_BOND, KRATIO, 1, 1).n_bonds == 0
    assert install_bonds_by_gap(sim, 2 * GAP, LAM, E_BOND, KRATIO, 1, 1).n_bonds == 3
    b = install_bonds_by_gap(sim, 2 * GAP, LAM, E_BOND, KRATIO, 1, 1, groups=[2])
    assert b.n_bonds == 1 and (b.i[0], b.j[0]) == (2, 3)


def test_bond_stiffness_limits_the_time_step() -> None:
    """Bonds lower the critical step: an automatic dt follows, a user dt above is refused."""
    from tribodem.dem import Box, Material, ParticleState, Simulation, TimeStepError
    from tribodem.dem.bonds import install_bonds_by_gap

    def pair(dt: float | None) -> Simulation:
        p = ParticleState(dim=2, pos=[[0, 0, 0], [2.01e-3, 0, 0]], radius=1e-3, density=7850)
        mat = Material(young=1e6, law="linear", kratio=1.5)
        return Simulation(p, [mat], Box([-1, -1, 0], [1, 1, 0]), dt=dt)

    auto = pair(None)
    soft_crit = auto.dt_critical
    bonds = install_bonds_by_gap(auto, gap=2e-5, lambda_=1.0, E_bond=1e11, kratio=1.5,
                                 tensile_strength=1e9, cohesion=1e9)
    assert auto.dt_critical == bonds.critical_step(auto) < soft_crit
    assert "ParallelBonds" in auto.dt_limit_by
    assert auto.dt <= 0.2 * auto.dt_critical * (1 + 1e-12)
    user = pair(0.5 * soft_crit)
    with pytest.raises(TimeStepError):
        install_bonds_by_gap(user, gap=2e-5, lambda_=1.0, E_bond=1e11, kratio=1.5,
                             tensile_strength=1e9, cohesion=1e9)
