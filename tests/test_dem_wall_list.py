"""The near-wall list: a wall that starts far away (many skins) and moves in still meets
every particle, with the closed-form Hertz force (the list follows the wall's motion)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tribodem.dem import Box, Material, ParticleState, PlaneWall, Simulation
from tribodem.dem.state import FIX_ROTATION, FIX_TRANSLATION


def test_far_wall_moving_in_meets_fixed_spheres_with_hertz_force() -> None:
    r, e, nu = 1e-3, 2e9, 0.3
    mat = Material(name="m", young=e, poisson=nu, density=2500.0, cor=1.0, friction=0.0)
    xs = np.linspace(-0.02, 0.02, 9)
    pos = np.array([[x, 0.0, 0.0] for x in xs])
    p = ParticleState(dim=3, pos=pos, radius=r, density=2500.0)
    p.fixed[:] = FIX_TRANSLATION | FIX_ROTATION
    gap0, v = 20 * r, 5.0  # the wall starts 20 radii away: far outside the skin
    wall = PlaneWall([0, r + gap0, 0], [0, -1, 0], mode="velocity", velocity=[0, -v, 0],
                     name="top")
    sim = Simulation(p, [mat], Box([-0.05, -0.05, -0.05], [0.05, 0.05, 0.05]), walls=[wall])
    assert sim._wid.size == 0  # nothing is near the wall at the start
    depth = 0.02 * r  # final overlap
    steps = int(math.ceil((gap0 + depth) / (v * sim.dt)))
    builds0 = sim.nl.builds
    sim.step(steps)
    assert sim.nl.builds > builds0  # the wall's travel triggered rebuilds
    # overlap when the force was evaluated: the wall moves after the force pass of a step
    delta = r - (float(wall.point[1]) + v * sim.dt)  # the spheres sit at y = 0
    assert delta > 0
    estar = 1.0 / (2 * (1 - nu**2) / e)  # sphere on a wall of the same material
    hertz = 4.0 / 3.0 * estar * math.sqrt(r) * delta**1.5
    assert wall.contacts == len(xs)
    assert wall.normal_force == pytest.approx(len(xs) * hertz, rel=1e-9)
