"""Debris third body (Lu (2018) 3.2.6-3.2.7): eq 3.10 mass conservation, eqs 3.11-3.15,
servo to the target load, forces mapped back and load sharing in the first-body solver."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tribodem.contact import HalfSpaceSolver
from tribodem.fretting import FrettingLoop, make_criterion
from tribodem.fretting.debris import (
    DebrisField,
    DebrisSettings,
    interpolate,
    particle_count,
    run_de_phase,
    shape_function_coefficients,
    spread,
    stack_layers,
)


def test_eq_3_15_matches_the_fitted_shape_function() -> None:
    rng = np.random.default_rng(0)
    f = rng.uniform(0, 1, (6, 5))
    x0, y0, dx, dy = -1.0, 2.0, 0.5, 0.25
    for _ in range(20):
        i, j = rng.integers(0, 5), rng.integers(0, 4)
        xn = x0 + dx * np.array([i, i + 1, i, i + 1])
        yn = y0 + dy * np.array([j, j, j + 1, j + 1])
        fn = f[[i, i + 1, i, i + 1], [j, j, j + 1, j + 1]]
        a = shape_function_coefficients(xn, yn, fn)  # eqs 3.11-3.14
        x, y = xn[0] + rng.uniform() * dx, yn[0] + rng.uniform() * dy
        direct = a[0] + a[1] * x + a[2] * y + a[3] * x * y  # eq 3.15
        got = interpolate(f, np.array([x]), np.array([y]), x0, y0, dx, dy)[0]
        assert got == pytest.approx(direct, rel=1e-10)


def test_spread_conserves_force_and_interpolation_is_exact_for_bilinear() -> None:
    rng = np.random.default_rng(1)
    x, y = rng.uniform(0, 3.9, 500), rng.uniform(0, 2.9, 500)
    f = rng.uniform(0, 1e-3, 500)
    g = spread(f, x, y, 0.0, 0.0, 1.0, 1.0, (5, 4))
    assert g.sum() == pytest.approx(f.sum(), rel=1e-12)
    xx, yy = np.meshgrid(np.arange(5.0), np.arange(4.0), indexing="ij")
    lin = 2 + 3 * xx - yy + 0.5 * xx * yy
    np.testing.assert_allclose(interpolate(lin, x, y, 0, 0, 1, 1),
                               2 + 3 * x - y + 0.5 * x * y, rtol=1e-12)


def test_debris_volume_equals_worn_volume() -> None:
    """Eq 3.10 with the remainder carried: created volume = worn volume within 1%
    (in fact within one particle) over many generations; correction scales it."""
    s = DebrisSettings(seed=4)
    rng = np.random.default_rng(2)
    c = np.linspace(-1e-4, 1e-4, 41)
    cell = (c[1] - c[0]) ** 2
    for corr in (1.0, 0.77):
        d = DebrisField(DebrisSettings(seed=4, volume_correction=corr))
        for cyc in range(12):
            dw = rng.uniform(0, 4e-9, (41, 41)) * (rng.uniform(size=(41, 41)) < 0.3)
            d.generate(cyc, [(dw, c, c), (0.5 * dw, c, c)], cell)
        worn = d.worn_volume
        assert d.created > 1000
        assert abs(d.created_volume - corr * worn) <= s.particle_volume
        assert abs(d.created_volume - corr * worn) / (corr * worn) < 0.01
    assert particle_count(s.particle_volume * 7, s.diameter) == pytest.approx(7.0)


def test_particles_are_laid_without_overlap() -> None:
    rng = np.random.default_rng(3)
    xy = rng.uniform(0, 5e-6, (400, 2))
    d = 0.6e-6
    layer = stack_layers(xy, d)
    z = layer * d
    diff = xy[:, None, :] - xy[None, :, :]
    dist = np.sqrt((diff**2).sum(-1) + (z[:, None] - z[None, :]) ** 2)
    np.fill_diagonal(dist, np.inf)
    assert dist.min() >= d * (1 - 1e-12)


def test_servo_reaches_the_target_and_the_record_shows_it() -> None:
    """A debris layer between a flat lower body and a loaded conformal upper body."""
    n = 33
    c = np.linspace(-20e-6, 20e-6, n)
    x, y = np.meshgrid(c, c, indexing="ij")
    lower = np.zeros((n, n))
    gap = np.maximum(x**2 + y**2 - (10e-6) ** 2, 0) / (2 * 4e-3)  # flat within 10 um
    d = DebrisField(DebrisSettings(seed=1, ramp_steps=3000, max_steps=40_000))
    dw = (x**2 + y**2 < (10e-6) ** 2) * 1.5e-7
    d.generate(1, [(dw, c, c)], (c[1] - c[0]) ** 2)
    assert 300 < d.n < 2000
    target = 0.05  # N
    res = run_de_phase(d, lower, gap, c, target)
    assert res.converged
    assert res.rel_error < 1e-4
    assert abs(res.history[-1, 1] - target) / target < 1e-4  # the record shows it
    assert abs(res.history[-1, 2] - target) / target < 1e-4  # and the lower body carries it
    # forces mapped back to the grid conserve the load
    assert res.pressure.sum() * (c[1] - c[0]) ** 2 == pytest.approx(res.lower_force_N, rel=1e-9)


def test_debris_pressure_shares_the_load_in_the_solver() -> None:
    sol = HalfSpaceSolver(n=64, tolerance=1e-8)
    free = sol.solve_increment(0.0)
    pd = np.zeros((64, 64))
    pd[30:34, 30:34] = 0.2 * free.pressure.max()
    sol.reset()
    sol.set_debris_pressure(pd)
    inc = sol.solve_increment(0.0)
    total = inc.normal_load + sol.debris_load
    assert total == pytest.approx(sol.load, rel=1e-6)
    assert sol.debris_load > 0.03 * sol.load
    # the debris opens the gap where it sits: less solid pressure there
    assert inc.pressure[31, 31] < free.pressure[31, 31]
    with pytest.raises(ValueError, match="debris load"):
        sol.set_debris_pressure(pd * 100)


def test_coupled_loop_conserves_mass_and_shares_load() -> None:
    sol = HalfSpaceSolver(n=32, tolerance=1e-7)
    d = DebrisField(DebrisSettings(seed=0, ramp_steps=3000, max_steps=30_000))
    loop = FrettingLoop(sol, make_criterion("energy"), n_increments=16, debris=d,
                        debris_every=1)
    hist = loop.run(2)
    assert len(hist.de_phases) == 1
    ph = hist.de_phases[0]
    assert ph.converged and ph.rel_error < 1e-4
    row = hist.rows[-1]
    assert row["load_balance_error"] < 5e-3
    assert 0 < row["debris_load_fraction"] < 0.9
    vol = hist.volume("upper") + hist.volume("lower")
    mb = hist.debris_summary()
    assert mb["worn_volume_m3"] == pytest.approx(vol, rel=1e-12)
    assert abs(mb["debris_volume_created_m3"] - vol) / vol < 0.01
    assert mb["particles_created"] == mb["particles_in_contact"] + mb["particles_ejected"]
    assert math.isfinite(ph.summary()["max_pressure_change"])


def test_quick_coupled_cli_run(tmp_path) -> None:
    """`tribodem fretting run --quick --cycles 3 --debris-every 2`: the debris outputs."""
    import csv
    import json

    from typer.testing import CliRunner

    from tribodem.cli import full_app

    app = full_app()

    out = tmp_path / "fd"
    res = CliRunner().invoke(app, ["fretting", "run", "--quick", "--cycles", "3",
                                   "--debris-every", "2", "--out", str(out)])
    assert res.exit_code == 0, res.output
    rows = list(csv.DictReader(open(out / "results.csv")))
    assert len(rows) == 3
    for key in ("debris_particles", "debris_load_fraction", "max_pressure_with_debris_Pa"):
        assert key in rows[0]
    assert float(rows[1]["debris_load_fraction"]) > 0
    assert all(float(r["load_balance_error"]) < 5e-3 for r in rows)
    s = json.load(open(out / "summary.json"))["debris"]
    assert abs(s["volume_rel_error"]) < 0.01
    ph = s["de_phases"][0]
    assert ph["converged"] and ph["rel_error"] < 1e-4
    servo = list(csv.DictReader(open(out / "debris_servo_0002.csv")))
    last = servo[-1]
    assert abs(float(last["upper_force_N"]) / float(last["target_N"]) - 1) < 1e-4
    assert (out / "debris_0002.vtu").exists() and (out / "debris_layer.png").exists()
    from tribodem.io.stl import read_stl

    tris = read_stl(out / "de_surface_upper_0002.stl")  # geometry exchange, as the seed did
    assert tris.shape == (2 * 63 * 63, 3, 3)
    assert "--no-debris" in CliRunner().invoke(app, ["fretting", "run", "--help"]).output
