"""Lu (2018) section 5.4 debris study (`tribodem fretting debris-study`).

Closed forms: the centre / edge zones and their mean pressures on a Hertz distribution;
equilibrium (solid + debris force on the lower body = the applied load) and the imposed
particle count in the run, through the installed command; resume reuses finished stages,
and a study killed between two counts resumes to the uninterrupted study, bitwise.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from conftest import run_tribodem

from tribodem.fretting.debris import DebrisSettings
from tribodem.fretting.debris_counts import contact_zones, distribution_metrics, place_debris


def _hertz(n: int = 512, a_cells: float = 120.0) -> tuple[np.ndarray, np.ndarray, float]:
    dx = 1e-6
    c = (np.arange(n) - n // 2) * dx
    xw, yw = np.meshgrid(c, c, indexing="ij")
    a = a_cells * dx
    p = 1e9 * np.sqrt(np.clip(1 - (xw**2 + yw**2) / a**2, 0, None))
    return p, c, a


def test_zones_on_hertz_match_closed_form() -> None:
    """Quarter-area zones of a Hertz contact: centre r <= a/2, edge r >= (sqrt 3/2) a; mean
    pressures (2/3)(1 - (3/4)^1.5) / (1/4) p0 = 0.9346 p0 and (1/3) p0 (ratio 2.804)."""
    p, c, a = _hertz()
    z = contact_zones(p, c)
    dx = float(c[1] - c[0])
    assert math.isclose(z.radius_m, a, rel_tol=0.01)
    xw, yw = np.meshgrid(c, c, indexing="ij")
    r = np.hypot(xw, yw)
    assert r[z.centre].max() <= 0.5 * a + dx
    assert r[z.edge].min() >= math.sqrt(0.75) * a - dx
    m = distribution_metrics(p, z, dx)
    centre = (2 / 3) * (1 - 0.75**1.5) / 0.25
    assert math.isclose(m["centre_mean_pressure_Pa"] / 1e9, centre, rel_tol=0.01)
    assert math.isclose(m["edge_mean_pressure_Pa"] / 1e9, 1 / 3, rel_tol=0.03)
    # total force: (2/3) pi a^2 p0 on the grid
    assert math.isclose(m["total_force_N"], 2 / 3 * math.pi * a**2 * 1e9, rel_tol=0.005)


def test_placement_count_and_sites() -> None:
    """Exactly N particles, all inside the worn cells (within half a cell), none elsewhere."""
    n, dx = 64, 2e-6
    c = (np.arange(n) - n // 2) * dx
    depth = np.zeros((n, n))
    depth[20:30, 25:40] = 1e-8
    f = place_debris(DebrisSettings(seed=3), 12_345, [(depth, c, c)], dx * dx, cycle=7)
    assert f.n == 12_345
    i = np.floor((f.xy[:, 0] - c[0]) / dx + 0.5).astype(int)
    j = np.floor((f.xy[:, 1] - c[0]) / dx + 0.5).astype(int)
    assert ((i >= 20) & (i < 30) & (j >= 25) & (j < 40)).all()


#: the tiny study of these tests (its folder given with --out)
STUDY = ["fretting", "debris-study", "--quick", "--cycle", "2", "--counts", "300,1200",
         "--threads", "1", "--no-progress"]


@pytest.fixture(scope="module")
def study(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The folder of the tiny study, run once without interruption."""
    out = tmp_path_factory.mktemp("debris_study") / "study"
    r = run_tribodem(*STUDY, "--out", str(out))
    assert r.returncode == 0, r.stdout + r.stderr
    return out


def test_debris_study_command(study: Path) -> None:
    """The whole study on a tiny case: imposed counts, servo at its target, equilibrium of
    the lower body within 1e-6 of the load, more debris carrying more load; --resume reuses
    every stage and rewrites the same table."""
    out = study
    args = [*STUDY, "--out", str(out)]
    s = json.loads((out / "debris_study.json").read_text())
    assert s["cycle"] == 2 and [row["particles"] for row in s["rows"]] == [300, 1200]
    load = 100.0
    assert math.isclose(s["no_debris"]["total_force_N"], load, rel_tol=1e-6)
    for row in s["rows"]:
        assert row["particles_in_window"] == row["particles"]
        assert row["converged"] and row["servo_rel_error"] < 1e-4
        assert row["load_balance_error"] < 1e-6
        assert 0 < row["debris_load_fraction"] < 0.9
        assert row["solid_peak_pressure_Pa"] <= row["total_peak_pressure_Pa"] * (1 + 1e-12)
    assert s["rows"][1]["debris_load_fraction"] > s["rows"][0]["debris_load_fraction"]
    for name in ("debris_study.csv", "debris_study_profiles.png",
                 "debris_study_particles.png", "debris_study_profiles.csv"):
        assert (out / name).is_file(), name
    table = (out / "debris_study.csv").read_text()
    r2 = run_tribodem(*args, "--resume")
    assert r2.returncode == 0, r2.stdout + r2.stderr
    assert "DE phase" not in r2.stdout and "fretting run" not in r2.stdout
    assert (out / "debris_study.csv").read_text() == table
    # --resume alone takes the study's own config and counts
    r3 = run_tribodem("fretting", "debris-study", "--out", str(out), "--resume", "--no-progress")
    assert r3.returncode == 0, r3.stdout + r3.stderr
    assert "DE phase" not in r3.stdout and (out / "debris_study.csv").read_text() == table


def _numbers(row: dict) -> dict:
    """A count's row without its wall-clock time."""
    return {k: v for k, v in row.items() if k != "de_wall_time_s"}


def test_a_study_killed_after_a_count_resumes_to_the_uninterrupted_study(
        tmp_path: Path, study: Path) -> None:
    """kill -9 once the first count is done, then --resume: the next count is bitwise the
    uninterrupted study's (the first-body solver's warm starts after each count are in the
    count's stage checkpoint; without them the next count's solves started from the
    no-debris solution: peak pressure 2759442594 vs 2759462305 Pa)."""
    import signal
    import subprocess
    import time

    from conftest import tribodem_exe

    out = tmp_path / "killed"
    proc = subprocess.Popen([tribodem_exe(), *STUDY, "--out", str(out)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    first = out / "count_000300.json"
    end = time.monotonic() + 300
    while not first.exists():
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < end, "the first count did not finish"
        time.sleep(0.01)
    proc.send_signal(signal.SIGKILL)
    proc.communicate(timeout=60)
    assert not (out / "count_001200.json").exists(), "killed too late: the study finished"
    r = run_tribodem(*STUDY, "--out", str(out), "--resume")
    assert r.returncode == 0, r.stdout + r.stderr
    assert "300 debris particles" not in r.stdout and "1,200 debris particles" in r.stdout
    for count in (300, 1200):
        a = json.loads((study / f"count_{count:06d}.json").read_text())
        b = json.loads((out / f"count_{count:06d}.json").read_text())
        assert _numbers(a) == _numbers(b), count
        with np.load(study / f"count_{count:06d}.npz") as fa, \
                np.load(out / f"count_{count:06d}.npz") as fb:
            assert fa.files == fb.files
            for k in fa.files:
                assert np.array_equal(fa[k], fb[k]), (count, k)
