"""1D plane-strain line-contact backend: a cylinder (axis along y) on a flat, x the stroke.

The 2D elastic half-plane pair (x along the stroke, z the depth into the lower body) of
K. L. Johnson, *Contact Mechanics* (1985), solved on one cross-section of ``n`` cells of
width ``dx`` centred on the window points (the window travels with the upper body, as in
:mod:`tribodem.contact.base`); SI units throughout.

Influence coefficients (Johnson 1985 ch. 2, the surface displacements of a distributed
line traction on a half-plane, section 2.5): the summed normal surface displacement of the
two bodies under a pressure p(s), and the summed (relative) tangential surface displacement
under a shear q(s) on the upper body (-q on the lower), are both::

    w(x) = -(2 / (pi E*)) int p(s) ln(|x - s| / L) ds          (E* = contact_modulus)

For p constant on each cell, the cell integral is exact: with F(t) = t ln|t| - t,
int_cell ln|x_i - s| ds = dx [F(m + 1/2) - F(m - 1/2) + ln dx], m = i - j, so the
influence matrix is the symmetric Toeplitz ``K[i, j] = k[|i - j|]`` of one row
(:func:`influence_row`). The log kernel's additive constant (the length L) is undetermined
in plane strain (a half-plane's displacement is defined only relative to a point at a
finite distance):

* normal problem: the rigid approach is an unknown fixed by the load per unit length P'
  (N/m), so L does not change the pressure (the solver takes L = window, which makes K
  positive definite: the logarithmic capacity of the window, window / 4, is below L);
* tangential problem: the rigid tangential displacement is measured relative to the
  material at distance L from the load (``reference_length``, default the window): the
  stick/slip split and the traction for a given tangential *force* do not depend on L, the
  displacement at which they are reached does (the gross-slip displacement of a Hertz
  contact is delta_s = (2 mu P' / (pi E*)) (ln(2 L / a) + 1/2), the closed form of the
  Cattaneo-Mindlin strip for this kernel, :meth:`LineContactSolver.gross_slip_displacement`).

Products with K use its Toeplitz structure (one row, no stored matrix): on all n points by
an FFT convolution of size 2n, zero padded (non-periodic) for n >= 512, else by the dense
compiled product over the span of the nonzero entries (measured, CPU time: n = 256, a
contact of 64 points: 8.5 us dense, 11 us FFT; n = 1024, 256 points: 112 us dense, 22 us
FFT); products restricted to the contact points and the Cholesky factors of its
sub-matrices are dense (factors cached by the shape of the point set: K is Toeplitz, so a
set's factor depends only on its pattern).

Normal-tangential coupling (Dundurs' beta, :func:`tribodem.contact.base.dundurs_beta`) is
neglected, as in :mod:`tribodem.contact.halfspace`: exact for elastically similar bodies
(beta = 0, e.g. steel on steel); ``report()`` gives beta.

Normal contact (:func:`normal_contact`): p >= 0, gap g = h + K p - d >= 0, p g = 0 and
dx sum p = P', the convex quadratic programme min 1/2 p.K p + h.p; solved by a primal-dual
active-set (semismooth Newton) iteration on the contact set, warm-started from the previous
contact set (one dense Cholesky solve of the contact points per iteration: exact for that
set), with the Polonsky-Keer conjugate gradient (Polonsky & Keer, Wear 231, 1999) for a cold
start and as the fallback.

Tangential (:func:`tangential_increment`), Coulomb friction mu, incremental: given the
previous traction q_prev and the rigid displacement increment D of the upper body, the slip
increment is s = D + K (q - q_prev) at the contact points; stick: s = 0 and |q| <= mu p;
slip: q = -mu p sign(s) (the traction on the upper body opposes its slip). This is the box
QP min 1/2 (q - q_prev).K (q - q_prev) + D sum q over |q| <= mu p (s is its gradient),
solved by the same active-set iteration (stick / slip sets), warm-started from the last
increment's sets; gross slip (every point at q = -mu p sign D) is its first iterate when the
last increment slid everywhere the same way (the fast path: one matrix-vector product), and a
primal active-set method (finite, monotone) is the fallback.

The backend :class:`LineContactSolver` implements :class:`FirstBodySolver` with fields of
shape ``[n, 1]``; subsurface stress: :mod:`tribodem.contact.line_stress`. Cost of an
increment, warm-started, partial slip on a worn track (a real normal solve every increment),
CPU time on a loaded 2-core machine: about 0.15-0.2 ms at n = 256 and 0.25-0.5 ms at
n = 1024 (tests/test_contact_line.py prints it).
"""

from __future__ import annotations

import math
import time
from collections import OrderedDict
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Self

import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray

from tribodem.contact.base import (
    BODIES,
    Body,
    Capabilities,
    ElasticBody,
    FirstBodySolver,
    IncrementResult,
    Recession,
    SubsurfaceStress,
    Unsupported,
    WindowTooSmallError,
    contact_modulus,
    dundurs_beta,
)
from tribodem.contact.geometry import CylinderOnFlat, line_window
from tribodem.contact.line_stress import (
    plane_strain_tresca,
    plane_strain_voigt,
    plane_strain_von_mises,
    strip_stress,
)

#: tangential regimes: "gross" (q = mu p opposing the sliding, slip = the rigid increment,
#: elastic tangential compliance neglected) and "ciavarella-jaeger" (partial slip: the
#: incremental stick/slip solve, which for beta = 0 is exact and reproduces the
#: Ciavarella-Jaeger superposition of the 2-D Hertz contact)
REGIMES = ("gross", "ciavarella-jaeger")

#: offsets whose contact set is kept as the warm start of the next visit (as halfspace.py)
_WARM_STARTS = 64

#: smallest n at which the products on all n points go by FFT (measured: at n = 256 the
#: dense compiled product over a contact of n/4 points takes 8.5 us, a numpy FFT of size 2n
#: 11 us; at n = 1024 112 us against 22 us)
_FFT_MIN = 512

#: Polonsky-Keer tolerance of a cold start (the active-set iteration then makes it exact)
_PK_COLD_TOLERANCE = 1e-4


