"""Cycle-jumping replay benchmark (issue 4): every strategy on two synthetic series.

Series (``tribodem.cyclejump.synthetic_two_phase_series``, 2000 cycles):
* linear: constant wear per cycle, no noise;
* two-phase: running-in (first-cycle rate 10x steady, tau = 50 cycles) then steady, 10 %
  Gaussian multiplicative noise, noise seeds 0..9.

Prints a markdown table: cycles saved, final and maximum relative difference, and the number
of runs with a jump inside the running-in transition (true rate > 1.5x steady).

    .venv/bin/python benchmarks/cyclejump_replay.py [--seeds 10]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tribodem.cyclejump import (  # noqa: E402
    make_strategy,
    replay,
    synthetic_two_phase_series,
    transition_end,
)

CONFIGS: list[tuple[str, str, dict]] = [
    ("constant", "N = 20 (sec 4.2.1)", {}),
    ("cojocaru", "q_y 0.02, q_e 0.05 (sec 4.2.2)", {}),
    ("moving", "x 8, q_y 1, q_e 0.1 % (table 4.1)", {}),
    ("overlapping", "x 8, q_y 1, q_e 0.1 % (table 4.2)", {}),
    ("adaptive", "defaults", {}),
    ("adaptive", "cubic throughout (degree_late=none)", {"degree_late": None}),
    ("adaptive", "fig 4.15 cap (max_jump_initial=15)", {"max_jump_initial": 15}),
    ("adaptive", "taylor_order=2 (appendix III)", {"taylor_order": 2}),
    ("adaptive", "degree=2", {"degree": 2}),
]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--cycles", type=int, default=2000)
    args = ap.parse_args()
    te = transition_end()
    lin = synthetic_two_phase_series(n=args.cycles, ratio=1.0, noise=0.0)
    noisy = [synthetic_two_phase_series(n=args.cycles, seed=s) for s in range(args.seeds)]
    print("| strategy | parameters | linear: saved | linear: final diff | two-phase: saved "
          "mean (min) | final diff mean (max) | max diff over run, worst | runs jumping in "
          "transition | runs >= 70 % saved at <= 5 % | s/run |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name, label, kw in CONFIGS:
        r = replay(make_strategy(name, **kw), *lin)
        t0 = time.perf_counter()
        rows = []
        for c, inc in noisy:
            q = replay(make_strategy(name, **kw), c, inc)
            rows.append((q.cycles_saved_fraction, q.relative_difference,
                         q.max_relative_difference, any(s < te for s, _ in q.jumps)))
        dt = (time.perf_counter() - t0) / len(noisy)
        a = np.array(rows, dtype=float)
        print(f"| {name} | {label} | {100 * r.cycles_saved_fraction:.1f} % "
              f"| {100 * r.relative_difference:.2g} % "
              f"| {100 * a[:, 0].mean():.1f} % ({100 * a[:, 0].min():.1f} %) "
              f"| {100 * a[:, 1].mean():.2f} % ({100 * a[:, 1].max():.2f} %) "
              f"| {100 * a[:, 2].max():.2f} % | {int(a[:, 3].sum())}/{len(noisy)} "
              f"| {int(np.sum((a[:, 0] >= 0.7) & (a[:, 1] <= 0.05)))}/{len(noisy)} "
              f"| {dt:.2f} |")


if __name__ == "__main__":
    main()
