"""Cycle-jumping strategies (Lu (2018), chapter 4 and appendix III; eq 2.20).

A cycle-jumping strategy watches a per-cycle simulated quantity and, when the history
looks safe, skips ``n`` cycles by extrapolating the state over them. One interface,
:class:`JumpStrategy`, and five strategies:

* :class:`ConstantJump` -- McColl's constant jump length (eq 2.20, section 4.2.1);
* :class:`CojocaruJump` -- ratio of two adjacent slopes (eqs 4.1-4.2, section 4.2.2);
* :class:`MovingGroupsJump` -- slopes of two abutting groups (eqs 4.3-4.4, section 4.2.3);
* :class:`OverlappingGroupsJump` -- groups overlapping by half (eqs 4.5-4.6, section 4.2.4);
* :class:`AdaptiveJump` -- polynomial fit, coefficient convergence, curvature check,
  jump length and Taylor extrapolation (eqs 4.7-4.15, section 4.3) with the four
  modifications of section 4.4.

The state is the cumulative quantity (e.g. wear depth, m) after a cycle; it may be a
scalar or an array (a whole wear profile), in which case every element is advanced by
its own fitted rate. Protocol::

    s.observe(0, state0)                 # initial state (cycle 0)
    for each simulated cycle c:
        s.observe(c, state)
        n = s.propose_jump()
        if n: state = s.extrapolate(state, n)   # state now at cycle c + n

:func:`replay` runs that loop on a recorded series of per-cycle increments (appendix III
reads ``Result.csv``), and :func:`synthetic_two_phase_series` makes a running-in + steady
test series (seed figure 5.17); :func:`synthetic_smooth_series` makes linear, power-law,
exponential run-in and two-phase series.

Step control: every strategy but ``constant`` (opt-in there) bounds its jump
with :func:`error_controlled_jump`, the longest jump whose predicted local error stays
within a relative tolerance ``tol`` of the extrapolated increment, using the curvature of
the rates measured on simulated cycles (never on extrapolated ones). ``step_control=
"seed"`` restores each strategy's rule as the seed states it.
"""

from __future__ import annotations

import inspect
import math
from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

State = float | NDArray[np.float64]

#: Elements whose fitted rate is below this fraction of the largest |rate| carry no wear
#: and are left out of the linearity tests (they are still extrapolated by their own rate).
ACTIVE_FRACTION = 1e-3

#: Jump proposed for a perfectly linear history with no cap (the replay clips it to the
#: end of the series).
UNBOUNDED_JUMP = 10**9


def _as_2d(value: ArrayLike) -> NDArray[np.float64]:
    return np.atleast_1d(np.asarray(value, dtype=float)).reshape(-1)


def _active(rate: NDArray[np.float64]) -> NDArray[np.bool_]:
    m = float(np.max(np.abs(rate))) if rate.size else 0.0
    if m == 0.0:
        return np.zeros(rate.shape, dtype=bool)
    return np.abs(rate) >= ACTIVE_FRACTION * m


def error_controlled_jump(kappa: float, tol: float, lag: float = 0.0,
                          rate_error: float = 0.0) -> float:
    """Longest jump (cycles, not rounded) whose local error stays within ``tol``.

    A jump of L cycles extrapolates with a constant rate that was estimated ``lag`` cycles
    before the jump starts. If the rate changes by the relative amount ``kappa`` per cycle
    (kappa = |f''| / |f'|, 1/cycle), the extrapolated increment misses

        error = |f''| (lag L + L**2 / 2)        (difference of the linear and quadratic
                                                  predictors over the jump)

    and its ratio to the extrapolated increment |f'| L is kappa (lag + L / 2). Keeping
    that ratio <= ``tol`` gives L = 2 (tol / kappa - lag); ``inf`` for kappa = 0 and 0 when
    the lag alone uses the tolerance. Because every jump misses at most ``tol`` of what it
    adds, the cumulative value misses at most ``tol`` of its jumped part.
    """
    if not math.isfinite(kappa) or not rate_error < tol:
        return 0.0
    if kappa <= 0.0:
        return math.inf
    return max(0.0, 2.0 * ((tol - rate_error) / kappa - lag))


def _check_step_control(step_control: str, tol: float | None) -> None:
    if step_control not in ("error", "seed"):
        raise ValueError(f"step_control = {step_control!r}: must be 'error' (jump length "
                         "capped by the local error estimate) or 'seed' (the seed's rule alone)")
    if tol is not None and not (math.isfinite(tol) and tol > 0):
        raise ValueError(f"tol = {tol!r}: must be a finite number > 0 (relative local error "
                         "per jump)")


def _restore(template: State, arr: NDArray[np.float64]) -> State:
    if np.ndim(template) == 0:
        return float(arr.reshape(-1)[0])
    return arr.reshape(np.shape(template))


