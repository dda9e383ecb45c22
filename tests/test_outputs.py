"""The outputs read back with the libraries that read them (meshio, json, csv, matplotlib),
the packaging, the messages on stderr and the help texts."""

from __future__ import annotations

import ast
import csv
import json
import os
import re
import shutil
import subprocess
import sys
import tomllib
import types
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from conftest import TINY_CELL, TINY_RUN, run_tribodem

ROOT = Path(__file__).resolve().parents[1]
needs_ccx = pytest.mark.skipif(shutil.which("ccx") is None,
                               reason="CalculiX ccx not installed (apt install calculix-ccx)")


# --- packaging ------------------------------------------------------------------------------

def _pyproject() -> dict:
    return tomllib.loads((ROOT / "pyproject.toml").read_text())


#: import name -> the declared distribution that brings it, where they differ
#: (pydantic_core: pydantic pins its own, so pydantic is the requirement)
DIST = {"tomli_w": "tomli-w", "distributed": "dask", "pydantic_core": "pydantic"}


def _requirement_names(reqs: list[str]) -> set[str]:
    return {re.split(r"[\[<>=!~; ]", r, maxsplit=1)[0].lower() for r in reqs}


def test_pyproject_metadata_and_one_version() -> None:
    """SPDX license with its file, authors, URLs, classifiers, the version from
    ``tribodem.__version__`` only, py.typed shipped."""
    import tribodem

    proj = _pyproject()["project"]
    assert proj["license"] == "BSD-3-Clause" and proj["license-files"] == ["LICENSE"]
    assert (ROOT / "LICENSE").is_file() and (ROOT / "CITATION.cff").is_file()
    assert proj["authors"] == [{"name": "The tribodem developers"}]
    assert {"Homepage", "Repository", "Documentation", "Issues"} <= set(proj["urls"])
    assert all(u.startswith("https://github.com/tribodem/tribodem")
               for u in proj["urls"].values())
    assert "Typing :: Typed" in proj["classifiers"]
    assert not any(c.startswith("License ::") for c in proj["classifiers"])  # PEP 639
    assert "version" not in proj and proj["dynamic"] == ["version"]
    tool = _pyproject()["tool"]["setuptools"]
    assert tool["dynamic"]["version"] == {"attr": "tribodem.__version__"}
    assert tool["package-data"]["tribodem"] == ["py.typed"]
    assert (ROOT / "tribodem" / "py.typed").is_file()
    assert re.fullmatch(r"\d+\.\d+\.\d+", tribodem.__version__)
    cff = (ROOT / "CITATION.cff").read_text()
    assert f"version: {tribodem.__version__}" in cff
    assert any(r.startswith("setuptools>=") and int(r.split(">=")[1].split(".")[0]) >= 77
               for r in _pyproject()["build-system"]["requires"])  # PEP 639 license


def _third_party_imports() -> set[str]:
    names: set[str] = set()
    for path in (ROOT / "tribodem").rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                names |= {a.name.split(".")[0] for a in node.names}
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names.add(node.module.split(".")[0])
    return {n for n in names if n not in sys.stdlib_module_names and n != "tribodem"}


def test_every_runtime_import_is_a_declared_dependency() -> None:
    """Each package tribodem imports is a dependency, or (dask) in the extra ``cluster``
    (with dask-jobqueue, for the batch-cluster example); the extra ``test`` holds the
    cluster's packages, ``docs`` mkdocs."""
    proj = _pyproject()["project"]
    deps = _requirement_names(proj["dependencies"])
    extras = {k: _requirement_names(v) for k, v in proj["optional-dependencies"].items()}
    for name in sorted(_third_party_imports()):
        dist = DIST.get(name, name).lower()
        assert dist in deps or dist in extras["cluster"], name
    assert "dask" not in deps and extras["cluster"] == {"dask", "dask-jobqueue"}
    assert extras["cluster"] <= extras["test"]
    assert {"mkdocs", "mkdocstrings"} <= extras["docs"]
    assert {"pytest", "pytest-xdist", "hypothesis", "ruff", "import-linter"} <= extras["test"]


