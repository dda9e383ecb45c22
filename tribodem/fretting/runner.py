"""A fretting run from Python or the command line: :func:`run` (a config -> the files of one
run folder, returned as a :class:`~tribodem.io.record.RunResult`).

The folder holds ``results.csv`` (one row per cycle), ``summary.json``, ``config.toml``
(the resolved config, which reloads unchanged), ``checkpoint.npz`` and, as ``[output]``
asks, figures and VTK surfaces. ``results.csv`` and the checkpoint are rewritten
atomically every ``output.checkpoint_every`` simulated cycles (at least
``output.checkpoint_seconds`` apart), so a stopped run resumes
(``resume=True``) to the same result, bitwise.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from tribodem.contact.fe.ccx import CcxTimeoutError, FESolverStopped
from tribodem.fretting.case import FrettingCase, build_loop
from tribodem.fretting.config import (
    FrettingConfig,
    check_resume,
    recorded_config,
    resolve_config,
)
from tribodem.fretting.loop import FrettingHistory, FrettingLoop
from tribodem.fretting.output import (
    CHECKPOINT,
    read_checkpoint,
    write_checkpoint,
    write_debris_outputs,
    write_figures,
    write_profiles,
    write_results,
    write_rows,
    write_vtk_surfaces,
)
from tribodem.io import runs
from tribodem.io.config import ConfigError, dump_toml
from tribodem.io.record import ConfigSource, RunResult, as_out, checkpoint_meta
from tribodem.io.results import write_text

#: What a run says of itself: one line at a time (``typer.echo``, ``print``, a logger).
Echo = Callable[[str], None]
#: A checkpoint as read: (its metadata, the loop's state).
Checkpoint = tuple[dict[str, Any], dict[str, Any]]

RESUME_HINT = "add --resume to the same command"


@runs.releases_folders
def run(config: ConfigSource = None, out: str | os.PathLike[str] | None = None, *,
        quick: bool = False, resume: bool = False, progress: bool = False,
        overrides: Mapping[str, Any] | None = None, echo: Echo | None = None) -> RunResult:
    """Run the fretting wear loop into folder ``out``.

    ``config``: a :class:`~tribodem.fretting.config.FrettingConfig`, a dict shaped like the
    TOML file (``{"cycles": 3, "contact": {"n": 32}}``), the path of a TOML file, or None
    (the defaults; with ``resume``, the config the checkpoint records). Resolved as
    defaults <- ``config`` <- the ``quick`` preset (64^2 window, 10 cycles) <- ``overrides``
    (a dict shaped like the TOML file). ``resume``: continue from ``out/checkpoint.npz``
    (the same config, except the fields of
    :data:`~tribodem.fretting.config.RESUME_MAY_CHANGE`: ``cycles`` may be raised).
    ``progress``: a progress bar on stderr; ``echo``: called with a line every tenth of
    the cycles when there is no progress bar.

    Everything is checked before any work (``ConfigError`` naming the field, the value and
    what is allowed). An early stop (a contact that outgrew the window, a ccx job that did
    not converge) writes every output so far, then raises
    :class:`~tribodem.io.runs.RunStopped`. Returns the folder, ``summary.json``'s content
    and ``results.csv`` (``.to_dataframe()``: one row per cycle).
    """
    folder = as_out(out)  # type: ignore[arg-type]  # None is refused there, named
    runs.check_out_dir(folder, "--out", resume=resume, need=(CHECKPOINT,) if resume else ())
    ck = read_checkpoint(folder / CHECKPOINT) if resume else None
    base = recorded_config(ck[0].get("config") or {}) if ck is not None else None
    cfg = resolve_config(config, quick=quick, overrides=overrides, base=base)
    summary = run_config(cfg, folder, resume=resume, progress=progress, echo=echo,
                         checkpoint=ck)
    return RunResult(folder, summary, "results.csv", list(summary.get("files", [])))


def run_config(cfg: FrettingConfig, out: Path, *, resume: bool = False,
               progress: bool = False, echo: Echo | None = None,
               checkpoint: Checkpoint | None = None) -> dict[str, Any]:
    """:func:`run` on a resolved config, ``out`` checked: returns ``summary.json``'s
    content. ``checkpoint``: the (meta, state) already read from ``out`` (read here when
    None and ``resume``)."""
    case, loop = prepare_loop(cfg, out, resume, checkpoint)
    open_folder(cfg, out, resume)
    t0 = time.perf_counter()
    hist = run_cycles(cfg, loop, out, progress, echo, case.sizing_cycles)
    summary = write_outputs(case, loop, hist, out, t0)
    if hist.stopped:
        raise stop_error(loop, hist, out)
    return summary


def prepare_loop(cfg: FrettingConfig, out: Path, resume: bool,
                 checkpoint: Checkpoint | None) -> tuple[FrettingCase, FrettingLoop]:
    """The case and its loop, the ccx work folder ``out/fe`` set, restored from the
    checkpoint on ``resume`` (checked against ``cfg`` first: ``ConfigError``)."""
    ck = out / CHECKPOINT
    state: dict[str, Any] | None = None
    sizing = None
    if resume:
        meta, state = checkpoint if checkpoint is not None else read_checkpoint(ck)
        check_resume(cfg, meta, ck)
        # the grids keep the size the run started with (a window left out is sized for
        # the cycles first asked for, not for a raised cycles)
        sizing = int(meta.get("window_cycles") or (meta.get("config") or {}).get(
            "cycles") or cfg.cycles)
    case = FrettingCase.of(cfg, sizing_cycles=sizing)
    loop = build_loop(cfg, case)
    if loop.solver.runs_ccx:  # ccx decks, logs, results
        loop.solver.workdir = out / "fe"
    if state is not None:
        try:
            loop.load_state_dict(state)
        except (KeyError, TypeError, ValueError) as err:
            raise ConfigError(f"checkpoint '{ck}' cannot be read: it does not fit this run: "
                              f"{type(err).__name__}: {err}") from None
    return case, loop


#: what a fretting run writes in its folder (names and patterns): a new run in a folder
#: that held an earlier one removes them first, so no file of the earlier run passes for
#: this one's (the ccx job folder ``fe/`` stays: its job cache serves the same decks)
RUN_OUTPUTS = ("results.csv", "summary.json", "criterion.csv", "profiles.csv",
               "profiles.png", "wear_scar.png", "wear_vs_cycle.png", "debris_layer.png",
               "debris_pressure.png", "surface_*.vtu", "debris_*.vtu", "debris_*.pvd",
               "de_surface_*.stl", "debris*.csv", "fe/fields.pvd", "fe/cycle_*/job*.vtu",
               CHECKPOINT)


def remove_earlier_outputs(out: Path) -> None:
    """Remove the files of an earlier run in ``out`` (:data:`RUN_OUTPUTS`)."""
    for pattern in RUN_OUTPUTS:
        for p in out.glob(pattern):
            if p.is_file():
                p.unlink()


def open_folder(cfg: FrettingConfig, out: Path, resume: bool) -> None:
    """Announce ``out`` and its checkpoint (for Ctrl-C and stops; this takes the folder's
    lock), make the folder, remove an earlier run's outputs when not resuming (its
    checkpoint must not pass for this one's, nor its figures), write ``config.toml``."""
    ck = out / CHECKPOINT
    runs.announce(out, ck, resume_hint=RESUME_HINT)
    if resume:
        runs.checkpoint_written(ck)
    out.mkdir(parents=True, exist_ok=True)
    if not resume:
        remove_earlier_outputs(out)
    write_text(out / "config.toml", dump_toml(cfg.record()))


