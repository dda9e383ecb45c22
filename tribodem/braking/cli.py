"""``tribodem braking run`` and ``tribodem braking sweep`` (seed 000 sections 3.2-5, table 4)."""

from __future__ import annotations

import json
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any, Literal

import typer
from pydantic import BaseModel, ConfigDict, Field, model_validator

from tribodem.io.config import ConfigError, dump_toml, load_toml, merge, validate
from tribodem.io.results import write_text

braking_app = typer.Typer(help="Braking interface wear model (seed 000).", no_args_is_help=True)


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class ConditionCfg(_Strict):
    """Table 4 ``index`` or an explicit load (kN or Pa) and speed (r/min or m/s)."""

    index: int | None = Field(None, ge=1, le=5, description="table 4 condition 1..5")
    load_kN: float | None = Field(None, gt=0)
    pressure_Pa: float | None = Field(None, gt=0)
    rpm: float | None = Field(None, gt=0)
    speed_m_s: float | None = Field(None, gt=0)

    @model_validator(mode="after")
    def _one_form(self) -> ConditionCfg:
        if self.load_kN is not None and self.pressure_Pa is not None:
            raise ValueError("give load_kN or pressure_Pa, not both")
        if self.rpm is not None and self.speed_m_s is not None:
            raise ValueError("give rpm or speed_m_s, not both")
        return self


class GeometryCfg(_Strict):
    """Interface cell sizes (m)."""

    width_m: float = Field(216e-6, gt=0)
    disc_height_m: float = Field(72e-6, gt=0)
    pad_height_m: float = Field(108e-6, gt=0)
    roughness_amplitude_m: float = Field(8e-6, ge=0)
    roughness_modes: int = Field(4, ge=1, le=64)
    clearance_m: float = Field(5e-8, ge=0)
    seed: int = Field(0, ge=0)


class RunCfg(_Strict):
    """Simulated sliding time (s), sampling, numerics."""

    duration_s: float = Field(40e-6, gt=0, le=1e-2)
    samples: int = Field(150, ge=2, le=100_000)
    vtk_snapshots: int = Field(6, ge=0, le=10_000)
    micro: Literal["calibrated", "table3"] = "calibrated"
    plate_areal_mass_kg_m2: float = Field(
        0.0, ge=0, le=1e4,
        description="pressure plate mass per area (kg/m^2), e.g. 126 for the omitted pad "
                    "and back plate; 0 = wall_mass_ratio x the cell's pad mass")
    wall_mass_ratio: float = Field(0.05, gt=0, le=1000)
    backing: Literal["absorbing", "support"] = "absorbing"
    local_damping: float = Field(0.0, ge=0, lt=1)
    dt_safety: float = Field(0.3, gt=0, le=1)
    threads: int = Field(0, ge=0, le=256, description="0 = all cores")
    figures: bool = True


class ThermalCfg(_Strict):
    """Optional temperature boundary curve (CSV: time s, temperature K)."""

    curve: str | None = None
    time_map: Literal["simulated", "stretched"] = "simulated"


class BrakingConfig(_Strict):
    """``tribodem braking run`` configuration (TOML tables)."""

    condition: ConditionCfg = ConditionCfg()
    geometry: GeometryCfg = GeometryCfg()
    run: RunCfg = RunCfg()
    thermal: ThermalCfg = ThermalCfg()


QUICK: dict[str, Any] = {
    "geometry": {"width_m": 144e-6, "disc_height_m": 50e-6, "pad_height_m": 50e-6,
                 "roughness_amplitude_m": 6e-6, "roughness_modes": 3},
    "run": {"duration_s": 20e-6, "samples": 100, "vtk_snapshots": 4},
}


def setup_from_config(cfg: BrakingConfig) -> Any:
    """A ``RunSetup`` from a validated config; ConfigError when the load or speed is
    missing."""
    from tribodem.braking.conditions import get_condition, load_to_pressure, rpm_to_speed
    from tribodem.braking.model import Geometry
    from tribodem.braking.run import RunSetup

    c = cfg.condition
    base = get_condition(c.index) if c.index is not None else None
    if c.pressure_Pa is not None:
        p = c.pressure_Pa
    elif c.load_kN is not None:
        p = load_to_pressure(c.load_kN)
    elif base is not None:
        p = base.pressure_Pa
    else:
        raise ConfigError("braking: no load: give --condition 1..5 or [condition] index, "
                          "load_kN or pressure_Pa")
    if c.speed_m_s is not None:
        v = c.speed_m_s
    elif c.rpm is not None:
        v = rpm_to_speed(c.rpm)
    elif base is not None:
        v = base.speed_m_s
    else:
        raise ConfigError("braking: no speed: give --condition 1..5 or [condition] index, "
                          "rpm or speed_m_s")
    explicit = any(x is not None for x in (c.load_kN, c.pressure_Pa, c.rpm, c.speed_m_s))
    g = cfg.geometry
    geo = Geometry(width=g.width_m, disc_height=g.disc_height_m, pad_height=g.pad_height_m,
                   amplitude=g.roughness_amplitude_m, modes=g.roughness_modes,
                   clearance=g.clearance_m, seed=g.seed)
    from tribodem.braking.model import materials

    rmax = max(m.radius_range[1] for m in materials(cfg.run.micro))
    try:
        geo.check(rmax)
    except ValueError as err:
        raise ConfigError(f"braking: {err}") from None
    curve = None
    if cfg.thermal.curve is not None:
        curve = Path(cfg.thermal.curve)
        if not curve.is_file():
            raise ConfigError(f"braking: thermal.curve = '{curve}': file does not exist")
    r = cfg.run
    return RunSetup(pressure_Pa=p, speed_m_s=v, duration_s=r.duration_s, geometry=geo,
                    condition=None if explicit else c.index, micro=r.micro, samples=r.samples,
                    vtk_snapshots=r.vtk_snapshots, wall_mass_ratio=r.wall_mass_ratio,
                    plate_areal_mass=r.plate_areal_mass_kg_m2 or None, backing=r.backing,
                    local_damping=r.local_damping, dt_safety=r.dt_safety,
                    thermal_curve=curve, thermal_time_map=cfg.thermal.time_map,
                    figures=r.figures)


