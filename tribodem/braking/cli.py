"""``tribodem braking run`` and ``tribodem braking sweep`` (seed 000 sections 3.2-5, table 4).

Configuration: defaults < ``--config`` file < ``--quick`` preset < ``--condition``. The
resolved config is written to ``<out>/config.toml`` and reloads to the same config.

Life of a run (``tribodem.io.runs`` vocabulary): the inputs and ``--out`` are checked before
any work (exit 2); ``<out>/checkpoint.npz`` is written after the first sample, every
``run.checkpoint_every`` samples (default: about every 10% of the run) and at the end;
``--resume`` continues from it (its own config.toml, or a ``--config``/``--condition``
that must resolve to the checkpoint's config except ``run.threads``,
``run.checkpoint_every``, ``run.figures``; anything else: exit 2, nothing touched) to
bitwise the results of an uninterrupted run; resuming a finished run only reports it.
Without ``--resume`` a run in ``--out`` is replaced. Ctrl-C exits 130 naming the outputs
and the checkpoint; an instability exits 3 after writing the rows so far and a summary with
``status = "stopped"``.

A sweep runs each (condition, packing) member as an independent task on Dask
(``tribodem.braking.ensemble`` on ``tribodem.io.ensemble``: a local cluster of one-thread
worker processes, or ``--scheduler``), each in its own folder; re-running the same sweep
skips members whose summary.json is finished with the same config, resumes the others from
their checkpoints and starts over those whose config changed. Ctrl-C stops the members,
closes the cluster and exits 130; a failed member is reported (comparison.md, stderr) and
the comparison covers the others (exit 3).
"""

from __future__ import annotations

import json
import time
from pathlib import Path
from typing import Any, Literal

import typer
from pydantic import BaseModel, ConfigDict, Field, model_validator

from tribodem.io.config import (
    ConfigError,
    dump_toml,
    load_toml,
    merge,
    parse_int_list,
    validate,
)
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
    roughness_first_mode: int = Field(
        1, ge=1, le=64, description="lowest sine mode k (wavelength width/k); in a cell n "
        "times the default width, n keeps the default cell's wavelengths and asperities")
    clearance_m: float = Field(5e-8, ge=0)
    seed: int = Field(0, ge=0)


class RunCfg(_Strict):
    """Simulated sliding time (s), sampling, numerics."""

    duration_s: float = Field(40e-6, gt=0, le=1e-2)
    distance_m: float = Field(
        0.0, ge=0, le=0.1,
        description="slide this distance (m) instead of duration_s: duration = distance / "
                    "sliding speed, so the conditions of a sweep are compared at the same "
                    "distance (the closed cell's saturated wear depth, docs/braking.md); 0 = "
                    "off; not with duration_s in the same file")
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
    until_steady: bool = Field(
        False, description="slide past duration_s until the wear rate per sliding distance "
                           "is steady (last third within steady_tolerance of the middle "
                           "third), in blocks of 20% of duration_s, at most max_distance_m")
    max_distance_m: float = Field(0.0, ge=0, le=1.0,
                                  description="cap on the sliding distance (m) with "
                                              "until_steady; 0 = 5 x speed x duration_s")
    steady_tolerance: float = Field(0.15, gt=0, le=1)
    ramp_s: float = Field(0.0, ge=0, le=1e-2,
                          description="load ramped linearly from 0 over this sliding time "
                                      "(s); 0 = the full load at once")
    speed_ramp_s: float = Field(0.0, ge=0, le=1e-2,
                                description="the disc starts at rest under the loaded pad "
                                            "and reaches the speed linearly over this "
                                            "time (s); 0 = at speed from the start")
    outlet_length_m: float = Field(
        0.0, ge=0, le=0.1,
        description="debris outlet: a debris component leaves the cell once carried this "
                    "far (m) along the sliding relative to the pad (residence length, e.g. "
                    "a pad plateau, 50-500 um); 0 = closed cell, as in seed 000")
    worn_through_diameters: float = Field(
        2.0, ge=0, le=1000,
        description="stop the run (exit 3, outputs kept) when a body's remaining intact "
                    "thickness outside its anchored layer falls below this many of its "
                    "mean particle diameters (worn through: the boundary layer meets the "
                    "interface); 0 = never stop")
    feed: bool = Field(
        False, description="add a slab of fresh body behind a body's anchored layer "
                           "whenever one slab's thickness has been worn (3 mean particle "
                           "diameters), so slides can be longer than the bodies are thick "
                           "(with outlet_length_m); the bodies are then cut from a block "
                           "periodic in y (docs/braking.md 'Feed')")
    checkpoint_every: int = Field(
        0, ge=0, le=100_000,
        description="samples between checkpoints (checkpoint.npz in the output folder); "
                    "0 = ceil(samples / 10), about every 10% of the run")


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


