"""A recorded per-cycle series replayed with a cycle-jumping strategy (``tribodem jump
replay``).

The input CSV has columns ``cycle,increment`` (wear per cycle, as appendix III of Lu (2018)
reads ``Result.csv``); other columns are ignored. :func:`read_increments_csv` reads and
checks it, :func:`replay_csv` replays it (:func:`~tribodem.cyclejump.strategies.replay`)
and returns the summary the command prints, :func:`plot_replay` draws the replayed against
the reference curve. Bad input raises ``ConfigError`` naming the file, the line, the column
and what is allowed.
"""

from __future__ import annotations

import csv
import math
import os
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from tribodem.cyclejump.registry import STRATEGIES, make_strategy
from tribodem.cyclejump.strategies import JumpStrategy, ReplayResult, replay
from tribodem.io.config import ConfigError
from tribodem.io.results import write_figure

REQUIRED_COLUMNS = ("cycle", "increment")


def read_increments_csv(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """Read ``cycle,increment`` rows; refuse anything a replay cannot use (``ConfigError``).

    Cycles must be integers, strictly increasing and consecutive (one row per cycle);
    increments must be finite numbers.
    """
    p = Path(path)
    if p.is_dir():
        raise ConfigError(f"--input = '{p}': is a folder; allowed: a CSV file")
    if not p.is_file():
        raise ConfigError(f"--input = '{p}': file does not exist")
    try:
        with p.open(newline="") as fh:
            rows = list(csv.reader(fh))
    except (UnicodeDecodeError, csv.Error, OSError) as err:
        raise ConfigError(f"input file '{p}' is not a readable CSV: {err}") from None
    rows = [r for r in rows if r and any(x.strip() for x in r)]
    if not rows:
        raise ConfigError(f"input file '{p}' is empty; expected a header 'cycle,increment'")
    header = [h.strip().lower() for h in rows[0]]
    missing = [c for c in REQUIRED_COLUMNS if c not in header]
    if missing:
        raise ConfigError(
            f"input file '{p}': missing column(s) {', '.join(repr(m) for m in missing)}; "
            f"found {rows[0]!r}, required header columns: 'cycle' and 'increment'"
        )
    ic, ii = header.index("cycle"), header.index("increment")
    cycles: list[float] = []
    incs: list[float] = []
    for lineno, row in enumerate(rows[1:], start=2):
        vals = []
        for col, idx in (("cycle", ic), ("increment", ii)):
            raw = row[idx].strip() if idx < len(row) else ""
            try:
                v = float(raw)
            except ValueError:
                raise ConfigError(
                    f"input file '{p}', line {lineno}, column '{col}': value {raw!r} is not "
                    f"a number (allowed: finite decimal numbers)"
                ) from None
            if not math.isfinite(v):
                raise ConfigError(
                    f"input file '{p}', line {lineno}, column '{col}': value {raw!r} is not "
                    f"finite (allowed: finite decimal numbers)"
                )
            vals.append(v)
        c, inc = vals
        if c != int(c):
            raise ConfigError(f"input file '{p}', line {lineno}, column 'cycle': value {c:g} "
                              f"is not an integer cycle number")
        if cycles and c <= cycles[-1]:
            raise ConfigError(
                f"input file '{p}', line {lineno}, column 'cycle': value {c:g} is not greater "
                f"than the previous cycle {cycles[-1]:g} (cycles must be strictly increasing)"
            )
        if cycles and c != cycles[-1] + 1:
            raise ConfigError(
                f"input file '{p}', line {lineno}, column 'cycle': value {c:g} skips cycles "
                f"after {cycles[-1]:g} (one row per cycle, consecutive cycle numbers)"
            )
        cycles.append(c)
        incs.append(inc)
    return np.asarray(cycles), np.asarray(incs)


def plot_replay(result: ReplayResult, path: str | Path) -> Path:
    """Replayed vs reference cumulative curves and relative difference (seed figs 4.13-4.16)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ref_c, ref = result.reference_cycles, np.asarray(result.reference, dtype=float)
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7, 6), sharex=True,
                                   gridspec_kw={"height_ratios": [3, 1]})
    ax1.plot(ref_c, ref, color="tab:orange", lw=2, label="without cycle-jumping (reference)")
    ax1.plot(result.cycles, result.values, color="tab:blue", lw=1, marker=".", ms=2,
             label=f"{result.strategy} cycle-jumping")
    for start, n in result.jumps:
        ax1.axvspan(start, start + n, color="tab:blue", alpha=0.08, lw=0)
    ax1.set_ylabel("cumulative value (e.g. wear depth)")
    ax1.set_title(f"{result.strategy}: {100 * result.cycles_saved_fraction:.1f} % of cycles "
                  f"saved, final difference {100 * result.relative_difference:.2f} %")
    ax1.legend(loc="upper left")
    idx = np.searchsorted(ref_c, result.cycles)
    rr = np.abs(result.values - ref[idx]) / np.where(ref[idx] != 0, np.abs(ref[idx]), np.inf)
    ax2.plot(result.cycles, 100 * rr, color="tab:red", lw=1)
    ax2.set_xlabel("cycle")
    ax2.set_ylabel("rel. difference (%)")
    fig.tight_layout()

    return write_figure(path, fig)


def make_checked_strategy(strategy: str, params: Mapping[str, Any] | None = None
                          ) -> JumpStrategy:
    """The strategy named ``strategy`` with keyword parameters ``params``; ``ConfigError``
    for an unknown name or a value the strategy refuses."""
    if strategy not in STRATEGIES:
        raise ConfigError(f"--strategy {strategy!r} is unknown; allowed: {', '.join(STRATEGIES)}")
    given = dict(params or {})
    try:
        return make_strategy(strategy, **given)
    except (TypeError, ValueError) as err:
        # name the parameter the strategy refused, with its value (its message may not)
        named = [k for k in given if re.search(rf"\b{re.escape(k)}\b", str(err))] or list(given)
        shown = ", ".join(f"--param {k}={given[k]!r}" for k in named)
        raise ConfigError(f"strategy '{strategy}'{': ' + shown if shown else ''}: {err}"
                          ) from None


def replay_csv(strategy: str, input: str | os.PathLike[str], *,
               params: Mapping[str, Any] | None = None,
               plot: str | os.PathLike[str] | None = None) -> dict[str, Any]:
    """Replay the ``cycle,increment`` series of CSV file ``input`` with strategy
    ``strategy`` (a name of :data:`~tribodem.cyclejump.registry.STRATEGIES`, keyword
    parameters ``params``): jumped rows are not read, the strategy extrapolates them.

    Returns the summary ``tribodem jump replay --json`` prints (:meth:`ReplayResult.summary`
    with ``input`` and, when ``plot`` names a PNG file to write, ``plot``). Everything is
    checked before any work (``ConfigError``).
    """
    strat = make_checked_strategy(strategy, params)
    if plot is not None:
        from tribodem.io.runs import check_out_file

        check_out_file(plot, "--plot")
    cycles, incs = read_increments_csv(input)
    need = strat.foundation + 1
    if len(cycles) < need:
        raise ConfigError(
            f"input file '{input}' has {len(cycles)} data rows; the '{strategy}' strategy "
            f"needs at least {need} (its foundation of {strat.foundation} simulated cycles "
            f"plus one to jump over)"
        )
    result = replay(strat, cycles, incs)
    summary = result.summary()
    summary["input"] = str(input)
    if plot is not None:
        summary["plot"] = str(plot_replay(result, plot))
    return summary
