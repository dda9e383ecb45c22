"""The record a study keeps of itself (``out/study.toml``: its config and options) and
what a resume compares against it; shared by ``fretting study`` and ``fretting
debris-study``."""

from __future__ import annotations

import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from tribodem.fretting.config import RESUME_MAY_CHANGE, recorded_config, resume_diffs
from tribodem.io.config import ConfigError, dump_toml, load_toml


def load_toml_roundtrip(data: Mapping[str, Any]) -> dict[str, Any]:
    """``data`` as it reads back from TOML (for comparing with a saved study)."""
    return tomllib.loads(dump_toml(dict(data)))


def read_study(out: Path) -> dict[str, Any]:
    """``out/study.toml`` of an earlier study (``fretting study``, ``debris-study``) as
    :func:`load_toml_roundtrip` gives it, its config read as
    :func:`~tribodem.fretting.config.recorded_config` reads a recorded one
    (``ConfigError`` naming ``--out`` when it cannot be read)."""
    path = Path(out) / "study.toml"
    data = load_toml(path, "--out")
    if not isinstance(data.get("config"), dict):
        raise ConfigError(f"--out: '{path}' has no [config] table; allowed: the study.toml "
                          "a study wrote (or a new --out without --resume)")
    data["config"] = recorded_config(data["config"])
    return load_toml_roundtrip(data)


def study_diffs(out: Path, meta: Mapping[str, Any],
                may_change: tuple[str, ...] | None = None) -> list[str]:
    """What keeps the study ``meta`` (its ``config`` and the rest: ``quick``, ``counts``)
    from resuming the one ``out/study.toml`` records (:func:`read_study`), each as "field =
    new (study: old)": the configs compared as a run's resume compares them
    (:func:`~tribodem.fretting.config.resume_diffs`: how ccx runs, ``[output]`` and
    ``cycles`` may change, or the fields of ``may_change``), the rest by equality. Empty
    when it may resume."""
    old = read_study(out)
    new = load_toml_roundtrip(meta)
    diffs = resume_diffs(old["config"], new.get("config") or {}, what="study",
                         may_change=RESUME_MAY_CHANGE if may_change is None else may_change)
    return diffs + [f"{k} = {new.get(k)!r} (study: {old.get(k)!r})"
                    for k in sorted((set(old) | set(new)) - {"config"})
                    if old.get(k) != new.get(k)]
