"""Cycle jumping whose step control judges the underlying curve, not the noise (``smooth``).

The adaptive strategy of P. Lu, "Numerical Modelling of Fretting Wear and Debris
Particles" (PhD thesis, University of Exeter, 2018), chapter 4, section 4.3, fits a cubic
to the cumulative wear w(n) (eq 4.7), jumps dx = q_e |f'| / |f''| cycles (eq 4.13') and
extrapolates w + dx f'(n_end) (eq 4.15). The error-controlled version in
:mod:`tribodem.cyclejump.strategies` measures the curvature on the per-cycle rates and
checks the fitted rate against them. On a noisy series both tests read the noise as
curvature, so the jumps shrink with the noise and not with the curve. :class:`SmoothJump`
keeps the seed's ingredients: a polynomial fit, first-order extrapolation with the fitted
rate, the maximum jump of section 4.4 (a) and a foundation of simulated cycles (section
4.4). It replaces the step control with one that judges the smoothness of the underlying
curve from a local least-squares fit and the fit's uncertainty.

Data. After a simulated cycle c the strategy sees the cumulative state y(c). If it also
saw y(c - 1) (cycle c - 1 was simulated, or a jump ended there), the increment
r = y(c) - y(c - 1) is a *measured rate* at the mid-cycle m = c - 1/2. This is the log of
:class:`~tribodem.cyclejump.strategies.JumpStrategy`; extrapolated spans never enter it.
The model is r_i = f(m_i) + e_i, where f is the underlying rate dw/dn and the e_i are
independent noise.

1. Local fit. Take x = m - c0 (x <= -1/2) around the newest cycle c0, and the measured
   rates of a window c0 - m <= D. Fit by least squares

       f(c0 + x) ~ a + b x + c x^2 / 2 + d x^3 / 6     (a, b, c, d = f, f', f'', f''' at c0)

   Fitting the increments is the same as fitting the cumulative state with a polynomial
   one degree higher (the cubic of eq 4.7 is degree 2 here), under the right noise model.
   Independent per-cycle noise makes y a random walk, and the generalised least squares
   of a random walk are the ordinary least squares of its increments. The offsets that
   earlier jumps left in y (their extrapolation errors) also drop out. The residual
   s^2 = RSS / (W - p) (W rates, p coefficients) measures the noise plus whatever of the
   curve the model misses. It gives the covariance s^2 (V^T V)^-1 of the coefficients,
   multiplied by (t_(W-p) / z)^2 (:func:`student_factor`) so that a few rates do not pass
   for a precise fit.

   Degree: start from ``degree`` (3) and drop the top term while |coefficient| <= z se
   (z = ``confidence``). A noisy steady rate is then a straight line, not curvature.
   Where the curve does bend, the higher term removes the bias that a lower one leaves
   at the window's end. The endpoint slope of a quadratic fitted over [-D, 0] misses
   about 0.15 |f'''| D^2. After long jumps the newest ``foundation_cycles`` rates spread
   over a long span D, so this bias makes the seed's cubic w(n) under-predict the
   truncation of a power law by up to 40 %. With the cubic rate allowed, the bound below
   held on every noise-free series tried.

2. Window. The candidate spans are D_0 < D_1 < ...: D_0 holds the newest
   ``foundation_cycles`` rates, D_(j+1) = ``window_growth`` D_j, and the largest is
   ``window_fraction`` of the cycles run (the moving window of section 4.3). Each gives
   estimates (a_j, b_j) with standard errors. The rule is the intersection of confidence
   intervals (Goldenshluger and Nemirovski, Math. Methods Statist. 6 (1997) 135-170;
   Katkovnik, IEEE Trans. Signal Process. 47 (1999) 2567-2571): the window is the
   longest one whose intervals a_j -+ z se and b_j -+ z se intersect those of every
   shorter window. The standard errors are taken at the smallest residual s seen so far,
   that of the most local fit, so a long window's misfit does not widen its own interval.
   On a steady noisy rate every window agrees, and the longest one averages the most
   noise. Near a change of rate, the bias of the long windows shows against the short
   ones and the fit becomes local.

3. Extrapolation (eq 4.15 with the fitted rate). Over a jump of L cycles every element
   advances by L a_e, where a_e is its own fitted rate at c0. All elements use the same
   window and degree. The fit is linear in the data, so the elements' increments add up
   to the total's. Noise averages out over a jump because a_e is fitted over the window;
   it is not the last cycle's increment.

4. Predicted truncation error. The true increment is the integral of f over the jump.
   By the fitted model the extrapolation misses E(L) = integral_0^L (f(c0 + t) - a) dt,
   whose Taylor terms are b L^2/2, c L^3/6, d L^4/24. The prediction is

       T(L) = sqrt(E+(L)^2 + Var E(L)),   E+ = |b| L^2/2 + |c| L^3/6 + |d| L^4/24,

   where Var E = g^T Cov(b, c, d) g and g = (L^2/2, L^3/6, L^4/24). Cancellation between
   the terms is not relied on: a fitted polynomial's highest terms are the least reliable
   far out. For a completely monotone decay (exponential, power law: alternating Taylor
   terms of decreasing size), |b| L^2/2 alone already bounds the true error. The variance
   term is the curvature the fit cannot exclude, so a curve known from only a few rates
   is not taken for straight. With only b and no variance, T / (a L) = kappa L / 2: the
   seed's own error model (eq 4.13' with q_e = 2 tol).

5. Jump length. The jump is the longest L before the first L with

       T(L) > ``safety`` * ``tol`` * |a| L      (relative local error per jump <= tol).

   ``safety`` (0.9) is the usual factor of ODE step-size control (Hairer, Norsett and
   Wanner, Solving ODEs I, section II.4): T is itself an estimate. L is capped by the
   maximum jump of section 4.4 (a): L0 up to cycle n0, then L0 n / n0. There is no jump
   shorter than ``min_jump`` (4 = q_e / q_y of the seed, which keeps 1-3 cycle jumps out
   of a fast running-in), and none before ``foundation_cycles`` rates are measured.
   ``decide_on="total"`` (the default, and the fretting loop's worn volume) decides on the
   sum of the elements. ``"worst"`` decides on every element that carries wear
   (rate >= ACTIVE_FRACTION of the largest), each on the window the total chose.

6. Rate precision. No jump is made while se(a) > ``rate_tol`` |a| (3 %). The fitted rate's
   random error is the same fraction se(a) / |a| of every jump's increment, whatever its
   length, so shortening the jump cannot reduce it; only more measured rates do. Noise
   therefore never shortens a jump: it only decides how many cycles must be simulated
   before the rate is known well enough to jump at all. The gate matters on a noisy steady
   rate: long jumps leave only the newest ``foundation_cycles`` rates in the fit, and their
   rate error carries over from jump to jump. On linear series with 8 % noise (3000
   cycles, 20 seeds) the final error reached 5.6 % with ``rate_tol`` = 0.05, and 2.4 %
   with 0.03.

Error semantics. ``tol`` bounds the deterministic part of each jump's error, the part that
accumulates with a constant sign along a bending curve. From truncation, the final value
misses at most about ``tol`` of its jumped part. Each jump's predicted error bound
(:attr:`JumpPrediction.bound`) is T(L) + z L se(a); on noise-free data se(a) is the
fit's misfit. The random part of the final error is roughly ``rate_tol`` divided by the
square root of the number of independent fit windows.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
from numpy.typing import NDArray

from tribodem.cyclejump.strategies import ACTIVE_FRACTION, JumpStrategy

#: Highest degree of the rate polynomial the strategy supports.
MAX_DEGREE = 3

#: Candidate jump lengths are 1..16, then they grow by this factor. The chosen jump is at
#: most this fraction shorter than the longest allowed one.
_GRID_GROWTH = 1.04

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class LocalFit:
    """The local fit behind a decision (steps 1-2 of the module docstring).

    ``coef`` = (a, b, c, d): the total's fitted rate and its first three derivatives at
    ``cycle`` (state units per cycle, per cycle^2, ...), zero above ``degree``. ``cov`` is
    their covariance. ``weights`` (4, W) maps the window's measured rates to ``coef``, so
    every element's coefficients are ``weights @ rates``.
    """

    cycle: float  #: newest observed cycle c0
    start: int  #: index of the window's first measured rate in the strategy's rate log
    stop: int  #: one past the window's last
    span: float  #: D, cycles
    degree: int  #: degree of the rate polynomial kept (1..3)
    coef: FloatArray
    cov: FloatArray
    weights: FloatArray
    sigma: float  #: residual standard deviation of a measured rate (t-corrected)

    @property
    def samples(self) -> int:
        """Measured rates in the fit window."""
        return self.stop - self.start

    @property
    def rate_error(self) -> float:
        """se(a) / |a|: relative standard error of the fitted rate (inf for a = 0)."""
        a = abs(float(self.coef[0]))
        return math.sqrt(max(float(self.cov[0, 0]), 0.0)) / a if a > 0 else math.inf


@dataclass(frozen=True)
class JumpPrediction:
    """Predicted error of one jump of the total (state units)."""

    cycle: int  #: cycle the jump starts from
    length: int  #: cycles jumped
    increment: float  #: extrapolated increment of the total, L a
    truncation: float  #: T(L): the deterministic error the step control bounds
    random: float  #: L se(a): one standard error from the noise in the fitted rate
    confidence: float  #: z of :attr:`bound`
    window: float  #: span D of the fit, cycles
    samples: int  #: measured rates in the fit

    @property
    def bound(self) -> float:
        """T(L) + z L se(a): the predicted bound on the jump's error."""
        return self.truncation + self.confidence * self.random

    @property
    def relative_truncation(self) -> float:
        return self.truncation / abs(self.increment) if self.increment else math.inf

    @property
    def relative_random(self) -> float:
        return self.random / abs(self.increment) if self.increment else math.inf


