"""``tribodem fretting run | study | debris-study | sweep``: the options of each command,
parsed into the call of its library function (:func:`tribodem.fretting.run`,
:func:`~tribodem.fretting.study`, :func:`~tribodem.fretting.debris_study`,
:func:`~tribodem.fretting.sweep`) and the line it prints when done. Errors go to
``tribodem.cli.main`` (``ConfigError``: exit 2, ``RunStopped``: exit 3)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from tribodem.contact import BACKENDS
from tribodem.cyclejump import STRATEGIES
from tribodem.fretting.chapter6 import study
from tribodem.fretting.criteria import CRITERIA
from tribodem.fretting.debris_counts import QUICK_STUDY_COUNTS, debris_study
from tribodem.fretting.output import CHECKPOINT
from tribodem.fretting.runner import run
from tribodem.fretting.table_sweep import sweep
from tribodem.io import runs
from tribodem.io.config import ConfigError
from tribodem.io.helptext import reflowed

fretting_app = typer.Typer(help="Fretting wear loop (Lu (2018), PhD thesis, "
                                "Exeter: chapters 5-6).",
                           no_args_is_help=True, add_completion=False)


@fretting_app.callback()
def _fretting() -> None:
    """Fretting wear loop (Lu (2018), PhD thesis, Exeter: chapters 5-6)."""


def run_overrides(criterion: str | None, cycles: int | None, jump: str | None,
                  solver: str | None, threads: int | None, debris_every: int | None,
                  no_debris: bool) -> dict[str, Any]:
    """The config overrides of ``fretting run``'s options (``ConfigError`` naming an option
    whose value is not allowed)."""
    for opt, value, allowed in (("--criterion", criterion, tuple(CRITERIA)),
                                ("--jump", jump, ("none", *STRATEGIES)),
                                ("--solver", solver, tuple(BACKENDS))):
        if value is not None and value not in allowed:
            raise ConfigError(f"{opt} = {value!r}: allowed: {', '.join(allowed)}")
    ov: dict[str, Any] = {}
    if criterion is not None:
        ov.setdefault("wear", {})["criterion"] = criterion
    if cycles is not None:
        ov["cycles"] = cycles
    if jump is not None:
        ov.setdefault("jump", {})["strategy"] = jump
    if solver is not None:
        ov["solver"] = solver
    if threads is not None:
        runs.check_threads(threads, "--threads")
        ov.setdefault("fe", {})["threads"] = threads
    if debris_every is not None and no_debris:
        raise ConfigError("--debris-every and --no-debris: give one of them, not both")
    if debris_every is not None:
        ov.setdefault("debris", {})["every"] = debris_every
    if no_debris:
        ov.setdefault("debris", {})["every"] = None
    return ov


@fretting_app.command("run")
@reflowed
def run_cmd(
    out: Annotated[Path, typer.Option("--out", help="Output directory.")],
    config: Annotated[Path | None, typer.Option("--config", help="TOML config file.")] = None,
    criterion: Annotated[str | None, typer.Option(
        "--criterion", help=f"One of: {', '.join(CRITERIA)}.")] = None,
    cycles: Annotated[int | None, typer.Option("--cycles", help="Number of cycles.")] = None,
    jump: Annotated[str | None, typer.Option(
        "--jump", help=f"none or one of: {', '.join(STRATEGIES)}.")] = None,
    solver: Annotated[str | None, typer.Option(
        "--solver", help=f"First-body backend: {', '.join(BACKENDS)}.")] = None,
    threads: Annotated[int | None, typer.Option(
        "--threads", help="ccx threads of solver = 'fe' (0 = all cores).")] = None,
    debris_every: Annotated[int | None, typer.Option(
        "--debris-every", help="Debris third body: a DE phase every K cycles.")] = None,
    no_debris: Annotated[bool, typer.Option(
        "--no-debris", help="Switch the debris third body off (overrides the config).")
    ] = False,
    quick: Annotated[bool, typer.Option("--quick", help="64^2 grid, 10 cycles.")] = False,
    resume: Annotated[bool, typer.Option(
        "--resume", help=f"Continue from OUT/{CHECKPOINT} (same config; --cycles may be "
        "raised).")] = False,
    progress: Annotated[bool, typer.Option(
        "--progress/--no-progress", help="Progress bar with ETA on stderr.")] = True,
) -> None:
    """Run the fretting wear loop; writes results.csv, summary.json, figures, VTK to --out."""
    ov = run_overrides(criterion, cycles, jump, solver, threads, debris_every, no_debris)
    summary = run(config, out, quick=quick, resume=resume, progress=progress, overrides=ov,
                  echo=typer.echo).summary
    typer.echo(
        f"done: {summary['cycles']} cycles ({summary['cycles_simulated']} simulated, "
        f"{summary['cycles_jumped']} jumped) in {summary['wall_time_s']:.1f} s; worn volume "
        f"upper {summary['wear_volume_upper_m3']:.4g} m^3, lower "
        f"{summary['wear_volume_lower_m3']:.4g} m^3; maximum wear depth upper "
        f"{summary['wear_depth_upper_m']:.4g} m, lower {summary['wear_depth_lower_m']:.4g} m"
        f" -> {out}"
    )
    plots = [f for f in summary.get("files", []) if f.endswith(".png")]
    if plots:
        typer.echo(f"plots: {', '.join(str(out / f) for f in plots)}")


@fretting_app.command("study")
@reflowed
def study_cmd(
    out: Annotated[Path, typer.Option("--out", help="Output directory.")],
    config: Annotated[Path | None, typer.Option(
        "--config", help="TOML config of the case (default: the thesis's crossed cylinders; "
        "its criterion, cycles and jumping are the study's).")] = None,
    solver: Annotated[str | None, typer.Option(
        "--solver", help=f"First-body backend: {', '.join(BACKENDS)}.")] = None,
    quick: Annotated[bool, typer.Option(
        "--quick", help="64^2 grid, 5 and 15 cycles instead of 30 and 110 (a fast check, "
        "not the thesis's numbers).")] = False,
    stages: Annotated[str | None, typer.Option(
        "--stages", help="Comma-separated stages to run (default all: von_mises,s22,dfdi,"
        "swt,shear,energy,shear_jump).")] = None,
    threads: Annotated[int | None, typer.Option(
        "--threads", help="ccx threads of solver = 'fe' (0 = all cores).")] = None,
    resume: Annotated[bool, typer.Option(
        "--resume", help="Keep the finished stages of an earlier study in --out, resume the "
        "unfinished one (its config unless given).")] = False,
    progress: Annotated[bool, typer.Option(
        "--progress/--no-progress", help="Progress bars of the runs on stderr.")] = True,
) -> None:
    """The criteria study of Lu (2018) (thesis chapter 6): every material evolution criterion
    on one case (one cycle for von Mises, S22, DFDI, SWT; 30 for shear and energy; shear
    with jumping to 110), the thesis's numbers beside ours and the criteria ordered
    (study.md, study.json).

    With --quick on the elastic half-space the DFDI stage runs on its elastic-plastic
    counterpart (DFDI needs the plastic strain), and the multi-cycle threshold stages get a
    window twice the default."""
    ov = {"fe": {"threads": threads}} if threads is not None else None
    summary = study(config, out, quick=quick, resume=resume, progress=progress,
                    solver=solver, stages=stages, overrides=ov, echo=typer.echo).summary
    typer.echo(f"done: criteria study ({summary['solver']}), ours largest first: "
               f"{', '.join(summary['ranking_ours'])} -> {out}")


@fretting_app.command("debris-study")
@reflowed
def debris_study_cmd(
    out: Annotated[Path, typer.Option("--out", help="Output directory.")],
    config: Annotated[Path | None, typer.Option(
        "--config", help="TOML config of the case (default: the energy case).")] = None,
    counts: Annotated[str | None, typer.Option(
        "--counts", help="Debris particle counts (default: the thesis's 22000,81000,102000; "
        f"--quick: {','.join(str(c) for c in QUICK_STUDY_COUNTS)}).")] = None,
    cycle: Annotated[int | None, typer.Option(
        "--cycle", help="Cycle of the study (default: config cycles, 160).")] = None,
    threads: Annotated[int, typer.Option("--threads", help="DEM threads (0 = all).")] = 0,
    quick: Annotated[bool, typer.Option("--quick", help="64^2 grid, cycle 10, counts / 20.")
                     ] = False,
    resume: Annotated[bool, typer.Option(
        "--resume", help="Skip the finished stages of an earlier study in --out (its config "
        "and counts unless given).")] = False,
    progress: Annotated[bool, typer.Option(
        "--progress/--no-progress", help="Progress bar of the wear run on stderr.")] = True,
) -> None:
    """Debris as a third body (Lu (2018), thesis section 5.4): the contact force on the lower
    body at a cycle, without and with N debris particles (thesis figs 5.22-5.27); writes
    debris_study.{csv,json}, plots, per-count data."""
    summary = debris_study(config, out, counts=counts, cycle=cycle, quick=quick,
                           resume=resume, progress=progress, threads=threads,
                           echo=typer.echo).summary
    typer.echo(f"done: debris study at cycle {summary['cycle']} "
               f"({', '.join(f'{c:,}' for c in summary['counts'])} particles) -> {out}")


@fretting_app.command("sweep")
@reflowed
def sweep_cmd(
    table: Annotated[Path, typer.Option(
        "--table", help="CSV table: a header of config fields in dotted form (contact.load, "
        "wear.criterion, cycles, ...) and an optional name column; one row per member.")],
    out: Annotated[Path, typer.Option(
        "--out", help="Output directory (a folder per member, sweep.csv, sweep.json); "
        "re-running the same sweep there skips finished members and resumes the others.")],
    config: Annotated[Path | None, typer.Option(
        "--config", help="TOML base config of every row (default: the defaults).")] = None,
    quick: Annotated[bool, typer.Option(
        "--quick", help="64^2 grid, 10 cycles (as fretting run --quick); the table's cells "
        "override it.")] = False,
    workers: Annotated[int, typer.Option(
        "--workers", min=0, max=1024, help="Worker processes of the local Dask cluster "
        "(1 thread each); 0 = all local cores. Not with --scheduler.")] = 0,
    scheduler: Annotated[str | None, typer.Option(
        "--scheduler", help="Use an existing Dask cluster: tcp://HOST:PORT of its scheduler "
        "or its scheduler JSON file; --out must be on a file system the workers share.")
    ] = None,
    progress: Annotated[bool, typer.Option(
        "--progress/--no-progress", help="Progress bar (members done / running / failed) on "
        "stderr.")] = True,
) -> None:
    """A parameter study: every row of --table is a fretting run, an independent,
    idempotent task on Dask in OUT/<name>/; writes sweep.csv and sweep.json. A failed (or
    early-stopped) member is reported and the others go on (exit 3 at the end)."""
    sweep(table, out, config=config, quick=quick, workers=workers, scheduler=scheduler,
          progress=progress, echo=typer.echo, err_echo=lambda s: typer.echo(s, err=True))
