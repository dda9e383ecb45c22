"""CalculiX FE backend (plane strain pad on flat): mesh, deck, runner errors, Hertz, gross slip.

The ccx runs use a coarse mesh (h = a / 4) and skip when ``ccx`` is not on PATH.
"""

from __future__ import annotations

import math
import shutil
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from tribodem.contact.fe import (
    INSTALL_COMMAND,
    CcxConvergenceError,
    CcxError,
    CcxNotFoundError,
    CcxTimeoutError,
    ContactSettings,
    FEMaterial,
    LineCase,
    LineRun,
    LoadCase,
    PadOnFlat,
    build,
    cylinder_on_flat,
    hertz_line,
    read_dat,
    run_ccx,
    run_line_case,
    write_deck,
)
from tribodem.contact.fe.mesh import graded_half
from tribodem.contact.fe.results import internal_forces
from tribodem.contact.fe.validate import half_width_fit, hertz_checks, tangential_checks

needs_ccx = pytest.mark.skipif(shutil.which("ccx") is None,
                               reason=f"CalculiX ccx not on PATH ({INSTALL_COMMAND})")

COARSE = 0.25  # element size at the contact / a


def coarse_case(**kw: Any) -> LineCase:
    return LineCase(load=1e5, delta=3e-6, n_increments=32, half_cycle=True,
                    h_over_a=COARSE, **kw)


# --- no solver needed -------------------------------------------------------------------------

def test_hertz_line_formulas() -> None:
    p0, a = hertz_line(1e5, 4e-3, 131.868e9)
    assert p0 == pytest.approx(1.0244e9, rel=1e-4)
    assert a == pytest.approx(62.15e-6, rel=1e-3)
    assert 0.5 * math.pi * a * p0 == pytest.approx(1e5, rel=1e-12)  # P = pi a p0 / 2


def test_graded_half_uniform_then_growing() -> None:
    x = graded_half(10e-6, 1e-6, 1e-3, 1.2)
    d = np.diff(x)
    assert x[0] == 0.0 and x[-1] == pytest.approx(1e-3)
    assert np.allclose(d[:10], 1e-6)
    assert np.all(d[10:-1] / d[9:-2] == pytest.approx(1.2))
    assert d[-1] <= 1.2 * 1.2 * d[-2]


def test_mesh_is_valid_and_deterministic(tmp_path: Path) -> None:
    p = PadOnFlat(a=62e-6, h_fine=8e-6, stroke=20e-6)
    m1, m2 = cylinder_on_flat(p), cylinder_on_flat(p)
    assert np.array_equal(m1.nodes, m2.nodes) and np.array_equal(m1.elements, m2.elements)
    m1.check()
    ubot = m1.nodes[m1.node_sets["UBOT"] - 1]
    # pad surface nodes lie on the arc y = R - sqrt(R^2 - x^2), flat's top at y = 0
    assert np.allclose(ubot[:, 1], p.radius - np.sqrt(p.radius**2 - ubot[:, 0] ** 2), atol=1e-15)
    assert np.all(m1.nodes[m1.node_sets["LTOP"] - 1, 1] == 0.0)
    # straight columns of uniform spacing h under the contact on both bodies
    xt = np.sort(m1.nodes[m1.node_sets["LTOP"] - 1, 0])
    fine = xt[np.abs(xt) <= p.zone_factor * p.a + p.stroke]
    assert np.allclose(np.diff(fine), p.h_fine)
    out = m1.write_vtk(tmp_path / "mesh.vtu")
    import meshio

    back = meshio.read(out)
    assert back.points.shape[0] == m1.n_nodes
    assert back.cells[0].data.shape == (m1.n_elements, 4)


def test_internal_forces_patch() -> None:
    """A uniform stress on a distorted quad gives the boundary tractions' nodal forces."""
    xy = np.array([[[0.0, 0.0], [2.0, 0.1], [2.2, 1.5], [-0.1, 1.0]]])
    sxx, syy, sxy = 3.0, -2.0, 0.5
    s = np.tile([sxx, syy, 0.0, sxy], (1, 4, 1)).astype(float)
    f = internal_forces(xy, s)[0]
    assert np.allclose(f.sum(axis=0), 0.0, atol=1e-12)
    # exact: f_i = 1/2 sigma . (n1 L1 + n2 L2) of the two edges at node i (outward normals)
    pts = xy[0]
    expected = np.zeros((4, 2))
    sig = np.array([[sxx, sxy], [sxy, syy]])
    for i in range(4):
        j = (i + 1) % 4
        e = pts[j] - pts[i]
        n_len = np.array([e[1], -e[0]])  # outward normal x length (CCW polygon)
        expected[i] += 0.5 * sig @ n_len
        expected[j] += 0.5 * sig @ n_len
    assert np.allclose(f, expected, atol=1e-12)


