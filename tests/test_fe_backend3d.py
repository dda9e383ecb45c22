"""The ``fe3d`` first-body backend (CalculiX, 3D crossed cylinders, half model) behind the contract.

Closed forms and tolerances (Lu (2018): EN24T crossed cylinders R = 4 mm, 100 N, mu 0.6):

* Hertz point contact (Johnson 4.22-4.23, a sphere of R on a flat): on the window, the peak
  pressure p0 = 3 P / (2 pi a^2) within 3 %, the contact radius a = (3 P R / (4 E*))^(1/3)
  within 3 % from the pressure's second moment (Hertz: int r^2 p dA / P = 2 a^2 / 5, less
  the bilinear interpolant's own h^2 / 3), the window load equal to P within 1e-3; at the FE
  nodes, a least-squares fit of p^2 = p0^2 (1 - r^2 / a^2) within 3 %;
* gross slip: |Q| = mu P within 1 % at +A and -A, the traction on the upper body opposing
  its motion; -q.s >= 0 at every window point (to 1e-9 of its maximum) in every increment;
* morphing (seed eqs 3.7-3.8): an imposed paraboloid scar d0 (1 - r^2 / b^2), b = 1.5 h,
  centred between node columns: the worn volume from the morphed mesh equals its
  closed-form volume pi d0 b^2 / 2 within 1 % (the scar read on the window's cells, each
  node column moved by its tributary share; measured -0.16 % / -0.28 %, upper / lower: the
  cells' own sum, the morph adds nothing to it) and the hexahedra's volume loss equals that
  worn volume to 1e-9; on wear maps with sharp rims the morphed mesh loses the maps' volume
  sum(d) dx^2 to 1e-12, and with ``max_wear_kink`` it turns by at most 0.03 at any node;
* the installed command ``tribodem fretting run --solver fe3d --quick`` runs a cycle and
  resumes for a second (2 ccx jobs), writing its results, jobs.csv and the decks.

ccx budget on 1 thread (measured, docs/fe3d.md, BENCHMARKS.md): one h = a/3
job (compact bodies 4 a, ``fe3d_cases.COMPACT``; +-10 um, 4 increments; 62 s with Debian's
ccx, 131 s on bodies 6 a) shared by the Hertz and slip tests, and two h = a jobs for the
command (the quick preset: +-0.3 mm, 64 ccx increments a cycle; ~56 s with Debian's ccx).
Everything skips without ccx.
"""

from __future__ import annotations

import csv
import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from conftest import run_tribodem
from fe3d_cases import AMPLITUDE, COMPACT, LOAD, P0, A, fe3d_case, fe3d_solver

from tribodem.contact import ElasticBody
from tribodem.contact.fe.backend3d import FE3DContactSolver, hex_volumes, mesh_columns
from tribodem.contact.fe.ccx import INSTALL_COMMAND
from tribodem.contact.fe.slope import steepest
from tribodem.contact.geometry import crossed_cylinders

pytestmark = pytest.mark.skipif(shutil.which("ccx") is None,
                                reason=f"CalculiX ccx not on PATH ({INSTALL_COMMAND})")

# --- morphing (no ccx run) ------------------------------------------------------------------

def test_morphing_worn_volume_is_exact(tmp_path: Path) -> None:
    """A paraboloid scar 3 elements wide, off the columns, through set_surfaces: its volume."""
    solver = fe3d_solver(tmp_path)
    base_up, base_lo = crossed_cylinders()
    h = solver._mesh0.h_fine
    d0, b = 0.3 * h, 1.5 * h  # peak depth, radius (m), inside the fine zone and window

    def paraboloid(x0: float):  # noqa: ANN202
        def wear(x: np.ndarray, y: np.ndarray) -> np.ndarray:
            return d0 * np.maximum(0.0, 1 - ((x - x0) ** 2 + y * y) / (b * b))
        return wear

    wu, wl = paraboloid(0.3 * h), paraboloid(-0.2 * h)
    solver.set_surfaces(lambda x, y: base_up(x, y) + wu(x, y),
                        lambda x, y: base_lo(x, y) + wl(x, y))
    mesh0 = solver._mesh0
    morphed = solver.morphed_mesh()
    exact = 0.5 * math.pi * d0 * b * b  # both halves of the body, m^3
    v0, v1 = hex_volumes(mesh0.nodes, mesh0.elements), hex_volumes(morphed.nodes,
                                                                     morphed.elements)
    n_low = mesh0.n_lower
    cols = mesh_columns(mesh0)
    for body, inward, lost in (
            ("upper", 1.0, v0[n_low:].sum() - v1[n_low:].sum()),
            ("lower", -1.0, v0[:n_low].sum() - v1[:n_low].sum())):
        volume = solver.worn_volume(body, morphed)
        assert volume == pytest.approx(exact, rel=1e-2)  # the window's cells' sum
        assert 2 * float(lost) == pytest.approx(volume, rel=1e-9)  # the hexahedra's loss
        top = cols[body][..., 0]
        dz = (morphed.nodes[top, 2] - mesh0.nodes[top, 2]) * inward
        assert dz.min() >= 0.0 and dz.max() < d0
    np.testing.assert_array_equal(morphed.nodes[:, :2], mesh0.nodes[:, :2])  # x, y kept
    # eq 3.8: every element of a worn column keeps its share of the fine section
    k = int(mesh0.info["fine_layers"])
    col = cols["upper"][0, int(np.argmin(np.abs(solver._xs)))]
    d = morphed.nodes[col[0], 2] - mesh0.nodes[col[0], 2]
    before, after = np.diff(mesh0.nodes[col[:k + 1], 2]), np.diff(morphed.nodes[col[:k + 1], 2])
    height = abs(mesh0.nodes[col[0], 2] - mesh0.nodes[col[k], 2])
    assert d > 0.0
    np.testing.assert_allclose(after / before, (height - d) / height, rtol=1e-9)