def _positive(name: str, value: float, allow_zero: bool = False) -> float:
    """``value`` as a float, finite and > 0 (>= 0 with ``allow_zero``), else ValueError."""
    v = float(value)
    if not math.isfinite(v) or not (v >= 0.0 if allow_zero else v > 0.0):
        rule = ">= 0" if allow_zero else "> 0"
        raise ValueError(f"{name} = {value!r} is not allowed: must be finite and {rule}")
    return v


# ---------------------------------------------------------------------------------------
# influence coefficients


def influence_row(n: int, dx: float, modulus: float, reference_length: float
                  ) -> NDArray[np.float64]:
    """Row k (m/Pa) of the Toeplitz influence matrix ``K[i, j] = k[|i - j|]``, [n].

    Summed surface displacement of both bodies at cell centre i under a unit traction on
    cell j (Johnson 1985 section 2.5, the log kernel integrated exactly over the cell)::

        k[m] = -(2 dx / (pi E*)) [F(m + 1/2) - F(m - 1/2) + ln(dx / L)],
        F(t) = t ln|t| - t,

    L = ``reference_length`` (m), the distance at which the displacement vanishes.
    """
    return (2.0 * dx / (math.pi * modulus)) * _unit_row(n, dx, reference_length)


def _unit_row(n: int, dx: float, reference_length: float) -> NDArray[np.float64]:
    """Dimensionless influence row: :func:`influence_row` over 2 dx / (pi E*)."""
    t = np.arange(n, dtype=float)

    def prim(u: NDArray[np.float64]) -> NDArray[np.float64]:
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(u != 0.0, u * np.log(np.abs(u)) - u, 0.0)

    return -(prim(t + 0.5) - prim(t - 0.5)) - math.log(dx / reference_length)


def surface_displacement(traction: ArrayLike, dx: float, modulus: float,
                         reference_length: float) -> NDArray[np.float64]:
    """Summed surface displacement (m) of both bodies at the cell centres under a
    piecewise-constant ``traction`` (Pa, [n]): ``K @ traction`` as a non-periodic
    convolution (FFT of size 2n, zero padded)."""
    t = np.asarray(traction, dtype=float)
    n = t.size
    k = influence_row(n, dx, modulus, reference_length)
    ker = np.concatenate([k, [0.0], k[:0:-1]])  # circulant of size 2n embedding K
    f = np.fft.rfft(ker) * np.fft.rfft(np.concatenate([t, np.zeros(n)]))
    return np.fft.irfft(f, 2 * n)[:n]


# ---------------------------------------------------------------------------------------
# compiled kernels (dimensionless row k: K = (2 dx / (pi E*)) k; tractions in Pa, gaps and
# slips in the same Pa units, i.e. divided by 2 dx / (pi E*))


@njit(cache=True, fastmath=True)
def _cholesky(a: NDArray[np.float64]) -> bool:
    """In-place lower Cholesky factor of the SPD matrix ``a`` (its lower triangle is read;
    the upper one is left as is); False if it is not positive definite. (fastmath lets the
    dot products vectorise; the result is still a deterministic function of ``a``.)"""
    m = a.shape[0]
    for j in range(m):
        s = a[j, j]
        for k in range(j):
            s -= a[j, k] * a[j, k]
        if not s > 0.0:
            return False
        d = math.sqrt(s)
        a[j, j] = d
        for i in range(j + 1, m):
            s = a[i, j]
            for k in range(j):
                s -= a[i, k] * a[j, k]
            a[i, j] = s / d
    return True


