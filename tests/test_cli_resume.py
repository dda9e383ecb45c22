"""``tribodem dem run`` killed (SIGKILL) or interrupted (SIGINT) at a random point, then
``--resume``: every output equals the uninterrupted run's, byte for byte (the engine is
deterministic). Also: a run's resolved config.toml reloads unchanged. Through the installed
command, as a user runs it.
"""

from __future__ import annotations

import json
import os
import random
import signal
import subprocess
import time
from pathlib import Path

import pytest
from conftest import default_sigint, run_tribodem, tribodem_exe

CONFIG = """[case]
particles = 300
seed = 3
[run]
steps = 24000
threads = 1
[output]
scalars_every = 100
vtk_every = 2000
checkpoint_every = 2000
"""

#: Outputs compared byte for byte (summary.json: everything but the wall-clock time).
SAME = ["timeseries.csv", "checkpoint.npz", "config.toml", "vtk/particles.pvd",
        "vtk/chains.pvd"]


def _reference(tmp: Path, cfg: Path) -> Path:
    ref = tmp / "ref"
    r = run_tribodem("dem", "run", "--config", str(cfg), "--out", str(ref), "--no-progress")
    assert r.returncode == 0, r.stderr
    return ref


def _same(a: Path, b: Path) -> None:
    for name in SAME:
        assert (a / name).read_bytes() == (b / name).read_bytes(), name
    va = sorted(p.name for p in (a / "vtk").glob("*.vtu"))
    assert va == sorted(p.name for p in (b / "vtk").glob("*.vtu")) and len(va) == 26
    for n in va:
        assert (a / "vtk" / n).read_bytes() == (b / "vtk" / n).read_bytes(), n
    sa = json.loads((a / "summary.json").read_text())
    sb = json.loads((b / "summary.json").read_text())
    for k in ("wall_time_s",):
        sa.pop(k), sb.pop(k)
    assert sa == sb


def _start_and_stop(cfg: Path, out: Path, sig: int, rng: random.Random
                    ) -> subprocess.CompletedProcess:
    """Start a run, wait for its first checkpoint, stop it with ``sig`` a little later.

    The run's 22,000 steps after its first checkpoint take ~1.2 s on one core (2026), the
    wait at most 0.3 s: the signal lands mid-run (checked: no summary yet).
    """
    p = subprocess.Popen([tribodem_exe(), "dem", "run", "--config", str(cfg), "--out",
                          str(out), "--no-progress"], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True, preexec_fn=default_sigint)
    t0 = time.monotonic()
    while not (out / "checkpoint.npz").exists():
        assert p.poll() is None, p.communicate()
        assert time.monotonic() - t0 < 300
        time.sleep(0.02)
    time.sleep(rng.uniform(0.0, 0.3))
    assert p.poll() is None and not (out / "summary.json").exists(), "ended before the stop"
    p.send_signal(sig)
    o, e = p.communicate(timeout=120)
    return subprocess.CompletedProcess(p.args, p.returncode, o, e)


@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGINT], ids=["kill9", "sigint"])
def test_dem_run_stopped_then_resumed_equals_uninterrupted(tmp_path: Path, sig: int) -> None:
    cfg = tmp_path / "c.toml"
    cfg.write_text(CONFIG)
    ref = _reference(tmp_path, cfg)
    rng = random.Random(int.from_bytes(os.urandom(4)))
    out = tmp_path / "cut"
    r = _start_and_stop(cfg, out, sig, rng)
    assert r.returncode == (130 if sig == signal.SIGINT else -signal.SIGKILL), r.stderr
    if sig == signal.SIGINT:
        assert "Traceback" not in r.stderr
        assert "interrupted" in r.stderr and str(out) in r.stderr
        assert "checkpoint" in r.stderr and "--resume" in r.stderr
    r = run_tribodem("dem", "run", "--out", str(out), "--resume", "--no-progress")
    assert r.returncode == 0, r.stderr
    _same(ref, out)


