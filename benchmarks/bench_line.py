"""Plane-strain fretting of a cylinder on a flat: wall time of a long gross-slip Archard run
on one cross-section (the default of ``solver = "elastic"`` for a line contact) with and
without the default adaptive jumping, and the cost of a cycle there beside the n x n
window periodic along the cylinder's axis (``[elastic] line_model = "periodic-2d"``).

The case: a 6 mm cylinder on a flat at 20 N/mm, steel on steel (Hertz half-width 36 um),
amplitude 25 um, mu 0.6, Archard k 2.75e-14 / 5.5e-14 1/Pa (upper / lower), the default
n 256 and 48 increments a cycle, the window left out (sized for the scar). Prints one JSON
record per measurement (the fields of ``benchmarks/results.json``).

    .venv/bin/python benchmarks/bench_line.py            # jumping + cost per cycle
    .venv/bin/python benchmarks/bench_line.py --full     # also 20,000 cycles unjumped
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

from tribodem.fretting import run

CASE = {
    "contact": {"geometry": "cylinder_on_flat", "radius": 6e-3, "load_per_length": 2.0e4,
                "friction": 0.6, "amplitude": 25e-6},
    "wear": {"criterion": "archard", "archard_k_upper": 2.75e-14,
             "archard_k_lower": 5.5e-14},
    "output": {"vtk": False, "figures": False},
}


def timed(data: dict, folder: Path) -> tuple[float, dict]:
    t0 = time.perf_counter()
    res = run(data, str(folder))
    return time.perf_counter() - t0, res.summary


def record(case: str, value: float, unit: str, notes: str, **extra: object) -> None:
    print(json.dumps({"benchmark": "fretting", "case": case,
                      "command": ".venv/bin/python benchmarks/bench_line.py"
                                 + (" --full" if "unjumped" in case else ""),
                      "tribodem": round(value, 3), "unit": unit, "notes": notes, **extra}))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--full", action="store_true", help="also 20,000 cycles without jumping")
    args = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="bench_line_"))
    wall, s = timed({**CASE, "cycles": 20000, "jump": {"strategy": "adaptive"}}, tmp / "j")
    record("plane strain, 20,000 Archard cycles, adaptive jumping", wall, "s wall",
           f"{s['cycles_simulated']} cycles simulated; window {s['window_m'] * 1e3:.3g} mm, "
           f"{s['contact_case']['window_points']} points", target="<= 60 s")
    if args.full:
        wall, s = timed({**CASE, "cycles": 20000}, tmp / "f")
        record("plane strain, 20,000 Archard cycles unjumped", wall, "s wall",
               f"window {s['window_m'] * 1e3:.3g} mm", target="<= 600 s")
    per = {}
    for model in ("plane-strain", "periodic-2d"):
        data = {**CASE, "cycles": 20, "contact": {**CASE["contact"], "window": 3.64e-4},
                "elastic": {"line_model": model}}
        wall, _ = timed(data, tmp / model)
        per[model] = wall / 20
    record("cost of a cycle, n 256, 48 increments: one section vs the periodic window",
           per["plane-strain"], "s a cycle",
           f"periodic-2d {per['periodic-2d']:.3g} s a cycle",
           peer="periodic 256 x 256 window (tamaas)", peer_value=round(per["periodic-2d"], 3),
           ratio=round(per["periodic-2d"] / per["plane-strain"], 1))


if __name__ == "__main__":
    main()
