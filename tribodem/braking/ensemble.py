"""Braking sweep members on Dask: every (condition, packing) member is one independent task.

A sweep (:func:`tribodem.braking.sweep`, ``tribodem braking sweep --packings N``) runs its
members with the ensemble machinery of :mod:`tribodem.io.ensemble` (a local cluster of
one-thread worker processes, or ``--scheduler tcp://HOST:PORT``; members done / running /
failed; a failed member reported, not fatal; Ctrl-C stops the members and closes the
cluster). This module says what a braking member is (:func:`sweep_members`: an
:class:`tribodem.io.ensemble.Member` whose task is :func:`run_member`) and what its task
does.

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

from collections.abc import Callable
from pathlib import Path
from typing import Any

from tribodem.braking.checkpoint import CHECKPOINT, finished_summary, read_checkpoint
from tribodem.braking.config import (
    BrakingConfig,
    checkpoint_config,
    config_differences,
    setup_from_config,
)
from tribodem.braking.simulate import run_in_folder
from tribodem.io import runs
from tribodem.io.config import ConfigError, load_toml, merge, validate
from tribodem.io.ensemble import Member, stop_check


def member_plan(cfg_data: dict[str, Any], d: Path) -> tuple[str, Any]:
    """What a sweep member needs: ("done", summary) when ``d`` holds its finished run with
    the same config, ("resume", None) when it holds a usable checkpoint of it, else
    ("new", why-not-reused or None)."""
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
    done = finished_summary(d)
    if done is not None:
        return "done", done
    ck = d / CHECKPOINT
    if not ck.is_file():
        return "new", None
    try:
        rec = read_checkpoint(ck)
        ck_cfg = checkpoint_config(rec, ck)
    except ConfigError as err:
        return "new", str(err)
    if ck_cfg is not None and config_differences(ck_cfg, new):
        return "new", "its checkpoint belongs to another config"
    return "resume", None


@runs.releases_folders
def run_member(cfg_data: dict[str, Any], out: str, stop_event: str | None = None
               ) -> dict[str, Any]:
    """The task of one member (idempotent, retry-safe): decide from the folder's state --
    finished (return its summary), resumable (resume from the checkpoint) or neither (start
    over) -- then run with one numba thread. Returns the finished summary."""
    what, info = member_plan(cfg_data, Path(out))
    if what == "done":
        return info
    return run_in_folder(cfg_data, out, 1, resume=what == "resume",
                         should_stop=stop_check(stop_event))


def sweep_members(base: dict[str, Any], packings: int, out: Path,
                  conditions: list[int]) -> list[Member]:
    """The sweep's members, each config checked (ConfigError) before anything is made.
    Folders: ``condition_k`` with one packing, else ``condition_k/seed_s`` (packing s,
    geometry seed ``seed + s``; the folder name is kept from the former ``--seeds``, so
    earlier sweeps are skipped/resumed, not redone); ``conditions`` of table 4. Key:
    (condition, packing); ``info``: the condition and the packing."""
    seed0 = int(base["geometry"]["seed"])
    members = []
    for s in range(packings):
        for k in conditions:
            data = merge(base, {"condition": {"index": k}, "geometry": {"seed": seed0 + s}})
            setup_from_config(validate(BrakingConfig, data, source="sweep"))
            d = out / f"condition_{k}" if packings == 1 else out / f"condition_{k}" / f"seed_{s}"
            members.append(Member(key=(k, s), label=f"condition {k} packing {s}",
                                  task_name=f"braking-c{k}-p{s}", task=run_member, data=data,
                                  folder=d, info={"condition": k, "packing": s}))
    return members


def plan_members(members: list[Member], out: Path, echo: Callable[[str], None]
                 ) -> tuple[dict[Any, dict[str, Any]], list[Member]]:
    """(summaries of the members finished earlier with the same config, by key; the
    members to run), each member's plan told through ``echo`` (skipped, resuming, starting
    over and why)."""
    results: dict[Any, dict[str, Any]] = {}
    todo = []
    for m in members:
        what, info = member_plan(m.data, m.folder)
        name = m.folder.relative_to(out)
        if what == "done":
            results[m.key] = info
            echo(f"  {name}: finished earlier, skipped")
        else:
            if what == "resume":
                echo(f"  {name}: resuming from its checkpoint")
            elif info:
                echo(f"  {name}: starting over ({info})")
            todo.append(m)
    return results, todo


def projected_wall_s(members: int, member_s: float, workers: int,
                     startup_s: float = 0.0) -> float:
    """Projected wall time (s) of a sweep of ``members`` members, each ``member_s``
    seconds of one core (a measured member: ``wall_time_s`` of a finished member's
    summary, one thread), on ``workers`` one-thread workers: every worker takes the next
    member when it finishes one, so equal members run in ``ceil(members / workers)``
    rounds: ``T = startup_s + ceil(N / W) member_s``. ``startup_s``: the cluster's start
    (a batch queue's wait is not in it). A lower bound when members differ in cost (the
    last round waits for its slowest); ``ValueError`` on a count below 1 or a negative
    time."""
    if members < 1 or workers < 1:
        raise ValueError(f"members = {members!r}, workers = {workers!r}: both must be >= 1")
    if not (member_s >= 0 and startup_s >= 0):
        raise ValueError(f"member_s = {member_s!r}, startup_s = {startup_s!r}: must be >= 0 s")
    rounds = -(-members // workers)
    return startup_s + rounds * member_s