def test_a_slope_limited_morph_keeps_the_worn_volume(tmp_path: Path) -> None:
    """``max_wear_slope``: the morphed surfaces step by at most s x the column spacing and
    carry the same worn volume as the unlimited morph (a paraboloid pit, slope 0.4 at its
    rim, 0.13 between the columns it is projected on, limited to 0.1)."""
    base_up, base_lo = crossed_cylinders()
    meshes = {}
    for s in (None, 0.1):
        solver = fe3d_solver(tmp_path / str(s), max_wear_slope=s, max_wear_kink=None)
        h = solver._mesh0.h_fine
        d0, b = 0.3 * h, 1.5 * h

        def pit(x: np.ndarray, y: np.ndarray, d0: float = d0, b: float = b) -> np.ndarray:
            return d0 * np.maximum(0.0, 1 - (x * x + y * y) / (b * b))
        solver.set_surfaces(lambda x, y: base_up(x, y) + pit(x, y),
                            lambda x, y: base_lo(x, y) + pit(x, y))
        meshes[s] = (solver, solver.morphed_mesh())
    (plain, m0), (limited, m1) = meshes[None], meshes[0.1]
    for body, inward in (("upper", 1.0), ("lower", -1.0)):
        assert limited.worn_volume(body, m1) == pytest.approx(plain.worn_volume(body, m0),
                                                              rel=1e-9)
        top = mesh_columns(m1)[body][..., 0]
        w = (m1.nodes[top, 2] - limited._mesh0.nodes[top, 2]) * inward
        steps = steepest(w, *limited._grids[body])  # checked against numpy in test_fe_slope
        lim = limited.slope_limits[body]
        assert lim.steepest_before > 0.12 and steps <= 0.1 * 1.001
        assert lim.steepest_after == pytest.approx(steps, rel=1e-9)
    # a job failing on the steeper surfaces names the remedy; with the limit set, nothing
    assert "max_wear_slope = 0.1" in plain._steepness_hint()
    assert limited._steepness_hint() == ""
    with pytest.raises(ValueError, match="max_wear_slope"):
        fe3d_solver(tmp_path / "bad", max_wear_slope=0.0)


