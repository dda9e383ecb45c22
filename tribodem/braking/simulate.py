"""One braking-interface run: build, load, slide, measure, write results
(:func:`run_braking` on a :class:`~tribodem.braking.setup.RunSetup`; :func:`run_in_folder`
on a config, as ``tribodem braking run`` and every sweep member run it).

The sliding loop, its checkpoints and the resume are :class:`tribodem.braking.loop.
BrakingLoop`'s; the summary and its time mapping are :mod:`tribodem.braking.summary`'s. A
setup that differs from the checkpoint's (anything but ``checkpoint_every`` and
``figures``) or a checkpoint that cannot be read is refused with ``ConfigError`` before
any output is touched.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numba

from tribodem.braking.checkpoint import CHECKPOINT, check_resumable, read_checkpoint
from tribodem.braking.config import BrakingConfig, setup_from_config
from tribodem.braking.loop import BrakingLoop
from tribodem.braking.plots import plot_run
from tribodem.braking.setup import RunSetup, check_setup
from tribodem.braking.summary import run_summary, stopped_summary, worn_through_message
from tribodem.io.config import ConfigError, dump_toml, validate
from tribodem.io.record import as_out
from tribodem.io.results import write_csv, write_json, write_text
from tribodem.io.runs import RunStopped


def _saved_record(setup: RunSetup, out: Path | None, resume: bool) -> dict[str, Any] | None:
    """The checkpoint record a resume continues from, checked against ``setup`` (None
    for a new run); ``ConfigError`` when there is none or it belongs to another setup."""
    if not resume:
        return None
    if out is None:
        raise ValueError("run_braking: resume needs the output folder 'out'")
    ck = out / CHECKPOINT
    if not ck.is_file():
        raise ConfigError(f"--resume: no checkpoint at '{ck}'")
    saved = read_checkpoint(ck)
    check_resumable(saved, setup, ck)
    return saved


def _write_outputs(loop: BrakingLoop, summary: dict[str, Any]) -> None:
    """``timeseries.csv``, ``summary.json`` and (``figures``) the PNG figures in the
    loop's folder."""
    out = loop.out
    assert out is not None
    rows = loop.rows
    out.mkdir(parents=True, exist_ok=True)
    write_csv(out / "timeseries.csv", list(rows[0]), [list(r.values()) for r in rows])
    write_json(out / "summary.json", summary)
    if loop.setup.figures:
        plot_run(out, rows, loop.frames, loop.iface, summary)


def run_braking(setup: RunSetup, out: str | os.PathLike[str] | None = None, *,
                resume: bool = False, progress: bool = False,
                config: dict[str, Any] | None = None,
                should_stop: Callable[[], bool] | None = None) -> dict[str, Any]:
    """Run one braking interface simulation; write results to folder ``out`` (str or
    path, if given) and return the summary dict.

    With ``out``: ``timeseries.csv`` is rewritten as the run goes (at every checkpoint and
    at most every 2 s of wall time), a checkpoint ``out/checkpoint.npz`` is written after
    the first sample, every ``checkpoint_interval(setup)`` samples and at the end, and
    ``resume`` continues from it (bitwise the run an uninterrupted call gives; the
    wall-time fields excepted). Without ``resume`` an earlier run in ``out`` is replaced.
    An instability (``RunStopped``) is re-raised after the rows so far and a summary with
    ``status = "stopped"`` are written. ``progress``: a bar over the sliding steps.
    ``config``: the command's resolved config (JSON-able), kept in the checkpoint.
    ``should_stop``: polled after every sample (a sweep's stop event); when it says yes the
    run writes a checkpoint and stops (``RunStopped``), to be resumed later. A body worn
    through (``WORN_THROUGH``) ends the run at that sample: every output is written with
    ``status = "worn_through"``, then ``RunStopped`` says which body and where.
    """
    check_setup(setup)
    folder = as_out(out, "out") if out is not None else None
    saved = _saved_record(setup, folder, resume)
    loop = BrakingLoop(setup, folder, config=config, should_stop=should_stop)
    if saved is not None:
        loop.resume(saved)
    else:
        loop.start()
    try:
        loop.run(progress=progress)
    except RunStopped as err:
        if folder is not None:
            loop.write_rows()
            write_json(folder / "summary.json", stopped_summary(loop, err))
        raise
    loop.finish()
    summary = run_summary(loop)
    if folder is not None:
        _write_outputs(loop, summary)
    if summary["worn_through"]:
        where = f" in {str(folder)!r}" if folder is not None else ""
        raise RunStopped(worn_through_message(summary, setup, where))
    return summary


def run_in_folder(cfg_data: dict[str, Any], out: str | os.PathLike[str], threads: int = 0,
                  *, resume: bool = False, progress: bool = False,
                  should_stop: Callable[[], bool] | None = None) -> dict[str, Any]:
    """One run of the resolved config ``cfg_data`` (a dict shaped like the TOML file) in
    folder ``out``, as ``tribodem braking run`` and each sweep member run it: numba on
    ``threads`` threads (0: as it is), the resolved ``config.toml`` written (a resume
    leaves an identical one untouched), an earlier run's summary and checkpoint removed
    unless ``resume``, then :func:`run_braking`. Returns the summary."""
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
