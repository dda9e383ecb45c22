"""The steady wear rate with the debris outlet, its scatter, seed 000's trends.

    python docs/data/braking_outlet/analyse.py PATTERN [--conditions 5,1,3] [--from 4e-3]

``PATTERN`` holds ``{c}`` (condition) and ``{k}`` (packing), e.g. ``runs/c{c}_L216_p{k}``;
``A|B`` takes the first alternative holding a finished run. The runs are the default cell
with the 324-um pad and ``[run] outlet_length_m`` (``c5.toml``), 12 mm of sliding. Per
run: the steady wear rate of its summary (slope of the pad's mean wear depth over the last
two thirds of the distance), the rate from ``--from`` (default 2 mm) to the end, the
steady-state rule (``tribodem.braking.steady.steady_state`` with ``STEADY_CUTS``) tested as
``[run] until_steady`` tests it -- first at the default 40 us of condition 5 (1.9 mm),
then every 20 % of that -- the distance where it first passes, and the contact fraction.
Per condition: mean and sd/mean of the rates over the packings. Then the paired changes of
the rate 13 -> 21 kN (condition 1 -> 5) and 800 -> 1200 r/min (3 -> 5) with their 95 %
intervals (``tribodem.braking.compare``) beside the seed's. Markdown on stdout. Runs made
with the thick bodies (``thick.toml``) also show the disc's wear rate and the intact
thickness of each body left at the end (``remaining_thickness_*``; nan for older runs).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
from scipy.stats import chi2

from tribodem.braking.compare import (
    SEED_CHANGES,
    _series,
    change_with_error,
    ci95,
    packings_for,
    seed_inside,
)
from tribodem.braking.conditions import get_condition
from tribodem.braking.config import RunCfg
from tribodem.braking.steady import STEADY_BLOCK, STEADY_CUTS, _slope, steady_state

V5 = get_condition(5).speed_m_s
FIRST = RunCfg().duration_s * V5  # m: where until_steady first tests (40 us at 1200 r/min)
SEED = {f"{name} ({a} -> {b})": (a, pct) for name, a, b, pct, _ in SEED_CHANGES
        if (a, b) in ((1, 5), (3, 5))}


def run_dir(pattern: str, c: int, k: int) -> Path | None:
    """The first alternative of ``pattern`` (``A|B``) with a finished run."""
    for alt in pattern.split("|"):
        d = Path(alt.format(c=c, k=k))
        if (d / "summary.json").exists():
            return d
    return None


def first_pass(s: np.ndarray, h: np.ndarray, tol: float) -> tuple[float, float]:
    """(distance m, rate m/m) at which ``until_steady`` would stop this run: tests at
    FIRST, then every STEADY_BLOCK x FIRST; (nan, nan) if it never passes."""
    at = FIRST
    while at <= s[-1] * (1 + 1e-9):
        m = s <= at * (1 + 1e-9)
        st = steady_state(s[m], h[m], tol, STEADY_CUTS)
        if st["steady"]:
            return at, st["rate"]
        at += STEADY_BLOCK * FIRST
    return float("nan"), float("nan")


def reading(d: Path, start: float) -> dict[str, float]:
    """One run's rates (m/m), rule outcome and contact fraction."""
    ts = _series(d)
    sm = json.loads((d / "summary.json").read_text())
    s, h = ts["sliding_distance_m"], ts["wear_depth_mean_pad_m"]
    m = s >= start
    at, rate_at = first_pass(s, h, RunCfg().steady_tolerance)
    ej = ts["ejected_depth_pad_m"]
    win = {}
    for width in (2e-3, 4e-3):  # rates of consecutive windows after the run-in third
        edges = np.arange(s[-1] / 3.0, s[-1] + 1e-9, width)
        win[width] = [_slope(s[(s >= a) & (s <= a + width)], h[(s >= a) & (s <= a + width)])
                      for a in edges[:-1]]
    grid = [_slope(s[(s >= a) & (s <= a + 2e-3)], h[(s >= a) & (s <= a + 2e-3)])
            for a in np.arange(0.0, 12e-3 - 1e-9, 2e-3)]
    return {"windows": win, "grid": grid, "steady": sm["wear_rate_steady_m_per_m"],
            "from": _slope(s[m], h[m]),
            "ejected": _slope(s[m], ej[m]), "rule": bool(sm["steady_reached"]),
            "pass_at": at, "pass_rate": rate_at, "contact": sm["contact_fraction"],
            "slid": float(s[-1]), "layer": float(ts["transfer_layer_thickness_m"][m].mean()),
            "cpu": sm["wall_time_s"],
            "left": [sm.get(f"remaining_thickness_{b}_m", float("nan")) for b in ("disc", "pad")],
            "disc_rate": (_slope(s[m], ts["wear_depth_mean_disc_m"][m])
                          if "wear_depth_mean_disc_m" in ts else float("nan"))}


def sd_interval(x: np.ndarray) -> tuple[float, float, float]:
    """sd/mean of ``x`` and its 95 % interval (chi-square on n - 1 degrees of freedom)."""
    n = x.size
    cv = float(x.std(ddof=1) / x.mean())
    return (cv, cv * float(np.sqrt((n - 1) / chi2.ppf(0.975, n - 1))),
            cv * float(np.sqrt((n - 1) / chi2.ppf(0.025, n - 1))))