@njit(cache=True, fastmath=True)
def _cho_solve(lf: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """Solve (L L^T) x = b with the factor of :func:`_cholesky` (both sweeps along the
    rows of L)."""
    m = b.size
    y = np.empty(m)
    for i in range(m):
        s = b[i]
        for k in range(i):
            s -= lf[i, k] * y[k]
        y[i] = s / lf[i, i]
    for i in range(m - 1, -1, -1):
        xi = y[i] / lf[i, i]
        y[i] = xi
        for k in range(i):
            y[k] -= lf[i, k] * xi
    return y


@njit(cache=True)
def _sub_matrix(k: NDArray[np.float64], rows: NDArray[np.int64]) -> NDArray[np.float64]:
    """K[rows][:, rows] from the Toeplitz row (lower triangle filled)."""
    m = rows.size
    a = np.zeros((m, m))
    for i in range(m):
        ri = rows[i]
        for j in range(i + 1):
            a[i, j] = k[abs(ri - rows[j])]
    return a


@njit(cache=True, fastmath=True)
def _apply(k: NDArray[np.float64], x: NDArray[np.float64], cols: NDArray[np.int64],
           rows: NDArray[np.int64]) -> NDArray[np.float64]:
    """sum_j K[rows[a], cols[j]] x[j] for every a (x given on the increasing ``cols``):
    x is spread on the span cols[0]..cols[-1] and each row is two contiguous sweeps of the
    Toeplitz row (j < i: k[i - j], read ascending from the reversed row; j >= i:
    k[j - i])."""
    out = np.zeros(rows.size)
    if cols.size == 0:
        return out
    n = k.size
    kr = k[::-1].copy()  # kr[n - 1 - t] = k[t]
    c0 = cols[0]
    span = cols[-1] - c0 + 1
    xs = np.zeros(span)
    for j in range(cols.size):
        xs[cols[j] - c0] = x[j]
    for a in range(rows.size):
        i = rows[a] - c0  # row position in span coordinates
        lo = min(max(i, 0), span)
        s = 0.0
        off = n - 1 - i
        for j in range(lo):  # j < i: k[i - j] = kr[n - 1 - i + j]
            s += kr[off + j] * xs[j]
        for j in range(lo, span):  # j >= i
            s += k[j - i] * xs[j]
        out[a] = s
    return out


@njit(cache=True)
def _matvec(k: NDArray[np.float64], x: NDArray[np.float64]) -> NDArray[np.float64]:
    """K @ x on all n points (dense Toeplitz product over the nonzero span of x)."""
    nz = np.flatnonzero(x != 0.0)
    return _apply(k, x[nz], nz, np.arange(x.size))


@njit(cache=True)
def _normal_pk(k: NDArray[np.float64], h: NDArray[np.float64], total: float,
               p0: NDArray[np.float64], tol: float, max_iter: int
               ) -> tuple[NDArray[np.float64], int, bool]:
    """Polonsky-Keer conjugate gradient (Wear 231, 1999) for p >= 0, h + K p - d >= 0
    (complementary), sum p = total, from ``p0`` (uniform if it carries nothing); stops
    when sum |p - p_old| <= tol total. Returns (p, iterations, converged)."""
    n = h.size
    p = p0.copy()
    for i in range(n):
        if p[i] < 0.0:
            p[i] = 0.0
    s0 = p.sum()
    if not s0 > 0.0:
        p[:] = total / n
    else:
        p *= total / s0
    t = np.zeros(n)
    g_old = 1.0
    conj = 0.0
    for it in range(1, max_iter + 1):
        g = _matvec(k, p) + h
        gbar = 0.0
        nc = 0
        for i in range(n):
            if p[i] > 0.0:
                gbar += g[i]
                nc += 1
        gbar /= max(nc, 1)
        g -= gbar
        gg = 0.0
        for i in range(n):
            if p[i] > 0.0:
                gg += g[i] * g[i]
        for i in range(n):
            t[i] = g[i] + conj * (gg / g_old) * t[i] if p[i] > 0.0 else 0.0
        g_old = max(gg, 1e-300)
        r = _matvec(k, t)
        rbar = 0.0
        for i in range(n):
            if p[i] > 0.0:
                rbar += r[i]
        rbar /= max(nc, 1)
        num = 0.0
        den = 0.0
        for i in range(n):
            if p[i] > 0.0:
                num += g[i] * t[i]
                den += (r[i] - rbar) * t[i]
        if den == 0.0:
            return p, it, True
        tau = num / den
        p_old = p.copy()
        for i in range(n):
            if p[i] > 0.0:
                p[i] = max(p[i] - tau * t[i], 0.0)
        conj = 1.0
        for i in range(n):
            if p[i] == 0.0 and g[i] < 0.0:
                p[i] = -tau * g[i]
                conj = 0.0
        p *= total / p.sum()
        if np.abs(p - p_old).sum() <= tol * total:
            return p, it, True
    return p, max_iter, False


@njit(cache=True)
def _tangential_primal(k: NDArray[np.float64], cidx: NDArray[np.int64],
                       bound: NDArray[np.float64], b: NDArray[np.float64],
                       q0: NDArray[np.float64], tol: float, sscale: float, max_iter: int
                       ) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                  NDArray[np.int8], int, bool]:
    """Primal (feasible) active-set method for the box QP min 1/2 q.K q + b.q over
    |q| <= bound on the contact points ``cidx`` (slip s = K q + b, its gradient), from
    ``q0`` clipped into the box: each step goes to the minimiser on the free (stick) set or
    stops at the first bound it meets; at a free-set minimiser the most violated bound is
    released. The objective decreases monotonically: finite for this strictly convex QP.
    Returns (q, s, state, iterations, converged), state 0 stick, +-1 at q = +-bound."""
    m = cidx.size
    q = np.empty(m)
    state = np.zeros(m, dtype=np.int8)
    for a in range(m):
        q[a] = min(max(q0[a], -bound[a]), bound[a])
        if q[a] >= bound[a]:
            state[a] = 1
        elif q[a] <= -bound[a]:
            state[a] = -1
    bmax = bound.max() if m > 0 else 0.0
    s = np.zeros(m)
    for it in range(1, max_iter + 1):
        free = np.flatnonzero(state == 0)
        fixed = np.flatnonzero(state != 0)
        at_min = True
        if free.size > 0:
            rows = cidx[free]
            rhs = -b[free] - _apply(k, q[fixed], cidx[fixed], rows)
            mat = _sub_matrix(k, rows)
            if not _cholesky(mat):
                return q, s, state, it, False
            target = _cho_solve(mat, rhs)
            dirn = target - q[free]
            if np.abs(dirn).max() > tol * bmax:
                at_min = False
                alpha = 1.0
                block = -1
                for jj in range(free.size):
                    a = free[jj]
                    if dirn[jj] > 0.0:
                        r = (bound[a] - q[a]) / dirn[jj]
                    elif dirn[jj] < 0.0:
                        r = (-bound[a] - q[a]) / dirn[jj]
                    else:
                        continue
                    if r < alpha:
                        alpha = r
                        block = jj
                for jj in range(free.size):
                    q[free[jj]] += alpha * dirn[jj]
                if block >= 0:
                    a = free[block]
                    state[a] = 1 if dirn[block] > 0.0 else -1
                    q[a] = state[a] * bound[a]
            else:
                for jj in range(free.size):
                    q[free[jj]] = target[jj]
        if at_min:
            s = _apply(k, q, cidx, cidx) + b
            worst = -1
            viol = tol * sscale
            for a in range(m):
                v = s[a] * state[a]  # > 0: the bound pushes the wrong way
                if v > viol:
                    viol = v
                    worst = a
            if worst < 0:
                for a in range(m):
                    if state[a] == 0:
                        s[a] = 0.0
                return q, s, state, it, True
            state[worst] = 0
    return q, s, state, max_iter, False


