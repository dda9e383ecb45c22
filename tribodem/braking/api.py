"""The braking room as a library: :func:`run` (what ``tribodem braking run`` does) and
:func:`sweep` (what ``tribodem braking sweep`` does), each returning a
:class:`~tribodem.io.record.RunResult`.

Both follow the run-record protocol of :mod:`tribodem.io.record`: the config (a
:class:`~tribodem.braking.config.BrakingConfig`, a dict shaped like the TOML file, the
path of a TOML file, or None) is resolved as defaults <- config <- quick preset <- the
condition; everything is checked before any work (``ConfigError``); the folder holds the
resolved ``config.toml``, the checkpoint and the results.

Life of a run: ``<out>/checkpoint.npz`` is written after the first sample, every
``run.checkpoint_every`` samples (default: about every 10% of the run) and at the end;
``resume`` continues from it (its own config.toml, or a config/condition that must resolve
to the checkpoint's config except ``run.threads``, ``run.checkpoint_every``,
``run.figures``; anything else: ``ConfigError``, nothing touched) to bitwise the results of
an uninterrupted run; resuming a finished run only reports it. Without ``resume`` a run in
``out`` is replaced. An instability raises ``RunStopped`` after writing the rows so far and
a summary with ``status = "stopped"``.

A sweep runs each (condition, packing) member as an independent task on Dask
(:mod:`tribodem.braking.ensemble` on :mod:`tribodem.io.ensemble`: a local cluster of
one-thread worker processes, or ``scheduler``), each in its own folder; re-running the
same sweep skips members whose summary.json is finished with the same config, resumes the
others from their checkpoints and starts over those whose config changed. A failed member
is reported (comparison.md, ``echo``) and the comparison covers the others (then
``RunStopped``).

``echo``: where messages go, called as ``echo(text)`` for the report and ``echo(text,
err=True)`` for warnings and failures (``typer.echo`` / ``click.echo``); None: nowhere.
"""

from __future__ import annotations

import json
import os
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from tribodem.braking.checkpoint import CHECKPOINT, finished_summary, read_checkpoint
from tribodem.braking.compare import write_comparison
from tribodem.braking.conditions import CONDITIONS
from tribodem.braking.config import (
    BrakingConfig,
    check_same_config,
    checkpoint_config,
    resolve_config,
    setup_from_config,
)
from tribodem.braking.ensemble import plan_members, sweep_members
from tribodem.braking.simulate import run_in_folder
from tribodem.io import runs
from tribodem.io.config import ConfigError, load_toml
from tribodem.io.ensemble import Member, check_cluster_options, run_members
from tribodem.io.record import ConfigSource, RunResult, Source, as_out
from tribodem.io.results import write_csv
from tribodem.io.runs import RunStopped

#: ``echo(text)`` / ``echo(text, err=True)``: where a function's messages go
Echo = Callable[..., Any]
#: the summary entries of each member in a sweep's ``members.csv``
MEMBER_COLUMNS = (
    "status", "load_kN", "pressure_Pa", "speed_rpm", "sliding_speed_m_s",
    "simulated_time_s", "simulated_sliding_distance_m", "wear_depth_mean_m",
    "wear_depth_max_m", "wear_depth_mean_disc_m", "wear_rate_steady_m_per_m",
    "steady_reached", "contact_fraction", "contact_fraction_after_run_in", "broken_bonds",
    "broken_bonds_tensile", "broken_bonds_shear", "debris_particles",
    "force_chains", "strong_force_chains", "mean_wall_pressure_ratio", "particles_initial",
    "particles_final")


class _Teller:
    """``tell(text, err=False)``: a message through ``echo`` (nothing when None); ``err``:
    a warning or failure (``echo(text, err=True)``)."""

    def __init__(self, echo: Echo | None) -> None:
        self.echo = echo

    def __call__(self, text: str, err: bool = False) -> None:
        if self.echo is None:
            return
        if err:
            self.echo(text, err=True)
        else:
            self.echo(text)


def _listing(out: Path) -> list[str]:
    """The run's files named for a :class:`RunResult`: the folder's own files and the VTK
    indexes, relative to ``out``, sorted."""
    files = [p for p in out.glob("*") if p.is_file()] + list(out.glob("vtk/*.pvd"))
    return sorted(str(p.relative_to(out)) for p in files if not p.name.startswith("."))


def _resumed_config(config: ConfigSource, out: Path, condition: int | None, quick: bool
                    ) -> tuple[BrakingConfig, dict[str, Any]]:
    """(config, checkpoint record) of a resume in ``out``: its own config.toml (or its
    checkpoint's config) unless ``config`` is given, with ``quick`` and ``condition``
    laid over; ``ConfigError`` (nothing touched) when the folder cannot be resumed or
    the config differs from the checkpoint's."""
    ck = out / CHECKPOINT
    runs.check_out_dir(out, "--out", resume=True, need=(CHECKPOINT,))
    rec = read_checkpoint(ck)
    old = checkpoint_config(rec, ck)
    own = out / "config.toml"
    base = load_toml(own) if own.is_file() else old
    if config is None and base is None:
        raise ConfigError(f"--resume: '{out}' has no config.toml and the checkpoint no "
                          "config; give the run's --config")
    recorded = Source(dict(base or {}), str(own) if own.is_file() else f"checkpoint '{ck}'")
    cfg = resolve_config(config if config is not None else recorded, condition=condition,
                         quick=quick)
    setup_from_config(cfg)
    check_same_config(cfg, old, ck)
    return cfg, rec


