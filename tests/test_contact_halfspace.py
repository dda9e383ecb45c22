"""First-body half-space solver (tamaas): Hertz, subsurface shear, gross-slip fretting cycle."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tribodem.contact import (
    ElasticBody,
    HalfSpaceSolver,
    HeightMap,
    HertzSphere,
    WindowTooSmallError,
    crossed_cylinders,
    cycle_offsets,
    max_shear,
    von_mises,
)
from tribodem.fretting import Criterion, FrettingLoop

LOAD, MU, AMPLITUDE = 100.0, 0.6, 0.3e-3


@pytest.fixture(scope="module")
def solver() -> HalfSpaceSolver:
    return HalfSpaceSolver()


@pytest.fixture(scope="module")
def hertz(solver: HalfSpaceSolver) -> HertzSphere:
    # crossed equal cylinders of D = 8 mm == sphere of R = D/2 = 4 mm on a flat
    return HertzSphere(4e-3, LOAD, solver.modulus)


@pytest.fixture(scope="module")
def loaded(solver: HalfSpaceSolver):
    solver.reset()
    return solver.solve_increment(0.0)


def test_hertz_peak_pressure_and_radius(solver, hertz, loaded) -> None:
    assert solver.n == 256 and solver.window == pytest.approx(10 * hertz.contact_radius)
    assert loaded.normal_load == pytest.approx(LOAD, rel=1e-6)
    assert loaded.max_pressure == pytest.approx(hertz.peak_pressure, rel=0.02)
    a = math.sqrt(loaded.contact_area / math.pi)
    assert a == pytest.approx(hertz.contact_radius, rel=0.02)
    # the pressure profile itself, not only its peak
    r = np.hypot(*np.meshgrid(solver.coords, solver.coords, indexing="ij"))
    err = np.abs(loaded.pressure - hertz.pressure(r)).max() / hertz.peak_pressure
    assert err < 0.05
    assert np.all(loaded.traction == 0.0) and np.all(loaded.slip == 0.0)


def test_subsurface_max_shear_at_048a(solver, hertz, loaded) -> None:
    a, p0 = hertz.contact_radius, hertz.peak_pressure
    ss = solver.subsurface_stress(loaded, "lower", depth=a, nz=41)
    assert ss.stress.shape == (41, solver.n, solver.n, 6)
    i0 = solver.n // 2
    # surface: sigma_zz = -p, sigma_xx = sigma_yy = -(1 + 2 nu)/2 p0 at the centre
    assert ss.stress[0, i0, i0, 2] == pytest.approx(-loaded.max_pressure, rel=1e-3)
    assert ss.stress[0, i0, i0, 0] == pytest.approx(-0.8 * p0, rel=0.02)
    # the maximum of the whole field lies on the axis (axisymmetric Hertz field)
    k, i, j = np.unravel_index(ss.tresca.argmax(), ss.tresca.shape)
    assert (i, j) == (i0, i0)
    col = ss.tresca[:, i0, i0]
    y0, y1, y2 = col[k - 1], col[k], col[k + 1]  # parabolic refinement around the grid max
    d = 0.5 * (y0 - y2) / (y0 - 2 * y1 + y2)
    z_max = ss.z[k] + d * (ss.z[1] - ss.z[0])
    t_max = y1 - 0.25 * (y0 - y2) * d
    z = np.linspace(1e-9, a, 200001)
    ref = hertz.axis_max_shear(0.3, z)
    assert z[ref.argmax()] / a == pytest.approx(0.48, abs=0.005)
    assert ref.max() / p0 == pytest.approx(0.31, abs=0.002)
    assert z_max == pytest.approx(z[ref.argmax()], rel=0.03)
    assert t_max == pytest.approx(ref.max(), rel=0.03)
    assert t_max / p0 == pytest.approx(0.31, abs=0.01)
    assert ss.von_mises.max() / p0 == pytest.approx(0.62, abs=0.015)


class _Recorder(Criterion):
    """A criterion that wears nothing and records: every increment, and the dissipated
    energy density deposited on both bodies' grids (J/m^2) -- the loop's own deposit."""

    name = "recorder"

    def __init__(self) -> None:
        self.increments: list = []
        self.energy_upper = self.energy_lower = None

    def begin_cycle(self, grid, solver) -> None:  # noqa: ANN001
        super().begin_cycle(grid, solver)
        if self.energy_upper is None:
            self.energy_upper = np.zeros((grid.n, grid.n))
            self.energy_lower = np.zeros((grid.n_track, grid.n))

    def add_increment(self, index: int, inc) -> None:  # noqa: ANN001
        self.increments.append(inc)
        self.energy_upper += inc.energy_density
        self.grid.deposit(self.energy_lower, inc.energy_density, inc)

    def depths(self):  # noqa: ANN201
        return np.zeros_like(self.energy_upper), np.zeros_like(self.energy_lower)


def _cycles(solver, amplitude: float, n_inc: int, cycles: int = 1):  # noqa: ANN001, ANN202
    rec = _Recorder()
    loop = FrettingLoop(solver, rec, amplitude=amplitude, n_increments=n_inc)
    hist = loop.run(cycles)
    return rec, loop.grid, hist


def test_gross_slip_cycle_traction_and_energy(solver) -> None:
    rec, grid, _ = _cycles(solver, AMPLITUDE, 16)
    incs = rec.increments
    assert len(incs) == 16
    for inc in incs:
        step = inc.offset - inc.start_offset
        assert abs(step) == pytest.approx(4 * AMPLITUDE / 16)
        inside = inc.pressure > 0
        q = inc.traction
        # q = mu p, along x, opposing the upper body's sliding direction
        assert np.allclose(q[..., 0], -np.sign(step) * MU * inc.pressure, rtol=1e-12, atol=0)
        assert np.all(q[..., 1] == 0.0) and np.all(q[~inside] == 0.0)
        assert np.allclose(inc.slip[inside, 0], step) and np.all(inc.slip[~inside] == 0.0)
        assert inc.normal_load == pytest.approx(LOAD, rel=1e-6)
    expected = MU * LOAD * 4 * AMPLITUDE
    by_increments = sum(float(i.energy_density.sum()) * solver.dx**2 for i in incs)
    assert by_increments == pytest.approx(expected, rel=0.02)
    cell = solver.dx**2
    assert float(rec.energy_upper.sum()) * cell == pytest.approx(expected, rel=0.02)
    assert float(rec.energy_lower.sum()) * cell == pytest.approx(expected, rel=0.02)
    # upper body: fixed spot of radius a; lower body: a track of length 2 (A + a)
    a = math.sqrt(incs[0].contact_area / math.pi)
    worn_x = grid.x_lower[rec.energy_lower.sum(axis=1) > 0]
    assert worn_x.min() == pytest.approx(-AMPLITUDE - a, abs=3 * solver.dx + 0.25 * AMPLITUDE)
    assert worn_x.max() == pytest.approx(AMPLITUDE + a, abs=3 * solver.dx + 0.25 * AMPLITUDE)
    spot = grid.x_upper[rec.energy_upper.sum(axis=1) > 0]
    assert spot.max() - spot.min() < 2 * a + 2 * solver.dx
    # density on the upper spot centre: mu p0 * 4A (the spot is always in contact)
    i0 = solver.n // 2
    assert rec.energy_upper[i0, i0] == pytest.approx(
        MU * incs[0].max_pressure * 4 * AMPLITUDE, rel=1e-6
    )


def test_sliding_subsurface_traction_signs(solver) -> None:
    solver.reset()
    solver.solve_increment(0.0)
    inc = solver.solve_increment(1e-5)  # upper body slides towards +x
    i0 = solver.n // 2
    lower = solver.subsurface_stress(inc, "lower", nz=9)
    upper = solver.subsurface_stress(inc, "upper", nz=9)
    q = MU * inc.pressure[i0, i0]
    # surface equilibrium: sigma_xz = -t_x (t: traction applied to that body, z into it)
    assert lower.stress[0, i0, i0, 4] == pytest.approx(-q, rel=1e-3)
    assert upper.stress[0, i0, i0, 4] == pytest.approx(q, rel=1e-3)
    # friction moves the yield point to the surface region for mu = 0.6
    assert lower.von_mises.max() > 0.62 * inc.max_pressure
    # the upper body sees the reversed shear: its field is the mirror image in x
    mirrored = np.roll(np.flip(upper.von_mises, axis=1), 1, axis=1)
    scale = lower.von_mises.max()
    assert np.abs(lower.von_mises - mirrored).max() < 0.01 * scale
    assert np.abs(lower.von_mises - upper.von_mises).max() > 0.1 * scale


def test_height_map_surfaces_match_callables() -> None:
    up, lo = crossed_cylinders()
    ref = HalfSpaceSolver(n=64)
    x = np.linspace(-1.5e-3, 1.5e-3, 601)
    xx, yy = np.meshgrid(x, x, indexing="ij")
    maps = HalfSpaceSolver(
        HeightMap.centred(up(xx, yy), x[1] - x[0]),
        HeightMap.centred(lo(xx, yy), x[1] - x[0]),
        n=64,
        window=ref.window,
    )
    p_ref = ref.solve_increment(2e-4).pressure
    p_map = maps.solve_increment(2e-4).pressure
    assert np.abs(p_map - p_ref).max() < 0.01 * p_ref.max()
    with pytest.raises(ValueError, match="height map covers"):
        maps.solve_increment(1.0e-3)


def test_stress_helpers_on_known_states() -> None:
    s = np.zeros((2, 6))
    s[0, 0] = 100.0  # uniaxial
    s[1, 5] = 50.0  # pure shear xy
    assert von_mises(s) == pytest.approx([100.0, 50.0 * math.sqrt(3)])
    assert max_shear(s) == pytest.approx([50.0, 50.0])


def test_window_too_small_is_refused() -> None:
    with pytest.raises(WindowTooSmallError, match="enlarge window"):
        HalfSpaceSolver(n=32, window=1.5e-4).solve_increment(0.0)


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"load": -1.0}, "load"),
        ({"friction": float("nan")}, "friction"),
        ({"n": 15}, "n"),
        ({"regime": "partial"}, "regime"),
        ({"window": 0.0}, "window"),
        ({"upper_material": ElasticBody(poisson=0.3)}, "upper and lower"),
    ],
)
def test_bad_input_is_refused(kwargs, field) -> None:
    if "upper_material" in kwargs:
        kwargs = {"upper": crossed_cylinders()[0]}
    with pytest.raises(ValueError, match=field):
        HalfSpaceSolver(**kwargs)


def test_bad_cycle_and_material_input_is_refused() -> None:
    with pytest.raises(ValueError, match="n_increments"):
        cycle_offsets(3e-4, 10)
    with pytest.raises(ValueError, match="amplitude"):
        cycle_offsets(-3e-4, 8)
    with pytest.raises(ValueError, match="poisson"):
        ElasticBody(poisson=0.5)
    assert cycle_offsets(1.0, 8).tolist() == [0.5, 1.0, 0.5, 0.0, -0.5, -1.0, -0.5, 0.0]


@pytest.fixture(scope="module")
def cj() -> HalfSpaceSolver:
    return HalfSpaceSolver(regime="ciavarella-jaeger")


def _delta_star(s: HalfSpaceSolver) -> float:
    """Mindlin's gross-slip displacement mu kappa d for the default Hertz contact, m."""
    s.reset()
    inc = s.solve_increment(0.0)
    return MU * s.kappa * s.approach(inc.pressure, s.gap(0.0))


