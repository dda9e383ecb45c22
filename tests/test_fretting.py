"""Fretting wear loop: criteria, column search, geometry update, jumping, CLI."""

from __future__ import annotations

import csv
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tribodem.contact import HalfSpaceSolver
from tribodem.cyclejump import make_strategy
from tribodem.fretting import (
    ALPHA_SEED,
    RESULT_COLUMNS,
    CriterionUnavailable,
    FrettingLoop,
    column_search,
    make_criterion,
)
from tribodem.fretting.case import build_loop
from tribodem.fretting.config import FrettingConfig, resolve_config
from tribodem.io.config import ConfigError

ROOT = Path(__file__).resolve().parents[1]
LOAD, MU, AMP = 100.0, 0.6, 0.3e-3


def test_energy_volume_equals_alpha_times_dissipated_energy():
    loop = FrettingLoop(HalfSpaceSolver(n=64), make_criterion("energy"), amplitude=AMP)
    h = loop.run(4)
    e = h.cumulative_energy
    # gross slip: the interface dissipates mu P 4A per cycle (independent check of e)
    assert e == pytest.approx(4 * MU * LOAD * 4 * AMP, rel=1e-3)
    # eq 2.7: the total worn volume (both bodies) is alpha x the dissipated energy, shared
    # equally by default
    total = h.volume("upper") + h.volume("lower")
    assert total == pytest.approx(ALPHA_SEED * e, rel=1e-9)
    for body in ("upper", "lower"):
        assert h.volume(body) == pytest.approx(0.5 * ALPHA_SEED * e, rel=0.01)
        assert h.rows[-1][f"wear_volume_{body}_m3"] == pytest.approx(h.volume(body), rel=1e-12)
    # the worn surfaces are what the solver sees next cycle (geometry update)
    assert loop.solver.upper(np.zeros(1), np.zeros(1))[0] == pytest.approx(
        h.wear_upper[32, 32], rel=1e-9)
    # depth grows with cycles on both bodies, deepest at the centre of the upper spot
    d = [r["wear_depth_upper_m"] for r in h.rows]
    assert all(b > a for a, b in zip(d, d[1:], strict=False))
    assert np.unravel_index(np.argmax(h.wear_upper), h.wear_upper.shape) == (32, 32)


def _punch(radius: float):
    def g(x, y):
        return np.where(np.hypot(x, y) <= radius, 0.0, 2e-5)
    return g


def _flat(x, y):
    return np.zeros(np.broadcast_shapes(np.shape(x), np.shape(y)))


def test_archard_flat_on_flat_volume_equals_k_p_s():
    ku, kl, amp, cycles = 2e-15, 5e-16, 0.1e-3, 2
    solver = HalfSpaceSolver(_punch(0.2e-3), _flat, load=LOAD, n=64, window=1.0e-3)
    h = FrettingLoop(solver, make_criterion("archard", k_upper=ku, k_lower=kl), amplitude=amp,
                     n_increments=16).run(cycles)
    s = 4 * amp * cycles  # sliding distance, m
    for body, k in (("upper", ku), ("lower", kl)):  # each body: k_body P s
        assert h.volume(body) == pytest.approx(k * LOAD * s, rel=0.01)
    # the lower body's scar spreads over the stroke: shallower than the upper one
    assert h.wear_lower.max() < h.wear_upper.max() * kl / ku


@pytest.mark.parametrize("z", [np.linspace(0, 1e-4, 11), np.geomspace(1e-7, 1e-4, 17)])
def test_column_search_linear_field_matches_analytic_crossing(z):
    rng = np.random.default_rng(3)
    v0 = rng.uniform(700e6, 2000e6, size=(5, 7))
    grad = rng.uniform(5e12, 3e13, size=(5, 7))  # Pa/m, decreasing with depth
    thr = 680e6
    values = v0[None] - grad[None] * z[:, None, None]
    depth, sat = column_search(values, z, thr)
    exact = (v0 - thr) / grad
    inside = exact < z[-1]
    np.testing.assert_allclose(depth[inside], exact[inside], rtol=1e-6)
    assert np.all(sat == ~inside)
    np.testing.assert_array_equal(depth[~inside], z[-1])
    # below threshold everywhere: no wear; subsurface peak above threshold: removed to the
    # depth where the field falls back below it
    d0, _ = column_search(np.full((11, 2), 1.0), z[:11] if z.size >= 11 else z, 2.0)
    assert np.all(d0 == 0.0)
    zz = np.linspace(0, 4, 5)
    d1, _ = column_search(np.array([0.5, 1.5, 3.0, 1.0, 0.0]), zz, 2.0)
    assert float(d1) == pytest.approx(2.0 + (3.0 - 2.0) / (3.0 - 1.0))


