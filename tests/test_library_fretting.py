"""tribodem.fretting as a library: a run, its resume and a sweep from Python, with dict
configs and str paths, giving what the command gives.

Tiny cases (32^2 half-space, 8 increments a cycle, no figures or VTK): the physics is
tested elsewhere."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from conftest import run_tribodem, without_timings

import tribodem.fretting
from tribodem.fretting import RESULT_COLUMNS, FrettingConfig, run
from tribodem.io.config import ConfigError, dump_toml
from tribodem.io.record import RunResult

SMALL = {"contact": {"n": 32, "n_increments": 8},
         "output": {"figures": False, "vtk": False}}


def _same_run(a: Path, b: Path) -> None:
    """The same results.csv and config.toml, bitwise, and the same summary numbers."""
    for name in ("results.csv", "config.toml"):
        assert (a / name).read_bytes() == (b / name).read_bytes(), name
    sa = json.loads((a / "summary.json").read_text())
    sb = json.loads((b / "summary.json").read_text())
    assert without_timings(sa) == without_timings(sb)


def test_a_run_from_a_dict_returns_its_table_and_summary(tmp_path: Path) -> None:
    res = run({**SMALL, "cycles": 3}, str(tmp_path / "a"))
    assert isinstance(res, RunResult) and res.out == tmp_path / "a"
    df = res.to_dataframe()
    assert len(df) == 3 and list(df["cycle"]) == [1, 2, 3]
    assert list(df.columns) == list(RESULT_COLUMNS)
    assert res.summary["cycles"] == 3 and res["wear_volume_lower_m3"] > 0
    assert df["wear_volume_lower_m3"].iloc[-1] == pytest.approx(res["wear_volume_lower_m3"],
                                                                rel=1e-12)
    assert "results.csv" in res.files and (tmp_path / "a" / "config.toml").is_file()
    # the preset and the overrides go over the dict: defaults <- config <- quick <- overrides
    q = tribodem.fretting.resolve_config(SMALL, quick=True, overrides={"cycles": 2})
    assert (q.cycles, q.contact.n) == (2, 64)
    assert FrettingConfig.quick().contact.n == 64
    with pytest.raises(ConfigError, match="cycles"):
        run({"cycles": 0}, str(tmp_path / "bad"))
    with pytest.raises(ConfigError, match="--out"):
        run(SMALL, "")
    assert not (tmp_path / "bad").exists()


def test_resume_from_python_equals_the_uninterrupted_run_and_the_command(
        tmp_path: Path) -> None:
    """2 cycles, then ``resume=True`` with ``cycles`` raised to 4 (the checkpoint's own
    config): bitwise the uninterrupted 4-cycle run, and what ``tribodem fretting run
    --resume`` makes of the same 2 cycles."""
    whole = run({**SMALL, "cycles": 4}, str(tmp_path / "whole"))
    run({**SMALL, "cycles": 2}, str(tmp_path / "py"))
    resumed = run(None, str(tmp_path / "py"), resume=True, overrides={"cycles": 4})
    assert len(resumed.to_dataframe()) == 4
    _same_run(whole.out, resumed.out)
    cfg = tmp_path / "small.toml"
    cfg.write_text(dump_toml(SMALL))
    cli = tmp_path / "cli"
    r = run_tribodem("fretting", "run", "--config", str(cfg), "--cycles", "2",
                     "--no-progress", "--out", str(cli), timeout=120)
    assert r.returncode == 0, r.stderr
    r = run_tribodem("fretting", "run", "--resume", "--cycles", "4", "--no-progress",
                     "--out", str(cli), timeout=120)
    assert r.returncode == 0, r.stderr
    _same_run(whole.out, cli)


def test_a_sweep_of_dict_rows_and_of_a_dataframe(tmp_path: Path) -> None:
    """Two members from dict rows on a one-worker local cluster: sweep.csv as a DataFrame
    with a row each; the same table as a DataFrame again skips both (no cluster)."""
    pytest.importorskip("distributed")
    pd = pytest.importorskip("pandas")
    rows = [{"name": "heavy", "contact.load": 100, "cycles": 2},
            {"name": "light", "contact.load": 50.0, "cycles": 2}]
    res = tribodem.fretting.sweep(rows, str(tmp_path / "s"), config=SMALL, workers=1)
    df = res.to_dataframe()
    assert len(df) == 2 and list(df["name"]) == ["heavy", "light"]
    assert list(df["status"]) == ["done", "done"] and list(df["cycles_done"]) == [2, 2]
    assert res.summary["members"] == 2 and res.summary["run"] == 2
    heavy, light = df["wear_volume_lower_m3"]
    assert heavy > light > 0
    lines: list[str] = []
    again = tribodem.fretting.sweep(pd.DataFrame(rows), tmp_path / "s", config=SMALL,
                                    echo=lines.append)
    assert again.summary["skipped"] == 2 and again.summary["run"] == 0
    assert any("heavy: finished earlier, skipped" in s for s in lines)
    with pytest.raises(ConfigError, match="row 1 .*contact.load"):
        tribodem.fretting.sweep([{"contact.load": -1}], tmp_path / "t", config=SMALL)


def test_a_study_of_two_stages_returns_its_stage_table(tmp_path: Path) -> None:
    """``study`` with two of the chapter 6 stages: study.csv, a row per stage; a stage
    name that is not the study's is refused before any work."""
    cfg = {**SMALL, "wear": {"stress_nz": 9, "stress_samples": 4}}
    res = tribodem.fretting.study(cfg, str(tmp_path / "st"), stages=["von_mises", "s22"])
    df = res.to_dataframe()
    assert list(df["stage"]) == ["von_mises", "s22"] and list(df["cycles"]) == [1, 1]
    assert sorted(res.summary["ranking_ours"]) == ["s22", "von_mises"]
    assert "study.csv" in res.files and (tmp_path / "st" / "von_mises" / "results.csv").is_file()
    with pytest.raises(ConfigError, match="--stages"):
        tribodem.fretting.study(cfg, str(tmp_path / "no"), stages="wear")
