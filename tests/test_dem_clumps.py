"""Rigid clumps: union volumes, torque-free rotation, rigidity, free fall, resting weight,
checkpoints and periodic wrap (Lu (2018) figure 3.6 debris shapes)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tribodem.dem import Box, Material, PlaneWall, Simulation
from tribodem.dem.clumps import (
    DEBRIS_SHAPES,
    debris_template,
    make_clumps,
    make_template,
    quat_to_matrix,
    random_quaternions,
    union_properties,
)

STEEL = Material(name="steel", young=2.1e11, poisson=0.3, density=7850.0, cor=0.72,
                 friction=0.6, rolling_friction=0.001)


def lens(d: float, r: float) -> float:
    """Volume of the intersection of two spheres of radius r at centre distance d."""
    return math.pi * (4 * r + d) * (2 * r - d) ** 2 / 12


def quat_between(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Unit quaternion rotating unit vector a onto unit vector b (not antiparallel)."""
    a = a / np.linalg.norm(a)
    b = b / np.linalg.norm(b)
    q = np.concatenate([[1.0 + a @ b], np.cross(a, b)])
    return q / np.linalg.norm(q)


def test_union_volume_exact_for_pairs_and_rows() -> None:
    for d in (0.2, 1.0, 1.9):
        v, cen, _ = union_properties(np.array([[0, 0, 0], [d, 0, 0]]), [1.0, 1.0])
        exact = 2 * 4 / 3 * math.pi - lens(d, 1.0)
        assert abs(v / exact - 1) < 1e-9
        assert abs(cen[0] - d / 2) < 1e-12
    # rubbing row: neighbours overlap, ends do not -> inclusion-exclusion is exact
    t = debris_template("rubbing", 1.0)
    r = float(t.radii[0])
    s = float(np.linalg.norm(t.offsets[1] - t.offsets[0]))
    assert 2 * s > 2 * r  # end spheres apart
    exact = 3 * 4 / 3 * math.pi * r**3 - 2 * lens(s, r)
    assert abs(t.volume / exact - 1) < 1e-9


@pytest.mark.parametrize("shape", DEBRIS_SHAPES)
def test_template_volume_is_sphere_of_diameter(shape: str) -> None:
    d = 0.6e-6
    t = debris_template(shape, d)
    target = math.pi * d**3 / 6
    assert abs(t.volume / target - 1) < 1e-3
    # independent check: midpoint voxel count of the union (0.1%)
    lo = (t.offsets - t.radii[:, None]).min(0)
    hi = (t.offsets + t.radii[:, None]).max(0)
    n = 160
    h = (hi - lo) / n
    ax = [lo[k] + (np.arange(n) + 0.5) * h[k] for k in range(3)]
    x, y = np.meshgrid(ax[0], ax[1], indexing="ij")
    count = 0
    for z in ax[2]:
        inside = np.zeros_like(x, dtype=bool)
        for c, r in zip(t.offsets, t.radii, strict=True):
            inside |= (x - c[0]) ** 2 + (y - c[1]) ** 2 + (z - c[2]) ** 2 < r * r
        count += int(inside.sum())
    assert abs(count * h.prod() / target - 1) < 1e-3
    assert shape != "spherical" or t.members == 1


def test_template_principal_frame() -> None:
    t = make_template(np.array([[0, 0, 0], [1.5, 0.2, 0], [0.1, 1.0, 0.4]]), [1.0, 0.8, 0.6])
    vol, cen, second = union_properties(t.offsets, t.radii)
    assert np.abs(cen).max() < 1e-12  # centre of mass at the origin
    tensor = np.trace(second) * np.eye(3) - second
    assert np.abs(tensor - np.diag(t.inertia_per_density)).max() < 1e-9 * tensor.max()
    assert abs(vol / t.volume - 1) < 1e-12


def asymmetric_spinner() -> tuple[Simulation, object]:
    t = make_template(np.array([[0, 0, 0], [1.2e-3, 0, 0], [0, 0.8e-3, 0.3e-3],
                                [-0.2e-3, 0.1e-3, 0.9e-3]]),
                      np.array([1e-3, 0.8e-3, 0.7e-3, 0.6e-3]), "asym")
    i1, i2, i3 = t.inertia_per_density
    assert i1 < 0.95 * i2 and i2 < 0.95 * i3  # truly asymmetric
    p, cl = make_clumps([t], [0], [[0, 0, 0]], quat=[[0.9, 0.1, 0.3, -0.2]],
                        omega=[[30.0, -50.0, 80.0]], vel=[[0.1, 0, 0]])
    sim = Simulation(p, [STEEL], Box([-1, -1, -1], [1, 1, 1]), dt=1e-5, force_dt=True)
    sim.add_interaction(cl)
    return sim, cl