def test_deck_plastic_table_and_steps(tmp_path: Path) -> None:
    mesh = cylinder_on_flat(PadOnFlat(a=62e-6, h_fine=16e-6, stroke=3e-6))
    mat = FEMaterial(yield_strength=680e6)
    deck = write_deck(tmp_path / "job.inp", mesh, LoadCase(load=1e5, delta=3e-6), mat, mat)
    text = deck.read_text()
    assert text.count("*STEP") == 3 and text.count("*PLASTIC") == 2
    e_pl = 0.132 - 1000e6 / 240e9
    h = (1000e6 - 680e6) / e_pl  # the line through the yield and the UTS, past the UTS
    assert f"{680e6 + h:.9e}, {1.0:.9e}" in text
    held = FEMaterial(yield_strength=680e6, beyond_uts="hold")
    text = write_deck(tmp_path / "held.inp", mesh, LoadCase(load=1e5, delta=3e-6), held,
                      held).read_text()
    assert f"{1000e6:.9e}, {e_pl:.9e}" in text and f"{1.0:.9e}" not in text
    assert "TYPE=SURFACE TO SURFACE" in text and "*CHANGE FRICTION" in text
    with pytest.raises(ValueError, match="multiple of 4"):
        write_deck(tmp_path / "bad.inp", mesh, LoadCase(delta=1e-6, n_increments=6))


def test_one_plastic_law_for_every_backend() -> None:
    """The ccx table of the bilinear EN24T law (seed table 5.1) is tamaas's: the line
    sigma = Y + h eps_p with h = bilinear_hardening (2.50 GPa; E_t from (Y / E, Y) to
    (0.132, UTS)), to round-off, through (UTS, 0.132 - UTS / E); "hold" stops it at the
    UTS; a given ``hardening`` is the same line, held at the UTS where the line meets it."""
    from tribodem.contact import bilinear_hardening

    y, u, e = 680e6, 1000e6, 240e9
    h = bilinear_hardening(e, y, u, 0.132)
    (y0, p0), (s1, p1) = FEMaterial(yield_strength=y).plastic_table()
    assert (y0, p0) == (y, 0.0) and p1 == 1.0
    assert (s1 - y0) / p1 == pytest.approx(h, rel=1e-12)
    p_uts = 0.132 - u / e
    assert y0 + (s1 - y0) * p_uts == pytest.approx(u, rel=1e-12)
    assert FEMaterial(yield_strength=y, beyond_uts="hold").plastic_table() == [
        (y, 0.0), (u, p_uts)]
    assert FEMaterial(yield_strength=y, hardening=h).plastic_table() == [(y, 0.0), (y + h, 1.0)]
    (_, _), (s2, p2) = FEMaterial(yield_strength=y, hardening=h,
                                  beyond_uts="hold").plastic_table()
    assert s2 == u and p2 == pytest.approx(p_uts, rel=1e-12)
    assert FEMaterial(yield_strength=y, hardening=0.0, beyond_uts="hold").plastic_table() == [
        (y, 0.0)]
    with pytest.raises(ValueError, match="beyond_uts = 'cap' is not allowed"):
        FEMaterial(yield_strength=y, beyond_uts="cap")


def test_read_dat_blocks(tmp_path: Path) -> None:
    dat = tmp_path / "x.dat"
    dat.write_text("\n total force (fx,fy,fz) for set LBOT and time  0.2000000E+01\n\n"
                   "        1.0E+00  2.0E+05 0.0\n\n"
                   " displacements (vx,vy,vz) for set REF and time  0.2000000E+01\n\n"
                   "      7  1.0E-06 -2.0E-06  0.0\n")
    blocks = read_dat(dat)
    assert [(b.kind, b.set_name, b.time) for b in blocks] == [
        ("total force", "LBOT", 2.0), ("displacements", "REF", 2.0)]
    assert blocks[0].rows.tolist() == [[1.0, 2e5, 0.0]]


def test_missing_ccx_names_the_install_command(tmp_path: Path,
                                               monkeypatch: pytest.MonkeyPatch) -> None:
    _, deck = build(coarse_case(), tmp_path)
    with pytest.raises(CcxNotFoundError, match="apt-get install -y calculix-ccx"):
        run_ccx(deck, executable="ccx-not-installed-here")
    monkeypatch.setenv("PATH", "")
    monkeypatch.setenv("TRIBODEM_CCX", "ccx")  # not a PARDISO build beside this Python either
    with pytest.raises(CcxNotFoundError) as exc:
        run_ccx(deck)
    assert INSTALL_COMMAND in str(exc.value)