def test_python_m_tribodem_is_the_command() -> None:
    import tribodem

    r = subprocess.run([sys.executable, "-m", "tribodem", "--version"], capture_output=True,
                       text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines()[0] == f"tribodem {tribodem.__version__}"


def test_without_dask_a_cluster_command_names_the_extra(monkeypatch: pytest.MonkeyPatch
                                                        ) -> None:
    """Dask missing: the sweeps and calibrate's workers are refused before any work, naming
    ``pip install 'tribodem[cluster]'``; calibrate in this process needs no Dask."""
    from tribodem.io import ensemble
    from tribodem.io.config import ConfigError

    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed fails
    for cmd in ("braking sweep", "fretting sweep"):
        with pytest.raises(ConfigError, match=re.escape("pip install 'tribodem[cluster]'")):
            ensemble.check_cluster_options(cmd, 0, None)
    with pytest.raises(ConfigError, match="--workers 1 to run in this process"):
        ensemble.check_cluster_options("calibrate", 2, None, alternative="--workers 1 to run "
                                       "in this process")
    ensemble.check_cluster_options("calibrate", 1, None, in_process=True)
    with pytest.raises(ConfigError, match="distributed is not installed"):
        ensemble.open_client(None, 1)


# --- messages on stderr ---------------------------------------------------------------------

def test_configure_sets_what_is_shown(capsys: pytest.CaptureFixture[str]) -> None:
    import logging

    from tribodem.io import logs

    log = logging.getLogger("tribodem.test_outputs")
    try:
        for verbosity, shown in ((-1, {"warning"}), (0, {"warning", "info"}),
                                 (1, {"warning", "info", "debug"})):
            logs.configure(verbosity)
            log.debug("debug")
            log.info("info")
            log.warning("warning")
            err = capsys.readouterr().err
            assert {w for w in ("debug", "info", "warning") if w in err} == shown
            assert capsys.readouterr().out == ""
        logs.configure(0)
        log.info("bare")
        assert capsys.readouterr().err == "bare\n"  # default: the bare text
    finally:
        top = logging.getLogger(logs.ROOT)
        if logs._handler is not None:
            top.removeHandler(logs._handler)
            logs._handler = None
        top.propagate = True
        top.setLevel(logging.NOTSET)


def test_the_compile_note_comes_once_and_only_on_a_cold_cache(tmp_path: Path) -> None:
    """A process that compiles (numba's disk cache empty) says the note once, before the
    compile; the next process, loading from the cache, says nothing."""
    from tribodem.io.logs import COMPILE_NOTE

    (tmp_path / "kern.py").write_text(
        "import numba\nfrom tribodem.io.logs import configure\nconfigure(0)\n\n\n"
        "@numba.njit(cache=True)\ndef f(x):\n    return x + 1\n\n\n"
        "@numba.njit(cache=True)\ndef g(x):\n    return x * 2\n\n\n"
        "print(f(1), g(2))\n")
    env = {"NUMBA_CACHE_DIR": str(tmp_path / "cache"), "PATH": "/usr/bin:/bin",
           "PYTHONPATH": str(ROOT)}
    cold = subprocess.run([sys.executable, "kern.py"], cwd=tmp_path, capture_output=True,
                          text=True, env=env, timeout=300)
    assert cold.returncode == 0, cold.stderr
    assert cold.stderr.count(COMPILE_NOTE) == 1 and cold.stdout == "2 4\n"
    warm = subprocess.run([sys.executable, "kern.py"], cwd=tmp_path, capture_output=True,
                          text=True, env=env, timeout=300)
    assert warm.returncode == 0 and COMPILE_NOTE not in warm.stderr


# --- braking --------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def braking_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The tiny braking cell of the CLI tests: 1 us, 12 rows, 3 snapshots, figures."""
    d = tmp_path_factory.mktemp("braking")
    cfg = d / "tiny.toml"
    cfg.write_text(TINY_CELL + "[run]\nduration_s = 1e-6\nsamples = 12\nvtk_snapshots = 3\n"
                   + TINY_RUN)
    out = d / "run"
    r = run_tribodem("braking", "run", "--condition", "5", "--config", str(cfg), "--out",
                     str(out), "--no-progress")
    assert r.returncode == 0, r.stderr
    return out


def test_a_rate_not_steady_is_null_with_the_reason(braking_run: Path) -> None:
    s = json.loads((braking_run / "summary.json").read_text())
    assert s["steady_reached"] is False
    assert s["wear_rate_steady_m_per_m"] is None and s["wear_rate_steady_reason"]
    assert isinstance(s["wear_rate_last_two_thirds_m_per_m"], float)


def test_steady_reasons() -> None:
    from tribodem.braking.steady import steady_reason, steady_state

    s = np.linspace(0.0, 1e-3, 30)
    assert steady_reason(steady_state(s, 2e-3 * s), 0.15) is None
    falling = steady_state(s, -2e-3 * s)
    assert "positive" in steady_reason(falling, 0.15)
    bent = steady_state(s, 1e-3 * s**2 / s[-1])
    assert "still changing" in steady_reason(bent, 0.15)
    assert "too few" in steady_reason(steady_state(s[:4], s[:4]), 0.15)


def test_force_chains_read_back_with_their_lines(braking_run: Path) -> None:
    """Every chains file the ``.pvd`` lists is read by meshio with its line cells and their
    data (a snapshot without chains has no file); the particles have 3D points."""
    import meshio

    vtk = braking_run / "vtk"
    listed = [d.get("file") for d in ET.parse(vtk / "chains.pvd").getroot().iter("DataSet")]
    assert listed and sorted(listed) == sorted(p.name for p in vtk.glob("chains_*.vtu"))
    for name in listed:
        m = meshio.read(vtk / name)
        lines = m.cells_dict["line"]
        assert len(lines) > 0 and lines.max() < len(m.points)
        assert m.cell_data_dict["normal_force"]["line"].shape == (len(lines),)
    parts = [d.get("file") for d in ET.parse(vtk / "particles.pvd").getroot().iter("DataSet")]
    assert len(parts) == 3
    for name in parts:
        m = meshio.read(vtk / name)
        assert m.points.shape[1] == 3 and np.all(m.points[:, 2] == 0.0)
        assert len(m.cells_dict["vertex"]) == len(m.points)


def test_wear_history_one_quantity_per_axis(braking_run: Path) -> None:
    from matplotlib.image import imread

    from tribodem.braking.plots import HISTORY_PANELS

    img = imread(braking_run / "wear_history.png")
    assert img.ndim == 3 and img.shape[0] > 600
    units = [re.search(r"\(([^)]+)\)$", ylabel) for _, ylabel, _ in HISTORY_PANELS]
    assert all(units), "every axis names its unit"
    for _, _, curves in HISTORY_PANELS:
        assert all("_" not in label for _, label, _ in curves)  # words, not column names
    rows = list(csv.DictReader((braking_run / "timeseries.csv").open()))
    assert all(key in rows[0] for _, _, curves in HISTORY_PANELS for key, _, _ in curves)


def _fake_run(folder: Path, rate: float, depth: float) -> tuple[dict, Path]:
    folder.mkdir(parents=True)
    t = np.linspace(0.0, 1e-6, 6)
    with (folder / "timeseries.csv").open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["time_s", "wear_depth_mean_m", "force_chains", "strong_force_chains"])
        for k, tk in enumerate(t):
            w.writerow([tk, depth * k / 5, 100 + k, 40 + k])
    s = {"wear_depth_mean_m": depth, "wear_rate_last_two_thirds_m_per_m": rate,
         "wear_rate_steady_m_per_m": None, "steady_reached": False, "contact_fraction": 0.9,
         "pressure_Pa": 0.4e6, "sliding_speed_m_s": 40.0, "simulated_time_s": 1e-6,
         "simulated_sliding_distance_m": 4e-5, "wear_depth_max_m": 2 * depth,
         "wear_depth_mean_disc_m": 0.0, "broken_bonds": 10, "broken_bonds_tensile": 6,
         "broken_bonds_shear": 4, "debris_particles": 3, "mean_wall_pressure_ratio": 1.0,
         "particles_final": 100, "particles_initial": 100, "wall_time_s": 1.0,
         "wear_depth_mean_extrapolated_8s_m": depth, "steady_wear_rate_m_s": 0.0}
    return s, folder


