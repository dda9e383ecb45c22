"""Condition-5 runs with the debris outlet and the feed.

    python docs/data/braking_feed/analyse.py RUN_DIR [RUN_DIR ...]

Per run (``summary.json`` and ``timeseries.csv`` of ``tribodem braking run``): how it
ended, the distance slid, whether the steady-state rule passed in the run (``[run]
until_steady``: it stops there), the steady wear rate (slope of the pad's mean wear depth
over the last two thirds), the middle- and last-third rates, the disc's rate over the
same span, the slabs fed, the least remaining thickness of each body after the first
millimetre, the scatter of 4-mm window rates after the run-in third, the contact
fraction and the wall time. Then the mean and the sd/mean of the steady rate over the
runs with its 95 % interval (chi-square). Markdown on stdout.
"""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path

import numpy as np
from scipy.stats import chi2


def _slope(x: np.ndarray, y: np.ndarray) -> float:
    return float(np.polyfit(x, y, 1)[0]) if x.size >= 2 and np.ptp(x) > 0 else float("nan")


def reading(d: Path) -> dict[str, object]:
    sm = json.loads((d / "summary.json").read_text())
    with open(d / "timeseries.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    col = {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}
    s, h = col["sliding_distance_m"], col["wear_depth_mean_pad_m"]
    after = s >= s[-1] / 3.0
    edges = np.arange(s[-1] / 3.0, s[-1] + 1e-12, 4e-3)
    win = np.array([_slope(s[(s >= a) & (s <= a + 4e-3)], h[(s >= a) & (s <= a + 4e-3)])
                    for a in edges[:-1]])
    late = s >= 1e-3
    feed = sm.get("feed") or {}
    return {"status": sm["status"], "slid": float(s[-1]), "steady": bool(sm["steady_reached"]),
            "rate": sm["wear_rate_steady_m_per_m"], "mid": sm["wear_rate_middle_third_m_per_m"],
            "last": sm["wear_rate_last_third_m_per_m"],
            "disc": _slope(s[after], col["wear_depth_mean_disc_m"][after]),
            "fed": feed.get("slabs_fed", {}),
            "left": [float(col[f"remaining_thickness_{b}_m"][late].min()) for b in ("pad",
                                                                                     "disc")],
            "win": float(win.std(ddof=1) / win.mean()) if win.size > 1 else float("nan"),
            "nwin": int(win.size), "contact": sm["contact_fraction"],
            "wall": sm["wall_time_s"], "particles": (sm["particles_initial"],
                                                     sm["particles_final"])}


def main(dirs: list[str]) -> None:
    print("| run | status | slid mm | rule passed in the run | steady rate um/mm (mid / "
          "last third) | disc rate um/mm | slabs fed pad / disc | least pad / disc left um | "
          "4-mm windows sd/mean (n) | contact fraction | particles start / end | wall s |\n"
          "|---|---|---|---|---|---|---|---|---|---|---|---|")
    rates = []
    for d in dirs:
        x = reading(Path(d))
        fed = x["fed"]
        print(f"| {Path(d).name} | {x['status']} | {x['slid'] * 1e3:.1f} | "
              f"{'yes' if x['steady'] else 'no'} | {x['rate'] * 1e3:.2f} ({x['mid'] * 1e3:.2f}"
              f" / {x['last'] * 1e3:.2f}) | {x['disc'] * 1e3:.2f} | {fed.get('pad', 0)} / "
              f"{fed.get('disc', 0)} | {x['left'][0] * 1e6:.0f} / {x['left'][1] * 1e6:.0f} | "
              f"{100 * x['win']:.0f} % ({x['nwin']}) | {x['contact']:.2f} | "
              f"{x['particles'][0]} / {x['particles'][1]} | {x['wall']:.0f} |")
        if x["status"] == "finished":
            rates.append(x["rate"])
    r = np.array(rates)
    if r.size >= 2:
        n = r.size
        cv = float(r.std(ddof=1) / r.mean())
        lo = cv * float(np.sqrt((n - 1) / chi2.ppf(0.975, n - 1)))
        hi = cv * float(np.sqrt((n - 1) / chi2.ppf(0.025, n - 1)))
        print(f"\nsteady rate over {n} finished runs: mean {r.mean() * 1e3:.2f} um/mm, "
              f"sd/mean {100 * cv:.1f} % (95 % interval {100 * lo:.0f}-{100 * hi:.0f} %)")


if __name__ == "__main__":
    main(sys.argv[1:])