def test_which_ccx_runs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """resolve_ccx: the caller's name, else $TRIBODEM_CCX, else ccx_pardiso (PATH, then
    this Python's bin), else ccx; ccx_solvers reads the solvers built into a binary,
    ccx_patches tribodem's patches, ccx_build all of it for a summary."""
    from tribodem.contact.fe import CCX_PATCHES, ccx_build, ccx_patches, ccx_solvers, resolve_ccx

    bin_dir, prefix = tmp_path / "bin", tmp_path / "prefix"
    (prefix / "bin").mkdir(parents=True)
    bin_dir.mkdir()
    for name, text in (("ccx", "using the unsymmetric spooles solver"),
                       ("ccx_pardiso", "using the unsymmetric pardiso solver\0"
                                       "using the unsymmetric spooles solver\0"
                                       + "\0".join(m.decode() for m in CCX_PATCHES.values()))):
        exe = bin_dir / name
        exe.write_text(f"#!/bin/sh\n# {text}\n")
        exe.chmod(0o755)
    monkeypatch.setenv("PATH", str(bin_dir))
    monkeypatch.delenv("TRIBODEM_CCX", raising=False)
    monkeypatch.setattr(sys, "prefix", str(prefix))
    assert resolve_ccx() == str(bin_dir / "ccx_pardiso")
    assert ccx_solvers(str(bin_dir / "ccx_pardiso")) == ["PARDISO", "SPOOLES"]
    assert ccx_solvers(str(bin_dir / "ccx")) == ["SPOOLES"]
    assert ccx_patches(str(bin_dir / "ccx_pardiso")) == list(CCX_PATCHES)
    assert ccx_patches(str(bin_dir / "ccx")) == []
    build = ccx_build(str(bin_dir / "ccx_pardiso"))
    assert build["solvers"] == ["PARDISO", "SPOOLES"] and build["patches"] == list(CCX_PATCHES)
    assert build["version"] == "version unknown"  # the stand-in prints no version line
    monkeypatch.setenv("TRIBODEM_CCX", "ccx")
    assert resolve_ccx() == str(bin_dir / "ccx")
    assert resolve_ccx("ccx_pardiso") == str(bin_dir / "ccx_pardiso")  # the caller's wins
    monkeypatch.delenv("TRIBODEM_CCX")
    (bin_dir / "ccx_pardiso").rename(prefix / "bin" / "ccx_pardiso")  # beside this Python
    assert resolve_ccx() == str(prefix / "bin" / "ccx_pardiso")
    (prefix / "bin" / "ccx_pardiso").unlink()
    assert resolve_ccx() == str(bin_dir / "ccx")
    monkeypatch.setenv("TRIBODEM_CCX", str(tmp_path / "nowhere" / "ccx"))
    assert resolve_ccx() is None


