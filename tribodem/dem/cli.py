"""CLI of the engine room: ``tribodem dem run`` (the demo scenario) and ``tribodem bench dem``."""

from __future__ import annotations

import json
import time
from pathlib import Path
from typing import Literal

import numpy as np
import typer
from pydantic import BaseModel, ConfigDict, Field

from tribodem.io.config import ConfigError, dump_toml, load_toml, merge, validate
from tribodem.io.results import write_json, write_text

dem_app = typer.Typer(help="Run the DEM engine on its own (demo scenarios).",
                      no_args_is_help=True)
bench_app = typer.Typer(help="Measure performance.", no_args_is_help=True)


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class CaseCfg(_Strict):
    """Which scenario and how big."""

    kind: Literal["settle3d", "compress2d"] = "settle3d"
    particles: int = Field(2000, ge=10, le=5_000_000, description="number of particles")
    seed: int = Field(0, ge=0)


class RunCfg(_Strict):
    """Length of the run and threads."""

    steps: int = Field(4000, ge=1, le=100_000_000)
    threads: int = Field(0, ge=0, le=256, description="0 = all cores")


class OutputCfg(_Strict):
    """Sampling intervals (steps); 0 switches an output off."""

    scalars_every: int = Field(50, ge=1)
    vtk_every: int = Field(1000, ge=0)
    checkpoint_every: int = Field(2000, ge=0)


class DemRunConfig(_Strict):
    """``tribodem dem run`` configuration (TOML tables [case], [run], [output])."""

    case: CaseCfg = CaseCfg()
    run: RunCfg = RunCfg()
    output: OutputCfg = OutputCfg()


QUICK = {"case": {"particles": 1000}, "run": {"steps": 3000},
         "output": {"vtk_every": 500, "checkpoint_every": 500}}


def _build(cfg: DemRunConfig):  # noqa: ANN202 - returns (Simulation, BenchCase)
    from tribodem.dem.bench import CASES, simulation_from_case

    case = CASES[cfg.case.kind](n=cfg.case.particles, steps=cfg.run.steps, seed=cfg.case.seed)
    return simulation_from_case(case), case


@dem_app.command("run")
def dem_run(
    out: Path = typer.Option(..., "--out", help="Output directory."),
    config: Path | None = typer.Option(None, "--config", help="TOML config file."),
    quick: bool = typer.Option(False, "--quick", help="Small, fast variant."),
    resume: bool = typer.Option(False, "--resume", help="Continue from OUT/checkpoint.npz."),
    progress: bool = typer.Option(True, "--progress/--no-progress"),
) -> None:
    """Settle spheres in a box (or compress disks): writes timeseries.csv, vtk/, summary.json."""
    import numba

    from tribodem.dem.recorders import ScalarRecorder, VTKRecorder, default_probes

    data = load_toml(config) if config else {}
    if quick:
        data = merge(QUICK, data)
    cfg = validate(DemRunConfig, data, source=str(config) if config else "dem run")
    if cfg.run.threads:
        numba.set_num_threads(min(cfg.run.threads, numba.config.NUMBA_NUM_THREADS))
    ck = out / "checkpoint.npz"
    if resume and not ck.exists():
        raise ConfigError(f"--resume: no checkpoint at '{ck}'")
    out.mkdir(parents=True, exist_ok=True)
    write_text(out / "config.toml", dump_toml(cfg.model_dump()))
    sim, case = _build(cfg)
    scalars = ScalarRecorder(out / "timeseries.csv", default_probes(sim))
    if resume:
        sim.load_checkpoint(ck)
        old = np.genfromtxt(out / "timeseries.csv", delimiter=",", names=True, ndmin=1)
        scalars.rows = [list(r) for r in old if r["step"] <= sim.step_count]
    sim.add_recorder(scalars, cfg.output.scalars_every)
    if cfg.output.vtk_every:
        sim.add_recorder(VTKRecorder(out / "vtk"), cfg.output.vtk_every)
    t0 = time.perf_counter()
    remaining = cfg.run.steps - sim.step_count
    every = cfg.output.checkpoint_every or remaining
    while remaining > 0:
        k = min(every, remaining)
        sim.run(k, progress=progress and remaining > 2000)
        remaining -= k
        if cfg.output.checkpoint_every:
            sim.save_checkpoint(ck)
    sim.close_recorders()
    wall = time.perf_counter() - t0
    summary = {
        "case": case.name, "particles": sim.p.n, "steps": sim.step_count,
        "dt_s": sim.dt, "dt_critical_s": sim.dt_critical, "dt_limited_by": sim.dt_limit_by,
        "simulated_time_s": sim.time, "wall_time_s": wall, "contacts": sim.n_contacts(),
        "kinetic_energy_J": sim.kinetic_energy(), "neighbor_builds": sim.nl.builds,
        "threads": numba.get_num_threads(),
        "assumptions": "simulated time is physical time (no scaling); dt = case dt "
                       "(0.2 x critical estimate); no damping except the contact dashpots",
    }
    write_json(out / "summary.json", summary)
    typer.echo(json.dumps(summary, indent=2))


@bench_app.command("dem")
def bench_dem(
    case: str = typer.Option("settle3d", "--case", help="settle3d (Hertz) or compress2d."),
    quick: bool = typer.Option(False, "--quick", help="2,000 particles, 200 steps."),
    particles: int | None = typer.Option(None, "--particles", min=10),
    steps: int | None = typer.Option(None, "--steps", min=1),
    threads: int | None = typer.Option(None, "--threads", min=1),
    as_json: bool = typer.Option(False, "--json", help="Print one JSON object."),
) -> None:
    """Particle-steps per second of the engine on a benchmark case."""
    from tribodem.dem.bench import CASES, run_case

    if case not in CASES:
        raise ConfigError(f"bench dem: --case = {case!r}: must be one of {sorted(CASES)}")
    if quick:
        particles = particles or 2000
        steps = steps or 200
    res = run_case(case, n=particles, steps=steps, threads=threads)
    if as_json:
        typer.echo(json.dumps(res))
    else:
        typer.echo(f"{res['case']}: {res['particles']} particles x {res['steps']} steps on "
                   f"{res['threads']} thread(s): {res['particle_steps_per_s']:.3e} "
                   "particle-steps/s")
