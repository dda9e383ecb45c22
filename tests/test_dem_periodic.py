"""Periodic axes: a chain of disks closed across the seam; contacts straddling the seam."""

from __future__ import annotations

import numpy as np

from tribodem.dem import Box, Material, ParticleState, Simulation
from tribodem.dem.state import FIX_X

R = 1e-3
MAT = Material(young=1e9, poisson=0.3, density=2000, friction=0.5, law="linear", kratio=1.5)


def ring(n: int = 8, eps: float = 0.01, vx: float = 0.0) -> tuple[Simulation, float]:
    """n disks along x in a periodic box just too short for them: every contact (also the
    one across the seam) has overlap 2 R eps."""
    L = n * 2 * R * (1 - eps)
    x = (np.arange(n) + 0.5) * 2 * R * (1 - eps)
    pos = np.stack([x, np.full(n, 5 * R), np.zeros(n)], 1)
    p = ParticleState(dim=2, pos=pos, radius=R, density=2000, vel=np.tile([vx, 0, 0], (n, 1)))
    box = Box([0, 0, 0], [L, 10 * R, 0], [True, False, False])
    return Simulation(p, [MAT], box, dt_safety=0.1), 2 * R * 2 * R * eps / 2


def test_chain_closes_across_seam() -> None:
    sim, _ = ring()
    sim.step(1)
    c = sim.contacts()
    assert len(c["i"]) == 8  # 7 inner contacts + the one across the seam
    kn = 2 * R * 1.0 * MAT.young / (2 * R)  # PFC deformability, unit thickness
    np.testing.assert_allclose(c["normal_force"], kn * 2 * R * 0.01, rtol=1e-9)
    assert np.abs(sim.force).max() < 1e-9 * c["normal_force"].max()


def test_chain_moves_through_seam_unchanged() -> None:
    sim, _ = ring(vx=2.0)
    sim.step(1)
    f0 = np.sort(sim.contacts()["normal_force"])
    L = sim.box.length[0]
    steps = int(1.5 * L / (2.0 * sim.dt))  # every disk crosses the seam at least once
    sim.step(steps)
    c = sim.contacts()
    assert len(c["i"]) == 8
    np.testing.assert_allclose(np.sort(c["normal_force"]), f0, rtol=1e-6)
    assert (sim.p.pos[:, 0] >= 0).all() and (sim.p.pos[:, 0] < L).all()
    np.testing.assert_allclose(sim.p.vel[:, 0], 2.0, rtol=1e-9)


def sheared_pair(x0: float) -> Simulation:
    """Two overlapping disks along x at x0 (held in x), sliding past each other in y."""
    L = 20 * R
    d = 2 * R * 0.99
    pos = np.array([[x0, 5 * R, 0], [x0 + d, 5 * R, 0]])
    pos[:, 0] %= L
    p = ParticleState(dim=2, pos=pos, radius=R, density=2000,
                      vel=[[0, 0.05, 0], [0, -0.05, 0]], omega=[[0, 0, 3.0], [0, 0, -1.0]],
                      fixed=FIX_X)
    return Simulation(p, [MAT], Box([0, 0, 0], [L, 10 * R, 0], [True, False, False]), dt=1e-8)


def test_contact_across_seam_equals_interior_contact() -> None:
    inside = sheared_pair(8 * R)
    seam = sheared_pair(20 * R - 0.5 * R)  # second disk wraps to the other side
    assert seam.p.pos[1, 0] < seam.p.pos[0, 0]
    for _ in range(50):
        inside.step(20)
        seam.step(20)
        np.testing.assert_allclose(seam.force, inside.force, rtol=1e-7, atol=1e-9)
        np.testing.assert_allclose(seam.torque, inside.torque, rtol=1e-7, atol=1e-12)
    assert inside.n_contacts() == 1 and seam.n_contacts() == 1
    assert np.abs(inside.hist).max() > 0  # the shear spring was loaded (history kept)
    np.testing.assert_allclose(seam.hist, inside.hist, rtol=1e-7)
