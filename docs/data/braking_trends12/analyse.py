"""Seed 000's two trends asked of the saturated wear depth, not of the run-in.

    python docs/data/braking_trends12/analyse.py C5_DIR_PATTERN C1_DIR_PATTERN C3_DIR_PATTERN
        [--skip K,K,...]

Each pattern holds ``{k}`` for the packing (e.g. ``runs/fixed_p{k}``); ``A|B`` takes the
first of A, B that holds a finished run for packing k. The runs are the
default cell with the 324-um pad (``docs/data/braking_long16/fixed.toml``) of conditions 5
(21 kN, 1200 r/min), 1 (13 kN, 1200 r/min) and 3 (21 kN, 800 r/min) on the same packings
(``[geometry] seed`` K), slid at least ``AT`` (12 mm). Per packing and condition: the pad's
mean wear depth at 1.9 mm (the seed's 40 us at 1200 r/min: the run-in) and at ``AT``, and
the rate over the last ``LATE`` of it (is the depth saturated?). Then the paired changes
13 -> 21 kN (condition 1 -> 5) and 800 -> 1200 r/min (3 -> 5) with their 95 % intervals
(``tribodem.braking.compare``, as the sweeps compute them), beside the seed's +24.75 % and
+16.22 %. Conditions are compared at the same sliding distance (the saturated depth is
reached in distance, not in time); the time each took is printed, and the changes at the
same time (255 us: 12 mm at 1200 r/min, 8 mm at 800 r/min) beside them, as the seed
compares its conditions at the same braking time. Markdown on stdout.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from tribodem.braking.compare import (
    SEED_CHANGES,
    _series,
    change_with_error,
    ci95,
    seed_inside,
)
from tribodem.braking.conditions import get_condition
from tribodem.braking.config import RunCfg
from tribodem.braking.steady import _slope

AT = 12.0e-3  # m slid: where the depth is compared
V5 = get_condition(5).speed_m_s  # m/s: condition 5 (1200 r/min)
RUN_IN = RunCfg().duration_s * V5  # m: the seed's 40 us at condition 5's speed (1.9 mm)
LATE = 2.0e-3  # m: the window of the late rate
#: the seed's two end-to-end changes (label, from condition, %) to condition 5
SEED = {f"{name} ({a} -> {b})": (a, pct) for name, a, b, pct, _ in SEED_CHANGES
        if (a, b) in ((1, 5), (3, 5))}


def reading(d: Path) -> dict[str, float]:
    """Depths at RUN_IN and AT, the late rate (m/m) and the time to AT, of one run."""
    ts = _series(d)
    s, h, t = ts["sliding_distance_m"], ts["wear_depth_mean_pad_m"], ts["time_s"]
    if s[-1] < AT * (1 - 1e-3):
        raise SystemExit(f"{d}: slid {s[-1] * 1e3:.2f} mm, less than {AT * 1e3:.0f} mm")
    m = (s >= AT - LATE) & (s <= AT)
    return {"run_in": float(np.interp(RUN_IN, s, h)), "at": float(np.interp(AT, s, h)),
            "late": _slope(s[m], h[m]), "t_at": float(np.interp(AT, s, t)),
            "same_time": float(np.interp(AT / V5, t, h))}


def run_dir(pattern: str, k: int) -> Path | None:
    """The first alternative of ``pattern`` (``A|B``) with a finished run for packing k."""
    for alt in pattern.split("|"):
        d = Path(alt.format(k=k))
        if (d / "summary.json").exists():
            return d
    return None


def main(patterns: list[str], skip: tuple[int, ...] = ()) -> None:
    conds = dict(zip((5, 1, 3), patterns, strict=True))
    ks = [k for k in range(100) if k not in skip and all(run_dir(p, k) is not None
                                                         for p in conds.values())]
    r = {c: [reading(run_dir(p, k)) for k in ks] for c, p in conds.items()}
    print(f"packings: {ks}\n")
    print("| condition | depth at 1.9 mm, um (mean, sd/mean) | depth at 12 mm, um (mean, "
          "sd/mean) | rate over 10-12 mm, um/mm (mean) | time to 12 mm, us |\n"
          "|---|---|---|---|---|")
    for c in conds:
        a = np.array([x["run_in"] for x in r[c]])
        b = np.array([x["at"] for x in r[c]])
        late = np.array([x["late"] for x in r[c]])
        print(f"| {c} | {a.mean() * 1e6:.1f} ({a.std(ddof=1) / a.mean():.0%}) | "
              f"{b.mean() * 1e6:.1f} ({b.std(ddof=1) / b.mean():.0%}) | "
              f"{late.mean() * 1e3:.2f} | {r[c][0]['t_at'] * 1e6:.0f} |")
    print("\n| trend | seed | ours at 1.9 mm (run-in) | ours at 12 mm (saturated) | seed inside "
          "the 12-mm interval | ours at the same time, 255 us |\n|---|---|---|---|---|---|")
    n = len(ks)
    for name, (c0, seed_pct) in SEED.items():
        cells = []
        for key in ("run_in", "at", "same_time"):
            a = np.array([x[key] for x in r[c0]])
            b = np.array([x[key] for x in r[5]])
            pct, se = change_with_error(a, b, paired=True)
            cells.append((pct, ci95(se, n)))
        inside = seed_inside(seed_pct, *cells[1])
        pm = [f"{p:+.1f} +- {h:.1f} %" for p, h in cells]
        print(f"| {name} | {seed_pct:+.2f} % | {pm[0]} | {pm[1]} | {'yes' if inside else 'no'}"
              f" | {pm[2]} |")
    print(f"\n(+- : half-width of the paired 95 % interval over {n} packings, Student t)")


if __name__ == "__main__":
    args = sys.argv[1:]
    skip: tuple[int, ...] = ()
    if "--skip" in args:
        i = args.index("--skip")
        skip = tuple(int(k) for k in args[i + 1].split(","))
        del args[i:i + 2]
    main(args, skip)