#: the ``--quick`` preset: a narrower cell and a thinner disc than the defaults, 20 us. Its
#: pad has the default height: a 50-um pad shattered under the first impacts at conditions
#: 1-4 (worn through within 0.06-0.55 mm, docs/braking.md "Bodies worn through")
QUICK: dict[str, Any] = {
    "geometry": {"width_m": 144e-6, "disc_height_m": 50e-6, "pad_height_m": 108e-6,
                 "roughness_amplitude_m": 6e-6, "roughness_modes": 3},
    "run": {"duration_s": 20e-6, "distance_m": 0.0, "samples": 100, "vtk_snapshots": 4},
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
                   first_mode=g.roughness_first_mode, clearance=g.clearance_m, seed=g.seed)
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
    if r.feed and curve is not None:
        raise ConfigError(f"braking: run.feed = true with thermal.curve = '{curve}': the "
                          "feed does not carry temperatures; allowed: one of the two")
    duration = r.distance_m / v if r.distance_m else r.duration_s
    return RunSetup(pressure_Pa=p, speed_m_s=v, duration_s=duration, geometry=geo,
                    condition=None if explicit else c.index, micro=r.micro, samples=r.samples,
                    vtk_snapshots=r.vtk_snapshots, wall_mass_ratio=r.wall_mass_ratio,
                    plate_areal_mass=r.plate_areal_mass_kg_m2 or None, backing=r.backing,
                    local_damping=r.local_damping, dt_safety=r.dt_safety,
                    thermal_curve=curve, thermal_time_map=cfg.thermal.time_map,
                    figures=r.figures, checkpoint_every=r.checkpoint_every,
                    until_steady=r.until_steady, max_distance_m=r.max_distance_m,
                    steady_tolerance=r.steady_tolerance, ramp_s=r.ramp_s,
                    speed_ramp_s=r.speed_ramp_s, outlet_length_m=r.outlet_length_m,
                    worn_through_diameters=r.worn_through_diameters, feed=r.feed)


#: config fields a resumed run may change (they do not change the results)
RESUME_FREE = ("run.threads", "run.checkpoint_every", "run.figures")
#: what ``braking run`` prints of the summary
_SHOWN = ("status", "condition", "pressure_Pa", "sliding_speed_m_s", "simulated_time_s",
          "simulated_sliding_distance_m", "wear_depth_mean_m", "wear_depth_max_m",
          "broken_bonds", "debris_particles", "force_chains", "particles_initial",
          "particles_final", "mean_wall_pressure_ratio", "wear_rate_steady_m_per_m",
          "steady_reached", "run_in_distance_m", "run_in_depth_m", "contact_fraction",
          "wall_time_s")


def _config(condition: int | None, config: Path | None, quick: bool,
            base: dict[str, Any] | None = None, source: str = "braking") -> BrakingConfig:
    """Defaults <- config file (or ``base``: a resumed run's own config) <- ``--quick``
    preset <- ``--condition``."""
    if config is not None:
        data, source = load_toml(config), str(config)
        run = data.get("run", {}) if isinstance(data.get("run"), dict) else {}
        if "duration_s" in run and run.get("distance_m"):
            raise ConfigError(f"{source}: field 'run.duration_s' = {run['duration_s']!r} and "
                              f"'run.distance_m' = {run['distance_m']!r}: give one run length "
                              "(distance_m replaces duration_s)")
    else:
        data = base or {}
    if quick:
        data = merge(data, QUICK) if (config is not None or base) else merge(QUICK, data)
    if condition is not None:
        data = merge(data, {"condition": {"index": condition}})
    return validate(BrakingConfig, data, source=source)


def config_differences(old: dict[str, Any], new: dict[str, Any]) -> list[tuple[str, Any, Any]]:
    """(field, old, new) of the resolved configs that differ, ``RESUME_FREE`` left out."""
    from tribodem.braking.run import differences

    return [d for d in differences(old, new) if d[0] not in RESUME_FREE]


def _checkpoint_config(rec: dict[str, Any], path: Path) -> dict[str, Any] | None:
    """The resolved config a checkpoint's run was made with (None when it has none)."""
    if rec.get("config") is None:
        return None
    return validate(BrakingConfig, rec["config"], source=f"checkpoint '{path}'").model_dump()


def _check_same(cfg: BrakingConfig, old: dict[str, Any] | None, path: Path) -> None:
    if old is None:
        return
    diff = config_differences(old, cfg.model_dump())
    if diff:
        name, a, b = diff[0]
        more = f" (and {len(diff) - 1} more)" if len(diff) > 1 else ""
        raise ConfigError(
            f"--resume: {name} = {b!r} differs from the checkpointed run's {a!r}{more} "
            f"('{path}'); allowed: the same value (only {', '.join(RESUME_FREE)} may change)")