def main(pattern: str, conds: list[int], start: float) -> None:
    ks = [k for k in range(200) if all(run_dir(pattern, c, k) for c in conds)]
    r = {c: [reading(run_dir(pattern, c, k), start) for k in ks] for c in conds}
    print(f"pattern {pattern}; packings {ks}; rates from {start * 1e3:g} mm\n")
    print("| condition | packing | slid mm | steady rate (last 2/3) um/mm | rate from "
          f"{start * 1e3:g} mm um/mm | ejected um/mm | rule on the whole run | until_steady "
          "would stop at mm (rate um/mm) | contact fraction | transfer layer um | wall s | "
          "disc wear rate um/mm | intact disc / pad left at the end, um |\n"
          "|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for c in conds:
        for k, x in zip(ks, r[c], strict=True):
            stop = ("no pass" if not np.isfinite(x["pass_at"]) else
                    f"{x['pass_at'] * 1e3:.2f} ({x['pass_rate'] * 1e3:.1f})")
            print(f"| {c} | {k} | {x['slid'] * 1e3:.2f} | {x['steady'] * 1e3:.2f} | "
                  f"{x['from'] * 1e3:.2f} | {x['ejected'] * 1e3:.2f} | "
                  f"{'steady' if x['rule'] else 'not steady'} | {stop} | "
                  f"{x['contact']:.2f} | {x['layer'] * 1e6:.1f} | {x['cpu']:.0f} | "
                  f"{x['disc_rate'] * 1e3:.2f} | {x['left'][0] * 1e6:.0f} / "
                  f"{x['left'][1] * 1e6:.0f} |")
    print("\n| condition | steady rate um/mm: mean, sd/mean between packings (95 % interval) "
          f"| rate from {start * 1e3:g} mm: mean, sd/mean | within a run: sd/mean of "
          "the rates of 2-mm / 4-mm windows after the run-in | contact fraction (min-max) "
          "|\n|---|---|---|---|---|")
    for c in conds:
        a = np.array([x["steady"] for x in r[c]])
        b = np.array([x["from"] for x in r[c]])
        cf = [x["contact"] for x in r[c]]
        cv, lo, hi = sd_interval(a)
        within = []
        for width in (2e-3, 4e-3):  # each run's windows relative to its own mean, pooled
            rel = [np.array(x["windows"][width]) / np.mean(x["windows"][width]) for x in r[c]]
            within.append(float(np.concatenate(rel).std(ddof=1)))
        print(f"| {c} | {a.mean() * 1e3:.2f}, {cv:.0%} ({lo:.0%}-{hi:.0%}) | "
              f"{b.mean() * 1e3:.2f}, {b.std(ddof=1) / b.mean():.0%} | "
              f"{within[0]:.0%} / {within[1]:.0%} | {min(cf):.2f}-{max(cf):.2f} |")
    print("\n| condition | mean over the packings of the rate per 2-mm window from 0, um/mm "
          "(is there a trend?) |\n|---|---|")
    for c in conds:
        per = np.array([x["grid"] for x in r[c]])
        print(f"| {c} | {', '.join(f'{v * 1e3:.1f}' for v in per.mean(axis=0))} |")
    if 5 not in conds or len(ks) < 2:
        return
    print("\n| trend (steady rate) | seed | ours, last 2/3 | ours, from "
          f"{start * 1e3:g} mm | seed inside | ours per unit time (rate x speed, last 2/3) | "
          "seed inside | packings for +-10 pp (per metre / per time) |\n"
          "|---|---|---|---|---|---|---|---|")
    for name, (c0, seed_pct) in SEED.items():
        if c0 not in conds:
            continue
        cells = []
        v0, v5 = get_condition(c0).speed_m_s, V5
        for key, f0, f5 in (("steady", 1.0, 1.0), ("from", 1.0, 1.0), ("steady", v0, v5)):
            a = np.array([x[key] for x in r[c0]]) * f0
            b = np.array([x[key] for x in r[5]]) * f5
            pct, se = change_with_error(a, b, paired=True)
            cells.append((pct, ci95(se, len(ks)), packings_for(se, len(ks))))
        yes = ["yes" if seed_inside(seed_pct, *cells[i][:2]) else "no" for i in (0, 2)]
        pm = [f"{p:+.1f} +- {h:.1f} %" for p, h, _ in cells]
        print(f"| {name} | {seed_pct:+.2f} % | {pm[0]} | {pm[1]} | {yes[0]} | {pm[2]} | "
              f"{yes[1]} | {cells[0][2]} / {cells[2][2]} |")
    print(f"\n(+- : half-width of the paired 95 % interval over {len(ks)} packings, Student t)")


if __name__ == "__main__":
    args = sys.argv[1:]
    conds, start = [5, 1, 3], 2e-3
    if "--conditions" in args:
        i = args.index("--conditions")
        conds = [int(c) for c in args[i + 1].split(",")]
        del args[i:i + 2]
    if "--from" in args:
        i = args.index("--from")
        start = float(args[i + 1])
        del args[i:i + 2]
    main(args[0], conds, start)
