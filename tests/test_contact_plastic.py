"""The elastic-plastic half-space with friction: the closed forms its validation uses
(tribodem.contact.hertz_yield), the traction transfer onto the plastic grid, the plastic
kernel (tribodem.contact.plastic_halfspace) and the backend's per-cycle records."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tribodem.contact import Capabilities, ElastoPlasticSolver
from tribodem.contact.hertz_yield import (
    SURFACE_DEPTH,
    axis_stress,
    first_yield_frictionless,
    point_force_stress,
    sliding_hertz_stress,
)
from tribodem.contact.plastic_halfspace import PlasticHalfSpace, block_average

NU = 0.3


def test_frictionless_first_yield_is_johnsons():
    """Johnson table 6.1 (nu = 0.3): p0_y = 1.60 Y at z = 0.48 a; measured from eq 3.46:
    1.6128 Y (max sigma_vM 0.6200 p0) at 0.4809 a."""
    fy = first_yield_frictionless(NU)
    assert fy.p0_over_y == pytest.approx(1.61, abs=0.01)
    assert fy.depth == pytest.approx(0.48, abs=0.005)
    assert fy.vm_over_p0 == pytest.approx(0.62, abs=0.001)


@pytest.mark.parametrize("z", [0.1, 0.48, 1.0])
def test_point_force_quadrature_reproduces_the_axis_closed_form(z: float):
    """The Boussinesq quadrature of the Hertz pressure on the axis against Johnson eq 3.46
    (measured: 1e-12 relative in sigma_r and sigma_z)."""
    s = sliding_hertz_stress(1e-9, z, 0.0, NU)
    sr, sz = axis_stress(z, NU)
    assert s[0, 0] == pytest.approx(float(sr), rel=1e-6)
    assert s[2, 2] == pytest.approx(float(sz), rel=1e-6)
    assert s[1, 1] == pytest.approx(float(sr), rel=1e-6)


def test_sliding_surface_stress_closed_form():
    """Inside the contact on the surface, the Hertz traction q = mu p0 sqrt(1 - r^2/a^2)
    along x gives sigma_x = -pi (4 + nu) mu p0 x / (8 a) and sigma_xz = -q (Hamilton 1983,
    Johnson section 7.1); the quadrature at z = 1e-3 a: -0.50567 against -0.50658 at x = 0.3
    a (0.2 %), sigma_xz within 0.3 %."""
    x = 0.3
    s = sliding_hertz_stress(x, SURFACE_DEPTH, 1.0, NU) - sliding_hertz_stress(
        x, SURFACE_DEPTH, 0.0, NU)
    assert s[0, 0] == pytest.approx(-math.pi * (4 + NU) * x / 8, rel=0.005)
    assert s[0, 2] == pytest.approx(-math.sqrt(1 - x * x), rel=0.005)


@pytest.mark.parametrize("point", [(0.3, -0.2, 0.4), (-0.5, 0.1, 0.05)])
def test_point_force_stresses_are_in_equilibrium_and_free_at_the_surface(point):
    """Both concentrated-force fields satisfy div sigma = 0 (central differences, relative to
    the stress gradient's scale: < 1e-5) and leave the surface traction-free off the load."""
    x, y, z = point
    h = 1e-4
    for which in (0, 1):
        div = np.zeros(3)
        for j, d in enumerate(np.eye(3) * h):
            up = point_force_stress(np.array(x + d[0]), np.array(y + d[1]), np.array(z + d[2]),
                                    NU)[which]
            dn = point_force_stress(np.array(x - d[0]), np.array(y - d[1]), np.array(z - d[2]),
                                    NU)[which]
            div += (up[:, j] - dn[:, j]) / (2 * h)
        scale = np.abs(point_force_stress(np.array(x), np.array(y), np.array(z), NU)[which]
                       ).max() / math.sqrt(x * x + y * y + z * z)
        assert np.abs(div).max() < 1e-5 * scale
        surf = point_force_stress(np.array(x), np.array(y), np.array(1e-9), NU)[which]
        assert np.abs(surf[2]).max() < 1e-6 * np.abs(surf).max()


def test_block_average_keeps_the_force_and_a_uniform_field():
    """Overlap weights: a non-integer ratio of cell sizes (2.5) still keeps sum t dA to
    rounding, and a uniform field stays uniform."""
    rng = np.random.default_rng(3)
    f = rng.random((24, 20, 3))
    dx, g = 1e-6, 2.5e-6
    # fine cells span [-0.5, 23.5] x [-0.5, 19.5] um; coarse ones [-0.5, 29.5] x [-0.5, 24.5]
    out = block_average(f, 0.0, dx, 0.75e-6, g, 12, 0.0, 0.75e-6, 10)
    assert out.shape == (12, 10, 3)
    assert (out * g * g).sum(axis=(0, 1)) == pytest.approx((f * dx * dx).sum(axis=(0, 1)),
                                                           rel=1e-12)
    ones = block_average(np.ones((40, 40, 1)), 0.0, dx, 10e-6, g, 8, 0.0, 10e-6, 8)
    assert ones == pytest.approx(np.ones((8, 8, 1)), rel=1e-12)


def _hertz(s: PlasticHalfSpace, p0: float, a: float, mu: float) -> np.ndarray:
    xx, yy = np.meshgrid(s.x, s.y, indexing="ij")
    p = p0 * np.sqrt(np.maximum(1 - (xx**2 + yy**2) / a**2, 0))
    return np.stack([mu * p, 0 * p, p], -1)


def test_kernel_yields_below_the_surface_without_friction_and_at_it_with():
    """A Hertz traction at p0 = 2 Y on the plastic kernel (16 x 16 x 9, a / 4 cells):
    frictionless, the plastic strain peaks below the surface (Johnson: first yield at
    0.48 a); with q = 0.5 p (Hamilton: surface yield above mu ~ 0.3, here at p0 = 1.09 Y)
    it peaks at the surface, and more of it; unloading leaves residual stress and a
    residual dent (positive displacement into the body) at the centre."""
    a = 1e-4
    kw = dict(nx=16, ny=16, nz=9, dx=a / 4, depth=2 * a, x0=-2 * a, y0=-2 * a, young=240e9,
              poisson=NU, yield_strength=680e6, hardening=2.5e9, length=a)
    s0 = PlasticHalfSpace(**kw)
    dp0 = s0.load(_hertz(s0, 2 * 680e6, a, 0.0))
    p0, z0, _ = s0.peak()
    assert dp0.max() == pytest.approx(p0) and p0 > 0 and z0 > 0.2 * a
    s1 = PlasticHalfSpace(**kw)
    s1.load(_hertz(s1, 2 * 680e6, a, 0.5))
    p1, z1, _ = s1.peak()
    assert z1 == 0.0 and p1 > p0
    s0.load(np.zeros((16, 16, 3)))
    assert np.abs(s0.residual_stress).max() > 10e6
    assert s0.residual_displacement[8, 8] > 0
    assert s0.cumulated_plastic_strain.max() == pytest.approx(p0, rel=1e-9)  # elastic unload


def test_backend_capabilities_and_cycle_records():
    s = ElastoPlasticSolver(load=1.0, n=32, ep_n=8, ep_nz=4, amplitude=2e-5)
    caps = s.capabilities
    assert isinstance(caps, Capabilities)
    assert {"plastic", "plastic_every_cycle", "partial_slip", "subsurface",
            "debris"} <= caps.names()
    assert s.bodies["lower"].nx == s.ep_n + 2 * s.ep_pad and s.ep_pad >= 1
    assert s.ep_dx / s.dx == pytest.approx(round(s.ep_dx / s.dx))
    rows = [{"peeq_increment_upper": v, "peeq_increment_lower": v / 2}
            for v in (0.1, 0.01, 5e-5)]
    assert s.shakedown(rows) == {"reached": True, "cycle": 3, "peeq_increment": 5e-5,
                                 "tolerance": 1e-4}
    assert s.shakedown(rows[:2])["reached"] is False
    assert s.shakedown(rows[:2])["last_peeq_increment"] == 0.01


def test_cycle_records_start_at_the_first_loading_and_carry_the_state():
    """Two frictionless cycles of 4 increments at 10 N (p0 1.28 GPa = 1.9 Y) on coarse
    grids:
    the first cycle's record includes the first loading (its increase of p equals the peak p
    of the virgin body), the plastic state is carried (the peak never falls), every yielding
    increment gives one step per body, and report() holds both cycles and a shakedown
    statement."""
    from tribodem.contact import cycle_offsets

    s = ElastoPlasticSolver(load=10.0, friction=0.0, n=32, ep_n=8, ep_nz=5, amplitude=2e-5,
                            load_steps=2)
    s.solve_increment(0.0)  # the loop's first loading
    peaks = []
    for _ in range(2):
        s.begin_cycle()
        for off in cycle_offsets(2e-5, 4):
            s.solve_increment(float(off))
        peaks.append(s.cycle_columns())
    rep = s.report()
    rows = rep["cycles"]
    assert len(rows) == 2 and rows[1] == peaks[1]
    first = rows[0]
    assert first["max_peeq_lower"] > 1e-4
    assert first["peeq_increment_lower"] == pytest.approx(first["max_peeq_lower"], rel=1e-12)
    assert rows[1]["max_peeq_lower"] >= first["max_peeq_lower"]
    assert rows[1]["max_peeq_upper"] >= first["max_peeq_upper"]
    assert set(rep["shakedown"]) >= {"reached", "tolerance"}
    steps = s.plastic_steps()
    assert steps and {st.body for st in steps} <= {"upper", "lower"}
    assert all(st.dp.shape == st.stress.shape[:-1] for st in steps)


def test_gross_slip_shakes_down_and_a_yielded_state_does_not_resume():
    """mu = 0.3 gross slip at 10 N on coarse grids, two cycles of 4 increments: the
    frictional traction adds plastic strain in the first cycle (peak p 1.2e-3 on the lower
    body against 5.7e-4 after the frictionless loading, measured) and none in the second:
    shakedown reached at cycle 2; a checkpoint of that yielded state is refused on resume
    (tamaas's residual keeps state the model's fields do not carry)."""
    from tribodem.contact import cycle_offsets
    from tribodem.io.config import ConfigError

    kw = dict(load=10.0, friction=0.3, n=32, ep_n=8, ep_nz=5, amplitude=2e-5, load_steps=2)
    s = ElastoPlasticSolver(**kw)
    s.solve_increment(0.0)
    loaded = s.bodies["lower"].peak()[0]
    for _ in range(2):
        s.begin_cycle()
        for off in cycle_offsets(2e-5, 4):
            s.solve_increment(float(off))
    rows = s.report()["cycles"]
    assert rows[0]["max_peeq_lower"] > 1.5 * loaded > 0
    assert rows[1]["peeq_increment_lower"] < 1e-4 and rows[1]["peeq_increment_upper"] < 1e-4
    assert s.report()["shakedown"]["reached"] and s.report()["shakedown"]["cycle"] == 2
    with pytest.raises(ConfigError, match="cannot resume"):
        ElastoPlasticSolver(**kw).load_state_dict(s.state_dict())


def test_a_plastic_increment_beyond_small_strains_stops_the_run():
    """A Hertz traction at p0 = 2.35 Y with q = 0.6 p applied at once on a coarse kernel
    (12 x 12 x 5, a / 3 cells): p would rise by more than 0.5 in the surface layer (0.40 on
    a / 6.4 cells, measured; here checked against a bound of 0.01), so the kernel stops with
    PlasticSolveStopped (the loop's early stop, exit 3), the traction not taken as applied."""
    from tribodem.contact import WindowTooSmallError
    from tribodem.contact.plastic_halfspace import PlasticSolveStopped

    a = 1e-4
    s = PlasticHalfSpace(nx=12, ny=12, nz=5, dx=a / 3, depth=a, x0=-2 * a, y0=-2 * a,
                         young=240e9, poisson=NU, yield_strength=680e6, hardening=2.5e9,
                         length=a)
    s.MAX_INCREMENT = 0.01  # type: ignore[misc]  (a tighter bound for a quick test)
    with pytest.raises(PlasticSolveStopped, match="plastic strain increment") as err:
        s.load(_hertz(s, 1.6e9, 1.2 * a, 0.6))
    assert isinstance(err.value, WindowTooSmallError)  # what the loop stops on
    assert not np.any(s.traction)
