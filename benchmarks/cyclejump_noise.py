"""Cycle-jumping under noise: the ``adaptive`` default against ``polynomial`` (docs/cyclejump.md).

Series: ``tribodem.cyclejump.synthetic_smooth_series(shape, n, noise, seed)`` with the
shapes linear, power (h ~ N^0.5), exponential (run-in 10x steady decaying over n/10
cycles) and two_phase (the same law with tau = 50). The noise is Gaussian multiplicative,
per cycle. The noisy rows use seeds 0..S-1; the noise-free rows use one series.

Strategies: ``make_strategy("adaptive")`` (:class:`~tribodem.cyclejump.SmoothJump`, the
step control on a fitted curve: what the fretting loop builds for ``jump.strategy =
"adaptive"``) and ``make_strategy("polynomial", decide_on="total")`` (the thesis' adaptive
polynomial strategy, the default before), both on their defaults (tol 1 %).

Prints one Markdown row per shape x n x noise: cycles saved % (mean, smallest over the
seeds) and final relative error % (mean, largest), then the mean wall time of one replay.

    .venv/bin/python benchmarks/cyclejump_noise.py [--seeds 3] [--cycles 1500 3000]
        [--noises 0 0.02 0.05 0.08]
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tribodem.cyclejump import (  # noqa: E402
    SMOOTH_SHAPES,
    JumpStrategy,
    make_strategy,
    replay,
    synthetic_smooth_series,
)

STRATEGIES: list[tuple[str, Callable[[], JumpStrategy]]] = [
    ("polynomial", lambda: make_strategy("polynomial", decide_on="total")),
    ("adaptive", lambda: make_strategy("adaptive")),
]


def cell(values: list[float], worst: Callable[[list[float]], float], digits: int) -> str:
    """'mean (worst)' of percentages; just the value for a single run."""
    mean = f"{np.mean(values):.{digits}f}"
    return mean if len(values) == 1 else f"{mean} ({worst(values):.{digits}f})"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=3, help="noise seeds per noisy row (3)")
    ap.add_argument("--cycles", type=int, nargs="+", default=[1500, 3000],
                    help="cycles per series (1500 3000)")
    ap.add_argument("--noises", type=float, nargs="+", default=[0.0, 0.02, 0.05, 0.08],
                    help="relative noise per cycle (0 0.02 0.05 0.08)")
    args = ap.parse_args()
    names = [name for name, _ in STRATEGIES]
    print("| shape | n | noise | " + " | ".join(
        f"{nm} saved % | {nm} final error %" for nm in names) + " |")
    print("|---|---|---|" + "---|---|" * len(names))
    wall = dict.fromkeys(names, 0.0)
    runs = 0
    for shape in SMOOTH_SHAPES:
        for n in args.cycles:
            for noise in args.noises:
                seeds = range(args.seeds) if noise > 0 else [0]
                series = [synthetic_smooth_series(shape, n=n, noise=noise, seed=s)
                          for s in seeds]
                runs += len(series)
                cells = []
                for name, make in STRATEGIES:
                    t0 = time.perf_counter()
                    res = [replay(make(), c, inc) for c, inc in series]
                    wall[name] += time.perf_counter() - t0
                    cells.append(cell([100 * r.cycles_saved_fraction for r in res], min, 0))
                    cells.append(cell([100 * r.relative_difference for r in res], max, 2))
                print(f"| {shape} | {n} | {100 * noise:.0f} % | " + " | ".join(cells) + " |",
                      flush=True)
    print()
    print("Mean wall time of one replay: " + ", ".join(
        f"{name} {wall[name] / runs:.2f} s" for name in names) + ".")


if __name__ == "__main__":
    main()
