"""The default cell with a 3x thicker pad slid up to 16 mm (condition 5).

    python docs/data/braking_long16/analyse.py RUN_DIR [RUN_DIR ...]

Per run (``tribodem braking run --condition 5 --config fixed.toml``, one folder each):
the summary's steady-state reading, then the pad's wear rate per sliding distance in
consecutive windows of ``WINDOW`` (least-squares slope of the mean pad wear depth against
the distance slid, ``timeseries.csv``), so one sees whether the rate still falls after the
4 mm the default runs stop at. Last: the per-packing scatter (sd/mean) of the steady rate
and of each window's rate over the runs that reached it. Markdown on stdout.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from tribodem.braking.compare import _series  # the sweep comparison's timeseries reader
from tribodem.braking.config import RunCfg
from tribodem.braking.steady import STEADY_BLOCK, STEADY_CUTS, _slope, steady_state

WINDOW = 2.0e-3  # m of sliding per window
#: ``until_steady`` as the default run does it: first test after 40 us, then every 8 us
FIRST_S = RunCfg().duration_s
BLOCK_S = STEADY_BLOCK * FIRST_S


def first_pass(ts: dict[str, np.ndarray], cuts: tuple[float, ...],
               tol: float = 0.15) -> tuple[float, float]:
    """Where the tool's own rule (``tribodem.braking.steady.steady_state`` with ``cuts``)
    first passes on the run's prefix, tested as ``until_steady`` tests it; (distance m,
    the steady rate it would report m/m), or NaNs if it never passes."""
    t, s, h = ts["time_s"], ts["sliding_distance_m"], ts["wear_depth_mean_pad_m"]
    at = FIRST_S
    while at <= t[-1] + 1e-12:
        m = t <= at + 1e-12
        st = steady_state(s[m], h[m], tol, cuts)
        if st["steady"]:
            return float(s[m][-1]), float(st["rate"])
        at += BLOCK_S
    return float("nan"), float("nan")


def window_rates(ts: dict[str, np.ndarray]) -> list[float]:
    """Wear rate of the pad (m of mean depth per m slid) in each full window (the
    steady-state rule's own least-squares slope)."""
    s = ts["sliding_distance_m"]
    d = ts["wear_depth_mean_pad_m"]
    out = []
    for k in range(int(s[-1] // WINDOW)):
        m = (s >= k * WINDOW) & (s <= (k + 1) * WINDOW)
        out.append(_slope(s[m], d[m]) if m.sum() >= 3 else float("nan"))
    return out


def _at(at: float, rate: float) -> str:
    return "no pass" if at != at else f"{at * 1e3:.2f} / {rate * 1e3:.2f}"


def main(dirs: list[Path]) -> None:
    rows, windows, passes = [], [], []
    for d in dirs:
        s = json.loads((d / "summary.json").read_text())
        ts = _series(d)
        windows.append(window_rates(ts))
        passes.append((first_pass(ts, (1.0,)), first_pass(ts, STEADY_CUTS)))
        rows.append((d.name, s))
    print("| run | slid mm | steady | steady rate um/mm | mid / last third um/mm | run-in mm"
          " / um | contact fraction | pad max depth um | rate per 2-mm window, um/mm |")
    print("|---|---|---|---|---|---|---|---|---|")
    for (name, s), w in zip(rows, windows, strict=True):
        print(f"| {name} | {s['simulated_sliding_distance_m'] * 1e3:.2f} | "
              f"{'yes' if s['steady_reached'] else 'no'} | "
              f"{s['wear_rate_steady_m_per_m'] * 1e3:.2f} | "
              f"{s['wear_rate_middle_third_m_per_m'] * 1e3:.2f} / "
              f"{s['wear_rate_last_third_m_per_m'] * 1e3:.2f} | "
              f"{s['run_in_distance_m'] * 1e3:.2f} / {s['run_in_depth_m'] * 1e6:.1f} | "
              f"{s['contact_fraction']:.2f} | {s['wear_depth_max_pad_m'] * 1e6:.1f} | "
              + ", ".join(f"{r * 1e3:.2f}" for r in w) + " |")
    print("\n| run | the thirds' test alone: first pass (tested every 8 us from 40 us), mm"
          " / rate it reports um/mm | with the cuts to 90 and 80 % (`STEADY_CUTS`) | the "
          "run's second half, um/mm |\n|---|---|---|---|")
    for (name, _), ((a0, r0), (a1, r1)), w in zip(rows, passes, windows, strict=True):
        late = np.mean(w[len(w) // 2:]) if w else float("nan")
        print(f"| {name} | {_at(a0, r0)} | {_at(a1, r1)} | {late * 1e3:.2f} |")
    depth = np.array([s["wear_depth_mean_pad_m"] for _, s in rows])
    late = np.array([np.mean(w[len(w) // 2:]) for w in windows])
    if len(rows) > 1:
        print(f"\npad mean wear depth at the end over {len(rows)} runs: mean "
              f"{depth.mean() * 1e6:.1f} um, sd/mean {depth.std(ddof=1) / depth.mean():.0%}; "
              f"rate over the last half (mean of its windows): mean {late.mean() * 1e3:.2f}"
              f" um/mm, sd {late.std(ddof=1) * 1e3:.2f} um/mm")
    rates = np.array([s["wear_rate_steady_m_per_m"] for _, s in rows])
    print(f"\nsteady rate over {len(rates)} runs: mean {rates.mean() * 1e3:.2f} um/mm, "
          f"sd/mean {rates.std(ddof=1) / rates.mean():.0%}" if len(rates) > 1 else "")
    for k in range(max(len(w) for w in windows)):
        r = np.array([w[k] for w in windows if len(w) > k])
        if len(r) > 1:
            print(f"window {k * WINDOW * 1e3:.0f}-{(k + 1) * WINDOW * 1e3:.0f} mm: {len(r)} runs,"
                  f" mean {r.mean() * 1e3:.2f} um/mm, sd/mean {r.std(ddof=1) / r.mean():.0%}")


if __name__ == "__main__":
    main([Path(a) for a in sys.argv[1:]])
