"""How the run-to-run scatter of a wear rate falls with the sliding window it is measured
over (docs/braking.md): for every finished member of one condition of a braking
sweep, the pad's mean wear depth is read from timeseries.csv; after the run-in (the first
third of the distance) the rest is cut into windows of length L, and the rate of each
window, (depth at the end - depth at the start) / L, is pooled over the members. If the
wear came in independent events, sd/mean would fall as L^-1/2 (the last column constant).

    python docs/data/braking_sweep_105/window_scatter.py SWEEP_DIR [CONDITION [PACKINGS]]

(PACKINGS: only the members seed_0 .. seed_{PACKINGS-1}, as the sweep's comparison.)
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from tribodem.braking.compare import _series


def members(sweep: Path, condition: int, packings: int | None = None) -> list[np.ndarray]:
    """(sliding distance m, pad mean wear depth m) of each finished member."""
    out = []
    for d in sorted((sweep / f"condition_{condition}").glob("seed_*")):
        if packings is not None and int(d.name.split("_")[1]) >= packings:
            continue
        s = d / "summary.json"
        if not s.exists() or json.loads(s.read_text()).get("status") != "finished":
            continue
        ts = _series(d)  # the sweep comparison's own reader of timeseries.csv
        out.append(np.c_[ts["sliding_distance_m"], ts["wear_depth_mean_pad_m"]])
    return out


def main() -> None:
    sweep, condition = Path(sys.argv[1]), int(sys.argv[2]) if len(sys.argv) > 2 else 5
    packings = int(sys.argv[3]) if len(sys.argv) > 3 else None
    runs = members(sweep, condition, packings)
    s_end = min(r[-1, 0] for r in runs)
    s0 = s_end / 3
    print(f"condition {condition}: {len(runs)} finished members, {s_end * 1e6:.0f} um slid; "
          f"windows after the first third ({s0 * 1e6:.0f} um)")
    print("| window um | windows | mean rate um/mm | sd um/mm | sd/mean "
          "| sd/mean x sqrt(L / 1 mm) |")
    print("|---|---|---|---|---|---|")
    for parts in (12, 6, 4, 2, 1):
        L = (s_end - s0) / parts
        rates = []
        for r in runs:
            for k in range(parts):
                a, b = s0 + k * L, s0 + (k + 1) * L
                rates.append((np.interp(b, r[:, 0], r[:, 1]) - np.interp(a, r[:, 0], r[:, 1])) / L)
        x = np.array(rates)
        cv = x.std(ddof=1) / x.mean()
        print(f"| {L * 1e6:.0f} | {x.size} | {x.mean() * 1e3:.2f} | {x.std(ddof=1) * 1e3:.2f} | "
              f"{cv:.2f} | {cv * np.sqrt(L / 1e-3):.2f} |")


if __name__ == "__main__":
    main()
