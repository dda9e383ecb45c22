"""Coulomb sliding and constant-torque rolling friction of a sphere on a plane wall."""

from __future__ import annotations

import math

import numpy as np

from tribodem.dem import Box, Material, ParticleState, PlaneWall, Simulation
from tribodem.dem.state import FIX_ROTATION

G = 9.81
R = 0.005
SOFT = dict(young=1.0e8, poisson=0.3, density=7850.0, cor=0.5)


def sphere_on_floor(v0: float, mu: float, mu_r: float = 0.0, rolling: bool = False,
                    fix_rotation: bool = False) -> Simulation:
    mat = Material(name="soft", friction=mu, rolling_friction=mu_r, **SOFT)
    m = SOFT["density"] * 4 / 3 * math.pi * R**3
    estar = SOFT["young"] / (2 * (1 - SOFT["poisson"] ** 2))
    delta = (m * G / (4 / 3 * estar * math.sqrt(R))) ** (2 / 3)  # static overlap
    omega = [[0, v0 / (R - delta), 0]] if rolling else None
    p = ParticleState(dim=3, pos=[[0, 0, R - delta]], radius=R, density=SOFT["density"],
                      vel=[[v0, 0, 0]], omega=omega,
                      fixed=FIX_ROTATION if fix_rotation else 0)
    floor = PlaneWall([0, 0, 0], [0, 0, 1], name="floor")
    return Simulation(p, [mat], Box([-1, -1, -1], [1, 1, 1]), walls=[floor],
                      gravity=(0, 0, -G))


def test_sliding_sphere_decelerates_at_mu_g() -> None:
    mu, v0 = 0.3, 1.0
    sim = sphere_on_floor(v0, mu)
    t, v = [], []
    t_slip = 2 * v0 / (7 * mu * G)  # rolling sets in at v = 5/7 v0
    while sim.time < 0.8 * t_slip:
        sim.step(1)
        t.append(sim.time)
        v.append(sim.p.vel[0, 0])
    t, v = np.array(t), np.array(v)
    sel = t > 0.1 * t_slip
    decel = -np.polyfit(t[sel], v[sel], 1)[0]
    assert abs(decel - mu * G) / (mu * G) < 0.01, decel
    # the friction torque spins the sphere up: omega R = 5/2 (v0 - v)
    spin = sim.p.omega[0, 1] * R
    assert abs(spin - 2.5 * (v0 - v[-1])) / spin < 0.02


def test_sliding_without_rotation_stops_at_v2_over_2mug() -> None:
    mu, v0 = 0.3, 0.5
    sim = sphere_on_floor(v0, mu, fix_rotation=True)
    t_stop = v0 / (mu * G)
    sim.step(int(1.3 * t_stop / sim.dt))
    dist = sim.p.pos[0, 0]
    expect = v0**2 / (2 * mu * G)
    assert abs(dist - expect) / expect < 0.01, (dist, expect)
    assert abs(sim.p.vel[0, 0]) < 1e-3 * v0


def test_rolling_friction_stops_at_analytic_distance() -> None:
    mu, mu_r, v0 = 0.5, 0.05, 0.5
    sim = sphere_on_floor(v0, mu, mu_r=mu_r, rolling=True)
    # rolling without slip: a = mu_r g / (1 + I/(m R^2)) = mu_r g / 1.4
    expect = 0.7 * v0**2 / (mu_r * G)
    t_stop = v0 / (mu_r * G / 1.4)
    sim.step(int(1.2 * t_stop / sim.dt))
    dist = sim.p.pos[0, 0]
    assert abs(dist - expect) / expect < 0.02, (dist, expect)
    assert abs(sim.p.vel[0, 0]) < 1e-3 * v0