class _Factors:
    """Cholesky factors of K[idx][:, idx] and K[idx][:, idx]^-1 1, by the pattern
    idx - idx[0]: K is Toeplitz, so they depend on it only (bitwise: the same pattern gives
    the same factor wherever it lies, so a cache hit changes no result). The least
    recently used are dropped beyond ``budget`` bytes."""

    def __init__(self, k: NDArray[np.float64], budget: float = 32e6) -> None:
        self.k = k
        n = k.size
        #: FFT of the circulant of size 2n that embeds K (non-periodic product, zero padded)
        self.kf = (np.fft.rfft(np.concatenate([k, [0.0], k[:0:-1]])) if n >= _FFT_MIN
                   else None)
        self.budget = budget
        self._store: OrderedDict[bytes, tuple[NDArray[np.float64], NDArray[np.float64]]] = (
            OrderedDict())
        self._bytes = 0

    def full(self, x: NDArray[np.float64], idx: NDArray[np.int64]) -> NDArray[np.float64]:
        """K @ (x on ``idx``, 0 elsewhere) on all n points: FFT convolution of size 2n for
        n >= :data:`_FFT_MIN`, else the dense compiled product over the span of idx."""
        n = self.k.size
        if self.kf is None:
            return _apply(self.k, x, idx, np.arange(n))
        full = np.zeros(2 * n)
        full[idx] = x
        return np.fft.irfft(self.kf * np.fft.rfft(full), 2 * n)[:n]

    def get(self, idx: NDArray[np.int64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(Cholesky factor of K[idx][:, idx], K[idx][:, idx]^-1 1)."""
        rel = idx - idx[0]
        key = rel.tobytes()
        hit = self._store.get(key)
        if hit is not None:
            self._store.move_to_end(key)
            return hit
        a = _sub_matrix(self.k, rel)
        if not _cholesky(a):
            raise np.linalg.LinAlgError("influence sub-matrix not positive definite")
        entry = (a, _cho_solve(a, np.ones(idx.size)))
        self._store[key] = entry
        self._bytes += a.nbytes
        while self._bytes > self.budget and len(self._store) > 1:
            _, (old, _) = self._store.popitem(last=False)
            self._bytes -= old.nbytes
        return entry


# ---------------------------------------------------------------------------------------
# the two problems on one cross-section


@dataclass
class NormalSolution:
    """Solution of :func:`normal_contact` (SI)."""

    pressure: NDArray[np.float64]  #: Pa, [n]
    gap: NDArray[np.float64]  #: loaded gap, m, [n] (0 in contact)
    approach: float  #: rigid approach d, m, relative to the kernel's reference length
    iterations: int  #: active-set iterations (+ Polonsky-Keer iterations)
    method: str  #: "active-set", "polonsky-keer+active-set" or "polonsky-keer"


def _normal_active_set(k: NDArray[np.float64], h: NDArray[np.float64], total: float,
                       free: NDArray[np.bool_], tol: float, max_iter: int,
                       factors: _Factors
                       ) -> tuple[NDArray[np.float64], float, NDArray[np.float64], int, bool]:
    """Primal-dual active set for p >= 0, h + K p - d >= 0 (complementary), sum p = total,
    from the contact set guess ``free``. Each iteration solves the set's equations exactly
    (K_FF p_F = d - h_F, sum p_F = total: a cached Cholesky factor, one solve), then drops
    the points of p < -tol max p and adds those of gap < -tol total. Returns (p, d, gap,
    iterations, converged)."""
    n = h.size
    free = free.copy()
    p = np.zeros(n)
    d = 0.0
    for it in range(1, max_iter + 1):
        if not free.any():
            free[int(np.argmin(h))] = True
        idx = np.flatnonzero(free)
        lf, y2 = factors.get(idx)
        y1 = _cho_solve(lf, h[idx])
        d = (total + y1.sum()) / y2.sum()
        pf = d * y2 - y1
        gap = h + factors.full(pf, idx) - d
        drop = pf < -tol * pf.max()
        add = ~free & (gap < -tol * total)
        if not drop.any() and not add.any():
            p[idx] = np.maximum(pf, 0.0)
            return p, d, gap, it, True
        free[idx[drop]] = False
        free |= add
    p[idx] = np.maximum(pf, 0.0)
    return p, d, gap, max_iter, False


def normal_contact(
    gap: ArrayLike,
    load_per_length: float,
    dx: float,
    modulus: float,
    *,
    guess: ArrayLike | None = None,
    tolerance: float = 1e-10,
    max_iter: int = 200,
    factors: _Factors | None = None,
) -> NormalSolution:
    """Frictionless normal line contact of two elastic half-planes under P' (N/m).

    Finds p >= 0 (Pa) on the n cells with gap(x) + w(x) - d >= 0, zero where p > 0, and
    dx sum p = P' (``gap``: the summed recessions h, m; w: :func:`surface_displacement` of
    p; d: the rigid approach, unknown). ``guess``: a previous pressure or contact mask (its
    contact set warm-starts the active-set iteration); else a Polonsky-Keer cold start to
    1e-4. ``tolerance``: relative (a point of pressure below -tol max p leaves the contact
    set, a point of gap below -tol (pi/2) P'/E* enters it; the solution is then exact for
    its set). The kernel's reference length is the window n dx (the pressure does not
    depend on it; the approach does). ``factors``: a cache of the kernel's factors (the
    solver keeps one across increments).
    """
    h = np.ascontiguousarray(gap, dtype=float)
    n = h.size
    c = 2.0 * dx / (math.pi * modulus)
    if factors is None or factors.k.size != n:
        factors = _Factors(_unit_row(n, dx, n * dx))
    k = factors.k
    ht = (h - h.min()) / c
    total = _positive("load_per_length", load_per_length) / dx
    tol = _positive("tolerance", tolerance)
    iters = 0
    method = "active-set"
    if guess is not None and np.any(np.asarray(guess) > 0):
        free = np.asarray(guess) > 0
    else:
        p0, it0, _ = _normal_pk(k, ht, total, np.zeros(n), max(tol, _PK_COLD_TOLERANCE),
                                100 * n)
        iters += it0
        method = "polonsky-keer+active-set"
        free = p0 > 0.0
    p, d, gt, it, ok = _normal_active_set(k, ht, total, free, tol, max_iter, factors)
    iters += it
    if not ok:  # fallback: Polonsky-Keer to the tolerance (it converges), then polish
        p, it0, _ = _normal_pk(k, ht, total, p, tol, 100 * n)
        iters += it0
        p2, d2, g2, it, ok = _normal_active_set(k, ht, total, p > 0.0, tol, max_iter,
                                                factors)
        iters += it
        if ok:
            p, d, gt, method = p2, d2, g2, "polonsky-keer+active-set"
        else:
            method = "polonsky-keer"
            idx = np.flatnonzero(p > 0)
            u = factors.full(p[idx], idx)
            d = float(np.mean(ht[idx] + u[idx]))
            gt = ht + u - d
    g = np.where(p > 0.0, 0.0, np.maximum(gt * c, 0.0))
    return NormalSolution(pressure=p, gap=g, approach=float(d * c + h.min()),
                          iterations=int(iters), method=method)


@dataclass
class TangentialSolution:
    """Solution of :func:`tangential_increment` (SI)."""

    traction: NDArray[np.float64]  #: shear traction on the upper body, Pa, [n]
    slip: NDArray[np.float64]  #: slip increment (upper w.r.t. lower), m, [n] (0: stick)
    stick: NDArray[np.bool_]  #: contact points that stick, [n]
    state: NDArray[np.int8]  #: 0 stick, +1 q = +mu p, -1 q = -mu p (0 off contact), [n]
    iterations: int
    method: str  #: "active-set" or "primal-active-set"


def tangential_increment(
    pressure: ArrayLike,
    previous: ArrayLike,
    step: float,
    friction: float,
    dx: float,
    modulus: float,
    reference_length: float,
    *,
    state: ArrayLike | None = None,
    tolerance: float = 1e-10,
    max_iter: int = 200,
    factors: _Factors | None = None,
) -> TangentialSolution:
    """One increment of the Coulomb stick/slip problem on the contact points (p > 0).

    ``previous``: the shear traction on the upper body before the increment (Pa, [n]);
    ``step``: rigid tangential displacement increment of the upper body (m). The slip
    increment (upper w.r.t. lower) is s = step + K (q - q_prev) (K: :func:`influence_row`
    with ``reference_length``); stick: s = 0, |q| <= mu p; slip: q = -mu p sign(s).
    Points off contact carry q = 0 and report no slip. ``state``: the last increment's
    stick/slip sets (0 / +1 / -1 per point) as the starting guess (None: all stick); a
    state of -sign(step) everywhere is the gross-slip fast path (no solve: one product).
    Primal-dual active-set iterations on the stick set (each one solve of the stick
    points' equations K_SS dq_S = -step - K_S,rest dq_rest, in increments dq = q - q_prev
    so that small slips are not lost to cancellation), the primal active-set method as the
    fallback. ``tolerance`` relative (on mu p and on |step| + mu P'/E*).
    """
    p = np.ascontiguousarray(pressure, dtype=float)
    qp = np.ascontiguousarray(previous, dtype=float)
    n = p.size
    mu = _positive("friction", friction, allow_zero=True)
    tol = _positive("tolerance", tolerance)
    c = 2.0 * dx / (math.pi * modulus)
    if factors is None or factors.k.size != n:
        factors = _Factors(_unit_row(n, dx, reference_length))
    k = factors.k
    cidx = np.flatnonzero(p > 0.0)
    q = np.zeros(n)
    slip = np.zeros(n)
    st = np.zeros(n, dtype=np.int8)
    no_stick = np.zeros(n, dtype=bool)
    if cidx.size == 0:
        return TangentialSolution(q, slip, no_stick, st, 0, "active-set")
    ds = step / c
    bound = mu * p[cidx]
    if mu == 0.0:  # frictionless: q = 0, the slip is the rigid step plus the released shear
        nz = np.flatnonzero(qp)
        slip[cidx] = (ds - _apply(k, qp[nz], nz, cidx)) * c
        return TangentialSolution(q, slip, no_stick, st, 0, "active-set")
    sscale = abs(ds) + mu * p.sum()
    s0 = (np.zeros(cidx.size, dtype=np.int8) if state is None
          else np.asarray(state, dtype=np.int8)[cidx].copy())
    ok = False
    sc = np.zeros(cidx.size)
    it = 0
    for it in range(1, max_iter + 1):  # noqa: B007 - the count is reported
        stick = s0 == 0
        q[:] = 0.0
        q[cidx] = s0 * bound
        dq = q - qp  # known increments: off contact and at the sliding points
        dq[cidx[stick]] = 0.0
        if stick.any():
            rows = cidx[stick]
            nz = np.flatnonzero(dq)
            rhs = -ds - _apply(k, dq[nz], nz, rows)
            lf, _ = factors.get(rows)
            dq[rows] = _cho_solve(lf, rhs)
            q[rows] = qp[rows] + dq[rows]
        nz = np.flatnonzero(dq)
        sc = ds + _apply(k, dq[nz], nz, cidx)
        sc[stick] = 0.0
        qc = q[cidx]
        new = s0.copy()
        new[stick & (qc > bound * (1 + tol))] = 1
        new[stick & (qc < -bound * (1 + tol))] = -1
        new[(s0 == 1) & (sc > tol * sscale)] = 0
        new[(s0 == -1) & (sc < -tol * sscale)] = 0
        if np.array_equal(new, s0):
            ok = True
            q[cidx] = np.clip(qc, -bound, bound)
            break
        s0 = new
    method = "active-set"
    if not ok:
        nz = np.flatnonzero(qp)
        b = ds - _apply(k, qp[nz], nz, cidx)
        qc, sc, s0, it2, ok = _tangential_primal(k, cidx, bound, b, qp[cidx], tol, sscale,
                                                 100 * max(cidx.size, 1))
        it += it2
        method = "primal-active-set"
        if not ok:
            raise RuntimeError(f"tangential solve did not converge in {it} iterations")
        q[:] = 0.0
        q[cidx] = qc
    slip[cidx] = np.where(s0 == 0, 0.0, sc * c)
    st[cidx] = s0
    stick_mask = np.zeros(n, dtype=bool)
    stick_mask[cidx] = s0 == 0
    return TangentialSolution(q, slip, stick_mask, st, int(it), method)


# ---------------------------------------------------------------------------------------
# the backend


class LineContactSolver(FirstBodySolver):
    """Elastic plane-strain line contact on one cross-section (``contact = "line"``).

    Fields have shape ``[n, 1]``: n points along x (spacing ``dx``, ``window = n dx``) and
    ONE point along y, the cross-section y = 0 of a contact that does not vary along the
    cylinder's axis. ``load`` (N) keeps the meaning it has for
    :class:`tribodem.contact.HalfSpaceSolver`'s line contact: the total load on a square
    window of side ``window``, so the load per unit length is P' = load / window (N/m);
    likewise ``normal_load`` = window x the integral of p along x (= load) and
    ``contact_area`` = window x the contact width. Energy densities (J/m^2) are per unit
    area of the surface, as in every backend.

    ``upper``/``lower``: recessions (m), called as ``f(x, y)`` with y = 0: the upper one
    at the window points, the lower one at lab x = window x + offset exactly (never rounded
    to grid points). Defaults: a cylinder of radius 4 mm (axis along y) on a flat, 100 N,
    friction 0.6, EN24T on both sides, n = 256, a window of ``window_radii`` Hertz
    half-widths (:func:`tribodem.contact.geometry.line_window`) when ``window`` is None.
    ``regime``: ``"gross"`` (q = -mu p sign(step), slip = the rigid increment) or
    ``"ciavarella-jaeger"`` (partial slip: the exact incremental stick/slip solve,
    :func:`tangential_increment`, with the tangential displacement measured relative to
    the material at ``reference_length`` (m, default the window) from the load).
    ``tolerance``: relative tolerance of both solves. Dundurs' beta is neglected (exact
    for elastically similar bodies). ``contact`` must be ``"line"`` (the keyword the
    fretting CLI passes to backends that solve line contacts).
    """

    #: the backend it is the line-contact path of (for messages)
    name = "elastic"
    capabilities = Capabilities(partial_slip=True, subsurface=True, debris=False,
                                contacts=("line",), repeatable=True)
    contact = "line"

    def __init__(
        self,
        upper: Recession | None = None,
        lower: Recession | None = None,
        load: float = 100.0,
        friction: float = 0.6,
        upper_material: ElasticBody | None = None,
        lower_material: ElasticBody | None = None,
        n: int = 256,
        window: float | None = None,
        regime: str = "gross",
        tolerance: float = 1e-10,
        window_radii: float = 10.0,
        contact: str = "line",
        reference_length: float | None = None,
        max_iterations: int = 200,
    ) -> None:
        if (upper is None) != (lower is None):
            raise ValueError("upper and lower must both be given or both be None (defaults)")
        if upper is None or lower is None:
            upper, lower = CylinderOnFlat().recessions()
        if contact != "line":
            raise ValueError(f"contact = {contact!r} is not allowed: {type(self).__name__} "
                             "solves a line contact only (plane strain); allowed: 'line'")
        self.upper, self.lower = upper, lower
        self.load = _positive("load", load)
        self.friction = _positive("friction", friction, allow_zero=True)
        self.upper_material = upper_material or ElasticBody()
        self.lower_material = lower_material or ElasticBody()
        if int(n) != n or n < 16 or n % 2:
            raise ValueError(f"n = {n!r} is not allowed: must be an even integer >= 16")
        self.n = int(n)
        if regime not in REGIMES:
            raise ValueError(f"regime = {regime!r} is not allowed: use 'gross' (q = mu p) or "
                             "'ciavarella-jaeger' (partial slip, incremental stick/slip)")
        self.regime = regime
        self.tolerance = _positive("tolerance", tolerance)
        if int(max_iterations) != max_iterations or max_iterations < 1:
            raise ValueError(f"max_iterations = {max_iterations!r}: must be an integer >= 1")
        self.max_iterations = int(max_iterations)
        self.modulus = contact_modulus(self.upper_material, self.lower_material)
        #: Dundurs' beta (neglected: the normal and tangential problems are uncoupled)
        self.beta = dundurs_beta(self.upper_material, self.lower_material)
        if window is None:
            kx = self._curvature()
            if not kx > 0:
                raise ValueError("window is None but the summed recession has no positive "
                                 f"curvature along x (kx = {kx:.3g} 1/m): give window (m)")
            window = line_window(1.0 / kx, self.load,
                                 self.modulus, _positive("window_radii", window_radii))
        self.dx = _positive("window", window) / self.n
        w = self.window
        if reference_length is None:
            reference_length = w
        #: length L of the tangential log kernel (the displacement reference), m
        self.reference_length = _positive("reference_length", reference_length)
        if self.reference_length < 0.5 * w:
            raise ValueError(f"reference_length = {reference_length!r} m is below half the "
                             f"window ({0.5 * w:.4g} m): the tangential influence matrix "
                             "would not be positive definite; allowed: >= window / 2")
        # influence rows and their factor caches: normal (L = window), tangential (L)
        self._fn = _Factors(_unit_row(self.n, self.dx, w))
        self._ft = _Factors(_unit_row(self.n, self.dx, self.reference_length))
        self._check_flat_along_y()
        self._upper_key: object = None
        self._upper_values = np.zeros(self.n)
        self.reset()

    @property
    def ny(self) -> int:
        """One point along y: the cross-section y = 0."""
        return 1

    @property
    def dy(self) -> float:
        """The cross-section stands for the window's whole side along y, m."""
        return self.window

    # -- construction helpers
    @classmethod
    def from_case(cls, case: Any, options: Mapping[str, Any] | None = None) -> Self:
        """Build from a case object (duck-typed, e.g. :class:`tribodem.contact.base.ContactCase`)
        with attributes ``upper, lower, upper_material, lower_material, load, friction, n,
        window, regime, tolerance`` (and optionally ``contact``: None or "line").

        ``options``: config tables by name, as :meth:`FirstBodySolver.from_case` takes them;
        this backend reads only the table ``"line"`` (a mapping or a pydantic model) with
        the keywords ``reference_length``, ``window_radii``, ``max_iterations``, and ignores
        the others (``[fe]``, ``[plastic]``, ...)."""
        table = None if options is None else options.get("line")
        if table is None:
            extra: dict[str, Any] = {}
        elif hasattr(table, "model_dump"):
            extra = dict(table.model_dump())
        else:
            extra = dict(table)
        allowed = {"reference_length", "window_radii", "max_iterations"}
        bad = sorted(set(extra) - allowed)
        if bad:
            raise ValueError(f"line.{bad[0]} is not an option of {cls.__name__}; allowed: "
                             f"{', '.join(sorted(allowed))}")
        names = ("upper_material", "lower_material", "load", "friction", "n", "window",
                 "regime", "tolerance")
        kw: dict[str, Any] = {k: getattr(case, k) for k in names}
        kw["contact"] = getattr(case, "contact", None) or "line"
        extra = {k: v for k, v in extra.items() if v is not None}
        return cls(case.upper, case.lower, **kw, **extra)

    def _curvature(self) -> float:
        """Curvature (1/m) along x of the summed recession at the origin (10 um steps)."""
        h = 1e-5
        x = np.array([-h, 0.0, h])
        y = np.zeros(3)
        g = np.asarray(self.upper(x, y) + self.lower(x, y), dtype=float)
        return float((g[0] + g[2] - 2 * g[1]) / h**2)

    def _check_flat_along_y(self) -> None:
        """Refuse surfaces that vary along y (a line contact's must not): compared at
        y = 0 and y = +-window/4 on the window (skipped where a height map does not cover
        those y)."""
        x = self.coords
        for f, name in ((self.upper, "upper"), (self.lower, "lower")):
            try:
                ref = np.asarray(f(x, np.zeros_like(x)), dtype=float)
                span = max(float(np.ptp(ref)), 1e-300)
                for yv in (-0.25 * self.window, 0.25 * self.window):
                    other = np.asarray(f(x, np.full_like(x, yv)), dtype=float)
                    if float(np.abs(other - ref).max()) > 1e-9 * span + 1e-15:
                        raise ValueError(f"the {name} recession varies along y: a line "
                                         "contact's surfaces must not depend on y (axis "
                                         "along y)")
            except ValueError as err:
                if "varies along y" in str(err):
                    raise
                continue  # a height map not covering +-W/4: nothing to compare

    # -- contract
    def reset(self) -> None:
        n = self.n
        self._offset: float | None = None
        self._direction = 0.0
        self._traction = np.zeros(n)
        self._pressure = np.zeros(n)
        self._state = np.zeros(n, dtype=np.int8)
        self._warm: dict[float, NDArray[np.bool_]] = {}
        #: the last normal solve and its gap: a solve of the same gap returns it (same
        #: result bitwise: the active-set solution depends only on the gap and the set)
        self._last_normal: tuple[NDArray[np.float64], NormalSolution] | None = None
        self._stats = {"increments": 0, "normal_reused": 0, "normal_iterations": 0,
                       "tangential_iterations": 0, "normal_fallbacks": 0, "tangential_fallbacks": 0,
                       "normal_seconds": 0.0, "tangential_seconds": 0.0}

    @property
    def load_per_length(self) -> float:
        """P' = load / window, N/m."""
        return self.load / self.window

    def hertz(self) -> tuple[float, float]:
        """(p0 Pa, a m) of the Hertz line contact of the summed recession's curvature at the
        origin under P' (Johnson eqs 4.43-4.45): a = sqrt(4 P' R / (pi E*)), p0 = 2 P' /
        (pi a)."""
        r = 1.0 / self._curvature()
        a = math.sqrt(4 * self.load_per_length * r / (math.pi * self.modulus))
        return 2 * self.load_per_length / (math.pi * a), a

    def gross_slip_displacement(self, half_width: float | None = None) -> float:
        """Rigid displacement (m) from the unloaded tangential state to gross slip of a
        Hertz contact of half-width a under this kernel (reference length L): the
        Cattaneo-Mindlin strip, delta_s = (2 mu P' / (pi E*)) (ln(2 L / a) + 1/2)."""
        a = self.hertz()[1] if half_width is None else half_width
        return (2 * self.friction * self.load_per_length / (math.pi * self.modulus)
                * (math.log(2 * self.reference_length / a) + 0.5))

    def _gap1d(self, offset: float) -> NDArray[np.float64]:
        x = self.coords
        y = np.zeros_like(x)
        if self.upper is not self._upper_key:  # the upper body's points are fixed
            self._upper_values = np.asarray(self.upper(x, y), dtype=float).reshape(self.n)
            self._upper_key = self.upper
        lower = np.asarray(self.lower(x + offset, y), dtype=float).reshape(self.n)
        return self._upper_values + lower

    def gap(self, offset: float) -> NDArray[np.float64]:
        """Summed recession with the upper body at ``offset`` (m), [n, 1], m."""
        return self._gap1d(float(offset)).reshape(self.n, 1)

    def _normal(self, h: NDArray[np.float64], guess: NDArray[np.bool_] | None
                ) -> NormalSolution:
        t0 = time.perf_counter()
        last = self._last_normal
        if last is not None and np.array_equal(h, last[0]):
            sol = last[1]  # the same gap as the last solve (e.g. an unworn flat lower body)
            self._stats["normal_reused"] += 1
        else:
            sol = normal_contact(h, self.load_per_length, self.dx, self.modulus, guess=guess,
                                 tolerance=self.tolerance, max_iter=self.max_iterations,
                                 factors=self._fn)
            self._last_normal = (h.copy(), sol)
            self._stats["normal_iterations"] += sol.iterations
            self._stats["normal_fallbacks"] += sol.method == "polonsky-keer"
        self._stats["normal_seconds"] += time.perf_counter() - t0
        return sol

    def loaded_solution(self, offset: float = 0.0, debris: bool = False
                        ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(pressure Pa, loaded gap m), [n, 1], of the normal contact at ``offset``; the load
        history is untouched. No debris pressure (``debris=True``: Unsupported)."""
        if debris:
            raise Unsupported(f"{type(self).__name__} takes no debris pressure")
        guess = self._pressure > 0 if np.any(self._pressure > 0) else None
        sol = self._normal(self._gap1d(float(offset)), guess)
        return sol.pressure.reshape(self.n, 1), sol.gap.reshape(self.n, 1)

    def _check_window(self, p: NDArray[np.float64], offset: float) -> None:
        """Refuse a contact on either x edge of the window."""
        if max(p[0], p[-1]) > 0.0:
            raise WindowTooSmallError(
                f"contact touches the window edge at offset {offset:.4g} m (window "
                f"{self.window:.4g} m, n {self.n}): enlarge window")

    def solve_increment(self, offset: float) -> IncrementResult:
        offset = float(offset)
        if not math.isfinite(offset):
            raise ValueError(f"offset = {offset!r} is not allowed: must be finite (m)")
        n = self.n
        start = offset if self._offset is None else self._offset
        step = offset - start
        reversal = False
        if step != 0.0:
            new_dir = math.copysign(1.0, step)
            reversal = new_dir != self._direction
            self._direction = new_dir
        h = self._gap1d(offset)
        key = round(offset / self.dx, 9)
        guess = self._warm.get(key)
        if guess is None and np.any(self._pressure > 0):
            guess = self._pressure > 0
        sol = self._normal(h, guess)
        p = sol.pressure.copy()
        if key in self._warm or len(self._warm) < _WARM_STARTS:
            self._warm[key] = p > 0
        self._check_window(p, offset)
        contact = p > 0.0
        stick: NDArray[np.bool_] | None = None
        t0 = time.perf_counter()
        if self.regime == "gross":
            q = -self.friction * p * self._direction
            slip = np.where(contact, step, 0.0)
        elif step == 0.0 and not np.any(self._traction):
            q = np.zeros(n)
            slip = np.zeros(n)
            stick = contact.copy()
            self._state[:] = 0
        else:
            state = np.zeros(n, dtype=np.int8) if reversal else self._state
            ts = tangential_increment(p, self._traction, step, self.friction, self.dx,
                                      self.modulus, self.reference_length, state=state,
                                      tolerance=self.tolerance, max_iter=self.max_iterations,
                                      factors=self._ft)
            q, slip, stick, self._state = ts.traction, ts.slip, ts.stick, ts.state
            self._stats["tangential_iterations"] += ts.iterations
            self._stats["tangential_fallbacks"] += ts.method != "active-set"
        self._stats["tangential_seconds"] += time.perf_counter() - t0
        self._stats["increments"] += 1
        self._traction = q
        self._pressure = p
        self._offset = offset
        zeros = np.zeros((n, 1))
        return IncrementResult(
            offset=offset,
            start_offset=start,
            direction=self._direction,
            pressure=p.reshape(n, 1),
            traction=np.stack([q.reshape(n, 1), zeros], axis=-1),
            slip=np.stack([slip.reshape(n, 1), zeros], axis=-1),
            contact_area=float(contact.sum() * self.dx * self.window),
            normal_load=float(p.sum() * self.dx * self.window),
            stick=None if stick is None else stick.reshape(n, 1),
        )

    def subsurface_stress(
        self,
        result: IncrementResult,
        body: Body = "lower",
        depth: float | None = None,
        nz: int = 33,
    ) -> SubsurfaceStress:
        """Plane-strain stress under ``body`` for a solved increment, [nz, n, 1, 6] (frame:
        x, y, z = depth into the body; :mod:`tribodem.contact.line_stress`, Johnson 1985
        ch. 2 uniform-strip closed forms over the n cells). ``depth`` defaults to 3
        half-widths (contact_area / (2 window)). Shear applied: ``traction`` on the upper
        body, ``-traction`` on the lower one, each in its own frame (x along the stroke, z
        into the body), as :meth:`HalfSpaceSolver.subsurface_stress`; the lower body's
        window centre lies at lab x = ``result.offset``. sigma_yy = nu (sigma_xx +
        sigma_zz) with that body's nu."""
        if body not in BODIES:
            raise ValueError(f"body = {body!r} is not allowed: use 'upper' or 'lower'")
        if int(nz) != nz or nz < 2:
            raise ValueError(f"nz = {nz!r} is not allowed: must be an integer >= 2")
        n = self.n
        if result.pressure.shape != (n, 1):
            raise ValueError(f"result.pressure has shape {result.pressure.shape}: expected "
                             f"({n}, 1) from this solver")
        if depth is None:
            depth = 3.0 * max(result.contact_area, self.dx * self.window) / (2 * self.window)
        depth = _positive("depth", depth)
        mat = self.upper_material if body == "upper" else self.lower_material
        sign = 1.0 if body == "upper" else -1.0
        x = self.coords
        edges = np.append(x - 0.5 * self.dx, x[-1] + 0.5 * self.dx)
        z = np.linspace(0.0, depth, int(nz))
        zz, xx = np.meshgrid(z, x, indexing="ij")
        s4 = strip_stress(xx, zz, edges, result.pressure[:, 0],
                          sign * result.traction[:, 0, 0], mat.poisson)
        s4 = s4.reshape(int(nz), n, 1, 4)
        return SubsurfaceStress(
            body=body,
            z=z,
            x=x,
            y=np.zeros(1),
            stress=plane_strain_voigt(s4),
            von_mises=plane_strain_von_mises(s4),
            tresca=plane_strain_tresca(s4),
        )

    # -- resume and report
    def state_dict(self) -> dict[str, Any]:
        """The load history (everything :meth:`reset` clears, including the warm starts),
        as floats and numpy arrays; the surfaces are not included (their owner sets
        them). :meth:`load_state_dict` restores it bitwise."""
        keys = list(self._warm)
        return {
            "offset": self._offset, "direction": self._direction,
            "traction": self._traction.copy(), "pressure": self._pressure.copy(),
            "state": self._state.copy(),
            "warm_keys": np.array(keys, dtype=float),
            "warm": (np.stack([self._warm[k] for k in keys]) if keys
                     else np.zeros((0, self.n), dtype=bool)),
            "stats": dict(self._stats),
        }

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore :meth:`state_dict` (same n: ``ValueError`` otherwise)."""
        n = self.n
        if np.shape(state["traction"]) != (n,):
            raise ValueError(f"solver state of shape {np.shape(state['traction'])} does not "
                             f"fit this solver's ({n},) cross-section")
        off = state["offset"]
        self._offset = None if off is None else float(off)
        self._direction = float(state["direction"])
        self._traction = np.array(state["traction"], dtype=float)
        self._pressure = np.array(state["pressure"], dtype=float)
        self._state = np.array(state["state"], dtype=np.int8)
        self._warm = {float(k): np.array(w, dtype=bool)
                      for k, w in zip(state["warm_keys"], state["warm"], strict=True)}
        self._last_normal = None
        self._stats = dict(self._stats) | dict(state.get("stats", {}))

    def report(self) -> dict[str, Any]:
        """Solver statistics for summary.json: the load per length, Dundurs' beta (neglected),
        the reference length, iterations, fallbacks and the time spent in the solves."""
        st = dict(self._stats)
        inc = max(int(st["increments"]), 1)
        return {
            "contact": "line", "load_per_length_N_per_m": self.load_per_length,
            "dundurs_beta_neglected": self.beta,
            "reference_length_m": self.reference_length, "regime": self.regime,
            **st,
            "seconds_per_increment": (st["normal_seconds"] + st["tangential_seconds"]) / inc,
        }
