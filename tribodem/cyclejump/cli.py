"""``tribodem jump``: replay a recorded per-cycle series with a cycle-jumping strategy.

Option parsing only (``--param key=value`` into the strategy's typed keywords): the replay
is :func:`tribodem.cyclejump.recorded.replay_csv`. Bad input raises ``ConfigError`` (the
``tribodem`` entry point turns it into exit code 2 with a one-line message).
"""

from __future__ import annotations

import inspect
import json
import math
from pathlib import Path
from typing import Annotated, Any

import typer

from tribodem.cyclejump.registry import STRATEGIES
from tribodem.io.config import ConfigError

jump_app = typer.Typer(
    help="Cycle-jumping strategies (Lu (2018) chapter 4): replay a recorded series.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)


def _parse_value(key: str, raw: str, annotation: str, strategy: str) -> Any:
    """Convert ``raw`` to the type named by the constructor annotation."""
    low = raw.strip().lower()
    ann = str(annotation)
    if "None" in ann and low in ("none", "null", ""):
        return None
    try:
        if ann.startswith("bool"):
            if low in ("1", "true", "yes", "on"):
                return True
            if low in ("0", "false", "no", "off"):
                return False
            raise ValueError
        if ann.startswith("int"):
            v = float(raw)
            if v != int(v):
                raise ValueError
            return int(v)
        if ann.startswith("float"):
            v = float(raw)
            if not math.isfinite(v):
                raise ValueError
            return v
    except ValueError:
        kind = ann.replace(" | None", " or none")
        raise ConfigError(f"--param {key}={raw!r} for strategy '{strategy}': "
                          f"expected {kind}") from None
    return raw


def parse_params(strategy: str, items: list[str]) -> dict[str, Any]:
    """``key=value`` strings -> constructor keyword arguments of ``strategy``."""
    sig = inspect.signature(STRATEGIES[strategy].__init__)
    allowed = {k: p for k, p in sig.parameters.items() if k != "self"}
    out: dict[str, Any] = {}
    for item in items:
        if "=" not in item:
            raise ConfigError(f"--param {item!r}: expected key=value")
        key, raw = (s.strip() for s in item.split("=", 1))
        if key not in allowed:
            raise ConfigError(
                f"--param {key!r} is not a parameter of strategy '{strategy}'; allowed: "
                f"{', '.join(f'{k} (default {p.default!r})' for k, p in allowed.items())}"
            )
        out[key] = _parse_value(key, raw, allowed[key].annotation, strategy)
    return out


@jump_app.callback()
def _jump() -> None:
    """Cycle-jumping strategies (Lu (2018) chapter 4)."""


@jump_app.command("replay")
def replay_cmd(
    strategy: Annotated[str, typer.Option("--strategy", help=f"One of: {', '.join(STRATEGIES)}.")],
    input: Annotated[Path, typer.Option("--input", help="CSV with columns cycle,increment.")],
    param: Annotated[list[str] | None, typer.Option(
        "--param", help="Strategy parameter key=value (repeatable).")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print the summary as JSON.")] = False,
    plot: Annotated[Path | None, typer.Option(
        "--plot", help="Write a PNG of replayed vs reference curves.")] = None,
) -> None:
    """Replay a recorded run: jumped rows are not read, the strategy extrapolates them."""
    from tribodem.cyclejump.recorded import replay_csv

    if strategy not in STRATEGIES:
        raise ConfigError(f"--strategy {strategy!r} is unknown; allowed: {', '.join(STRATEGIES)}")
    summary = replay_csv(strategy, input, params=parse_params(strategy, param or []), plot=plot)
    if as_json:
        typer.echo(json.dumps(summary, indent=2))
    else:
        for k, v in summary.items():
            if k != "params":
                typer.echo(f"{k}: {v}")
