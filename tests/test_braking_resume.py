"""``tribodem braking run/sweep`` never lie: checkpoints, --resume after kill -9 or Ctrl-C
(bitwise the uninterrupted results), a sweep that skips finished members and resumes the
others, refused inputs before any work. Every test runs the installed command."""

from __future__ import annotations

import json
import random
import shutil
import signal
import subprocess
import time
from pathlib import Path

import pytest
from conftest import TINY_CELL, TINY_RUN, default_sigint, run_tribodem, tribodem_exe

#: a tiny interface (~150 particles), ~17k steps per microsecond of sliding
SMALL = f"""
[condition]
index = 5

{TINY_CELL}
[run]
{TINY_RUN}duration_s = {{duration}}
samples = 20
vtk_snapshots = 3
figures = false
threads = 1
"""


def _config(folder: Path, duration: float = 2e-6, name: str = "small.toml") -> Path:
    p = folder / name
    p.write_text(SMALL.format(duration=duration))
    return p


def _numbers(summary: Path) -> dict[str, float]:
    """The numeric summary entries, wall-clock timings left out."""
    s = json.loads(summary.read_text())
    return {k: v for k, v in s.items() if isinstance(v, (int, float)) and not
            isinstance(v, bool) and not k.startswith("wall_time")}


def _same_results(a: Path, b: Path) -> None:
    na, nb = _numbers(a / "summary.json"), _numbers(b / "summary.json")
    assert na.keys() == nb.keys()
    for k in na:  # bitwise (nan == nan)
        assert repr(na[k]) == repr(nb[k]), k
    assert (a / "timeseries.csv").read_text() == (b / "timeseries.csv").read_text()
    for pvd in ("particles.pvd", "chains.pvd"):
        assert (a / "vtk" / pvd).read_text() == (b / "vtk" / pvd).read_text()
    assert json.loads((a / "summary.json").read_text())["status"] == "finished"


def _snapshot(folder: Path) -> dict[str, tuple[bytes, int]]:
    return {str(p.relative_to(folder)): (p.read_bytes(), p.stat().st_mtime_ns)
            for p in sorted(folder.rglob("*")) if p.is_file()}


