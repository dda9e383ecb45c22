"""The plane-strain section of the elastic backend against the 2D CalculiX backend (``fe``,
elastic, plane strain) over 20 gross-slip Archard cycles: the worn profiles' maximum depth
and width on both bodies.

The case: a 6 mm cylinder on a flat at 20 N/mm, steel on steel (Hertz half-width 36 um),
mu 0.6, amplitude 25 um, local Archard k 1.375e-13 / 2.75e-13 1/Pa (upper / lower: each
cycle wears 0.047 elastic approaches, inside the default ``wear.update_tolerance``, so both
backends update the geometry once a cycle), window 0.364 mm, n 128 and 24 increments a
cycle for fe; the section also at n 256 and 48 increments, in gross slip and with the
Ciavarella-Jaeger partial slip (``[contact] regime``), fe's own regime being Coulomb
friction in the FE contact. The width is where the depth exceeds 5 % and 50 % of its
maximum, interpolated linearly, against the finest fe mesh run. The runs resume: ``--out``
keeps them (fe at h = a/4 is 10-15 min on one core, ``--fine`` adds h = a/8, about 35 min,
and compares with it).

    .venv/bin/python benchmarks/line_vs_fe.py --out runs/line_vs_fe [--fine]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from tribodem.fretting import run

CASE: dict[str, Any] = {
    "cycles": 20,
    "contact": {"geometry": "cylinder_on_flat", "radius": 6e-3, "load_per_length": 2.0e4,
                "friction": 0.6, "amplitude": 25e-6, "n": 128, "n_increments": 24,
                "window": 3.64e-4},
    "wear": {"criterion": "archard", "archard_k_upper": 1.375e-13,
             "archard_k_lower": 2.75e-13},
    "output": {"vtk": False, "figures": False},
}


def variants(fine: bool) -> dict[str, dict[str, Any]]:
    """Run name -> config: fe (the reference) first, then the plane-strain section."""
    out: dict[str, dict[str, Any]] = {
        "fe_a4": {**CASE, "solver": "fe", "fe": {"h_over_a": 0.25, "retries": 4}}}
    if fine:
        out["fe_a8"] = {**CASE, "solver": "fe", "fe": {"h_over_a": 0.125, "retries": 4}}
    for regime in ("gross", "ciavarella-jaeger"):
        for n, inc in ((128, 24), (256, 48)):
            out[f"line_{regime}_{n}"] = {
                **CASE, "contact": {**CASE["contact"], "n": n, "n_increments": inc,
                                    "regime": regime}}
    return out


def profiles(folder: Path) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """body -> (x m, depth m) of the last cycle in ``folder/profiles.csv``."""
    d = pd.read_csv(folder / "profiles.csv")
    last = d[d.cycle == d.cycle.max()]
    return {b: (g.x_m.to_numpy(), g.wear_depth_m.to_numpy())
            for b, g in last.sort_values("x_m").groupby("body")}


def width(x: np.ndarray, w: np.ndarray, frac: float) -> float:
    """Length (m) over which ``w`` exceeds ``frac`` x its maximum, the crossings
    interpolated linearly."""
    t = frac * w.max()
    i = np.nonzero(w > t)[0]
    i0, i1 = i[0], i[-1]
    left = x[i0 - 1] + (t - w[i0 - 1]) / (w[i0] - w[i0 - 1]) * (x[i0] - x[i0 - 1])
    right = x[i1] + (t - w[i1]) / (w[i1 + 1] - w[i1]) * (x[i1 + 1] - x[i1])
    return float(right - left)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, help="folder of the runs (kept; resumed)")
    ap.add_argument("--fine", action="store_true", help="also fe at h = a/8")
    args = ap.parse_args()
    root = Path(args.out)
    root.mkdir(parents=True, exist_ok=True)
    got = {}
    for name, data in variants(args.fine).items():
        folder = root / name
        if not (folder / "summary.json").exists() or json.loads(
                (folder / "summary.json").read_text()).get("stopped"):
            run(data, folder, resume=(folder / "checkpoint.npz").exists())
        got[name] = profiles(folder)
    base = "fe_a8" if args.fine else "fe_a4"  # the reference: the finest fe mesh run
    ref = got.pop(base)
    for name, prof in got.items():
        cells = []
        for body in ("upper", "lower"):
            (xr, wr), (x, w) = ref[body], prof[body]
            cells.append(f"{body} depth {w.max() / wr.max() - 1:+.2%}, width "
                         f"{width(x, w, 0.05) / width(xr, wr, 0.05) - 1:+.2%} (5 %) "
                         f"{width(x, w, 0.5) / width(xr, wr, 0.5) - 1:+.2%} (50 %)")
        print(f"{name} against {base}: " + "; ".join(cells))


if __name__ == "__main__":
    main()