class JumpStrategy(ABC):
    """Common interface: ``observe`` a cycle, ``propose_jump``, ``extrapolate`` the state.

    ``foundation`` is the number of simulated cycles the strategy needs before it can
    propose any jump; a replay on fewer rows is refused.
    """

    name: ClassVar[str] = "base"

    def __init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        """Forget all history."""
        self._cycles: list[float] = []
        self._states: list[NDArray[np.float64]] = []
        self._shape: tuple[int, ...] | None = None
        self._first_cycle = math.nan  # first observed cycle (the slope-ratio family drops
        # its history after a jump; the rate log below is kept)
        # measured rates (increment of a simulated cycle whose predecessor was observed
        # one cycle earlier), kept across jumps and window restarts: (mid-cycle, rate)
        self._rate_cycles = np.empty(0)
        self._rates = np.empty((0, 0))
        self._n_rates = 0
        self.jumps: list[tuple[int, int]] = []  # (cycle the jump starts from, length)

    @property
    @abstractmethod
    def foundation(self) -> int:
        """Simulated cycles needed before the first jump can be proposed."""

    def observe(self, cycle: int, value: State) -> None:
        """Record the state (cumulative quantity) after a simulated cycle ``cycle``."""
        if self._cycles and cycle <= self._cycles[-1]:
            raise ValueError(f"cycle {cycle} is not after the last one ({self._cycles[-1]})")
        if self._shape is None:
            self._shape = np.shape(value)
        new = _as_2d(value)
        if not self._cycles and not self._n_rates:
            self._first_cycle = float(cycle)
        if self._cycles and cycle == self._cycles[-1] + 1:
            self._log_rate(cycle - 0.5, new - self._states[-1])
        self._cycles.append(float(cycle))
        self._states.append(new)
        self._after_observe(jumped=False)

    def _log_rate(self, mid: float, rate: NDArray[np.float64]) -> None:
        n = self._n_rates
        if n == len(self._rate_cycles):  # grow the buffers (amortised O(1) per rate)
            cap = max(64, 2 * n)
            xs, ys = np.empty(cap), np.empty((cap, rate.size))
            if n:
                xs[:n], ys[:n] = self._rate_cycles[:n], self._rates[:n]
            self._rate_cycles, self._rates = xs, ys
        self._rate_cycles[n] = mid
        self._rates[n] = rate
        self._n_rates = n + 1

    def _rate_rows(self, since: float, min_samples: int, act: NDArray[np.bool_] | None,
                   total: bool) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
        """Measured rates after cycle ``since`` (at least the newest ``min_samples``):
        (mid-cycles, rates (n, elements)); ``act`` selects elements, ``total`` sums them.

        A measured rate is the recorded increment of a simulated cycle whose predecessor
        was observed one cycle earlier. Extrapolated spans never contribute, so a jump
        cannot make the curve look straighter than it is, and the log survives jumps and
        window restarts. ``None`` with fewer than ``max(min_samples, 3)`` rates.
        """
        n, m = self._n_rates, max(min_samples, 3)
        if n < m:
            return None
        tm = self._rate_cycles[:n]
        k = max(0, min(int(np.searchsorted(tm, since)), n - m))
        r = self._rates[k:n]
        if act is not None:
            r = r[:, act]
        if total:
            r = r.sum(axis=1, keepdims=True)
        if r.shape[1] == 0:
            return None
        return tm[k:], r

    def measured_curvature(self, act: NDArray[np.bool_] | None = None,
                           window_fraction: float | None = 0.5, min_samples: int = 3,
                           both_ends: bool = True, total: bool = False) -> float:
        """Relative curvature kappa = |f''| / |f'| (1/cycle) of the measured rates.

        A least-squares line is fitted to the measured rates (see :meth:`_rate_rows`) of
        the newest ``window_fraction`` of the history (all of it for ``None``); its slope
        is f'' and f' is its value at the newest rate (and at the oldest with
        ``both_ends``: the larger kappa counts). The worst element counts. ``nan``
        without an estimate (too few rates), ``inf`` where the rate is 0.
        """
        since = -math.inf
        if window_fraction is not None and self._cycles:
            since = self._cycles[-1] - window_fraction * (self._cycles[-1] - self._first_cycle)
        rows = self._rate_rows(since, min_samples, act, total)
        if rows is None:
            return math.nan
        tm, r = rows
        x = tm - tm[-1]
        xm = x.mean()
        rm = r.mean(axis=0)
        slope = ((x - xm) @ (r - rm)) / float((x - xm) @ (x - xm))
        level = rm - slope * xm  # the line at the newest rate
        kap = 0.0
        for e in ([0.0, float(x[0])] if both_ends else [0.0]):
            f1 = np.abs(level + slope * e)
            with np.errstate(divide="ignore", invalid="ignore"):
                kk = np.where(f1 > 0, np.abs(slope) / f1, np.where(slope == 0, 0.0, np.inf))
            kap = max(kap, float(np.max(kk)))
        return kap

    def _after_observe(self, jumped: bool) -> None:  # noqa: B027 - optional hook
        """Hook for strategies that update fits on every new point."""

    @abstractmethod
    def propose_jump(self) -> int:
        """Number of cycles to skip now (0 = simulate the next cycle)."""

    @abstractmethod
    def _increment(self, n: int) -> NDArray[np.float64]:
        """Extrapolated change of the state over the next ``n`` cycles."""

    def extrapolate(self, state: State, n: int) -> State:
        """State after skipping ``n`` cycles from the last observed one.

        The jumped-to point is recorded as the strategy's latest point (appendix III
        appends it to the fitted data), so the next ``observe`` is at cycle ``last + n + 1``.
        """
        if n <= 0:
            return state
        new = _as_2d(state) + self._increment(n)
        start = int(self._cycles[-1])
        self.jumps.append((start, int(n)))
        self._cycles.append(float(start + n))
        self._states.append(new)
        self._after_observe(jumped=True)
        return _restore(state, new)

    def params(self) -> dict[str, Any]:
        """The strategy's parameters (for reports)."""
        names = [k for k in inspect.signature(type(self).__init__).parameters if k != "self"]
        return {k: getattr(self, k) for k in names}


class ConstantJump(JumpStrategy):
    """McColl's constant jump (eq 2.20, section 4.2.1).

    After every simulated cycle, jump ``jump_length - 1`` cycles assuming the wear rate of
    that cycle stays constant: H_total = N * H^N. Default N = 20 (section 4.2.1; McColl
    et al. used 30).

    The rule is blind to curvature. ``step_control="error"`` (opt-in; the default
    ``"seed"`` keeps eq 2.20, whose over-prediction during running-in is the seed's point)
    keeps the extrapolation with the newest cycle's rate but shortens the jump to
    :func:`error_controlled_jump` (relative local error per jump <= ``tol``, default 1 %;
    the rate is half a cycle old, lag 0.5), with the curvature measured on the rates of
    the simulated cycles of the newest half of the run (:meth:`measured_curvature`);
    ``jump_length - 1`` stays the longest jump. No jump before 3 rates are measured.
    """

    name = "constant"

    def __init__(self, jump_length: int = 20, step_control: str = "seed",
                 tol: float = 0.01) -> None:
        if jump_length < 1:
            raise ValueError(f"jump_length = {jump_length!r}: must be >= 1")
        _check_step_control(step_control, tol)
        self.jump_length = int(jump_length)
        self.step_control = step_control
        self.tol = float(tol)
        super().__init__()

    @property
    def foundation(self) -> int:
        return 1

    @property
    def tolerance(self) -> float:
        """Relative local error per jump with ``step_control="error"``."""
        return self.tol

    def _rate(self) -> NDArray[np.float64]:
        return (self._states[-1] - self._states[-2]) / (self._cycles[-1] - self._cycles[-2])

    def propose_jump(self) -> int:
        if len(self._cycles) < 2:
            return 0
        if self.step_control == "seed":
            return self.jump_length - 1
        # error control: the rate of the newest cycle is the rate half a cycle back (lag 0.5)
        kap = self.measured_curvature(_active(self._rate()))
        if math.isnan(kap):  # fewer than 3 measured rates: no evidence of the curvature yet
            return 0
        dx = error_controlled_jump(kap, self.tol, lag=0.5)
        return int(min(dx, self.jump_length - 1))

    def _increment(self, n: int) -> NDArray[np.float64]:
        return n * self._rate()


