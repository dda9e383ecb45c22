"""A contact law is a style: a test-only law, defined here and registered, runs in the
engine without any edit of the kernels, and meets its closed-form collision.

The law: a frictionless linear spring ``Fn = k delta`` with ``k = 2 E* R*`` (N/m), no
dashpot. Two equal spheres meeting head-on at relative speed v0 separate after
``T = pi sqrt(m*/k)`` with their velocities exchanged (restitution 1), the largest overlap
``v0 sqrt(m*/k)``.
"""

from __future__ import annotations

import math
import types

import numpy as np
import pytest
from numba import njit

from tribodem.dem import Box, Material, ParticleState, Simulation, laws
from tribodem.dem.laws.table import P_ESTAR


def _spring_law() -> types.ModuleType:
    mod = types.ModuleType("spring_law")
    mod.NAME = "test_spring"
    mod.TIME_STEP = "stiffness"

    @njit(inline="always")
    def normal(prop, delta, vn, rstar, mstar, lin_k):
        k = 2.0 * prop[P_ESTAR] * rstar
        return k * delta, 0.0, 0.0, k, 0.5 * k * delta * delta

    mod.normal = normal
    return mod


@pytest.fixture
def spring_law():
    law_id = laws.register(_spring_law())
    yield law_id
    laws.unregister("test_spring")


def test_registered_law_runs_and_meets_its_closed_form(spring_law) -> None:
    assert spring_law == 2 and laws.ids()["test_spring"] == 2
    r, e, nu, rho, v0 = 5e-3, 2.1e11, 0.3, 7850.0, 0.2
    mat = Material(name="s", young=e, poisson=nu, density=rho, friction=0.0, law="test_spring")
    p = ParticleState(dim=3, pos=[[0, 0, 0], [2 * r + 1e-9, 0, 0]], radius=r, density=rho,
                      vel=[[v0 / 2, 0, 0], [-v0 / 2, 0, 0]])
    mstar = 0.5 * rho * 4.0 / 3.0 * math.pi * r**3
    estar = e / (2 * (1 - nu**2))
    k = 2.0 * estar * (r / 2)
    period = math.pi * math.sqrt(mstar / k)
    dt = period / 2000
    sim = Simulation(p, [mat], Box([-1, -1, -1], [1, 1, 1]), dt=dt)
    steps, in_contact, max_overlap = 0, 0, 0.0
    while steps < 4000:
        sim.step(1)
        steps += 1
        ov = float(sim.pinfo[:, 0].max(initial=0.0))
        if ov > 0:
            in_contact += 1
            max_overlap = max(max_overlap, ov)
        elif in_contact:
            break
    assert in_contact * dt == pytest.approx(period, abs=2 * dt)
    assert max_overlap == pytest.approx(v0 * math.sqrt(mstar / k), rel=1e-3)
    np.testing.assert_allclose(sim.p.vel[:, 0], [-v0 / 2, v0 / 2], rtol=1e-5)


def test_builtin_laws_are_untouched_by_a_registration(spring_law) -> None:
    from tribodem.dem.contact import pair_forces_cross as pair_forces

    assert laws.active(pair_forces) is not pair_forces  # re-bound for three laws
    laws.unregister("test_spring")
    assert laws.active(pair_forces) is pair_forces  # the cached built-in kernel again
    laws.register(_spring_law())  # for the fixture's clean-up


def test_bad_law_modules_are_refused() -> None:
    bad = types.ModuleType("bad")
    bad.NAME = "hertz"
    with pytest.raises(ValueError, match="registered already"):
        laws.register(bad)
    bad.NAME = "x"
    bad.TIME_STEP = "cfl"
    with pytest.raises(ValueError, match="TIME_STEP"):
        laws.register(bad)
    with pytest.raises(ValueError, match="law = 'nope'"):
        Material(law="nope")
