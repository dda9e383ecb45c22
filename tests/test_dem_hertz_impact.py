"""Head-on Hertz impact of two equal steel spheres against closed-form Hertz theory."""

from __future__ import annotations

import math

import pytest
from conftest import STEEL, two_spheres

from tribodem.dem.contact import hertz_damping_from_cor, hertz_restitution

R = 0.005


def hertz_theory(v0: float) -> tuple[float, float]:
    """Contact duration (s) and peak force (N) of an undamped Hertz impact."""
    e, nu = STEEL["young"], STEEL["poisson"]
    estar = e / (2 * (1 - nu**2))
    rstar = R / 2
    mstar = STEEL["density"] * 4 / 3 * math.pi * R**3 / 2
    tc = 2.868 * (mstar**2 / (rstar * estar**2 * v0)) ** 0.2
    dmax = (15 * mstar * v0**2 / (16 * estar * math.sqrt(rstar))) ** 0.4
    return tc, 4 / 3 * estar * math.sqrt(rstar) * dmax**1.5


def impact(v0: float, cor: float) -> tuple[float, float, float]:
    """Run one impact; return restitution, contact duration (s), peak force (N)."""
    sim = two_spheres(v0, cor)
    tc, _ = hertz_theory(v0)
    sim.dt = tc / 1000
    fmax, t_in, t_out = 0.0, None, None
    while sim.step_count < 100_000:
        sim.step(1)
        if sim.pinfo[0, 0] > 0:
            t_in = sim.time if t_in is None else t_in
            fmax = max(fmax, float(sim.pinfo[0, 1]))
        elif t_in is not None:
            t_out = sim.time
            break
    assert t_out is not None, "spheres did not separate"
    e = -(sim.p.vel[0, 0] - sim.p.vel[1, 0]) / v0
    return e, t_out - t_in, fmax


@pytest.mark.parametrize("v0", [0.01, 0.1, 1.0])
def test_restitution_matches_set_cor(v0: float) -> None:
    e, _, _ = impact(v0, 0.72)
    assert abs(e - 0.72) / 0.72 < 0.01, e


@pytest.mark.parametrize("v0", [0.01, 1.0])
def test_undamped_duration_and_peak_force(v0: float) -> None:
    e, t, f = impact(v0, 1.0)
    tc, fmax = hertz_theory(v0)
    assert abs(e - 1.0) < 1e-3
    assert abs(t - tc) / tc < 0.02, (t, tc)
    assert abs(f - fmax) / fmax < 0.02, (f, fmax)


def test_damping_formula_gives_cor() -> None:
    """The closed-form dashpot factor reproduces e in the exact non-dimensional impact."""
    for e in (0.3, 0.5, 0.72, 0.9):
        assert abs(hertz_restitution(hertz_damping_from_cor(e)) - e) < 1e-6