class _SlopeRatioJump(JumpStrategy):
    """Shared machinery of the Cojocaru family (eqs 4.1-4.6).

    Two groups of ``group_size`` consecutive points (cumulative state vs cycle) are fitted
    with straight lines; their slopes s1 (older) and s2 (newer) give the ratio
    r = (s2 - s1) / s1. Linear if |r| <= q_y (the seed's "<=?"; the absolute value is
    taken so a falling rate is not read as linear). The jump length generalises eq 4.2 to
    groups whose centres are ``spacing`` cycles apart: dx = floor(q_e * spacing / |r|),
    i.e. the number of cycles over which the slope changes by the fraction q_e (for
    Cojocaru, spacing = 1 and this is eq 4.2 exactly). The state is extrapolated with the
    newest slope: state + dx * s2 (section 4.5). Groups never span a jump: after a jump
    the history restarts at the jumped-to point, so each jump needs fresh evidence.
    For an array state the worst element (largest |r|) decides.

    Step control (``step_control="error"``, the default): the ratio sees the curvature
    inside its groups only, and a ratio that is small by chance (noise, an inflection)
    gives an arbitrarily long jump. The jump is therefore also capped by
    :func:`error_controlled_jump`: relative local error per jump <= ``tol`` (default
    q_e / 2, the seed's own tolerance: q_e is the relative change of the rate over the jump,
    twice the relative error of the extrapolated increment), with the curvature measured on
    the rates of the simulated cycles of the newest half of the run, across jumps
    (:meth:`measured_curvature`), and the lag (x - 1) / 2 between the newest group's centre,
    where s2 is the rate, and the newest point. ``step_control="seed"``: eqs 4.2/4.4/4.6
    alone.
    """

    group_size: int
    q_y: float
    q_e: float
    max_jump: int | None
    step_control: str = "error"
    tol: float | None = None

    def _set_step_control(self, step_control: str, tol: float | None) -> None:
        _check_step_control(step_control, tol)
        self.step_control = step_control
        self.tol = None if tol is None else float(tol)

    @property
    def tolerance(self) -> float:
        """Relative local error per jump: ``tol``, or q_e / 2 when ``tol`` is None."""
        return self.q_e / 2 if self.tol is None else self.tol

    def _lag(self) -> float:
        """Cycles between the newest group's centre (where its slope is the rate) and the
        newest point."""
        return (self.group_size - 1) / 2

    def _groups(self) -> tuple[slice, slice]:
        raise NotImplementedError

    def _span_needed(self) -> int:
        raise NotImplementedError

    def _spacing(self) -> float:
        raise NotImplementedError

    @property
    def foundation(self) -> int:
        return self._span_needed() - 1

    def _after_observe(self, jumped: bool) -> None:
        if jumped:  # evidence restarts at the jumped-to point
            self._cycles = self._cycles[-1:]
            self._states = self._states[-1:]

    def _slope(self, sl: slice) -> NDArray[np.float64]:
        x = np.asarray(self._cycles[sl])
        y = np.vstack(self._states[sl])
        xc = x - x.mean()
        return (xc @ (y - y.mean(axis=0))) / (xc @ xc)

    def ratio(self) -> float:
        """Worst-element |r| of eq 4.1/4.3/4.5 on the latest points (nan if too few)."""
        if len(self._cycles) < self._span_needed():
            return math.nan
        g1, g2 = self._groups()
        s1, s2 = self._slope(g1), self._slope(g2)
        act = _active(s2) & (s1 != 0)
        if not np.any(act):
            return math.nan
        return float(np.max(np.abs((s2[act] - s1[act]) / s1[act])))

    def reset(self) -> None:
        super().reset()
        #: (cycle, |r| or nan, proposed jump) per check: the figure 4.4/4.7/4.10 history
        self.history: list[tuple[int, float, int]] = []

    def propose_jump(self) -> int:
        r = self.ratio()
        n = 0
        if math.isfinite(r) and r <= self.q_y:
            dx = math.inf if r == 0 else self.q_e * self._spacing() / r
            if self.step_control == "error":
                # the ratio sees the curvature inside its groups only; the rates measured
                # over the newest half of the run (across jumps) cap the jump too
                kap = self.measured_curvature(_active(self._slope(self._groups()[1])))
                if not math.isnan(kap):
                    dx = min(dx, error_controlled_jump(kap, self.tolerance, self._lag()))
            if self.max_jump is not None:
                dx = min(dx, self.max_jump)
            n = int(min(dx, UNBOUNDED_JUMP))
        self.history.append((int(self._cycles[-1]), r, n))
        return n

    def _increment(self, n: int) -> NDArray[np.float64]:
        _, g2 = self._groups()
        return n * self._slope(g2)


