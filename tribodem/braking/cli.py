"""``tribodem braking run`` and ``tribodem braking sweep`` (Sha et al. (2022):
sections 3.2-5, table 4): the options parsed, then :func:`tribodem.braking.run` /
:func:`tribodem.braking.sweep` called and their result printed.

Configuration: defaults < ``--config`` file < ``--quick`` preset < ``--condition``
(:mod:`tribodem.braking.config`). What a run and a sweep do, write, resume and refuse is
said in :mod:`tribodem.braking.api`. Exit codes (``tribodem.cli.main``): 2 for a refused
input (nothing touched), 3 for a run that stopped early or a failed sweep member (outputs
kept), 130 for Ctrl-C (naming the outputs and the checkpoint).
"""

from __future__ import annotations

import json
from pathlib import Path

import typer

from tribodem.braking.api import run, sweep
from tribodem.braking.conditions import CONDITIONS
from tribodem.io.config import ConfigError, parse_int_list
from tribodem.io.helptext import reflowed

braking_app = typer.Typer(help="Braking interface wear model (Sha et al. (2022), "
                          "Lubricants).",
                          no_args_is_help=True)

#: what ``braking run`` prints of the summary
SHOWN = ("status", "condition", "pressure_Pa", "sliding_speed_m_s", "simulated_time_s",
         "simulated_sliding_distance_m", "wear_depth_mean_m", "wear_depth_max_m",
         "broken_bonds", "debris_particles", "force_chains", "particles_initial",
         "particles_final", "mean_wall_pressure_ratio", "wear_rate_steady_m_per_m",
         "steady_reached", "run_in_distance_m", "run_in_depth_m", "contact_fraction",
         "contact_fraction_after_run_in",
         "wall_time_s")


@braking_app.command("run")
@reflowed
def braking_run(
    out: Path = typer.Option(..., "--out", help="Output directory (an earlier run there is "
                             "replaced unless --resume)."),
    condition: int | None = typer.Option(
        None, "--condition",
        help="Braking condition 1..5: load and speed of table 4 of Sha et al. (2022)."),
    config: Path | None = typer.Option(None, "--config", help="TOML config file."),
    quick: bool = typer.Option(False, "--quick", help="Small, fast variant (< 3 min); it "
                               "overrides the config file, --condition overrides both."),
    resume: bool = typer.Option(False, "--resume", help="Continue the run in --out from its "
                                "checkpoint (its own config.toml unless --config/--condition "
                                "are given, which must match it)."),
    progress: bool = typer.Option(True, "--progress/--no-progress",
                                  help="Progress bar with ETA on stderr."),
) -> None:
    """One interface run: summary.json, timeseries.csv, PNG figures, vtk/ snapshots,
    checkpoint.npz (resumable with --resume)."""
    result = run(config, out, condition=condition, quick=quick, resume=resume,
                 progress=progress, echo=typer.echo)
    typer.echo(json.dumps({k: result.summary.get(k) for k in SHOWN}, indent=2))


def parse_conditions(text: str | None) -> list[int] | None:
    """``--conditions`` ("1,3,5"; None: all) -> sorted condition numbers (ConfigError:
    exit 2)."""
    if text is None:
        return None
    return sorted(parse_int_list(
        text, "braking sweep: --conditions", lambda k: k in CONDITIONS,
        f"distinct comma-separated conditions of {sorted(CONDITIONS)} (Sha et al. (2022) table 4), "
        "e.g. 1,3,5"))


def parse_packings(packings: int | None, seeds: int | None) -> int:
    """``--packings`` with its deprecated alias ``--seeds`` (a warning; ConfigError when
    both are given and differ); default 1."""
    if seeds is not None:
        typer.echo("warning: --seeds is deprecated: it counts packing/roughness "
                   "realisations; use --packings", err=True)
        if packings is not None and packings != seeds:
            raise ConfigError(f"braking sweep: --seeds = {seeds} (deprecated alias of "
                              f"--packings) contradicts --packings = {packings}; allowed: "
                              "give --packings only")
    return packings or seeds or 1


@braking_app.command("sweep")
@reflowed
def braking_sweep(
    out: Path = typer.Option(..., "--out", help="Output directory; re-running the same sweep "
                             "there skips finished members and resumes the others."),
    config: Path | None = typer.Option(None, "--config", help="TOML config (condition ignored)."),
    quick: bool = typer.Option(False, "--quick", help="Small, fast variant (< 3 min); it "
                               "overrides the config file."),
    packings: int | None = typer.Option(
        None, "--packings", min=1, max=1000,
        help="Packing/roughness realisations per condition (geometry seeds seed, seed+1, "
             "...); changes are paired over them. Default 1."),
    seeds: int | None = typer.Option(None, "--seeds", min=1, max=1000, hidden=True,
                                     help="Deprecated alias of --packings."),
    conditions: str | None = typer.Option(
        None, "--conditions",
        help="Which conditions (table 4 of Sha et al. (2022)) to run, e.g. 1,3,5 (the two "
             "end-to-end trends, 13 -> 21 kN and 800 -> 1200 r/min, at 3/5 of the cost); "
             "changes needing an absent condition are left unevaluated. Default: all five."),
    workers: int = typer.Option(
        0, "--workers", min=0, max=1024,
        help="Worker processes of the local Dask cluster (1 thread each); 0 = all local "
             "cores. Not with --scheduler."),
    scheduler: str | None = typer.Option(
        None, "--scheduler",
        help="Use an existing Dask cluster: tcp://HOST:PORT of its scheduler (dask "
             "scheduler / dask worker, dask-jobqueue, Kubernetes) or its scheduler JSON "
             "file; --out must be on a file system the workers share."),
    progress: bool = typer.Option(True, "--progress/--no-progress",
                                  help="Progress bar (members done / running / failed) on "
                                       "stderr."),
) -> None:
    """Conditions 1-5 (or --conditions) x --packings on Dask: comparison.md,
    comparison.json, comparison.csv (ours with paired 95% intervals beside the paper's,
    Sha et al. (2022) section 5), members.csv (one row per member).

    Each (condition, packing) member is an independent, idempotent task with its own
    folder and checkpoints; a re-run with the same --out skips the finished members,
    resumes the unfinished ones and starts over those whose config changed. A worker lost
    mid-member: the scheduler reschedules the member, which resumes from its checkpoint. A
    failed member is reported and left out of the comparison (exit 3 at the end)."""
    n_pack = parse_packings(packings, seeds)
    sweep(out, config=config, quick=quick, packings=n_pack,
          conditions=parse_conditions(conditions), workers=workers, scheduler=scheduler,
          progress=progress, echo=typer.echo)