def student_factor(z: float, dof: int) -> float:
    """t_dof / z: the Student-t quantile matching the normal quantile ``z``, divided by z.

    Uses the Cornish-Fisher expansion t = z + (z^3 + z) / (4 v) + (5 z^5 + 16 z^3 + 3 z) /
    (96 v^2) (Abramowitz and Stegun 26.7.5). It is about 1.41 for z = 2, v = 4 and 1.01
    for v = 100.
    """
    v = float(max(dof, 1))
    t = z + (z**3 + z) / (4 * v) + (5 * z**5 + 16 * z**3 + 3 * z) / (96 * v * v)
    return t / z


def _taylor_weights(length: FloatArray, terms: int) -> list[FloatArray]:
    """L^(k+1) / (k+1)! for k = 1..terms-1: the integrals of the Taylor terms over a jump."""
    return [length ** (k + 1) / math.factorial(k + 1) for k in range(1, terms)]


def predicted_truncation(coef: FloatArray, cov: FloatArray, length: FloatArray | list[float],
                         ) -> FloatArray:
    """T(L) = sqrt(E+^2 + Var E) (step 4 of the module docstring).

    ``coef`` is (4,) or (4, K): (a, b, c, d) per element. ``cov`` is (4, 4) or (4, 4, K).
    ``length`` is (m,) jump lengths. Returns (m,) or (m, K).
    """
    L = np.asarray(length, dtype=float)
    g = _taylor_weights(L, coef.shape[0])
    e_abs = sum(np.multiply.outer(gk, np.abs(coef[k + 1])) for k, gk in enumerate(g))
    var = sum(np.multiply.outer(gi * gj, cov[i + 1, j + 1])
              for i, gi in enumerate(g) for j, gj in enumerate(g))
    return np.sqrt(e_abs * e_abs + np.maximum(var, 0.0))