def body_momentum_energy(cl, k: int = 0) -> tuple[np.ndarray, float]:  # noqa: ANN001
    rm = quat_to_matrix(cl.quat)[k]
    w = cl.omega[k]
    inertia = rm @ np.diag(cl.inertia[k]) @ rm.T
    return inertia @ w, 0.5 * w @ inertia @ w


def test_torque_free_asymmetric_clump_conserves_momentum_energy_and_shape() -> None:
    sim, cl = asymmetric_spinner()
    assert sim.nl.n_pairs == 0  # members of one clump never interact
    p = sim.p
    l0, e0 = body_momentum_energy(cl)
    d0 = np.linalg.norm(p.pos[:, None] - p.pos[None], axis=2)
    omega0 = cl.omega[0].copy()
    sim.step(20000)  # 2.6 turns about the fast axis, omega dt ~ 1e-3
    l1, e1 = body_momentum_energy(cl)
    d1 = np.linalg.norm(p.pos[:, None] - p.pos[None], axis=2)
    assert np.linalg.norm(l1 - l0) / np.linalg.norm(l0) < 1e-6
    assert abs(e1 / e0 - 1) < 1e-3
    assert np.abs(d1 - d0).max() < 1e-12 * d0.max()
    assert np.linalg.norm(cl.omega[0] - omega0) > 1.0  # the spin axis precesses
    # members carry the body motion
    assert np.abs(cl.member_positions() - p.pos).max() < 1e-15
    r = p.pos - cl.pos[0]
    assert np.abs(p.vel - (cl.vel[0] + np.cross(cl.omega[0], r))).max() < 1e-12
    assert np.abs(cl.pos[0, 0] - 0.1 * sim.time) < 1e-12


def test_dumbbell_free_falls_with_g() -> None:
    t = make_template(np.array([[0, 0, 0], [1.5e-3, 0, 0]]), [1e-3, 1e-3], "dumbbell")
    g = 9.81
    p, cl = make_clumps([t], [0], [[0, 0, 0]], quat=random_quaternions(1,
                        np.random.default_rng(0)))
    sim = Simulation(p, [STEEL], Box([-1, -1, -1], [1, 1, 1]), gravity=(0, 0, -g), dt=1e-5,
                     force_dt=True)
    sim.add_interaction(cl)
    sim.step(1000)
    t_ = sim.time
    assert math.isclose(cl.vel[0, 2], -g * t_, rel_tol=1e-12)
    assert np.allclose(p.vel[:, 2], -g * t_, rtol=1e-12, atol=0)
    assert math.isclose(cl.pos[0, 2], -0.5 * g * t_ * (t_ + sim.dt), rel_tol=1e-10)
    assert np.abs(cl.omega).max() == 0.0
    assert math.isclose(p.mass.sum(), cl.mass[0], rel_tol=1e-12)


def resting_clump(shape: str, seed: int = 0) -> tuple[Simulation, object]:
    t = debris_template(shape, 1e-3)
    if shape == "chunk":  # a face down: three members on the wall
        face = t.offsets[:3].mean(0) - t.offsets[3]
        q = quat_between(face, np.array([0.0, 0.0, -1.0]))
    else:
        q = np.array([1.0, 0, 0, 0])
    p, cl = make_clumps([t], [0], [[0, 0, 0]], quat=[q])
    low = float((p.pos[:, 2] - p.radius).min())
    p, cl = make_clumps([t], [0], [[0, 0, 2e-8 - low]], quat=[q])
    sim = Simulation(p, [STEEL], Box([-1e-2] * 3, [1e-2] * 3),
                     walls=[PlaneWall([0, 0, 0], [0, 0, 1], name="floor")],
                     gravity=(0, 0, -9.81), local_damping=0.7)
    sim.add_interaction(cl)
    return sim, cl


@pytest.mark.parametrize("shape", ["chunk", "rubbing"])
def test_clump_rests_on_wall_with_its_weight(shape: str) -> None:
    sim, cl = resting_clump(shape)
    weight = cl.mass[0] * 9.81
    wall = sim.walls[0]
    for _ in range(60):
        sim.step(500)
        if abs(wall.normal_force / weight - 1) < 1e-8 and cl.kinetic_energy() < 1e-25:
            break
    assert wall.contacts == 3  # chunk: a face of three members; rubbing: the whole row
    assert abs(wall.normal_force / weight - 1) < 1e-6, wall.normal_force / weight
    assert np.abs(wall.force[:2]).max() < 1e-6 * weight


def test_clump_checkpoint_resume_is_bitwise(tmp_path) -> None:
    sim, cl = resting_clump("chunk")
    cl.vel[0] = [0.01, -0.005, 0.0]  # a sliding, tumbling start
    cl.angmom[0] = [1e-12, 3e-12, -2e-12]
    sim.step(300)
    path = sim.save_checkpoint(tmp_path / "c.npz")
    sim.step(300)
    ref = (sim.p.pos.copy(), cl.quat.copy(), cl.angmom.copy(), sim.walls[0].normal_force)
    sim2, cl2 = resting_clump("chunk")
    sim2.load_checkpoint(path)
    sim2.step(300)
    assert np.array_equal(sim2.p.pos, ref[0])
    assert np.array_equal(cl2.quat, ref[1])
    assert np.array_equal(cl2.angmom, ref[2])
    assert sim2.walls[0].normal_force == ref[3]