def test_ciavarella_jaeger_matches_mindlin_loading(cj, hertz) -> None:
    assert cj.kappa == pytest.approx((2 - 0.3) / (2 * (1 - 0.3)))
    d_star = _delta_star(cj)
    assert d_star == pytest.approx(MU * cj.kappa * hertz.approach, rel=0.005)
    for frac in (0.3, 0.7):
        cj.reset()
        cj.solve_increment(0.0)
        inc = cj.solve_increment(frac * d_star)
        q_total = -float(inc.traction[..., 0].sum()) * cj.dx**2
        mindlin = MU * LOAD * (1 - (1 - frac) ** 1.5)  # Johnson eq 7.43
        assert q_total == pytest.approx(mindlin, rel=0.01)
        c = math.sqrt(inc.stick.sum() * cj.dx**2 / math.pi)
        assert c == pytest.approx(
            hertz.contact_radius * (1 - q_total / (MU * LOAD)) ** (1 / 3), rel=0.03
        )
        slip = inc.pressure > 0
        assert np.all(np.abs(inc.traction[..., 0]) <= MU * inc.pressure * (1 + 1e-12))
        assert np.allclose(
            np.abs(inc.traction[slip & ~inc.stick, 0]), MU * inc.pressure[slip & ~inc.stick]
        )
        assert np.all(inc.slip[inc.stick] == 0.0)


