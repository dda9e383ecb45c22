"""CLI of the materials room: ``tribodem calibrate`` (Sha et al. (2022) section 3.1, tables 1-3).

Option parsing only: the calibration run is :func:`tribodem.materials.calibration.calibrate`.
"""

from __future__ import annotations

from pathlib import Path

import typer

from tribodem.io.helptext import reflowed
from tribodem.materials.calibration import FULL_SPECIMENS, QUICK_SPECIMENS


@reflowed
def calibrate(
    material: str = typer.Option(..., "--material", help="q345b (disc) or cu-pm (pad)."),
    out: Path = typer.Option(..., "--out", help="Output directory."),
    quick: bool = typer.Option(False, "--quick",
                               help=f"{QUICK_SPECIMENS} specimens instead of {FULL_SPECIMENS}."),
    seed: int = typer.Option(0, "--seed", min=0, help="First specimen seed."),
    specimens: int | None = typer.Option(
        None, "--specimens", min=1, max=10000,
        help=f"Specimens (packings) per iteration; default {FULL_SPECIMENS} "
             f"({QUICK_SPECIMENS} with --quick)."),
    workers: int = typer.Option(
        0, "--workers", min=0, max=1024,
        help="Worker processes of a local Dask cluster (1 thread each), one specimen per "
             "task; 0 = all local cores; 1 = in this process, no cluster. Not with "
             "--scheduler."),
    scheduler: str | None = typer.Option(
        None, "--scheduler", help="Use an existing Dask cluster: tcp://HOST:PORT of its "
        "scheduler or its scheduler JSON file."),
    progress: bool = typer.Option(True, "--progress/--no-progress",
                                  help="Progress bar (compression tests) with ETA on stderr."),
) -> None:
    """Calibrate the bond micro-parameters E_c and kratio so that uniaxial compression of
    packed specimens gives the material's E and nu (Sha et al. (2022), table 1): writes
    summary.json, history.csv and stress_strain.png.

    E and nu of a test are Sha et al. (2022)'s eq 12: the slopes of the axial stress and of the
    lateral strain against the axial strain, fitted between 10 % and 50 % of the peak
    stress. Each iteration's compression tests run one task per specimen on Dask (the same
    results on any number of workers; --workers 1 runs them in this process, without
    Dask)."""
    from tribodem.materials.calibration import calibrate as run_calibration

    run_calibration(material, out, quick=quick, seed=seed, specimens=specimens,
                    workers=workers, scheduler=scheduler, progress=progress, echo=typer.echo)