def test_periodic_wrap_keeps_members_with_body() -> None:
    t = debris_template("rubbing", 1e-3)
    length = 6e-3
    p, cl = make_clumps([t], [0], [[length - 1e-4, 1e-3, 0]], vel=[[2.0, 0, 0]],
                        omega=[[0, 0, 300.0]])
    sim = Simulation(p, [STEEL], Box([0, 0, -1], [length, length, 1], [True, True, False]),
                     dt=1e-6, force_dt=True)
    sim.add_interaction(cl)
    sim.step(2000)  # crosses the periodic face
    assert 0 <= cl.pos[0, 0] < length
    x = cl.member_positions()
    wrapped = x.copy()
    wrapped[:, :2] %= length
    assert np.abs(sim.p.pos - wrapped).max() < 1e-12
    assert ((sim.p.pos[:, :2] >= 0) & (sim.p.pos[:, :2] < length)).all()


def test_two_clumps_collide_and_conserve_momentum() -> None:
    t = debris_template("chunk", 1e-3)
    q = random_quaternions(2, np.random.default_rng(5))
    p, cl = make_clumps([t, debris_template("rubbing", 1e-3)], [0, 1],
                        [[-0.6e-3, 0, 0], [0.6e-3, 0.1e-3, 0]], quat=q,
                        vel=[[0.5, 0, 0], [-0.5, 0, 0]])
    sim = Simulation(p, [STEEL], Box([-1, -1, -1], [1, 1, 1]))
    sim.add_interaction(cl)
    mom0 = (cl.mass[:, None] * cl.vel).sum(0)
    hit = False
    for _ in range(40):
        sim.step(100)
        hit |= sim.n_contacts() > 0
    assert hit
    mom1 = (cl.mass[:, None] * cl.vel).sum(0)
    assert np.abs(mom1 - mom0).max() < 1e-12 * np.abs(cl.mass * 0.5).sum()
    assert cl.vel[0, 0] < 0.5 and cl.vel[1, 0] > -0.5  # they bounced


def test_make_clumps_vectorised_layout() -> None:
    temps = [debris_template(s, 0.6e-6) for s in DEBRIS_SHAPES]
    rng = np.random.default_rng(1)
    kind = rng.integers(0, 3, 1000)
    pos = rng.uniform(0, 1e-4, (1000, 3))
    p, cl = make_clumps(temps, kind, pos, random_quaternions(1000, rng))
    counts = np.array([1, 4, 3])[kind]
    assert p.n == counts.sum() == cl.members.size
    assert np.array_equal(np.diff(cl.mstart), counts)
    assert np.abs(cl.member_positions() - p.pos).max() < 1e-18
    assert math.isclose(p.mass.sum(), cl.mass.sum(), rel_tol=1e-12)
    assert np.allclose(cl.mass, 7850 * math.pi * 0.6e-6**3 / 6, rtol=1e-12)


def test_viscous_damping_acts_on_bodies_like_eq4() -> None:
    """(M + eta dt/2) V+ = (M - eta dt/2) V- for the body; the same factor on L."""
    c = 50.0
    t = debris_template("rubbing", 1e-3)
    p, cl = make_clumps([t], [0], [[0, 0, 0]], vel=[[1.0, 0, 0]], omega=[[0, 0, 40.0]])
    sim = Simulation(p, [STEEL], Box([-1, -1, -1], [1, 1, 1]), dt=1e-5, force_dt=True,
                     viscous_damping=c)
    sim.add_interaction(cl)
    l0 = cl.angmom[0].copy()
    sim.step(400)
    h = 0.5 * c * sim.dt
    factor = ((1 - h) / (1 + h)) ** 400
    assert math.isclose(cl.vel[0, 0], factor, rel_tol=1e-12)
    assert np.allclose(cl.angmom[0], factor * l0, rtol=1e-12, atol=0)
    assert math.isclose(cl.omega[0, 2], 40.0 * factor, rel_tol=1e-9)


def test_local_damping_reduces_body_driving_force() -> None:
    alpha = 0.7
    t = debris_template("chunk", 1e-3)
    p, cl = make_clumps([t], [0], [[0, 0, 0]], vel=[[0, 0, -1.0]])
    sim = Simulation(p, [STEEL], Box([-1, -1, -1], [1, 1, 1]), gravity=(0, 0, -9.81),
                     dt=1e-5, force_dt=True, local_damping=alpha)
    sim.add_interaction(cl)
    sim.step(100)
    accel = (cl.vel[0, 2] + 1.0) / sim.time
    assert math.isclose(accel, -9.81 * (1 - alpha), rel_tol=1e-10)
