"""Sweep comparison: our condition 1-5 results beside Sha et al. (2022) sections 3.4 and 5."""

from __future__ import annotations

import csv
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from tribodem.braking.conditions import CONDITIONS, SEED_BRAKING_TIME_S
from tribodem.io.results import write_csv, write_json, write_text

#: Sha et al. (2022) section 5: (from, to, wear depth change %, force chain change %)
SEED_CHANGES = [
    ("load 13->17 kN", 1, 2, 13.14, -23.37),
    ("load 17->21 kN", 2, 5, 11.61, -5.96),
    ("load 13->21 kN", 1, 5, 24.75, None),
    ("speed 800->1000 r/min", 3, 4, 7.45, -15.58),
    ("speed 1000->1200 r/min", 4, 5, 8.77, -3.86),
    ("speed 800->1200 r/min", 3, 5, 16.22, None),
]
#: Sha et al. (2022) figure 12 caption: condition 5 average wear depth (braking time s, depth m)
SEED_FIG12 = [(0.1, 3.66e-7), (0.5, 5.42e-6), (1.0, 1.16e-5), (2.0, 2.15e-5), (4.0, 4.15e-5),
              (8.0, 7.69e-5)]


#: why a change has no percentage (:func:`pct_reason`)
NOT_POSITIVE = ("a change in percent is given only between two positive quantities "
                "(a negative wear rate: the measured wear depth fell over the distance slid)")


def _pct(a: float, b: float) -> float:
    """The change from ``a`` to ``b`` in percent of ``a``; nan unless both are positive
    (between negative or zero quantities a percentage misleads: from -1 to -2.26 would read
    +126 %)."""
    return 100.0 * (b - a) / a if positive(a) and positive(b) else float("nan")


def positive(x: float | None) -> bool:
    """Whether ``x`` is a finite positive number."""
    return x is not None and bool(np.isfinite(x)) and x > 0


def pct_reason(a: float | None, b: float | None) -> str | None:
    """Why the change from ``a`` to ``b`` has no percentage (None when it has one): a
    quantity missing (a condition without a run) or not positive (:data:`NOT_POSITIVE`)."""
    if a is None or b is None or not (np.isfinite(a) and np.isfinite(b)):
        return "a condition has no value (not run, or all its members failed)"
    if positive(a) and positive(b):
        return None
    return f"from {a:.4g} to {b:.4g}: {NOT_POSITIVE}"


