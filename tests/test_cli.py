"""The ``tribodem`` command: version, benchmark JSON, config refusal, demo run and resume."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np


def tribodem(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "tribodem.cli", *args], capture_output=True,
                          text=True, timeout=600)


def test_version() -> None:
    r = tribodem("--version")
    assert r.returncode == 0 and r.stdout.startswith("tribodem ")
    assert "\nccx: " in r.stdout  # the ccx the finite-element backends run, or how to install it


def test_bench_quick_json() -> None:
    r = tribodem("bench", "dem", "--quick", "--json")
    assert r.returncode == 0, r.stderr
    res = json.loads(r.stdout)
    for key in ("case", "particles", "steps", "particle_steps_per_s", "threads"):
        assert key in res
    assert res["particles"] == 2000 and res["steps"] == 200 and res["particle_steps_per_s"] > 0


def test_bad_config_is_refused_with_field_value_and_range(tmp_path: Path) -> None:
    cfg = tmp_path / "bad.toml"
    cfg.write_text("[case]\nparticles = -5\n[run]\nsteps = 10\n")
    r = tribodem("dem", "run", "--config", str(cfg), "--out", str(tmp_path / "o"))
    assert r.returncode == 2
    assert "case.particles" in r.stderr and "-5" in r.stderr and "greater than or equal" in \
        r.stderr
    assert "Traceback" not in r.stderr
    assert not (tmp_path / "o").exists()  # refused before any work
    cfg.write_text("[case]\nkind = 'brake'\n")
    r = tribodem("dem", "run", "--config", str(cfg), "--out", str(tmp_path / "o"))
    assert r.returncode == 2 and "case.kind" in r.stderr and "settle3d" in r.stderr
    cfg.write_text("[run]\nstepz = 3\n")
    r = tribodem("dem", "run", "--config", str(cfg), "--out", str(tmp_path / "o"))
    assert r.returncode == 2 and "run.stepz" in r.stderr


def test_demo_run_and_resume(tmp_path: Path) -> None:
    cfg = tmp_path / "c.toml"
    cfg.write_text("[case]\nparticles = 400\n[run]\nsteps = 600\n"
                   "[output]\nvtk_every = 300\ncheckpoint_every = 300\nscalars_every = 50\n")
    full = tmp_path / "full"
    r = tribodem("dem", "run", "--config", str(cfg), "--out", str(full), "--no-progress")
    assert r.returncode == 0, r.stderr
    s = json.loads((full / "summary.json").read_text())
    assert s["steps"] == 600 and s["particles"] == 400
    assert (full / "vtk" / "particles.pvd").exists()
    import meshio

    mesh = meshio.read(next((full / "vtk").glob("particles_*.vtu")))
    assert mesh.points.shape == (400, 3) and "velocity" in mesh.point_data
    # resume: run 300 steps, then continue to 600 from the checkpoint
    half = tmp_path / "half"
    cfg2 = tmp_path / "c2.toml"
    cfg2.write_text(cfg.read_text().replace("steps = 600", "steps = 300"))
    assert tribodem("dem", "run", "--config", str(cfg2), "--out", str(half),
                    "--no-progress").returncode == 0
    r = tribodem("dem", "run", "--config", str(cfg), "--out", str(half), "--resume",
                 "--no-progress")
    assert r.returncode == 0, r.stderr
    a = np.load(full / "checkpoint.npz")
    b = np.load(half / "checkpoint.npz")
    assert np.array_equal(a["p_pos"], b["p_pos"]) and np.array_equal(a["p_vel"], b["p_vel"])
    ta = np.genfromtxt(full / "timeseries.csv", delimiter=",", names=True)
    tb = np.genfromtxt(half / "timeseries.csv", delimiter=",", names=True)
    assert np.array_equal(ta["step"], tb["step"])