def test_ctrl_c_as_the_command_ends_exits_130_with_the_message_or_0(tmp_path: Path) -> None:
    """Ctrl-C after the results are written, while the process shuts down: exit 130 with
    the message (or 0 if it came too late to matter), never death by SIGINT (exit -2, no
    message: what Python's shutdown, which restores the default action, gave before)."""
    cfg = tmp_path / "c.toml"
    cfg.write_text(CONFIG.replace("steps = 24000", "steps = 200"))
    for i in range(6):
        out = tmp_path / f"o{i}"
        p = subprocess.Popen([tribodem_exe(), "dem", "run", "--config", str(cfg), "--out",
                              str(out), "--no-progress"], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, preexec_fn=default_sigint)
        t0 = time.monotonic()
        while not (out / "summary.json").exists() and p.poll() is None:
            assert time.monotonic() - t0 < 300
            time.sleep(0.0005)
        p.send_signal(signal.SIGINT)
        _, e = p.communicate(timeout=120)
        assert p.returncode in (0, 130) and "Traceback" not in e, (p.returncode, e)
        if p.returncode == 130:
            assert "interrupted" in e and str(out) in e and "--resume" in e, e


def test_dem_resume_refuses_a_changed_case_before_touching_outputs(tmp_path: Path) -> None:
    cfg = tmp_path / "c.toml"
    cfg.write_text(CONFIG.replace("steps = 24000", "steps = 250"))
    out = tmp_path / "o"
    assert run_tribodem("dem", "run", "--config", str(cfg), "--out", str(out),
                        "--no-progress").returncode == 0
    before = {p: p.read_bytes() for p in out.rglob("*") if p.is_file()}
    other = tmp_path / "other.toml"
    other.write_text(CONFIG.replace("particles = 300", "particles = 400"))
    r = run_tribodem("dem", "run", "--config", str(other), "--out", str(out), "--resume")
    assert r.returncode == 2 and "case.particles" in r.stderr and "Traceback" not in r.stderr
    (out / "checkpoint.npz").write_bytes(b"truncated")
    before[out / "checkpoint.npz"] = b"truncated"
    r = run_tribodem("dem", "run", "--out", str(out), "--resume")
    assert r.returncode == 2 and "checkpoint" in r.stderr and "Traceback" not in r.stderr
    assert {p: p.read_bytes() for p in out.rglob("*") if p.is_file()} == before


def test_dem_resolved_config_reloads_unchanged(tmp_path: Path) -> None:
    a, b = tmp_path / "a", tmp_path / "b"
    assert run_tribodem("dem", "run", "--quick", "--out", str(a), "--no-progress").returncode == 0
    r = run_tribodem("dem", "run", "--config", str(a / "config.toml"), "--out", str(b),
                     "--no-progress")
    assert r.returncode == 0, r.stderr
    assert (a / "config.toml").read_bytes() == (b / "config.toml").read_bytes()
    assert (a / "timeseries.csv").read_bytes() == (b / "timeseries.csv").read_bytes()


def test_step0_contacts_are_the_touching_pairs(tmp_path: Path) -> None:
    """The step-0 sample (before any force evaluation) counts the pairs that really touch
    (centre distance < r_i + r_j, counted independently here), not every listed pair."""
    import meshio
    import numpy as np
    from scipy.spatial.distance import pdist

    from tribodem.dem.bench import CASES

    case = CASES["settle3d"](n=300, seed=3)
    r = case.radii
    touching = int(np.count_nonzero(pdist(case.positions) <
                                    (r[:, None] + r[None, :])[np.triu_indices(len(r), 1)]))
    cfg = tmp_path / "c.toml"
    cfg.write_text(CONFIG.replace("steps = 24000", "steps = 25"))
    out = tmp_path / "o"
    assert run_tribodem("dem", "run", "--config", str(cfg), "--out", str(out),
                        "--no-progress").returncode == 0
    ts = np.atleast_1d(np.genfromtxt(out / "timeseries.csv", delimiter=",", names=True))
    assert ts["step"][0] == 0 and ts["contacts"][0] == touching < 50
    chains = meshio.read(out / "vtk" / "chains_000000000.vtu")
    assert sum(len(c.data) for c in chains.cells) == touching


def test_outputs_get_the_umask_mode(tmp_path: Path) -> None:
    out = tmp_path / "o"
    cfg = tmp_path / "c.toml"
    cfg.write_text(CONFIG.replace("steps = 24000", "steps = 25"))
    r = run_tribodem("dem", "run", "--config", str(cfg), "--out", str(out), "--no-progress",
                     env={**os.environ}, preexec_fn=lambda: os.umask(0o022))
    assert r.returncode == 0, r.stderr
    for name in ("summary.json", "timeseries.csv", "config.toml"):
        assert (out / name).stat().st_mode & 0o777 == 0o644, name