def jump_grid(cap: int) -> FloatArray:
    """Candidate jump lengths up to ``cap``: every integer to 16, then growing by 4 %."""
    if cap < 1:
        return np.empty(0)
    head = np.arange(1, min(cap, 16) + 1, dtype=float)
    if cap <= 16:
        return head
    k = int(math.ceil(math.log(cap / 16.0) / math.log(_GRID_GROWTH)))
    tail = np.minimum(np.floor(16.0 * _GRID_GROWTH ** np.arange(1, k + 1)), cap)
    return np.unique(np.concatenate([head, tail, [float(cap)]]))


def longest_jump(coef: FloatArray, cov: FloatArray, tol: float, cap: int) -> NDArray[np.int64]:
    """Longest candidate L <= ``cap`` before the first one with T(L) > tol a L (step 5).

    ``coef`` is (4, K) and ``cov`` (4, 4, K): K elements at once. Returns (K,), 0 where one
    cycle already fails or the rate is not positive.
    """
    grid = jump_grid(cap)
    k = coef.shape[1]
    if grid.size == 0:
        return np.zeros(k, dtype=np.int64)
    t = predicted_truncation(coef, cov, grid)  # (m, K)
    rate = coef[0]
    fails = ~(t <= tol * np.abs(rate)[None, :] * grid[:, None])
    first = np.where(fails.any(axis=0), fails.argmax(axis=0), grid.size)
    out = np.where(first > 0, grid[np.maximum(first - 1, 0)], 0.0).astype(np.int64)
    return np.where(rate > 0, out, 0)


