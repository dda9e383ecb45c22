"""The braking room as a library: ``tribodem.braking.run`` and ``tribodem.braking.sweep``
from Python with dict configs and str paths give what the command line gives (a run, its
resume, a finished run only reported), as ``RunResult`` (``.summary``,
``.to_dataframe()``). Every run is on the tiny cell of the CLI tests (~150 particles)."""

from __future__ import annotations

import json
import tomllib
from pathlib import Path
from typing import Any

import pytest
from conftest import TINY_CELL, run_tribodem

import tribodem.braking
import tribodem.braking.loop as loop_mod
from tribodem.braking import BrakingConfig, RunSetup, run_braking
from tribodem.braking.model import Geometry
from tribodem.io.config import ConfigError, dump_toml
from tribodem.io.record import RunResult

#: 1 us of sliding on the tiny cell (~17k steps), a checkpoint at every sample; the
#: worn-through guard off as in the CLI tests on this cell
RUN = {"duration_s": 1e-6, "samples": 10, "vtk_snapshots": 0, "figures": False,
       "threads": 1, "worn_through_diameters": 0.0}
CONFIG: dict[str, Any] = {**tomllib.loads(TINY_CELL), "run": RUN}


def _numbers(folder: Path) -> dict[str, str]:
    s = json.loads((folder / "summary.json").read_text())
    return {k: repr(v) for k, v in s.items() if not k.startswith("wall_time")}


def _same_run(a: Path, b: Path) -> None:
    assert _numbers(a) == _numbers(b)
    assert (a / "timeseries.csv").read_bytes() == (b / "timeseries.csv").read_bytes()


@pytest.fixture(scope="module")
def lib_run(tmp_path_factory: pytest.TempPathFactory) -> RunResult:
    """An uninterrupted run from Python: a dict config, a str folder."""
    out = tmp_path_factory.mktemp("lib") / "b"
    return tribodem.braking.run(CONFIG, str(out), condition=5)


def test_run_from_python_returns_its_summary_and_table(lib_run: RunResult) -> None:
    r = lib_run
    assert r.out.is_dir() and r.table == "timeseries.csv"
    assert r.summary["status"] == "finished" and r["condition"] == 5
    assert r.summary == json.loads((r.out / "summary.json").read_text())
    df = r.to_dataframe()
    # a row at the start, one per sample, one for the remainder of the steps
    assert len(df) - 1 in (RUN["samples"], RUN["samples"] + 1) and df["time_s"].iloc[0] == 0.0
    assert df["sliding_distance_m"].iloc[-1] == pytest.approx(
        r["simulated_sliding_distance_m"])
    assert {"summary.json", "timeseries.csv", "config.toml", "checkpoint.npz"} <= set(r.files)
    # the folder's config.toml is the resolved config: it reloads to the same model
    assert tribodem.braking.resolve_config(r.out / "config.toml") == \
        tribodem.braking.resolve_config(CONFIG, condition=5)
    assert isinstance(tribodem.braking.resolve_config(CONFIG), BrakingConfig)


def test_summary_states_what_stands_for_the_backing_plate(lib_run: RunResult) -> None:
    """The summary states the backing: the dashpots' impedances are the pad's rho c_p and
    rho c_s (plane strain, table 1 E, nu, rho: closed form), the plate's mass per area is
    the plate mass over W t, and the real back plate's travel under the full pressure over
    the run is p T^2 / (2 m) with the assumed 126 kg/m^2."""
    import math

    from tribodem.braking.model import PLATE_AREAL_MASS, materials

    s = lib_run.summary
    pad = materials("calibrated")[1]
    e, nu, rho = pad.young, pad.poisson, pad.density
    c_p = math.sqrt(e * (1 - nu) / (rho * (1 + nu) * (1 - 2 * nu)))
    c_s = math.sqrt(e / (2 * rho * (1 + nu)))
    assert s["backing"] == "absorbing"
    assert s["backing_impedance_normal_Pa_s_m"] == pytest.approx(rho * c_p, rel=1e-12)
    assert s["backing_impedance_shear_Pa_s_m"] == pytest.approx(rho * c_s, rel=1e-12)
    assert s["backing_plate_areal_mass_kg_m2"] == pytest.approx(
        s["plate_mass_kg"] / (s["cell_width_m"] * 1.0), rel=1e-12)
    assert s["backing_real_plate_areal_mass_kg_m2"] == PLATE_AREAL_MASS == 126.0
    assert s["backing_real_plate_travel_m"] == pytest.approx(
        s["pressure_Pa"] * s["simulated_time_s"] ** 2 / (2 * PLATE_AREAL_MASS), rel=1e-9)
    assert any("back plate" in a for a in s["assumptions"])


