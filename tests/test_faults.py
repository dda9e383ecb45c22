"""Faults of the environment, the disk and the scheduler end a command cleanly, through the
installed command: SIGTERM like Ctrl-C (exit 143, outputs and checkpoint named, resumable),
a run folder in use refused naming its holder (a killed holder's lock is free again), the
environment variables numba reads checked first, paths the file system cannot hold refused
before any work, and a full disk during a run ending with exit 3 and the outputs kept."""

from __future__ import annotations

import hashlib
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
