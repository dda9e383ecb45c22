"""CLI of the engine room: ``tribodem dem run`` (the demo scenario) and ``tribodem bench dem``.

Option parsing only: the run is :func:`tribodem.dem.demo.run`, the benchmark
:func:`tribodem.dem.bench.benchmark`.
"""

from __future__ import annotations

import json
from pathlib import Path

import typer

from tribodem.io.helptext import reflowed

dem_app = typer.Typer(help="Run the DEM engine on its own (demo scenarios).",
                      no_args_is_help=True)
bench_app = typer.Typer(help="Measure performance.", no_args_is_help=True)


@dem_app.command("run")
@reflowed
def dem_run(
    out: Path = typer.Option(..., "--out", help="Output directory."),
    config: Path | None = typer.Option(None, "--config", help="TOML config file."),
    quick: bool = typer.Option(False, "--quick", help="Small, fast variant."),
    resume: bool = typer.Option(False, "--resume", help="Continue from OUT/checkpoint.npz."),
    progress: bool = typer.Option(True, "--progress/--no-progress",
                                  help="Progress bar with ETA on stderr."),
) -> None:
    """Settle spheres in a box (or compress disks): writes timeseries.csv, vtk/, summary.json."""
    from tribodem.dem.demo import run

    run(config, out, quick=quick, resume=resume, progress=progress, echo=typer.echo)


@bench_app.command("dem")
@reflowed
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
    from tribodem.dem.bench import benchmark, describe

    res = benchmark(case, quick=quick, particles=particles, steps=steps, threads=threads)
    typer.echo(json.dumps(res) if as_json else describe(res))