def _finished_summary(out: Path) -> dict[str, Any] | None:
    """The run's summary.json when it is complete (``status`` finished), else None."""
    try:
        s = json.loads((out / "summary.json").read_text())
    except (OSError, ValueError):
        return None
    return s if isinstance(s, dict) and s.get("status") == "finished" else None


def _run_one(cfg_data: dict[str, Any], out: str, threads: int, resume: bool = False,
             progress: bool = False, should_stop: Any = None) -> dict[str, Any]:
    """One run in ``out`` (the ``braking run`` command and each sweep worker): writes the
    resolved config.toml, then runs (``resume``: from ``out/checkpoint.npz``)."""
    import numba

    from tribodem.braking.run import CHECKPOINT, run_braking

    if threads:
        numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
    cfg = validate(BrakingConfig, cfg_data, source="sweep")
    setup = setup_from_config(cfg)
    o = Path(out)
    o.mkdir(parents=True, exist_ok=True)
    if not resume:  # a new run replaces an earlier one: never leave its results as ours
        for name in ("summary.json", CHECKPOINT):
            (o / name).unlink(missing_ok=True)
    text = dump_toml(cfg.model_dump())
    own = o / "config.toml"
    if not (own.is_file() and own.read_text() == text):  # a resume leaves it untouched
        write_text(own, text)
    return run_braking(setup, o, resume=resume, progress=progress, config=cfg.model_dump(),
                       should_stop=should_stop)


