"""The engine's compiled multi-step loop (``engine._run_steps``) gives bitwise the results
of the Python step loop: particles, contacts, walls (servo and boundary drives), bonds and
their break log, and the braking cell's own compiled pieces (pad backing, braking loop)."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from tribodem.braking.drive import SlidingDrive
from tribodem.braking.model import Geometry, build_interface, start_sliding
from tribodem.dem import Box, Material, ParticleState, PlaneWall, Simulation, SimulationUnstable
from tribodem.dem.bonds import install_bonds_by_gap
from tribodem.dem.compiled import np_sum

R = 1.0e-3


class _Probe:
    """A recorder: the step counts it sampled at (the compiled loop stops there)."""

    def __init__(self) -> None:
        self.steps: list[int] = []

    def sample(self, sim: Simulation) -> None:
        self.steps.append(sim.step_count)

    def close(self) -> None:
        pass


def bed(dim: int) -> Simulation:
    """A bonded, compressed bed with friction and rolling friction: periodic in x, a fixed
    floor, a PFC servo lid and (3D) a boundary-moving side wall; bonds weak enough to
    break."""
    rng = np.random.default_rng(5)
    nx, ny, nz = (10, 8, 1) if dim == 2 else (6, 5, 4)
    g = np.meshgrid(*(np.arange(k) * 1.98 * R for k in (nx, ny, nz)), indexing="ij")
    pos = np.c_[g[0].ravel() + R, g[1].ravel() + R, g[2].ravel() + (R if dim == 3 else 0)]
    m = pos.shape[0]
    pos += rng.uniform(-0.05, 0.05, (m, 3)) * R
    vel = rng.normal(0, 0.05, (m, 3))
    omega = rng.normal(0, 50.0, (m, 3))
    p = ParticleState(dim=dim, pos=pos, radius=rng.uniform(0.99, 1.04, m) * R,
                      density=2500.0, thickness=2 * R, vel=vel, omega=omega)
    mat = Material(law="hertz" if dim == 3 else "linear", young=1e9, poisson=0.3,
                   density=2500.0, friction=0.3, rolling_friction=0.05, cor=0.6, beta_n=0.2,
                   beta_s=0.1)
    top = ny * 1.98 * R + 0.5 * R
    walls = [PlaneWall([0, 0, 0], [0, 1, 0], name="floor"),
             PlaneWall([0, top, 0], [0, -1, 0], mode="servo", target_force=2.0,
                       max_speed=0.5, name="lid")]
    if dim == 3:
        walls.append(PlaneWall([0, 0, 0], [0, 0, 1], mode="boundary", target_force=1.0,
                               servo_mass=1e-3, servo_damping=0.1, name="side"))
    hi = 0.0 if dim == 2 else 0.05
    box = Box([0, -0.01, -hi], [nx * 1.98 * R, 0.05, hi], [True, False, False])
    sim = Simulation(p, [mat], box, walls=walls, gravity=(0, -9.81e3, 0))
    install_bonds_by_gap(sim, 0.2 * R, 0.8, 1e9, 2.0, 2e5, 4e5)
    return sim


def state(sim: Simulation) -> dict[str, Any]:
    """Everything a step changes."""
    b = sim.interactions[0]
    out = {k: getattr(sim.p, k).copy() for k in ("pos", "vel", "omega")}
    out.update(hist=sim.hist.copy(), pinfo=sim.pinfo.copy(), force=sim.force.copy(),
               wall_hist=sim.wall_hist.copy(), fn=b.fn.copy(), fs=b.fs.copy(),
               mb=b.mb.copy(), mode=b.mode.copy(), log=list(b.log), time=sim.time,
               steps=sim.step_count, builds=sim.nl.builds)
    for k, w in enumerate(sim.walls):
        out[f"wall{k}"] = (w.point.tolist(), w.velocity.tolist(), w.force.tolist(),
                           w.normal_force, w.stiffness, w.contacts)
    return out


def assert_same(a: dict[str, Any], b: dict[str, Any]) -> None:
    for k, v in a.items():
        if isinstance(v, np.ndarray):
            assert np.array_equal(v, b[k]), k
        else:
            assert v == b[k], k


@pytest.mark.parametrize("dim", [2, 3])
def test_compiled_loop_equals_the_python_loop(dim: int) -> None:
    runs = []
    for fast in (True, False):
        sim = bed(dim)
        sim.compiled_loop = fast
        probe = _Probe()
        sim.add_recorder(probe, 37)
        assert (sim._compiled_states() is not None) == fast
        sim.step(150)
        sim.step(1)
        sim.step(149)
        runs.append((state(sim), probe.steps))
    (a, sa), (b, sb) = runs
    assert sa == sb == [0, *range(37, 301, 37)]
    assert a["log"] and a["builds"] > 1  # bonds broke, the neighbour list was rebuilt
    assert a["wall1"][3] != 0.0  # the servo lid carries load
    assert_same(a, b)


def test_a_piece_without_compiled_form_keeps_the_python_loop() -> None:
    class Push:
        def compute(self, sim: Simulation) -> None:
            sim.ext_force[:, 0] += 1e-6

    sim = bed(2)
    assert sim._compiled_states() is not None
    sim.add_interaction(Push())
    assert sim._compiled_states() is None
    x0 = sim.p.pos[:, 0].mean()
    sim.step(5)
    assert sim.p.pos[:, 0].mean() != x0


def test_np_sum_is_numpys_sum() -> None:
    rng = np.random.default_rng(0)
    for n in (0, 1, 7, 8, 9, 127, 128, 129, 255, 300, 1000, 4097):
        a = rng.standard_normal(n + 2) * 10.0 ** rng.uniform(-6, 6, n + 2)
        assert np_sum(a, n) == float(np.sum(a[:n]))


def test_braking_pieces_compiled_equal_python() -> None:
    """The pad backing and the braking loop's accumulators in the compiled loop."""
    geo = Geometry(width=100e-6, disc_height=36e-6, pad_height=36e-6, amplitude=4e-6,
                   modes=2, seed=3, clearance=0.0)
    out = []
    for fast in (True, False):
        it = build_interface(geo, 20e6)  # a high load: contact within 2,000 steps
        start_sliding(it, 47.0)
        loop = SlidingDrive(it, 0, 0, 47.0)
        it.sim.add_interaction(loop)
        it.sim.compiled_loop = fast
        assert (it.sim._compiled_states() is not None) == fast
        it.sim.step(1200)
        it.sim.step(800)
        out.append((it.sim.p.pos.copy(), it.sim.p.vel.copy(), loop.total, loop.n,
                    loop.distance, loop.contact.copy(), it.backing.reaction,
                    it.wall.target_force, it.wall.point.tolist(), it.bonds.broken_count()))
    a, b = out
    assert a[5][1] > 0 and a[-1] > 0  # the bodies touched, bonds broke
    for x, y in zip(a, b, strict=True):
        assert np.array_equal(x, y)


def test_instability_stops_at_the_same_step_with_the_same_message() -> None:
    """The compiled loop's stability test (``_unstable``) stops where ``check_stability``
    raises in the Python loop, and Python raises the same error there."""
    msgs = []
    for fast in (True, False):
        sim = bed(2)
        sim.dt *= 30.0  # far above the critical step: overlaps run away
        sim.compiled_loop = fast
        with pytest.raises(SimulationUnstable) as err:
            sim.step(5000)
        msgs.append((str(err.value), sim.step_count))
    assert msgs[0] == msgs[1]
    assert msgs[0][1] % 100 == 0 and "step" in msgs[0][0]
