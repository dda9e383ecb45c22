"""Copy finished braking runs into this folder: summary.json and the time series reduced to
the columns the analysis and a reader need.

    python docs/data/braking_trends12/collect.py [--to DIR] RUN_DIR [RUN_DIR ...]

Each RUN_DIR (e.g. ``runs/c1_p7``) lands here (or in DIR) under its own name.
"""

from __future__ import annotations

import csv
import shutil
import sys
from pathlib import Path

HERE = Path(__file__).parent
COLUMNS = ("time_s", "sliding_distance_m", "wear_depth_mean_pad_m", "broken_bonds",
           "debris_particles", "transfer_layer_thickness_m", "interface_force_N",
           "delaminated_particles_pad", "ejected_depth_pad_m", "wear_depth_mean_disc_m",
           "remaining_thickness_disc_m", "remaining_thickness_pad_m")


def collect(run: Path, to: Path = HERE) -> None:
    """Copy one finished run (summary.json, reduced timeseries.csv) into to/run.name."""
    if not (run / "summary.json").exists():
        raise SystemExit(f"{run}: no summary.json (not finished)")
    out = to / run.name
    out.mkdir(exist_ok=True)
    shutil.copyfile(run / "summary.json", out / "summary.json")
    with open(run / "timeseries.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    cols = [c for c in COLUMNS if c in rows[0]]
    with open(out / "timeseries.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(cols)
        w.writerows([r[c] for c in cols] for r in rows)


if __name__ == "__main__":
    args = sys.argv[1:]
    to = HERE
    if args[:1] == ["--to"]:
        to, args = Path(args[1]), args[2:]
    for arg in args:
        collect(Path(arg), to)