def _start(*args: str) -> subprocess.Popen:
    return subprocess.Popen([tribodem_exe(), *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, preexec_fn=default_sigint)


def _wait_for(path: Path, proc: subprocess.Popen, timeout: float = 60.0) -> None:
    end = time.monotonic() + timeout
    while not path.exists():
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < end, f"no {path} after {timeout} s"
        time.sleep(0.02)


@pytest.fixture(scope="module")
def reference(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """(config, folder) of an uninterrupted run."""
    root = tmp_path_factory.mktemp("braking_ref")
    # 4 us of sliding (~70k steps, about 2 s since the compiled step loop): room to be
    # interrupted between its first checkpoint and its end
    cfg = _config(root, duration=4e-6)
    out = root / "B"
    r = run_tribodem("braking", "run", "--config", str(cfg), "--out", str(out),
                     "--no-progress", timeout=300)
    assert r.returncode == 0, r.stderr
    return cfg, out


def _check_ctrl_c_exit(r: subprocess.CompletedProcess, out: Path) -> None:
    """Exit 130, no traceback, the message names the outputs (and the checkpoint)."""
    assert "Traceback" not in r.stderr
    assert r.returncode == 130, r.stderr
    assert "interrupted (Ctrl-C)" in r.stderr and str(out) in r.stderr


def _interrupt(cfg: Path, out: Path, sig: int) -> subprocess.CompletedProcess:
    """Start a run, wait for its first checkpoint, send ``sig`` a random moment later."""
    proc = _start("braking", "run", "--config", str(cfg), "--out", str(out), "--no-progress")
    try:
        _wait_for(out / "checkpoint.npz", proc)
        time.sleep(random.uniform(0.1, 0.8))
        assert proc.poll() is None, "the run ended before it could be interrupted"
        proc.send_signal(sig)
        stdout, stderr = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert not (out / "summary.json").exists()
    return subprocess.CompletedProcess(proc.args, proc.returncode, stdout, stderr)


def test_kill9_then_resume_gives_the_uninterrupted_results(
        reference: tuple[Path, Path], tmp_path: Path) -> None:
    cfg, ref = reference
    out = tmp_path / "A"
    r = _interrupt(cfg, out, signal.SIGKILL)
    assert r.returncode == -signal.SIGKILL
    # resumed with the reference run's resolved config.toml: it must reload to the very
    # config the checkpoint was made with (else: exit 2), and be written back unchanged
    r = run_tribodem("braking", "run", "--config", str(ref / "config.toml"), "--out",
                     str(out), "--resume", "--no-progress", timeout=300)
    assert r.returncode == 0, r.stderr
    _same_results(ref, out)
    assert (out / "config.toml").read_text() == (ref / "config.toml").read_text()


def test_ctrl_c_exits_130_naming_outputs_then_resume(reference: tuple[Path, Path],
                                                     tmp_path: Path) -> None:
    cfg, ref = reference
    out = tmp_path / "A"
    stopped = _interrupt(cfg, out, signal.SIGINT)
    # resumed from its own config.toml (no --config)
    r = run_tribodem("braking", "run", "--out", str(out), "--resume", "--no-progress",
                     timeout=300)
    assert r.returncode == 0, r.stderr
    _same_results(ref, out)
    _check_ctrl_c_exit(stopped, out)
    assert "checkpoint" in stopped.stderr and "--resume" in stopped.stderr


def test_resume_of_a_finished_run_only_reports_it(reference: tuple[Path, Path],
                                                  tmp_path: Path) -> None:
    cfg, ref = reference
    out = tmp_path / "B"
    shutil.copytree(ref, out)
    before = _snapshot(out)
    r = run_tribodem("braking", "run", "--config", str(cfg), "--out", str(out), "--resume",
                     "--no-progress", timeout=120)
    assert r.returncode == 0, r.stderr
    assert "already finished" in r.stderr
    assert json.loads(r.stdout)["status"] == "finished"
    assert _snapshot(out) == before


def test_bad_inputs_are_refused_before_any_work(reference: tuple[Path, Path],
                                                tmp_path: Path) -> None:
    cfg, ref = reference
    f = tmp_path / "a_file"
    f.write_text("x")
    r = run_tribodem("braking", "run", "--config", str(cfg), "--out", str(f), timeout=120)
    assert r.returncode == 2 and "Traceback" not in r.stderr and "--out" in r.stderr
    assert f.read_text() == "x"
    r = run_tribodem("braking", "sweep", "--config", str(cfg), "--out", str(f), timeout=120)
    assert r.returncode == 2 and "Traceback" not in r.stderr and "--out" in r.stderr
    empty = tmp_path / "empty"
    empty.mkdir()
    r = run_tribodem("braking", "run", "--out", str(empty), "--resume", timeout=120)
    assert r.returncode == 2 and "Traceback" not in r.stderr and "checkpoint" in r.stderr
    assert list(empty.iterdir()) == []
    # a config that differs from the checkpoint's: refused, nothing touched
    out = tmp_path / "B"
    shutil.copytree(ref, out)
    (out / "summary.json").unlink()  # an unfinished run
    before = _snapshot(out)
    other = _config(tmp_path, duration=1.5e-6, name="other.toml")
    r = run_tribodem("braking", "run", "--config", str(other), "--out", str(out), "--resume",
                     timeout=120)
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert "run.duration_s" in r.stderr and "differs" in r.stderr
    r = run_tribodem("braking", "run", "--out", str(out), "--resume", "--condition", "3",
                     timeout=120)
    assert r.returncode == 2 and "condition.index" in r.stderr
    assert _snapshot(out) == before
    # a truncated checkpoint
    ck = out / "checkpoint.npz"
    ck.write_bytes(ck.read_bytes()[:4000])
    before = _snapshot(out)
    r = run_tribodem("braking", "run", "--out", str(out), "--resume", timeout=120)
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert "cannot be read" in r.stderr and "checkpoint" in r.stderr
    assert _snapshot(out) == before


SWEEP = f"""
{TINY_CELL}
[run]
{TINY_RUN}duration_s = 0.6e-6
samples = 8
vtk_snapshots = 2
figures = false
"""


def _sweep(cfg: Path, out: Path) -> subprocess.CompletedProcess:
    return run_tribodem("braking", "sweep", "--config", str(cfg), "--out", str(out),
                        "--workers", "2", "--no-progress", timeout=300)


def test_sweep_ctrl_c_then_reruns_resume_skip_and_redo_only_the_missing(tmp_path: Path
                                                                         ) -> None:
    cfg = tmp_path / "sweep.toml"
    cfg.write_text(SWEEP)
    out = tmp_path / "S"
    # Ctrl-C while the first members run: prompt stop, workers killed
    proc = _start("braking", "sweep", "--config", str(cfg), "--out", str(out), "--workers",
                  "2", "--no-progress")
    try:
        _wait_for(out / "condition_1" / "checkpoint.npz", proc)
        time.sleep(0.2)
        assert proc.poll() is None
        proc.send_signal(signal.SIGINT)
        t = time.monotonic()
        stdout, stderr = proc.communicate(timeout=30)
        assert time.monotonic() - t < 10
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    stopped = subprocess.CompletedProcess(proc.args, proc.returncode, stdout, stderr)
    assert "sweep stopped" in stderr and "Traceback" not in stderr
    assert not (out / "condition_5" / "summary.json").exists()
    # the same sweep again: the unfinished members resume from their checkpoints
    r = _sweep(cfg, out)
    assert r.returncode == 0, r.stderr
    assert "condition_1: resuming" in r.stdout
    first = {k: (out / f"condition_{k}" / "summary.json").read_text() for k in range(1, 6)}
    comparison = (out / "comparison.csv").read_text()
    # once more: every member is skipped
    r = _sweep(cfg, out)
    assert r.returncode == 0, r.stderr
    assert "0 run, 5 skipped" in r.stdout and r.stdout.count("skipped") >= 5
    assert (out / "comparison.csv").read_text() == comparison
    # a member without its summary: only it runs again (from its final checkpoint)
    (out / "condition_3" / "summary.json").unlink()
    untouched = _snapshot(out / "condition_1")
    r = _sweep(cfg, out)
    assert r.returncode == 0, r.stderr
    assert "1 run, 4 skipped" in r.stdout and "condition_3: resuming" in r.stdout
    assert _snapshot(out / "condition_1") == untouched
    for k in range(1, 6):
        a = json.loads(first[k])
        b = json.loads((out / f"condition_{k}" / "summary.json").read_text())
        assert a["status"] == "finished"
        assert {x: repr(v) for x, v in a.items() if not x.startswith("wall_time")} == \
               {x: repr(v) for x, v in b.items() if not x.startswith("wall_time")}
    assert (out / "comparison.csv").read_text() == comparison
    _check_ctrl_c_exit(stopped, out)


def test_sweep_reports_a_failed_member_and_compares_the_rest(tmp_path: Path) -> None:
    cfg = tmp_path / "sweep.toml"
    cfg.write_text(SWEEP.replace("0.6e-6", "0.2e-6"))
    out = tmp_path / "S"
    out.mkdir()
    (out / "condition_3").write_text("in the way")  # its folder cannot be made
    r = _sweep(cfg, out)
    assert r.returncode == 3 and "Traceback" not in r.stderr
    assert "condition 3" in r.stderr and "1 of 5 sweep members failed" in r.stderr
    md = (out / "comparison.md").read_text()
    assert "## Failed members" in md and "condition 3 packing 0" in md
    assert "not evaluated: no run of condition 3" in md
    for k in (1, 2, 4, 5):
        assert json.loads((out / f"condition_{k}" / "summary.json").read_text())[
            "status"] == "finished"
