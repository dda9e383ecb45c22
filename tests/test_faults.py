"""Faults of the environment, the disk and the scheduler end a command cleanly, through the
installed command: SIGTERM like Ctrl-C (exit 143, outputs and checkpoint named, resumable),
a run folder in use refused naming its holder (a killed holder's lock is free again), the
environment variables numba reads checked first, paths the file system cannot hold refused
before any work, and a full disk during a run ending with exit 3 and the outputs kept.

Values no real material or rig has, and values whose arrays would not fit in memory, are
refused before any work naming the field, the value and the range (a finished run's folder
left byte for byte as it was); a run that replaces a finished one and stops early leaves
none of the earlier run's files; a read-only output subfolder ends a run with exit 3."""

from __future__ import annotations

import hashlib
import json
import math
import os
import signal
import subprocess
import time
from pathlib import Path

import pytest
from conftest import run_tribodem, tribodem_exe

from tribodem.io.config import dump_toml

#: a dem run that takes a few seconds: 300 spheres, checkpoints every 200 steps
SMALL = {"case": {"particles": 300, "seed": 3}, "run": {"steps": 400, "threads": 1},
         "output": {"scalars_every": 50, "vtk_every": 200, "checkpoint_every": 200}}
#: the same for long enough to be stopped while it works
LONG = {**SMALL, "run": {"steps": 400_000, "threads": 1}}


def _config(tmp: Path, data: dict, name: str = "c.toml") -> Path:
    p = tmp / name
    p.write_text(dump_toml(data))
    return p


def _start(cfg: Path, out: Path) -> subprocess.Popen[str]:
    return subprocess.Popen([tribodem_exe(), "dem", "run", "--config", str(cfg), "--out",
                             str(out), "--no-progress"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


def _wait_for(path: Path, proc: subprocess.Popen[str], seconds: float = 120) -> None:
    t0 = time.monotonic()
    while not path.exists():
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() - t0 < seconds, f"{path} did not appear"
        time.sleep(0.1)


def _hashes(folder: Path) -> dict[str, str]:
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}


def test_sigterm_ends_like_ctrl_c_with_143(tmp_path: Path) -> None:
    out = tmp_path / "out"
    proc = _start(_config(tmp_path, LONG), out)
    _wait_for(out / "checkpoint.npz", proc)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 143, err
    assert "terminated (SIGTERM)" in err and str(out) in err and "checkpoint" in err
    assert "Traceback" not in err


def test_a_folder_in_use_is_refused_naming_the_holder(tmp_path: Path) -> None:
    out = tmp_path / "out"
    cfg = _config(tmp_path, LONG)
    first = _start(cfg, out)
    try:
        _wait_for(out / "config.toml", first)
        before = (out / "config.toml").read_bytes()
        r = run_tribodem("dem", "run", "--config", str(cfg), "--out", str(out),
                         "--no-progress", timeout=120)
        assert r.returncode == 2, r.stderr
        assert f"pid {first.pid}" in r.stderr and "in use" in r.stderr
        assert "Traceback" not in r.stderr
        assert (out / "config.toml").read_bytes() == before  # the holder's, untouched
    finally:
        first.kill()  # kill -9: the lock goes with the process
        first.communicate(timeout=60)
    small = _config(tmp_path, SMALL, "small.toml")
    r = run_tribodem("dem", "run", "--config", str(small), "--out", str(out),
                     "--no-progress", timeout=300)
    assert r.returncode == 0, r.stderr  # the killed run's lock is free again


@pytest.mark.parametrize(("name", "value"), [
    ("NUMBA_NUM_THREADS", "0"), ("NUMBA_NUM_THREADS", "-1"), ("NUMBA_NUM_THREADS", "abc"),
    ("OMP_NUM_THREADS", "0"), ("NUMBA_THREADING_LAYER", "bogus")])
def test_environment_checked_first(tmp_path: Path, name: str, value: str) -> None:
    out = tmp_path / "out"
    r = run_tribodem("dem", "run", "--quick", "--out", str(out), timeout=60,
                     env={**os.environ, name: value})
    assert r.returncode == 2, r.stderr
    assert name in r.stderr and repr(value) in r.stderr and "allowed" in r.stderr
    assert "Traceback" not in r.stderr and not out.exists()


@pytest.mark.parametrize("out", ["", "x" * 300, "/".join(["y" * 200] * 25)])
def test_paths_the_file_system_cannot_hold(tmp_path: Path, out: str) -> None:
    r = run_tribodem("dem", "run", "--quick", "--out", out, timeout=60, cwd=tmp_path)
    assert r.returncode == 2, r.stderr
    assert "--out" in r.stderr and "allowed" in r.stderr and "Traceback" not in r.stderr
    assert list(tmp_path.iterdir()) == []


def _small_tmpfs(where: Path, size: str) -> bool:
    if os.geteuid() != 0:
        return False
    where.mkdir()
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(where)],
                       capture_output=True)
    return r.returncode == 0