class CojocaruJump(_SlopeRatioJump):
    """Cojocaru's slope ratio on three consecutive points (eqs 4.1-4.2, section 4.2.2).

    r = (s_(n+1 to n+2) - s_(n to n+1)) / s_(n to n+1); jump if |r| <= q_y, by
    dx = floor(q_e / |r|) cycles. Defaults q_y = 0.02, q_e = 0.05 (section 4.2.2).
    ``max_jump`` (cycles, default none) caps dx; the seed sets no cap. ``step_control``,
    ``tol``: the error-controlled cap of :class:`_SlopeRatioJump` (default on, tol = q_e / 2
    = 2.5 %).
    """

    name = "cojocaru"

    def __init__(self, q_y: float = 0.02, q_e: float = 0.05, max_jump: int | None = None,
                 step_control: str = "error", tol: float | None = None) -> None:
        self.group_size = 2
        self.q_y = float(q_y)
        self.q_e = float(q_e)
        self.max_jump = None if max_jump is None else int(max_jump)
        self._set_step_control(step_control, tol)
        super().__init__()

    def _span_needed(self) -> int:
        return 3

    def _groups(self) -> tuple[slice, slice]:
        return slice(-3, -1), slice(-2, None)

    def _spacing(self) -> float:
        return 1.0


class _GroupsJump(_SlopeRatioJump):
    """Slope ratio of two groups of ``group_size`` cycles (sections 4.2.3-4.2.4)."""

    even_groups = False

    def __init__(self, group_size: int = 8, q_y: float = 1.0, q_e: float = 0.001,
                 max_jump: int | None = None, step_control: str = "error",
                 tol: float | None = None) -> None:
        if group_size < 2 or (self.even_groups and group_size % 2):
            kind = "an even number" if self.even_groups else "a whole number"
            raise ValueError(f"group_size = {group_size!r}: must be {kind} >= 2")
        self.group_size = int(group_size)
        self.q_y = float(q_y)
        self.q_e = float(q_e)
        self.max_jump = None if max_jump is None else int(max_jump)
        self._set_step_control(step_control, tol)
        super().__init__()


class MovingGroupsJump(_GroupsJump):
    """Moving-average groups (eqs 4.3-4.4, section 4.2.3).

    Two abutting groups of x points: r = (s_(n+x to n+2x) - s_(n to n+x)) / s_(n to n+x);
    group centres are x cycles apart, dx = floor(q_e * x / |r|). Defaults x = 8,
    q_y = 1, q_e = 0.1 % (table 4.1, the column in which the seed saw jumps).
    ``step_control``, ``tol``: the error-controlled cap of :class:`_SlopeRatioJump`
    (default on, tol = q_e / 2 = 0.05 %; lag 3.5 cycles for x = 8).
    """

    name = "moving"

    def _span_needed(self) -> int:
        return 2 * self.group_size

    def _groups(self) -> tuple[slice, slice]:
        x = self.group_size
        return slice(-2 * x, -x), slice(-x, None)

    def _spacing(self) -> float:
        return float(self.group_size)


class OverlappingGroupsJump(_GroupsJump):
    """Groups overlapping by half (eqs 4.5-4.6, section 4.2.4).

    Groups (n .. n+x) and (n+x/2 .. n+1.5x) share x/2 points; centres are x/2 cycles
    apart, dx = floor(q_e * (x/2) / |r|). Defaults x = 8, q_y = 1, q_e = 0.1 % (table 4.2).
    ``step_control``, ``tol``: the error-controlled cap of :class:`_SlopeRatioJump`
    (default on, tol = q_e / 2 = 0.05 %; lag 3.5 cycles for x = 8).
    """

    name = "overlapping"
    even_groups = True

    def _span_needed(self) -> int:
        return self.group_size + self.group_size // 2

    def _groups(self) -> tuple[slice, slice]:
        x, h = self.group_size, self.group_size // 2
        return slice(-(x + h), -h), slice(-x, None)

    def _spacing(self) -> float:
        return self.group_size / 2


@dataclass
class AdaptiveDiagnostics:
    """Per-check record of the adaptive strategy (figure 4.12-style history)."""

    cycle: list[int] = field(default_factory=list)
    q_coef: list[float] = field(default_factory=list)  # max relative coefficient change
    curvature: list[float] = field(default_factory=list)  # |f''| / |f'|, 1/cycle
    proposed: list[int] = field(default_factory=list)