def _scale(span: float, p: int) -> FloatArray:
    """From coefficients of u^k (u = x / span) to derivatives f^(k)(c0) = k! beta_k / span^k."""
    return np.array([math.factorial(k) / span**k for k in range(p)])


class SmoothJump(JumpStrategy):
    """Error-controlled cycle jumping on a local fit of the underlying curve (``smooth``).

    The equations are in the module docstring. Parameters:

    * ``tol`` (0.01): relative local truncation error per jump. This is the seed's
      q_e / 2 = 2 % / 2 (section 4.4). From truncation, the final value misses at most
      about ``tol`` of its jumped part;
    * ``degree`` (3): highest degree of the rate polynomial, lowered while the top term is
      not significant (2 = the cubic w(n) of eq 4.7);
    * ``foundation_cycles`` (8, section 4.4): measured rates needed before the first jump,
      and the fewest rates in a fit;
    * ``window_fraction`` (0.5): the longest fit window, as a fraction of the cycles run
      (section 4.3's moving window). ``window_growth`` (1.5): the ratio of successive
      candidate windows;
    * ``confidence`` (2.0): z of the window rule's intervals, of the degree test and of
      :attr:`JumpPrediction.bound`;
    * ``safety`` (0.9): T(L) <= safety * tol * a L;
    * ``rate_tol`` (0.03): no jump while se(a) > rate_tol |a| (None: no such gate);
    * ``min_jump`` (4): the shortest jump made. ``max_jump_initial`` (200) and
      ``max_jump_until`` (200): the maximum jump is L0 up to cycle n0, then L0 n / n0
      (section 4.4 (a));
    * ``decide_on`` ("total"): the sum of an array state decides (the fretting loop's worn
      volume), or with ``"worst"`` every element carrying wear decides.

    Every element is extrapolated by its own fitted rate. :attr:`predictions` holds the
    predicted error of every jump made (:class:`JumpPrediction`). :attr:`history` holds
    one (cycle, proposal, window span, rates in the fit, degree) entry per decision.
    """

    name: ClassVar[str] = "adaptive"

    def __init__(
        self,
        tol: float = 0.01,
        degree: int = 3,
        foundation_cycles: int = 8,
        window_fraction: float = 0.5,
        window_growth: float = 1.5,
        confidence: float = 2.0,
        safety: float = 0.9,
        rate_tol: float | None = 0.03,
        min_jump: int = 4,
        max_jump_initial: int = 200,
        max_jump_until: int = 200,
        decide_on: str = "total",
    ) -> None:
        if not (math.isfinite(tol) and tol > 0):
            raise ValueError(f"tol = {tol!r}: must be a finite number > 0 (relative local error "
                             "per jump)")
        if degree not in range(1, MAX_DEGREE + 1):
            raise ValueError(f"degree = {degree!r}: must be 1..{MAX_DEGREE} (2: the cubic w(n) of "
                             "eq 4.7)")
        if foundation_cycles < degree + 3:
            raise ValueError(f"foundation_cycles = {foundation_cycles!r}: must be >= degree + 3 "
                             f"= {degree + 3}")
        if not 0.0 < window_fraction <= 1.0:
            raise ValueError(f"window_fraction = {window_fraction!r}: must be in (0, 1]")
        if not window_growth > 1.0:
            raise ValueError(f"window_growth = {window_growth!r}: must be > 1")
        if not (math.isfinite(confidence) and confidence > 0):
            raise ValueError(f"confidence = {confidence!r}: must be a finite number > 0")
        if not 0.0 < safety <= 1.0:
            raise ValueError(f"safety = {safety!r}: must be in (0, 1]")
        if rate_tol is not None and not (math.isfinite(rate_tol) and rate_tol > 0):
            raise ValueError(f"rate_tol = {rate_tol!r}: must be None or a finite number > 0")
        if min_jump < 1:
            raise ValueError(f"min_jump = {min_jump!r}: must be >= 1")
        if max_jump_initial < 1 or max_jump_until < 1:
            raise ValueError(f"max_jump_initial = {max_jump_initial!r}, max_jump_until = "
                             f"{max_jump_until!r}: both must be >= 1")
        if decide_on not in ("total", "worst"):
            raise ValueError(f"decide_on = {decide_on!r}: must be 'total' (the sum of the "
                             "state, e.g. the worn volume) or 'worst' (every element)")
        self.tol = float(tol)
        self.degree = int(degree)
        self.foundation_cycles = int(foundation_cycles)
        self.window_fraction = float(window_fraction)
        self.window_growth = float(window_growth)
        self.confidence = float(confidence)
        self.safety = float(safety)
        self.rate_tol = None if rate_tol is None else float(rate_tol)
        self.min_jump = int(min_jump)
        self.max_jump_initial = int(max_jump_initial)
        self.max_jump_until = int(max_jump_until)
        self.decide_on = decide_on
        super().__init__()

    def reset(self) -> None:
        super().reset()
        # measured rates of the total, index-aligned with the base class's per-element log
        self._tot_cycles = np.empty(0)
        self._tot_rates = np.empty(0)
        self._n_tot = 0
        self._fit_cache: LocalFit | None = None
        self.predictions: list[JumpPrediction] = []
        self.history: list[tuple[int, int, float, int, int]] = []

    @property
    def foundation(self) -> int:
        return self.foundation_cycles

    @property
    def tolerance(self) -> float:
        """Relative local truncation error per jump."""
        return self.tol

    def max_jump(self, cycle: float) -> int:
        """Section 4.4 (a): the maximum jump length at ``cycle``."""
        if cycle <= self.max_jump_until:
            return self.max_jump_initial
        return int(self.max_jump_initial * cycle / self.max_jump_until)

    # --- data --------------------------------------------------------------------------

    def _after_observe(self, jumped: bool) -> None:
        self._fit_cache = None
        n = self._n_rates
        if n <= self._n_tot:
            return
        if n > len(self._tot_rates):  # grow (amortised O(1) per rate)
            cap = max(64, 2 * n)
            xs, ys = np.empty(cap), np.empty(cap)
            xs[: self._n_tot] = self._tot_cycles[: self._n_tot]
            ys[: self._n_tot] = self._tot_rates[: self._n_tot]
            self._tot_cycles, self._tot_rates = xs, ys
        self._tot_cycles[self._n_tot:n] = self._rate_cycles[self._n_tot:n]
        self._tot_rates[self._n_tot:n] = self._rates[self._n_tot:n].sum(axis=1)
        self._n_tot = n

    # --- steps 1-2: the local fit ------------------------------------------------------

    def _fit_window(self, x: FloatArray, r: FloatArray, span: float,
                    ) -> tuple[int, FloatArray, FloatArray, FloatArray, float]:
        """Fit the total's rates ``r`` (W,) on one window (step 1).

        The degree is lowered from ``degree`` while the top term is not significant.
        Returns (degree, coef (4,), cov (4, 4), weights (4, W), s). One QR factorisation
        serves every degree, because the fits of degrees 1..3 are nested in its columns.
        """
        w_n = len(x)
        top = min(self.degree, w_n - 2)
        V = np.vander(x / span, top + 1, increasing=True)  # 1, u, u^2, ...
        Q, R = np.linalg.qr(V)
        qr = Q.T @ r
        rr = float(r @ r)
        floor = (1e-12 * float(np.max(np.abs(r)))) ** 2  # exact data: rounding-level errors
        deg = top
        while True:
            p = deg + 1
            Rinv = np.linalg.inv(R[:p, :p])
            beta = Rinv @ qr[:p]
            rss = max(rr - float(qr[:p] @ qr[:p]), 0.0)
            if rss < 1e-9 * rr:  # (near) exact fit: the residual directly, no cancellation
                res = r - V[:, :p] @ beta
                rss = float(res @ res)
            s2 = max(rss / max(w_n - p, 1), floor)
            s2 *= student_factor(self.confidence, w_n - p) ** 2
            unit = Rinv @ Rinv.T  # (V^T V)^-1 of this degree
            if deg == 1 or abs(beta[deg]) > self.confidence * math.sqrt(s2 * unit[deg, deg]):
                break
            deg -= 1
        sc = _scale(span, p)
        coef = np.zeros(MAX_DEGREE + 1)
        cov = np.zeros((MAX_DEGREE + 1, MAX_DEGREE + 1))
        weights = np.zeros((MAX_DEGREE + 1, w_n))
        coef[:p] = sc * beta
        cov[:p, :p] = s2 * sc[:, None] * unit * sc[None, :]
        weights[:p] = sc[:, None] * (Rinv @ Q[:, :p].T)
        return deg, coef, cov, weights, math.sqrt(s2)

    def local_fit(self) -> LocalFit | None:
        """The fit the next decision uses (None before ``foundation_cycles`` rates)."""
        if self._fit_cache is not None:
            return self._fit_cache
        n, nf = self._n_tot, self.foundation_cycles
        if n < nf or not self._cycles:
            return None
        c0 = self._cycles[-1]
        tm, tr = self._tot_cycles[:n], self._tot_rates[:n]
        d_min = max(c0 - float(tm[n - nf]), 1.0)
        d_max = max(self.window_fraction * (c0 - self._cycles[0]), d_min)
        spans = [d_min]
        while spans[-1] * self.window_growth < d_max:
            spans.append(spans[-1] * self.window_growth)
        if spans[-1] < d_max:
            spans.append(d_max)
        z = self.confidence
        lo = np.full(2, -np.inf)
        hi = np.full(2, np.inf)
        best: LocalFit | None = None
        last_k = -1
        s_ref = math.inf
        for span in spans:
            k = min(int(np.searchsorted(tm, c0 - span, side="left")), n - nf)
            if k == last_k:
                continue  # no new rate in this window
            last_k = k
            deg, coef, cov, w, s = self._fit_window(tm[k:] - c0, tr[k:], span)
            s_ref = min(s_ref, s)
            se = np.sqrt(np.diag(cov)[:2]) * (s_ref / s)
            lo = np.maximum(lo, coef[:2] - z * se)
            hi = np.minimum(hi, coef[:2] + z * se)
            if best is not None and np.any(lo > hi):
                break  # this window's bias shows against the shorter ones: keep the last
            best = LocalFit(cycle=c0, start=k, stop=n, span=span, degree=deg, coef=coef,
                            cov=cov, weights=w, sigma=s)
        self._fit_cache = best
        return best

    # --- steps 3-6 ---------------------------------------------------------------------

    def _element_fit(self, fit: LocalFit) -> tuple[FloatArray, FloatArray]:
        """Per-element (coef (4, K), cov (4, 4, K)) on the total's window and degree."""
        r = self._rates[fit.start:fit.stop]  # (W, K)
        coef = fit.weights @ r
        p = fit.degree + 1
        V = np.vander((self._rate_cycles[fit.start:fit.stop] - fit.cycle) / fit.span, p,
                      increasing=True)
        res = r - V @ (coef[:p] / _scale(fit.span, p)[:, None])
        s2 = np.einsum("ij,ij->j", res, res) / max(fit.samples - p, 1)
        s2 *= student_factor(self.confidence, fit.samples - p) ** 2
        unit = fit.cov / max(fit.sigma**2, 1e-300)
        return coef, unit[:, :, None] * s2[None, None, :]

    def propose_jump(self) -> int:
        fit = self.local_fit()
        cycle = self._cycles[-1]
        proposal = 0
        if fit is not None and math.isfinite(fit.coef[0]) and fit.coef[0] > 0 and (
                self.rate_tol is None or fit.rate_error <= self.rate_tol):
            cap = self.max_jump(cycle)
            tol = self.safety * self.tol
            if self.decide_on == "total" or self._rates.shape[1] == 1:
                proposal = int(longest_jump(fit.coef[:, None], fit.cov[:, :, None], tol,
                                            cap)[0])
            else:
                coef, cov = self._element_fit(fit)
                act = np.abs(coef[0]) >= ACTIVE_FRACTION * float(np.max(np.abs(coef[0])))
                if np.all(coef[0][act] > 0):
                    proposal = int(np.min(longest_jump(coef[:, act], cov[:, :, act], tol,
                                                       cap)))
            if proposal < self.min_jump:
                proposal = 0
        self.history.append((int(cycle), proposal, math.nan if fit is None else fit.span,
                             0 if fit is None else fit.samples,
                             0 if fit is None else fit.degree))
        return proposal

    def _increment(self, n: int) -> FloatArray:
        fit = self.local_fit()
        if fit is None:  # no measured rates yet: nothing to extrapolate with
            k = self._rates.shape[1] if self._n_rates else int(np.prod(self._shape or ()))
            return np.zeros(k)
        rate = fit.weights[0] @ self._rates[fit.start:fit.stop]  # (K,): each element's a
        a = float(fit.coef[0])
        self.predictions.append(JumpPrediction(
            cycle=int(fit.cycle), length=int(n), increment=n * a,
            truncation=float(predicted_truncation(fit.coef, fit.cov, [float(n)])[0]),
            random=n * math.sqrt(max(float(fit.cov[0, 0]), 0.0)),
            confidence=self.confidence, window=fit.span, samples=fit.samples))
        return n * rate