def _series(run_dir: Path) -> dict[str, np.ndarray]:
    with (run_dir / "timeseries.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


def _late_mean(s: dict[str, np.ndarray], key: str) -> float:
    t = s["time_s"]
    return float(s[key][t >= 0.5 * t[-1]].mean())


def _fmt(x: float | None) -> str:
    return "-" if x is None or not np.isfinite(x) else f"{x:+.2f}%"


def change_with_error(a: np.ndarray, b: np.ndarray, paired: bool = True
                      ) -> tuple[float, float]:
    """Relative change (%) of the mean of ``b`` over the mean of ``a`` and its standard
    error (%; nan with one seed). ``paired`` (same length): entry s of both comes from the
    same packing and roughness seed (a sweep's conditions share them), so the error is
    that of the mean per-seed difference, ``sd(b - a) / sqrt(n) / mean(a)``; otherwise
    the standard errors of both means are propagated to first order."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    ma, mb = float(a.mean()), float(b.mean())
    pct = _pct(ma, mb)
    if min(a.size, b.size) < 2 or not np.isfinite(pct):
        return pct, float("nan")
    if paired and a.size == b.size:
        return pct, 100.0 * float((b - a).std(ddof=1)) / np.sqrt(a.size) / abs(ma)
    sa = float(a.std(ddof=1)) / np.sqrt(a.size)
    sb = float(b.std(ddof=1)) / np.sqrt(b.size)
    return pct, 100.0 * abs(mb / ma) * float(np.hypot(sa / ma, sb / mb))


def _factor(n: int | None) -> float:
    """Multiple of the standard error a change must exceed: the two-sided 95% Student t
    quantile with n - 1 degrees of freedom (n seeds), or 2 when n is not given."""
    if n is None:
        return 2.0
    from scipy.stats import t as student_t

    return float(student_t.ppf(0.975, max(n - 1, 1)))


def step_verdict(pct: float, se: float, n: int | None = None) -> str:
    """``up`` / ``down`` when the change exceeds ``_factor(n)`` standard errors (95% t
    for n seeds), else ``not resolved`` (``no scatter`` with one seed; ``no change in
    percent`` when ``pct`` is nan: :func:`pct_reason`)."""
    if not np.isfinite(pct):
        return "no change in percent (a quantity is not positive)"
    if not np.isfinite(se):
        return "no scatter (1 seed)"
    k = _factor(n)
    if pct > k * se:
        return "up"
    if pct < -k * se:
        return "down"
    return "not resolved"


def trend_verdict(steps: list[tuple[float, float]], total: tuple[float, float],
                  want: str, n: int | None = None) -> str:
    """Verdict on a seed trend (``want`` = ``up`` or ``down``) from its two steps and the
    total change, each (pct, se), over n seeds."""
    if not np.isfinite(total[0]):
        return ("not evaluated: the total change has no percentage (a quantity is not "
                "positive, or a condition has no value)")
    tv = step_verdict(*total, n)
    sv = [step_verdict(*x, n) for x in steps]
    other = "down" if want == "up" else "up"
    if tv == want and other not in sv:
        return "reproduced (total change resolved, no step resolved against it)"
    if tv == want:
        return "partly: total change resolved, but a step is resolved against it"
    if tv == other:
        return "not reproduced: the total change is resolved in the opposite direction"
    sign_ok = (total[0] > 0) == (want == "up")
    return ("not resolved: the sign of the total change agrees, but it is within the 95% "
            "interval" if sign_ok else
            "not reproduced: the total change has the opposite sign (within the scatter)")


def steady_rate(r: dict[str, Any]) -> float:
    """A run's wear rate per sliding distance after the run-in (m/m): the slope over the
    last two thirds of its distance, ``wear_rate_last_two_thirds_m_per_m`` (whether the
    steady-state rule passed or not: ``steady_reached``; runs made before that field have
    it as ``wear_rate_steady_m_per_m``), or for runs made before both the second-half rate
    in time divided by the speed."""
    for key in ("wear_rate_last_two_thirds_m_per_m", "wear_rate_steady_m_per_m"):
        if r.get(key) is not None:
            return float(r[key])
    return float(r["steady_wear_rate_m_s"]) / float(r["sliding_speed_m_s"])


def _mean_summary(runs: list[dict[str, Any]]) -> dict[str, Any]:
    """Mean over seeds of every numeric summary entry (the first run's other entries)."""
    out = dict(runs[0])
    for k, v in runs[0].items():
        if isinstance(v, (int, float)) and not isinstance(v, bool):
            out[k] = float(np.mean([r[k] for r in runs]))
    return out


def _pm(pct: float, se: float) -> str:
    return _fmt(pct) if not np.isfinite(se) else f"{pct:+.1f} +- {se:.1f}%"


def ci95(se: float, n: int) -> float:
    """Half-width (percentage points) of the two-sided 95% Student-t interval of a paired
    change over n packings with standard error ``se`` (nan with one packing)."""
    return _factor(n) * se if np.isfinite(se) and n >= 2 else float("nan")


#: the half-width (percentage points) a sweep's paired 95% intervals are sized for in the
#: "packings needed" estimate
TARGET_CI95_PP = 10.0


def packings_for(se: float, n: int, half_width: float = TARGET_CI95_PP) -> int | None:
    """Packings per condition for a paired 95% half-width of ``half_width`` percentage
    points at the scatter measured over ``n`` packings (standard error ``se``): the sd
    of a per-packing change, ``se sqrt(n)``, is assumed to stay, so the smallest m with
    t(0.975, m - 1) x sd / sqrt(m) <= ``half_width``. None without a measured scatter
    (one packing)."""
    if not (np.isfinite(se) and n >= 2 and half_width > 0):
        return None
    sd = se * np.sqrt(n)
    m = max(2, int(np.ceil((1.96 * sd / half_width) ** 2)))
    while _factor(m) * sd / np.sqrt(m) > half_width:
        m += 1
    return m


def seed_inside(seed_pct: float | None, pct: float, half: float) -> bool | None:
    """The rule of ``reproduced``: the seed's change lies inside our paired 95% interval,
    ``|seed - ours| <= ci95``; None when there is no interval (one packing) or no seed
    value."""
    if seed_pct is None or not (np.isfinite(half) and np.isfinite(pct)):
        return None
    return bool(abs(seed_pct - pct) <= half)


def _ci(pct: float, half: float) -> str:
    return _fmt(pct) if not np.isfinite(half) else f"{pct:+.1f} +- {half:.1f}%"


def _sd(x: float, fmt: str) -> str:
    return format(x, fmt) if np.isfinite(x) else "-"


def _num(x: float) -> float | None:
    return float(x) if x is not None and np.isfinite(x) else None


def length_text(results: dict[int, dict[str, Any]], t_sim: float) -> str:
    """What the runs simulate: the same time for every condition (the seed's way), or
    the same sliding distance (``[run] distance_m``: the times differ with the speed)."""
    times = [float(r["simulated_time_s"]) for r in results.values()]
    if max(times) - min(times) <= 1e-6 * max(times):
        return (f"Every run simulates {t_sim * 1e6:.3g} us of sliding (the same braking time "
                "for all conditions, as the seed compares at 8 s); the seed's 8 s are not "
                f"simulated (fraction {t_sim / SEED_BRAKING_TIME_S:.2e}).")
    dist = [float(r["simulated_sliding_distance_m"]) for r in results.values()]
    return (f"Every run slides {np.mean(dist) * 1e3:.3g} mm (a fixed distance, `[run] "
            "distance_m`: the conditions are compared at the same sliding distance, not at "
            f"the same time as the seed does; {min(times) * 1e6:.3g}-{max(times) * 1e6:.3g} us"
            " of sliding); the seed's 8 s are not simulated.")


@dataclass
class SweepStats:
    """What a comparison is made of: the runs of each condition (summary, folder; one per
    packing), the conditions without any run (``missing``), the mean summary per
    condition, the packings compared (the fewest of any condition), each condition's
    first time series, the per-packing values of each quantity (``wear`` m, ``rate``
    m/m, ``contact``, ``chains``, ``strong``: late means) with their means and standard
    deviations, and the paired changes (%, standard error %) of every seed change."""

    runs: dict[int, list[tuple[dict[str, Any], Path]]]
    missing: list[int]
    results: dict[int, dict[str, Any]]
    n_seeds: int
    series: dict[int, dict[str, np.ndarray]]
    per_seed: dict[str, dict[int, np.ndarray]]
    wear: dict[int, float]
    spread: dict[int, float]
    rate: dict[int, float]
    rate_sd: dict[int, float]
    contact: dict[int, float]
    chains: dict[int, float]
    strong: dict[int, float]
    ch: dict[str, dict[tuple[int, int], tuple[float, float]]]

    @property
    def t_sim(self) -> float:
        """The simulated time (s) of the first condition's mean summary."""
        return float(next(iter(self.results.values()))["simulated_time_s"])


def _per_packing(runs: dict[int, list[tuple[dict[str, Any], Path]]], missing: list[int]
                 ) -> dict[str, dict[int, np.ndarray]]:
    """Per quantity and condition, the values of its packings: the end wear depth (m),
    the steady wear rate (m/m), the contact fraction and the late means of the force
    chains and the strong ones; a missing condition has one nan."""
    per_seed = {
        "wear": {k: np.array([r["wear_depth_mean_m"] for r, _ in v]) for k, v in runs.items()},
        "rate": {k: np.array([steady_rate(r) for r, _ in v]) for k, v in runs.items()},
        "contact": {k: np.array([r.get("contact_fraction", np.nan) for r, _ in v])
                    for k, v in runs.items()},
        "chains": {k: np.array([_late_mean(_series(d), "force_chains") for _, d in v])
                   for k, v in runs.items()},
        "strong": {k: np.array([_late_mean(_series(d), "strong_force_chains") for _, d in v])
                   for k, v in runs.items()},
    }
    for q in per_seed:
        per_seed[q].update({k: np.full(1, np.nan) for k in missing})
    return per_seed


def _means(x: dict[int, np.ndarray]) -> dict[int, float]:
    return {k: float(v.mean()) for k, v in x.items()}


def _sds(x: dict[int, np.ndarray]) -> dict[int, float]:
    return {k: float(v.std(ddof=1)) if v.size > 1 else float("nan") for k, v in x.items()}


def sweep_stats(runs: dict[int, list[tuple[dict[str, Any], Path]]]) -> SweepStats:
    """The :class:`SweepStats` of the runs of each condition (``ValueError`` without any)."""
    runs = {k: v for k, v in runs.items() if v}
    if not runs:
        raise ValueError("write_comparison: no runs")
    nan = (float("nan"), float("nan"))
    missing = [k for k in CONDITIONS if k not in runs]
    results = {k: _mean_summary([r for r, _ in v]) for k, v in runs.items()}
    n_seeds = min(len(v) for v in runs.values())
    series = {k: _series(v[0][1]) for k, v in runs.items()}  # condition 5 history: seed 0
    per_seed = _per_packing(runs, missing)
    ch: dict[str, dict[tuple[int, int], tuple[float, float]]] = {
        q: {(a, b): change_with_error(per_seed[q][a], per_seed[q][b])
            if a in runs and b in runs else nan
            for _, a, b, _, _ in SEED_CHANGES} for q in per_seed if q != "contact"}
    return SweepStats(
        runs=runs, missing=missing, results=results, n_seeds=n_seeds, series=series,
        per_seed=per_seed, wear=_means(per_seed["wear"]), spread=_sds(per_seed["wear"]),
        rate=_means(per_seed["rate"]), rate_sd=_sds(per_seed["rate"]),
        contact=_means(per_seed["contact"]), chains=_means(per_seed["chains"]),
        strong=_means(per_seed["strong"]), ch=ch)


@dataclass
class ChangeTable:
    """The seed's changes evaluated: comparison.csv's rows, the markdown table's lines,
    the (label, ours, seed) wear rows printed, the packings needed per change and
    comparison.json's trends."""

    rows_csv: list[list[Any]] = field(default_factory=list)
    lines: list[str] = field(default_factory=list)
    printed: list[tuple[str, str, str]] = field(default_factory=list)
    need: list[str] = field(default_factory=list)
    trends_json: list[dict[str, Any]] = field(default_factory=list)


def _yes(x: bool | None) -> str:
    return "-" if x is None else ("yes" if x else "no")


def _add_change(t: ChangeTable, st: SweepStats, label: str, a: int, b: int, seed_w: float,
                seed_c: float | None) -> None:
    """Evaluate one seed change (conditions ``a`` -> ``b``, the seed's wear and chain
    changes %) into ``t``."""
    n_seeds, wear, rate, chains = st.n_seeds, st.wear, st.rate, st.chains
    (ow, ow_se), (orr, orr_se) = st.ch["wear"][(a, b)], st.ch["rate"][(a, b)]
    (oc, oc_se), (os_, _) = st.ch["chains"][(a, b)], st.ch["strong"][(a, b)]
    hw, hr, hc = (ci95(x, n_seeds) for x in (ow_se, orr_se, oc_se))
    t.rows_csv.append([label, a, b, n_seeds, wear[a], wear[b], ow, ow_se,
                       step_verdict(ow, ow_se, n_seeds), seed_w, rate[a], rate[b], orr, orr_se,
                       step_verdict(orr, orr_se, n_seeds), chains[a], chains[b], oc, oc_se,
                       "" if seed_c is None else seed_c, os_, hw, hr, hc,
                       pct_reason(wear[a], wear[b]) or "", pct_reason(rate[a], rate[b]) or "",
                       pct_reason(chains[a], chains[b]) or ""])
    inside_w, inside_c = seed_inside(seed_w, ow, hw), seed_inside(seed_c, oc, hc)
    t.lines.append(f"| {label} | {a}->{b} | {wear[a] * 1e6:.2f} -> {wear[b] * 1e6:.2f} | "
                   f"{_ci(ow, hw)} | {_fmt(seed_w)} | {_yes(inside_w)} | "
                   f"{step_verdict(ow, ow_se, n_seeds)} | "
                   f"{_ci(orr, hr)} | {step_verdict(orr, orr_se, n_seeds)} | "
                   f"{chains[a]:.0f} -> {chains[b]:.0f} | {_ci(oc, hc)} | "
                   f"{_fmt(seed_c)} | {_yes(inside_c)} |")
    t.printed.append((label, _ci(ow, hw), _fmt(seed_w)))
    need_w = packings_for(ow_se, n_seeds)
    t.need.append(f"{label} {need_w or '-'}")
    for q, seed_pct, pct, half, inside, se, need_q in (
            ("wear_depth", seed_w, ow, hw, inside_w, ow_se, need_w),
            ("force_chains", seed_c, oc, hc, inside_c, oc_se, packings_for(oc_se, n_seeds))):
        if seed_pct is None:
            continue
        frm, to = (st.wear[a], st.wear[b]) if q == "wear_depth" else (chains[a], chains[b])
        t.trends_json.append({
            "change": label, "from_condition": a, "to_condition": b, "quantity": q,
            "seed_pct": seed_pct, "ours_pct": _num(pct),
            "ours_pct_reason": None if np.isfinite(pct) else pct_reason(frm, to),
            "ci95_pct": _num(half),
            "se_pct": _num(se), "reproduced": inside,
            "packings_for_ci95_10pp": need_q,
            "resolved": None if not np.isfinite(half) else bool(abs(pct) > half)})


def change_table(st: SweepStats) -> ChangeTable:
    """Every seed change of section 5 (``SEED_CHANGES``) evaluated on the sweep."""
    t = ChangeTable()
    for label, a, b, seed_w, seed_c in SEED_CHANGES:
        _add_change(t, st, label, a, b, seed_w, seed_c)
    return t


#: comparison.csv's columns
CSV_COLUMNS = [
    "change", "from_condition", "to_condition", "seeds", "wear_depth_from_m",
    "wear_depth_to_m", "wear_depth_change_pct", "wear_depth_change_se_pct",
    "wear_depth_verdict", "seed_wear_depth_change_pct", "wear_rate_from_m_per_m",
    "wear_rate_to_m_per_m", "wear_rate_change_pct", "wear_rate_change_se_pct",
    "wear_rate_verdict", "force_chains_from", "force_chains_to",
    "force_chains_change_pct", "force_chains_change_se_pct",
    "seed_force_chains_change_pct", "strong_force_chains_change_pct",
    "wear_depth_change_ci95_pct", "wear_rate_change_ci95_pct",
    "force_chains_change_ci95_pct", "wear_depth_change_reason", "wear_rate_change_reason",
    "force_chains_change_reason"]


def _trend(st: SweepStats, q: str, ks: tuple[int, int, int], want: str) -> str:
    """The verdict on the trend of quantity ``q`` over conditions ``ks`` (``want``: up or
    down); not evaluated when a condition has no run."""
    a, b, c = ks
    lost = [k for k in ks if k in st.missing]
    if lost:
        return f"not evaluated: no run of condition {', '.join(map(str, lost))}"
    return trend_verdict([st.ch[q][(a, b)], st.ch[q][(b, c)]], st.ch[q][(a, c)], want,
                         st.n_seeds)


def verdicts(st: SweepStats) -> list[tuple[str, str]]:
    """(trend, verdict) of the seed's six trends: wear depth and steady rate up with load
    and speed, force chains down with both."""
    return [
        ("wear depth rises with load (13 -> 17 -> 21 kN; seed +24.75%)",
         _trend(st, "wear", (1, 2, 5), "up")),
        ("wear depth rises with speed (800 -> 1000 -> 1200 r/min; seed +16.22%)",
         _trend(st, "wear", (3, 4, 5), "up")),
        ("steady wear rate per distance rises with load", _trend(st, "rate", (1, 2, 5), "up")),
        ("steady wear rate per distance rises with speed",
         _trend(st, "rate", (3, 4, 5), "up")),
        ("force chains fall with load (seed -23.37%, -5.96%)",
         _trend(st, "chains", (1, 2, 5), "down")),
        ("force chains fall with speed (seed -15.58%, -3.86%)",
         _trend(st, "chains", (3, 4, 5), "down")),
    ]


def _history_lines(st: SweepStats) -> list[str]:
    """The condition 5 history (packing 0) beside figure 12: the seed's times mapped to
    the same fractions of the simulated window."""
    r5, s5 = st.results.get(5), st.series.get(5)
    hist = []
    t5 = float(r5["simulated_time_s"]) if r5 is not None else st.t_sim  # distance_m: its own
    for ts, hs in SEED_FIG12 if s5 is not None else []:
        tt = ts / SEED_BRAKING_TIME_S * t5
        h = float(np.interp(tt, s5["time_s"], s5["wear_depth_mean_m"]))
        hist.append(f"| {ts:g} | {hs * 1e3:.3g} | {tt * 1e6:.3g} | {h * 1e3:.3g} | "
                    f"{hs / SEED_FIG12[-1][1]:.3f} | "
                    f"{h / max(float(s5['wear_depth_mean_m'][-1]), 1e-300):.3f} |")
    return hist


def _condition_lines(st: SweepStats) -> list[str]:
    """One markdown row per condition: table 4, the simulated window, the means +- sd."""
    per = []
    for k in sorted(st.results):
        r = st.results[k]
        c = CONDITIONS[k]
        per.append(f"| {k} | {c.load_kN:g} | {r['pressure_Pa'] / 1e6:.4g} | {c.rpm:g} | "
                   f"{r['sliding_speed_m_s']:.4g} | {r['simulated_time_s'] * 1e6:.3g} | "
                   f"{r['simulated_sliding_distance_m'] * 1e6:.4g} | "
                   f"{st.wear[k] * 1e6:.2f} +- {_sd(st.spread[k] * 1e6, '.2f')} | "
                   f"{st.rate[k] * 1e3:.3g} +- {_sd(st.rate_sd[k] * 1e3, '.2g')} | "
                   f"{st.contact[k]:.3f} | "
                   f"{r['wear_depth_max_m'] * 1e6:.1f} | "
                   f"{r['wear_depth_mean_disc_m'] * 1e6:.2f} | {r['broken_bonds']:.0f} "
                   f"({r['broken_bonds_tensile']:.0f}/{r['broken_bonds_shear']:.0f}) | "
                   f"{r['debris_particles']:.0f} | {st.chains[k]:.0f} | {st.strong[k]:.0f} | "
                   f"{r['mean_wall_pressure_ratio']:.3f} | "
                   f"{r['particles_final']:.0f}/{r['particles_initial']:.0f} | "
                   f"{r['wall_time_s']:.0f} |")
    return per


def _rel_rate(st: SweepStats) -> dict[int, float]:
    """Per condition the scatter (sd / mean) of the steady wear rate between packings."""
    return {k: st.rate_sd[k] / st.rate[k] for k in st.rate
            if st.rate[k] > 0 and np.isfinite(st.rate_sd[k])}


def _scatter_text(st: SweepStats) -> str:
    """The paragraph on the scatter between packings and the rule of the verdicts."""
    n_seeds = st.n_seeds
    rel = [st.spread[k] / st.wear[k] for k in st.wear
           if st.wear[k] > 0 and np.isfinite(st.spread[k])]
    rel_rate = _rel_rate(st)
    scatter = (f"Seed-to-seed scatter of the pad wear depth: sd/mean = "
               f"{100 * min(rel):.1f}-{100 * max(rel):.1f}% over {n_seeds} seeds. A change "
               f"is called up/down only when it exceeds {_factor(n_seeds):.2f} standard "
               f"errors (two-sided 95% Student t, {n_seeds - 1} degrees of freedom), "
               "otherwise 'not resolved'. The conditions of one seed share its packing "
               "and roughness (only load and speed differ), so changes are paired: the "
               "error is that of the mean per-seed difference." if rel else
               "One packing per condition: the scatter between packings is not measured "
               "here (use --packings N), so no change can be called resolved.")
    if rel_rate:
        scatter += (" Scatter of the steady wear rate between packings (sd/mean): " + ", ".join(
            f"condition {k} {100 * v:.0f}%" for k, v in sorted(rel_rate.items())) + ".")
    return scatter


def _extrapolation_text(r5: dict[str, Any] | None) -> str:
    """Condition 5's extrapolation to 8 s beside the seed's depth."""
    return (
        f"Our linear extrapolation to 8 s (steady rate over the second half, clipped at "
        f"0): {r5['wear_depth_mean_extrapolated_8s_m'] * 1e3:.3g} mm "
        f"(rate {r5['steady_wear_rate_m_s']:.3g} m/s) vs the seed's 7.69e-2 mm: an "
        "extrapolation over ~6 orders of magnitude in time, not a result."
        if r5 is not None else "Condition 5 has no run (not run or failed): no history.")


def _md_conditions(st: SweepStats, wall_s: float, cluster: str | int, quick: bool
                   ) -> list[str]:
    """comparison.md's title, what was run and the per-condition table."""
    seeds_txt = "; ".join(
        f"{k}: " + ", ".join(f"{x * 1e6:.1f}" for x in st.per_seed["wear"][k])
        for k in sorted(st.per_seed["wear"]))
    missing = st.missing
    return [
        "# Braking sweep: tribodem vs Sha et al. (2022)" + (" (--quick)" if quick else ""),
        "",
        f"Condition(s) {', '.join(map(str, sorted(st.runs)))} of table 4"
        + (f" (not run or all failed: {', '.join(map(str, missing))})" if missing else "")
        + f" x {st.n_seeds} packing/roughness seed(s) in {wall_s:.0f} s on "
        f"{cluster if isinstance(cluster, str) else f'{cluster} worker processes'}; values "
        "are means over packings +- the standard deviation over "
        f"seeds. {length_text(st.results, st.t_sim)} Wear depth = mean pad "
        "wear depth at the end (worn solid area / (packing fraction x width)); steady wear "
        "rate = wear depth per sliding distance after the run-in (summary.json "
        "`wear_rate_last_two_thirds_m_per_m`: slope over the last two thirds of the "
        "distance, whether or not the run's steady-state rule passed, `steady_reached`); "
        "contact fraction = share of the time the interface carries load; force chains = "
        "time mean over the second half of the run.",
        "",
        "## Per condition",
        "",
        "| cond. | load kN | p MPa | r/min | v m/s | t_sim us | slid um | pad wear mean um "
        "(+- sd) | steady wear rate um/mm (+- sd) | contact fraction | pad wear max um | "
        "disc wear mean um | "
        "broken bonds (tens./shear) | debris | chains | strong chains | mean plate force / "
        "target | particles end/start | wall s |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
        *_condition_lines(st),
        "",
        f"Pad wear depth per seed (um), condition: values -- {seeds_txt}.",
        "",
    ]


def _md_changes(st: SweepStats, t: ChangeTable) -> list[str]:
    """comparison.md's table of changes beside the seed's and the packings needed."""
    n_seeds = st.n_seeds
    return [
        "## Changes: ours (mean change +- paired 95% interval) beside the seed's (section 5)",
        "",
        f"Our change = change of the means over {n_seeds} packing(s) +- the half-width of "
        "the two-sided 95% Student-t interval of the paired per-packing changes "
        + (f"({_factor(n_seeds):.2f} standard errors, {n_seeds - 1} degrees of freedom). "
           if n_seeds > 1 else "(none with one packing: use --packings N). ") +
        "'seed inside' (comparison.json `reproduced`): the seed's change lies inside our "
        "interval, |seed - ours| <= half-width; 'verdict': our interval excludes 0 "
        f"(up/down) or not (not resolved). '-': no change in percent: {NOT_POSITIVE} "
        "(comparison.csv `*_change_reason`).",
        "",
        "| change | conditions | our wear depth um | our wear change (95%) | seed wear change "
        "| seed inside | verdict | our wear-rate change (95%) | verdict | our force chains | "
        "our chain change (95%) | seed chain change | seed inside |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
        *t.lines,
        "",
        f"Packings per condition for a +-{TARGET_CI95_PP:g} pp wear-depth interval at the "
        "scatter measured here (the sd of the per-packing change assumed to stay; "
        "comparison.json `packings_for_ci95_10pp`): " + "; ".join(t.need) + "."
        if n_seeds > 1 else "",
        "",
    ]


def _md_trends(st: SweepStats, trends: list[tuple[str, str]],
               failed: dict[str, str] | None) -> list[str]:
    """comparison.md's trends, scatter, condition 5 history and failed members."""
    fail_lines = ["## Failed members", "", "Left out of every mean and change above:", "",
                  *[f"- {m}: {e}" for m, e in failed.items()], ""] if failed else []
    return [
        "## Trends",
        "",
        *[f"- {w}: **{v}**." for w, v in trends],
        "",
        _scatter_text(st),
        "",
        "## Condition 5 history beside figure 12",
        "",
        "Seed 0 of condition 5. The seed's times are seconds of braking; ours are the "
        "same fractions of our simulated window (microseconds). Only the shapes "
        "(depth / final depth) can be compared; the absolute depths are for different "
        "sliding distances.",
        "",
        "| seed t s | seed depth mm | our t us | our depth mm | seed h/h(8 s) | "
        "our h/h(end) |",
        "|---|---|---|---|---|---|",
        *_history_lines(st),
        "",
        _extrapolation_text(st.results.get(5)),
        "",
        *fail_lines,
    ]


def _comparison_json(st: SweepStats, t: ChangeTable, trends: list[tuple[str, str]],
                     failed: dict[str, str] | None, wall_s: float, cluster: str | int
                     ) -> dict[str, Any]:
    """comparison.json: the rule, the trends against the seed's, the per-condition means,
    the verdicts, the failed members, the wall time (s) and the cluster."""
    rel_rate = _rel_rate(st)
    return {
        "packings": st.n_seeds,
        "conditions": {str(k): len(v) for k, v in sorted(st.runs.items())},
        "rule": "ours_pct = relative change of the means over packings; ci95_pct = half-width "
                "(percentage points) of the two-sided 95% Student-t interval of the paired "
                "per-packing changes (t(0.975, n-1) x se); reproduced = |seed_pct - ours_pct| "
                "<= ci95_pct (null with one packing); resolved = |ours_pct| > ci95_pct",
        "trends": t.trends_json,
        "per_condition": {str(k): {
            "packings": int(st.per_seed["wear"][k].size),
            "wear_depth_mean_m": _num(st.wear[k]), "wear_depth_sd_m": _num(st.spread[k]),
            "wear_rate_steady_m_per_m": _num(st.rate[k]),
            "wear_rate_steady_sd_m_per_m": _num(st.rate_sd[k]),
            "wear_rate_steady_scatter": _num(rel_rate.get(k, float("nan"))),
            "contact_fraction": _num(st.contact[k])} for k in sorted(st.results)},
        "verdicts": {w: v for w, v in trends},
        "failed": dict(failed or {}),
        "wall_time_s": wall_s,
        "cluster": str(cluster),
    }


def write_comparison(out: Path, runs: dict[int, list[tuple[dict[str, Any], Path]]],
                     wall_s: float, cluster: str | int, quick: bool,
                     failed: dict[str, str] | None = None) -> list[tuple[str, str, str]]:
    """Write comparison.csv, comparison.md and comparison.json from the runs of each
    condition (one per packing seed): seed means, the standard error of each change over
    seeds, and a verdict per change and per trend; return (label, ours, seed) wear rows.
    ``wall_s``: the sweep's wall time (s); ``cluster``: where it ran.

    ``failed`` (member -> error) is listed; a condition without any run (all its members
    failed) leaves the changes and trends that need it unevaluated ("-")."""
    st = sweep_stats(runs)
    t = change_table(st)
    write_csv(out / "comparison.csv", CSV_COLUMNS, t.rows_csv)
    trends = verdicts(st)
    text = "\n".join([*_md_conditions(st, wall_s, cluster, quick), *_md_changes(st, t),
                      *_md_trends(st, trends, failed)])
    write_text(out / "comparison.md", text)
    write_json(out / "comparison.json", _comparison_json(st, t, trends, failed, wall_s,
                                                         cluster))
    return t.printed
