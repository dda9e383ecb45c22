"""``tribodem fretting sweep``: the ensemble mechanics, through the installed command.

A 3-row table on a 2-worker local Dask cluster gives per-member results identical (bytes of
results.csv and config.toml) to the same configs run alone with ``fretting run``; a re-run
skips every finished member without starting a cluster; a re-run after a row changed, a
summary lost and a failing row added re-runs only the changed member, resumes the one from
its checkpoint, reports the failed one and exits 3; a bad table exits 2 naming row, field
and value, before anything is written. Tiny cases: 64^2 half-space (``elastic``), 2-3
cycles, no figures or VTK (physics is tested elsewhere)."""

from __future__ import annotations

import csv
import json
import shutil
import subprocess
from pathlib import Path

import pytest
from conftest import run_tribodem, tribodem_exe

pytest.importorskip("distributed")

BASE = """[output]
figures = false
vtk = false
"""
TABLE = """name,contact.load,wear.criterion,cycles
a,100,energy,2
b,50,archard,3
c,80,energy,2
"""
#: the same members as TOML configs of their own (``--quick`` spelt out: contact.n 64,
#: wear.stress_nz 17, debris.ramp_steps 4000)
ALONE = """cycles = {cycles}
solver = "elastic"

[contact]
n = 64
load = {load}

[wear]
criterion = "{criterion}"
stress_nz = 17

[debris]
ramp_steps = 4000

[output]
figures = false
vtk = false
"""
#: b's load changed, new columns empty (the base's values) for a, b, c, and a row d whose
#: solver cannot be built (a line contact in the Ciavarella-Jaeger regime on the periodic
#: window: the half-space solver refuses it when it is built, in the member's task)
CHANGED = ("name,contact.geometry,contact.regime,elastic.line_model,contact.load,"
           "wear.criterion,cycles\n") + """a,,,,100,energy,2
b,,,,60,archard,3
c,,,,80,energy,2
d,cylinder_on_flat,ciavarella-jaeger,periodic-2d,100,energy,2
"""
ROWS = {"a": (100.0, "energy", 2), "b": (50.0, "archard", 3), "c": (80.0, "energy", 2)}


def _sweep(root: Path, table: str, out: Path, *extra: str) -> subprocess.CompletedProcess:
    """The sweep of ``table`` (written beside ``out``) on ``root/base.toml``, --quick."""
    t = out.parent / "table.csv"
    t.write_text(table)
    return run_tribodem("fretting", "sweep", "--table", str(t), "--out", str(out),
                        "--config", str(root / "base.toml"), "--quick", "--no-progress",
                        *extra, timeout=300)


def _rows(out: Path) -> dict[str, dict[str, str]]:
    with (out / "sweep.csv").open() as fh:
        return {r["name"]: r for r in csv.DictReader(fh)}


@pytest.fixture(scope="module")
def root(tmp_path_factory: pytest.TempPathFactory) -> Path:
    r = tmp_path_factory.mktemp("fsweep")
    (r / "base.toml").write_text(BASE)
    return r


@pytest.fixture(scope="module")
def swept(root: Path) -> Path:
    """The 3-row sweep on a 2-worker local cluster."""
    out = root / "S"
    r = _sweep(root, TABLE, out, "--workers", "2")
    assert r.returncode == 0, r.stderr
    assert "local cluster of 2 worker process(es)" in r.stdout
    assert "3 run, 0 skipped" in r.stdout and "Traceback" not in r.stderr
    return out


