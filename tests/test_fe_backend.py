"""The ``fe`` first-body backend (CalculiX, plane-strain cylinder on flat) behind the contract.

Closed forms and tolerances:

* Hertz line contact (Johnson 4.45): p0 = sqrt(P' E* / (pi R)) within 2 % (peak window
  pressure), half-width a = sqrt(4 P' R / (pi E*)) within 2 % from a least-squares fit of
  p^2 = p0^2 (1 - x^2 / a^2) over the FE contact nodes (within 4 % over the window cells
  above p0 / 2: the mapping's linear interpolation between nodes);
* gross slip: |Q| = mu P' within 1 % at both ends of the stroke, opposing the upper body's
  motion (base.py: traction on the upper body); energy density -q.s >= 0;
* morphing (seed eqs 3.7-3.8): the area lost by the elements equals the imposed depth
  profile's integral (exact for a profile linear between columns) to 1e-9;
* the column depths morphing takes (:func:`surface_projection`, the lumped L2 projection
  onto the nodes' linear shape functions): a linear (bilinear) function projects to its
  value at each shape function's centroid x_i + (h_right - h_left) / 3, within 1e-4 (the
  midpoint rule); a parabolic scar narrower than two elements keeps its area 4/3 d0 c
  within 0.5 % (the nodal values alone: -30 %); a cosine two elements long keeps
  sinc^2(pi / 2) = 4 / pi^2 of its amplitude within 1e-3.

ccx runs use coarse meshes (h = a/4, one job for the Hertz and slip checks; h = a/2 for the
command-line run) and skip without ccx.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import shutil
import stat
from pathlib import Path

import numpy as np
import pytest
from conftest import run_tribodem

from tribodem.contact import ElasticBody, contact_modulus
from tribodem.contact.base import ContactCase
from tribodem.contact.fe import PadOnFlat, cylinder_on_flat, hertz_line
from tribodem.contact.fe.backend import FEContactSolver, cell_average
from tribodem.contact.fe.ccx import INSTALL_COMMAND
from tribodem.contact.fe.mesh import (
    element_areas,
    morph_columns,
    surface_profile,
    surface_projection,
    worn_area,
)
from tribodem.contact.fe.options import FEOptions
from tribodem.contact.fe.results import tributary_length
from tribodem.contact.fe.validate import half_width_fit
from tribodem.contact.geometry import cylinder, flat

needs_ccx = pytest.mark.skipif(shutil.which("ccx") is None,
                               reason=f"CalculiX ccx not on PATH ({INSTALL_COMMAND})")

E_STAR = contact_modulus(ElasticBody(), ElasticBody())
LOAD = 1e5  # N/m
P0, A = hertz_line(LOAD, 4e-3, E_STAR)
WINDOW = 10 * A


# --- no solver needed -------------------------------------------------------------------------

def _mesh(h_over_a: float = 0.25):
    return cylinder_on_flat(PadOnFlat(radius=4e-3, a=A, h_fine=h_over_a * A, stroke=20e-6,
                                      size_factor=20))


@pytest.mark.parametrize("body", ["lower", "upper"])
def test_morphing_volume_is_exact(body: str) -> None:
    """A tent profile with its kinks on columns: the elements lose exactly its area."""
    mesh = _mesh()
    x, y0 = surface_profile(mesh, body)
    h = mesh.h_fine
    d0, c = 0.3 * h, 6 * h  # depth at x = 0 and half-width of the tent, m
    wear = d0 * np.maximum(0.0, 1.0 - np.abs(x) / c)
    morphed = morph_columns(mesh, body, wear)
    _, y1 = surface_profile(morphed, body)
    inward = -1.0 if body == "lower" else 1.0  # the flat recedes down, the pad up
    np.testing.assert_allclose((y1 - y0) * inward, wear, rtol=0, atol=1e-18)
    exact = d0 * c  # integral of the tent, m^2 per m
    lost = float(element_areas(mesh).sum() - element_areas(morphed).sum())
    assert lost == pytest.approx(exact, rel=1e-9)
    assert worn_area(mesh, morphed, body) == pytest.approx(exact, rel=1e-12)
    np.testing.assert_array_equal(morphed.nodes[:, 0], mesh.nodes[:, 0])  # columns straight
    # eq 3.8: every element of a worn column keeps its share of the fine section's height
    cols = mesh.columns[body]
    k = mesh.fine_layers
    j = int(np.argmin(np.abs(x)))
    before = np.diff(mesh.nodes[cols[j, :k + 1], 1])
    after = np.diff(morphed.nodes[cols[j, :k + 1], 1])
    height = abs(mesh.nodes[cols[j, 0], 1] - mesh.nodes[cols[j, k], 1])
    np.testing.assert_allclose(after / before, (height - d0) / height, rtol=1e-9)
    deep = cols[:, k:].ravel()  # below the fine section nothing moves
    np.testing.assert_array_equal(morphed.nodes[deep], mesh.nodes[deep])


def test_morphing_smooth_profile_and_limit() -> None:
    """A parabolic scar sampled on the columns: trapezoid rule error bound; too deep refused."""
    mesh = _mesh()
    x, _ = surface_profile(mesh, "lower")
    d0, c = 1e-6, 0.8 * A
    wear = d0 * np.maximum(0.0, 1.0 - (x / c) ** 2)
    area = worn_area(mesh, morph_columns(mesh, "lower", wear), "lower")
    exact = 4.0 / 3.0 * d0 * c
    h = mesh.h_fine  # trapezoid error of a parabola: (2c) h^2 |f''| / 12, plus the two ends
    assert abs(area - exact) <= 2 * c * h * h * 2 * d0 / c**2 / 12 + 2 * d0 * h
    with pytest.raises(ValueError, match="fine section"):
        morph_columns(mesh, "lower", np.full(x.size, mesh.info["fine_depth"]))


def test_surface_projection_is_volume_true() -> None:
    """Linear functions: the shape functions' centroids; a narrow scar keeps its area."""
    xs = np.array([-400.0, -200, -100, -50, 0, 50, 100, 200, 400]) * 1e-6
    left = np.diff(xs, prepend=xs[0])  # element lengths either side of each node
    right = np.diff(xs, append=xs[-1])
    centroid = xs + (right - left) / 3.0  # of each node's (half) hat function
    box = (-1.0, 1.0, -1.0, 1.0)
    mean = surface_projection(lambda x, y: 2e-6 + 0.01 * x, xs, None, box, 5e-7)
    np.testing.assert_allclose(mean, 2e-6 + 0.01 * centroid, rtol=1e-4, atol=0)
    ys = np.array([0.0, 30, 90, 250]) * 1e-6  # from the symmetry plane
    cy = ys + (np.diff(ys, append=ys[-1]) - np.diff(ys, prepend=ys[0])) / 3.0
    mean2 = surface_projection(lambda x, y: (1 + 300 * x) * (2 - 900 * y), xs, ys, box, 5e-7)
    np.testing.assert_allclose(mean2, np.outer(2 - 900 * cy, 1 + 300 * centroid), rtol=1e-4)
    d0, c, x0 = 1e-6, 30e-6, 20e-6  # a scar 1.2 elements wide, off the nodes

    def scar(x: np.ndarray, y: np.ndarray) -> np.ndarray:
        return d0 * np.maximum(0.0, 1.0 - ((x - x0) / c) ** 2)

    exact = 4.0 / 3.0 * d0 * c
    area = float(np.sum(surface_projection(scar, xs, None, box, 1e-6) * tributary_length(xs)))
    assert area == pytest.approx(exact, rel=5e-3)
    nodal = float(np.sum(scar(xs, 0 * xs) * tributary_length(xs)))
    assert nodal < 0.75 * exact  # what sampling at the nodes alone would remove
    cut = surface_projection(lambda x, y: np.ones_like(x), xs, None, (-150e-6, 1, -1, 1), 1e-6)
    assert cut[0] == 0.0 and cut[3] == pytest.approx(1.0, rel=1e-12)  # zero outside the box
    # a wave two elements long (the shortest the nodes carry) keeps 0.4 of its amplitude
    grid = np.arange(-40, 41) * 50e-6
    wave = surface_projection(lambda x, y: np.cos(np.pi * x / 50e-6), grid, None, box, 1e-6)
    assert np.abs(wave[5:-5]).max() == pytest.approx(4.0 / np.pi**2, rel=1e-3)


