"""Fretting geometries: [contact] geometry and per-body materials, the
Hertz line contact on the periodic half-space, the window check per direction, bad input."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from conftest import run_tribodem
from scipy.integrate import quad

from tribodem.contact import ElasticBody, WindowTooSmallError, contact_modulus
from tribodem.contact.geometry import (
    SEED_RADIUS,
    CrossedCylinders,
    CylinderOnFlat,
    FlatPunch,
    HertzCylinder,
    HertzSphere,
    load_height_map,
    punch_contact_radius,
    punch_load,
)
from tribodem.fretting.case import FrettingCase, build_loop, build_solver, check_window
from tribodem.fretting.config import resolve_config
from tribodem.io.config import ConfigError
from tribodem.io.stl import heightmap_to_triangles, write_stl

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"

#: two different bodies: bearing steel on a titanium alloy (Pa, -)
STEEL = {"young_upper": 210e9, "poisson_upper": 0.3}
TI = {"young_lower": 110e9, "poisson_lower": 0.34}


def _cfg(**contact: object):  # noqa: ANN202 - a FrettingConfig
    return resolve_config(None, overrides={"contact": contact})


def test_default_is_the_seed_case_defined_once() -> None:
    c = _cfg().contact
    assert c.geometry == "crossed_cylinders"
    assert c.radius_upper == c.radius_lower == CrossedCylinders().radius_upper == SEED_RADIUS
    assert c.load == 100.0 and c.load_per_length is None
    es = contact_modulus(ElasticBody(), ElasticBody())
    assert FrettingCase.of(_cfg()).hertz_radius == pytest.approx(
        HertzSphere(SEED_RADIUS, 100.0, es).contact_radius, rel=1e-12)
    # diameter still sets both radii; an explicit radius wins
    d = _cfg(diameter=6e-3, radius_upper=2e-3).contact
    assert (d.radius_upper, d.radius_lower) == (2e-3, 3e-3)


def test_per_body_materials_give_the_pair_modulus() -> None:
    cfg = _cfg(geometry="sphere_on_flat", n=32, **STEEL, **TI)
    s = build_solver(FrettingCase.of(cfg))
    up, lo = ElasticBody(210e9, 0.3), ElasticBody(110e9, 0.34)
    assert (s.upper_material, s.lower_material) == (up, lo)
    assert s.modulus == pytest.approx(contact_modulus(up, lo), rel=1e-15)
    # young / poisson alone still set both bodies
    s2 = build_solver(FrettingCase.of(_cfg(n=32, young=200e9, poisson=0.28)))
    assert s2.upper_material == s2.lower_material == ElasticBody(200e9, 0.28)


LINE = {"geometry": "cylinder_on_flat", "radius": 4e-3, "load_per_length": 1e5, "n": 256,
        "tolerance": 1e-10, **STEEL, **TI}


@pytest.fixture(scope="module")
def line() -> tuple[object, object, HertzCylinder]:
    """Cylinder on flat, P' = 1e5 N/m, two different bodies, 256^2 on the window periodic
    along the axis (``[elastic] line_model = "periodic-2d"``), default window."""
    cfg = resolve_config(None, overrides={"contact": LINE,
                                          "elastic": {"line_model": "periodic-2d"}})
    s = build_solver(FrettingCase.of(cfg))
    es = contact_modulus(ElasticBody(210e9, 0.3), ElasticBody(110e9, 0.34))
    return s, s.solve_increment(0.0), HertzCylinder(4e-3, 1e5, es)


def test_line_contact_on_one_section_by_default_matches_hertz() -> None:
    """The same case by default: one plane-strain cross-section of 256 points, the same
    window and load; p0 and the half-width within 1 % (measured +0.005 % and -0.4 %, half
    a grid cell: the contact width counted in cells)."""
    s = build_solver(FrettingCase.of(_cfg(**LINE)))
    r = s.solve_increment(0.0)
    es = contact_modulus(ElasticBody(210e9, 0.3), ElasticBody(110e9, 0.34))
    h = HertzCylinder(4e-3, 1e5, es)
    assert r.pressure.shape == (256, 1) and s.contact == "line"
    assert s.load == pytest.approx(1e5 * s.window, rel=1e-12)
    assert r.normal_load == pytest.approx(s.load, rel=1e-6)
    assert s.window == pytest.approx(10 * h.half_width, rel=1e-9)
    assert r.max_pressure == pytest.approx(h.peak_pressure, rel=0.01)
    assert r.contact_area / (2 * s.window) == pytest.approx(h.half_width, rel=0.01)


def test_line_contact_matches_hertz_plane_strain(line) -> None:
    s, r, h = line
    assert s.contact == "line" and "line" in s.capabilities.contacts
    # load: P' over the window's length, the total on the window
    assert s.load == pytest.approx(1e5 * s.window, rel=1e-12)
    assert r.normal_load == pytest.approx(s.load, rel=1e-6)
    assert s.window == pytest.approx(10 * h.half_width, rel=1e-9)
    # an infinitely long cylinder: the pressure does not vary along y (the axis)
    assert np.ptp(r.pressure, axis=1).max() <= 1e-9 * r.max_pressure
    p = r.pressure[:, s.n // 2]
    # p0 = sqrt(P' E* / (pi R)) within 2 % (measured +0.82 %)
    assert r.max_pressure == pytest.approx(h.peak_pressure, rel=0.02)
    # a = sqrt(4 P' R / (pi E*)) within 2 %: from the contact area (area / (2 W), measured
    # -0.39 %) and from the elliptic profile p^2 = p0^2 (1 - x^2/a^2) (measured -0.91 %)
    assert r.contact_area / (2 * s.window) == pytest.approx(h.half_width, rel=0.02)
    x, m = s.coords, p > 0
    slope, icept = np.polyfit(x[m] ** 2, p[m] ** 2, 1)
    assert math.sqrt(-icept / slope) == pytest.approx(h.half_width, rel=0.02)
    # the profile: rms error 2 %, largest 8 % at the contact edges (the sqrt's steep flank
    # on a grid of a / 12.8; measured 1.4 % / 6.0 %)
    err = (p - h.pressure(x)) / h.peak_pressure
    print(f"line contact: p0 {r.max_pressure / h.peak_pressure - 1:+.4f}, a(area) "
          f"{r.contact_area / (2 * s.window) / h.half_width - 1:+.4f}, a(fit) "
          f"{math.sqrt(-icept / slope) / h.half_width - 1:+.4f}, profile rms "
          f"{np.sqrt(np.mean(err[m] ** 2)):.4f} max {np.abs(err).max():.4f}")
    assert np.sqrt(np.mean(err[m] ** 2)) <= 0.02 and np.abs(err).max() <= 0.08


def test_line_contact_window_checked_along_x_only(line) -> None:
    s, r, h = line
    # the contact touches both y edges (periodic along the axis) and is accepted
    assert (r.pressure[:, 0] > 0).any() and (r.pressure[:, -1] > 0).any()
    # subsurface default depth: 3 half-widths (not 3 sqrt(area / pi))
    ss = s.subsurface_stress(r, "lower", nz=3)
    assert ss.z[-1] == pytest.approx(3 * r.contact_area / (2 * s.window), rel=1e-12)
    # along x the contact must stay inside the window; along y it may reach the edges
    on_y = np.zeros((s.n, s.n))
    on_y[1:-1, 0] = on_y[1:-1, -1] = 1.0
    s._check_window(on_y, 0.0)
    on_x = np.zeros((s.n, s.n))
    on_x[-1, 5] = 1.0
    with pytest.raises(WindowTooSmallError, match="enlarge window"):
        s._check_window(on_x, 0.0)
    from tribodem.contact import HalfSpaceSolver

    u, lo = CylinderOnFlat().recessions()
    with pytest.raises(ValueError, match="ciavarella-jaeger"):
        HalfSpaceSolver(u, lo, load=10.0, n=32, regime="ciavarella-jaeger")


def test_total_load_and_load_per_length_are_the_same_case() -> None:
    a = build_solver(FrettingCase.of(_cfg(geometry="cylinder_on_flat", load_per_length=2e5,
                                          n=32)))
    b = build_solver(FrettingCase.of(_cfg(geometry="cylinder_on_flat", load=2e5 * a.window,
                                          window=a.window, n=32)))
    assert b.load == pytest.approx(a.load, rel=1e-12) and b.window == a.window
    # total load without a window: W^3 = 10^2 4 P R / (pi E*), i.e. 10 half-widths
    c = build_solver(FrettingCase.of(_cfg(geometry="cylinder_on_flat", load=50.0, n=32)))
    assert c.window == pytest.approx(
        10 * HertzCylinder(SEED_RADIUS, 50.0 / c.window, c.modulus).half_width, rel=1e-9)


def test_check_window_per_geometry() -> None:
    # line contact: 4 half-widths along x, with P' = load / window
    with pytest.raises(ConfigError, match=r"contact.window = 0.0001 m .*half-width"):
        check_window(FrettingCase.of(_cfg(geometry="cylinder_on_flat", window=1e-4)))
    check_window(FrettingCase.of(_cfg(geometry="cylinder_on_flat", window=1e-3)))
    # punch: the contact radius beyond the flat face
    a = punch_contact_radius(0.25e-3, SEED_RADIUS, 100.0, contact_modulus(ElasticBody(),
                                                                          ElasticBody()))
    assert a > 0.25e-3
    with pytest.raises(ConfigError, match="rounded flat punch"):
        check_window(FrettingCase.of(_cfg(geometry="flat_punch", window=3.9 * a)))
    check_window(FrettingCase.of(_cfg(geometry="flat_punch", window=4.1 * a)))


def test_punch_load_closed_form_and_solved_contact() -> None:
    b, re, es = 0.2e-3, 3e-3, 1.3e11
    for a in (0.21e-3, 0.3e-3):
        # Sneddon's integral with r = a sin t (no end singularity)
        num = 2 * es / re * quad(lambda t, a=a: (a * math.sin(t)) ** 2 * (a * math.sin(t) - b),
                                 math.asin(b / a), math.pi / 2, epsabs=0, epsrel=1e-12)[0]
        assert punch_load(a, b, re, es) == pytest.approx(num, rel=1e-7)
    assert punch_load(0.3e-3, 0.0, re, es) == pytest.approx(
        4 * es * 0.3e-3**3 / (3 * re), rel=1e-12)  # Hertz for b = 0
    s = build_solver(FrettingCase.of(_cfg(geometry="flat_punch", n=128, tolerance=1e-9)))
    r = s.solve_increment(0.0)
    fp = FlatPunch()
    a = fp.contact_size(100.0, s.modulus)[0]
    assert math.sqrt(r.contact_area / math.pi) == pytest.approx(a, rel=0.03)


def test_height_maps_csv_npy_stl_and_the_lower_track(tmp_path: Path) -> None:
    dx, m = 25e-6, 41
    c = (np.arange(m) - m // 2) * dx
    x, y = np.meshgrid(c, c, indexing="ij")
    z = x**2 / (2 * 4e-3) + y**2 / (2 * 3e-3)
    np.savetxt(tmp_path / "u.csv", z, delimiter=",")
    np.save(tmp_path / "u.npy", z)
    np.save(tmp_path / "l.npy", -z)  # a lower body convex towards the upper one
    write_stl(tmp_path / "u.stl", heightmap_to_triangles(c, c, z))
    ref = load_height_map(tmp_path / "u.csv", "upper", dx)
    assert ref.values.shape == (m, m) and ref.extent[1] == pytest.approx(0.5e-3)
    for f in ("u.npy", "u.stl"):
        hm = load_height_map(tmp_path / f, "upper", dx)
        assert np.allclose(hm.values, ref.values, atol=1e-15)
    # the lower body: heights up, recession = max - z
    assert np.allclose(load_height_map(tmp_path / "u.npy", "lower", dx).values,
                       z.max() - z)
    # a lower map must cover the window plus the stroke along x
    cfg = _cfg(geometry="height_map", lower_map=str(tmp_path / "l.npy"), map_dx=dx, n=32,
               amplitude=0.1e-3)
    loop = build_loop(cfg)
    assert loop.solver.window < 1e-3 - 2 * 0.1e-3
    with pytest.raises(ConfigError, match=r"contact.lower_map = .*stroke"):
        check_window(FrettingCase.of(_cfg(geometry="height_map",
                                          lower_map=str(tmp_path / "l.npy"), map_dx=dx, n=32,
                                          window=0.9e-3)))


def _refused(tmp_path: Path, toml: str, *expect: str) -> None:
    cfg = tmp_path / "bad.toml"
    cfg.write_text(toml)
    p = run_tribodem("fretting", "run", "--config", str(cfg), "--out", str(tmp_path / "o"),
                     "--no-progress", timeout=120)
    assert p.returncode == 2, (p.returncode, p.stderr)
    assert "Traceback" not in p.stderr
    for e in expect:
        assert e in p.stderr, (e, p.stderr)
    assert not (tmp_path / "o" / "results.csv").exists()


@pytest.mark.parametrize(("name", "toml", "expect"), [
    ("negative radius", '[contact]\ngeometry = "sphere_on_flat"\nradius = -0.004\n',
     ("contact.radius", "-0.004")),
    ("negative edge radius", '[contact]\ngeometry = "flat_punch"\nedge_radius = -1e-3\n',
     ("contact.edge_radius", "-0.001")),
    ("foreign field", '[contact]\nradius = 0.004\n', ("contact.radius", "0.004",
                                                       "crossed_cylinders")),
    ("both loads", '[contact]\ngeometry = "cylinder_on_flat"\nload = 10.0\n'
     'load_per_length = 1e5\n', ("contact.load_per_length", "100000.0")),
    ("sphere window", '[contact]\ngeometry = "sphere_on_flat"\nwindow = 1e-4\n',
     ("contact.window", "0.0001")),
    ("line window", '[contact]\ngeometry = "cylinder_on_flat"\nload_per_length = 1e5\n'
     'window = 1e-4\n', ("contact.window", "0.0001", "along x")),
    ("line partial slip", '[contact]\ngeometry = "cylinder_on_flat"\n'
     'regime = "ciavarella-jaeger"\n[elastic]\nline_model = "periodic-2d"\n',
     ("regime = 'ciavarella-jaeger'", "line contact")),
    ("line debris", '[contact]\ngeometry = "cylinder_on_flat"\n[debris]\nevery = 2\n',
     ("debris.every = 2", "line contact")),
    ("line on elastic-plastic", 'solver = "elastic-plastic"\n[contact]\n'
     'geometry = "cylinder_on_flat"\n', ("contact.geometry", "line_contact")),
])
def test_bad_geometry_exits_2_naming_field_and_value(tmp_path: Path, name: str, toml: str,
                                                     expect: tuple[str, ...]) -> None:
    _refused(tmp_path, toml, *expect)


def test_bad_height_maps_exit_2(tmp_path: Path) -> None:
    z = np.zeros((21, 21))
    z[3, 4] = np.nan
    np.savetxt(tmp_path / "nan.csv", z, delimiter=",")
    _refused(tmp_path, '[contact]\ngeometry = "height_map"\nupper_map = "nan.csv"\n'
             'map_dx = 1e-5\n', "contact.upper_map", "nan.csv", "non-finite", "row 3")
    np.save(tmp_path / "line.npy", np.zeros(50))
    _refused(tmp_path, '[contact]\ngeometry = "height_map"\nupper_map = "line.npy"\n'
             'map_dx = 1e-5\n', "contact.upper_map", "line.npy", "shape (50,)")
    np.save(tmp_path / "ok.npy", np.zeros((5, 5)))
    _refused(tmp_path, '[contact]\ngeometry = "height_map"\nupper_map = "ok.npy"\n',
             "contact.upper_map", "ok.npy", "map_dx")
    # a flat map: the contact fills the window (no window can hold it)
    _refused(tmp_path, '[contact]\ngeometry = "height_map"\nupper_map = "ok.npy"\n'
             'map_dx = 1e-4\nn = 32\n', "contact.upper_map", "ok.npy", "flat")
    # a map smaller than the given window
    _refused(tmp_path, '[contact]\ngeometry = "height_map"\nupper_map = "ok.npy"\n'
             'map_dx = 1e-5\nwindow = 1e-4\n', "contact.upper_map", "ok.npy", "+-2e-05")


@pytest.mark.parametrize("example", ["cylinder_on_flat", "sphere_on_flat", "heightmap"])
def test_examples_run(tmp_path: Path, example: str) -> None:
    out = tmp_path / example
    p = run_tribodem("fretting", "run", "--config", str(EXAMPLES / f"fretting_{example}.toml"),
                     "--out", str(out), "--no-progress", "--cycles", "3", timeout=300)
    assert p.returncode == 0, p.stderr
    s = json.loads((out / "summary.json").read_text())
    case = s["contact_case"]
    assert s["cycles"] == 3 and s["wear_volume_lower_m3"] > 0
    if example == "cylinder_on_flat":
        assert case["contact"] == "line" and case["load_given"] == "load_per_length"
        assert case["load_per_length_N_per_m"] == pytest.approx(1e5, rel=1e-12)
    else:
        assert case["contact"] == "point" and case["load_given"] == "load"
    if example == "sphere_on_flat":
        assert case["upper"]["young_Pa"] == 210e9 and case["lower"]["young_Pa"] == 240e9
