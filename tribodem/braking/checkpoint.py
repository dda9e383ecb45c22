"""A braking run's folder state: its checkpoint (``checkpoint.npz``: the engine state with
the braking loop's record inside) and its finished summary.

The checkpoint is written atomically by the engine's ``Simulation.save_checkpoint``; the
braking loop's own state rides in it as the state of the loop's engine interaction
(:class:`tribodem.braking.drive.SlidingDrive`) under the key :data:`LOOP_KEY`. A resume
reads the record first (:func:`read_checkpoint`: every array is read, so a damaged file
is refused before any work) and refuses a setup that differs from the recorded one
(:func:`check_resumable`).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from tribodem.braking.setup import FREE_SETUP_FIELDS, WORN_THROUGH, RunSetup, setup_record
from tribodem.io.config import ConfigError
from tribodem.io.record import differences

#: the run's checkpoint in its output folder
CHECKPOINT = "checkpoint.npz"
#: the version of the braking loop's record in the checkpoint
LOOP_VERSION = 2
#: the key (after the interaction's prefix) of the loop record in the checkpoint
LOOP_KEY = "braking_loop"
#: setup fields added after checkpoints were first written, with the value the run of an
#: older checkpoint (which does not record them) had -- or, for the worn-through guard,
#: resumes with (a run that had no guard gets the default one from its next sample on)
ADDED_FIELDS: dict[tuple[str, ...], Any] = {("geometry", "first_mode"): 1,
                                             ("outlet_length_m",): 0.0,
                                             ("worn_through_diameters",): WORN_THROUGH,
                                             ("feed",): False}


def read_checkpoint(path: str | Path) -> dict[str, Any]:
    """The braking-loop record of a run's checkpoint. Every array is read (zip CRC), so a
    truncated or corrupt file is refused (``ConfigError``) before any work."""
    path = Path(path)
    try:
        with np.load(path, allow_pickle=False) as z:
            for k in z.files:
                z[k]  # noqa: B018 - read it: checks the CRC
            keys = [k for k in z.files if k.endswith("_" + LOOP_KEY)]
            if not keys:
                raise ValueError("it holds no braking-run state (not a braking checkpoint)")
            rec = json.loads(str(z[keys[0]]))
    except Exception as err:  # noqa: BLE001 - any unreadable file
        raise ConfigError(f"checkpoint '{path}' cannot be read: {err}") from None
    if rec.get("version") != LOOP_VERSION:
        raise ConfigError(f"checkpoint '{path}' cannot be read: braking-loop version "
                          f"{rec.get('version')!r}, expected {LOOP_VERSION}")
    return rec


def check_resumable(rec: dict[str, Any], setup: RunSetup, path: str | Path) -> None:
    """``ConfigError`` naming the first setup field that differs from the checkpoint's run
    (only ``checkpoint_every`` and ``figures`` may change); an older checkpoint's missing
    fields count as their ``ADDED_FIELDS`` values."""
    recorded = json.loads(json.dumps(rec["setup"]))
    for keys, value in ADDED_FIELDS.items():
        d = recorded
        for key in keys[:-1]:
            d = d.get(key, {})
        d.setdefault(keys[-1], value)
    diff = differences(recorded, setup_record(setup))
    if diff:
        name, old, new = diff[0]
        raise ConfigError(
            f"--resume: {name} = {new!r} differs from the checkpointed run's {old!r} "
            f"('{path}'); allowed: the same value (only {', '.join(FREE_SETUP_FIELDS)} may "
            "change)")


def finished_summary(out: str | Path) -> dict[str, Any] | None:
    """The run's ``summary.json`` in folder ``out`` when it is complete (``status``
    finished), else None."""
    try:
        s = json.loads((Path(out) / "summary.json").read_text())
    except (OSError, ValueError):
        return None
    return s if isinstance(s, dict) and s.get("status") == "finished" else None
