"""The rules a braking run applies to its measurements: the steady state of the wear rate
per sliding distance, the linear extrapolation of the wear depth in time, and the
worn-through floor of each body.

Steady state: ``until_steady`` slides past ``duration_s`` in blocks of ``STEADY_BLOCK`` of
it until :func:`steady_state` holds on the wear depth against the sliding distance (the
last-third rate within ``steady_tolerance`` of the middle-third rate, on the run and on
the run cut to 90 % and 80 % of its distance: ``STEADY_CUTS``), at most
``max_distance_m``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from tribodem.braking.measure import Reference
from tribodem.braking.model import DISC, PAD
from tribodem.braking.setup import WORN_THROUGH

#: the steady-state test must hold on the run and on the run cut to these fractions of
#: its distance: a single pass can be luck on a depth that moves in steps (ten 16-mm
#: runs: the test alone passed in 9, at 3-14 mm, reporting rates 0.3-74x those of the
#: runs' second halves; with the cuts it passed in none)
STEADY_CUTS = (1.0, 0.9, 0.8)
#: ``until_steady`` slides on in blocks of this fraction of ``duration_s`` between tests
STEADY_BLOCK = 0.2


def _slope(x: np.ndarray, y: np.ndarray) -> float:
    """Least-squares slope of ``y`` over ``x`` (nan with fewer than two distinct x)."""
    return float(np.polyfit(x, y, 1)[0]) if x.size >= 2 and np.ptp(x) > 0 else float("nan")


def _thirds(s: np.ndarray, h: np.ndarray, tol: float) -> tuple[bool, float, float]:
    """(the last third's rate within ``tol`` of the middle third's, positive; the two
    rates, m/m) on one series."""
    a, b = s[-1] / 3.0, 2.0 * s[-1] / 3.0
    mid, last = (s >= a) & (s <= b), s >= b
    r_mid, r_last = _slope(s[mid], h[mid]), _slope(s[last], h[last])
    return bool(r_mid > 0 and abs(r_last - r_mid) <= tol * r_mid), r_mid, r_last


def steady_state(s: np.ndarray, h: np.ndarray, tol: float = 0.15,
                 cuts: tuple[float, ...] = (1.0,)) -> dict[str, Any]:
    """The steady-state test on the wear depth ``h`` (m) against the sliding distance
    ``s`` (m): least-squares rates over the middle and the last third of the distance;
    steady when the middle-third rate is positive and the last-third rate lies within
    ``tol`` of it -- on the series cut to each fraction in ``cuts`` of its distance (the
    runs use ``STEADY_CUTS``: the whole run, 90 % and 80 % of it). The steady rate (m of
    wear per m slid) is the slope over the last two thirds of the whole series; the run-in
    is its first third (its distance, and the depth at its end)."""
    s, h = np.asarray(s, dtype=float), np.asarray(h, dtype=float)
    nan = float("nan")
    if s.size < 6 or not s[-1] > 0:
        return {"steady": False, "rate": nan, "rate_mid": nan, "rate_last": nan,
                "run_in_distance": nan, "run_in_depth": nan}
    ok, r_mid, r_last = _thirds(s, h, tol)
    for f in cuts:
        if not ok:
            break
        if f < 1.0:  # the whole series (1.0) was just tested
            m = s <= f * s[-1] * (1.0 + 1e-12)
            ok = bool(m.sum() >= 6 and _thirds(s[m], h[m], tol)[0])
    a = s[-1] / 3.0
    after = s >= a
    return {"steady": bool(ok), "rate": _slope(s[after], h[after]), "rate_mid": r_mid,
            "rate_last": r_last, "run_in_distance": a,
            "run_in_depth": float(np.interp(a, s, h))}


def steady_reason(st: dict[str, Any], tol: float) -> str | None:
    """Why :func:`steady_state`'s result ``st`` has no steady rate (None when it has one):
    too few rows, a middle-third rate that is not positive, or a last-third rate outside
    ``tol`` of it (on the whole run or on one of its cuts)."""
    if st["steady"]:
        return None
    mid, last = st["rate_mid"], st["rate_last"]
    if not np.isfinite(mid):
        return ("too few measurement rows (at least 6 over a positive sliding distance) for "
                "the steady-state rule")
    if not mid > 0:
        return (f"the steady-state rule needs a positive wear rate, but the middle third's "
                f"is {mid:.4g} m/m (the wear depth does not grow with the distance slid)")
    if abs(last - mid) > tol * mid:
        return (f"the rate is still changing: the last third's ({last:.4g} m/m) is not "
                f"within +-{100 * tol:g}% of the middle third's ({mid:.4g} m/m) within the "
                "distance slid")
    return (f"the last third's rate ({last:.4g} m/m) is within +-{100 * tol:g}% of the "
            f"middle third's ({mid:.4g} m/m) on the whole run, but not on the run cut to "
            f"{', '.join(f'{f:.0%}' for f in STEADY_CUTS[1:])} of its distance")


def wear_vs_distance(rows: list[dict[str, float]]) -> tuple[np.ndarray, np.ndarray]:
    """(sliding distance m, mean wear depth m) of every measurement row."""
    return (np.array([r["sliding_distance_m"] for r in rows]),
            np.array([r["wear_depth_mean_m"] for r in rows]))


def wear_extrapolation(t: np.ndarray, h: np.ndarray, target_s: float) -> tuple[float, float]:
    """(steady wear rate m/s, depth at ``target_s`` m): least-squares slope of h(t) over
    the second half of the record, extrapolated linearly from the last point."""
    half = t >= 0.5 * t[-1]
    if half.sum() < 2:
        return float("nan"), float("nan")
    rate = float(np.polyfit(t[half], h[half], 1)[0])
    return rate, float(h[-1] + max(rate, 0.0) * (target_s - t[-1]))


def worn_floor(ref: Reference, diameters: float = WORN_THROUGH) -> dict[str, float]:
    """Per body ("disc", "pad") the remaining thickness (m) below which it is worn
    through: ``diameters`` (``RunSetup.worn_through_diameters``) mean particle diameters
    of that body (0: never)."""
    return {name: diameters * 2.0 * float(ref.radius[ref.group == body].mean())
            for body, name in ((DISC, "disc"), (PAD, "pad"))}


def worn_text(worn: dict[str, Any]) -> str:
    """The start of the sentence saying where a body was worn through (``worn_through``),
    for the stop's message and the summary's note; its parenthesis is left open."""
    return (f"the {worn['body']} was worn through after "
            f"{1e3 * worn['sliding_distance_m']:.3g} mm of sliding (remaining thickness "
            f"{1e6 * worn['remaining_thickness_m']:.3g} um < {1e6 * worn['floor_m']:.3g} um")


def worn_through(row: dict[str, float], floor: dict[str, float]) -> dict[str, Any] | None:
    """The first body worn through in a measurement row (``worn_floor``), or None."""
    for name, f in floor.items():
        left = row.get(f"remaining_thickness_{name}_m", float("inf"))
        if left < f:
            return {"body": name, "sliding_distance_m": row["sliding_distance_m"],
                    "remaining_thickness_m": left, "floor_m": f}
    return None
