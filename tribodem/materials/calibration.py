"""Automatic calibration of E_c and kratio against E and nu (Sha et al. (2022) section 3.1,
table 2).

The uniaxial compression test (``run_compression``, eq 12) is run on ``n_specimens``
specimens of the seed's size (0.05 x 0.1 mm, seeds ``seed .. seed + n - 1``, packed once;
each iteration re-bonds the same packings with the new micro-parameters) and the mean E
and nu are driven to the targets of table 1:

- E_c (contacts and bonds together): ``E_c <- E_c E_target / E`` (every stiffness scales
  with E_c; the eq 12 E grows a little slower, x2 E_c -> x1.7 E, because the curve
  stiffens with strain as sub-bond-gap gaps close, so this is iterated);
- kratio (contacts and bonds together): secant iteration on ``nu(log kratio)`` (nu grows
  with kratio; first slope 0.2 per unit log), steps capped at a factor 3, kratio kept in
  ``KRATIO_RANGE``.

The specimens are packed, and each iteration's compression tests run, through a mapper
(:mod:`tribodem.io.ensemble`: in this process, or one task per specimen on Dask with
``tribodem calibrate --workers/--scheduler``): the same results either way.

Stops when ``|E - E_t| / E_t <= tol`` and ``|nu - nu_t| / nu_t <= tol`` (tol 2.6%, the
largest error of the seed's table 2) or after ``max_iter`` tests. Bond strengths are not
calibrated: they only move the peak, not E or nu.

:func:`calibrate_spec` is the iteration on a :class:`MaterialSpec`; :func:`calibrate` is
``tribodem calibrate`` from Python: a material of the library by name, an output folder
with ``summary.json``, ``history.csv`` (one row per iteration, the table of its
:class:`~tribodem.io.record.RunResult`) and ``stress_strain.png``.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from tribodem.io import runs
from tribodem.io.ensemble import Mapper, one_thread_on_worker, serial_map
from tribodem.io.record import RunResult, as_out
from tribodem.materials.compression import CompressionResult, run_compression
from tribodem.materials.library import MaterialSpec
from tribodem.materials.specimen import Specimen, make_specimen

TOLERANCE = 0.026  # Sha et al. (2022) table 2: largest relative error 2.58%
KRATIO_RANGE = (0.1, 20.0)
SPECIMEN_WIDTH = 0.05e-3  # m, Sha et al. (2022) section 3.1
SPECIMEN_HEIGHT = 0.1e-3  # m


@dataclass
class CalibrationResult:
    """Calibrated micro-parameters, measured E (Pa) and nu, relative errors, history."""

    spec: MaterialSpec
    young: float
    poisson: float
    young_error: float
    poisson_error: float
    converged: bool
    iterations: int
    history: list[dict[str, float]]
    per_specimen: list[dict[str, float]]
    test: CompressionResult
    wall_time: float
    notes: list[str] = field(default_factory=list)


def _specimen_task(args: tuple[MaterialSpec, float, float, int]) -> Specimen:
    """Pack one specimen (a task: (spec, width m, height m, seed))."""
    one_thread_on_worker()
    spec, width, height, seed = args
    return make_specimen(spec, width, height, seed=seed)


def _compression_task(args: tuple[Specimen, MaterialSpec, dict[str, float]]
                      ) -> CompressionResult:
    """Re-bond one specimen with a spec and compress it (a task: (specimen, spec, keywords
    of ``run_compression``))."""
    one_thread_on_worker()
    specimen, spec, kw = args
    return run_compression(specimen.with_spec(spec), **kw)  # type: ignore[arg-type]


def measure(specimens: list[Specimen], spec: MaterialSpec,
            on_test: Callable[[], None] | None = None, map_: Mapper = serial_map,
            **kw: float) -> tuple[float, float, list[CompressionResult]]:
    """Mean E (Pa) and nu over the specimens re-bonded with ``spec`` (eq 12); ``on_test``
    is called after each specimen's test; ``map_`` runs the tests (in order of the
    specimens; :mod:`tribodem.io.ensemble`)."""
    res = map_(_compression_task, [(s, spec, kw) for s in specimens], on_test)
    return (float(np.mean([r.young for r in res])), float(np.mean([r.poisson for r in res])),
            res)


def calibrate_spec(spec: MaterialSpec, n_specimens: int = 3, seed: int = 0,
                   tol: float = TOLERANCE, max_iter: int = 12, width: float = SPECIMEN_WIDTH,
                   height: float = SPECIMEN_HEIGHT, platen_speed: float = 0.1,
                   on_test: Callable[[], None] | None = None, map_: Mapper = serial_map
                   ) -> CalibrationResult:
    """Adjust E_c and kratio of ``spec`` until E and nu are within ``tol`` of its targets.

    ``on_test``: called after every compression test (``n_specimens`` per iteration, at
    most ``max_iter`` iterations), e.g. to advance a progress bar. ``map_``: runs the
    packings and each iteration's tests (:mod:`tribodem.io.ensemble`; on Dask: one task
    per specimen)."""
    if not n_specimens >= 1:
        raise ValueError(f"calibrate: n_specimens = {n_specimens!r}: must be >= 1")
    if not 0 < tol < 1:
        raise ValueError(f"calibrate: tol = {tol!r}: must be in (0, 1)")
    if not max_iter >= 1:
        raise ValueError(f"calibrate: max_iter = {max_iter!r}: must be >= 1")
    t0 = time.perf_counter()
    specimens = map_(_specimen_task, [(spec, width, height, seed + k)
                                      for k in range(n_specimens)], None)
    cur = spec
    history: list[dict[str, float]] = []
    slope = 0.2  # d nu / d ln(kratio), first guess (measured 0.15-0.25)
    prev: tuple[float, float] | None = None
    notes: list[str] = []
    best: tuple[float, MaterialSpec, float, float, list[CompressionResult]] | None = None
    converged = False
    for it in range(1, max_iter + 1):
        young, nu, res = measure(specimens, cur, on_test, map_, platen_speed=platen_speed)
        e_err = (young - spec.young) / spec.young
        n_err = (nu - spec.poisson) / spec.poisson
        history.append({"iteration": it, "effective_modulus_Pa": cur.effective_modulus,
                        "kratio": cur.kratio, "E_Pa": young, "nu": nu,
                        "E_rel_error": e_err, "nu_rel_error": n_err})
        score = max(abs(e_err), abs(n_err))
        if best is None or score < best[0]:
            best = (score, cur, young, nu, res)
        if abs(e_err) <= tol and abs(n_err) <= tol:
            converged = True
            break
        lk = math.log(cur.kratio)
        if prev is not None and lk != prev[0] and nu != prev[1]:
            s = (nu - prev[1]) / (lk - prev[0])
            if s > 0:
                slope = s
        prev = (lk, nu)
        step = float(np.clip((spec.poisson - nu) / slope, -math.log(3.0), math.log(3.0)))
        kr = float(np.clip(cur.kratio * math.exp(step), *KRATIO_RANGE))
        if kr == cur.kratio:
            notes.append(f"kratio at its bound {kr} with nu = {nu:.3f}: the target "
                         f"{spec.poisson} is out of reach of this 2D packing")
            break
        cur = cur.with_micro(effective_modulus=cur.effective_modulus * spec.young / young,
                             kratio=kr)
    assert best is not None
    _, cur, young, nu, res = best
    if not converged:
        notes.append(f"not converged within {tol:.1%} after {len(history)} tests; best "
                     "iterate reported")
    per = [{"seed": seed + k, "particles": r.info["particles"], "E_Pa": r.young,
            "nu": r.poisson, "peak_stress_Pa": r.peak_stress} for k, r in enumerate(res)]
    return CalibrationResult(
        spec=cur, young=young, poisson=nu, young_error=(young - spec.young) / spec.young,
        poisson_error=(nu - spec.poisson) / spec.poisson, converged=converged,
        iterations=len(history), history=history, per_specimen=per, test=res[0],
        wall_time=time.perf_counter() - t0, notes=notes)


#: Specimens per iteration and most iterations: ``quick`` and full.
QUICK_SPECIMENS, FULL_SPECIMENS = 3, 8
QUICK_MAX_ITER, FULL_MAX_ITER = 8, 15
TABLE = "history.csv"

ASSUMPTIONS = (
    "2D disks of unit thickness (1 m); specimen 0.05 x 0.1 mm as Sha et al. (2022) section 3.1, "
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

#: The summary entries ``tribodem calibrate`` prints.
SHOWN = ("material", "E_Pa", "nu", "E_rel_error", "nu_rel_error", "converged", "iterations",
         "wall_time_s")


@runs.releases_folders
def calibrate(material: str, out: str | os.PathLike[str], *, quick: bool = False,
              seed: int = 0, specimens: int | None = None, workers: int | None = None,
              scheduler: str | None = None, progress: bool = False,
              echo: Callable[[str], Any] | None = None) -> RunResult:
    """Calibrate E_c and kratio of library material ``material`` (``"q345b"``, ``"cu-pm"``)
    by uniaxial compression (Sha et al. (2022) eq 12) to table 1's E and nu; writes
    ``summary.json``, ``history.csv`` and ``stress_strain.png`` to ``out``.

    ``quick``: :data:`QUICK_SPECIMENS` specimens per iteration and at most
    :data:`QUICK_MAX_ITER` iterations (else :data:`FULL_SPECIMENS`, :data:`FULL_MAX_ITER`);
    ``specimens`` overrides the count; ``seed``: the first specimen's seed. ``workers``: 1
    runs in this process, N > 1 on a local Dask cluster of N single-thread workers, 0 on
    one with a worker per core (the command's default); None (the default here): in this
    process, or on ``scheduler``, an existing Dask cluster (its address or scheduler
    file). The results are the same, bitwise, wherever they run. ``progress``: a bar of
    the compression tests on stderr; ``echo``: called with the printed summary (JSON text)
    at the end.

    Everything is checked before any work (``ConfigError``). Returns the folder, the summary
    and the table ``history.csv``.
    """
    import json
    from contextlib import nullcontext

    from tribodem.io.config import ConfigError
    from tribodem.io.ensemble import check_cluster_options, task_map
    from tribodem.io.results import write_csv, write_json
    from tribodem.materials.compression import plot_stress_strain
    from tribodem.materials.library import LIBRARY

    key = str(material).strip().lower()
    if key not in LIBRARY:
        raise ConfigError(f"calibrate: --material = {material!r}: must be one of "
                          f"{sorted(LIBRARY)}")
    if specimens is not None and not 1 <= specimens <= 10000:
        raise ConfigError(f"calibrate: --specimens = {specimens!r}: allowed: 1..10000")
    if seed < 0:
        raise ConfigError(f"calibrate: --seed = {seed!r}: allowed: >= 0")
    if workers is None:
        workers = 0 if scheduler is not None else 1
    if not 0 <= workers <= 1024:
        raise ConfigError(f"calibrate: --workers = {workers!r}: allowed: 0..1024 (0 = a "
                          "worker per core, 1 = in this process)")
    spec = LIBRARY[key]
    check_cluster_options("calibrate", workers, scheduler,
                          in_process=scheduler is None and workers == 1,
                          alternative="--workers 1 to run in this process")
    path = as_out(out)
    runs.check_out_dir(path, "--out")
    runs.announce(path)
    n = specimens if specimens is not None else (QUICK_SPECIMENS if quick else FULL_SPECIMENS)
    local = scheduler is None and workers == 1
    max_iter = QUICK_MAX_ITER if quick else FULL_MAX_ITER
    # one step per compression test; the total is the most the calibration may need
    # (n specimens x max_iter iterations): it usually converges earlier
    with (runs.progress(n * max_iter, "test", f"calibrate {key}", enabled=progress) as bar,
          nullcontext(serial_map) if local else task_map(scheduler, workers) as map_):
        res = calibrate_spec(spec, n_specimens=n, seed=seed, max_iter=max_iter,
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
    path.mkdir(parents=True, exist_ok=True)
    write_json(path / "summary.json", summary)
    cols = list(res.history[0])
    write_csv(path / TABLE, cols, [[h[c] for c in cols] for h in res.history])
    plot_stress_strain(res.test, path / "stress_strain.png",
                       title=f"{spec.name}: uniaxial compression, specimen seed {seed} "
                             "(calibrated)")
    if echo is not None:
        echo(json.dumps({k: summary[k] for k in SHOWN}, indent=2))
    return RunResult(out=path, summary=summary, table=TABLE,
                     files=["summary.json", TABLE, "stress_strain.png"])