def test_a_resumed_run_keeps_the_jobs_of_an_older_jobs_csv(tmp_path: Path) -> None:
    """``prior_job_rows``: a ``jobs.csv`` written before the ``penalty_scale`` column
    existed keeps its rows on resume (the column filled with 1, the scale those jobs ran
    at); a file with a column this version does not know starts afresh."""
    from tribodem.contact.fe import jobs

    old = [c for c in jobs.JOB_COLUMNS if c != "penalty_scale"]
    path = tmp_path / "jobs.csv"
    path.write_text(",".join(old) + "\n" + ",".join(str(k) for k in range(len(old))) + "\n")
    rows = jobs.prior_job_rows(path)
    assert len(rows) == 1 and len(rows[0]) == len(jobs.JOB_COLUMNS)
    got = dict(zip(jobs.JOB_COLUMNS, rows[0], strict=True))
    assert got["penalty_scale"] == "1" and got["cycle"] == "0" and got["deck"] == "11"
    path.write_text(",".join(jobs.JOB_COLUMNS + ("future",)) + "\n")
    assert jobs.prior_job_rows(path) == []
    assert jobs.prior_job_rows(tmp_path / "none.csv") == []


def test_retries_halve_the_increments_then_the_penalty(tmp_path: Path,
                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    """A job that does not converge is retried at half the increments, then also with the
    contact's penalty stiffnesses halved (``attempt_settings``), each deck named for it; the
    last failure is raised (ccx replaced by a stand-in that converges only on a soft deck)."""
    from types import SimpleNamespace

    from tribodem.contact.fe import jobs
    from tribodem.contact.fe.ccx import CcxConvergenceError

    assert [jobs.attempt_settings(a) for a in range(5)] == [
        (1, 1.0), (2, 1.0), (2, 0.5), (4, 0.5), (4, 0.25)]
    ran: list[str] = []

    def stand_in(deck: Path, **kw: object) -> SimpleNamespace:
        ran.append(deck.name)
        if "soft" not in deck.name:
            raise CcxConvergenceError("ccx did not converge", "*ERROR: too many cutbacks", deck)
        return SimpleNamespace(job=deck.with_suffix(""), cached=False)

    monkeypatch.setattr(jobs, "run_ccx", stand_in)
    written: list[tuple[str, int, float]] = []

    def write(refine: int, name: str, scale: float) -> Path:
        written.append((name, refine, scale))
        deck = tmp_path / f"{name}.inp"
        deck.write_text(f"{refine} {scale}\n")
        return deck

    run, refine, scale, _, _ = jobs.run_job(write, 2, 1, 60.0, None)
    assert written == [("job", 1, 1.0), ("job_refine2", 2, 1.0), ("job_refine2_soft2", 2, 0.5)]
    assert ran == ["job.inp", "job_refine2.inp", "job_refine2_soft2.inp"]
    assert (refine, scale, run.job.name) == (2, 0.5, "job_refine2_soft2")
    written.clear()
    with pytest.raises(CcxConvergenceError):
        jobs.run_job(write, 1, 1, 60.0, None)
    assert [w[0] for w in written] == ["job", "job_refine2"]


def test_retry_from_last_starts_where_the_previous_job_converged(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """``run_job(start=k)`` writes and runs no attempt before ``k`` (``[fe] retry_from =
    "last"``); ``attempt_index`` inverts ``attempt_settings``; ``start`` beyond ``retries``
    runs the last attempt only."""
    from types import SimpleNamespace

    from tribodem.contact.fe import jobs

    for a in range(9):
        assert jobs.attempt_index(*jobs.attempt_settings(a)) == a
    with pytest.raises(ValueError, match="no attempt"):
        jobs.attempt_index(3, 1.0)
    ran: list[str] = []
    monkeypatch.setattr(jobs, "run_ccx", lambda deck, **kw: (
        ran.append(deck.name), SimpleNamespace(job=deck.with_suffix(""), cached=False))[1])

    def write(refine: int, name: str, scale: float) -> Path:
        deck = tmp_path / f"{name}.inp"
        deck.write_text(f"{refine} {scale}\n")
        return deck

    _, refine, scale, _, _ = jobs.run_job(write, 4, 1, 60.0, None, start=3)
    assert ran == ["job_refine4_soft2.inp"] and (refine, scale) == (4, 0.5)
    ran.clear()
    _, refine, scale, _, _ = jobs.run_job(write, 2, 1, 60.0, None, start=4)
    assert ran == ["job_refine2_soft2.inp"] and (refine, scale) == (2, 0.5)


def test_a_backend_keeps_its_last_attempt_across_a_resume(tmp_path: Path) -> None:
    """A ccx backend records the attempt its last job converged on in its state (a
    resumed run starts where the uninterrupted one would); a state saved before that was
    kept takes it from the run's ``jobs.csv`` (its last row's refine and penalty scale);
    ``retry_from = "first"`` always starts at the configured job."""
    from fe3d_cases import fe3d_solver

    from tribodem.contact.fe import jobs

    s = fe3d_solver(tmp_path, retries=4, retry_from="last")
    assert s._first_attempt() == 0
    s._last_attempt = 4
    assert s._first_attempt() == 4
    state = s.state_dict()
    other = fe3d_solver(tmp_path / "b", retries=3, retry_from="last")
    other.load_state_dict(state)
    assert other._first_attempt() == 3  # no further than its own retries
    first = fe3d_solver(tmp_path / "c", retries=4)
    first.load_state_dict(state)
    assert first._last_attempt == 4 and first._first_attempt() == 0
    old = {k: v for k, v in state.items() if k != "last_attempt"}
    (tmp_path / "d").mkdir()
    row = dict.fromkeys(jobs.JOB_COLUMNS, "0") | {"refine": "4", "penalty_scale": "0.5"}
    jobs.write_csv(tmp_path / "d" / "jobs.csv", jobs.JOB_COLUMNS, [list(row.values())])
    old["workdir"] = str(tmp_path / "d")
    older = fe3d_solver(None, retries=4, retry_from="last")
    older.load_state_dict(old)
    assert older._first_attempt() == 3
    with pytest.raises(ValueError, match="retry_from = 'middle' is not allowed"):
        fe3d_solver(tmp_path / "e", retry_from="middle")


def test_a_failed_deck_is_not_run_again(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A deck that did not converge leaves a ``.failed`` record (its key, ccx's message):
    the same deck is skipped the next time (a resumed run goes on from the next attempt),
    a changed deck runs, and a known failure as the last attempt raises with ccx's first
    message and the record's path."""
    from types import SimpleNamespace

    from tribodem.contact.fe import jobs
    from tribodem.contact.fe.ccx import CcxConvergenceError

    ran: list[str] = []

    def stand_in(deck: Path, **kw: object) -> SimpleNamespace:
        ran.append(deck.name)
        if "soft" not in deck.name:
            raise CcxConvergenceError("ccx did not converge",
                                      "*ERROR: increment size smaller than minimum", deck)
        return SimpleNamespace(job=deck.with_suffix(""), cached=False)

    monkeypatch.setattr(jobs, "run_ccx", stand_in)
    text = {"body": "mesh A"}

    def write(refine: int, name: str, scale: float) -> Path:
        deck = tmp_path / f"{name}.inp"
        deck.write_text(f"{text['body']} {refine} {scale}\n")
        return deck

    with pytest.raises(CcxConvergenceError):  # the cycle stops after one retry
        jobs.run_job(write, 1, 1, 60.0, None)
    assert ran == ["job.inp", "job_refine2.inp"]
    assert (tmp_path / "job.failed").read_text().splitlines()[1].startswith(
        "ccx did not converge (deck ")
    ran.clear()
    run, refine, scale, _, _ = jobs.run_job(write, 2, 1, 60.0, None)  # resumed, one more
    assert ran == ["job_refine2_soft2.inp"] and (refine, scale) == (2, 0.5)
    ran.clear()
    with pytest.raises(CcxConvergenceError, match=r"not run again.*job_refine2\.failed"):
        jobs.run_job(write, 1, 1, 60.0, None)
    assert ran == []
    text["body"] = "mesh B"  # another geometry: another deck, run again
    with pytest.raises(CcxConvergenceError, match="increment size smaller than minimum$"):
        jobs.run_job(write, 1, 1, 60.0, None)
    assert ran == ["job.inp", "job_refine2.inp"]


def test_cell_average_conserves_the_integral() -> None:
    xn = np.array([-2.0, -1.0, 0.0, 0.5, 1.0, 3.0])
    vn = np.array([0.0, 1.0, 3.0, 2.0, 1.0, 0.0])
    dx = 0.25
    centres = np.arange(-16, 16) * dx
    avg = cell_average(xn, vn, centres, dx)
    assert float(avg.sum() * dx) == pytest.approx(float(np.sum(0.5 * (vn[1:] + vn[:-1])
                                                                 * np.diff(xn))), rel=1e-12)
    assert avg[0] == 0.0 and avg[-1] == 0.0


# --- one coarse ccx job: loading and a gross-slip cycle --------------------------------------

AMPLITUDE = 10e-6  # m: gross slip is reached at about 3 um (docs/fe.md)


def line_case(load: float = LOAD * WINDOW, n: int = 64) -> ContactCase:
    """The EN24T cylinder R 4 mm on a flat, mu 0.6, on a window of 10 half-widths (``load``
    N on it), +-10 um in 4 increments."""
    return ContactCase(upper=cylinder(8e-3, axis="y"), lower=flat(),
                       upper_material=ElasticBody(), lower_material=ElasticBody(), load=load,
                       friction=0.6, amplitude=AMPLITUDE, n_increments=4, n=n, window=WINDOW,
                       contact="line")


@pytest.fixture(scope="module")
def served(tmp_path_factory: pytest.TempPathFactory):  # noqa: ANN201
    solver = FEContactSolver(line_case(n=128),
                             FEOptions(h_over_a=0.25, size_factor=40, threads=1, timeout=600),
                             workdir=tmp_path_factory.mktemp("fe_backend"))
    solver.reset()
    loaded = solver.solve_increment(0.0)
    solver.begin_cycle()
    incs = [solver.solve_increment(float(o)) for o in solver.offsets]
    return solver, loaded, incs


@needs_ccx
def test_backend_hertz_line(served) -> None:  # noqa: ANN001
    solver, loaded, _ = served
    assert len(solver.jobs) == 1  # the loading and the first cycle: one job
    p = loaded.pressure[:, 0]
    np.testing.assert_array_equal(loaded.pressure, np.repeat(p[:, None], solver.n, axis=1))
    assert loaded.normal_load == pytest.approx(solver.load, rel=1e-3)
    assert p.max() == pytest.approx(P0, rel=0.02)
    # half-width: the FE nodes (the model), and the window cells (the model mapped)
    a_nodes, _ = half_width_fit(solver.results.contact[solver.results.at(2.0)], P0)
    assert a_nodes == pytest.approx(A, rel=0.02)
    x = solver.coords
    inner = p > 0.5 * p.max()  # away from the edge cells, which the mapping smears
    slope, icpt = np.polyfit(x[inner] ** 2, p[inner] ** 2, 1)  # p^2 = p0^2 (1 - x^2 / a^2)
    # the window holds cell averages of the nodes' piecewise-linear interpolant, which
    # flattens the elliptical profile between nodes: measured -2.7 % at h = a/4
    assert math.sqrt(icpt / -slope) == pytest.approx(A, rel=0.04)
    assert loaded.direction == 0.0 and not loaded.slip.any()


@needs_ccx
def test_backend_gross_slip_and_signs(served) -> None:  # noqa: ANN001
    solver, _, incs = served
    mu, dx = solver.friction, solver.dx
    for inc in incs:
        assert inc.start_offset + (inc.offset - inc.start_offset) == inc.offset
        assert np.all(inc.energy_density >= 0.0)
        raw = -np.einsum("ijk,ijk->ij", inc.traction, inc.slip)
        assert raw.min() >= -1e-9 * max(raw.max(), 1e-30)  # -q.s >= 0 before any clipping
        s = inc.slip[..., 0]
        assert np.all(s * inc.direction >= 0.0)  # the upper body slides the way it moves
        assert inc.traction[..., 1].max() == 0.0 and inc.slip[..., 1].max() == 0.0
    for k in (0, 2):  # +A and -A: gross slip, traction on the upper body opposes its motion
        inc = incs[k]
        q = float(inc.traction[:, 0, 0].sum() * dx)
        p = float(inc.pressure[:, 0].sum() * dx)
        assert p == pytest.approx(LOAD, rel=1e-3)
        assert -inc.direction * q / (mu * p) == pytest.approx(1.0, abs=0.01)
    # the cycle dissipates at most the rigid-slip work 4 A mu P (the bodies' compliance
    # takes part of each stroke) and at least half of it at A = 3 x the gross-slip distance
    energy = sum(float(i.energy_density.sum()) * dx * dx for i in incs)
    rigid = 4 * AMPLITUDE * mu * LOAD * solver.window
    assert 0.5 * rigid < energy < rigid


@needs_ccx
def test_backend_subsurface_stress_under_hertz(served) -> None:  # noqa: ANN001
    """McEwen's line-contact field on the axis (Johnson 4.47-4.48): sigma_zz = -p0 /
    sqrt(1 + z^2/a^2) within 4 % of p0, the maximum shear 0.300 p0 at z = 0.786 a within 3 %
    of p0 and one element; the loading's field is the same under both bodies."""
    solver, loaded, incs = served
    lower = solver.subsurface_stress(loaded, "lower", depth=2 * A, nz=41)
    upper = solver.subsurface_stress(loaded, "upper", depth=2 * A, nz=41)
    i = solver.n // 2  # x = 0
    z = lower.z
    szz = lower.stress[:, i, 0, 2]
    # linear elements at h = a/4: measured 3.0 % of p0 at most (between the imposed surface
    # value and the first Gauss points)
    np.testing.assert_allclose(szz, -P0 / np.sqrt(1 + (z / A) ** 2), rtol=0, atol=0.04 * P0)
    tau = lower.tresca[:, i, 0]
    k = int(np.argmax(tau))
    assert tau[k] == pytest.approx(0.300 * P0, abs=0.03 * P0)
    assert abs(z[k] - 0.786 * A) <= solver.mesh.h_fine
    np.testing.assert_allclose(upper.stress[:, i, 0, 2], szz, rtol=0, atol=0.04 * P0)
    assert lower.stress.shape == (41, solver.n, solver.n, 6)
    # gross slip at +A: at the surface sigma_xz = q under the flat and -q in the pad, q the
    # traction on the upper body (the half-space backend's convention)
    inc = incs[0]
    j = int(np.argmax(inc.pressure[:, 0]))
    q = inc.traction[j, 0, 0]
    assert q < 0.0
    sl = solver.subsurface_stress(inc, "lower", depth=A, nz=5)
    su = solver.subsurface_stress(inc, "upper", depth=A, nz=5)
    assert sl.stress[0, j, 0, 4] == pytest.approx(q, rel=0.05)
    assert su.stress[0, j, 0, 4] == pytest.approx(-q, rel=0.05)


@needs_ccx
def test_backend_refuses_offsets_out_of_order(served) -> None:  # noqa: ANN001
    solver, _, _ = served
    solver._k = 0  # the next increment of a cycle in progress (no new job)
    solver._served = solver._served or []
    with pytest.raises(ValueError, match="not increment 1"):
        solver.solve_increment(0.5 * AMPLITUDE)
    solver._k = None


# --- the command ------------------------------------------------------------------------------

CONFIG = """cycles = 2
solver = "fe"
[contact]
geometry = "cylinder_on_flat"
radius = 4e-3
load_per_length = 1.0e5
amplitude = 10e-6
n_increments = 4
n = 64
[fe]
h_over_a = 0.5
[output]
vtk = false
figures = false
"""


def _ccx_wrapped_in_cycle_2(tmp_path: Path, action: str) -> dict[str, str]:
    """The environment of a run whose ``ccx`` is a wrapper in front of Debian's: it runs the
    shell ``action`` first when the job is cycle 2's (in its folder; ``$2`` is the job
    name), then the real ccx (``TRIBODEM_CCX``: the wrapper, not a PARDISO build)."""
    real = shutil.which("ccx")
    assert real is not None
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    wrapper = bin_dir / "ccx"
    wrapper.write_text(f"#!/bin/sh\ncase \"$PWD\" in */cycle_0002) {action};; esac\n"
                       f"exec {real} \"$@\"\n")
    wrapper.chmod(wrapper.stat().st_mode | stat.S_IEXEC)
    return dict(os.environ, PATH=f"{bin_dir}{os.pathsep}{os.environ['PATH']}",
                TRIBODEM_CCX="ccx")


@needs_ccx
def test_ccx_failure_stops_the_run_with_exit_3(tmp_path: Path) -> None:
    """A deck ccx refuses (here: cycle 2's, spoiled by a wrapper in front of the real ccx)
    stops the run with exit 3, ccx's message and the deck path; cycle 1's outputs stay, and
    ``--resume`` (ccx fixed) finishes the run. (Resumed = uninterrupted, bitwise: measured
    on 2 cycles at h = a/2, results.csv identical.)"""
    env = _ccx_wrapped_in_cycle_2(
        tmp_path, "sed -i '2a *BOUNDARY\\nNOSUCHSET, 1, 2' \"$2.inp\"")
    cfg = tmp_path / "fe.toml"
    cfg.write_text(CONFIG)
    out = tmp_path / "run"
    r = run_tribodem("fretting", "run", "--config", str(cfg), "--out", str(out),
                     "--no-progress", env=env)
    assert r.returncode == 3, r.stderr
    assert "Traceback" not in r.stderr
    deck = out / "fe" / "cycle_0002" / "job.inp"
    assert str(deck) in r.stderr
    assert "NOSUCHSET" in r.stderr and "*ERROR" in r.stderr
    rows = (out / "results.csv").read_text().splitlines()
    assert len(rows) == 2 and rows[1].startswith("1,")
    summary = json.loads((out / "summary.json").read_text())
    assert summary["stopped"].startswith("cycle 2")
    assert (out / "fe" / "cycle_0001" / "job.dat").is_file()
    assert "--resume" in r.stderr  # the hint: fix the deck's problem, then resume
    # ... which works: without the spoiling wrapper, --resume runs cycle 2's job again
    r = run_tribodem("fretting", "run", "--config", str(cfg), "--out", str(out), "--resume",
                     "--no-progress")
    assert r.returncode == 0, r.stderr
    rows = (out / "results.csv").read_text().splitlines()
    assert [ln.split(",")[0] for ln in rows[1:]] == ["1", "2"]
    assert "NOSUCHSET" not in (out / "fe" / "cycle_0002" / "job.inp").read_text()


@needs_ccx
def test_a_ccx_job_over_its_time_limit_stops_with_the_setting_named(tmp_path: Path) -> None:
    """A job killed by ``fe.timeout`` (here cycle 2's, held up by a wrapper that sleeps
    first) stops the run with exit 3, the limit and the setting to raise; the resume with a
    larger limit (``fe.timeout`` may change on resume) finishes the run."""
    env = _ccx_wrapped_in_cycle_2(tmp_path, "sleep 120")
    cfg = tmp_path / "fe.toml"
    # 10 s: cycle 1's job takes ~1-3 s (h = a/2, 4 increments); the wait is the test's cost
    cfg.write_text(CONFIG.replace("[fe]\n", "[fe]\ntimeout = 10\n"))
    out = tmp_path / "run"
    r = run_tribodem("fretting", "run", "--config", str(cfg), "--out", str(out),
                     "--no-progress", env=env)
    assert r.returncode == 3, r.stderr
    assert "Traceback" not in r.stderr
    assert "10 s wall-clock limit" in r.stderr
    assert "raise fe.timeout (now 10 s)" in r.stderr
    rows = (out / "results.csv").read_text().splitlines()
    assert len(rows) == 2 and rows[1].startswith("1,")
    cfg.write_text(CONFIG)  # the backend's own limit
    r = run_tribodem("fretting", "run", "--config", str(cfg), "--out", str(out), "--resume",
                     "--no-progress")
    assert r.returncode == 0, r.stderr
    rows = (out / "results.csv").read_text().splitlines()
    assert [ln.split(",")[0] for ln in rows[1:]] == ["1", "2"]


def test_missing_ccx_exits_2_with_the_install_command(tmp_path: Path) -> None:
    cfg = tmp_path / "fe.toml"
    cfg.write_text(CONFIG)
    env = dict(os.environ, PATH=str(tmp_path / "nowhere"), TRIBODEM_CCX="ccx")
    r = run_tribodem("fretting", "run", "--config", str(cfg), "--out", str(tmp_path / "run"),
                     "--no-progress", env=env)
    assert r.returncode == 2, r.stderr
    assert INSTALL_COMMAND in r.stderr and "solver = 'fe'" in r.stderr
    assert "Traceback" not in r.stderr
    assert not (tmp_path / "run" / "results.csv").exists()


def test_fe_refuses_a_point_contact(tmp_path: Path) -> None:
    r = run_tribodem("fretting", "run", "--solver", "fe", "--cycles", "1", "--out",
                     str(tmp_path / "run"), "--no-progress")
    assert r.returncode == 2
    assert "point_contact" in r.stderr and "solver = 'fe'" in r.stderr


def test_fe_usage_errors_exit_2(tmp_path: Path) -> None:
    """--threads beyond the cores and a mode that does not exist are refused before any
    work, naming the field and what is allowed."""
    cfg = tmp_path / "fe.toml"
    cfg.write_text(CONFIG)
    r = run_tribodem("fretting", "run", "--config", str(cfg), "--threads", "999", "--out",
                     str(tmp_path / "a"), "--no-progress")
    assert r.returncode == 2 and "--threads = 999" in r.stderr and "allowed" in r.stderr
    cfg.write_text(CONFIG.replace("[fe]\n", "[fe]\nmode = \"replayed\"\n"))
    r = run_tribodem("fretting", "run", "--config", str(cfg), "--out", str(tmp_path / "b"),
                     "--no-progress")
    assert r.returncode == 2 and "fe.mode" in r.stderr and "chained" in r.stderr
    assert "Traceback" not in r.stderr
    cfg.write_text(CONFIG.replace("[fe]\n", "[fe]\nsize_factor = 6\n"))  # fe3d's range
    r = run_tribodem("fretting", "run", "--config", str(cfg), "--out", str(tmp_path / "c"),
                     "--no-progress")
    assert r.returncode == 2 and "size_factor = 6" in r.stderr and ">= 10" in r.stderr
    assert "Traceback" not in r.stderr and not (tmp_path / "c").exists()


def test_deck_split_cycles(tmp_path: Path) -> None:
    """One step per quarter of each cycle (seating + load + 4 x cycles), ramped targets
    +d, 0, -d, 0, the pair declared once, the node-to-surface tension written."""
    from tribodem.contact.fe.deck import LoadCase, sliding_contact, write_deck

    mesh = _mesh(0.5)
    deck = write_deck(tmp_path / "job.inp", mesh,
                      LoadCase(load=LOAD, delta=5e-6, n_increments=8, split_cycle=True,
                               cycles=2), contact=sliding_contact(0.6, P0),
                      fine_stress=False).read_text()
    assert deck.count("*STEP") == 2 + 4 * 2
    assert deck.count("*CONTACT PAIR") == 1 and "TYPE=NODE TO SURFACE" in deck
    ref = int(mesh.node_sets["REF"][0])
    targets = [ln.split(",")[3].strip() for ln in deck.splitlines()
               if ln.startswith(f"{ref}, 1, 1,")]
    assert [float(t) for t in targets[2:]] == [5e-6, 0.0, -5e-6, 0.0] * 2
    assert f"{1e-5 * P0:.9e}" in deck  # tension at large clearances
    # ccx reads a data field as at most 20 characters: 48 increments a cycle made a minimum
    # increment of 8.333333333333334e-06 (21), read as 8.3 (docs/fe3d.md "Deck fields")
    deck = write_deck(tmp_path / "job48.inp", mesh,
                      LoadCase(load=LOAD, delta=5e-6, n_increments=48, split_cycle=True),
                      contact=sliding_contact(0.6, P0), fine_stress=False).read_text()
    lines = deck.splitlines()
    data = [ln for k, ln in enumerate(lines) if not ln.startswith("*")
            and lines[k - 1] != "*HEADING"]
    assert not [f for ln in data for f in ln.split(",") if len(f.strip()) > 20]
    assert "0.0833333333333, 1, 8.33333333333e-06, 0.0833333333333" in deck  # 1/12 a step


@needs_ccx
def test_job_cache_serves_the_same_job_without_running_ccx(tmp_path: Path) -> None:
    """Two solvers on the same case and a shared ``cache``: the first runs ccx and stores the
    job, the second copies it (``cached``, no ccx time) and serves bitwise the same fields;
    a changed case (another load) is a different deck and runs."""
    def solve(load: float, name: str):  # noqa: ANN202
        s = FEContactSolver(line_case(load=load * WINDOW),
                            FEOptions(h_over_a=0.5, size_factor=20, threads=1, timeout=600,
                                      cache=str(tmp_path / "cache")),
                            workdir=tmp_path / name)
        s.reset()
        loaded = s.solve_increment(0.0)
        s.begin_cycle()
        return s, [loaded] + [s.solve_increment(float(o)) for o in s.offsets]

    first, a = solve(LOAD, "first")
    second, b = solve(LOAD, "second")
    third, _ = solve(0.8 * LOAD, "third")
    assert [j.cached for j in first.jobs + second.jobs + third.jobs] == [False, True, False]
    assert second.jobs[0].seconds_ccx == 0.0
    for x, y in zip(a, b, strict=True):
        np.testing.assert_array_equal(x.pressure, y.pressure)
        np.testing.assert_array_equal(x.traction, y.traction)
        np.testing.assert_array_equal(x.slip, y.slip)
    rows = (tmp_path / "second" / "jobs.csv").read_text().splitlines()
    assert rows[0].split(",")[-2:] == ["cached", "deck"] and rows[1].split(",")[-2] == "1"
    assert len(list((tmp_path / "cache").iterdir())) == 2  # two decks, no temporary left


def test_a_failure_record_names_the_build_not_the_file(tmp_path: Path) -> None:
    """A ``.failed`` record's key is the deck and the ccx build by what it is (version,
    solvers, patches), so it holds for the same build at another path or made anew (a run
    carried to another machine); the job cache's key stays the file's (results of two
    builds agree within tolerances only)."""
    import os
    import shutil

    from tribodem.contact.fe import jobs
    from tribodem.contact.fe.ccx import resolve_ccx

    exe = resolve_ccx(None)
    if exe is None:
        pytest.skip("no ccx")
    copies = []
    for k, name in enumerate(("a", "b")):
        (tmp_path / name).mkdir()
        copies.append(str(shutil.copy2(exe, tmp_path / name / "ccx")))
        os.utime(copies[-1], ns=(10**18 + k, 10**18 + k))
    deck = hashlib.sha256(b"*HEADING\nsame deck\n")
    assert jobs._failure_key(deck, copies[0]) == jobs._failure_key(deck, copies[1])
    assert jobs._cache_key(deck, copies[0]) != jobs._cache_key(deck, copies[1])
    other = hashlib.sha256(b"*HEADING\nanother deck\n")
    assert jobs._failure_key(other, copies[0]) != jobs._failure_key(deck, copies[0])