def test_a_full_disk_during_a_run_ends_with_3_and_keeps_the_outputs(tmp_path: Path) -> None:
    disk = tmp_path / "disk"
    if not _small_tmpfs(disk, "160k"):
        pytest.skip("needs root and tmpfs to make a small real file system")
    try:
        out = disk / "out"
        cfg = _config(tmp_path, {**SMALL, "run": {"steps": 2000, "threads": 1},
                                 "output": {"scalars_every": 50, "vtk_every": 100,
                                            "checkpoint_every": 400}})
        r = run_tribodem("dem", "run", "--config", str(cfg), "--out", str(out),
                         "--no-progress", timeout=300)
        assert r.returncode == 3, (r.returncode, r.stderr)
        assert "No space left on device" in r.stderr and str(out) in r.stderr
        assert "Traceback" not in r.stderr
        assert (out / "config.toml").is_file()
    finally:
        subprocess.run(["umount", "-l", str(disk)], check=False)


# ---------------------------------------------------------------- refused before any work
#: Every case runs the installed command: exit 2, the field (or option) and the value
#: named, no traceback; on a finished run's folder the folder stays byte for byte as it
#: was; a new --out is not made.

ROOT = Path(__file__).resolve().parents[1]

#: a tiny braking run (conftest's cell, 1 us of sliding, ~6 s)
BRAKING = {"condition": {"index": 5},
           "geometry": {"width_m": 100e-6, "disc_height_m": 36e-6, "pad_height_m": 36e-6,
                        "roughness_amplitude_m": 4e-6, "roughness_modes": 2, "seed": 3},
           "run": {"worn_through_diameters": 0.0, "duration_s": 1e-6, "samples": 5,
                   "vtk_snapshots": 1, "figures": False, "threads": 1}}


def _merge(base: dict, over: dict) -> dict:
    out = dict(base)
    for k, v in over.items():
        out[k] = _merge(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) \
            else v
    return out


