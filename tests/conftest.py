"""Shared fixtures: small builders for DEM test scenes."""

from __future__ import annotations

import numpy as np
import pytest

from tribodem.dem import Box, Material, ParticleState, Simulation

STEEL = dict(young=2.1e11, poisson=0.3, density=7850.0)


def two_spheres(v0: float, cor: float, r: float = 0.005, friction: float = 0.0) -> Simulation:
    """Two equal steel spheres approaching head-on along x at relative speed v0."""
    mat = Material(name="steel", cor=cor, friction=friction, **STEEL)
    p = ParticleState(dim=3, pos=[[0, 0, 0], [2 * r + 1e-9, 0, 0]], radius=r,
                      density=STEEL["density"], vel=[[v0 / 2, 0, 0], [-v0 / 2, 0, 0]])
    return Simulation(p, [mat], Box([-1, -1, -1], [1, 1, 1]))


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(1234)
