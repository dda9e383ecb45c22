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
