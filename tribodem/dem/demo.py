"""The engine's demo run: spheres settling in a box, or disks compressed between walls.

:func:`run` is what ``tribodem dem run`` does, callable from Python: one folder with
``timeseries.csv`` (the table of the :class:`~tribodem.io.record.RunResult`),
``summary.json``, ``config.toml`` (the resolved config, reloadable with ``--config``), VTK
snapshots and force chains (``vtk/``) and ``checkpoint.npz``. The config follows the run
record of :mod:`tribodem.io.record`: defaults <- the config <- the quick preset; a resume
compares the config with the one the checkpoint recorded, field by field, and only
``run.steps`` / ``run.threads`` may differ (:attr:`DemRunConfig.MAY_CHANGE`).
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from tribodem.dem.config import DemRunConfig
from tribodem.io import runs
from tribodem.io.config import ConfigError, dump_toml, load_toml
from tribodem.io.record import (
    ConfigSource,
    RunResult,
    as_out,
    checkpoint_meta,
    config_diffs,
    may_change_text,
    read_source,
    resolve,
)

if TYPE_CHECKING:
    from tribodem.dem.bench_cases import BenchCase
    from tribodem.dem.engine import Simulation

CHECKPOINT = "checkpoint.npz"
TABLE = "timeseries.csv"
ASSUMPTIONS = ("simulated time is physical time (no scaling); dt = case dt "
               "(0.2 x critical estimate); no damping except the contact dashpots")


def build(cfg: DemRunConfig) -> tuple[Simulation, BenchCase]:
    """The simulation of ``cfg``'s case (a benchmark case of :mod:`tribodem.dem.bench`)."""
    from tribodem.dem.bench import CASES, simulation_from_case

    case = CASES[cfg.case.kind](n=cfg.case.particles, steps=cfg.run.steps, seed=cfg.case.seed)
    return simulation_from_case(case), case


def _recorded(out: Path) -> tuple[dict[str, Any] | None, Path | None]:
    """The config a resumed run in ``out`` was made with, and where it was read: the
    checkpoint's record, else the folder's ``config.toml``, else (None, None).
    ``ConfigError`` when the checkpoint cannot be read."""
    from tribodem.dem.engine import read_checkpoint_record

    ck = out / CHECKPOINT
    try:
        record = read_checkpoint_record(ck)
    except Exception as err:  # noqa: BLE001 - any unreadable or foreign checkpoint
        raise ConfigError(f"--resume: checkpoint '{ck}' cannot be used: {err}") from None
    if record is not None and isinstance(record.get("config"), dict):
        return record["config"], ck
    own = out / "config.toml"
    if own.is_file():
        return load_toml(own, "--out"), own
    return None, None


def resolve_config(config: ConfigSource = None, *, quick: bool = False,
                   recorded: dict[str, Any] | None = None,
                   recorded_in: Path | None = None) -> DemRunConfig:
    """Defaults <- ``config`` <- the quick preset; with no config, a resumed run's
    ``recorded`` config (read from ``recorded_in``) stands in for it (``ConfigError``
    naming every bad field)."""
    if config is None and recorded is not None:
        data, source = recorded, str(recorded_in or "the recorded config")
    else:
        src = read_source(config)
        data, source = src.data, src.name if config is not None else "dem run"
    return resolve(DemRunConfig, data, source=source,
                   quick=DemRunConfig.QUICK if quick else None)


@runs.releases_folders
def run(config: ConfigSource = None, out: str | Path = "runs/demo", *, quick: bool = False,
        resume: bool = False, progress: bool = False,
        echo: Callable[[str], Any] | None = None) -> RunResult:
    """Settle spheres in a box (or compress disks) and write the run's folder ``out``.

    ``config``: a :class:`DemRunConfig`, a dict shaped like the TOML file (``{"case":
    {"particles": 400}, "run": {"steps": 600}}``), the path of a TOML file, or None (the
    defaults; with ``resume``, the config the run was made with). ``quick``: the preset
    :attr:`DemRunConfig.QUICK` over the config. ``resume``: continue from
    ``out/checkpoint.npz`` to the same result, bitwise, as the uninterrupted run (only
    ``run.steps`` and ``run.threads`` may differ from the recorded config). ``progress``:
    a progress bar on stderr. ``echo``: called with the summary as JSON text at the end
    (the command prints it); None: silent.

    Everything is checked before any work (``ConfigError``: the field, the value, what is
    allowed). Returns the folder, the summary and the table ``timeseries.csv``.
    """
    import numba

    from tribodem.dem.recorders import ScalarRecorder, VTKRecorder, default_probes
    from tribodem.dem.state import BYTES_PER_PARTICLE
    from tribodem.io.results import write_json, write_text

    out = as_out(out)
    ck = out / CHECKPOINT
    runs.check_out_dir(out, "--out", resume=resume, need=(CHECKPOINT,) if resume else ())
    recorded, where = _recorded(out) if resume else (None, None)
    cfg = resolve_config(config, quick=quick, recorded=recorded, recorded_in=where)
    data = cfg.model_dump(mode="json")
    if recorded is not None:
        old = resolve_config(recorded=recorded, recorded_in=where).model_dump(mode="json")
        diffs = config_diffs(old, data, DemRunConfig.MAY_CHANGE)
        if diffs:
            raise ConfigError("\n".join(
                f"--resume: {k} = {new!r} differs from the checkpointed run's {was!r} "
                f"('{where}'); allowed: the same value "
                f"({may_change_text(DemRunConfig.MAY_CHANGE)})" for k, was, new in diffs))
    runs.check_memory(cfg.case.particles, BYTES_PER_PARTICLE, "case.particles")
    threads = runs.check_threads(cfg.run.threads, "run.threads")
    numba.set_num_threads(threads)
    sim, case = build(cfg)
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
    scalars = ScalarRecorder(out / TABLE, default_probes(sim))
    vtk = VTKRecorder(out / "vtk") if cfg.output.vtk_every else None
    if resume:
        scalars.resume(sim.step_count)
        if vtk is not None:
            vtk.resume(sim.step_count)
        runs.checkpoint_written(ck)
    sim.add_recorder(scalars, cfg.output.scalars_every)
    if vtk is not None:
        sim.add_recorder(vtk, cfg.output.vtk_every)

    def save() -> None:
        sim.save_checkpoint(ck, checkpoint_meta(data, steps_done=sim.step_count))

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
                save()
                runs.checkpoint_written(ck)
    sim.close_recorders()
    if cfg.output.checkpoint_every and sim.step_count % every:  # the end, to extend later
        save()
    summary = {
        "case": case.name, "particles": sim.p.n, "steps": sim.step_count,
        "dt_s": sim.dt, "dt_critical_s": sim.dt_critical, "dt_limited_by": sim.dt_limit_by,
        "simulated_time_s": sim.time, "wall_time_s": time.perf_counter() - t0,
        "contacts": sim.n_contacts(), "kinetic_energy_J": sim.kinetic_energy(),
        "neighbor_builds": sim.nl.builds, "threads": numba.get_num_threads(),
        "assumptions": ASSUMPTIONS,
    }
    write_json(out / "summary.json", summary)
    if echo is not None:
        echo(json.dumps(summary, indent=2))
    files = ["summary.json", TABLE, "config.toml"]
    if cfg.output.checkpoint_every:
        files.append(CHECKPOINT)
    if vtk is not None:
        files += ["vtk/particles.pvd", "vtk/chains.pvd"]
    return RunResult(out=out, summary=summary, table=TABLE, files=files)
