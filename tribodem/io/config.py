"""TOML configs -> validated pydantic models, with errors a user can act on.

A bad value is refused before any work: the message names the field, the value given
and what is allowed (``ConfigError``; the CLI turns it into exit code 2, no traceback).
"""

from __future__ import annotations

import tomllib
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any, TypeVar

from pydantic import BaseModel, ValidationError

M = TypeVar("M", bound=BaseModel)


class ConfigError(ValueError):
    """A configuration value that cannot be used; the message says which and why."""


def format_validation_error(err: ValidationError, source: str = "config") -> str:
    """One line per bad field: ``source: field = value: what is allowed``."""
    lines = []
    for e in err.errors():
        field = ".".join(str(p) for p in e["loc"]) or "(root)"
        value = e.get("input", "<missing>")
        msg = e["msg"]
        ctx = e.get("ctx") or {}
        allowed = ", ".join(f"{k} {v}" for k, v in ctx.items() if k != "error")
        if e["type"] == "missing":
            lines.append(f"{source}: field '{field}' is required")
        else:
            extra = f" (allowed: {allowed})" if allowed else ""
            lines.append(f"{source}: field '{field}' = {value!r}: {msg}{extra}")
    return "\n".join(lines)


def validate(model: type[M], data: dict[str, Any], source: str = "config") -> M:
    """Validate ``data`` against ``model`` or raise ``ConfigError`` with a readable message."""
    try:
        return model.model_validate(data)
    except ValidationError as err:
        raise ConfigError(format_validation_error(err, source)) from None


def parse_int_list(text: str, field: str, ok: Callable[[int], bool], allowed: str
                   ) -> tuple[int, ...]:
    """Comma-separated distinct integers (spaces ignored, any order), each passing ``ok``;
    else ``ConfigError`` naming ``field``, the value and ``allowed``."""
    try:
        vals = tuple(int(v) for v in text.replace(" ", "").split(","))
    except ValueError:
        vals = ()
    if not vals or not all(ok(v) for v in vals) or len(set(vals)) < len(vals):
        raise ConfigError(f"{field} = {text!r}: allowed: {allowed}")
    return vals


def load_toml(path: str | Path, field: str = "--config") -> dict[str, Any]:
    """Read a TOML file, turning every problem into ``ConfigError`` naming ``field``."""
    p = Path(path)
    if p.is_dir():
        raise ConfigError(f"{field} = '{p}': is a folder; allowed: a TOML file")
    if not p.is_file():
        raise ConfigError(f"{field} = '{p}': config file does not exist")
    try:
        with p.open("rb") as fh:
            return tomllib.load(fh)
    except tomllib.TOMLDecodeError as err:
        raise ConfigError(f"{field} = '{p}': not valid TOML: {err}") from None
    except (OSError, UnicodeDecodeError) as err:
        raise ConfigError(f"{field} = '{p}': cannot be read: {err}") from None


def load_config(model: type[M], path: str | Path) -> M:
    """Load and validate a TOML config file."""
    return validate(model, load_toml(path), source=str(path))


def merge(base: dict[str, Any], override: dict[str, Any]) -> dict[str, Any]:
    """Recursive dict merge (override wins); used for --quick presets over defaults."""
    out = dict(base)
    for k, v in override.items():
        if isinstance(v, dict) and isinstance(out.get(k), dict):
            out[k] = merge(out[k], v)
        else:
            out[k] = v
    return out


def _without_none(value: Any) -> Any:
    """``value`` with every None entry of its tables left out (TOML has no null), tables in
    arrays too; tuples become lists."""
    if isinstance(value, Mapping):
        return {str(k): _without_none(v) for k, v in value.items() if v is not None}
    if isinstance(value, list | tuple):
        return [_without_none(v) for v in value]
    return value


def dump_toml(data: Mapping[str, Any]) -> str:
    """The TOML text of a resolved config (tomli-w: tables of scalars, arrays, tables).

    A key whose value is None is left out (TOML has no null): on reload the field takes its
    default, which is None wherever a config model allows None, so the file round-trips.
    """
    import tomli_w

    return tomli_w.dumps(_without_none(data))
