"""Central-difference integrator: free flight, viscous damping (Sha et al. (2022) eq 4), local
damping."""

from __future__ import annotations

import math

import numpy as np

from tribodem.dem import Box, Material, ParticleState, Simulation


def free_particle(c: float = 0.0, alpha: float = 0.0, g: float = 0.0) -> Simulation:
    p = ParticleState(dim=3, pos=[[0, 0, 0]], radius=1e-3, density=1000, vel=[[1.0, 0, 0]],
                      omega=[[0, 0, 5.0]])
    return Simulation(p, [Material()], Box([-1, -1, -1], [1, 1, 1]), gravity=(0, 0, -g),
                      dt=1e-4, force_dt=True, viscous_damping=c, local_damping=alpha)


def test_free_fall_is_exact() -> None:
    sim = free_particle(g=9.81)
    sim.step(1000)
    t = sim.time
    # leapfrog: x_n = v0 t - g t^2/2 - g dt t/2 (velocity form, v at half steps)
    assert math.isclose(sim.p.pos[0, 0], 1.0 * t, rel_tol=1e-12)
    expect_z = -0.5 * 9.81 * t * (t + sim.dt)
    assert math.isclose(sim.p.pos[0, 2], expect_z, rel_tol=1e-10)


def test_viscous_damping_matches_eq4() -> None:
    """(m + eta dt/2) v+ = (m - eta dt/2) v-  ->  v decays as exp(-c t) to O((c dt)^2)."""
    c = 50.0
    sim = free_particle(c=c)
    sim.step(400)
    h = 0.5 * c * sim.dt
    exact_discrete = ((1 - h) / (1 + h)) ** 400
    assert math.isclose(sim.p.vel[0, 0], exact_discrete, rel_tol=1e-12)
    assert math.isclose(sim.p.vel[0, 0], math.exp(-c * sim.time), rel_tol=1e-4)
    assert math.isclose(sim.p.omega[0, 2], 5.0 * exact_discrete, rel_tol=1e-12)


def test_local_damping_reduces_driving_force() -> None:
    """PFC local damping: the force along the motion is scaled by (1 - alpha)."""
    alpha = 0.7
    sim = free_particle(alpha=alpha, g=9.81)
    sim.p.vel[:] = [[0, 0, -1.0]]  # moving down, gravity down: force reduced
    sim.step(100)
    accel = (sim.p.vel[0, 2] + 1.0) / sim.time
    assert math.isclose(accel, -9.81 * (1 - alpha), rel_tol=1e-10)
    assert np.allclose(sim.p.vel[0, :2], 0.0)