@pytest.fixture(scope="module")
def finished(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Folders of finished runs: a 2-cycle quick fretting run and a tiny braking run."""
    root = tmp_path_factory.mktemp("finished")
    fr = root / "fretting"
    r = run_tribodem("fretting", "run", "--quick", "--cycles", "2", "--out", str(fr),
                     "--no-progress", timeout=300)
    assert r.returncode == 0, r.stderr
    br = root / "braking"
    cfg = _config(root, BRAKING, "braking.toml")
    r = run_tribodem("braking", "run", "--config", str(cfg), "--out", str(br),
                     "--no-progress", timeout=300)
    assert r.returncode == 0, r.stderr
    return {"fretting": fr, "braking": br}


def _curve(tmp: Path, kind: str) -> Path:
    p = tmp / f"curve_{kind}.csv"
    if kind == "empty":
        p.write_bytes(b"")
    elif kind == "binary":
        p.write_bytes(bytes(range(256)) * 8)
    else:
        p.write_text("a thermal curve\nhot, then cold\n")
    return p


#: (id, command, config (a dict laid over the command's base: fretting's defaults, the
#: tiny braking run) or other arguments, the folder it runs on ("fretting"/"braking": the
#: finished run's; "new": a new one), the words of the message)
REFUSALS: list[tuple[str, str, dict | list[str], str, list[str]]] = [
    ("young-1e300", "fretting", {"contact": {"young": 1e300}}, "fretting",
     ["contact.young", "1e+300", "1e6..2e12 Pa", "allow_unphysical = true"]),
    ("young-1e20", "fretting", {"contact": {"young": 1e20}}, "fretting",
     ["contact.young", "1e+20", "1e6..2e12 Pa"]),
    ("young-1e20-allowed", "fretting", {"allow_unphysical": True, "contact": {"young": 1e20}},
     "fretting", ["contact.window", "does not resolve the contact"]),
    ("friction-1e6", "fretting", {"contact": {"friction": 1e6}}, "fretting",
     ["contact.friction", "1000000.0", "0..5"]),
    ("radius-100", "fretting", {"contact": {"geometry": "sphere_on_flat", "radius": 100.0}},
     "fretting", ["contact.radius", "100.0", "1e-6..10 m"]),
    ("load-1e9", "fretting", {"contact": {"load": 1e9}}, "fretting",
     ["contact.load", "1e-6..1e6 N"]),
    ("load-nan", "fretting", {"contact": {"load": math.nan}}, "fretting",
     ["contact.load", "nan", "finite"]),
    ("amplitude-inf", "fretting", {"contact": {"amplitude": math.inf}}, "fretting",
     ["contact.amplitude", "inf", "finite"]),
    ("amplitude-1e10", "fretting", {"contact": {"amplitude": 1e10}}, "fretting",
     ["contact.amplitude", "10000000000.0", "1e-9..0.1 m"]),
    ("amplitude-1e10-allowed", "fretting",
     {"allow_unphysical": True, "contact": {"amplitude": 1e10}}, "fretting",
     ["contact.amplitude", "10000000000.0", "track grid", "GiB"]),
    ("window-1", "fretting", {"contact": {"window": 1.0}}, "fretting",
     ["contact.window", "1.0", "does not resolve the contact"]),
    ("archard-k", "fretting", {"wear": {"criterion": "archard", "archard_k_lower": 1e-3}},
     "fretting", ["wear.archard_k_lower", "0.001", "0..1e-9 1/Pa"]),
    ("hardening", "fretting", {"plastic": {"hardening": 1e13}}, "fretting",
     ["plastic.hardening", "0..2e12 Pa"]),
    ("debris-diameter-allowed", "fretting",
     {"allow_unphysical": True, "debris": {"every": 1, "diameter": 1e-9}}, "fretting",
     ["debris.diameter", "1e-09", "GiB"]),
    ("allow-yes", "fretting", {"allow_unphysical": "yes"}, "fretting",
     ["allow_unphysical", "'yes'", "boolean"]),
    ("width-1e300", "braking", {"geometry": {"width_m": 1e300}}, "braking",
     ["geometry.width_m", "1e+300", "1e-6..0.5 m"]),
    ("width-1e300-allowed", "braking",
     {"allow_unphysical": True, "geometry": {"width_m": 1e300}}, "braking",
     ["geometry.width_m", "1e+300", "particles", "memory"]),
    ("rpm-1e6", "braking", {"condition": {"index": None, "load_kN": 13.0, "rpm": 1e6}},
     "braking", ["condition.rpm", "1000000.0", "r/min"]),
    ("curve-empty", "braking", {"thermal": {"curve": "{curve:empty}"}}, "braking",
     ["thermal.curve", "curve_empty.csv", "no (time s, temperature K) rows"]),
    ("curve-binary", "braking", {"thermal": {"curve": "{curve:binary}"}}, "braking",
     ["thermal.curve", "curve_binary.csv", "cannot be read"]),
    ("curve-text", "braking", {"thermal": {"curve": "{curve:text}"}}, "braking",
     ["thermal.curve", "curve_text.csv", "not two numbers"]),
    ("jump-param-value", "jump",
     ["replay", "--strategy", "constant", "--input",
      str(ROOT / "examples" / "wear_increments_two_phase.csv"), "--param", "jump_length=-5"],
     "none", ["--param jump_length=-5", "jump_length = -5: must be >= 1"]),
    ("sweep-load-inf", "sweep", ["contact.load", "100", "inf"], "new",
     ["--table", "row 2", "contact.load", "inf", "finite"]),
    ("sweep-young-1e300", "sweep", ["contact.young", "2e11", "1e300"], "new",
     ["--table", "row 2", "contact.young", "1e+300", "1e6..2e12 Pa"]),
]


def _args(case: tuple, tmp: Path, finished: dict[str, Path]) -> tuple[list[str], Path | None]:
    """The command line of a case and the folder it writes to (None: it writes none)."""
    _, command, given, where, _ = case
    out = finished[where] if where in finished else tmp / "new" if where == "new" else None
    if command in ("fretting", "braking"):
        def fill(v: object) -> object:
            if isinstance(v, str) and v.startswith("{curve:"):
                return str(_curve(tmp, v[7:-1]))
            return v
        data = {k: ({kk: fill(vv) for kk, vv in v.items()} if isinstance(v, dict) else v)
                for k, v in given.items()}
        if command == "braking":
            data = _merge(BRAKING, data)
            if data["condition"].get("index", 0) is None:
                del data["condition"]["index"]
        cfg = _config(tmp, data, "refused.toml")
        return [command, "run", "--config", str(cfg), "--out", str(out), "--no-progress"], out
    if command == "sweep":
        col, a, b = given
        table = tmp / "table.csv"
        table.write_text(f"name,{col}\none,{a}\ntwo,{b}\n")
        return ["fretting", "sweep", "--table", str(table), "--out", str(out), "--quick",
                "--workers", "1", "--no-progress"], out
    return [command, *given], out


@pytest.mark.parametrize("case", REFUSALS, ids=[c[0] for c in REFUSALS])
def test_refused_before_any_work_naming_the_field(tmp_path: Path, finished: dict[str, Path],
                                                  case: tuple) -> None:
    args, out = _args(case, tmp_path, finished)
    before = _hashes(out) if out is not None and out.exists() else None
    r = run_tribodem(*args, timeout=120)
    text = r.stdout + r.stderr
    assert r.returncode == 2, (r.returncode, text)
    assert "Traceback" not in text, text
    for w in case[4]:
        assert w in text, f"{case[0]}: {w!r} not in:\n{text}"
    if before is not None:
        assert _hashes(out) == before, f"{case[0]}: the finished run's folder changed"
    elif out is not None:
        assert not out.exists(), f"{case[0]}: the refused command made {out}"


def test_validate_keep_a_file_is_refused(tmp_path: Path) -> None:
    from tribodem.contact.fe.ccx import resolve_ccx

    if resolve_ccx() is None:
        pytest.skip("needs CalculiX's ccx (the --keep check comes after it)")
    plain = tmp_path / "jobs.txt"
    plain.write_text("not a folder\n")
    r = run_tribodem("validate", "--solver", "fe", "--keep", str(plain), timeout=120)
    assert r.returncode == 2, r.stderr
    assert "--keep" in r.stderr and "is a file" in r.stderr and "Traceback" not in r.stderr
    assert plain.read_text() == "not a folder\n"


# ---------------------------------------------------------------- during a run

def _fretting(args: list[str], out: Path) -> subprocess.Popen[str]:
    return subprocess.Popen([tribodem_exe(), "fretting", "run", *args, "--out", str(out),
                             "--no-progress"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


def test_two_fretting_runs_on_one_folder(tmp_path: Path) -> None:
    out = tmp_path / "out"
    cfg = _config(tmp_path, {"cycles": 100_000, "contact": {"n": 64, "window": 1.4e-3}})
    first = _fretting(["--config", str(cfg)], out)
    try:
        _wait_for(out / "config.toml", first)
        before = (out / "config.toml").read_bytes()
        r = run_tribodem("fretting", "run", "--quick", "--cycles", "2", "--out", str(out),
                         "--no-progress", timeout=120)
        assert r.returncode == 2, r.stderr
        assert f"pid {first.pid}" in r.stderr and "in use" in r.stderr
        assert "Traceback" not in r.stderr
        assert (out / "config.toml").read_bytes() == before
    finally:
        first.kill()
        first.communicate(timeout=60)


def test_a_run_that_replaces_a_finished_one_and_stops_early_leaves_none_of_its_files(
        tmp_path: Path) -> None:
    """A finished 20-cycle run with figures and VTK, then, in its folder, a run without
    them whose contact outgrows its window at cycle 4 (exit 3): what is left is the new
    run's, up to its stop; none of the earlier run's figures, surfaces or rows."""
    out = tmp_path / "out"
    r = run_tribodem("fretting", "run", "--quick", "--cycles", "20", "--out", str(out),
                     "--no-progress", timeout=300)
    assert r.returncode == 0, r.stderr
    assert list(out.glob("*.png")) and list(out.glob("*.vtu"))
    cfg = _config(tmp_path, {"cycles": 20, "contact": {"n": 64, "window": 5.3e-4},
                             "wear": {"alpha": 1e-10, "stress_nz": 17,
                                      "update_tolerance": 0},  # a cycle, one update
                             "output": {"figures": False, "vtk": False}})
    r = run_tribodem("fretting", "run", "--config", str(cfg), "--out", str(out),
                     "--no-progress", timeout=300)
    assert r.returncode == 3, (r.returncode, r.stderr)
    assert "window" in r.stderr and "Traceback" not in r.stderr
    assert not list(out.glob("*.png")) and not list(out.glob("*.vtu")), sorted(out.iterdir())
    rows = (out / "results.csv").read_text().strip().splitlines()
    summary = json.loads((out / "summary.json").read_text())
    assert summary["stopped"] and summary["config"]["contact"]["window"] == 5.3e-4
    assert 1 < len(rows) < 21 and len(rows) - 1 == summary["cycles"] < 20


def test_a_read_only_vtk_folder_during_a_dem_run_ends_with_3(tmp_path: Path) -> None:
    """OUT/vtk made read-only (a read-only file system as root, whom permissions do not
    stop): the run ends at its first snapshot with exit 3, naming the file, and keeps what
    it wrote."""
    out = tmp_path / "out"
    vtk = out / "vtk"
    vtk.mkdir(parents=True)
    mounted = False
    if os.geteuid() == 0:
        r = subprocess.run(["mount", "-t", "tmpfs", "-o", "ro,size=64k", "tmpfs", str(vtk)],
                           capture_output=True)
        if r.returncode != 0:
            pytest.skip("needs a read-only mount as root")
        mounted = True
    else:
        vtk.chmod(0o555)
    try:
        r = run_tribodem("dem", "run", "--config", str(_config(tmp_path, SMALL)), "--out",
                         str(out), "--no-progress", timeout=300)
        assert r.returncode == 3, (r.returncode, r.stderr)
        assert "Traceback" not in r.stderr
        assert str(vtk / "particles_000000000.vtu") in r.stderr, r.stderr
        assert ".tmp" not in r.stderr  # the file, not the atomic write's temporary
        assert str(out) in r.stderr and (out / "config.toml").is_file()
    finally:
        if mounted:
            subprocess.run(["umount", "-l", str(vtk)], check=False)
        else:
            vtk.chmod(0o755)
