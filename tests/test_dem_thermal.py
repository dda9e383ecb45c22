"""Thermal room (Sha et al. (2022) eq 13): free expansion of a bonded block, conduction through
intact bonds only, boundary curves."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tribodem.dem import Box, Material, ParticleState, Simulation
from tribodem.dem.bonds import install_bonds_by_gap
from tribodem.dem.state import FIX_ROTATION, FIX_TRANSLATION
from tribodem.dem.thermal import Thermal, read_curve

R = 1.0e-3
GAP = 1.0e-5
E_BOND = 1.0e9
RHO = 2500.0
C_HEAT = 500.0  # J/(kg K)
T0 = 300.0


def test_free_bonded_block_strains_alpha_dt() -> None:
    """A 5 x 5 bonded square lattice heated by dT settles at strain alpha dT (within 1%)."""
    n_side, alpha, d_t = 5, 1.0e-5, 100.0
    s = 2 * R + GAP
    xy = np.array([(ix * s, iy * s, 0.0) for iy in range(n_side) for ix in range(n_side)])
    p = ParticleState(dim=2, pos=xy, radius=R, density=RHO, thickness=2 * R)
    mat = Material(law="linear", young=E_BOND, density=RHO)
    sim = Simulation(p, [mat], Box([-0.1, -0.1, 0], [0.1, 0.1, 0]), dt=1e-7, force_dt=True,
                     local_damping=0.7)
    bonds = install_bonds_by_gap(sim, 2 * GAP, 1.0, E_BOND, 1.75, 1e12, 1e12)
    assert bonds.n_bonds == 2 * n_side * (n_side - 1)
    sim.dt = 0.2 * min(bonds.critical_step(sim), sim.dt_critical)
    thermal = Thermal(sim, C_HEAT, expansion=alpha, temperature=T0, bonds=bonds)
    sim.add_interaction(thermal)
    corners = (0, n_side * n_side - 1)
    size0 = np.linalg.norm(sim.p.pos[corners[1]] - sim.p.pos[corners[0]])
    r0 = sim.p.radius.copy()
    m0 = sim.p.mass.copy()
    thermal.set_temperature(T0 + d_t)
    sim.step(2000)
    e_scale = 0.5 * bonds.kn[0] * bonds.area[0] * (alpha * d_t * 2 * R) ** 2  # J
    assert sim.kinetic_energy() < 1e-9 * e_scale  # settled
    size = np.linalg.norm(sim.p.pos[corners[1]] - sim.p.pos[corners[0]])
    strain = size / size0 - 1.0
    assert abs(strain - alpha * d_t) / (alpha * d_t) < 0.01, strain
    assert np.allclose(sim.p.radius, r0 * (1 + alpha * d_t), rtol=1e-12)
    assert np.allclose(sim.p.mass, m0, rtol=1e-12)
    # free expansion leaves the bonds unloaded
    assert np.abs(bonds.fn).max() < 1e-3 * bonds.kn[0] * bonds.area[0] * alpha * d_t * 2 * R


def test_heat_crosses_intact_bonds_only() -> None:
    """Pairs (0, 1) and (2, 3): break (2, 3), hold 0 and 2 at 400 K: particle 1 follows
    T = 400 - 100 exp(-t / (m c eta)), particle 3 stays at 300 K exactly."""
    pos = [[0, 0, 0], [2 * R + GAP, 0, 0], [0, 10 * R, 0], [2 * R + GAP, 10 * R, 0]]
    p = ParticleState(dim=2, pos=pos, radius=R, density=RHO, thickness=2 * R,
                      group=[1, 0, 1, 0], fixed=FIX_TRANSLATION | FIX_ROTATION)
    mat = Material(law="linear", young=E_BOND, density=RHO)
    sim = Simulation(p, [mat], Box([-0.1, -0.1, 0], [0.1, 0.1, 0]), dt=1e-6, force_dt=True)
    bonds = install_bonds_by_gap(sim, 2 * GAP, 1.0, E_BOND, 1.75, 1e6, 1e6)
    assert bonds.n_bonds == 2
    sim.p.vel[3, 0] = 1e-3  # pull particle 3 away until its bond breaks (tension)
    while bonds.broken_count() == 0:
        sim.step(1)
    sim.p.vel[3, 0] = 0.0
    assert bonds.broken_count("tensile") == 1 and (bonds.log[0].i, bonds.log[0].j) == (2, 3)
    mass = sim.p.mass[1]
    tau = 200 * sim.dt  # time constant m c eta
    eta = tau / (mass * C_HEAT)
    thermal = Thermal(sim, C_HEAT, temperature=T0, bonds=bonds, resistance=eta)
    thermal.add_boundary(sim, 1, [0.0, 1.0], [400.0, 400.0])
    sim.add_interaction(thermal)
    t_start = sim.time
    sim.step(int(round(tau / sim.dt)))
    # explicit conduction lags the exponential by ~ n (dt/tau)^2 / 2 = 0.25 %
    rise = (thermal.temperature[1] - T0) / 100.0
    assert abs(rise - (1 - math.exp(-(sim.time - t_start) / tau))) < 0.01, rise
    sim.step(int(round(6 * tau / sim.dt)))
    assert abs(thermal.temperature[1] - 400.0) < 1.0
    assert thermal.temperature[3] == T0
    assert thermal.temperature[0] == thermal.temperature[2] == 400.0


def test_boundary_curve_is_interpolated(tmp_path) -> None:
    f = tmp_path / "curve.csv"
    f.write_text("time_s,T_K\n0.0,300\n1e-3,500\n")
    times, temps = read_curve(f)
    p = ParticleState(dim=3, pos=[[0, 0, 0]], radius=R, density=RHO, group=[4])
    sim = Simulation(p, [Material()], Box([-1, -1, -1], [1, 1, 1]), dt=1e-5, force_dt=True)
    thermal = Thermal(sim, C_HEAT, expansion=1e-5, temperature=300.0)
    thermal.add_boundary(sim, 4, times, temps)
    sim.add_interaction(thermal)
    sim.step(40)  # t = 4e-4 s -> 380 K
    assert abs(thermal.temperature[0] - 380.0) < 1e-9
    # incremental dR = alpha R dT each step (+2 K per step): compounded growth
    assert abs(sim.p.radius[0] / R - (1 + 1e-5 * 2.0) ** 40) < 1e-12
    sim.step(100)  # beyond the end: held at 500 K
    assert thermal.temperature[0] == 500.0


def test_bad_thermal_input_is_refused() -> None:
    pos = [[0, 0, 0], [2 * R + GAP, 0, 0]]
    p = ParticleState(dim=2, pos=pos, radius=R, density=RHO, thickness=2 * R)
    sim = Simulation(p, [Material(law="linear")], Box([-1, -1, 0], [1, 1, 0]), dt=1e-6,
                     force_dt=True)
    bonds = install_bonds_by_gap(sim, 2 * GAP, 1.0, E_BOND, 1.75, 1e6, 1e6)
    with pytest.raises(ValueError, match="heat_capacity = -1.0"):
        Thermal(sim, -1.0)
    with pytest.raises(ValueError, match="conduction limit"):
        Thermal(sim, C_HEAT, bonds=bonds, resistance=1e-9)
    th = Thermal(sim, C_HEAT)
    with pytest.raises(ValueError, match="group = 7"):
        th.add_boundary(sim, 7, [0.0], [300.0])
    with pytest.raises(ValueError, match="increase strictly"):
        th.add_boundary(sim, 0, [1.0, 0.0], [300.0, 310.0])