def test_no_percent_change_between_negative_rates(tmp_path: Path) -> None:
    """Two negative rates (-1e-3 -> -2.26e-3 m/m would read +126 %): no percentage, the
    reason in comparison.csv and a '-' in comparison.md; positive depths keep theirs."""
    from tribodem.braking.compare import _pct, pct_reason, write_comparison

    assert np.isnan(_pct(-1e-3, -2.2588e-3)) and _pct(1.0, 1.5) == pytest.approx(50.0)
    assert pct_reason(1.0, 2.0) is None and "positive" in pct_reason(-1.0, -2.0)
    runs = {1: [_fake_run(tmp_path / "c1", -1e-3, 1e-6)],
            5: [_fake_run(tmp_path / "c5", -2.2588e-3, 1.2e-6)]}
    write_comparison(tmp_path, runs, 1.0, "here", quick=True)
    rows = {r["change"]: r for r in csv.DictReader((tmp_path / "comparison.csv").open())}
    r = rows["load 13->21 kN"]
    assert r["wear_rate_change_pct"] == "nan" and "positive" in r["wear_rate_change_reason"]
    assert float(r["wear_depth_change_pct"]) == pytest.approx(20.0)
    assert r["wear_depth_change_reason"] == ""
    assert "+125" not in (tmp_path / "comparison.md").read_text()
    j = json.loads((tmp_path / "comparison.json").read_text())
    wear = [t for t in j["trends"] if t["change"] == "load 13->21 kN"
            and t["quantity"] == "wear_depth"][0]
    assert wear["ours_pct"] == pytest.approx(20.0) and wear["ours_pct_reason"] is None
    assert "not evaluated" in j["verdicts"]["steady wear rate per distance rises with load"]


