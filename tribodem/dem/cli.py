"""CLI of the engine room: ``tribodem dem run`` (the demo scenario) and ``tribodem bench dem``."""

from __future__ import annotations

import json
import time
from pathlib import Path
from typing import Literal

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


def _resolve(config: Path | None, quick: bool, out: Path, resume: bool) -> DemRunConfig:
    """Defaults <- config file <- ``--quick`` <- (resume) the run's own config.toml.

    With ``--resume`` and no ``--config`` the run's own resolved config is used; a config
    that differs from it in anything but ``run.steps`` / ``run.threads`` is refused.
    """
    own = out / "config.toml"
    if resume and config is None and own.is_file():
        config = own
    data = load_toml(config) if config else {}
    if quick:
        data = merge(data, QUICK) if config else merge(QUICK, data)
    cfg = validate(DemRunConfig, data, source=str(config) if config else "dem run")
    if resume and own.is_file() and config != own:
        old = validate(DemRunConfig, load_toml(own), source=str(own)).model_dump()
        new = cfg.model_dump()
        for sec in ("case", "output"):
            for k, v in new[sec].items():
                if old[sec][k] != v:
                    raise ConfigError(
                        f"--resume: {sec}.{k} = {v!r} differs from the checkpointed run's "
                        f"{old[sec][k]!r} ('{own}'); allowed: the same value (only "
                        "run.steps and run.threads may change)")
    return cfg


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
    from tribodem.dem.state import BYTES_PER_PARTICLE
    from tribodem.io import runs

    ck = out / "checkpoint.npz"
    runs.check_out_dir(out, "--out", resume=resume, need=("checkpoint.npz",) if resume else ())
    cfg = _resolve(config, quick, out, resume)
    runs.check_memory(cfg.case.particles, BYTES_PER_PARTICLE, "case.particles")
    threads = runs.check_threads(cfg.run.threads, "run.threads")
    numba.set_num_threads(threads)
    sim, case = _build(cfg)
    if resume:  # check the checkpoint before touching any output
        try:
            sim.load_checkpoint(ck)
        except Exception as err:  # noqa: BLE001 - any unreadable or foreign checkpoint
            raise ConfigError(f"--resume: checkpoint '{ck}' cannot be used: {err}") from None
        if sim.step_count > cfg.run.steps:
            raise ConfigError(f"run.steps = {cfg.run.steps}: the checkpoint is already at step "
                              f"{sim.step_count}; allowed: >= {sim.step_count}")
    runs.announce(out, ck if cfg.output.checkpoint_every else None,
                  resume_hint="add --resume to the same command")
    out.mkdir(parents=True, exist_ok=True)
    write_text(out / "config.toml", dump_toml(cfg.model_dump()))
    scalars = ScalarRecorder(out / "timeseries.csv", default_probes(sim))
    vtk = VTKRecorder(out / "vtk") if cfg.output.vtk_every else None
    if resume:
        scalars.resume(sim.step_count)
        if vtk is not None:
            vtk.resume(sim.step_count)
        runs.checkpoint_written(ck)
    sim.add_recorder(scalars, cfg.output.scalars_every)
    if vtk is not None:
        sim.add_recorder(vtk, cfg.output.vtk_every)
    t0 = time.perf_counter()
    every = cfg.output.checkpoint_every or cfg.run.steps
    chunk = max(1, min(every, 1000))
    with runs.progress(cfg.run.steps, "step", "dem run", enabled=progress,
                       initial=sim.step_count) as bar:
        while sim.step_count < cfg.run.steps:
            k = min(chunk, cfg.run.steps - sim.step_count, every - sim.step_count % every)
            sim.step(k)
            bar.update(k)
            if cfg.output.checkpoint_every and sim.step_count % every == 0:
                scalars.flush()  # the CSV is never behind the checkpoint
                sim.save_checkpoint(ck)
                runs.checkpoint_written(ck)
    sim.close_recorders()
    if cfg.output.checkpoint_every and sim.step_count % every:  # the end, to extend later
        sim.save_checkpoint(ck)
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
    case: str = typer.Option("settle3d", "--case",
                             help="settle3d (Hertz), compress2d, dense3d (Hertz, "
                                  "coordination 6) or bonded3d (bonds, uniaxial compression)."),
    quick: bool = typer.Option(False, "--quick", help="2,000 particles, 200 steps."),
    particles: int | None = typer.Option(None, "--particles", min=10, max=100_000_000),
    steps: int | None = typer.Option(None, "--steps", min=1, max=10**9),
    threads: int | None = typer.Option(None, "--threads", help="1..cores (default: all)."),
    as_json: bool = typer.Option(False, "--json", help="Print one JSON object."),
) -> None:
    """Particle-steps per second of the engine on a benchmark case."""
    from tribodem.dem.bench import CASES, run_case

    if case not in CASES:
        raise ConfigError(f"bench dem: --case = {case!r}: must be one of {sorted(CASES)}")
    from tribodem.dem.state import BYTES_PER_PARTICLE
    from tribodem.io import runs

    if quick:
        particles = particles or 2000
        steps = steps or 200
    if threads is not None:
        runs.check_threads(threads, "--threads", zero_means_all=False)
    if particles is not None:
        runs.check_memory(particles, BYTES_PER_PARTICLE, "--particles")
    res = run_case(case, n=particles, steps=steps, threads=threads)
    if as_json:
        typer.echo(json.dumps(res))
    else:
        typer.echo(f"{res['case']}: {res['particles']} particles x {res['steps']} steps on "
                   f"{res['threads']} thread(s): {res['particle_steps_per_s']:.3e} "
                   "particle-steps/s")