@runs.releases_folders
def run(config: ConfigSource = None, out: str | os.PathLike[str] | None = None, *,
        condition: int | None = None, quick: bool = False, resume: bool = False,
        progress: bool = False, echo: Echo | None = None) -> RunResult:
    """One braking-interface run in folder ``out`` (str or path), as ``tribodem braking
    run``: ``summary.json``, ``timeseries.csv`` (the result's table, one row per sample),
    PNG figures, ``vtk/`` snapshots, ``config.toml`` and ``checkpoint.npz``.

    ``config``: a :class:`BrakingConfig`, a dict shaped like the TOML file, a TOML file's
    path, or None; ``condition``: table 4 condition 1..5 (over the config); ``quick``: the
    small preset (:meth:`BrakingConfig.quick`, over the config); ``resume``: continue the
    run in ``out`` from its checkpoint (a finished run is only reported); ``progress``: a
    bar on stderr. ``ConfigError`` before any work for a bad input; ``RunStopped`` for a
    run that stopped early (outputs kept)."""
    tell = _Teller(echo)
    if condition is not None and condition not in CONDITIONS:
        raise ConfigError(f"braking run: --condition = {condition!r}: must be one of "
                          f"{sorted(CONDITIONS)} (Sha et al. (2022) table 4)")
    if condition is None and config is None and not resume:
        raise ConfigError("braking run: give --condition 1..5 or --config FILE")
    if out is None:
        raise ConfigError("braking run: --out = None: allowed: a folder path (str or Path)")
    folder = as_out(out)
    ck = folder / CHECKPOINT
    rec: dict[str, Any] = {}
    if resume:  # everything checked before any output is touched
        cfg, rec = _resumed_config(config, folder, condition, quick)
    else:
        cfg = resolve_config(config, condition=condition, quick=quick)
        setup_from_config(cfg)  # refuse a bad condition before any work
        runs.check_out_dir(folder, "--out")
    runs.check_threads(cfg.run.threads, "run.threads")
    if resume and rec.get("finished"):  # only reported: the folder is not touched
        done = finished_summary(folder)
        if done is not None:
            tell(f"braking run: '{folder}' is already finished ({rec['done']} steps); "
                 "nothing to do", err=True)
            return RunResult(folder, done, table="timeseries.csv", files=_listing(folder))
    runs.announce(folder, ck, resume_hint="add --resume to the same command")
    summary = run_in_folder(cfg.model_dump(), str(folder), cfg.run.threads, resume=resume,
                            progress=progress)
    return RunResult(folder, summary, table="timeseries.csv", files=_listing(folder))


def _check_conditions(conditions: Sequence[int] | None) -> list[int]:
    """The sweep's conditions, sorted (None: all of table 4); ``ConfigError`` naming them
    unless distinct conditions of table 4."""
    if conditions is None:
        return sorted(CONDITIONS)
    conds = list(conditions)
    if not conds or len(set(conds)) < len(conds) or not all(
            isinstance(k, int) and k in CONDITIONS for k in conds):
        raise ConfigError(f"braking sweep: --conditions = {conditions!r}: allowed: distinct "
                          f"conditions of {sorted(CONDITIONS)} (Sha et al. (2022) table 4), e.g. "
                          "[1, 3, 5]")
    return sorted(conds)


def _write_members(out: Path, members: list[Member],
                   results: dict[Any, dict[str, Any]], failed: dict[Any, str]) -> None:
    """``members.csv``: one row per member (condition, packing, folder, then the summary
    entries of ``MEMBER_COLUMNS``; a failed member: status ``failed``, the rest empty)."""
    rows = []
    for m in members:
        s = results.get(m.key)
        if s is None:
            vals = ["failed" if m.key in failed else "not run"] + [""] * (len(MEMBER_COLUMNS) - 1)
        else:
            vals = [s.get(k, "") for k in MEMBER_COLUMNS]
        rows.append([m.info["condition"], m.info["packing"], str(m.folder.relative_to(out)),
                     *vals])
    write_csv(out / "members.csv", ["condition", "packing", "folder", *MEMBER_COLUMNS], rows)