# --- fretting -------------------------------------------------------------------------------

def test_zero_wear_says_why(tmp_path: Path) -> None:
    """A threshold never reached: summary.json's wear_zero_reason names it and the largest
    value reached."""
    from tribodem.fretting import run

    res = run({"wear": {"criterion": "von_mises", "yield_strength": 2e10},
               "output": {"figures": False, "vtk": False}}, tmp_path / "r", quick=True,
              overrides={"cycles": 1})
    s = json.loads((tmp_path / "r" / "summary.json").read_text())
    assert s["wear_volume_upper_m3"] == s["wear_volume_lower_m3"] == 0.0
    assert s["wear_zero_reason"] == res.summary["wear_zero_reason"]
    assert "never reached its threshold 2e+10 Pa" in s["wear_zero_reason"]
    assert "largest over the last simulated cycle: upper" in s["wear_zero_reason"]


def test_zero_wear_reasons_of_each_kind() -> None:
    from tribodem.fretting.output import wear_zero_reason

    base = {"wear_volume_upper_m3": 0.0, "wear_volume_lower_m3": 0.0, "cycles": 1,
            "dissipated_energy_total_J": 1e-3}
    assert wear_zero_reason({**base, "wear_volume_lower_m3": 1e-15}) is None
    assert "no cycle" in wear_zero_reason({**base, "cycles": 0})
    dfdi = wear_zero_reason({**base, "criterion": {"name": "dfdi", "kind": "threshold"},
                             "criterion_last_cycle": {"max_dfdi_upper": 0.2,
                                                      "max_dfdi_lower": 0.3}})
    assert "DFDI" in dfdi and "upper 0.2, lower 0.3" in dfdi
    swt = wear_zero_reason({**base, "criterion": {"name": "swt", "kind": "threshold"},
                            "criterion_last_cycle": {"miner_sum_max_upper": 1e-3,
                                                     "miner_sum_max_lower": 2e-3,
                                                     "cycles_to_first_wear_upper": 900.0,
                                                     "cycles_to_first_wear_lower": 480.0}})
    assert "Miner" in swt and "cycles to first wear: upper 900, lower 480" in swt
    shear = wear_zero_reason({**base, "criterion": {"name": "shear", "kind": "threshold",
                                                    "threshold": 1.0, "unit": "-"},
                              "criterion_last_cycle": {"max_value_upper": 0.5,
                                                       "max_value_lower": 0.6}})
    assert shear.endswith("threshold 1 (largest over the last simulated cycle: upper 0.5, "
                          "lower 0.6)")
    stick = wear_zero_reason({**base, "dissipated_energy_total_J": 0.0,
                              "criterion": {"name": "energy", "kind": "rate"}})
    assert "no slip" in stick