def test_interrupted_run_resumed_from_python_equals_the_command_line(
        lib_run: RunResult, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The command line on the same config gives the library's run bitwise; a library
    run interrupted at its 6th sample and resumed from Python (its own config.toml) gives
    it too; resuming the finished run only reports it."""
    cfg = tmp_path / "tiny.toml"
    cfg.write_text(dump_toml(CONFIG))
    cli = tmp_path / "cli"
    r = run_tribodem("braking", "run", "--condition", "5", "--config", str(cfg), "--out",
                     str(cli), "--no-progress", timeout=300)
    assert r.returncode == 0, r.stderr
    _same_run(lib_run.out, cli)
    assert json.loads(r.stdout)["status"] == "finished"

    real, calls = loop_mod.measure, [0]

    def interrupted(*a: object, **k: object) -> dict:
        calls[0] += 1
        if calls[0] == 6:
            raise KeyboardInterrupt
        return real(*a, **k)

    out = str(tmp_path / "lib")
    monkeypatch.setattr(loop_mod, "measure", interrupted)
    with pytest.raises(KeyboardInterrupt):
        tribodem.braking.run(CONFIG, out, condition=5)
    monkeypatch.setattr(loop_mod, "measure", real)
    assert (Path(out) / "checkpoint.npz").is_file()
    assert not (Path(out) / "summary.json").exists()
    res = tribodem.braking.run(None, out, resume=True)
    assert res.summary["status"] == "finished"
    _same_run(cli, Path(out))
    said: list[tuple[str, bool]] = []
    before = (Path(out) / "timeseries.csv").stat().st_mtime_ns
    again = tribodem.braking.run(None, out, resume=True,
                                 echo=lambda s, err=False: said.append((s, err)))
    assert again.summary == res.summary
    assert again.to_dataframe().equals(lib_run.to_dataframe())
    assert any("already finished" in s and err for s, err in said)
    assert (Path(out) / "timeseries.csv").stat().st_mtime_ns == before


def test_bad_library_inputs_are_refused_before_any_work(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="--out"):
        tribodem.braking.run(CONFIG, "", condition=5)
    with pytest.raises(ConfigError, match="--out"):
        tribodem.braking.run(CONFIG, None, condition=5)
    with pytest.raises(ConfigError, match="distance_m"):
        tribodem.braking.run({"run": {"duration_s": 1e-6, "distance_m": 1e-3}},
                             str(tmp_path / "x"), condition=5)
    with pytest.raises(ConfigError, match=r"config: field 'run.samples' = 1"):
        tribodem.braking.run({"run": {"samples": 1}}, str(tmp_path / "x"), condition=5)
    with pytest.raises(ConfigError, match="--conditions"):
        tribodem.braking.sweep(str(tmp_path / "s"), config=CONFIG, conditions=[1, 6])
    with pytest.raises(ConfigError, match="--packings"):
        tribodem.braking.sweep(str(tmp_path / "s"), config=CONFIG, packings=0)
    assert list(tmp_path.iterdir()) == []


def test_run_braking_takes_a_str_folder(tmp_path: Path) -> None:
    geo = Geometry(width=100e-6, disc_height=36e-6, pad_height=36e-6, amplitude=4e-6,
                   modes=2, seed=3)
    setup = RunSetup(pressure_Pa=0.53e6, speed_m_s=47.12, duration_s=0.1e-6, geometry=geo,
                     condition=5, samples=2, vtk_snapshots=0, figures=False,
                     worn_through_diameters=0.0)
    s = run_braking(setup, str(tmp_path / "rb"))
    assert s["status"] == "finished" and (tmp_path / "rb" / "summary.json").is_file()


def test_sweep_from_python_returns_one_row_per_member(tmp_path: Path) -> None:
    """Two members on a one-worker local cluster; the same sweep again skips both without
    a cluster and gives the same table."""
    config = {**CONFIG, "run": {**RUN, "duration_s": 0.3e-6, "samples": 6}}
    out = str(tmp_path / "s")
    said: list[str] = []
    r = tribodem.braking.sweep(out, config=config, conditions=[5, 1], workers=1,
                               echo=lambda s, err=False: said.append(s))
    df = r.to_dataframe()
    assert r.table == "members.csv" and list(df["condition"]) == [1, 5]
    assert list(df["status"]) == ["finished"] * 2 and list(df["packing"]) == [0, 0]
    assert list(df["folder"]) == ["condition_1", "condition_5"]
    for k, w in zip(df["condition"], df["wear_depth_mean_m"], strict=True):
        s = json.loads((tmp_path / "s" / f"condition_{k}" / "summary.json").read_text())
        assert repr(float(s["wear_depth_mean_m"])) == repr(float(w))
    assert r.summary["ran"] == 2 and r.summary["conditions"] == [1, 5]
    assert r.summary["comparison"]["conditions"] == {"1": 1, "5": 1}
    assert {"comparison.md", "comparison.csv", "comparison.json", "members.csv"} <= set(
        r.files)
    assert any("2 run, 0 skipped" in s for s in said)
    again = tribodem.braking.sweep(out, config=config, conditions=[1, 5])
    assert again.summary["ran"] == 0 and again.summary["skipped"] == 2
    assert again.to_dataframe().equals(df)
