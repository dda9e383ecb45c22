"""Cycle-jumping replay benchmark: every strategy on two synthetic series.

Series (``tribodem.cyclejump.synthetic_two_phase_series``, 2000 cycles):
* linear: constant wear per cycle, no noise;
* two-phase: running-in (first-cycle rate 10x steady, tau = 50 cycles) then steady, 10 %
  Gaussian multiplicative noise, noise seeds 0..9.

Prints a markdown table: cycles saved, final and maximum relative difference, and the number
of runs with a jump inside the running-in transition (true rate > 1.5x steady).

    .venv/bin/python benchmarks/cyclejump_replay.py [--seeds 10]

``--smooth`` (the step control): every strategy on the smooth shapes of
``tribodem.cyclejump.synthetic_smooth_series`` (linear, power law h ~ N^0.5, exponential
run-in r_s + 9 r_s exp(-N / (n/10)), two-phase), 3000 cycles, without noise and with 2 %
multiplicative noise (noise seeds 0..S-1). One Markdown row per strategy setting, one column
per shape and noise: "cycles saved % / final relative error %" (noisy columns: mean saved
(smallest) / largest error over the seeds).

    .venv/bin/python benchmarks/cyclejump_replay.py --smooth [--seeds 5] [--cycles 3000]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tribodem.cyclejump import (  # noqa: E402
    SMOOTH_SHAPES,
    make_strategy,
    replay,
    synthetic_smooth_series,
    synthetic_two_phase_series,
    transition_end,
)

CONFIGS: list[tuple[str, str, dict]] = [
    ("constant", "N = 20 (sec 4.2.1)", {}),
    ("cojocaru", "q_y 0.02, q_e 0.05 (sec 4.2.2)", {}),
    ("moving", "x 8, q_y 1, q_e 0.1 % (table 4.1)", {}),
    ("overlapping", "x 8, q_y 1, q_e 0.1 % (table 4.2)", {}),
    ("adaptive", "defaults (a fitted curve)", {}),
    ("polynomial", "defaults", {}),
    ("polynomial", "cubic throughout (degree_late=none)", {"degree_late": None}),
    ("polynomial", "fig 4.15 cap (max_jump_initial=15)", {"max_jump_initial": 15}),
    ("polynomial", "taylor_order=2 (appendix III)", {"taylor_order": 2}),
    ("polynomial", "degree=2", {"degree": 2}),
]


SMOOTH_CONFIGS: list[tuple[str, str, dict]] = [
    ("constant", "defaults (eq 2.20, no step control)", {}),
    ("constant", "step_control=error (tol 1 %)", {"step_control": "error"}),
    ("cojocaru", "defaults (tol = q_e/2 = 2.5 %)", {}),
    ("cojocaru", "step_control=seed (eq 4.2 alone)", {"step_control": "seed"}),
    ("cojocaru", "q_e = 2 % (tol 1 %)", {"q_e": 0.02}),
    ("moving", "defaults (tol = q_e/2 = 0.05 %)", {}),
    ("moving", "step_control=seed (eq 4.4 alone)", {"step_control": "seed"}),
    ("moving", "q_e = 2 % (tol 1 %)", {"q_e": 0.02}),
    ("overlapping", "defaults (tol = q_e/2 = 0.05 %)", {}),
    ("overlapping", "step_control=seed (eq 4.6 alone)", {"step_control": "seed"}),
    ("overlapping", "q_e = 2 % (tol 1 %)", {"q_e": 0.02}),
    ("adaptive", "defaults (a fitted curve, tol 1 %)", {}),
    ("adaptive", "tol 0.5 %", {"tol": 0.005}),
    ("adaptive", "tol 2 %", {"tol": 0.02}),
    ("polynomial", "defaults (tol = q_e/2 = 1 %)", {}),
    ("polynomial", "step_control=seed (the thesis' sections 4.3-4.4)", {"step_control": "seed"}),
]


def smooth_table(cycles: int, seeds: int) -> None:
    """Markdown table of every strategy on the smooth shapes (see the module docstring)."""
    noises = (0.0, 0.02)
    series = {(sh, nz): [synthetic_smooth_series(sh, n=cycles, noise=nz, seed=s)
                         for s in (range(seeds) if nz else [0])]
              for sh in SMOOTH_SHAPES for nz in noises}
    cols = [(sh, nz) for sh in SMOOTH_SHAPES for nz in noises]
    print("| strategy | setting | " + " | ".join(
        f"{sh}{', 2 % noise' if nz else ''}" for sh, nz in cols) + " | s/run |")
    print("|---|---|" + "---|" * len(cols) + "---|")
    for name, label, kw in SMOOTH_CONFIGS:
        cells = []
        t0, runs = time.perf_counter(), 0
        for key in cols:
            res = [replay(make_strategy(name, **kw), c, inc) for c, inc in series[key]]
            runs += len(res)
            saved = [100 * r.cycles_saved_fraction for r in res]
            err = 100 * max(r.relative_difference for r in res)
            low = f" ({min(saved):.0f})" if len(res) > 1 else ""
            cells.append(f"{np.mean(saved):.0f}{low} / {err:.2g}")
        dt = (time.perf_counter() - t0) / runs
        print(f"| {name} | {label} | " + " | ".join(cells) + f" | {dt:.2f} |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=None,
                    help="noise seeds (default 10; 5 with --smooth)")
    ap.add_argument("--cycles", type=int, default=None,
                    help="cycles per series (default 2000; 3000 with --smooth)")
    ap.add_argument("--smooth", action="store_true",
                    help="the smooth-shape table of the step control")
    args = ap.parse_args()
    if args.smooth:
        smooth_table(args.cycles or 3000, 5 if args.seeds is None else args.seeds)
        return
    args.seeds = 10 if args.seeds is None else args.seeds
    args.cycles = args.cycles or 2000
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