def test_debris_layer_titles_clear_of_the_colour_bars() -> None:
    from tribodem.fretting.output import debris_layer_figure

    rng = np.random.default_rng(0)
    pos = np.column_stack([rng.uniform(-6e-4, 6e-4, (3000, 2)), np.zeros(3000)])
    ph = types.SimpleNamespace(positions=pos, start_positions=pos - 1e-9, cycle=160,
                               particle_force=rng.normal(0, 1e-3, (3000, 3)), particles=3000)
    fig = debris_layer_figure(ph)
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    main, bars = fig.axes[:2], fig.axes[2:]
    assert len(bars) == 2
    for ax in main:
        title = ax.title.get_window_extent(renderer)
        assert title.x0 >= fig.bbox.x0 and title.x1 <= fig.bbox.x1
        assert title.y1 <= fig.bbox.y1
        assert not any(title.overlaps(b.get_tightbbox(renderer)) for b in bars)


def test_quick_study_runs_every_stage_in_its_window() -> None:
    """--quick: DFDI on the elastic backend's plastic counterpart; the multi-cycle threshold
    stages on a window of 20 contact radii; the others as configured."""
    from tribodem.fretting.case import FrettingCase, check_compatible
    from tribodem.fretting.chapter6 import (
        QUICK_THRESHOLD_WINDOW_RADII,
        quick_stage,
        stage_config,
        stages,
    )
    from tribodem.fretting.config import resolve_config

    cfg = resolve_config(None, quick=True)
    plan = {s.name: s for s in stages(quick=True)}
    dfdi, notes = quick_stage(stage_config(cfg, plan["dfdi"]), plan["dfdi"])
    assert dfdi.solver == "elastic-plastic" and notes["solver"] == "elastic-plastic"
    check_compatible(dfdi)
    a = FrettingCase.of(cfg).hertz_radius
    for name in ("shear", "shear_jump"):
        scfg, notes = quick_stage(stage_config(cfg, plan[name]), plan[name])
        assert scfg.contact.window == pytest.approx(QUICK_THRESHOLD_WINDOW_RADII * a)
        assert "window" in notes["quick_note"]
    for name in ("von_mises", "energy"):
        scfg, notes = quick_stage(stage_config(cfg, plan[name]), plan[name])
        assert notes == {} and scfg == stage_config(cfg, plan[name])


FE_CONFIG = {"cycles": 1, "solver": "fe",
             "contact": {"geometry": "cylinder_on_flat", "radius": 4e-3,
                         "load_per_length": 1.0e5, "amplitude": 10e-6, "n_increments": 4,
                         "n": 64},
             "fe": {"h_over_a": 0.5}, "output": {"figures": False, "vtk": True}}


@needs_ccx
def test_fe_fields_open_in_meshio_with_a_pvd(tmp_path: Path) -> None:
    """Each ccx job's mesh and fields as job.vtu (meshio reads it: quads, the stresses of
    the printed elements, the materials), listed in fe/fields.pvd with its cycle."""
    import meshio

    from tribodem.fretting import run

    res = run(FE_CONFIG, tmp_path / "r")
    fe = tmp_path / "r" / "fe"
    assert "fe/fields.pvd" in res.summary["files"]
    entries = [(float(d.get("timestep")), d.get("file"))
               for d in ET.parse(fe / "fields.pvd").getroot().iter("DataSet")]
    assert entries == [(1.0, "cycle_0001/job.vtu")]
    job = next(csv.DictReader((fe / "jobs.csv").open()))
    m = meshio.read(fe / "cycle_0001" / "job.vtu")
    quads = m.cells_dict["quad"]
    assert len(quads) == int(job["elements"]) and quads.max() < len(m.points)
    stress = m.cell_data_dict["stress_Pa"]["quad"]
    vm = m.cell_data_dict["von_mises_Pa"]["quad"]
    printed = np.isfinite(stress[:, 0])
    assert stress.shape == (len(quads), 6) and 0 < printed.sum() < len(quads)
    assert 1e8 < np.nanmax(vm) < 1e10  # a steel contact at ~1 GPa
    assert set(np.unique(m.cell_data_dict["material"]["quad"])) == {1, 2}


