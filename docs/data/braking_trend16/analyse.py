"""The trend study on the 16-junction default cell, from the members finished so far.

Reads every finished member of a braking sweep folder (``condition_k/seed_s/summary.json``)
and prints, in markdown: one row per member (contact fraction, pad wear depth, wear rate
per mm slid, strong force chains, broken bonds by mode and place on the pad), the means per
condition, and, where at least two packings have all five conditions, the sweep's
comparison on those packings (``tribodem.braking.compare.write_comparison`` into OUT: the
trends per braking time, the wear depth after the same 40 us, and per sliding distance,
the steady wear rate, with paired 95 % intervals).

    python docs/data/braking_trend16/analyse.py SWEEP_DIR [OUT_DIR]
"""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from tribodem.braking.compare import steady_rate, write_comparison
from tribodem.braking.measure import Reference, breaks_by_place, mean_surface
from tribodem.braking.model import DISC, PAD
from tribodem.braking.summary import contact_after_run_in

PLACES = [(f"broken_bonds_pad_{p}_{m}", f"pad {p} {m}") for p in ("surface", "bulk")
          for m in ("tensile", "shear")]


def fill_in(s: dict, folder: Path) -> dict:
    """A summary written before the contact after the run-in and the breaks by place
    were measured: both computed here from the member's time series and final
    checkpoint (``contact_after_run_in``, ``breaks_by_place`` on the checkpoint's bonds
    and reference positions), as the run's own summary would give them."""
    if "contact_fraction_after_run_in" not in s:
        with (folder / "timeseries.csv").open() as fh:
            rows = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(fh)]
        s.update(contact_after_run_in(rows))
    if "broken_bonds_pad_surface_tensile" not in s:
        z = np.load(folder / "checkpoint.npz")
        pos, rad, grp, w = z["x2_a_ref_pos"], z["x2_a_ref_radius"], z["p_group"], s["cell_width_m"]
        ref = Reference(pos=pos, radius=rad, group=grp, phi={}, width=w,
                        surface={b: mean_surface(pos, rad, grp, b, w) for b in (DISC, PAD)})
        bonds = SimpleNamespace(i=z["x0_i"], j=z["x0_j"], mode=z["x0_mode"])
        s.update(breaks_by_place(SimpleNamespace(bonds=bonds), ref))  # type: ignore[arg-type]
    return s


def finished(sweep: Path) -> dict[tuple[int, int], tuple[dict, Path]]:
    """(condition, packing) -> (summary, folder) of the finished members."""
    out = {}
    for f in sorted(sweep.glob("condition_*/seed_*/summary.json")):
        s = json.loads(f.read_text())
        if s.get("status") == "finished":
            k = int(f.parent.parent.name.split("_")[1])
            out[(k, int(f.parent.name.split("_")[1]))] = (fill_in(s, f.parent), f.parent)
    return out


def main() -> None:
    """Print the tables; the comparison on complete packings into OUT_DIR if given."""
    sweep = Path(sys.argv[1])
    runs = finished(sweep)
    print("| condition | packing | contact fraction (after run-in) | pad wear depth (um) | "
          "rate (um/mm) | "
          "strong chains | breaks (tensile/shear) | " + " | ".join(n for _, n in PLACES)
          + " | wall s |")
    print("|---|---|---|---|---|---|---|" + "---|" * len(PLACES) + "---|")
    for (k, s), (r, _) in sorted(runs.items()):
        places = " | ".join(f"{r.get(key, float('nan')):.0f}" for key, _ in PLACES)
        cf_late = r.get("contact_fraction_after_run_in", float("nan"))
        print(f"| {k} | {s} | {r['contact_fraction']:.3f} ({cf_late:.2f}) | "
              f"{r['wear_depth_mean_m'] * 1e6:.2f} | {steady_rate(r) * 1e3:.2f} | "
              f"{r['strong_force_chains']:.0f} | {r['broken_bonds_tensile']:.0f}/"
              f"{r['broken_bonds_shear']:.0f} | {places} | {r['wall_time_s']:.0f} |")
    cf = [r["contact_fraction"] for r, _ in runs.values()]
    if cf:
        print(f"\n{len(runs)} members; contact fraction {min(cf):.3f}-{max(cf):.3f}; "
              f"wall time {np.mean([r['wall_time_s'] for r, _ in runs.values()]):.0f} s a "
              "member on average")
    packs = sorted({s for _, s in runs})
    complete = [s for s in packs if all((k, s) in runs for k in range(1, 6))]
    if len(complete) >= 2 and len(sys.argv) > 2:
        out = Path(sys.argv[2])
        out.mkdir(parents=True, exist_ok=True)
        by_k = {k: [runs[(k, s)] for s in complete] for k in range(1, 6)}
        write_comparison(out, by_k, 0.0, f"{len(complete)} complete packings", False)
        print(f"\ncomparison on packings {complete}: {out / 'comparison.md'}")
    else:
        print(f"\ncomplete packings (all five conditions): {complete}; the comparison needs "
              "two")


if __name__ == "__main__":
    main()