def test_shear_criterion_wears_both_bodies_and_reports_grid():
    from tribodem.contact import HertzSphere

    crit = make_criterion("shear", nz=9, samples=4)
    solver = HalfSpaceSolver(n=32)
    h = FrettingLoop(solver, crit, n_increments=8).run(1)
    # surface shear mu p0 = 0.6 x 2.76 GPa > 0.8 UTS: wear at the centre of both bodies
    assert h.wear_upper[16, 16] > 0 and h.wear_lower.max() > 0
    info = crit.info()
    # the largest D = tau / (0.8 UTS) is the surface traction mu p_max of gross slip (eq 6.9)
    d_max = MU * h.rows[0]["max_pressure_Pa"] / (0.8 * 1000e6)
    assert info["max_value_upper"] == pytest.approx(d_max, rel=1e-6)
    assert info["max_value_lower"] == pytest.approx(d_max, rel=1e-6)
    p0 = HertzSphere(4e-3, LOAD, solver.modulus).peak_pressure
    assert info["max_value_upper"] == pytest.approx(MU * p0 / 800e6, rel=0.02)
    # default grid: 3 equivalent contact radii deep; the wear stays inside it
    a = float(np.sqrt(h.rows[0]["contact_area_m2"] / np.pi))
    assert info["grid_depth_m"] == pytest.approx(3 * a, rel=0.1)
    assert info["saturated_columns_upper"] == 0 and h.wear_upper.max() < info["grid_depth_m"]


def test_unavailable_criteria_refuse_with_reason():
    crit = make_criterion("dfdi")  # refused before any work by an elastic solver
    with pytest.raises(CriterionUnavailable,
                       match="'dfdi' needs plastic .the equivalent plastic strain.*HalfSpace"):
        FrettingLoop(HalfSpaceSolver(n=32), crit, n_increments=8)
    with pytest.raises(ValueError, match="unknown criterion"):
        make_criterion("hardness")


def test_jumped_run_matches_unjumped_on_steady_case():
    cycles = 30
    ref = FrettingLoop(HalfSpaceSolver(n=32), make_criterion("energy")).run(cycles)
    jl = FrettingLoop(HalfSpaceSolver(n=32), make_criterion("energy"),
                      strategy=make_strategy("constant", jump_length=5)).run(cycles)
    assert [r["cycle"] for r in jl.rows] == list(range(1, cycles + 1))
    assert jl.cycles_jumped > 0 and jl.cycles_simulated + jl.cycles_jumped == cycles
    assert sum(r["jumped"] for r in jl.rows) == jl.cycles_jumped
    for body in ("upper", "lower"):
        assert jl.volume(body) == pytest.approx(ref.volume(body), rel=0.03)
    assert np.abs(jl.wear_upper - ref.wear_upper).max() <= 0.03 * ref.wear_upper.max()


def test_config_refuses_bad_values():
    with pytest.raises(ConfigError, match="wear.criterion"):
        resolve_config(None, overrides={"wear": {"criterion": "nope"}})
    with pytest.raises(ConfigError, match="n_increments"):
        resolve_config(None, overrides={"contact": {"n_increments": 10}})
    with pytest.raises(ConfigError, match="Extra inputs"):
        resolve_config(None, overrides={"contact": {"radius": 1.0}})
    with pytest.raises(ConfigError, match="plastic strain"):
        build_loop(FrettingConfig.model_validate({"wear": {"criterion": "dfdi"}}))


def _cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "tribodem.cli", "fretting", "run", *args],
                          cwd=ROOT, capture_output=True, text=True, timeout=300)


def test_cli_quick_writes_results_and_summary(tmp_path):
    cfg = tmp_path / "f.toml"
    cfg.write_text("cycles = 6\n[jump]\nstrategy = \"constant\"\nparams = {jump_length = 3}\n")
    out = tmp_path / "run"
    p = _cli("--config", str(cfg), "--quick", "--cycles", "6", "--out", str(out))
    assert p.returncode == 0, p.stderr
    with (out / "results.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    assert tuple(rows[0].keys()) == RESULT_COLUMNS
    assert [int(r["cycle"]) for r in rows] == list(range(1, 7))
    assert any(r["jumped"] == "1" for r in rows)
    s = json.loads((out / "summary.json").read_text())
    assert s["cycles_simulated"] + s["cycles_jumped"] == 6
    assert s["config"]["contact"]["n"] == 64 and s["criterion"]["name"] == "energy"
    assert s["wear_volume_upper_m3"] == pytest.approx(float(rows[-1]["wear_volume_upper_m3"]))
    for f in ("profiles.png", "wear_scar.png", "wear_vs_cycle.png", "surface_upper.vtu",
              "config.toml"):
        assert (out / f).stat().st_size > 0


@pytest.mark.parametrize("args", [("--criterion", "nope"), ("--solver", "plastic"),
                                  ("--criterion", "dfdi"), ("--jump", "sometimes")])
def test_cli_bad_input_exits_2(tmp_path, args):
    p = _cli("--quick", *args, "--out", str(tmp_path / "x"))
    assert p.returncode == 2, p.stderr
    assert "Traceback" not in p.stderr and p.stderr.strip()
    assert not (tmp_path / "x" / "results.csv").exists()
