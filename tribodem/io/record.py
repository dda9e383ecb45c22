"""The run-record protocol every command and library function follows.

One run is one folder. Its configuration is resolved in one order, everywhere:

    model defaults  <-  the config (a model, a dict shaped like the TOML file, or a TOML
    file)  <-  the ``quick`` preset  <-  the caller's overrides (command-line options)

(:func:`resolve`). The resolved config is recorded in the folder (``config.toml``) and in
every checkpoint (:func:`checkpoint_meta`); a resume compares the config it is given with
the recorded one field by field (:func:`config_diffs`), leaving out only the fields the
room declares free to change (its ``may_change`` prefixes: how many cycles, what is
written, how many threads). The output folder is checked before any work
(:func:`tribodem.io.runs.check_out_dir`). What a run returns to Python is a
:class:`RunResult`: its folder, its summary and its table.
"""

from __future__ import annotations

import copy
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

from pydantic import BaseModel

from tribodem.io.config import ConfigError, load_toml, merge, validate

if TYPE_CHECKING:
    import pandas as pd

M = TypeVar("M", bound=BaseModel)

#: What a library function accepts as a config: a validated model, a dict shaped like the
#: TOML file, the path of a TOML file, or None (the defaults).
ConfigSource = BaseModel | Mapping[str, Any] | str | os.PathLike[str] | None


@dataclass(frozen=True)
class Source:
    """A config as read: its data (JSON-like dicts), what to call it in messages, and the
    file it came from (None for a model, a dict or the defaults)."""

    data: dict[str, Any]
    name: str
    path: Path | None = None


def read_source(config: ConfigSource, field: str = "--config") -> Source:
    """``config`` as plain data (:class:`Source`); a file is read here (``ConfigError``
    naming ``field`` when it cannot be)."""
    if config is None:
        return Source({}, "defaults")
    if isinstance(config, BaseModel):
        return Source(config.model_dump(mode="json"), type(config).__name__)
    if isinstance(config, Mapping):
        return Source(copy.deepcopy(dict(config)), "config")
    if isinstance(config, str | os.PathLike):
        path = Path(config)
        return Source(load_toml(path, field), str(path), path)
    raise ConfigError(f"{field} = {config!r}: allowed: a config model, a dict shaped like the "
                      "TOML file, or the path of a TOML file")


def resolve(model: type[M], data: Mapping[str, Any], *, source: str = "config",
            quick: Mapping[str, Any] | None = None,
            overrides: Mapping[str, Any] | None = None) -> M:
    """Defaults <- ``data`` <- ``quick`` <- ``overrides``, validated (``ConfigError`` naming
    every bad field as ``source: field = value: what is allowed``)."""
    merged = merge(dict(data), dict(quick or {}))
    merged = merge(merged, dict(overrides or {}))
    return validate(model, merged, source=source)


def flatten(data: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    """Nested dicts as one dict of dotted names (``{"a": {"b": 1}}`` -> ``{"a.b": 1}``)."""
    out: dict[str, Any] = {}
    for k, v in data.items():
        if isinstance(v, Mapping):
            out |= flatten(v, f"{prefix}{k}.")
        else:
            out[f"{prefix}{k}"] = v
    return out


def nest(dotted: Mapping[str, Any]) -> dict[str, Any]:
    """The inverse of :func:`flatten`."""
    out: dict[str, Any] = {}
    for k, v in dotted.items():
        d = out
        *heads, last = k.split(".")
        for h in heads:
            d = d.setdefault(h, {})
        d[last] = v
    return out


def differences(old: Mapping[str, Any], new: Mapping[str, Any], prefix: str = ""
                ) -> list[tuple[str, Any, Any]]:
    """(dotted name, old, new) of every entry that differs between two nested dicts, in
    sorted order (an entry missing on one side is None there)."""
    out: list[tuple[str, Any, Any]] = []
    for k in sorted(set(old) | set(new), key=str):
        a, b = old.get(k), new.get(k)
        name = f"{prefix}{k}"
        if isinstance(a, Mapping) and isinstance(b, Mapping):
            out += differences(a, b, name + ".")
        elif a != b:
            out.append((name, a, b))
    return out


def is_free(name: str, may_change: tuple[str, ...]) -> bool:
    """Whether dotted field ``name`` is one a resume may change: equal to an entry of
    ``may_change``, or under an entry that ends with ``.`` (a whole table)."""
    return any(name == m or (m.endswith(".") and name.startswith(m)) for m in may_change)


def config_diffs(old: Mapping[str, Any], new: Mapping[str, Any],
                 may_change: tuple[str, ...] = ()) -> list[tuple[str, Any, Any]]:
    """(field, recorded, given) of the fields in which config ``new`` makes another run
    than the recorded ``old``, the fields of ``may_change`` (:func:`is_free`) left out."""
    return [d for d in differences(old, new) if not is_free(d[0], may_change)]


def may_change_text(may_change: tuple[str, ...]) -> str:
    """What a refused resume says may change: "only cycles, [output], fe.threads may
    change"."""
    return "only " + ", ".join(f"[{k[:-1]}]" if k.endswith(".") else k
                               for k in may_change) + " may change"


def checkpoint_meta(config: Mapping[str, Any], **fields: Any) -> dict[str, Any]:
    """The metadata a checkpoint carries: the resolved config it was made with, the
    tribodem version that made it and the room's own fields (steps or cycles done)."""
    from tribodem import __version__

    return {"config": dict(config), "tribodem": __version__, **fields}


def as_out(out: str | os.PathLike[str], field: str = "--out") -> Path:
    """An output folder given as str or path; the empty string is refused (it would mean
    the current folder without saying so)."""
    if isinstance(out, str) and not out.strip():
        raise ConfigError(f"{field} = {out!r}: allowed: a folder path (not empty)")
    if not isinstance(out, str | os.PathLike):
        raise ConfigError(f"{field} = {out!r}: allowed: a folder path (str or Path)")
    return Path(out)


@dataclass
class RunResult:
    """What a run returns: its folder, its summary (``summary.json`` as a dict) and its
    table (a CSV file in the folder, one row per cycle, sample or member).

    ``to_dataframe()`` reads the table with pandas.
    """

    out: Path
    summary: dict[str, Any]
    table: str = "results.csv"
    files: list[str] = field(default_factory=list)

    def to_dataframe(self) -> pd.DataFrame:
        """The run's table (``out / table``) as a pandas DataFrame."""
        import pandas as pd

        return pd.read_csv(self.out / self.table)

    def __getitem__(self, key: str) -> Any:
        """A summary entry (``result["wear_volume_lower_m3"]``)."""
        return self.summary[key]
