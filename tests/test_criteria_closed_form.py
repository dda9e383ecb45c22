"""The ``s22`` and ``von_mises`` criteria against the closed-form Hertz subsurface field.

A frictionless sphere-on-flat contact (crossed equal cylinders of D = 8 mm are a sphere of
R = 4 mm on a flat) carries the same Hertz field at every position of the stroke, so after
one cycle the column search (seed 6.3, fig 6.4) must put the wear depth of the deepest
column where the closed-form axis field (Johnson, Contact Mechanics eq 3.72) falls back
below the threshold:

- S22: |sigma_zz(z)| = p0 / (1 + z^2/a^2)  ->  z = a sqrt(p0 / T - 1);
- von Mises on the axis: |sigma_zz - sigma_rr| (axisymmetric), rising from
  (1 - 2 nu)/2 p0 at the surface to 0.62 p0 at 0.48 a, the depth where it falls below T.

Tolerances: 1% (S22) and 3% (von Mises: its axis field bends more between the nz levels
the column search interpolates linearly); measured 0.05% and 0.8-1.7% on a 64^2 grid.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from tribodem.contact import HalfSpaceSolver, HertzSphere, cycle_offsets
from tribodem.fretting import TrackGrid, make_criterion

LOAD, NU, N_INC = 100.0, 0.3, 8


@pytest.fixture(scope="module")
def contact() -> tuple[HalfSpaceSolver, HertzSphere]:
    solver = HalfSpaceSolver(n=64, friction=0.0, load=LOAD)
    return solver, HertzSphere(4e-3, LOAD, solver.modulus)


def axis_stresses(h: HertzSphere, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """sigma_zz, sigma_rr on the axis at depths z (Pa), Johnson eq 3.72."""
    a, p0 = h.contact_radius, h.peak_pressure
    zeta = np.maximum(np.asarray(z, dtype=float) / a, 1e-12)
    sz = -p0 / (1 + zeta**2)
    sr = -p0 * ((1 + NU) * (1 - zeta * np.arctan(1 / zeta)) - 0.5 / (1 + zeta**2))
    return sz, sr


def one_cycle(solver: HalfSpaceSolver, crit) -> tuple[np.ndarray, np.ndarray]:  # noqa: ANN001
    """Wear depth maps (upper, lower) of ``crit`` after one frictionless cycle."""
    crit.set_increments(N_INC)
    grid = TrackGrid(n=solver.n, dx=solver.dx, pad=int(math.ceil(0.3e-3 / solver.dx)) + 1)
    solver.reset()
    solver.solve_increment(0.0)
    crit.begin_cycle(grid, solver)
    for i, s in enumerate(cycle_offsets(0.3e-3, N_INC)):
        crit.add_increment(i, solver.solve_increment(float(s)))
    return crit.depths()


def one_cycle_depth(solver: HalfSpaceSolver, name: str, threshold: float, depth: float,
                    nz: int) -> tuple[float, dict]:
    """Deepest wear of the upper body after one frictionless cycle of ``name``."""
    crit = make_criterion(name, yield_strength=threshold, depth=depth, nz=nz, samples=4)
    du, dl = one_cycle(solver, crit)
    assert du.max() > 0 and dl.max() > 0  # both bodies wear under the same field
    return float(du.max()), crit.info()


@pytest.mark.parametrize("ratio", [0.3, 0.6])
def test_s22_depth_is_where_sigma_zz_falls_below_the_threshold(contact, ratio) -> None:
    solver, h = contact
    a, p0 = h.contact_radius, h.peak_pressure
    t = ratio * p0
    depth, nz = 3.0 * a, 61
    got, info = one_cycle_depth(solver, "s22", t, depth, nz)
    ref = a * math.sqrt(p0 / t - 1.0)  # |sigma_zz| = p0 / (1 + z^2/a^2) = T
    assert info["saturated_columns_upper"] == 0
    assert got == pytest.approx(ref, rel=0.01)  # measured: 0.05%
    # the surface value of the field is the peak pressure (the largest |sigma_zz|)
    assert info["max_value_upper"] == pytest.approx(p0, rel=0.03)


@pytest.mark.parametrize("ratio", [0.4, 0.55])
def test_von_mises_depth_is_where_the_axis_field_falls_below_the_threshold(contact, ratio
                                                                          ) -> None:
    solver, h = contact
    a, p0 = h.contact_radius, h.peak_pressure
    t = ratio * p0

    def vm(z: float) -> float:
        sz, sr = axis_stresses(h, np.array([z]))
        return float(abs(sz[0] - sr[0]))

    z_peak = 0.48 * a  # maximum of the axis field (0.62 p0 for nu = 0.3)
    assert vm(z_peak) / p0 == pytest.approx(0.62, abs=0.01)
    ref = brentq(lambda z: vm(z) - t, z_peak, 5 * a)  # below the peak, falling through T
    depth, nz = 3.0 * a, 61
    got, info = one_cycle_depth(solver, "von_mises", t, depth, nz)
    assert got == pytest.approx(ref, rel=0.03)  # measured: 0.8%, 1.7%
    assert info["max_value_upper"] / p0 == pytest.approx(0.62, abs=0.02)


def test_threshold_above_the_field_wears_nothing(contact) -> None:
    solver, h = contact
    for name, ratio in (("s22", 1.05), ("von_mises", 0.7)):
        crit = make_criterion(name, yield_strength=ratio * h.peak_pressure, nz=17, samples=4)
        du, dl = one_cycle(solver, crit)
        assert du.max() == 0.0 and dl.max() == 0.0, name


def test_the_lower_track_gets_the_field_between_sampled_positions(contact) -> None:
    """Four samples of an eight-increment cycle (+A, 0, -A, 0: 300 um apart, three contact
    radii) of a field that is the same at every position: the lower body's wear depth
    along the track's centre line is the closed-form axis depth wherever the contact
    centre passed (|x| <= A), not only at the sampled positions (each shift takes the
    two samples' fields interpolated to it)."""
    solver, h = contact
    a, p0 = h.contact_radius, h.peak_pressure
    t = 0.3 * p0
    crit = make_criterion("s22", yield_strength=t, depth=3.0 * a, nz=61, samples=4)
    _, dl = one_cycle(solver, crit)
    ref = a * math.sqrt(p0 / t - 1.0)
    grid = crit.grid
    line = dl[:, grid.n // 2]
    passed = np.abs(grid.x_lower) <= 0.3e-3 - grid.dx
    assert passed.sum() > 3 * 0.3e-3 / a  # the track centre line, several radii long
    assert line[passed] == pytest.approx(ref, rel=0.01)