def test_members_equal_the_same_configs_run_alone(root: Path, swept: Path) -> None:
    procs = {}
    for name, (load, crit, cycles) in ROWS.items():
        cfg = root / f"alone_{name}.toml"
        cfg.write_text(ALONE.format(load=load, criterion=crit, cycles=cycles))
        procs[name] = subprocess.Popen(
            [tribodem_exe(), "fretting", "run", "--config", str(cfg), "--out",
             str(root / f"alone_{name}"), "--no-progress"], stdout=subprocess.PIPE,
            stderr=subprocess.PIPE, text=True)
    for p in procs.values():
        _, err = p.communicate(timeout=300)
        assert p.returncode == 0, err
    rows = _rows(swept)
    assert list(rows) == ["a", "b", "c"]
    for name, (load, crit, cycles) in ROWS.items():
        alone, member = root / f"alone_{name}", swept / name
        for f in ("results.csv", "config.toml"):
            assert (member / f).read_bytes() == (alone / f).read_bytes(), (name, f)
        s = json.loads((alone / "summary.json").read_text())
        r = rows[name]
        assert r["status"] == "done" and r["message"] == ""
        assert (r["contact.load"], r["wear.criterion"], r["cycles"]) == (
            f"{load:g}", crit, str(cycles))
        assert int(r["cycles_done"]) == cycles == s["cycles"]
        for k in ("wear_depth_upper_m", "wear_depth_lower_m", "wear_volume_upper_m3",
                  "wear_volume_lower_m3"):
            assert float(r[k]) == s[k], (name, k)
    j = json.loads((swept / "sweep.json").read_text())
    assert (j["members"], j["done"], j["failed"], j["run"]) == (3, 3, 0, 3)


def test_rerun_skips_finished_and_reruns_only_what_changed(root: Path, swept: Path,
                                                           tmp_path: Path) -> None:
    out = tmp_path / "S"
    shutil.copytree(swept, out)  # copy2: modification times kept
    mtime = {n: (out / n / "summary.json").stat().st_mtime_ns for n in ROWS}
    r = _sweep(root, TABLE, out)
    assert r.returncode == 0, r.stderr
    for n in ROWS:
        assert f"  {n}: finished earlier, skipped" in r.stdout
        assert (out / n / "summary.json").stat().st_mtime_ns == mtime[n]
    assert "nothing to run (0 run, 3 skipped" in r.stdout  # no cluster started

    # CHANGED, and a's summary lost (its checkpoint is at its last cycle)
    (out / "a" / "summary.json").unlink()
    a_results = (out / "a" / "results.csv").read_bytes()
    b_results = (out / "b" / "results.csv").read_bytes()
    r = _sweep(root, CHANGED, out, "--workers", "1")
    assert r.returncode == 3, r.stderr
    assert "Traceback" not in r.stderr
    assert "  a: resuming from its checkpoint" in r.stdout
    assert "  b: starting over (contact.load changed from 50.0 to 60.0)" in r.stdout
    assert "  c: finished earlier, skipped" in r.stdout
    assert "3 run, 1 skipped" in r.stdout
    assert "member 'd' (row 4): failed: ConfigError: contact: regime" in r.stderr
    assert "1 of 4 sweep members failed" in r.stderr
    assert (out / "c" / "summary.json").stat().st_mtime_ns == mtime["c"]
    assert (out / "a" / "results.csv").read_bytes() == a_results
    assert (out / "b" / "results.csv").read_bytes() != b_results
    rows = _rows(out)
    assert {n: rows[n]["status"] for n in rows} == {"a": "done", "b": "done", "c": "done",
                                                    "d": "failed"}
    assert rows["b"]["contact.load"] == "60" and "regime" in rows["d"]["message"]
    assert rows["d"]["wear_depth_lower_m"] == "" and rows["d"]["contact.regime"] == \
        "ciavarella-jaeger"
    s = json.loads((out / "b" / "summary.json").read_text())
    assert s["config"]["contact"]["load"] == 60.0 and float(rows["b"]["wear_depth_lower_m"]) \
        == s["wear_depth_lower_m"]


@pytest.mark.parametrize("table, wanted", [
    ("name,contact.lod\na,100\n", ["column 'contact.lod'", "contact.load"]),
    ("name,contact.load,wear.criterion\na,100,energy\nb,-5,energy\n",
     ["row 2", "name 'b'", "contact.load", "-5", "greater than 0"]),
    ("", ["is empty"]),
    ("name,cycles\na,2\na,3\n", ["row 2", "name = 'a'", "distinct"]),
])
def test_bad_table_exits_2_before_anything_is_written(root: Path, tmp_path: Path,
                                                      table: str, wanted: list[str]) -> None:
    out = tmp_path / "X"
    r = _sweep(root, table, out)
    assert r.returncode == 2, (r.stdout, r.stderr)
    assert "Traceback" not in r.stderr and r.stderr.startswith("error: ")
    for w in wanted:
        assert w in r.stderr, (w, r.stderr)
    assert not out.exists()