def test_frd_mesh_reader_and_vtu(tmp_path: Path) -> None:
    """A hand-written .frd (two quads) and .dat (one element's stresses at two times): the
    .vtu holds the mesh and the last time's mean stress of the printed element."""
    import meshio

    from tribodem.contact.fe.fields import job_vtu

    def node(i: int, x: float, y: float) -> str:
        return f" -1{i:10d}{x:12.5E}{y:12.5E}{0.0:12.5E}"

    nodes = [node(1, 0, 0), node(2, 1, 0), node(3, 2, 0), node(4, 0, 1), node(5, 1, 1),
             node(6, 2, 1)]
    frd = ["    1C", "    1UMAT    1MLOWER", f"    2C{6:30d}{1:37d}", *nodes, " -3",
           f"    3C{2:30d}{1:37d}",
           " -1         1    9    0    1", " -2         1         2         5         4",
           " -1         2    9    0    2", " -2         2         3         6         5",
           " -3", " 9999"]
    (tmp_path / "job.frd").write_text("\n".join(frd) + "\n")
    head = " stresses (elem, integ.pnt.,sxx,syy,szz,sxy,sxz,syz) for set S and time  {}"
    dat = [head.format("0.1000000E+01"), "", "  2 1 9 9 9 9 9 9", "",
           head.format("0.2000000E+01"), "", "  2 1 1 2 3 4 5 6", "  2 2 3 4 5 6 7 8", ""]
    (tmp_path / "job.dat").write_text("\n".join(dat) + "\n")
    m = meshio.read(job_vtu(tmp_path / "job.frd"))
    assert m.points.shape == (6, 3) and m.cells_dict["quad"].tolist() == [[0, 1, 4, 3],
                                                                           [1, 2, 5, 4]]
    s = m.cell_data_dict["stress_Pa"]["quad"]
    assert np.isnan(s[0]).all()
    # ccx's (xx, yy, zz, xy, xz, yz) mean (2, 3, 4, 5, 6, 7) in ParaView's order
    assert s[1].tolist() == [2.0, 3.0, 4.0, 5.0, 7.0, 6.0]
    assert m.cell_data_dict["material"]["quad"].tolist() == [1, 2]


# --- STL through meshio ---------------------------------------------------------------------

@pytest.mark.parametrize("binary", [True, False])
def test_stl_is_read_by_meshio(tmp_path: Path, binary: bool) -> None:
    import meshio

    from tribodem.io.stl import heightmap_to_triangles, write_stl

    tri = heightmap_to_triangles(np.linspace(0, 1e-3, 4), np.linspace(0, 2e-3, 3),
                                 np.zeros((4, 3)))
    path = write_stl(tmp_path / "s.stl", tri, binary=binary)
    with np.errstate(over="ignore"):  # meshio sizes an ASCII file as binary first
        m = meshio.read(path)
    assert len(m.cells_dict["triangle"]) == len(tri)
    assert np.allclose(m.points[m.cells_dict["triangle"]], tri)


# --- help texts ------------------------------------------------------------------------------

def _commands() -> list[tuple[str, object]]:
    import typer

    from tribodem.cli import full_app

    out = []

    def walk(c: object, path: str) -> None:
        out.append((path, c))
        for name, sub in getattr(c, "commands", {}).items():
            walk(sub, f"{path} {name}")

    walk(typer.main.get_command(full_app()), "tribodem")
    return out


def test_help_paragraphs_wrap_to_the_terminal() -> None:
    """No command's help keeps its docstring's line breaks inside a paragraph (typer would
    break each of them again on a narrow terminal); every equation cited names its paper."""
    from tribodem.io.helptext import reflow

    assert reflow("a\n    b\n\n    c\n    - d\n    - e\n      f") == "a b\n\nc\n- d\n- e f"
    # the room commands of this change (jump's are another room's)
    for path, cmd in _commands():
        if not path.startswith(("tribodem braking", "tribodem fretting", "tribodem dem",
                                "tribodem bench", "tribodem calibrate", "tribodem validate")):
            continue
        for para in (cmd.help or "").split("\n\n"):
            assert "\n" not in para.replace("\n- ", " - "), (path, para)
        texts = [cmd.help or ""] + [p.help or "" for p in cmd.params if getattr(p, "help", None)]
        for t in texts:
            for m in re.finditer(r"\beqs? \d+", t):
                before = t[max(0, m.start() - 40):m.start()]
                assert re.search(r"Sha et al|Lu \(?2018", before), (path, t)
            assert "seed 00" not in t, (path, t)


def test_help_of_the_sweep_on_80_columns() -> None:
    r = run_tribodem("braking", "sweep", "--help", env={**os.environ, "COLUMNS": "80"})
    assert r.returncode == 0, r.stderr
    lines = [ln.strip() for ln in r.stdout.splitlines()]
    assert "own" not in lines and not any(ln in ("members,", "worker lost") for ln in lines)
    assert "idempotent task with its" in r.stdout
