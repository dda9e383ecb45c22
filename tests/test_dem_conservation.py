"""Energy conservation of an undamped frictionless box; pair forces equal and opposite."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from tribodem.dem import Box, Material, ParticleState, PlaneWall, Simulation


def gas_box(law: str, n_side: int = 10, seed: int = 0) -> Simulation:
    """n_side^3 spheres with random velocities in a closed box, no friction, no damping."""
    rng = np.random.default_rng(seed)
    r, s = 1.0e-3, 2.2e-3
    idx = np.arange(n_side**3)
    pos = np.stack([idx % n_side, (idx // n_side) % n_side, idx // n_side**2], 1) * s + s / 2
    radius = rng.uniform(0.8, 1.0, idx.size) * r
    vel = rng.normal(0.0, 0.5, (idx.size, 3))
    mat = Material(young=1e8, poisson=0.3, density=2500, friction=0.0, cor=1.0, law=law,
                   kratio=1.0)
    L = n_side * s
    walls = [PlaneWall(np.zeros(3), e) for e in np.eye(3)]
    walls += [PlaneWall(np.full(3, L), -e) for e in np.eye(3)]
    p = ParticleState(dim=3, pos=pos, radius=radius, density=2500, vel=vel)
    return Simulation(p, [mat], Box(np.zeros(3), np.full(3, L)), walls=walls,
                      dt_safety=0.1, track_energy=True)


def test_energy_conserved_hertz_box() -> None:
    sim = gas_box("hertz")
    assert sim.p.n >= 1000
    sim.step(1)
    e0 = sim.total_energy()
    energies = []
    for _ in range(100):
        sim.step(100)
        energies.append(sim.total_energy())
    drift = np.max(np.abs(np.array(energies) - e0)) / e0
    assert sim.step_count >= 10_000
    assert sim.nl.builds > 1  # particles moved and contacts changed
    assert drift < 0.005, drift


def test_energy_conserved_linear_box() -> None:
    sim = gas_box("linear", n_side=10, seed=1)
    sim.step(1)
    e0 = sim.total_energy()
    sim.step(10_000)
    assert abs(sim.total_energy() - e0) / e0 < 0.005


vec = st.tuples(*[st.floats(-1.0, 1.0) for _ in range(3)])


@settings(max_examples=60, deadline=None)
@given(d=vec, vi=vec, vj=vec, wi=vec, wj=vec, ri=st.floats(0.5, 1.5), rj=st.floats(0.5, 1.5),
       overlap=st.floats(0.001, 0.2), law=st.sampled_from(["hertz", "linear"]),
       hist=vec)
def test_pair_forces_equal_and_opposite(d, vi, vj, wi, wj, ri, rj, overlap, law, hist) -> None:
    """Newton's third law and angular momentum balance for any contact configuration."""
    n = np.array(d) + np.array([1e-3, 0, 0])
    n /= np.linalg.norm(n)
    dist = (ri + rj) * (1 - overlap)
    pos = np.array([[0.0, 0, 0], n * dist])
    mat = Material(young=1e6, poisson=0.25, density=1000, friction=0.4, cor=0.6, law=law,
                   kratio=1.5, beta_n=0.3, beta_s=0.2, rolling_friction=0.1)
    p = ParticleState(dim=3, pos=pos, radius=[ri, rj], density=1000, vel=[vi, vj],
                      omega=[wi, wj])
    sim = Simulation(p, [mat], Box([-5, -5, -5], [5, 5, 5]), dt=1e-3, force_dt=True)
    sim.hist[:] = np.array([hist], dtype=float) * 0.01
    sim.step(1)  # sim.force / sim.torque: the totals the particles received in that step
    force, torque = sim.force, sim.torque
    assert sim.n_contacts() == 1
    scale = np.abs(force).max() + 1e-30
    np.testing.assert_allclose(force[0], -force[1], atol=1e-12 * scale)
    # total angular momentum change about the origin vanishes (rolling torque is pair-balanced)
    lsum = np.cross(pos[0], force[0]) + np.cross(pos[1], force[1]) + torque[0] + torque[1]
    assert np.abs(lsum).max() <= 1e-9 * scale * (ri + rj)