@braking_app.command("run")
def braking_run(
    out: Path = typer.Option(..., "--out", help="Output directory (an earlier run there is "
                             "replaced unless --resume)."),
    condition: int | None = typer.Option(None, "--condition", help="Table 4 condition 1..5."),
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
    from tribodem.braking.conditions import CONDITIONS
    from tribodem.braking.run import CHECKPOINT, read_checkpoint
    from tribodem.io import runs

    if condition is not None and condition not in CONDITIONS:
        raise ConfigError(f"braking run: --condition = {condition!r}: must be one of "
                          f"{sorted(CONDITIONS)} (seed 000 table 4)")
    if condition is None and config is None and not resume:
        raise ConfigError("braking run: give --condition 1..5 or --config FILE")
    ck = out / CHECKPOINT
    rec: dict[str, Any] = {}
    if resume:  # everything checked before any output is touched
        runs.check_out_dir(out, "--out", resume=True, need=(CHECKPOINT,))
        rec = read_checkpoint(ck)
        old = _checkpoint_config(rec, ck)
        own = out / "config.toml"
        base = load_toml(own) if own.is_file() else old
        if config is None and base is None:
            raise ConfigError(f"--resume: '{out}' has no config.toml and the checkpoint no "
                              "config; give the run's --config")
        cfg = _config(condition, config, quick, base=base,
                      source=str(own) if own.is_file() else f"checkpoint '{ck}'")
        setup_from_config(cfg)
        _check_same(cfg, old, ck)
    else:
        cfg = _config(condition, config, quick)
        setup_from_config(cfg)  # refuse a bad condition before any work
        runs.check_out_dir(out, "--out")
    runs.check_threads(cfg.run.threads, "run.threads")
    runs.announce(out, ck, resume_hint="add --resume to the same command")
    if resume and rec.get("finished"):
        done = _finished_summary(out)
        if done is not None:
            typer.echo(f"braking run: '{out}' is already finished ({rec['done']} steps); "
                       "nothing to do", err=True)
            typer.echo(json.dumps({k: done.get(k) for k in _SHOWN}, indent=2))
            return
    summary = _run_one(cfg.model_dump(), str(out), cfg.run.threads, resume=resume,
                       progress=progress)
    typer.echo(json.dumps({k: summary[k] for k in _SHOWN}, indent=2))


def _conditions(text: str | None) -> list[int]:
    """``--conditions`` ("1,3,5"; None: all) -> sorted condition numbers (ConfigError:
    exit 2)."""
    from tribodem.braking.conditions import CONDITIONS

    if text is None:
        return sorted(CONDITIONS)
    return sorted(parse_int_list(
        text, "braking sweep: --conditions", lambda k: k in CONDITIONS,
        f"distinct comma-separated conditions of {sorted(CONDITIONS)} (seed 000 table 4), "
        "e.g. 1,3,5"))


def _members(base: dict[str, Any], packings: int, out: Path,
             conditions: list[int]) -> list[Any]:
    """The sweep's members, each config checked (ConfigError) before anything is made.
    Folders: ``condition_k`` with one packing, else ``condition_k/seed_s`` (packing s,
    geometry seed ``seed + s``; the folder name is kept from the former ``--seeds``, so
    earlier sweeps are skipped/resumed, not redone); ``conditions`` of table 4."""
    from tribodem.braking.ensemble import Member

    seed0 = int(base["geometry"]["seed"])
    members = []
    for s in range(packings):
        for k in conditions:
            data = merge(base, {"condition": {"index": k}, "geometry": {"seed": seed0 + s}})
            setup_from_config(validate(BrakingConfig, data, source="sweep"))
            d = out / f"condition_{k}" if packings == 1 else out / f"condition_{k}" / f"seed_{s}"
            members.append(Member(k, s, data, d))
    return members


@braking_app.command("sweep")
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
        help="Which conditions of table 4 to run, e.g. 1,3,5 (the two end-to-end trends, "
             "13 -> 21 kN and 800 -> 1200 r/min, at 3/5 of the cost); changes needing an "
             "absent condition are left unevaluated. Default: all five."),
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
    comparison.json, comparison.csv (ours with paired 95% intervals beside the seed's).

    Each (condition, packing) member is an independent, idempotent task with its own
    folder and checkpoints; a re-run with the same --out skips the finished members,
    resumes the unfinished ones and starts over those whose config changed. A worker lost
    mid-member: the scheduler reschedules the member, which resumes from its checkpoint. A
    failed member is reported and left out of the comparison (exit 3 at the end)."""
    from tribodem.braking.compare import write_comparison
    from tribodem.braking.ensemble import member_plan
    from tribodem.io import runs
    from tribodem.io.ensemble import check_cluster_options, run_members
    from tribodem.io.runs import RunStopped

    if seeds is not None:
        typer.echo("warning: --seeds is deprecated: it counts packing/roughness "
                   "realisations; use --packings", err=True)
        if packings is not None and packings != seeds:
            raise ConfigError(f"braking sweep: --seeds = {seeds} (deprecated alias of "
                              f"--packings) contradicts --packings = {packings}; allowed: "
                              "give --packings only")
    n_pack = packings or seeds or 1
    check_cluster_options("braking sweep", workers, scheduler)
    conds = _conditions(conditions)
    base = _config(None, config, quick).model_dump()
    base["condition"] = {}
    t0 = time.perf_counter()
    members = _members(base, n_pack, out, conds)
    runs.check_out_dir(out, "--out")  # every member checked first: no folder for a bad one
    runs.announce(out)
    results: dict[tuple[int, int], dict[str, Any]] = {}
    todo = []
    for m in members:
        what, info = member_plan(m.data, m.folder)
        name = m.folder.relative_to(out)
        if what == "done":
            results[m.key] = info
            typer.echo(f"  {name}: finished earlier, skipped")
        else:
            if what == "resume":
                typer.echo(f"  {name}: resuming from its checkpoint")
            elif info:
                typer.echo(f"  {name}: starting over ({info})")
            todo.append(m)
    failed: dict[tuple[int, int], str] = {}
    where = "nothing to run"
    if todo:
        try:
            done, failed, where = run_members(
                todo, len(members), len(results), scheduler=scheduler, workers=workers,
                progress=progress, echo=lambda s: typer.echo(s, err=True),
                desc="braking sweep")
        except BaseException:
            typer.echo("\nsweep stopped: finished members are kept; run the same command "
                       "again to skip them and resume the others from their checkpoints",
                       err=True)
            raise
        results.update(done)
    wall = time.perf_counter() - t0
    runs_by_k: dict[int, list[tuple[dict[str, Any], Path]]] = {}
    for m in members:
        if m.key in results:
            runs_by_k.setdefault(m.condition, []).append((results[m.key], m.folder))
    fails = {f"condition {k} packing {s}": msg for (k, s), msg in sorted(failed.items())}
    rows = write_comparison(out, runs_by_k, wall, where, quick, failed=fails) \
        if runs_by_k else []
    skipped = len(members) - len(todo)
    typer.echo(f"sweep: condition(s) {','.join(map(str, conds))} x {n_pack} packing(s) "
               f"in {wall:.1f} s on {where} "
               f"({len(todo)} run, {skipped} skipped as finished, {len(failed)} failed) "
               f"-> {out / 'comparison.md'}")
    for r in rows:
        typer.echo(f"  {r[0]}: ours {r[1]}, seed {r[2]}")
    if failed:
        first = next(iter(fails.items()))
        raise RunStopped(f"{len(failed)} of {len(members)} sweep members failed (first: "
                         f"{first[0]}: {first[1]}); the comparison covers the others")