def _config(condition: int | None, config: Path | None, quick: bool) -> BrakingConfig:
    data = load_toml(config) if config else {}
    if quick:
        data = merge(QUICK, data)
    if condition is not None:
        data = merge(data, {"condition": {"index": condition}})
    return validate(BrakingConfig, data, source=str(config) if config else "braking")


def _run_one(cfg_data: dict[str, Any], out: str, threads: int) -> dict[str, Any]:
    """Worker: one run in its own process (sweep)."""
    import numba

    from tribodem.braking.run import run_braking

    if threads:
        numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
    cfg = validate(BrakingConfig, cfg_data, source="sweep")
    setup = setup_from_config(cfg)
    o = Path(out)
    o.mkdir(parents=True, exist_ok=True)
    write_text(o / "config.toml", dump_toml(cfg.model_dump(exclude_none=True)))
    return run_braking(setup, o)


@braking_app.command("run")
def braking_run(
    out: Path = typer.Option(..., "--out", help="Output directory."),
    condition: int | None = typer.Option(None, "--condition", help="Table 4 condition 1..5."),
    config: Path | None = typer.Option(None, "--config", help="TOML config file."),
    quick: bool = typer.Option(False, "--quick", help="Small, fast variant (< 3 min)."),
) -> None:
    """One interface run: summary.json, timeseries.csv, PNG figures, vtk/ snapshots."""
    from tribodem.braking.conditions import CONDITIONS

    if condition is not None and condition not in CONDITIONS:
        raise ConfigError(f"braking run: --condition = {condition!r}: must be one of "
                          f"{sorted(CONDITIONS)} (seed 000 table 4)")
    if condition is None and config is None:
        raise ConfigError("braking run: give --condition 1..5 or --config FILE")
    cfg = _config(condition, config, quick)
    setup_from_config(cfg)  # refuse a bad condition before any work
    summary = _run_one(cfg.model_dump(), str(out), cfg.run.threads)
    typer.echo(json.dumps({k: summary[k] for k in (
        "condition", "pressure_Pa", "sliding_speed_m_s", "simulated_time_s",
        "simulated_sliding_distance_m", "wear_depth_mean_m", "wear_depth_max_m",
        "broken_bonds", "debris_particles", "force_chains", "particles_initial",
        "particles_final", "mean_wall_pressure_ratio", "wall_time_s")}, indent=2))


@braking_app.command("sweep")
def braking_sweep(
    out: Path = typer.Option(..., "--out", help="Output directory."),
    config: Path | None = typer.Option(None, "--config", help="TOML config (condition ignored)."),
    quick: bool = typer.Option(False, "--quick", help="Small, fast variant (< 3 min)."),
    workers: int = typer.Option(2, "--workers", min=1, max=64, help="Parallel processes."),
    seeds: int = typer.Option(1, "--seeds", min=1, max=100,
                              help="Packing/roughness realisations per condition (averaged)."),
) -> None:
    """Conditions 1-5 in parallel: comparison.csv, comparison.md (ours beside the seed's)."""
    from tribodem.braking.compare import write_comparison

    base = _config(None, config, quick).model_dump()
    base["condition"] = {}
    seed0 = int(base["geometry"]["seed"])
    t0 = time.perf_counter()
    out.mkdir(parents=True, exist_ok=True)
    jobs = {}
    with ProcessPoolExecutor(max_workers=workers) as ex:
        for s in range(seeds):
            for k in range(1, 6):
                data = merge(base, {"condition": {"index": k},
                                    "geometry": {"seed": seed0 + s}})
                d = out / f"condition_{k}" if seeds == 1 else out / f"condition_{k}" / f"seed_{s}"
                jobs[(k, s)] = (ex.submit(_run_one, data, str(d), 1), d)
        runs: dict[int, list[tuple[dict[str, Any], Path]]] = {k: [] for k in range(1, 6)}
        for (k, _s), (f, d) in jobs.items():
            runs[k].append((f.result(), d))
    wall = time.perf_counter() - t0
    rows = write_comparison(out, runs, wall, workers, quick)
    typer.echo(f"sweep: 5 conditions x {seeds} seed(s) in {wall:.1f} s on {workers} workers "
               f"-> {out / 'comparison.md'}")
    for r in rows:
        typer.echo(f"  {r[0]}: ours {r[1]}, seed {r[2]}")
