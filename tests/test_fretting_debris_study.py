"""Seed 003 section 5.4 debris study (`tribodem fretting debris-study`).

Closed forms: the centre / edge zones and their mean pressures on a Hertz distribution;
equilibrium (solid + debris force on the lower body = the applied load) and the imposed
particle count in the run, through the installed command; resume reuses finished stages.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
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


def test_debris_study_command(tmp_path: Path) -> None:
    """The whole study on a tiny case: imposed counts, servo at its target, equilibrium of
    the lower body within 1e-6 of the load, more debris carrying more load; --resume reuses
    every stage and rewrites the same table."""
    out = tmp_path / "study"
    args = ["fretting", "debris-study", "--quick", "--cycle", "2", "--counts", "300,1200",
            "--threads", "1", "--no-progress", "--out", str(out)]
    r = run_tribodem(*args)
    assert r.returncode == 0, r.stdout + r.stderr
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