def _run_todo(todo: list[Member], total: int, done: int, *, scheduler: str | None,
              workers: int, progress: bool, tell: Callable[..., None]
              ) -> tuple[dict[Any, dict[str, Any]], dict[Any, str], str]:
    """The members ``todo`` on Dask (:func:`tribodem.io.ensemble.run_members`): (summaries,
    failures by key, where they ran); a stop (Ctrl-C, an error) says what a re-run does."""
    if not todo:
        return {}, {}, "nothing to run"
    try:
        return run_members(todo, total, done, scheduler=scheduler, workers=workers,
                           progress=progress, echo=lambda s: tell(s, err=True),
                           desc="braking sweep")
    except BaseException:
        tell("\nsweep stopped: finished members are kept; run the same command again to "
             "skip them and resume the others from their checkpoints", err=True)
        raise


@runs.releases_folders
def sweep(out: str | os.PathLike[str], *, config: ConfigSource = None, quick: bool = False,
          packings: int = 1, conditions: Sequence[int] | None = None, workers: int = 0,
          scheduler: str | None = None, progress: bool = False, echo: Echo | None = None
          ) -> RunResult:
    """Conditions 1-5 (or ``conditions``) x ``packings`` on Dask in folder ``out``, as
    ``tribodem braking sweep``: each member in ``condition_k`` (``condition_k/seed_s``
    with several packings), then ``comparison.md``, ``comparison.json``,
    ``comparison.csv`` (ours with paired 95% intervals beside the seed's) and
    ``members.csv`` (the result's table: one row per member).

    ``config``: as for :func:`run` (its condition ignored); ``packings``: packing and
    roughness realisations per condition (geometry seeds seed, seed+1, ...); ``workers``:
    processes of a local cluster (0: all local cores), or ``scheduler``: an existing
    cluster (tcp://HOST:PORT or a scheduler file); ``progress``: a bar on stderr. The
    result's summary: what ran, was skipped and failed, where, in how many seconds, the
    printed wear changes and comparison.json. A failed member: ``RunStopped`` after the
    comparison of the others."""
    tell = _Teller(echo)
    folder = as_out(out)
    if not (isinstance(packings, int) and 1 <= packings <= 1000):
        raise ConfigError(f"braking sweep: --packings = {packings!r}: allowed: 1..1000")
    if not (isinstance(workers, int) and 0 <= workers <= 1024):
        raise ConfigError(f"braking sweep: --workers = {workers!r}: allowed: 0..1024 (0 = "
                          "all local cores)")
    check_cluster_options("braking sweep", workers, scheduler)
    conds = _check_conditions(conditions)
    base = resolve_config(config, quick=quick).model_dump()
    base["condition"] = {}
    t0 = time.perf_counter()
    members = sweep_members(base, packings, folder, conds)
    runs.check_out_dir(folder, "--out")  # every member checked first: no folder for a bad one
    runs.announce(folder)
    results, todo = plan_members(members, folder, tell)
    done, failed, where = _run_todo(todo, len(members), len(results), scheduler=scheduler,
                                    workers=workers, progress=progress, tell=tell)
    results.update(done)
    wall = time.perf_counter() - t0
    return _report(folder, members, results, failed, todo, conds, packings, wall, where,
                   quick, tell)


def _report(out: Path, members: list[Member], results: dict[Any, dict[str, Any]],
            failed: dict[Any, str], todo: list[Member], conds: list[int], packings: int,
            wall: float, where: str, quick: bool, tell: Callable[..., None]) -> RunResult:
    """The sweep's comparison and members.csv written, its report told, its result (or
    ``RunStopped`` naming the first failed member)."""
    runs_by_k: dict[int, list[tuple[dict[str, Any], Path]]] = {}
    for m in members:
        if m.key in results:
            runs_by_k.setdefault(m.info["condition"], []).append((results[m.key], m.folder))
    fails = {f"condition {k} packing {s}": msg for (k, s), msg in sorted(failed.items())}
    rows = write_comparison(out, runs_by_k, wall, where, quick, failed=fails) \
        if runs_by_k else []
    _write_members(out, members, results, failed)
    skipped = len(members) - len(todo)
    tell(f"sweep: condition(s) {','.join(map(str, conds))} x {packings} packing(s) "
         f"in {wall:.1f} s on {where} "
         f"({len(todo)} run, {skipped} skipped as finished, {len(failed)} failed) "
         f"-> {out / 'comparison.md'}")
    for r in rows:
        tell(f"  {r[0]}: ours {r[1]}, seed {r[2]}")
    if failed:
        first = next(iter(fails.items()))
        raise RunStopped(f"{len(failed)} of {len(members)} sweep members failed (first: "
                         f"{first[0]}: {first[1]}); the comparison covers the others")
    comparison = json.loads((out / "comparison.json").read_text()) if runs_by_k else None
    summary = {"conditions": conds, "packings": packings, "members": len(members),
               "ran": len(todo), "skipped": skipped, "failed": fails, "cluster": where,
               "wall_time_s": wall,
               "wear_changes": [{"change": a, "ours": b, "seed": c} for a, b, c in rows],
               "comparison": comparison}
    return RunResult(out, summary, table="members.csv", files=_listing(out))
