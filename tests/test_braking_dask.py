"""``tribodem braking sweep`` on Dask: a local cluster and an external one (``dask
scheduler`` + two ``dask worker`` processes on 127.0.0.1, started and torn down here) give
the same member results; a worker killed mid-sweep does not stop it; a re-run after the
sweep and its workers were killed finishes only the missing members. Every sweep runs the
installed command on a tiny interface (~150 particles, 0.5 us: ~1-2 s per member)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from conftest import TINY_CELL, TINY_RUN, run_tribodem, tribodem_exe

pytest.importorskip("distributed")

SWEEP = f"""
{TINY_CELL}
[run]
{TINY_RUN}duration_s = 0.5e-6
samples = 8
vtk_snapshots = 2
figures = false
"""
DASK = str(Path(sys.executable).with_name("dask"))


def _numbers(folder: Path) -> dict[str, str]:
    s = json.loads((folder / "summary.json").read_text())
    assert s["status"] == "finished"
    return {k: repr(v) for k, v in s.items() if not k.startswith("wall_time")}


def _same_member(a: Path, b: Path) -> None:
    assert _numbers(a) == _numbers(b), (a, b)
    assert (a / "timeseries.csv").read_text() == (b / "timeseries.csv").read_text()


def _finished(folder: Path) -> bool:
    try:
        return json.loads((folder / "summary.json").read_text())["status"] == "finished"
    except (OSError, ValueError, KeyError):
        return False


@pytest.fixture(scope="module")
def config(tmp_path_factory: pytest.TempPathFactory) -> Path:
    p = tmp_path_factory.mktemp("dask_cfg") / "sweep.toml"
    p.write_text(SWEEP)
    return p


@pytest.fixture(scope="module")
def local(config: Path) -> Path:
    """A 2-packing sweep on a 2-worker local cluster (the reference results)."""
    out = config.parent / "L"
    r = run_tribodem("braking", "sweep", "--config", str(config), "--out", str(out),
                     "--packings", "2", "--workers", "2", "--no-progress", timeout=400)
    assert r.returncode == 0, r.stderr
    assert "local cluster of 2 worker process(es)" in r.stdout
    return out


class Cluster:
    """``dask scheduler`` and ``dask worker`` processes on 127.0.0.1 (free ports: the
    scheduler picks its port and writes it to its scheduler file)."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        self.file = folder / "scheduler.json"
        self.env = {**os.environ, "NUMBA_NUM_THREADS": "1"}
        self.scheduler = subprocess.Popen(
            [DASK, "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
             "--scheduler-file", str(self.file)], stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL, env=self.env)
        end = time.monotonic() + 60
        while not (self.file.is_file() and self.file.stat().st_size):
            assert self.scheduler.poll() is None and time.monotonic() < end
            time.sleep(0.1)
        time.sleep(0.2)
        self.address = json.loads(self.file.read_text())["address"]
        assert self.address.startswith("tcp://127.0.0.1:")
        self.workers: list[subprocess.Popen] = []

    def start_workers(self, n: int) -> None:
        from distributed import Client

        for _ in range(n):
            self.workers.append(subprocess.Popen(
                [DASK, "worker", self.address, "--nthreads", "1", "--nworkers", "1",
                 "--no-nanny", "--no-dashboard", "--host", "127.0.0.1"],
                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=self.env))
        alive = sum(w.poll() is None for w in self.workers)
        with Client(self.address, timeout="30s") as c:
            c.wait_for_workers(alive, timeout=90)

    def kill_workers(self, which: list[subprocess.Popen] | None = None) -> None:
        for w in which if which is not None else self.workers:
            if w.poll() is None:
                w.send_signal(signal.SIGKILL)
                w.wait()
        self.workers = [w for w in self.workers if w.poll() is None]

    def close(self) -> None:
        self.kill_workers()
        self.scheduler.terminate()
        try:
            self.scheduler.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.scheduler.kill()
            self.scheduler.wait()


@pytest.fixture(scope="module")
def cluster(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Cluster]:
    c = Cluster(tmp_path_factory.mktemp("dask_cluster"))
    try:
        yield c
    finally:
        c.close()


