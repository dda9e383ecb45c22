"""Plane-strain line contacts by default: a cylinder on a flat solved on one cross-section
(``[elastic] line_model = "plane-strain"``), in agreement with the n x n periodic window
it replaces, in a window sized to hold the scar the wear law predicts, with the worn
profiles written as a table.

The case is a 6 mm cylinder on a flat at 20 N/mm, steel on steel (Hertz half-width 36 um),
amplitude 25 um, gross slip, Archard wear on both bodies with different coefficients.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from tribodem.contact import HalfSpaceSolver
from tribodem.contact.line import LineContactSolver
from tribodem.fretting import FrettingConfig, build_loop, recorded_config, run

LINE = {"geometry": "cylinder_on_flat", "radius": 6e-3, "load_per_length": 2.0e4,
        "friction": 0.6, "amplitude": 25e-6}


def line_case(cycles: int, k: float = 2.75e-14, **contact: object) -> dict:
    """The line case over ``cycles`` with Archard k (upper; the lower twice that)."""
    return {"cycles": cycles, "contact": {**LINE, **contact},
            "wear": {"criterion": "archard", "archard_k_upper": k, "archard_k_lower": 2 * k},
            "output": {"vtk": False, "figures": False}}


def test_one_cross_section_agrees_with_the_periodic_window() -> None:
    """60 cycles of fast wear (k 2e-13 / 4e-13 1/Pa, 16 increments, n 64, the window of
    the default 10 half-widths given): the maximum depth of each body on one section within
    1.5 % of the n x n periodic window's (measured: 1.3 % upper, 0.5 % lower), the worn
    volumes equal to rounding."""
    data = line_case(60, k=2e-13, n=64, n_increments=16, amplitude=34e-6, window=3.64e-4)
    hist = {}
    for model in ("plane-strain", "periodic-2d"):
        cfg = FrettingConfig.model_validate({**data, "elastic": {"line_model": model}})
        loop = build_loop(cfg)
        assert isinstance(loop.solver, LineContactSolver if model == "plane-strain"
                          else HalfSpaceSolver)
        hist[model] = loop.run(cfg.cycles)
    one, two = hist["plane-strain"], hist["periodic-2d"]
    assert one.wear_upper.shape == (64, 1) and two.wear_upper.shape == (64, 64)
    for body in ("upper", "lower"):
        assert one.volume(body) == pytest.approx(two.volume(body), rel=1e-9)
        a = getattr(one, f"wear_{body}").max()
        b = getattr(two, f"wear_{body}").max()
        assert abs(a / b - 1) < 0.015, body


def _volume_kps(summary: dict, k: float, cycles: int) -> tuple[float, float]:
    """Archard's k P s per body: P = P' x window, s = 4 A per cycle (gross slip)."""
    load = summary["contact_case"]["load_per_length_N_per_m"] * summary["window_m"]
    s = 4 * LINE["amplitude"] * cycles
    return k * load * s, 2 * k * load * s


def test_the_default_window_holds_the_scar(tmp_path: Path) -> None:
    """2,000 cycles at ten times the wear coefficient wear as deep as 20,000 at k: the
    scar outgrows the default window (10 half-widths) several times over. By default the
    window is sized for it, the run does not stop, each body's worn volume is k P s
    within 1 % and the scar ends inside the window on both bodies."""
    k = 2.75e-13
    res = run(line_case(2000, k=k, n=128, n_increments=24)
              | {"jump": {"strategy": "adaptive"}}, str(tmp_path / "w"))
    s = res.summary
    assert s["stopped"] is None and s["cycles"] == 2000
    case = s["contact_case"]
    assert "sized for the scar" in case["window_reason"]
    default = 10 * math.sqrt(4 * LINE["load_per_length"] * LINE["radius"]
                             / (math.pi * case["modulus_Pa"]))  # 10 Hertz half-widths
    assert s["window_m"] > 2 * default
    up, lo = _volume_kps(s, k, 2000)
    assert s["wear_volume_upper_m3"] == pytest.approx(up, rel=0.01)
    assert s["wear_volume_lower_m3"] == pytest.approx(lo, rel=0.01)
    prof = pd.read_csv(tmp_path / "w" / "profiles.csv")
    assert list(prof.columns) == ["cycle", "body", "x_m", "wear_depth_m"]
    last = prof[prof.cycle == 2000]
    for body in ("upper", "lower"):
        h = last[last.body == body].wear_depth_m.to_numpy()
        assert h.max() > 0 and h[0] == 0.0 and h[-1] == 0.0  # inside the window
    assert sorted(set(prof.cycle)) == [1, 500, 1000, 1500, 2000]


def _depth_and_width(folder: Path, body: str) -> tuple[float, float]:
    prof = pd.read_csv(folder / "profiles.csv")
    b = prof[(prof.cycle == prof.cycle.max()) & (prof.body == body)]
    h, x = b.wear_depth_m.to_numpy(), b.x_m.to_numpy()
    worn = x[h > 0.01 * h.max()]
    return float(h.max()), float(worn.max() - worn.min())


def test_doubling_the_points_and_the_increments_changes_little(tmp_path: Path) -> None:
    """200 cycles at thirty times k (the scar of 6,000 cycles at k), every cycle simulated:
    n 128 / 24 increments against n 256 / 48 changes the maximum depth and the width of
    each body's scar by < 2 % (measured on the 10,000-cycle case at k with the default
    jumping, n 256 / 48 against 512 / 96: depth 1.2 % / 0.3 %, width 0.0 % / 0.3 %, upper /
    lower; docs/fretting.md "Sampling of the stroke")."""
    out = {}
    for n, inc in ((128, 24), (256, 48)):
        out[n] = tmp_path / f"n{n}"
        run(line_case(200, k=8.25e-13, n=n, n_increments=inc), str(out[n]))
    for body in ("upper", "lower"):
        (d1, w1), (d2, w2) = (_depth_and_width(out[n], body) for n in (128, 256))
        assert abs(d1 / d2 - 1) < 0.02 and abs(w1 / w2 - 1) < 0.02, (body, d1, d2, w1, w2)


def test_a_resume_keeps_the_grids_a_raised_cycles_would_size_otherwise(tmp_path: Path
                                                                       ) -> None:
    """The window is sized for the cycles first asked for; raising ``cycles`` on a resume
    keeps it (the grids must fit the checkpoint)."""
    out = tmp_path / "r"
    first = run(line_case(100, k=8.25e-13, n=128, n_increments=24), str(out))
    assert "sized for the scar" in first.summary["contact_case"]["window_reason"]
    more = run(None, str(out), resume=True, overrides={"cycles": 200})
    assert more.summary["cycles"] == 200
    assert more.summary["window_m"] == first.summary["window_m"]
    assert "after 100 cycles" in more.summary["contact_case"]["window_reason"]


def test_records_of_line_runs_before_version_5_keep_the_periodic_window() -> None:
    """A line-contact run recorded before ``[elastic] line_model`` existed ran on the n x n
    periodic window, and its record reads so; its 'adaptive' jumping was the polynomial
    strategy."""
    old = FrettingConfig.model_validate(line_case(10)).model_dump(mode="json")
    del old["elastic"]
    old |= {"config_version": 4, "jump": {**old["jump"], "strategy": "adaptive"}}
    read = recorded_config(json.loads(json.dumps(old)))
    assert read["elastic"] == {"line_model": "periodic-2d"}
    assert read["jump"]["strategy"] == "polynomial"
    point = FrettingConfig().model_dump(mode="json")
    del point["elastic"]
    assert "elastic" not in recorded_config(point | {"config_version": 4})


def test_a_cross_section_run_writes_its_outputs(tmp_path: Path) -> None:
    """Figures and VTK of a run on one cross-section (a strip of the window's side)."""
    import meshio

    data = line_case(3, n=64) | {"output": {"vtk": True, "figures": True}}
    res = run(data, str(tmp_path / "o"))
    assert {"profiles.png", "wear_scar.png", "surface_lower.vtu"} <= set(res.files)
    mesh = meshio.read(tmp_path / "o" / "surface_lower.vtu")
    assert mesh.points.shape[0] == 2 * res.summary["grid"]["n_track"]
    assert np.ptp(mesh.points[:, 1]) == pytest.approx(res.summary["window_m"])