class AdaptiveJump(JumpStrategy):
    """Adaptive polynomial-convergence strategy (section 4.3) with section 4.4's fixes.

    After every new point (simulated, or the jumped-to point as in appendix III) the
    cumulative state w(n) is fitted with a polynomial of ``degree`` (3, eq 4.7) in
    t = n - n_r, n_r the cycle where the current window (re)started (cycle 0 = origin at
    first, as appendix III starts its data at (0, 0)). The fit uses the points after
    n_r within the last ``window_fraction`` (1/2) of all cycles run (the moving window
    the seed allows in section 4.3; ``None`` = every point since n_r, the seed's
    preliminary version), never fewer than ``foundation_cycles`` (8, section 4.4).

    1. Convergence (eqs 4.9-4.12): "safe" when every coefficient changed by at most
       ``q_coef`` (2 %, section 4.3) relative to the previous fit. Decision: denominators
       are floored at ``coef_floor`` x (fitted rise over the window) / span^k for the
       coefficient of t^k, so a negligible term (the cubic term of a straight line)
       cannot block convergence through a near-zero denominator.
    2. Linearity (eq 4.13): f'' has units, so the dimensionless curvature
       kappa = |f''| / |f'| (relative change of the rate per cycle, 1/cycle) is compared
       with q_y. Decision: kappa is taken as the larger of its values at both ends of the
       window (``curvature_over_window``), so a window still holding the running-in is
       not called linear because its newest end happens to be straight.
    3. Jump length (eq 4.13'): dx = floor(q_e |f'(t_end)| / |f''|) = floor(q_e / kappa),
       q_e = 2 % (section 4.4): the cycles over which the rate changes by q_e.
    4. Extrapolation (eq 4.15): state + dx f'(t_end); ``taylor_order=2`` adds
       f'' dx^2 / 2 as appendix III does.

    Section 4.4 modifications:

    a. maximum jump length: ``max_jump_initial`` up to cycle ``max_jump_until`` (200),
       then growing in proportion to the cycle number (L = L0 n / 200). L0 = 200 is the
       seed's final variant (figure 4.16); 15 is the figure 4.15 variant;
    b. decreasing q_y: ``q_y`` (0.5 %) up to cycle ``q_y_until`` (300, where appendix III
       switches thresholds), then ``q_y_late`` (0.02 %, figure 4.16); since kappa <= q_y
       means dx >= q_e / q_y, late jumps must be >= 100 cycles long. Appendix III also
       lowers the polynomial degree after cycle 300 (to a straight line); decision:
       ``degree_late`` = 2 after ``q_y_until`` (a line has no curvature left to check; the
       end curvature of a cubic on noisy wear is too noisy for q_y = 0.02 %); ``None``
       keeps ``degree`` throughout (the text's version);
    c. maximum consecutive jumps: after ``max_consecutive_jumps`` (3) jumps separated
       only by single simulated cycles, no jump until ``refit_cycles`` (8) new cycles were
       simulated and a new converged fit exists;
    d. moving window: at that point the old polynomial is abandoned and the window restarts
       at the present cycle (``moving_window=True``).

    For an array state every element is fitted and extrapolated by its own f'. With
    ``decide_on="worst"`` the worst element carrying wear decides convergence and linearity;
    with ``"total"`` the sum of the elements does (for a wear-depth map: the worn volume).
    Decision: the fretting loop uses ``"total"``: on a grid, a point the growing scar reaches
    starts wearing with a kink, so single points never look polynomial, while the worn
    volume does (the fit is linear in the data: the sum's fit is the sum of the fits).

    Step control (``step_control="error"``, the default). Steps 1 and 4 are kept; steps 2
    and 3 become an error-controlled jump, as in an ODE integrator. The seed's linearity
    gate kappa <= q_y refuses every jump on a curve that bends, however smoothly (a power
    law or a slow run-in), instead of shortening the jump; and the polynomial, which
    contains the jumped-to points (its own straight extrapolations), can look straighter
    than the wear is. So:

    2'. kappa is the larger of the polynomial's (as above) and the one measured on the
        rates of the simulated cycles of the newest ``window_fraction`` of the run
        (:meth:`measured_curvature`; no jumped point enters it);
    2''. the extrapolation rate f'(t_end) is checked against the measured rates
        (:meth:`rate_mismatch`): its relative error e_r beyond two standard errors uses up
        part of the tolerance; if e_r >= tol the polynomial no longer follows the wear and,
        with ``moving_window``, the window restarts (modification d) at the present cycle;
    3'. dx = floor(2 (tol - e_r) / kappa) (:func:`error_controlled_jump`): the longest jump
        whose predicted error (truncation 0.5 |f''| dx^2, the difference of the linear and
        quadratic predictors, plus e_r |f'| dx) stays within ``tol`` of the extrapolated
        increment |f'| dx, capped by modification a; no jump shorter than ``min_jump``.

    ``tol`` (default None = q_e / 2 = 1 %): relative local error per jump. Since every jump
    misses at most ``tol`` of what it adds, the final value misses at most ``tol`` of its
    jumped part (noise adds a random part). With e_r = 0 this is the seed's
    dx = q_e / kappa (eq 4.13'). ``min_jump`` (4 cycles) = q_e / q_y, the shortest jump the
    seed's early linearity gate allowed (it keeps jumps out of a fast running-in).
    ``q_y``, ``q_y_late``, ``q_y_until`` are used by ``step_control="seed"`` only (the
    seed's version, steps 1-4 unchanged). With ``taylor_order=2`` the same (first-order)
    error estimate is used, which is then conservative.
    """

    name = "polynomial"

    def __init__(
        self,
        degree: int = 3,
        degree_late: int | None = 2,
        foundation_cycles: int = 8,
        q_coef: float = 0.02,
        coef_floor: float = 0.05,
        q_y: float = 0.005,
        q_y_late: float = 0.0002,
        q_y_until: int = 300,
        q_e: float = 0.02,
        max_jump_initial: int = 200,
        max_jump_until: int = 200,
        max_consecutive_jumps: int = 3,
        refit_cycles: int = 8,
        moving_window: bool = True,
        window_fraction: float | None = 0.5,
        curvature_over_window: bool = True,
        taylor_order: int = 1,
        decide_on: str = "worst",
        step_control: str = "error",
        tol: float | None = None,
        min_jump: int = 4,
    ) -> None:
        _check_step_control(step_control, tol)
        if min_jump < 1:
            raise ValueError(f"min_jump = {min_jump!r}: must be >= 1")
        self.step_control = step_control
        self.tol = None if tol is None else float(tol)
        self.min_jump = int(min_jump)
        if decide_on not in ("worst", "total"):
            raise ValueError(f"decide_on = {decide_on!r}: must be 'worst' (every element) or "
                             "'total' (the sum of the state, e.g. the worn volume)")
        self.decide_on = decide_on
        if degree < 1:
            raise ValueError(f"degree = {degree!r}: must be >= 1")
        if taylor_order not in (1, 2):
            raise ValueError(f"taylor_order = {taylor_order!r}: must be 1 (eq 4.15) or 2 "
                             "(appendix III)")
        if foundation_cycles < degree + 1:
            raise ValueError(f"foundation_cycles = {foundation_cycles!r}: must be >= degree + 1 "
                             f"= {degree + 1}")
        self.degree = int(degree)
        if degree_late is not None and not 2 <= degree_late <= degree:
            raise ValueError(f"degree_late = {degree_late!r}: must be None or in [2, degree = "
                             f"{degree}]")
        self.degree_late = None if degree_late is None else int(degree_late)
        self.foundation_cycles = int(foundation_cycles)
        self.q_coef = float(q_coef)
        self.coef_floor = float(coef_floor)
        self.q_y = float(q_y)
        self.q_y_late = float(q_y_late)
        self.q_y_until = int(q_y_until)
        self.q_e = float(q_e)
        self.max_jump_initial = int(max_jump_initial)
        self.max_jump_until = int(max_jump_until)
        self.max_consecutive_jumps = int(max_consecutive_jumps)
        self.refit_cycles = int(refit_cycles)
        self.moving_window = bool(moving_window)
        if window_fraction is not None and not 0.0 < window_fraction <= 1.0:
            raise ValueError(f"window_fraction = {window_fraction!r}: must be in (0, 1] or None")
        self.curvature_over_window = bool(curvature_over_window)
        self.window_fraction = None if window_fraction is None else float(window_fraction)
        self.taylor_order = int(taylor_order)
        super().__init__()

    def reset(self) -> None:
        super().reset()
        self._n0 = 0  # index of the window's first point in the history
        self._coef: NDArray[np.float64] | None = None
        self._prev: NDArray[np.float64] | None = None
        self._consecutive = 0
        self._since_reset = 0
        self._blocked = False
        self.diagnostics = AdaptiveDiagnostics()

    @property
    def foundation(self) -> int:
        return self.foundation_cycles

    @property
    def tolerance(self) -> float:
        """Relative local error per jump: ``tol``, or q_e / 2 when ``tol`` is None."""
        return self.q_e / 2 if self.tol is None else self.tol

    def max_jump(self, cycle: float) -> int:
        """Section 4.4 (a): maximum jump length at ``cycle``."""
        if cycle <= self.max_jump_until:
            return self.max_jump_initial
        return int(self.max_jump_initial * cycle / self.max_jump_until)

    def degree_at(self, cycle: float) -> int:
        """Polynomial degree at ``cycle`` (``degree_late`` after ``q_y_until``)."""
        if self.degree_late is not None and cycle > self.q_y_until:
            return self.degree_late
        return self.degree

    def q_y_at(self, cycle: float) -> float:
        """Section 4.4 (b): linearity threshold at ``cycle`` (1/cycle)."""
        return self.q_y if cycle <= self.q_y_until else self.q_y_late

    def _window(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Points of the fit window, t = cycle - reference cycle of the current window."""
        cyc = np.asarray(self._cycles[self._n0:])
        y = np.vstack(self._states[self._n0:])
        if self.window_fraction is not None and len(cyc) > self.foundation_cycles:
            start = cyc[-1] - self.window_fraction * (cyc[-1] - self._cycles[0])
            k = min(int(np.searchsorted(cyc, start)), len(cyc) - self.foundation_cycles)
            cyc, y = cyc[k:], y[k:]
        return cyc - self._cycles[self._n0], y

    def _after_observe(self, jumped: bool) -> None:
        if jumped:
            self._consecutive += 1
        else:
            self._since_reset += 1
        t, y = self._window()
        self._prev = self._coef
        self._coef = None
        deg = self.degree_at(self._cycles[-1])
        if len(t) >= max(self.foundation_cycles, deg + 1):
            # highest power first, shape (degree + 1, elements)
            self._coef = np.polyfit(t, y, deg)

    def _derivs(self, t: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        assert self._coef is not None
        c = self._coef
        p = np.arange(c.shape[0] - 1, -1, -1, dtype=float)[:, None]
        d1 = np.sum(np.where(p >= 1, p * c * t ** np.maximum(p - 1, 0), 0.0), axis=0)
        d2 = np.sum(np.where(p >= 2, p * (p - 1) * c * t ** np.maximum(p - 2, 0), 0.0), axis=0)
        return d1, d2

    def _converged(self, span: float, rise: NDArray[np.float64],
                   act: NDArray[np.bool_]) -> float:
        """Max relative coefficient change (eqs 4.9-4.12) over active elements.

        Denominators are floored at ``coef_floor * rise / span**k`` for the coefficient of
        t**k (``rise`` = fitted change of the state over the window, ``span`` its length).
        """
        assert self._coef is not None and self._prev is not None
        c, prev = self._coef[:, act], self._prev[:, act]
        p = np.arange(c.shape[0] - 1, -1, -1, dtype=float)[:, None]
        floor = self.coef_floor * np.abs(rise[act])[None, :] / max(span, 1.0) ** p
        denom = np.maximum(np.abs(prev), floor)
        denom = np.where(denom > 0, denom, np.inf)
        return float(np.max(np.abs(c - prev) / denom))

    def _converged_total(self, t0: float, t1: float, act: NDArray[np.bool_]) -> float:
        """Relative coefficient change (eqs 4.9-4.12) of the fit of the summed state."""
        assert self._coef is not None and self._prev is not None
        c = self._coef[:, act].sum(axis=1)
        prev = self._prev[:, act].sum(axis=1)
        p = np.arange(c.size - 1, -1, -1, dtype=float)
        rise = abs(float(np.polyval(c, t1) - np.polyval(c, t0)))
        floor = self.coef_floor * rise / max(t1 - t0, 1.0) ** p
        denom = np.maximum(np.abs(prev), floor)
        denom = np.where(denom > 0, denom, np.inf)
        return float(np.max(np.abs(c - prev) / denom))

    def rate_mismatch(self, act: NDArray[np.bool_], cycle: float) -> float:
        """Relative error of the extrapolation rate f'(t_end) of the polynomial, judged
        against the measured rates (0 when within two standard errors; ``inf`` without
        enough measured rates).

        A quadratic is fitted to the measured rates of the fit window (at least
        ``foundation_cycles`` of them) and evaluated at ``cycle``: an independent estimate
        of the present rate, which sees no jumped point. The mismatch is
        (|f'(t_end) - rate| - 2 se) / |rate|, se = standard error of that estimate; the
        worst element counts (the total with ``decide_on="total"``).
        """
        total = self.decide_on == "total"
        t, _ = self._window()
        rows = self._rate_rows(t[0] + self._cycles[self._n0], self.foundation_cycles, act,
                               total)
        if rows is None:
            return math.inf
        tm, r = rows
        x = (tm - cycle) / max(cycle - tm[0], 1.0)
        v = np.vander(x, 3)
        coef, *_ = np.linalg.lstsq(v, r, rcond=None)
        sigma = np.sqrt(np.sum((r - v @ coef) ** 2, axis=0) / max(len(x) - 3, 1))
        se = sigma * math.sqrt(float(np.linalg.pinv(v.T @ v)[-1, -1]))
        meas = coef[-1]
        d1 = self._derivs(float(t[-1]))[0][act]
        if total:
            d1 = np.array([d1.sum()])
        with np.errstate(divide="ignore", invalid="ignore"):
            mis = (np.abs(d1 - meas) - 2.0 * se) / np.abs(meas)
        mis = np.where(np.isfinite(mis), mis, np.inf)
        return max(0.0, float(np.max(mis)))

    def _restart_window(self) -> None:
        self._n0 = len(self._cycles) - 1
        self._coef = None
        self._prev = None

    def propose_jump(self) -> int:
        cycle = self._cycles[-1]
        proposal = 0
        qc = curv = math.nan
        if self._consecutive >= self.max_consecutive_jumps and self.max_consecutive_jumps > 0:
            # section 4.4 (c) + (d): too many jumps in a row -> block and restart window
            self._consecutive = 0
            self._since_reset = 0
            self._blocked = True
            if self.moving_window:
                self._restart_window()
        elif self._blocked and self._since_reset < self.refit_cycles:
            pass
        elif self._coef is not None and self._prev is not None and \
                self._prev.shape == self._coef.shape:
            self._blocked = False
            t, y = self._window()
            t_end = float(t[-1])
            d1, d2 = self._derivs(t_end)
            act = act_el = _active(d1)
            if np.any(act):
                rise = np.polyval(self._coef, t_end) - np.polyval(self._coef, float(t[0]))
                d1s, d2s = self._derivs(float(t[0]))
                if self.decide_on == "total":
                    qc = self._converged_total(float(t[0]), t_end, act)
                    d1, d2, d2s = (np.array([np.sum(v[act])]) for v in (d1, d2, d2s))
                    act = np.ones(1, dtype=bool)
                else:
                    qc = self._converged(t_end - float(t[0]), rise, act)
                if self.curvature_over_window:
                    d2 = np.maximum(np.abs(d2), np.abs(d2s))
                curv = float(np.max(np.abs(d2[act]) / np.abs(d1[act])))
                if self.step_control == "seed":
                    if qc <= self.q_coef and curv <= self.q_y_at(cycle):
                        dx = math.inf if curv == 0 else self.q_e / curv
                        proposal = int(min(dx, self.max_jump(cycle), UNBOUNDED_JUMP))
                elif qc <= self.q_coef:
                    kap = self.measured_curvature(
                        act_el, self.window_fraction, self.foundation_cycles,
                        self.curvature_over_window, self.decide_on == "total")
                    rate_err = self.rate_mismatch(act_el, cycle)
                    curv = max(curv, math.inf if math.isnan(kap) else kap)
                    dx = error_controlled_jump(curv, self.tolerance, rate_error=rate_err)
                    proposal = int(min(dx, self.max_jump(cycle), UNBOUNDED_JUMP))
                    if proposal < self.min_jump:
                        proposal = 0
                    if rate_err >= self.tolerance and self.moving_window and \
                            len(self._cycles) - self._n0 > 2 * self.foundation_cycles:
                        # the polynomial no longer follows the measured rate: drop it
                        self._restart_window()
        if proposal == 0:
            self._consecutive = 0
        d = self.diagnostics
        d.cycle.append(int(cycle))
        d.q_coef.append(qc)
        d.curvature.append(curv)
        d.proposed.append(proposal)
        return proposal

    def _increment(self, n: int) -> NDArray[np.float64]:
        t, _ = self._window()
        d1, d2 = self._derivs(float(t[-1]))
        inc = n * d1
        if self.taylor_order == 2:
            inc = inc + 0.5 * n * n * d2
        return inc


@dataclass
class ReplayResult:
    """Outcome of :func:`replay`. Values in the units of the increments."""

    strategy: str
    params: dict[str, Any]
    cycles_total: int
    cycles_simulated: int
    cycles_saved_fraction: float
    final_value: State
    reference_final_value: State
    relative_difference: float
    max_relative_difference: float
    jumps: list[tuple[int, int]]  # (cycle jumped from, number of cycles skipped)
    cycles: NDArray[np.float64]  # cycles where the replay has a value
    values: NDArray[np.float64]  # replayed state there
    reference: NDArray[np.float64]  # reference cumulative state, every cycle
    reference_cycles: NDArray[np.float64]

    def summary(self) -> dict[str, Any]:
        """JSON-ready summary (no per-cycle arrays)."""
        def num(v: State) -> Any:
            return float(v) if np.ndim(v) == 0 else np.asarray(v).tolist()
        return {
            "strategy": self.strategy,
            "params": self.params,
            "cycles_total": self.cycles_total,
            "cycles_simulated": self.cycles_simulated,
            "cycles_saved_fraction": self.cycles_saved_fraction,
            "final_value": num(self.final_value),
            "reference_final_value": num(self.reference_final_value),
            "relative_difference": self.relative_difference,
            "max_relative_difference": self.max_relative_difference,
            "jumps": len(self.jumps),
        }


def _reldiff(a: NDArray[np.float64], b: NDArray[np.float64]) -> float:
    """|a - b| / |b| (norms over elements for a profile); 0 where b is 0."""
    nb = float(np.linalg.norm(b))
    return float(np.linalg.norm(a - b)) / nb if nb > 0 else 0.0


def replay(strategy: JumpStrategy, cycles: ArrayLike, increments: ArrayLike) -> ReplayResult:
    """Replay a recorded run with cycle-jumping.

    ``increments[i]`` is the quantity gained in cycle ``cycles[i]`` (scalar per row, or a
    row of profile values: shape (N,) or (N, K)). Simulating a cycle = reading its row and
    adding it to the state; a jump of n cycles skips n rows and adds the strategy's
    extrapolation instead. The reference is the full cumulative sum. The relative
    difference is |value - reference| / |reference| (Euclidean norms for a profile),
    ``max_relative_difference`` is over every cycle where the replay has a value.
    """
    cyc = np.asarray(cycles, dtype=float).reshape(-1)
    inc = np.asarray(increments, dtype=float)
    n_rows = len(cyc)
    if inc.shape[0] != n_rows:
        raise ValueError("cycles and increments have different lengths")
    if n_rows < strategy.foundation + 1:
        raise ValueError(f"{n_rows} rows; the {strategy.name} strategy needs at least "
                         f"{strategy.foundation + 1}")
    if np.any(np.diff(cyc) <= 0):
        raise ValueError("cycles must be strictly increasing")
    ref = np.cumsum(inc, axis=0)
    strategy.reset()
    zero = np.zeros(inc.shape[1:]) if inc.ndim > 1 else 0.0
    strategy.observe(int(cyc[0]) - 1, zero)
    state: State = zero
    out_c: list[float] = []
    out_v: list[State] = []
    simulated = 0
    max_rd = 0.0
    i = 0
    while i < n_rows:
        state = state + inc[i]
        simulated += 1
        strategy.observe(int(cyc[i]), state)
        out_c.append(cyc[i])
        out_v.append(state)
        max_rd = max(max_rd, _reldiff(np.asarray(state), ref[i]))
        n = min(strategy.propose_jump(), n_rows - 1 - i)
        if n > 0:
            state = strategy.extrapolate(state, n)
            i += n
            out_c.append(cyc[i])
            out_v.append(state)
            max_rd = max(max_rd, _reldiff(np.asarray(state), ref[i]))
        i += 1
    final = state
    return ReplayResult(
        strategy=strategy.name,
        params=strategy.params(),
        cycles_total=n_rows,
        cycles_simulated=simulated,
        cycles_saved_fraction=1.0 - simulated / n_rows,
        final_value=final,
        reference_final_value=ref[-1] if inc.ndim > 1 else float(ref[-1]),
        relative_difference=_reldiff(np.asarray(final), ref[-1]),
        max_relative_difference=max_rd,
        jumps=list(strategy.jumps),
        cycles=np.asarray(out_c),
        values=np.asarray(out_v),
        reference=ref,
        reference_cycles=cyc,
    )


def two_phase_rate(cycles: ArrayLike, steady_rate: float = 1.0, ratio: float = 10.0,
                   tau: float = 50.0) -> NDArray[np.float64]:
    """Noise-free wear rate of :func:`synthetic_two_phase_series` (per cycle)."""
    n = np.asarray(cycles, dtype=float)
    return steady_rate * (1.0 + (ratio - 1.0) * np.exp(-(n - 1.0) / tau))


def synthetic_two_phase_series(
    n: int = 2000, ratio: float = 10.0, noise: float = 0.1, seed: int = 0,
    steady_rate: float = 1.0, tau: float = 50.0,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Running-in then steady wear (seed figure 5.17): ``(cycles, increments)``.

    increment(c) = steady_rate * (1 + (ratio - 1) * exp(-(c - 1) / tau)) * (1 + noise * z),
    c = 1..n, z ~ N(0, 1) i.i.d. (Gaussian multiplicative noise, ``numpy.random.default_rng
    (seed)``). The first cycle wears ``ratio`` times the steady rate; the rate is within
    1.5x of steady after c > 1 + tau * ln(2 (ratio - 1)) (145 cycles for the defaults).
    ``ratio = 1`` gives a linear series. Units: those of ``steady_rate`` (e.g. m/cycle).
    """
    c = np.arange(1, n + 1, dtype=float)
    rate = two_phase_rate(c, steady_rate, ratio, tau)
    z = np.random.default_rng(seed).standard_normal(n)
    return c, rate * (1.0 + noise * z)


def transition_end(ratio: float = 10.0, tau: float = 50.0, factor: float = 1.5) -> float:
    """Last cycle of the running-in transition: rate > ``factor`` x steady before it."""
    if ratio <= factor:
        return 0.0
    return 1.0 + tau * math.log((ratio - 1.0) / (factor - 1.0))


#: Shapes of :func:`synthetic_smooth_series`.
SMOOTH_SHAPES = ("linear", "power", "exponential", "two_phase")


def synthetic_smooth_series(
    shape: str, n: int = 3000, noise: float = 0.0, seed: int = 0, steady_rate: float = 1.0,
    ratio: float = 10.0, exponent: float = 0.5, decay: float | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Smooth wear series for step-control tests: ``(cycles, increments)``, c = 1..n.

    The noise-free rate (per cycle, units of ``steady_rate``) is

    * ``linear``: steady_rate;
    * ``power``: the increments of h(c) = steady_rate c**exponent (h ~ N**0.5: wear that
      slows down for ever, e.g. growing contact area);
    * ``exponential``: steady_rate (1 + (ratio - 1) exp(-(c - 1) / decay)), a run-in that
      starts ``ratio`` (10) times faster than steady and decays over ``decay`` cycles
      (default n / 10: a slow run-in over the first third of the run);
    * ``two_phase``: :func:`synthetic_two_phase_series` (the same law with tau = 50: a fast
      run-in, then steady).

    Each increment is multiplied by (1 + noise z), z ~ N(0, 1) i.i.d. from
    ``numpy.random.default_rng(seed)``, as in :func:`synthetic_two_phase_series`.
    """
    if shape not in SMOOTH_SHAPES:
        raise ValueError(f"unknown shape {shape!r}; allowed: {', '.join(SMOOTH_SHAPES)}")
    if shape == "two_phase":
        return synthetic_two_phase_series(n=n, ratio=ratio, noise=noise, seed=seed,
                                          steady_rate=steady_rate)
    c = np.arange(1, n + 1, dtype=float)
    if shape == "linear":
        rate = np.full(n, float(steady_rate))
    elif shape == "power":
        rate = steady_rate * (c**exponent - (c - 1.0) ** exponent)
    else:
        tau = n / 10.0 if decay is None else float(decay)
        rate = two_phase_rate(c, steady_rate, ratio, tau)
    z = np.random.default_rng(seed).standard_normal(n)
    return c, rate * (1.0 + noise * z)
