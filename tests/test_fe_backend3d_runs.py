"""The ``fe3d`` backend's longer ccx runs, in a file of their own so that ``--dist
loadfile`` puts them on another worker than test_fe_backend3d.py's (the fe suite on 2
workers: 7:45 as one file, bounded by it): first yield of the elastic-plastic bodies
(Johnson), debris pressure applied and conserved, the primed mode's steady loop. Closed
forms and tolerances in each test's docstring; everything skips without ccx.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from fe3d_cases import AMPLITUDE, COMPACT, LOAD, P0, A, fe3d_solver

from tribodem.contact.fe.ccx import INSTALL_COMMAND
from tribodem.contact.geometry import crossed_cylinders

pytestmark = pytest.mark.skipif(shutil.which("ccx") is None,
                                reason=f"CalculiX ccx not on PATH ({INSTALL_COMMAND})")


def test_plastic_first_yield_under_the_surface(tmp_path: Path) -> None:
    """Johnson's first yield of a frictionless point contact (von Mises, nu = 0.3): p0 = 1.60 Y at
    0.48 a under the surface. The normal loading (nearly frictionless, the deck's seating friction)
    at Hertz p0 = 0.9 x 1.60 Y leaves no plastic strain; at 1.2 x 1.60 Y both bodies yield, the
    peak plastic strain within h / 2 of 0.48 a deep (the Gauss point nearest it on an h = a / 2
    mesh; measured 0.61 a upper, 0.39 a lower on the compact bodies, fe3d_cases.COMPACT; 6 a:
    0.61 a both; both jobs 53 s with Debian's ccx against 116 s on bodies 6 a). Sliding at
    mu 0.6 then yields both at the surface (Johnson 7.3: mu > 0.3 moves first yield to the
    surface), and the report and plastic steps carry it. Two ccx jobs of 16 increments per cycle
    (fewer failed on the return strokes, docs/fe3d.md)."""
    from tribodem.materials.en24t import EN24T

    y = EN24T.yield_strength
    for factor in (0.9, 1.2):
        load = LOAD * (factor * 1.60 * y / P0) ** 3  # p0 ~ P^(1/3)
        solver = fe3d_solver(tmp_path / f"f{factor}", load=load, h_over_a=0.5,
                         material="elastic-plastic", plastic_increments=16, **COMPACT)
        assert solver.capabilities.plastic and not solver.capabilities.plastic_every_cycle
        solver.reset()
        solver.solve_increment(0.0)
        solver.begin_cycle()
        incs = [solver.solve_increment(float(o)) for o in solver.offsets]
        rep = solver.report()["cycles"][-1]
        a, h = solver.hertz[1], solver._mesh0.h_fine
        for body in ("upper", "lower"):
            loaded = rep[f"max_peeq_loaded_{body}"]
            if factor < 1.0:
                assert loaded == 0.0, (body, loaded)
            else:
                assert loaded > 1e-5, (body, loaded)
                assert abs(rep[f"max_peeq_loaded_depth_{body}_m"] - 0.48 * a) <= 0.5 * h
            assert rep[f"max_peeq_{body}"] > max(loaded, 1e-4)  # the sliding adds to it
            assert rep[f"max_peeq_depth_{body}_m"] < 0.25 * h  # at the surface Gauss point
        assert rep["max_s22_compressive_pa"] > 0.8 * factor * 1.60 * y
        # the loaded state's peak vertical stress: p0 at the top Gauss points (0.1 a deep on
        # axis: Hertz sigma_zz 0.99 p0), within the h = a / 2 mesh's +-15 % while elastic
        s22_loaded = rep["max_s22_compressive_loaded_pa"]
        assert s22_loaded <= rep["max_s22_compressive_pa"]
        if factor < 1.0:
            assert abs(s22_loaded / (factor * 1.60 * y) - 1.0) < 0.15, s22_loaded
        steps = solver.plastic_steps()
        assert len(steps) == 2 * (1 + len(incs))  # the loading and each increment, per body
        assert {s.body for s in steps} == {"upper", "lower"}
        assert solver.plastic_steps() == []  # forgotten once read


# --- debris third body: the pressure the DE phase maps back -----------------------------------

#: the compact bodies with the window reaching past the 3 a ring the test reads
WIDER = {**COMPACT, "window_radii": 8.0}


def test_debris_pressure_pushes_the_bodies_apart_and_is_conserved(tmp_path: Path) -> None:
    """``loaded_solution`` (what the loop's DE phase reads) and ``set_debris_pressure``, h = a/2:
    without debris the window carries P (1e-3) and the deformed gap at 2 a and 3 a is the
    half-space's (Johnson's Hertz separation, computed there) within 5 % (measured +2.7 %, +2.7 %
    on the compact bodies with an 8 a window; +2.9 %, +2.2 % on 6 a); with 20 % of P on a ring 1.2
    a < r < 2 a (both faces loaded, ``*DLOAD``) the solid contact carries 0.8 P (1e-3) in the
    loading and in every increment of the cycle, which reuses the job, and its peak pressure is the
    half-space's with the same debris within 3 % (measured -0.6 %; -1.2 % on 6 a)."""
    from tribodem.contact.halfspace import HalfSpaceSolver

    s = fe3d_solver(tmp_path, h_over_a=0.5, **WIDER)
    up, lo = crossed_cylinders()
    hs = HalfSpaceSolver(up, lo, load=LOAD, n=64, window=s.window)
    a, c = s.hertz[1], s.coords
    r = np.hypot(*np.meshgrid(c, c, indexing="ij"))
    p_fe, g_fe = s.loaded_solution(0.0)
    _, g_hs = hs.loaded_solution(0.0)
    assert float(p_fe.sum()) * s.dx**2 == pytest.approx(LOAD, rel=1e-3)
    for radius in (2.0, 3.0):
        ring = np.abs(r - radius * a) < 0.5 * s.dx
        assert g_fe[ring].mean() == pytest.approx(g_hs[ring].mean(), rel=0.05)
    pd = np.where((r > 1.2 * a) & (r < 2.0 * a), 1.0, 0.0)
    pd *= 0.2 * LOAD / (pd.sum() * s.dx**2)
    s.set_debris_pressure(pd)
    hs.set_debris_pressure(pd)
    assert s.debris_load == pytest.approx(0.2 * LOAD, rel=1e-12)
    total, _ = s.loaded_solution(0.0, debris=True)
    solid = total - pd
    assert float(solid.sum()) * s.dx**2 == pytest.approx(0.8 * LOAD, rel=1e-3)
    p_hs = hs.loaded_solution(0.0, debris=True)[0] - pd
    assert solid.max() == pytest.approx(p_hs.max(), rel=0.03)
    assert solid.max() < p_fe.max()  # the debris carry part of the load
    jobs = len(s.jobs)
    s.reset()
    s.solve_increment(0.0)
    s.begin_cycle()
    for o in s.offsets:
        assert s.solve_increment(float(o)).normal_load == pytest.approx(0.8 * LOAD, rel=1e-3)
    assert len(s.jobs) == jobs  # the cycle reused the job the DE phase read
    other = fe3d_solver(tmp_path / "other", h_over_a=0.5, **WIDER)
    other.load_state_dict(s.state_dict())
    np.testing.assert_array_equal(other.debris_pressure, pd)
    with pytest.raises(ValueError, match="debris load"):
        s.set_debris_pressure(pd * 6.0)


def test_primed_mode_serves_the_steady_loop(tmp_path: Path) -> None:
    """Mode ``primed`` (a continuous test): cycle 1 is the fresh cycle from virgin bodies,
    dissipating Cattaneo-Mindlin's 4 mu P (A - delta*); from cycle 2 each job first runs the
    previous cycle's second half, and the served cycle dissipates the steady
    Mindlin-Deresiewicz loop 4 mu P (A - 0.8 delta*), 8.6 % more at A = 10 um, delta* =
    3 mu P (2 - nu) / (8 G a). Both within 2 % (measured -0.53 % and -0.51 % at h = a/2)."""
    s = fe3d_solver(tmp_path, h_over_a=0.5, mode="primed")
    g = 240e9 / (2 * 1.3)
    d_star = 3 * 0.6 * LOAD * (2 - 0.3) / (8 * g * A)
    s.reset()
    s.solve_increment(0.0)
    energy = []
    for _ in range(2):
        s.begin_cycle()
        incs = [s.solve_increment(float(o)) for o in s.offsets]
        energy.append(sum(float(i.energy_density.sum()) for i in incs) * s.dx**2)
    assert len(s.jobs) == 2  # the loading's job served cycle 1; cycle 2 ran a primed one
    assert energy[0] == pytest.approx(4 * 0.6 * LOAD * (AMPLITUDE - d_star), rel=0.02)
    assert energy[1] == pytest.approx(4 * 0.6 * LOAD * (AMPLITUDE - 0.8 * d_star), rel=0.02)
    assert "*STEP" in s.jobs[1].deck.read_text() and \
        s.jobs[1].deck.read_text().count("*STEP") == s.jobs[0].deck.read_text().count("*STEP") + 2