def run_cycles(cfg: FrettingConfig, loop: FrettingLoop, out: Path, progress: bool,
               echo: Echo | None, window_cycles: int = 0) -> FrettingHistory:
    """The loop to ``cfg.cycles``, the checkpoint and ``results.csv`` rewritten every
    ``output.checkpoint_every`` simulated cycles and ``output.checkpoint_seconds`` apart,
    the progress shown; ``window_cycles``: the cycles the window was sized for (recorded
    in the checkpoint, so a resume builds the same grids)."""
    ck = out / CHECKPOINT
    record = cfg.record()  # the checkpoint records the config as config.toml does
    every = max(1, cfg.cycles // 10)

    def save(lp: FrettingLoop) -> None:
        assert lp.history is not None
        write_checkpoint(ck, checkpoint_meta(record, cycles_done=lp.cycles_done,
                                             window_cycles=window_cycles), lp.state_dict())
        runs.checkpoint_written(ck)
        write_rows(lp.history, out)  # never ahead of the checkpoint

    with runs.progress(cfg.cycles, "cycle", "fretting run", enabled=progress,
                       initial=loop.cycles_done) as bar:
        def report(row: dict[str, Any]) -> None:
            bar.update(1)
            bar.set_postfix_str(f"wear depth lower {row['wear_depth_lower_m']:.3g} m")
            if echo is not None and not progress and (
                    row["cycle"] % every == 0 or row["cycle"] == cfg.cycles):
                echo(f"cycle {row['cycle']}/{cfg.cycles}"
                     f"{' (jumped)' if row['jumped'] else ''}: wear depth upper "
                     f"{row['wear_depth_upper_m']:.4g} m, lower "
                     f"{row['wear_depth_lower_m']:.4g} m")

        return loop.run(cfg.cycles, progress=report, checkpoint=save,
                        checkpoint_every=cfg.output.checkpoint_every,
                        checkpoint_seconds=cfg.output.checkpoint_seconds)


def write_outputs(case: FrettingCase, loop: FrettingLoop, hist: FrettingHistory, out: Path,
                  t0: float) -> dict[str, Any]:
    """Figures, VTK and debris outputs as ``[output]`` asks, then ``results.csv`` and
    ``summary.json`` (returned); ``t0``: ``time.perf_counter()`` when this process started
    the loop (``wall_time_total_s``: from then to the summary, figures included)."""
    cfg = case.config
    files: list[str] = ["results.csv", "summary.json", "config.toml", CHECKPOINT]
    if (out / "criterion.csv").exists():
        files.append("criterion.csv")
    profiles = write_profiles(hist, out)
    if profiles is not None:
        files.append(profiles.name)
    if cfg.output.figures:
        files += [p.name for p in write_figures(hist, out)]
    if cfg.output.vtk:
        files += [p.name for p in write_vtk_surfaces(hist, out)]
        if loop.solver.runs_ccx and loop.solver.workdir is not None:
            # each ccx job's mesh and fields for ParaView: fe/cycle_*/job.vtu, fe/fields.pvd
            from tribodem.contact.fe.fields import write_fields

            pvd = write_fields(loop.solver.workdir, loop.cycles_done)
            if pvd is not None:
                files.append(pvd.relative_to(out).as_posix())
    if hist.de_phases:
        files += [p.name for p in write_debris_outputs(hist, out, figures=cfg.output.figures,
                                                       vtk=cfg.output.vtk)]
    extra = {
        "criterion": {"name": loop.criterion.name, "kind": loop.criterion.kind,
                      **loop.criterion.params()},
        "jump": {"strategy": cfg.jump.strategy,
                 **({"params": loop.strategy.params(), **jump_reading(loop)}
                    if loop.strategy else {})},
        "wear_updates": update_reading(loop),
        "window_m": loop.solver.window,
        "contact_case": case.summary(loop.solver),
        "first_body_report": loop.solver.report(),
        "wall_time_total_s": time.perf_counter() - t0,
        "files": files,
        "config": cfg.record(),
    }
    return write_results(hist, out, extra)


def stop_error(loop: FrettingLoop, hist: FrettingHistory, out: Path) -> runs.RunStopped:
    """The :class:`~tribodem.io.runs.RunStopped` of a run that stopped early, with the
    announcement of how to go on (raise ``fe.timeout``, retry the cycle, or a larger
    window: a resume would stop at the same cycle)."""
    ck = out / CHECKPOINT
    if isinstance(loop.stop_error, FESolverStopped):
        hint = (f"raise fe.timeout (now {loop.solver.timeout:g} s) and add --resume to the "
                "same command" if isinstance(loop.stop_error, CcxTimeoutError) else
                "see the deck and its .log, then add --resume to retry the cycle (a deck "
                "that did not converge is not run again: raise fe.retries, or delete its "
                ".failed file)")
    else:
        hint = ("a resume would stop at the same cycle: to go on, start a new run with a "
                "larger contact.window")
    runs.announce(out, ck, resume_hint=hint)
    return runs.RunStopped(f"{hist.stopped} (results.csv, summary.json and figures up "
                           f"to cycle {loop.cycles_done} are written)")


def update_reading(loop: FrettingLoop) -> dict[str, Any]:
    """The run's geometry updates (``FrettingLoop.wear_updates``) and one sentence on them,
    for summary.json's ``wear_updates``."""
    u = loop.wear_updates()
    tol, ratio = u["update_tolerance"], u["largest_increment_over_approach"]
    if tol is None:
        text = (f"one geometry update a cycle (wear.update_tolerance = 0); the largest "
                f"depth increment of a cycle was {ratio:.3g} elastic approaches")
    else:
        text = (f"a cycle's wear changes the depth anywhere by at most {tol:g} elastic "
                f"approaches per update (wear.update_tolerance); the largest cycle's was "
                f"{ratio:.3g}")
        if u["cycles_split"]:
            text += (f": {u['cycles_split']} cycles were split into sub-cycles (at most "
                     f"{u['most_subcycles']}), each adding its share of the cycle's wear")
        if u["cycles_over_tolerance"]:
            text += (f"; {u['cycles_over_tolerance']} cycles stayed over it (this criterion, "
                     "backend or the debris cannot repeat a cycle, or the split reached its "
                     "limit): their scars depend on the wear per cycle; a smaller wear "
                     "coefficient per cycle (or a coarser grid) resolves them")
    return {**u, "reading": text}


def jump_reading(loop: FrettingLoop) -> dict[str, Any]:
    """The run's jump decisions (``FrettingLoop.jump_decisions``) and one sentence on what
    limited the jumps, for summary.json's ``jump``."""
    d = loop.jump_decisions()
    tol, last = d["geometry_tolerance"], d["last"]
    if not d["decisions"]:
        text = "no jump decision yet (no simulated cycle was shown to the strategy)"
    elif tol is None:
        text = ("geometry control off (jump.geometry_tolerance = 0): every jump as the "
                f"strategy proposed it; {d['cycles_jumped']} cycles jumped")
    else:
        text = (f"the strategy proposed no jump in {d['decisions']} decisions"
                if not d["proposed"] else
                f"the strategy proposed a jump in {d['proposed']} of {d['decisions']} "
                f"decisions; the geometry (jump.geometry_tolerance = {tol:g}: a jump adds "
                f"at most {tol:.0%} of the contact's elastic approach to the depth anywhere)"
                f" cut {d['capped_by_geometry']} of them; {d['cycles_jumped']} cycles were "
                "jumped")
        if last["geometry_limit"] is not None and last["increment_over_approach"]:
            text += (f"; at the last decision the last cycle's largest depth increment, "
                     f"{last['depth_increment_m'] * 1e6:.3g} um, was "
                     f"{last['increment_over_approach']:.3g} elastic approaches "
                     f"({last['elastic_approach_m'] * 1e6:.3g} um), so the geometry allowed "
                     f"{last['geometry_limit']} cycles")
    return {"decisions": d, "reading": text}
