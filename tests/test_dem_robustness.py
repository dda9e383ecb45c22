"""Time-step refusal, bitwise checkpoint/resume, and stopping on numerical instability."""

from __future__ import annotations

import re

import numpy as np
import pytest

from tribodem.dem import (
    Box,
    Material,
    ParticleState,
    PlaneWall,
    Simulation,
    SimulationUnstable,
    TimeStepError,
)
from tribodem.dem.recorders import ScalarRecorder, VTKRecorder, default_probes


def pile(dt: float | None = None, force_dt: bool = False, law: str = "linear",
         seed: int = 3) -> Simulation:
    """300 disks/spheres falling into a box with friction and rolling resistance."""
    rng = np.random.default_rng(seed)
    n = 300
    r = rng.uniform(0.8e-3, 1.0e-3, n)
    pos = np.stack([(np.arange(n) % 15) * 2e-3 + 1e-3, (np.arange(n) // 15 % 5) * 2e-3 + 1e-3,
                    (np.arange(n) // 75) * 2e-3 + 1e-3], 1)
    mat = Material(young=1e8, poisson=0.3, density=2500, friction=0.5, rolling_friction=0.02,
                   cor=0.5, law=law, beta_n=0.2, kratio=1.5)
    walls = [PlaneWall([0, 0, 0], [0, 0, 1], name="floor"),
             PlaneWall([0, 0, 0], [1, 0, 0], name="left"),
             PlaneWall([30e-3, 0, 0], [-1, 0, 0], name="right")]
    p = ParticleState(dim=3, pos=pos, radius=r, density=2500,
                      vel=rng.normal(0, 0.05, (n, 3)))
    return Simulation(p, [mat], Box([0, 0, 0], [30e-3, 10e-3, 0.1], [False, True, False]),
                      walls=walls, gravity=(0, 0, -9.81), dt=dt, force_dt=force_dt)


def test_time_step_above_critical_is_refused() -> None:
    ref = pile()
    with pytest.raises(TimeStepError) as err:
        pile(dt=1.5 * ref.dt_critical)
    msg = str(err.value)
    assert "pair (" in msg and "critical time step" in msg, msg
    crit = float(re.search(r"critical time step ([0-9.eE+-]+) s", msg).group(1))
    assert abs(crit - ref.dt_critical) / ref.dt_critical < 1e-5
    pile(dt=0.99 * ref.dt_critical)  # accepted


def test_checkpoint_resume_is_bitwise_identical(tmp_path) -> None:
    straight = pile()
    straight.step(1500)
    first = pile()
    first.step(700)
    first.save_checkpoint(tmp_path / "ck.npz")
    resumed = pile()  # same setup, fresh state
    resumed.load_checkpoint(tmp_path / "ck.npz")
    resumed.step(800)
    assert straight.nl.builds > 2  # rebuilds happened on both sides of the checkpoint
    for name in ("pos", "vel", "omega"):
        assert np.array_equal(getattr(straight.p, name), getattr(resumed.p, name)), name
    assert np.array_equal(straight.hist, resumed.hist)
    assert np.array_equal(straight.wall_hist, resumed.wall_hist)
    assert straight.time == resumed.time and straight.step_count == resumed.step_count


def test_instability_stops_and_keeps_outputs(tmp_path) -> None:
    ref = pile()
    sim = pile(dt=8 * ref.dt_critical, force_dt=True)
    rec = ScalarRecorder(tmp_path / "series.csv", default_probes(sim), flush_every=1000)
    sim.add_recorder(rec, every=10)
    sim.add_recorder(VTKRecorder(tmp_path / "vtk"), every=50)
    with pytest.raises(SimulationUnstable) as err:
        sim.step(20_000)
    msg = str(err.value)
    assert "step" in msg and ("overlap" in msg or "non-finite" in msg)
    data = np.genfromtxt(tmp_path / "series.csv", delimiter=",", names=True)
    assert data.size >= 2 and data["step"][-1] <= sim.step_count
    assert any((tmp_path / "vtk").glob("particles_*.vtu"))
    assert (tmp_path / "vtk" / "particles.pvd").exists()


def test_same_result_on_one_and_two_threads() -> None:
    """Pair forces per pair, particle sums per fixed block: thread count changes nothing."""
    import numba

    from tribodem.dem.bench import simulation_from_case
    from tribodem.dem.bench_cases import settle3d_case
    from tribodem.dem.jit import PARALLEL_MIN

    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("needs 2 threads")
    finals = []
    before = numba.get_num_threads()
    try:
        for threads in (1, 2):
            numba.set_num_threads(threads)
            sim = simulation_from_case(settle3d_case(n=PARALLEL_MIN + 1000, steps=300))
            sim.step(300)
            finals.append((sim.p.pos.copy(), sim.p.vel.copy(), sim.walls[0].normal_force))
    finally:
        numba.set_num_threads(before)
    assert np.array_equal(finals[0][0], finals[1][0])
    assert np.array_equal(finals[0][1], finals[1][1])
    assert finals[0][2] == finals[1][2] and finals[0][2] > 0


def test_blocked_pair_sums_do_not_depend_on_the_cut() -> None:
    """The threaded pair pass (cross pairs, then blocks) gives the serial Newton kernel's
    sums bitwise for any cut into blocks: equal pair work, one block, empty blocks, random
    cuts (each particle adds its pairs in increasing pair index)."""
    from tribodem.dem.bench import simulation_from_case
    from tribodem.dem.bench_cases import settle3d_case
    from tribodem.dem.contact import (
        pair_block_bounds,
        pair_cross_list,
        pair_forces_blocked,
        pair_forces_cross,
        pair_forces_sum,
    )

    sim = simulation_from_case(settle3d_case(n=3000, steps=400))
    sim.step(400)  # a bed with contacts, some of them just ended
    p, nl = sim.p, sim.nl
    state = (sim.hist, sim.pinfo, sim.fpair, sim.tpair_i, sim.tpair_j)

    def common():
        hist, pinfo, fpair, ti, tj = (a.copy() for a in state)
        return hist, pinfo, fpair, ti, tj, np.zeros_like(p.pos), np.zeros_like(p.pos)

    hist, pinfo, fpair, ti, tj, force, torque = common()
    pair_forces_sum.serial(p.pos, p.vel, p.omega, p.radius, p.mass, p.inertia, p.mat,
                           nl.pair_i, nl.pair_j, hist, sim.pairtab, sim.elin, sim.box_length,
                           sim.box.periodic, p.dim, p.thickness, sim.dt, fpair, ti, tj, pinfo,
                           force, torque, None)
    assert np.count_nonzero(pinfo[:, 0] > 0) > 200
    balanced = np.zeros(5, dtype=np.int64)
    pair_block_bounds(nl.start, sim.pinfo, 4, balanced)
    rng = np.random.default_rng(3)
    cuts = [balanced, np.array([0, p.n]), np.array([0, 0, 1000, 1000, p.n, p.n]),
            np.concatenate([[0], np.sort(rng.integers(0, p.n, 9)), [p.n]])]
    for bounds in cuts:
        h2, pi2, f2, ti2, tj2, force2, torque2 = common()
        cross = np.zeros(nl.n_pairs, dtype=np.int64)
        ncross = pair_cross_list(nl.pair_i, nl.pair_j, bounds, cross)
        assert ncross == np.count_nonzero(np.searchsorted(bounds, nl.pair_i, "right")
                                          != np.searchsorted(bounds, nl.pair_j, "right"))
        pair_forces_cross.parallel(p.pos, p.vel, p.omega, p.radius, p.mass, p.inertia, p.mat,
                                   nl.pair_i, nl.pair_j, h2, sim.pairtab, sim.elin,
                                   sim.box_length, sim.box.periodic, p.dim, p.thickness,
                                   sim.dt, f2, ti2, tj2, pi2, cross, ncross)
        pair_forces_blocked.parallel(p.pos, p.vel, p.omega, p.radius, p.mass, p.inertia,
                                     p.mat, nl.start, nl.pair_i, nl.pair_j, nl.rev_start,
                                     nl.rev_pair, h2, sim.pairtab, sim.elin, sim.box_length,
                                     sim.box.periodic, p.dim, p.thickness, sim.dt, f2, ti2,
                                     tj2, pi2, force2, torque2, bounds)
        assert np.array_equal(force2, force), bounds
        assert np.array_equal(torque2, torque), bounds
        assert np.array_equal(h2, hist) and np.array_equal(pi2, pinfo)
        assert np.array_equal(f2, fpair)
    assert 0 < balanced[1] < balanced[2] < balanced[3] < p.n
