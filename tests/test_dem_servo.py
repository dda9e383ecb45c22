"""Servo walls hold a target force on a bed of >= 1000 particles (Lu (2018) eqs 3.2-3.6)."""

from __future__ import annotations

import numpy as np
import pytest

from tribodem.dem import Box, Material, ParticleState, PlaneWall, Simulation
from tribodem.dem.recorders import ScalarRecorder, default_probes

TARGET = 100.0  # N


def bed(mode: str, n_side: int = 10, seed: int = 0) -> Simulation:
    """n_side^3 spheres between a fixed bottom plate and a servo top plate, periodic in x, y."""
    rng = np.random.default_rng(seed)
    r, s = 1e-3, 2.05e-3
    idx = np.arange(n_side**3)
    pos = np.stack([idx % n_side, (idx // n_side) % n_side, idx // n_side**2], 1) * s + s / 2
    radius = rng.uniform(0.9, 1.0, idx.size) * r
    L = n_side * s
    mat = Material(young=1e8, poisson=0.3, density=2500, friction=0.5, cor=0.5)
    p = ParticleState(dim=3, pos=pos, radius=radius, density=2500)
    top = PlaneWall([0, 0, L], [0, 0, -1], mode=mode, target_force=TARGET,
                    servo_mass=float(p.mass.sum()), max_speed=0.05, name="top")
    bottom = PlaneWall([0, 0, 0], [0, 0, 1], name="bottom")
    return Simulation(p, [mat], Box([0, 0, 0], [L, L, L], [True, True, False]),
                      walls=[bottom, top], local_damping=0.7)


@pytest.mark.parametrize("mode", ["boundary", "servo"])
def test_servo_settles_to_target(mode: str, tmp_path) -> None:
    sim = bed(mode)
    assert sim.p.n >= 1000
    rec = ScalarRecorder(tmp_path / "servo.csv", default_probes(sim))
    sim.add_recorder(rec, every=100)
    top, bottom = sim.walls[1], sim.walls[0]
    for _ in range(40):
        sim.step(500)
        if abs(top.normal_force - TARGET) / TARGET < 1e-7 and abs(top.velocity[2]) < 1e-9:
            break
    rec.close()
    assert abs(top.normal_force - TARGET) / TARGET < 1e-5, top.normal_force
    # static equilibrium: the bottom plate carries the same load
    assert abs(bottom.normal_force - TARGET) / TARGET < 1e-5, bottom.normal_force
    hist = np.genfromtxt(tmp_path / "servo.csv", delimiter=",", names=True)
    forces = hist["top_normal_force_N"]
    assert forces[0] == 0.0 and abs(forces[-1] - TARGET) / TARGET < 1e-5
    assert len(forces) > 10
