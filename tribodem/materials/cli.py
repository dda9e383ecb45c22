"""CLI of the materials room: ``tribodem calibrate`` (seed 000 section 3.1, tables 1-3)."""

from __future__ import annotations

import json
from pathlib import Path

import typer

from tribodem.io.config import ConfigError
from tribodem.io.results import write_csv, write_json

QUICK_SPECIMENS, FULL_SPECIMENS = 3, 8
QUICK_MAX_ITER, FULL_MAX_ITER = 8, 15

ASSUMPTIONS = (
    "2D disks of unit thickness (1 m); specimen 0.05 x 0.1 mm as seed 000 section 3.1, "
    "radii uniform in [3.27, 3.93] um (mean 3.6 um, ratio 1.2) then scaled by ~0.98 to set "
    "the 1 MPa isotropic compaction stress (radius expansion in fixed walls, frictionless, "
    "mass-scaled); floating particles (< 3 contacts, walls included) deleted; parallel bonds "
    "by gap < 5e-9 m, lambda 1, bond modulus = E_c, bond kratio = kratio; stress release "
    "without walls (local damping 0.7). Compression: frictionless platens at 0.1 m/s each "
    "(seed speed; strain rate 2000 1/s, quasi-static at this size), local damping 0.1, stop "
    "below 70% of the peak; strains from boundary-particle gauges; eq 12 as least-squares "
    "slopes over 10-50% of the peak stress. E and nu are means over N specimens (seeds "
    "seed..seed+N-1, the same packings re-bonded every iteration); E_c scaled by "
    "E_target/E, kratio (contacts and bonds) by a secant on nu(ln kratio). Bond strengths "
    "(table 3) are not calibrated: they move the peak only.")


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
    """Calibrate E_c and kratio by uniaxial compression (seed 000 eq 12) to table 1's E, nu:
    writes summary.json, history.csv and stress_strain.png.

    The specimens are packed and each iteration's compression tests run one task per
    specimen on Dask (the same results on any number of workers)."""
    from contextlib import nullcontext

    from tribodem.io import runs
    from tribodem.io.ensemble import check_cluster_options, serial_map, task_map
    from tribodem.materials.calibrate import TOLERANCE
    from tribodem.materials.calibrate import calibrate as run_calibration
    from tribodem.materials.compression import plot_stress_strain
    from tribodem.materials.library import LIBRARY

    key = material.strip().lower()
    if key not in LIBRARY:
        raise ConfigError(f"calibrate: --material = {material!r}: must be one of "
                          f"{sorted(LIBRARY)}")
    spec = LIBRARY[key]
    check_cluster_options("calibrate", workers, scheduler)
    runs.check_out_dir(out, "--out")
    runs.announce(out)
    n = specimens if specimens is not None else (QUICK_SPECIMENS if quick else FULL_SPECIMENS)
    local = scheduler is None and workers == 1
    max_iter = QUICK_MAX_ITER if quick else FULL_MAX_ITER
    # one step per compression test; the total is the most the calibration may need
    # (n specimens x max_iter iterations): it usually converges earlier
    with (runs.progress(n * max_iter, "test", f"calibrate {key}", enabled=progress) as bar,
          nullcontext(serial_map) if local else task_map(scheduler, workers) as map_):
        res = run_calibration(spec, n_specimens=n, seed=seed, max_iter=max_iter,
                              on_test=lambda: bar.update(1), map_=map_)
        if hasattr(bar, "refresh"):  # converged early: end the bar where it is
            bar.total = bar.n
            bar.refresh()
    es = [p["E_Pa"] for p in res.per_specimen]
    ns = [p["nu"] for p in res.per_specimen]
    summary = {
        "material": spec.name, "quick": quick, "seed": seed, "specimens": n,
        "ran_on": ("this process" if local else scheduler or
                   f"local Dask cluster, {workers or 'all'} worker(s)"),
        "E_Pa": res.young, "nu": res.poisson, "E_target_Pa": spec.young,
        "nu_target": spec.poisson, "E_rel_error": res.young_error,
        "nu_rel_error": res.poisson_error, "tolerance": TOLERANCE,
        "converged": res.converged, "iterations": res.iterations,
        "wall_time_s": res.wall_time,
        "calibrated_micro_parameters": res.spec.micro_dict(),
        "seed_table3_micro_parameters": spec.micro_dict(),
        "per_specimen": res.per_specimen,
        "E_specimen_spread_Pa": [min(es), max(es)], "nu_specimen_spread": [min(ns), max(ns)],
        "peak_stress_Pa_specimen0": res.test.peak_stress,
        "history": res.history, "notes": res.notes, "assumptions": ASSUMPTIONS,
    }
    write_json(out / "summary.json", summary)
    cols = list(res.history[0])
    write_csv(out / "history.csv", cols, [[h[c] for c in cols] for h in res.history])
    plot_stress_strain(res.test, out / "stress_strain.png",
                       title=f"{spec.name}: uniaxial compression, specimen seed {seed} "
                             "(calibrated)")
    typer.echo(json.dumps({k: summary[k] for k in (
        "material", "E_Pa", "nu", "E_rel_error", "nu_rel_error", "converged", "iterations",
        "wall_time_s")}, indent=2))