def _start_sweep(config: Path, out: Path, scheduler: str) -> subprocess.Popen:
    return subprocess.Popen([tribodem_exe(), "braking", "sweep", "--config", str(config),
                             "--out", str(out), "--scheduler", scheduler, "--no-progress"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _wait(proc: subprocess.Popen, ready, timeout: float = 120.0) -> None:  # noqa: ANN001
    end = time.monotonic() + timeout
    while not ready():
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < end, "timed out"
        time.sleep(0.02)


def test_external_cluster_gives_the_local_results_and_survives_a_killed_worker(
        config: Path, local: Path, cluster: Cluster, tmp_path: Path) -> None:
    cluster.start_workers(2 - len(cluster.workers))
    out = tmp_path / "E"
    proc = _start_sweep(config, out, cluster.address)
    try:
        # the first checkpoint: both workers are busy with a member; kill one of them
        _wait(proc, lambda: any((out / f"condition_{k}" / "checkpoint.npz").is_file()
                                for k in range(1, 6)))
        cluster.kill_workers(cluster.workers[:1])
        stdout, stderr = proc.communicate(timeout=300)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 0, stderr
    assert "Traceback" not in stderr and "cluster at tcp://127.0.0.1:" in stdout
    assert "5 run, 0 skipped as finished, 0 failed" in stdout
    for k in range(1, 6):  # the external members equal the local ones (packing 0)
        _same_member(local / f"condition_{k}" / "seed_0", out / f"condition_{k}")
    j = json.loads((out / "comparison.json").read_text())
    assert j["packings"] == 1 and all(t["ci95_pct"] is None for t in j["trends"])


def test_rerun_after_killing_the_sweep_and_its_workers_finishes_only_the_missing(
        config: Path, local: Path, cluster: Cluster, tmp_path: Path) -> None:
    cluster.start_workers(2 - len(cluster.workers))
    out = tmp_path / "K"
    proc = _start_sweep(config, out, cluster.address)
    try:  # a lost job: the sweep and every worker killed after the first finished member
        _wait(proc, lambda: any(_finished(out / f"condition_{k}") for k in range(1, 6)))
        proc.send_signal(signal.SIGKILL)
        cluster.kill_workers()
        proc.wait()
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    done = [k for k in range(1, 6) if _finished(out / f"condition_{k}")]
    started = [k for k in range(1, 6) if k not in done
               and (out / f"condition_{k}" / "checkpoint.npz").is_file()]
    assert 1 <= len(done) < 5
    before = {k: (out / f"condition_{k}" / "summary.json").stat().st_mtime_ns for k in done}
    cluster.start_workers(2)
    r = run_tribodem("braking", "sweep", "--config", str(config), "--out", str(out),
                     "--scheduler", cluster.address, "--no-progress", timeout=300)
    assert r.returncode == 0, r.stderr
    assert f"{5 - len(done)} run, {len(done)} skipped as finished, 0 failed" in r.stdout
    for k in started:
        assert f"condition_{k}: resuming from its checkpoint" in r.stdout
    for k in done:  # untouched
        assert (out / f"condition_{k}" / "summary.json").stat().st_mtime_ns == before[k]
    for k in range(1, 6):
        _same_member(local / f"condition_{k}" / "seed_0", out / f"condition_{k}")


def test_local_sweep_comparison_has_paired_intervals(local: Path) -> None:
    j = json.loads((local / "comparison.json").read_text())
    assert j["packings"] == 2 and len(j["trends"]) == 10  # 6 wear + 4 force-chain changes
    for t in j["trends"]:
        assert {"seed_pct", "ours_pct", "ci95_pct", "reproduced"} <= set(t)
        assert t["ci95_pct"] is None or t["ci95_pct"] >= 0
        if t["ci95_pct"] is not None:  # the stated rule
            assert t["reproduced"] == (abs(t["seed_pct"] - t["ours_pct"]) <= t["ci95_pct"])
    md = (local / "comparison.md").read_text()
    assert "paired 95% interval" in md and "seed inside" in md


def test_sweep_of_chosen_conditions_reuses_members_and_evaluates_what_it_can(
        local: Path, tmp_path: Path) -> None:
    """``--conditions 1,5`` on a copy of the 2-packing sweep: its members are the same
    folders (skipped as finished, nothing run), and only the change 1 -> 5 is evaluated."""
    import shutil

    out = tmp_path / "C"
    shutil.copytree(local, out)
    for f in ("comparison.md", "comparison.json", "comparison.csv"):
        (out / f).unlink()
    r = run_tribodem("braking", "sweep", "--config", str(local.parent / "sweep.toml"),
                     "--out", str(out), "--packings", "2", "--conditions", "5,1",
                     "--workers", "2", "--no-progress", timeout=300)
    assert r.returncode == 0, r.stderr
    assert r.stdout.count("finished earlier, skipped") == 4
    assert "condition(s) 1,5 x 2 packing(s)" in r.stdout
    j = json.loads((out / "comparison.json").read_text())
    assert j["conditions"] == {"1": 2, "5": 2}
    full = json.loads((local / "comparison.json").read_text())
    for t, u in zip(j["trends"], full["trends"], strict=True):
        if (t["from_condition"], t["to_condition"]) == (1, 5):
            assert t == u  # the same members, the same paired change
        else:
            assert t["ours_pct"] is None and t["reproduced"] is None
    assert "Condition(s) 1, 5 of table 4 (not run or all failed: 2, 3, 4)" in (
        out / "comparison.md").read_text()


def test_sweep_options_refused_before_any_work(config: Path, tmp_path: Path) -> None:
    out = tmp_path / "X"
    r = run_tribodem("braking", "sweep", "--config", str(config), "--out", str(out),
                     "--scheduler", "nowhere", timeout=120)
    assert r.returncode == 2 and "--scheduler" in r.stderr and "Traceback" not in r.stderr
    r = run_tribodem("braking", "sweep", "--config", str(config), "--out", str(out),
                     "--scheduler", "tcp://127.0.0.1:8786", "--workers", "2", timeout=120)
    assert r.returncode == 2 and "--workers" in r.stderr
    r = run_tribodem("braking", "sweep", "--config", str(config), "--out", str(out),
                     "--seeds", "2", "--packings", "3", timeout=120)
    assert r.returncode == 2 and "deprecated" in r.stderr and "--packings" in r.stderr
    for bad in ("1,6", "1,1", "one"):
        r = run_tribodem("braking", "sweep", "--config", str(config), "--out", str(out),
                         "--conditions", bad, timeout=120)
        assert r.returncode == 2 and "--conditions" in r.stderr and bad in r.stderr
        assert "[1, 2, 3, 4, 5]" in r.stderr and "Traceback" not in r.stderr
    assert not out.exists()
    r = run_tribodem("braking", "sweep", "--help", timeout=120)
    assert "--packings" in r.stdout and "--seeds" not in r.stdout


def test_projected_wall_time_is_rounds_of_one_member() -> None:
    """``projected_wall_s``: equal members fill ceil(N / W) rounds (closed form), one
    worker runs them one after the other, more workers than members is one round;
    nonsense counts are refused."""
    from tribodem.braking import projected_wall_s

    assert projected_wall_s(40, 900.0, 1) == 40 * 900.0
    assert projected_wall_s(40, 900.0, 16, startup_s=60.0) == 60.0 + 3 * 900.0
    assert projected_wall_s(40, 900.0, 40) == projected_wall_s(40, 900.0, 400) == 900.0
    for w in range(1, 50):  # never below the total work shared out, never a round more
        t = projected_wall_s(40, 1.0, w)
        assert 40 / w <= t < 40 / w + 1
    with pytest.raises(ValueError, match="workers = 0"):
        projected_wall_s(40, 900.0, 0)
    with pytest.raises(ValueError, match="member_s = -1"):
        projected_wall_s(40, -1.0, 2)


def test_batch_cluster_example_writes_one_core_jobs_and_projects(tmp_path: Path) -> None:
    """examples/braking_cluster.py (dask-jobqueue, SLURM): the job script it would submit
    asks for one core and one one-thread worker with the thread counts pinned to 1; the
    member cost is the mean wall time of the finished members of a sweep folder (a
    stopped one is not counted); the projection is ``projected_wall_s`` per size."""
    pytest.importorskip("dask_jobqueue")
    import argparse
    import importlib.util

    path = Path(__file__).resolve().parents[1] / "examples" / "braking_cluster.py"
    spec = importlib.util.spec_from_file_location("braking_cluster", path)
    assert spec is not None and spec.loader is not None
    ex = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ex)
    for k, (status, wall) in enumerate((("finished", 100.0), ("finished", 300.0),
                                        ("stopped", 5.0))):
        d = tmp_path / f"condition_{k + 1}" / "seed_0"
        d.mkdir(parents=True)
        (d / "summary.json").write_text(json.dumps({"status": status, "wall_time_s": wall}))
    assert ex.measured_member_s(tmp_path) == (200.0, 2)
    with pytest.raises(ValueError, match="no finished member"):
        ex.measured_member_s(tmp_path / "condition_3")
    rows = ex.projection(40, 200.0, (1, 16, 40), startup_s=60.0)
    assert rows == [(1, 60.0 + 8000.0), (16, 60.0 + 600.0), (40, 260.0)]
    a = argparse.Namespace(memory="2GB", walltime="04:00:00", queue="long")
    cluster = ex.make_cluster(a)
    try:
        script = cluster.job_script()
    finally:
        cluster.close()
    assert "#SBATCH --cpus-per-task=1" in script and "--partition=long" in script
    assert "--nthreads 1" in script and "OMP_NUM_THREADS=1" in script
    assert "NUMBA_NUM_THREADS=1" in script and "-t 04:00:00" in script
