"""Rigid height-map surfaces: Hertz force of a plane wall, normals, servo load on a bed."""

from __future__ import annotations

import numpy as np
import pytest

from tribodem.dem import Box, Material, ParticleState, PlaneWall, Simulation
from tribodem.dem.surfaces import HeightMapSurface

R = 1e-3
MAT = Material(young=2e11, poisson=0.3, density=7800, friction=0.5, cor=0.7)


def _one(pos, walls=(), surfaces=()) -> Simulation:
    p = ParticleState(dim=3, pos=np.array([pos]), radius=R, density=7800)
    sim = Simulation(p, [MAT], Box([-0.1] * 3, [0.1] * 3, [False] * 3), walls=list(walls),
                     dt=1e-9)
    for s in surfaces:
        sim.add_interaction(s)
    return sim


def _grid(fn, n=21, half=5e-3):
    c = np.linspace(-half, half, n)
    x, y = np.meshgrid(c, c, indexing="ij")
    return fn(x, y), float(c[0]), float(c[1] - c[0])


def test_flat_map_equals_plane_wall_hertz() -> None:
    delta = 2e-6
    h, x0, d = _grid(lambda x, y: 0 * x)
    s = HeightMapSurface(point=[0, 0, 0], normal=[0, 0, 1], heights=h, x0=x0, y0=x0, dx=d,
                         dy=d, side="below")
    a = _one([3.3e-4, -1.7e-4, R - delta], surfaces=[s])
    a.step(1)
    b = _one([3.3e-4, -1.7e-4, R - delta], walls=[PlaneWall([0, 0, 0], [0, 0, 1])])
    b.step(1)
    estar = 1 / (2 * (1 - 0.3**2) / 2e11)
    hertz = 4 / 3 * estar * np.sqrt(R) * delta**1.5
    assert s.normal_force == pytest.approx(hertz, rel=1e-9)
    assert s.normal_force == pytest.approx(b.walls[0].normal_force, rel=1e-12)
    np.testing.assert_allclose(a.p.vel, b.p.vel, rtol=1e-12, atol=0)


def test_tilted_map_pushes_along_its_normal_and_upper_side() -> None:
    slope = 0.2
    h, x0, d = _grid(lambda x, y: slope * x)
    nrm = np.array([-slope, 0, 1]) / np.hypot(slope, 1)
    delta = 1e-6
    centre = np.array([1e-3, 0, slope * 1e-3]) + (R - delta) * nrm
    s = HeightMapSurface(point=[0, 0, 0], normal=[0, 0, 1], heights=h, x0=x0, y0=x0, dx=d,
                         dy=d, side="below")
    sim = _one(centre, surfaces=[s])
    sim.step(1)
    f = -s.force  # force on the particle
    np.testing.assert_allclose(f / np.linalg.norm(f), nrm, atol=1e-9)
    # the same plane as an upper body (particle below, surface shifted up by the servo point)
    up = HeightMapSurface(point=[0, 0, 0], normal=[0, 0, -1], heights=h, x0=x0, y0=x0, dx=d,
                          dy=d, side="above")
    below = np.array([1e-3, 0, slope * 1e-3]) - (R - delta) * nrm
    sim2 = _one(below, surfaces=[up])
    sim2.step(1)
    np.testing.assert_allclose(up.force, -s.force, rtol=1e-9)
    assert up.contacts == 1 and up.normal_force > 0


def test_outside_the_grid_no_contact() -> None:
    h, x0, d = _grid(lambda x, y: 0 * x)
    s = HeightMapSurface(point=[0, 0, 0], normal=[0, 0, 1], heights=h, x0=x0, y0=x0, dx=d,
                         dy=d)
    sim = _one([0.02, 0, 0.5 * R], surfaces=[s])
    sim.step(1)
    assert s.contacts == 0 and s.normal_force == 0.0


def test_boundary_servo_surface_loads_a_layer_to_target() -> None:
    """A curved upper map (sphere R 20 mm) servo-loads a layer of spheres on a flat map."""
    rng = np.random.default_rng(3)
    n_side, r = 12, 1e-4
    g = (np.arange(n_side) - n_side / 2 + 0.5) * 2.2 * r
    x, y = np.meshgrid(g, g, indexing="ij")
    pos = np.stack([x.ravel(), y.ravel(), np.full(x.size, r)], 1)
    radius = r * rng.uniform(0.97, 1.0, x.size)
    p = ParticleState(dim=3, pos=pos, radius=radius, density=7800)
    lo_h, x0, d = _grid(lambda x, y: 0 * x, n=41, half=2e-3)
    up_h, _, _ = _grid(lambda x, y: (x**2 + y**2) / (2 * 0.02), n=41, half=2e-3)
    target = 5.0
    lower = HeightMapSurface(point=[0, 0, 0], normal=[0, 0, 1], heights=lo_h, x0=x0, y0=x0,
                             dx=d, dy=d, side="below", name="lower")
    upper = HeightMapSurface(point=[0, 0, 2 * r + 1e-7], normal=[0, 0, -1], heights=up_h,
                             x0=x0, y0=x0, dx=d, dy=d, side="above", mode="boundary",
                             target_force=target, servo_mass=float(p.mass.sum()),
                             max_speed=0.05, name="upper")
    sim = Simulation(p, [MAT], Box([-3e-3] * 3, [3e-3] * 3, [False] * 3), local_damping=0.7)
    sim.add_interaction(lower)
    sim.add_interaction(upper)
    for _ in range(60):
        upper.servo_damping = 2 * np.sqrt(upper.servo_mass * max(upper.stiffness, 1.0))
        sim.step(500)
        if abs(upper.normal_force - target) < 1e-6 * target and abs(upper.velocity[2]) < 1e-9:
            break
    assert abs(upper.normal_force - target) / target < 1e-4
    assert abs(lower.normal_force - target) / target < 1e-4
    assert upper.contacts >= 1
