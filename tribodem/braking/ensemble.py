"""Braking sweep members on Dask: every (condition, packing) member is one independent task.

``tribodem braking sweep --packings N`` runs its 5 x N members with the ensemble machinery of
:mod:`tribodem.io.ensemble` (a local cluster of one-thread worker processes, or
``--scheduler tcp://HOST:PORT``; members done / running / failed; a failed member reported,
not fatal; Ctrl-C stops the members and closes the cluster). This module says what a
braking member is (:class:`Member`) and what its task does.

**A member is idempotent and retry-safe** (:func:`run_member`): the task itself looks at its
folder when it starts, on whichever worker (:func:`member_plan`), and returns the finished
summary found there, resumes from ``checkpoint.npz`` (bitwise the uninterrupted run) or
starts over; it runs with one numba thread and stops at its next sample after a checkpoint
when the sweep's stop event is set. Every file it writes is written atomically
(``tribodem.io.results``), so a worker killed at any moment leaves either the old or the new
version of each file, and a rescheduled attempt resumes from the last checkpoint. Two
attempts of the same member running at once (a worker cut off from the scheduler but still
alive) write the same bytes.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tribodem.io.config import ConfigError
from tribodem.io.ensemble import stop_check


@dataclass
class Member:
    """One (condition, packing) run of a sweep and its folder (a
    :class:`tribodem.io.ensemble.Member`: its task is :func:`run_member`)."""

    condition: int
    packing: int
    data: dict[str, Any]
    folder: Path

    @property
    def key(self) -> tuple[int, int]:
        return self.condition, self.packing

    @property
    def label(self) -> str:
        return f"condition {self.condition} packing {self.packing}"

    @property
    def task_name(self) -> str:
        return f"braking-c{self.condition}-p{self.packing}"

    @property
    def task(self) -> Any:
        return run_member

    @property
    def args(self) -> tuple[Any, ...]:
        return self.data, str(self.folder.resolve())


def member_plan(cfg_data: dict[str, Any], d: Path) -> tuple[str, Any]:
    """What a sweep member needs: ("done", summary) when ``d`` holds its finished run with
    the same config, ("resume", None) when it holds a usable checkpoint of it, else
    ("new", why-not-reused or None)."""
    from tribodem.braking.cli import (
        BrakingConfig,
        _checkpoint_config,
        _finished_summary,
        config_differences,
    )
    from tribodem.braking.run import CHECKPOINT, read_checkpoint
    from tribodem.io.config import load_toml, validate

    new = validate(BrakingConfig, cfg_data, source="sweep").model_dump()
    own = d / "config.toml"
    if not own.is_file():
        return "new", None
    try:
        old = validate(BrakingConfig, load_toml(own), source=str(own)).model_dump()
    except ConfigError:
        return "new", "its config.toml cannot be read"
    diff = config_differences(old, new)
    if diff:
        return "new", f"{diff[0][0]} changed from {diff[0][1]!r} to {diff[0][2]!r}"
    done = _finished_summary(d)
    if done is not None:
        return "done", done
    ck = d / CHECKPOINT
    if not ck.is_file():
        return "new", None
    try:
        rec = read_checkpoint(ck)
        ck_cfg = _checkpoint_config(rec, ck)
    except ConfigError as err:
        return "new", str(err)
    if ck_cfg is not None and config_differences(ck_cfg, new):
        return "new", "its checkpoint belongs to another config"
    return "resume", None


def run_member(cfg_data: dict[str, Any], out: str, stop_event: str | None = None
               ) -> dict[str, Any]:
    """The task of one member (idempotent, retry-safe): decide from the folder's state --
    finished (return its summary), resumable (resume from the checkpoint) or neither (start
    over) -- then run with one numba thread. Returns the finished summary."""
    from tribodem.braking.cli import _run_one

    what, info = member_plan(cfg_data, Path(out))
    if what == "done":
        return info
    return _run_one(cfg_data, out, 1, resume=what == "resume",
                    should_stop=stop_check(stop_event))