def _second_cycle_energy(s: HalfSpaceSolver, amplitude: float, n_inc: int) -> float:
    _, _, hist = _cycles(s, amplitude, n_inc, cycles=2)
    return hist.rows[1]["dissipated_energy_J"]


def test_ciavarella_jaeger_gross_slip_loop_energy(cj) -> None:
    d_star = _delta_star(cj)
    e = _second_cycle_energy(cj, AMPLITUDE, 16)
    loop = MU * LOAD * (4 * AMPLITUDE - 3.2 * d_star)  # Mindlin-Deresiewicz gross-slip loop
    assert e == pytest.approx(MU * LOAD * 4 * AMPLITUDE, rel=0.02)
    assert abs(e - loop) < 0.05 * 3.2 * MU * LOAD * d_star


def test_ciavarella_jaeger_partial_slip_loop_energy(cj) -> None:
    d_star = _delta_star(cj)
    e = _second_cycle_energy(cj, 0.5 * d_star, 8)
    r = 1 - 0.5**1.5  # Q* / (mu P) at half of delta* (Johnson eq 7.43)
    # loop energy, Johnson eq 7.59 written with delta* = mu kappa a^2 / R
    w = 4.8 * MU * LOAD * d_star * (1 - (1 - r) ** (5 / 3) - 5 * r / 6 * (1 + (1 - r) ** (2 / 3)))
    assert e == pytest.approx(w, rel=0.03)
    assert e < 0.1 * MU * LOAD * 4 * 0.5 * d_star  # far below the gross-slip work
