"""Rigid triangle-mesh surfaces: Hertz force equal to a plane wall's on faces, shared edges
and vertices (one contact, no double counting), tilted faces, binned lookup = brute force,
servo (boundary-moving) mode, checkpoints."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tribodem.dem import Box, Material, ParticleState, PlaneWall, Simulation
from tribodem.dem.trimesh import TriangleSurface, closest_point_on_triangle
from tribodem.io.stl import heightmap_to_triangles

STEEL = Material(name="steel", young=2.1e11, poisson=0.3, density=7850.0, cor=0.72,
                 friction=0.6, rolling_friction=0.001)
R = 1e-3
DELTA = 2e-6


def flat_mesh(n: int = 6, h: float = 1e-3, z: float = 0.0) -> np.ndarray:
    x = (np.arange(n + 1) - n / 2) * h
    return heightmap_to_triangles(x, x, np.full((n + 1, n + 1), z))


def one_sphere(xy: tuple[float, float], inter: object | None, wall: bool) -> Simulation:
    p = ParticleState(dim=3, pos=[[xy[0], xy[1], R - DELTA]], radius=R, density=7850.0,
                      vel=[[0.01, -0.02, -0.03]], omega=[[3.0, 1.0, -2.0]])
    walls = [PlaneWall([0, 0, 0], [0, 0, 1], name="floor")] if wall else []
    sim = Simulation(p, [STEEL], Box([-1, -1, -1], [1, 1, 1]), walls=walls)
    if inter is not None:
        sim.add_interaction(inter)
    return sim


# inside a face, on the diagonal, on a grid line (shared edge), on a grid vertex
SPOTS = [(0.3e-3, 0.1e-3), (0.25e-3, 0.25e-3), (0.5e-3, 0.2e-3), (0.0, 0.0), (1e-3, -1e-3)]


@pytest.mark.parametrize("xy", SPOTS)
def test_flat_mesh_gives_plane_wall_force(xy: tuple[float, float]) -> None:
    ref = one_sphere(xy, None, wall=True)
    surf = TriangleSurface(triangles=flat_mesh(), name="mesh")
    sim = one_sphere(xy, surf, wall=False)
    for _ in range(3):
        ref.step(1)
        sim.step(1)
        fw = ref.walls[0].force
        assert surf.contacts == 1
        assert np.abs(surf.force - fw).max() <= 1e-9 * np.abs(fw).max()
        assert np.abs(sim.p.vel - ref.p.vel).max() <= 1e-9 * np.abs(ref.p.vel).max()
        assert np.abs(sim.p.omega - ref.p.omega).max() <= 1e-9 * np.abs(ref.p.omega).max()
    # and the plane's Hertz force for the overlap at the first step
    hertz = 4 / 3 * STEEL.young / (2 * (1 - 0.09)) * math.sqrt(R) * DELTA**1.5
    assert 0.5 * hertz < -ref.walls[0].force[2] < 1.5 * hertz


def test_static_flat_mesh_force_is_hertz() -> None:
    surf = TriangleSurface(triangles=flat_mesh(), name="mesh")
    p = ParticleState(dim=3, pos=[[0.5e-3, 0.5e-3, R - DELTA]], radius=R, density=7850.0)
    sim = Simulation(p, [STEEL], Box([-1, -1, -1], [1, 1, 1]))
    sim.add_interaction(surf)
    sim.step(1)
    estar = STEEL.young / (2 * (1 - STEEL.poisson**2))
    hertz = 4 / 3 * estar * math.sqrt(R) * DELTA**1.5
    assert abs(-surf.force[2] / hertz - 1) < 1e-12
    assert np.abs(surf.force[:2]).max() == 0.0
    assert surf.normal_force == pytest.approx(hertz, rel=1e-12)


@pytest.mark.parametrize("angle", [20.0, 55.0])
def test_tilted_mesh_pushes_along_face_normal(angle: float) -> None:
    a = math.radians(angle)
    rot = np.array([[math.cos(a), 0, math.sin(a)], [0, 1, 0], [-math.sin(a), 0, math.cos(a)]])
    tri = flat_mesh() @ rot.T
    nrm = rot @ np.array([0.0, 0, 1])
    foot = rot @ np.array([0.3e-3, 0.1e-3, 0])
    p = ParticleState(dim=3, pos=[foot + (R - DELTA) * nrm], radius=R, density=7850.0)
    surf = TriangleSurface(triangles=tri)
    sim = Simulation(p, [STEEL], Box([-1, -1, -1], [1, 1, 1]))
    sim.add_interaction(surf)
    sim.step(1)
    estar = STEEL.young / (2 * (1 - STEEL.poisson**2))
    hertz = 4 / 3 * estar * math.sqrt(R) * DELTA**1.5
    assert np.abs(surf.force + hertz * nrm).max() < 1e-12 * hertz


def test_convex_ridge_edge_and_backside() -> None:
    """A sphere above a roof ridge touches the ridge line radially (one contact); a sphere
    behind the mesh gets nothing."""
    x = np.array([-1e-3, 0.0, 1e-3])
    z = np.array([[0.0, 0.0], [0.3e-3, 0.3e-3], [0.0, 0.0]])
    tri = heightmap_to_triangles(x, np.array([-1e-3, 1e-3]), z)
    p = ParticleState(dim=3, pos=[[0.0, 0.0, 0.3e-3 + R - DELTA], [0.0, 0.0, -2 * R]],
                      radius=R, density=7850.0)
    surf = TriangleSurface(triangles=tri)
    sim = Simulation(p, [STEEL], Box([-1, -1, -1], [1, 1, 1]))
    sim.add_interaction(surf)
    sim.step(1)
    estar = STEEL.young / (2 * (1 - STEEL.poisson**2))
    hertz = 4 / 3 * estar * math.sqrt(R) * DELTA**1.5
    assert surf.contacts == 1
    assert abs(-surf.force[2] / hertz - 1) < 1e-12
    assert np.abs(surf.particle_force[1]).max() == 0.0


def brute_force_overlap(tri: np.ndarray, nrm: np.ndarray, pos: np.ndarray,
                        r: np.ndarray) -> np.ndarray:
    """Deepest overlap of each particle over all triangles (the documented rule)."""
    out = np.zeros(len(pos))
    for i, x in enumerate(pos):
        best = 0.0
        for t, nn in zip(tri, nrm, strict=True):
            cx, cy, cz, region = closest_point_on_triangle(x[0], x[1], x[2], t)
            v = x - np.array([cx, cy, cz])
            if region == 0:
                if v @ nn <= -r[i]:
                    continue
                ov = r[i] - v @ nn
            else:
                if v @ nn < 0:
                    continue
                ov = r[i] - np.linalg.norm(v)
            best = max(best, ov)
        out[i] = best
    return out


def test_binned_lookup_matches_brute_force() -> None:
    rng = np.random.default_rng(7)
    h = 0.2e-3
    x = np.arange(21) * h
    z = 0.3e-3 * np.sin(x[:, None] / 0.7e-3) * np.cos(x[None, :] / 0.9e-3)
    z += rng.normal(0, 0.02e-3, z.shape)
    surf = TriangleSurface(triangles=heightmap_to_triangles(x, x, z))
    n = 300
    pos = np.column_stack([rng.uniform(-0.2e-3, 4.2e-3, (n, 2)), rng.uniform(-0.4e-3, 0.5e-3, n)])
    radius = rng.uniform(0.05e-3, 0.15e-3, n)
    p = ParticleState(dim=3, pos=pos, radius=radius, density=7850.0)
    sim = Simulation(p, [STEEL], Box([-1, -1, -1], [1, 1, 1]), dt=1e-9, force_dt=True)
    sim.add_interaction(surf)
    sim.ext_force[:] = 0.0
    surf.compute(sim)
    ref = brute_force_overlap(surf.triangles, surf.tri_normals, pos, radius)
    got = np.where(surf._touch[:, 0] > 0, surf._touch[:, 0], 0.0)
    assert (ref > 0).sum() > 50  # many contacts tested
    assert np.abs(got - ref).max() < 1e-15
    assert surf._grid[3].size > 1  # several cells


def test_boundary_servo_mesh_reaches_target_force() -> None:
    target = 0.5  # N
    p = ParticleState(dim=3, pos=[[0.0, 0.0, R]], radius=R, density=7850.0)
    top = TriangleSurface(triangles=flat_mesh(z=2 * R + 1e-6), flip=True, normal=[0, 0, -1],
                          mode="boundary", target_force=target, servo_mass=float(p.mass[0]),
                          servo_damping=2.0, max_speed=0.05, name="top")
    floor = PlaneWall([0, 0, 0], [0, 0, 1], name="floor")
    sim = Simulation(p, [STEEL], Box([-1, -1, -1], [1, 1, 1]), walls=[floor], local_damping=0.7)
    sim.add_interaction(top)
    for _ in range(60):
        sim.step(500)
        if abs(top.normal_force / target - 1) < 1e-9 and abs(top.velocity[2]) < 1e-12:
            break
    assert abs(top.normal_force / target - 1) < 1e-6
    assert abs(floor.normal_force / target - 1) < 1e-6


def test_path_motion_and_checkpoint(tmp_path) -> None:
    def stroke(t: float) -> np.ndarray:
        return np.array([1e-4 * math.sin(2e4 * t), 0.0, 0.0])

    def build() -> tuple[Simulation, TriangleSurface]:
        p = ParticleState(dim=3, pos=[[0.0, 0.0, R - 1e-8]], radius=R, density=7850.0)
        s = TriangleSurface(triangles=flat_mesh(), path=stroke)
        sim = Simulation(p, [STEEL], Box([-1, -1, -1], [1, 1, 1]), gravity=(0, 0, -9.81))
        sim.add_interaction(s)
        return sim, s

    sim, s = build()
    drag = 0.0
    for _ in range(200):
        sim.step(1)
        drag = max(drag, abs(s.force[0]))
    assert s.point[0] == stroke(sim.time - sim.dt)[0]  # the displacement of the last step
    ck = sim.save_checkpoint(tmp_path / "m.npz")
    sim.step(200)
    sim2, s2 = build()
    sim2.load_checkpoint(ck)
    sim2.step(200)
    assert np.array_equal(sim2.p.pos, sim.p.pos)
    assert np.array_equal(s2.force, s.force)
    assert drag > 0  # the moving surface drags the sphere