def _sharp_scar_maps(solver: FE3DContactSolver) -> tuple[np.ndarray, np.ndarray]:
    """Wear maps on the fretting loop's cells ([y, x]: the window's points for the upper
    body, the track's for the lower) with sharp rims: a flat-bottomed pit 0.3 h deep
    (r < 2.2 h) inside a ring 0.45 h deep (2.2 h < r < 2.6 h), off the y = 0 plane (centre
    y = 0.4 h: the map is not symmetric about it), the lower one drawn out along x over the
    stroke's length +-1.3 h; zero elsewhere. Depth steps of 0.3 h between neighbouring
    cells (slopes ~3 between cells, ~0.24 between node columns after the tributary morph)."""
    h, dx, c = solver._mesh0.h_fine, solver.dx, solver.coords
    k = int(round(solver.pad / dx))
    maps = []
    for x, half in ((c, 0.0), ((np.arange(c.size + 2 * k) - c.size // 2 - k) * dx, 1.3 * h)):
        gx, gy = np.meshgrid(x, c)
        r = np.hypot(np.maximum(np.abs(gx) - half, 0.0), gy - 0.4 * h)
        maps.append(np.where(r < 2.2 * h, 0.3 * h, np.where(r < 2.6 * h, 0.45 * h, 0.0)))
    return maps[0], maps[1]


def _set_maps(solver: FE3DContactSolver, up: np.ndarray, lo: np.ndarray) -> None:
    """The maps as the fretting loop gives them: base recession + a bilinear height map
    (``HeightMap``, values [x, y]) on the loop's grids."""
    from tribodem.contact.geometry import HeightMap

    base_up, base_lo = crossed_cylinders()
    dx, c = solver.dx, solver.coords
    k = int(round(solver.pad / dx))
    hu = HeightMap(up.T, dx, dx, float(c[0]), float(c[0]))
    hl = HeightMap(lo.T, dx, dx, float(c[0]) - k * dx, float(c[0]))
    solver.set_surfaces(lambda x, y: base_up(x, y) + hu(x, y),
                        lambda x, y: base_lo(x, y) + hl(x, y))


def _mesh_depth(solver: FE3DContactSolver, mesh, body: str) -> np.ndarray:  # noqa: ANN001
    """The morphed mesh's worn depth per surface column of ``body``, m [ny, nx]."""
    top = mesh_columns(mesh)[body][..., 0]
    inward = 1.0 if body == "upper" else -1.0
    return (mesh.nodes[top, 2] - solver._mesh0.nodes[top, 2]) * inward


def test_hat_integrals_are_exact() -> None:
    """:func:`.mesh.hat_integrals` on a graded node line: over the whole line each hat's
    integral is its tributary length (h_l + h_r) / 2; over [x_i, x_i + t h_r] it is
    t h_r - t^2 h_r / 2 (closed form of the falling half); intervals outside the line give
    0 and a column sums to the interval's length inside the line (all to 1e-15 m)."""
    from tribodem.contact.fe.mesh import hat_integrals

    x = np.array([0.0, 1.0, 1.5, 3.5, 4.0])
    whole = hat_integrals(x, np.array([-1.0]), np.array([5.0]))[:, 0]
    np.testing.assert_allclose(whole, [0.5, 0.75, 1.25, 1.25, 0.25], atol=1e-15)
    t, hr = 0.3, 2.0  # from node 2 (x = 1.5) into its right element, 2 long
    w = hat_integrals(x, np.array([1.5]), np.array([1.5 + t * hr]))[:, 0]
    assert w[2] == pytest.approx(t * hr - t * t * hr / 2, abs=1e-15)
    assert w[3] == pytest.approx(t * t * hr / 2, abs=1e-15)
    assert w[[0, 1, 4]].tolist() == [0.0, 0.0, 0.0]
    lo, hi = np.array([-2.0, -0.5, 0.2, 3.9]), np.array([-1.0, 0.7, 3.7, 4.6])
    sums = hat_integrals(x, lo, hi).sum(axis=0)
    np.testing.assert_allclose(sums, np.clip(hi, 0, 4) - np.clip(lo, 0, 4), atol=1e-15)


def test_tributary_morph_carries_the_wear_maps_volume_exactly(tmp_path: Path) -> None:
    """``[fe] morph = "tributary"`` (the default): on wear maps with sharp rims, off the
    symmetry plane (:func:`_sharp_scar_maps`), the morphed half mesh of each body loses
    exactly the maps' volume sum(d) dx^2 (the fretting loop's), to 1e-12 (measured 2e-16:
    rounding), and the hexahedra's volume loss equals it to 1e-9; every column depth lies
    in [0, the deepest cell]. The lumped projection it replaced (``morph =
    "projection"``, the interpolated maps sampled at dx / 2 on y >= 0 only) misses by more
    than 1e-4 here (measured +21 % / +17 %, upper / lower: it doubles the half y >= 0 of a
    map that is not symmetric about y = 0; the tributary morph folds the map onto the half
    model; on the seed's 7-cycle shear maps, nearly symmetric, it missed by -0.05 %)."""
    solver = fe3d_solver(tmp_path, max_wear_slope=None, max_wear_kink=None, **COMPACT)
    up, lo = _sharp_scar_maps(solver)
    _set_maps(solver, up, lo)
    morphed = solver.morphed_mesh()
    cell = solver.dx ** 2
    v0 = hex_volumes(solver._mesh0.nodes, solver._mesh0.elements)
    v1 = hex_volumes(morphed.nodes, morphed.elements)
    n_low = solver._mesh0.n_lower
    proj = fe3d_solver(tmp_path / "p", max_wear_slope=None, max_wear_kink=None,
                       morph="projection", **COMPACT)
    _set_maps(proj, up, lo)
    old = proj.morphed_mesh()
    for body, m, lost in (("upper", up, v0[n_low:].sum() - v1[n_low:].sum()),
                          ("lower", lo, v0[:n_low].sum() - v1[:n_low].sum())):
        volume = solver.worn_volume(body, morphed)
        assert volume == pytest.approx(float(m.sum()) * cell, rel=1e-12)
        assert 2 * float(lost) == pytest.approx(volume, rel=1e-9)
        w = _mesh_depth(solver, morphed, body)
        assert w.min() >= 0.0 and w.max() <= m.max() * (1 + 1e-12)
        assert abs(proj.worn_volume(body, old) / volume - 1.0) > 1e-4
    with pytest.raises(ValueError, match="morph"):
        fe3d_solver(tmp_path / "bad", morph="sampled")


def test_a_kink_limited_morph_keeps_the_volume_and_has_no_kinks(tmp_path: Path) -> None:
    """``[fe] max_wear_kink = 0.03`` (the default) after ``max_wear_slope = 0.1``: on the
    sharp-rimmed maps (their tributary morph turns by up to 0.25 at a node column, 0.10
    after the slope limit) the morphed surfaces of both bodies change slope by at most 0.03
    at every node along x and y (the y = 0 row against its mirror image too) and step by at
    most 0.1 x the column spacing (both within the limiters' 0.1 % tolerance; measured 0.0294 /
    0.0296 and 0.061 / 0.067), keep every depth >= 0, and lose the maps' volume to 1e-12
    (measured 0 / 2e-16); a wide shallow paraboloid within both limits is left bit for
    bit."""
    from tribodem.contact.fe.slope import kinks

    solver = fe3d_solver(tmp_path, **COMPACT)
    assert (solver.morph, solver.max_wear_slope, solver.max_wear_kink) == ("tributary", 0.1,
                                                                          0.03)
    up, lo = _sharp_scar_maps(solver)
    _set_maps(solver, up, lo)
    morphed = solver.morphed_mesh()
    for body, m in (("upper", up), ("lower", lo)):
        xs, ys = solver._grids[body]
        w = _mesh_depth(solver, morphed, body)
        kl = solver.kink_limits[body]
        assert kl.converged and kl.kink_before > 0.09  # after the slope limit
        # numpy's own count of the kinks (x, y, and the y = 0 row against its mirror)
        sx, sy = np.diff(w, axis=1) / np.diff(xs), np.diff(w, axis=0) / np.diff(ys)[:, None]
        worst = max(np.abs(np.diff(sx, axis=1)).max(), np.abs(np.diff(sy, axis=0)).max(),
                    2 * np.abs(sy[0]).max())
        assert worst == pytest.approx(kinks(w, xs, ys, mirror_y0=True), rel=1e-6, abs=1e-12)
        assert worst <= 0.03 * 1.001 and steepest(w, xs, ys) <= 0.1 * 1.001
        assert w.min() >= 0.0
        assert solver.worn_volume(body, morphed) == pytest.approx(float(m.sum()) * solver.dx**2,
                                                                  rel=1e-12)
        assert kl.moved_volume > 0.0
    # a surface within both limits: untouched
    gentle = fe3d_solver(tmp_path / "g", **COMPACT)
    plain = fe3d_solver(tmp_path / "o", max_wear_slope=None, max_wear_kink=None, **COMPACT)
    h = gentle._mesh0.h_fine
    base_up, base_lo = crossed_cylinders()
    for s in (gentle, plain):
        def bowl(x: np.ndarray, y: np.ndarray) -> np.ndarray:
            return 0.02 * h * np.maximum(0.0, 1 - (x * x + y * y) / (6 * h) ** 2)
        s.set_surfaces(lambda x, y: base_up(x, y) + bowl(x, y),
                       lambda x, y: base_lo(x, y) + bowl(x, y))
    np.testing.assert_array_equal(gentle.morphed_mesh().nodes, plain.morphed_mesh().nodes)
    with pytest.raises(ValueError, match="max_wear_kink"):
        fe3d_solver(tmp_path / "bad", max_wear_kink=-1.0)


def test_deck_fields_fit_ccx(tmp_path: Path) -> None:
    """ccx reads each data field as at most 20 characters: a minimum increment written as
    ``8.333333333333334e-06`` (48 increments a cycle) was read as 8.3 and ccx stopped ("a
    time point precedes the minimum time tmin"). Every field of the deck fits, and every
    ``*STATIC`` starts within its step with a minimum below the initial increment. A
    retry's softer contact (``penalty_scale`` 1/2) halves the normal penalty and the stick
    slope and nothing else of them (mu, the tension)."""
    for n_inc, material in ((48, "elastic"), (12, "elastic-plastic"), (16, "elastic")):
        solver = fe3d_solver(tmp_path, n_increments=n_inc, material=material)
        deck = solver.write_deck(tmp_path / f"job{n_inc}.inp", solver._mesh0, 1e-6)
        lines = deck.read_text().splitlines()
        data = [line for k, line in enumerate(lines)
                if not line.startswith("*") and lines[k - 1] != "*HEADING"]
        long = [f for line in data for f in line.split(",") if len(f.strip()) > 20]
        assert not long
        static = [lines[k + 1] for k, line in enumerate(lines) if line == "*STATIC"]
        soft = solver.write_deck(tmp_path / "soft.inp", solver._mesh0, 1e-6,
                                 penalty_scale=0.5).read_text().splitlines()
        for key in ("*SURFACE BEHAVIOR", "*FRICTION"):  # a retry's softer contact: k / 2
            rows = [(lines[k + 1], soft[k + 1]) for k, line in enumerate(lines)
                    if line.startswith(key)]
            assert rows
            for hard, half in rows:
                assert float(half.split(",")[1]) == pytest.approx(
                    0.5 * float(hard.split(",")[1]) if key == "*FRICTION" else
                    float(hard.split(",")[1]), rel=1e-9)
                assert float(half.split(",")[0]) == pytest.approx(
                    float(hard.split(",")[0]) if key == "*FRICTION" else
                    0.5 * float(hard.split(",")[0]), rel=1e-9)
        assert len(static) >= 6
        for row in static:
            initial, period, minimum, maximum = (float(v) for v in row.split(","))
            assert 0.0 < minimum < initial <= maximum <= period == 1.0


def test_loading_friction_sets_the_seating_and_loading_coefficient(tmp_path: Path) -> None:
    """``loading_friction``: "low" writes 0.001 for the seating and loading steps and mu from
    the first quarter; "full" writes mu from the seating on, and nothing else of the deck
    changes (the stick slopes, the pair, the steps); "auto" (the default) is "full" for
    elastic-plastic bodies and "low" for elastic ones; the cycle reports say which ran."""
    decks = {}
    for value, material, runs in (("low", "elastic", "low"), ("full", "elastic", "full"),
                                  ("auto", "elastic", "low"),
                                  ("auto", "elastic-plastic", "full")):
        solver = fe3d_solver(tmp_path / value, loading_friction=value, material=material)
        assert solver.loading_friction == runs
        path = solver.write_deck(tmp_path / f"{value}.inp", solver._mesh0, 1e-6)
        lines = path.read_text().splitlines()
        decks[value, material] = lines
        changed = [lines[k + 2].split(",")[0] for k, line in enumerate(lines)
                   if line == "*CHANGE FRICTION, INTERACTION=SI"]
        assert changed == (["0.001", "0.6"] if runs == "low" else ["0.6", "0.6"])
        assert solver._attempt_report()["loading_mu"] == (1e-3 if runs == "low" else 0.6)
    low, full = decks["low", "elastic"], decks["full", "elastic"]
    diff = [(a, b) for a, b in zip(low, full, strict=True) if a != b]
    assert diff == [("0.001, " + diff[0][0].split(", ")[1], "0.6, " + diff[0][0].split(", ")[1])]
    assert decks["auto", "elastic"] == low
    with pytest.raises(ValueError, match="loading_friction = 'half' is not allowed"):
        fe3d_solver(tmp_path / "bad", loading_friction="half")


def test_cycle_increments_cap_the_quarters_increments_only(tmp_path: Path) -> None:
    """``cycle_increments``: the quarters' largest ccx increment is 4 / (n_increments x
    ceil(cycle_increments / n_increments)) of a quarter's time (the quick preset: 8 and 64,
    1/16), for either material and beside ``plastic_increments`` (the larger rules); only
    the quarters' ``*STATIC`` lines change (the first increment is at most the largest), not
    the output times (``TQUARTER``), the seating or the loading; below 4 or not an integer
    is refused."""
    def quarters(**kw: float) -> tuple[list[float], list[str]]:
        solver = fe3d_solver(tmp_path, n_increments=8, **kw)
        lines = solver.write_deck(tmp_path / "job.inp", solver._mesh0, 1e-6).read_text()
        lines = lines.splitlines()
        static = [lines[k + 1] for k, line in enumerate(lines) if line == "*STATIC"]
        return [float(s.split(",")[3]) for s in static[2:6]], lines

    plain, lines0 = quarters()
    assert plain == [0.5] * 4
    capped, lines = quarters(cycle_increments=64)
    assert capped == [1 / 16] * 4
    changed = [k for k, (a, b) in enumerate(zip(lines0, lines, strict=True)) if a != b]
    statics = [k + 1 for k, line in enumerate(lines) if line == "*STATIC"]
    assert changed == statics[2:6]  # the quarters' *STATIC data lines, nothing else
    assert quarters(cycle_increments=20)[0] == pytest.approx([4 / 24] * 4, rel=1e-11)  # 8 x 3
    plastic = dict(material="elastic-plastic", plastic_increments=32)
    assert quarters(**plastic)[0] == [1 / 8] * 4
    assert quarters(cycle_increments=64, **plastic)[0] == [1 / 16] * 4
    assert quarters(cycle_increments=16, **plastic)[0] == [1 / 8] * 4
    for bad in (3, 8.5):
        with pytest.raises(ValueError, match=f"cycle_increments = {bad!r} is not allowed"):
            fe3d_solver(tmp_path, cycle_increments=bad)


def test_quarters_start_at_a_quarter_of_the_mindlin_slip(tmp_path: Path) -> None:
    """Every quarter of a cycle starts at a reversal, where the contact sticks again: its
    first ccx increment slides REVERSAL_SLIDE (1/4) of the Cattaneo-Mindlin gross-slip
    displacement, for identical bodies delta = 3 mu P (2 - nu) / (8 G a) (Johnson 7.42, both
    bodies' compliances), and may grow to the deck's largest increment, elastic or
    elastic-plastic (deck only, no ccx run)."""
    from tribodem.contact.fe.backend3d import REVERSAL_SLIDE

    def quarters(solver: FE3DContactSolver, name: str) -> list[list[float]]:
        deck = solver.write_deck(tmp_path / name, solver._mesh0, seat=1e-7).read_text()
        steps = deck.split("*STEP")[3:7]  # seating, load, then the four quarters
        return [[float(v) for v in st.split("*STATIC\n")[1].split("\n")[0].split(",")]
                for st in steps]

    body = ElasticBody()
    delta = 3.0 * 0.6 * LOAD * (2.0 - body.poisson) / (8.0 * body.shear * A)
    assert 3.1e-6 < delta < 3.2e-6  # the seed's case: 3.15 um
    amplitude = 0.3e-3
    plastic = fe3d_solver(tmp_path / "p", amplitude=amplitude, n_increments=16,
                      material="elastic-plastic")
    # (the solver's R comes from the surfaces' curvatures: a agrees to ~1e-6)
    assert plastic.gross_slip_displacement == pytest.approx(delta, rel=1e-5)
    elastic = fe3d_solver(tmp_path / "e", amplitude=amplitude, n_increments=16)
    for solver, name in ((plastic, "p.inp"), (elastic, "e.inp")):
        largest = 4.0 / (16 * solver.cycle_refine)
        for first, period, smallest, most in quarters(solver, name):
            assert first * amplitude == pytest.approx(REVERSAL_SLIDE * delta, rel=1e-5)
            assert (period, most) == (1.0, largest) and smallest <= first


def test_fe3d_refuses_other_geometries(tmp_path: Path) -> None:
    from tribodem.contact.geometry import cylinder, flat

    with pytest.raises(ValueError, match="crossed cylinders"):
        FE3DContactSolver(fe3d_case(upper=cylinder(8e-3, axis="y"), lower=flat()),
                          workdir=tmp_path)
    with pytest.raises(ValueError, match="size_factor"):
        fe3d_solver(tmp_path, size_factor=40.0)
    with pytest.raises(ValueError, match="mode"):
        fe3d_solver(tmp_path, mode="chained")


def test_fe_mesh_fields_left_out_are_each_backends_own_and_set_are_taken() -> None:
    """[fe] h_over_a / size_factor left out: each backend's own (fe3d h = a/3, bodies 8 a;
    fe a/4, 40 a); set, they reach the backend as given, fe3d's 0.25 too (a/4; before
    config_version 2 it was read as fe3d's own a/3). The ccx time limit: the backend's own
    (4 h) unless set."""
    from tribodem.fretting import FrettingConfig, build_solver

    own = build_solver(FrettingConfig.model_validate({"solver": "fe3d"}))
    assert (own.h_over_a, own.size_factor) == (pytest.approx(1 / 3), 8.0)
    set_ = build_solver(FrettingConfig.model_validate(
        {"solver": "fe3d", "fe": {"h_over_a": 0.25, "size_factor": 10.0, "timeout": 60}}))
    assert (set_.h_over_a, set_.size_factor) == (0.25, 10.0)
    assert (own.timeout, set_.timeout) == (14400.0, 60.0)
    line = build_solver(FrettingConfig.model_validate(
        {"solver": "fe", "contact": {"geometry": "cylinder_on_flat", "radius": 4e-3,
                                     "load_per_length": 1e5}}))
    assert (line.h_over_a, line.size_factor) == (0.25, 40.0)


def test_an_old_default_fe3d_checkpoint_resumes_on_fe3ds_own_mesh() -> None:
    """A checkpoint written before config_version 2 records [fe] h_over_a = 0.25 and
    size_factor = 40.0 (every field was; fe3d ran its own a/3, 8 a on them): resumed as
    ``fretting run --resume`` resumes it (its config as the base, checked against it), the
    solver is built on a/3 and 8 a again."""
    from conftest import before_config_v2

    from tribodem.fretting import (
        FrettingConfig,
        build_solver,
        check_resume,
        recorded_config,
        resolve_config,
    )

    old = before_config_v2(FrettingConfig(solver="fe3d"))
    cfg = resolve_config(None, base=recorded_config(old))
    check_resume(cfg, {"config": old, "cycles_done": 1}, Path("checkpoint.npz"))
    solver = build_solver(cfg)
    assert (solver.h_over_a, solver.size_factor) == (pytest.approx(1 / 3), 8.0)


# --- one coarse ccx job: the loading and a gross-slip cycle -----------------------------------

@pytest.fixture(scope="module")
def served(tmp_path_factory: pytest.TempPathFactory):  # noqa: ANN201
    solver = fe3d_solver(tmp_path_factory.mktemp("fe3d"), **COMPACT)
    solver.reset()
    loaded = solver.solve_increment(0.0)
    solver.begin_cycle()
    incs = [solver.solve_increment(float(o)) for o in solver.offsets]
    return solver, loaded, incs


def test_hertz_point_contact(served) -> None:  # noqa: ANN001
    solver, loaded, _ = served
    assert len(solver.jobs) == 1  # the loading and the first cycle: one job
    job, rep = solver.jobs[0], solver.report()["cycles"][0]  # the attempt it converged on
    assert (rep["attempt_refine"], rep["contact_penalty_scale"]) == (job.refine,
                                                                     job.penalty_scale)
    cell = solver.dx**2
    assert loaded.normal_load == pytest.approx(LOAD, rel=1e-3)
    p = loaded.pressure
    assert p.max() == pytest.approx(P0, rel=0.03)
    c = solver.coords
    r2 = c[:, None] ** 2 + c[None, :] ** 2
    # the window holds the bilinear interpolant of the nodal pressures, whose second moment
    # exceeds the nodes' by h^2 / 3 (h^2 / 6 per direction, exact on the uniform fine grid):
    # measured +5.4 % on a before, +0.9 % after removing it at h = a/3 (bodies 6 a; 4 a: +0.4 %)
    h = solver._mesh0.h_fine
    a_moment = math.sqrt(2.5 * (float((r2 * p).sum() / p.sum()) - h * h / 3.0))
    assert a_moment == pytest.approx(A, rel=0.03)
    np.testing.assert_allclose(p[:, 1:], p[:, 1:][:, ::-1], rtol=1e-9)  # mirror, y = 0
    # contact area: window points where the nodes' contact indicator interpolates to >= 1/2
    # (the FE contact edge lies between a contact node and a free one): measured +15.8 % of
    # pi a^2 at h = a/3 on bodies 6 a, +14.4 % on 4 a (the pressure's support on the window,
    # one node further: +97 %)
    assert loaded.contact_area == pytest.approx(math.pi * A * A, rel=0.25)
    # the model itself: the nodal pressures' Hertz fit
    st = solver._states[0]
    xg, yg = np.meshgrid(solver._xs, solver._ys)
    pn = st["p"]
    ok = pn > 0.05 * pn.max()
    m = np.column_stack([np.ones(int(ok.sum())), (xg**2 + yg**2)[ok]])
    coef, *_ = np.linalg.lstsq(m, pn[ok] ** 2, rcond=None)
    assert math.sqrt(-coef[0] / coef[1]) == pytest.approx(A, rel=0.03)
    assert loaded.direction == 0.0 and not loaded.slip.any() and not loaded.traction.any()
    assert float(loaded.pressure.sum()) * cell == pytest.approx(loaded.normal_load)


def test_gross_slip_and_signs(served) -> None:  # noqa: ANN001
    solver, _, incs = served
    mu, cell = solver.friction, solver.dx**2
    for inc in incs:
        raw = -np.einsum("ijk,ijk->ij", inc.traction, inc.slip)
        assert raw.min() >= -1e-9 * raw.max()  # -q.s >= 0 before any clipping
        assert np.all(inc.slip[..., 0] * inc.direction >= 0.0)  # slides the way it moves
        assert inc.stick is not None and inc.stick.shape == (solver.n, solver.n)
        # mirror symmetry about y = 0: qx even, qy odd
        tol = 1e-9 * float(np.abs(inc.traction).max())
        np.testing.assert_allclose(inc.traction[:, 1:, 0], inc.traction[:, 1:, 0][:, ::-1],
                                   rtol=0, atol=tol)
        np.testing.assert_allclose(inc.traction[:, 1:, 1], -inc.traction[:, 1:, 1][:, ::-1],
                                   rtol=0, atol=tol)
    for k in (0, 2):  # +A and -A: gross slip, the traction opposes the upper body's motion
        inc = incs[k]
        q = float(inc.traction[..., 0].sum()) * cell
        assert inc.normal_load == pytest.approx(LOAD, rel=1e-3)
        assert -inc.direction * q / (mu * inc.normal_load) == pytest.approx(1.0, abs=0.01)
        assert not inc.stick.any()
    # the cycle dissipates less than the rigid-slip work 4 A mu P: the bodies' compliance
    # takes part of each stroke. Cattaneo-Mindlin (Johnson 7.41), delta* = 3 mu P / (16 a)
    # sum (2 - nu) / G: from virgin bodies to gross slip 0.8 delta* of the stroke is not
    # slid, at each of the two reversals 1.6 delta*: E = 4 mu P (A - delta*) for the fresh
    # cycle 0 -> +A -> 0 -> -A -> 0; within 5 % (measured at A = 10 um, h = a/3: -1.6 % on
    # bodies 6 a, -2.4 % on these 4 a: the finite bodies' compliance, fe3d_cases.COMPACT)
    energy = sum(float(i.energy_density.sum()) * cell for i in incs)
    poisson, shear = ElasticBody().poisson, ElasticBody().shear
    delta_star = 3 * mu * LOAD / (16 * A) * 2 * (2 - poisson) / shear
    assert energy == pytest.approx(4 * mu * LOAD * (AMPLITUDE - delta_star), rel=0.05)


def test_subsurface_stress_on_the_axis(served) -> None:  # noqa: ANN001
    """Hertz point contact on the axis (Johnson 3.71): sigma_zz = -p0 / (1 + z^2 / a^2)
    within 12 % of p0 at h = a/3 (linear elements, the column profile linear between nodes
    a/3 apart: measured 10.4 % at z = a/2 on bodies 6 a, 9.2 % on 4 a); both bodies alike
    under the load."""
    solver, loaded, incs = served
    lower = solver.subsurface_stress(loaded, "lower", depth=2 * A, nz=21)
    upper = solver.subsurface_stress(loaded, "upper", depth=2 * A, nz=21)
    i = solver.n // 2
    szz = lower.stress[:, i, i, 2]
    np.testing.assert_allclose(szz, -P0 / (1 + (lower.z / A) ** 2), rtol=0, atol=0.12 * P0)
    np.testing.assert_allclose(upper.stress[:, i, i, 2], szz, rtol=0, atol=0.06 * P0)
    assert lower.stress.shape == (21, solver.n, solver.n, 6)
    # at the surface sigma_xz = q under the lower body and -q in the upper one
    inc = incs[0]
    q = inc.traction[i, i, 0]
    sl = solver.subsurface_stress(inc, "lower", depth=A, nz=3)
    su = solver.subsurface_stress(inc, "upper", depth=A, nz=3)
    assert sl.stress[0, i, i, 4] == pytest.approx(q, rel=0.1)
    assert su.stress[0, i, i, 4] == pytest.approx(-q, rel=0.1)


# --- the command ------------------------------------------------------------------------------

def test_quick_preset_runs_and_resumes(tmp_path: Path) -> None:
    """``tribodem fretting run --solver fe3d --quick`` (the seed's case on the quick fe3d
    preset: h = a, 8 increments) for one cycle, then ``--resume --cycles 2``, through the
    installed command. The quick run once stopped with exit 3 (a 21-character *STATIC
    field, then "too many cutbacks" at the first reversal); the second cycle's
    morphed mesh carries the loop's first-cycle volume (the projection, within 1 %). (The
    resumed run's results.csv was measured identical to an uninterrupted 2-cycle run's,
    docs/fe3d.md.)"""
    out = tmp_path / "quick"
    r = run_tribodem("fretting", "run", "--solver", "fe3d", "--quick", "--cycles", "1",
                     "--out", str(out), "--no-progress")
    assert r.returncode == 0, r.stderr
    r = run_tribodem("fretting", "run", "--out", str(out), "--resume", "--cycles", "2",
                     "--no-progress")
    assert r.returncode == 0, r.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["cycles"] == 2 and summary["stopped"] is None
    assert summary["wear_volume_upper_m3"] > 0 and summary["wear_volume_lower_m3"] > 0
    jobs = list(csv.DictReader((out / "fe" / "jobs.csv").open()))
    assert [(j["cycle"], j["elements"], j["refine"]) for j in jobs] == [("1", "800", "1"),
                                                                       ("2", "800", "1")]
    rows = list(csv.DictReader((out / "results.csv").open()))
    assert [row["cycle"] for row in rows] == ["1", "2"]
    first = float(rows[0]["wear_volume_upper_m3"])
    assert first > 0.0
    assert float(jobs[1]["worn_volume_upper_m3"]) == pytest.approx(first, rel=1e-2)
    for k in (1, 2):
        assert (out / "fe" / f"cycle_{k:04d}" / "job.dat").is_file()


# --- elastic-plastic bodies: Johnson's first yield -------------------------------------------