def test_ccx_environment(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """run_ccx hands ccx its thread counts and glibc's malloc tunables (kept if the caller
    set GLIBC_TUNABLES), through a stand-in ccx that prints its environment."""
    from tribodem.contact.fe.ccx import MALLOC_TUNABLES

    fake = tmp_path / "env_ccx"
    fake.write_text("#!/bin/sh\nenv\necho 'Job finished'\n")
    fake.chmod(0o755)
    deck = tmp_path / "job.inp"
    deck.write_text("*HEADING\n")
    monkeypatch.delenv("GLIBC_TUNABLES", raising=False)
    run_ccx(deck, threads=2, timeout=60, executable=str(fake))
    env = dict(ln.split("=", 1) for ln in (tmp_path / "job.log").read_text().splitlines()
               if "=" in ln)
    assert env["GLIBC_TUNABLES"] == MALLOC_TUNABLES
    assert env["OMP_NUM_THREADS"] == env["MKL_NUM_THREADS"] == "2"
    monkeypatch.setenv("GLIBC_TUNABLES", "glibc.malloc.hugetlb=1")
    run_ccx(deck, threads=1, timeout=60, executable=str(fake))
    assert "GLIBC_TUNABLES=glibc.malloc.hugetlb=1" in (tmp_path / "job.log").read_text()


# --- with ccx ---------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def coarse_run(tmp_path_factory: pytest.TempPathFactory) -> LineRun:
    if shutil.which("ccx") is None:
        pytest.skip(f"CalculiX ccx not on PATH ({INSTALL_COMMAND})")
    return run_line_case(coarse_case(), tmp_path_factory.mktemp("fe_coarse"), threads=1,
                         timeout=300)


@needs_ccx
def test_hertz_line_contact(coarse_run: LineRun) -> None:
    checks = {c["name"]: c for c in hertz_checks(coarse_run)}
    assert checks["hertz_p0"]["pass"], checks["hertz_p0"]
    assert checks["hertz_a"]["pass"], checks["hertz_a"]
    p0, a = coarse_run.case.hertz
    st = coarse_run.results.contact[coarse_run.results.at(2.0)]
    # the pressure integrates to the load and follows the Hertz ellipse
    assert np.trapezoid(st.pressure, st.x) == pytest.approx(1e5, rel=0.01)
    a_fit, p0_fit = half_width_fit(st, p0)
    inside = np.abs(st.x) < 0.8 * a
    hertz = p0 * np.sqrt(1 - (st.x[inside] / a) ** 2)
    assert np.max(np.abs(st.pressure[inside] - hertz)) < 0.03 * p0


@needs_ccx
def test_gross_slip_and_partial_slip(coarse_run: LineRun) -> None:
    checks = tangential_checks(coarse_run)
    gross = checks[0]
    assert gross["name"] == "gross_slip_Q_over_muP" and gross["pass"], gross
    res = coarse_run.results
    # the pad moves +x: friction on it is -x, and Q grows monotonically to mu P
    q = -res.tangential_force[res.times > 2.0]
    assert np.all(np.diff(q) > -1e-6 * q.max())
    for c in checks[1:]:
        if c["name"].startswith("Q("):
            assert c["pass"], c


@needs_ccx
def test_bad_deck_raises_ccx_error_with_message(tmp_path: Path) -> None:
    _, deck = build(coarse_case(), tmp_path)
    deck.write_text(deck.read_text().replace("*BOUNDARY\nLBOT, 1, 2", "*BOUNDARY\nNOSET, 1, 2"))
    with pytest.raises(CcxError) as exc:
        run_ccx(deck, timeout=60)
    assert "*ERROR" in exc.value.message and "NOSET" in exc.value.message
    assert exc.value.deck == deck.resolve() and str(deck.resolve()) in str(exc.value)
    assert not isinstance(exc.value, CcxConvergenceError)
    # no elastic constants: SPOOLES builds crash without an *ERROR line, PARDISO builds stop
    # with "too many cutbacks"; an error either way
    deck.write_text(deck.read_text().replace("NOSET", "LBOT").replace("*ELASTIC\n", "*ELASTIK\n"))
    with pytest.raises(CcxError):
        run_ccx(deck, timeout=60)
    # a ccx that exits 0 without "Job finished" and without an *ERROR line is an error too
    fake = tmp_path / "fake_ccx"
    fake.write_text("#!/bin/sh\necho 'some output'\n")
    fake.chmod(0o755)
    with pytest.raises(CcxError, match="no 'Job finished'"):
        run_ccx(deck, timeout=60, executable=str(fake))


@needs_ccx
def test_divergence_raises_convergence_error(tmp_path: Path) -> None:
    """Node-to-surface contact with friction during the loading, in fixed increments of P / 5
    (the set-up rejected in docs/fe.md): ccx 2.20 reports diverging iterations."""
    contact = ContactSettings(formulation="NODE TO SURFACE", mu_loading=0.6)
    _, deck = build(LineCase(h_over_a=0.5, contact=contact), tmp_path, fine_stress=False)
    text = deck.read_text()
    i = text.index("*STEP", text.index("*STEP") + 1)
    j = text.index("*BOUNDARY, OP=NEW", i)
    rest = text[j:].replace(", TIME POINTS=TLOAD", "")
    deck.write_text(text[:i] + "*STEP, INC=1000\n*STATIC, DIRECT\n0.2, 1.\n" + rest)
    with pytest.raises(CcxConvergenceError) as exc:
        run_ccx(deck, timeout=120)
    assert "diverge" in exc.value.message and exc.value.sta.startswith("2 ")


@needs_ccx
def test_timeout_kills_ccx(tmp_path: Path) -> None:
    _, deck = build(coarse_case(), tmp_path, fine_stress=False)
    with pytest.raises(CcxTimeoutError, match="wall-clock limit"):
        run_ccx(deck, timeout=0.5)


@needs_ccx
def test_validate_fe_all_checks_pass(tmp_path: Path) -> None:
    """The ``tribodem validate --solver fe`` 2D checks at the default mesh (h = a / 8). (Its
    reversal check, one more ccx job, is left to the command to keep CI inside its limit:
    measured worst |Q|/(mu P) 0.9969, docs/fe.md.)"""
    from tribodem.contact.fe.validate import validate_fe

    checks = validate_fe(tmp_path, threads=1, timeout=600, reversals=False)
    names = [c["name"] for c in checks]
    for prefix in ("hertz_p0", "hertz_a", "first_yield_p0_over_vm", "gross_slip_Q_over_muP",
                   "mindlin_c", "Q(delta", "slip_displacement", "plastic_onset_p0_over_Y"):
        assert any(n.startswith(prefix) for n in names), prefix
    assert sum(n.startswith("mindlin_c") for n in names) == 3
    failed = [c for c in checks if not c["pass"]]
    assert not failed, failed
    assert all(set(c) == {"name", "value", "reference", "error", "tolerance", "pass"}
               for c in checks)
