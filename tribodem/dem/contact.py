"""Particle contacts: materials, the pair property table, and the response every law shares.

The normal laws are styles in :mod:`tribodem.dem.laws` (``linear``: PFC deformability;
``hertz``: Hertz-Mindlin no-slip, as EDEM/LIGGGHTS; more by ``laws.register``). Common to
all: Coulomb friction on a shear spring carried in the contact history, constant
directional torque (CDT) rolling friction ``mu_r Fn R*`` opposing relative rolling
(``contact_response``), and the pair kernels: ``pair_forces_sum`` (serial) and
``pair_forces_cross`` + ``pair_forces_blocked`` (threaded), the same sums.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit, prange

from tribodem.dem import laws
from tribodem.dem.integrate import BLOCK
from tribodem.dem.jit import kernel
from tribodem.dem.laws import law_normal
from tribodem.dem.laws.table import (  # noqa: F401 - the table's columns, re-exported
    N_PROPS,
    P_BETAN,
    P_BETAS,
    P_ESTAR,
    P_GAMMA,
    P_GSTAR,
    P_KRATIO,
    P_LAW,
    P_MU,
    P_MUR,
    P_SQ2E,
    P_SQ8G,
)
from tribodem.dem.space import min_image

LINEAR = 0  # built-in law ids (tribodem.dem.laws.BUILTIN)
HERTZ = 1
HIST = 3  # history per contact: shear spring displacement (m), 3 components


@dataclass
class Material:
    """Particle or wall material (SI).

    ``young``/``poisson`` feed Hertz-Mindlin; ``effective_modulus`` (PFC E_c, default
    ``young``) and ``kratio`` feed the linear law. ``cor`` is the coefficient of
    restitution (Hertz); ``beta_n``/``beta_s`` are critical damping ratios (linear).
    """

    name: str = "material"
    young: float = 2.0e11
    poisson: float = 0.3
    density: float = 7850.0
    friction: float = 0.5
    rolling_friction: float = 0.0
    cor: float = 1.0
    effective_modulus: float | None = None
    kratio: float = 1.0
    beta_n: float = 0.0
    beta_s: float = 0.0
    law: str = "hertz"

    def __post_init__(self) -> None:
        checks = [
            ("young", self.young, self.young > 0, "> 0 Pa"),
            ("poisson", self.poisson, -1.0 < self.poisson < 0.5, "in (-1, 0.5)"),
            ("density", self.density, self.density > 0, "> 0 kg/m^3"),
            ("friction", self.friction, self.friction >= 0, ">= 0"),
            ("rolling_friction", self.rolling_friction, self.rolling_friction >= 0, ">= 0"),
            ("cor", self.cor, 0.0 < self.cor <= 1.0, "in (0, 1]"),
            ("kratio", self.kratio, self.kratio > 0, "> 0"),
            ("beta_n", self.beta_n, 0 <= self.beta_n < 1, "in [0, 1)"),
            ("beta_s", self.beta_s, 0 <= self.beta_s < 1, "in [0, 1)"),
            ("law", self.law, self.law in laws.ids(), f"one of {sorted(laws.ids())}"),
        ]
        for field_name, value, ok, allowed in checks:
            if not ok:
                raise ValueError(f"material '{self.name}': {field_name} = {value!r}: must be "
                                 f"{allowed}")
        if self.effective_modulus is None:
            self.effective_modulus = self.young
        elif not self.effective_modulus > 0:
            raise ValueError(f"material '{self.name}': effective_modulus = "
                             f"{self.effective_modulus!r}: must be > 0 Pa")

    @property
    def shear_modulus(self) -> float:
        """G = E / (2 (1 + nu)) (Pa)."""
        return self.young / (2.0 * (1.0 + self.poisson))


def hertz_restitution(gamma: float) -> float:
    """Restitution produced by dashpot factor ``gamma`` (``F_d = gamma sqrt(S_n m*) v_n``).

    Solves the non-dimensional impact ``x'' = -x^1.5 - g x^0.25 x'`` with
    ``g = gamma sqrt(3/2)`` (velocity independent for this dashpot) to contact end.
    Used to verify ``hertz_damping_from_cor``.
    """
    from scipy.integrate import solve_ivp

    g = gamma * math.sqrt(1.5)

    def rhs(_t: float, y: np.ndarray) -> list[float]:
        x = max(y[0], 0.0)
        return [y[1], -(x**1.5) - g * x**0.25 * y[1]]

    def end(_t: float, y: np.ndarray) -> float:
        return y[0]

    end.terminal = True
    end.direction = -1
    sol = solve_ivp(rhs, (0.0, 50.0), [1e-12, 1.0], events=end, rtol=1e-11, atol=1e-13,
                    method="DOP853")
    if sol.y_events[0].size == 0:  # over-damped: no rebound within the window
        return 0.0
    return float(-sol.y_events[0][0][1])


def hertz_damping_from_cor(cor: float) -> float:
    """Dashpot factor ``gamma = 2 sqrt(5/6) |ln e| / sqrt(ln^2 e + pi^2)`` (EDEM, Tsuji).

    With ``F_d = gamma sqrt(S_n m*) v_n`` the restitution is velocity independent and
    equals ``e`` (checked against ``hertz_restitution`` to 1e-9 in the tests).
    """
    if cor >= 1.0:
        return 0.0
    lne = math.log(cor)
    return 2.0 * math.sqrt(5.0 / 6.0) * abs(lne) / math.sqrt(lne * lne + math.pi**2)


def pair_table(materials: list[Material]) -> tuple[np.ndarray, np.ndarray]:
    """Pair property table ``[n, n, N_PROPS]`` and per-material linear moduli.

    Mixing: Hertz ``1/E* = sum (1-nu^2)/E``, ``1/G* = sum (2-nu)/G``; friction,
    rolling friction, restitution, kratio and damping ratios: arithmetic mean; the law
    is the first material's when they differ (set explicitly with ``set_pair``).
    """
    n = len(materials)
    tab = np.zeros((n, n, N_PROPS))
    for a, ma in enumerate(materials):
        for b, mb in enumerate(materials):
            set_pair(tab, a, b, ma, mb)
    elin = np.array([m.effective_modulus for m in materials], dtype=np.float64)
    return tab, elin


def set_pair(tab: np.ndarray, a: int, b: int, ma: Material, mb: Material, **override: float
             ) -> None:
    """Fill the (a, b) and (b, a) rows of the pair table from two materials."""
    estar = 1.0 / ((1 - ma.poisson**2) / ma.young + (1 - mb.poisson**2) / mb.young)
    gstar = 1.0 / ((2 - ma.poisson) / ma.shear_modulus + (2 - mb.poisson) / mb.shear_modulus)
    row = np.zeros(N_PROPS)
    row[P_LAW] = laws.ids()[ma.law]
    row[P_ESTAR] = estar
    row[P_GSTAR] = gstar
    row[P_MU] = 0.5 * (ma.friction + mb.friction)
    row[P_MUR] = 0.5 * (ma.rolling_friction + mb.rolling_friction)
    row[P_GAMMA] = hertz_damping_from_cor(0.5 * (ma.cor + mb.cor))
    row[P_KRATIO] = 0.5 * (ma.kratio + mb.kratio)
    row[P_BETAN] = 0.5 * (ma.beta_n + mb.beta_n)
    row[P_BETAS] = 0.5 * (ma.beta_s + mb.beta_s)
    row[P_SQ2E] = math.sqrt(2.0 * estar)
    row[P_SQ8G] = math.sqrt(8.0 * gstar)
    names = {"law": P_LAW, "friction": P_MU, "rolling_friction": P_MUR, "kratio": P_KRATIO,
             "beta_n": P_BETAN, "beta_s": P_BETAS}
    for k, v in override.items():
        if k == "cor":
            row[P_GAMMA] = hertz_damping_from_cor(float(v))
        elif k == "law":
            row[P_LAW] = laws.ids()[str(v)]
        else:
            row[names[k]] = float(v)
    tab[a, b] = row
    tab[b, a] = row


@njit(cache=True, inline="always")
def response(law, prop, n0, n1, n2, delta, v0, v1, v2, w0, w1, w2, rstar, mstar, istar, lin_k,
             h0, h1, h2, dt):
    """Force on the second body and rolling torque on the first, for one contact.

    n: unit normal from body 1 to body 2; v: velocity of body 2 minus body 1 at the
    contact point; w: omega_1 - omega_2; h: the shear spring (m) before the step.
    Returns (force on body 2 (3, N), rolling torque on body 1 (3, N m; body 2 gets minus
    it), normal force N, stored energy J, normal stiffness N/m, the shear spring after the
    step (3, m)). Scalars only: no array view in the hot loop (numba reference-counts
    views handed to inlined functions).
    """
    vn = v0 * n0 + v1 * n1 + v2 * n2
    fn, kt, ct, kn, energy = law_normal(law, prop, delta, vn, rstar, mstar, lin_k)
    # shear spring: rotate into the current tangent plane (keep its length), add slip
    hn = h0 * n0 + h1 * n1 + h2 * n2
    if hn != 0.0:
        len0 = h0 * h0 + h1 * h1 + h2 * h2
        h0 -= hn * n0
        h1 -= hn * n1
        h2 -= hn * n2
        len1 = h0 * h0 + h1 * h1 + h2 * h2
        if len1 > 0.0:
            sc = np.sqrt(len0 / len1)
            h0 *= sc
            h1 *= sc
            h2 *= sc
    vt0 = v0 - vn * n0
    vt1 = v1 - vn * n1
    vt2 = v2 - vn * n2
    h0 += vt0 * dt
    h1 += vt1 * dt
    h2 += vt2 * dt
    ft0 = -kt * h0 - ct * vt0
    ft1 = -kt * h1 - ct * vt1
    ft2 = -kt * h2 - ct * vt2
    ftm2 = ft0 * ft0 + ft1 * ft1 + ft2 * ft2
    fmax = prop[P_MU] * (fn if fn > 0.0 else 0.0)
    if ftm2 > fmax * fmax:
        sc = fmax / np.sqrt(ftm2)
        ft0 *= sc
        ft1 *= sc
        ft2 *= sc
        if kt > 0.0:
            h0 = -(ft0 + ct * vt0) / kt
            h1 = -(ft1 + ct * vt1) / kt
            h2 = -(ft2 + ct * vt2) / kt
        else:
            h0 = 0.0
            h1 = 0.0
            h2 = 0.0
    energy += 0.5 * kt * (h0 * h0 + h1 * h1 + h2 * h2)
    # rolling resistance (constant directional torque), without reversing the spin
    r0 = 0.0
    r1 = 0.0
    r2 = 0.0
    mur = prop[P_MUR]
    if mur > 0.0 and fn > 0.0:
        wn = w0 * n0 + w1 * n1 + w2 * n2
        wr0 = w0 - wn * n0
        wr1 = w1 - wn * n1
        wr2 = w2 - wn * n2
        wm = np.sqrt(wr0 * wr0 + wr1 * wr1 + wr2 * wr2)
        if wm > 0.0:
            tq = mur * fn * rstar
            tlim = istar * wm / dt
            if tq > tlim:
                tq = tlim
            r0 = -tq * wr0 / wm
            r1 = -tq * wr1 / wm
            r2 = -tq * wr2 / wm
    return (fn * n0 + ft0, fn * n1 + ft1, fn * n2 + ft2, r0, r1, r2, fn, energy, kn, h0, h1,
            h2)


@njit(cache=True, inline="always")
def contact_response(law, prop, n0, n1, n2, delta, v0, v1, v2, w0, w1, w2, rstar, mstar, istar,
                     lin_k, hist, dt):
    """``response`` with the shear spring in ``hist`` (3, m), updated in place. Returns
    (force on body 2 (3, N), rolling torque on body 1 (3, N m), normal force N, stored
    energy J, normal stiffness N/m)."""
    f0, f1, f2, r0, r1, r2, fn, energy, kn, h0, h1, h2 = response(
        law, prop, n0, n1, n2, delta, v0, v1, v2, w0, w1, w2, rstar, mstar, istar, lin_k,
        hist[0], hist[1], hist[2], dt)
    hist[0] = h0
    hist[1] = h1
    hist[2] = h2
    return f0, f1, f2, r0, r1, r2, fn, energy, kn


@njit(cache=True, inline="always")
def _lin_k(prop, ri, rj, ei, ej, dim, thickness):
    """PFC deformability stiffness (N/m) of a pair with the linear law (0 for other laws):
    ``A / (r_i/E_i + r_j/E_j)``, ``A = 2 r_min t`` (2D) or ``pi r_min^2`` (3D)."""
    if int(prop[P_LAW]) != LINEAR:
        return 0.0
    rmin = ri if ri < rj else rj
    area = 2.0 * rmin * thickness if dim == 2 else np.pi * rmin * rmin
    return area / (ri / ei + rj / ej)


@njit(cache=True, inline="always")
def _pair_consts(prop, ri, rj, mi, mj, ii, ij, ei, ej, dim, thickness):
    """The constants of a pair (fixed while radii, masses and materials are): the linear
    law's stiffness ``lin_k`` (N/m, ``_lin_k``), effective radius R* (m), mass m* (kg) and
    inertia I* (kg m^2; 0 without rolling friction)."""
    lin_k = _lin_k(prop, ri, rj, ei, ej, dim, thickness)
    rstar = ri * rj / (ri + rj)
    mstar = mi * mj / (mi + mj)
    istar = ii * ij / (ii + ij) if prop[P_MUR] > 0.0 else 0.0  # rolling friction only
    return lin_k, rstar, mstar, istar


#: columns of the per-pair constants (``pair_constants``)
C_LINK, C_RSTAR, C_MSTAR, C_ISTAR = range(4)
N_PCONST = 4
#: a listed pair with |d|^2 > (r_i + r_j)^2 x APART is apart for certain (the margin is far
#: above the rounding of the squares, so no pair the exact test finds touching is skipped):
#: if it was apart at the last evaluation too, the pair passes skip it without the root or
#: any store (``pinfo[p, 0]`` keeps the gap, <= 0, of the evaluation that found it apart)
APART = 1.0 + 1e-12


@njit(cache=True)
def pair_constants(radius, mass, inertia, mat, pair_i, pair_j, pairtab, elin, dim, thickness,
                   out):  # pragma: no cover - numba
    """``out[p]`` = the constants of listed pair p (``_pair_consts``: lin_k N/m, R* m,
    m* kg, I* kg m^2), computed as the pair kernels compute them (the same bits): kernels
    given them skip five divisions per contact."""
    for p in range(pair_i.shape[0]):
        i = pair_i[p]
        j = pair_j[p]
        mi = mat[i]
        mj = mat[j]
        (out[p, C_LINK], out[p, C_RSTAR], out[p, C_MSTAR],
         out[p, C_ISTAR]) = _pair_consts(pairtab[mi, mj], radius[i], radius[j], mass[i],
                                         mass[j], inertia[i], inertia[j], elin[mi], elin[mj],
                                         dim, thickness)


@njit(cache=True, inline="always")
def _pair(d0, d1, d2, dist, ri, rj, vi0, vi1, vi2, vj0, vj1, vj2, wi0, wi1, wi2, wj0, wj1, wj2,
          rstar, mstar, istar, prop, lin_k, h0, h1, h2, dt):
    """Contact of two touching particles i, j at separation d = x_j - x_i (m; ``dist`` =
    ``|d|`` below r_i + r_j): radii (m), velocities (m/s), spins (1/s), the pair's
    constants R* (m), m* (kg), I* (kg m^2) and linear-law stiffness ``lin_k`` (N/m; all
    from ``_pair_consts``), its property row, the shear spring ``h`` (m). Returns (force on
    j (3, N; i gets minus it),
    torque on i (3, N m), torque on j (3, N m), overlap m, normal force N, energy J,
    kn N/m, the new shear spring (3, m)). Scalars and the property row only, so it inlines
    into the pair loops without reference counting (and stays under 30 arguments: more
    make CPython pass them as *args, which numba cannot inline)."""
    delta = ri + rj - dist
    inv = 1.0 / dist
    n0 = d0 * inv
    n1 = d1 * inv
    n2 = d2 * inv
    ai = ri - 0.5 * delta
    aj = rj - 0.5 * delta
    # v_c = v + omega x arm: body i arm +ai n, body j arm -aj n
    v0 = (vj0 - aj * (wj1 * n2 - wj2 * n1)) - (vi0 + ai * (wi1 * n2 - wi2 * n1))
    v1 = (vj1 - aj * (wj2 * n0 - wj0 * n2)) - (vi1 + ai * (wi2 * n0 - wi0 * n2))
    v2 = (vj2 - aj * (wj0 * n1 - wj1 * n0)) - (vi2 + ai * (wi0 * n1 - wi1 * n0))
    law = int(prop[P_LAW])
    f0, f1, f2, r0, r1, r2, fn, energy, kn, h0, h1, h2 = response(
        law, prop, n0, n1, n2, delta, v0, v1, v2, wi0 - wj0, wi1 - wj1,
        wi2 - wj2, rstar, mstar, istar, lin_k, h0, h1, h2, dt)
    # torque = arm x force; body j: (-aj n) x F ; body i: (ai n) x (-F)
    tx = n1 * f2 - n2 * f1
    ty = n2 * f0 - n0 * f2
    tz = n0 * f1 - n1 * f0
    return (f0, f1, f2, -ai * tx + r0, -ai * ty + r1, -ai * tz + r2, -aj * tx - r0,
            -aj * ty - r1, -aj * tz - r2, delta, fn, energy, kn, h0, h1, h2)


@kernel
def pair_forces_sum(pos, vel, omega, radius, mass, inertia, mat, pair_i, pair_j, hist, pairtab,
                    elin, length, periodic, dim, thickness, dt, fpair, tpair_i, tpair_j, pinfo,
                    force, torque, pconst):
    """Forces of all listed pairs, summed straight into the particles (Newton pairs, as
    LIGGGHTS): ``force``/``torque`` (N, N m) are zeroed, then each touching pair p adds
    ``-fpair[p]`` / its torque on i to i and ``+fpair[p]`` / its torque on j to j in
    increasing p. ``fpair[p]``: force on j (N); ``pinfo[p]`` = (overlap m, normal force N,
    energy J, kn N/m); for a pair apart ``pinfo[p, 0]`` is <= 0, the gap (-) found when it
    was first found apart (not updated while it stays apart: see ``APART``). A pair found
    apart is cleared only if it was in contact (``pinfo[p, 0] > 0``) at the previous
    evaluation; ``tpair_*`` are not stored (only cleared when a contact ends). Run it
    through its serial build only (the loop writes shared rows); threaded runs use
    ``pair_forces_cross`` + ``pair_forces_blocked``, which give each particle its pairs in
    the same increasing p: the same bits.

    ``pconst``: the pairs' constants (``pair_constants``, valid while radii, masses and
    materials are unchanged) or ``None`` (computed per contact): the same values either
    way (each is its own compiled specialization).
    """
    n = force.shape[0]
    for i in range(n):
        for k in range(3):
            force[i, k] = 0.0
            torque[i, k] = 0.0
    m = pair_i.shape[0]
    for p in range(m):
        i = pair_i[p]
        j = pair_j[p]
        d0 = min_image(pos[j, 0] - pos[i, 0], length[0], periodic[0])
        d1 = min_image(pos[j, 1] - pos[i, 1], length[1], periodic[1])
        d2 = min_image(pos[j, 2] - pos[i, 2], length[2], periodic[2])
        ri = radius[i]
        rj = radius[j]
        dist2 = d0 * d0 + d1 * d1 + d2 * d2
        rs = ri + rj
        if dist2 > rs * rs * APART and not pinfo[p, 0] > 0.0:
            continue  # apart now and at the last evaluation: nothing to do
        f0 = f1 = f2 = a0 = a1 = a2 = b0 = b1 = b2 = fn = energy = kn = 0.0
        dist = np.sqrt(dist2)
        delta = rs - dist
        if delta > 0.0 and dist2 > 0.0:
            prop = pairtab[mat[i], mat[j]]
            if pconst is None:  # (a compile-time branch: None is its own type)
                lin_k, rstar, mstar, istar = _pair_consts(
                    prop, ri, rj, mass[i], mass[j], inertia[i], inertia[j], elin[mat[i]],
                    elin[mat[j]], dim, thickness)
            else:  # the constants given (the compiled multi-step loop)
                lin_k = pconst[p, C_LINK]
                rstar = pconst[p, C_RSTAR]
                mstar = pconst[p, C_MSTAR]
                istar = pconst[p, C_ISTAR]
            (f0, f1, f2, a0, a1, a2, b0, b1, b2, delta, fn, energy, kn, h0, h1, h2) = _pair(
                d0, d1, d2, dist, ri, rj, vel[i, 0], vel[i, 1], vel[i, 2], vel[j, 0], vel[j, 1],
                vel[j, 2], omega[i, 0], omega[i, 1], omega[i, 2], omega[j, 0], omega[j, 1],
                omega[j, 2], rstar, mstar, istar, prop, lin_k, hist[p, 0], hist[p, 1],
                hist[p, 2], dt)
            hist[p, 0] = h0
            hist[p, 1] = h1
            hist[p, 2] = h2
        if not (delta > 0.0 and dist2 > 0.0):  # apart: clear a contact that just ended
            if pinfo[p, 0] > 0.0:
                for k in range(3):
                    hist[p, k] = 0.0
                    fpair[p, k] = 0.0
                    tpair_i[p, k] = 0.0
                    tpair_j[p, k] = 0.0
                pinfo[p, 1] = 0.0
                pinfo[p, 2] = 0.0
                pinfo[p, 3] = 0.0
            pinfo[p, 0] = delta
            continue
        fpair[p, 0] = f0
        fpair[p, 1] = f1
        fpair[p, 2] = f2
        pinfo[p, 0] = delta
        pinfo[p, 1] = fn
        pinfo[p, 2] = energy
        pinfo[p, 3] = kn
        force[i, 0] -= f0
        force[i, 1] -= f1
        force[i, 2] -= f2
        torque[i, 0] += a0
        torque[i, 1] += a1
        torque[i, 2] += a2
        force[j, 0] += f0
        force[j, 1] += f1
        force[j, 2] += f2
        torque[j, 0] += b0
        torque[j, 1] += b1
        torque[j, 2] += b2


#: blocks per thread of the threaded Newton pair pass (``pair_forces_blocked``): fewer,
#: larger blocks leave fewer pairs across blocks to store; two per thread let a thread
#: that finishes first take another (settle3d 20k on 2 threads, interleaved: 1,172-1,218
#: us per step at 2 blocks per thread against 1,286-1,314 at 8, equal-count blocks).
BLOCKS_PER_THREAD = 2
#: the work of a touching pair against a listed pair found apart, for the block cuts
CONTACT_WORK = 3.0
#: the work of a particle's update against a listed pair's, for the block cuts (the
#: threaded loop updates a thread's particles in the region of their pairs,
#: ``engine._pairs_update``; settle3d: ~6 ns an update, ~10 ns a listed pair)
PARTICLE_WORK = 0.6


@njit(cache=True)
def pair_block_bounds(start, pinfo, nblk, bounds):  # pragma: no cover - numba
    """Cut the particles into ``nblk`` contiguous blocks of about equal pair work:
    ``bounds[b]:bounds[b + 1]`` is block b (``bounds`` has ``nblk + 1`` entries). A
    particle's work is its own row of the list, a listed pair counting 1 and a pair
    touching at the last evaluation (``pinfo[p, 0] > 0``) ``1 + CONTACT_WORK`` (in a
    settling bed the bottom blocks hold most contacts: equal particle counts left one
    thread idle), plus ``PARTICLE_WORK`` per particle for its update. The cuts between
    threads' shares (every ``BLOCKS_PER_THREAD``-th) fall between blocks of
    ``integrate.BLOCK`` particles: the threaded loop updates each thread's particles in
    the region that summed their pairs (``engine._pairs_update``). Any cut gives the same
    sums (``pair_forces_blocked``), so the cuts may change at any step without changing
    a bit."""
    n = start.shape[0] - 1
    total = PARTICLE_WORK * n
    for p in range(start[n]):
        total += 1.0 + (CONTACT_WORK if pinfo[p, 0] > 0.0 else 0.0)
    bounds[0] = 0
    b = 1
    acc = 0.0
    for i in range(n):
        if b >= nblk:
            break
        acc += PARTICLE_WORK
        for p in range(start[i], start[i + 1]):
            acc += 1.0 + (CONTACT_WORK if pinfo[p, 0] > 0.0 else 0.0)
        while (b < nblk and acc >= total * b / nblk
               and (b % BLOCKS_PER_THREAD or (i + 1) % BLOCK == 0)):
            bounds[b] = i + 1
            b += 1
    while b < nblk:
        bounds[b] = n
        b += 1
    bounds[nblk] = n


@njit(cache=True)
def pair_cross_list(pair_i, pair_j, bounds, out):  # pragma: no cover - numba
    """The listed pairs whose two particles lie in different blocks of ``bounds``
    (``pair_block_bounds``; i's block ends before j), in increasing pair index, into
    ``out[:k]``; returns k. They close each sorted row."""
    k = 0
    blk = 0
    for p in range(pair_i.shape[0]):
        i = pair_i[p]
        while i >= bounds[blk + 1]:
            blk += 1
        if pair_j[p] >= bounds[blk + 1]:
            out[k] = p
            k += 1
    return k


@kernel
def pair_forces_cross(pos, vel, omega, radius, mass, inertia, mat, pair_i, pair_j, hist,
                      pairtab, elin, length, periodic, dim, thickness, dt, fpair, tpair_i,
                      tpair_j, pinfo, cross, ncross):
    """First pass of the threaded Newton pairs: the pairs across blocks (``cross[:ncross]``,
    ``pair_cross_list``), stored with both torques (``fpair``, ``tpair_i``, ``tpair_j``,
    ``pinfo``, the history). Threads take equal shares of the list (prange over it: the
    cross pairs crowd at a few block boundaries); each writes only its own pairs' rows."""
    for q in prange(ncross):
        p = cross[q]
        i = pair_i[p]
        j = pair_j[p]
        d0 = min_image(pos[j, 0] - pos[i, 0], length[0], periodic[0])
        d1 = min_image(pos[j, 1] - pos[i, 1], length[1], periodic[1])
        d2 = min_image(pos[j, 2] - pos[i, 2], length[2], periodic[2])
        ri = radius[i]
        rj = radius[j]
        dist2 = d0 * d0 + d1 * d1 + d2 * d2
        rs = ri + rj
        if dist2 > rs * rs * APART and not pinfo[p, 0] > 0.0:
            continue  # apart now and at the last evaluation
        dist = np.sqrt(dist2)
        delta = rs - dist
        if not (delta > 0.0 and dist2 > 0.0):  # apart: clear a contact just ended
            if pinfo[p, 0] > 0.0:
                for k in range(3):
                    hist[p, k] = 0.0
                    fpair[p, k] = 0.0
                    tpair_i[p, k] = 0.0
                    tpair_j[p, k] = 0.0
                pinfo[p, 1] = 0.0
                pinfo[p, 2] = 0.0
                pinfo[p, 3] = 0.0
            pinfo[p, 0] = delta
            continue
        prop = pairtab[mat[i], mat[j]]
        lin_k, rstar, mstar, istar = _pair_consts(
            prop, ri, rj, mass[i], mass[j], inertia[i], inertia[j], elin[mat[i]],
            elin[mat[j]], dim, thickness)
        (f0, f1, f2, a0, a1, a2, b0, b1, b2, delta, fn, energy, kn, h0, h1,
         h2) = _pair(d0, d1, d2, dist, ri, rj, vel[i, 0], vel[i, 1], vel[i, 2],
                     vel[j, 0], vel[j, 1], vel[j, 2], omega[i, 0], omega[i, 1],
                     omega[i, 2], omega[j, 0], omega[j, 1], omega[j, 2], rstar, mstar,
                     istar, prop, lin_k, hist[p, 0], hist[p, 1], hist[p, 2], dt)
        hist[p, 0] = h0
        hist[p, 1] = h1
        hist[p, 2] = h2
        fpair[p, 0] = f0
        fpair[p, 1] = f1
        fpair[p, 2] = f2
        tpair_i[p, 0] = a0
        tpair_i[p, 1] = a1
        tpair_i[p, 2] = a2
        tpair_j[p, 0] = b0
        tpair_j[p, 1] = b1
        tpair_j[p, 2] = b2
        pinfo[p, 0] = delta
        pinfo[p, 1] = fn
        pinfo[p, 2] = energy
        pinfo[p, 3] = kn


@kernel(chunk=1)
def pair_forces_blocked(pos, vel, omega, radius, mass, inertia, mat, start, pair_i, pair_j,
                        rev_start, rev_pair, hist, pairtab, elin, length, periodic, dim,
                        thickness, dt, fpair, tpair_i, tpair_j, pinfo, force, torque, bounds):
    """Second pass of the threaded Newton pairs (after ``pair_forces_cross``): the
    particle sums ``force``/``torque`` (N, N m) of every pair, bitwise those of the serial
    ``pair_forces_sum``, with no pass over all pairs' stored forces.

    Threads take the blocks of ``bounds`` (``pair_block_bounds``; prange over blocks),
    contiguous ranges of particles. A block first
    zeroes its particles and adds the stored cross pairs of the earlier blocks where they
    are j (the head of each reverse-index row: pairs of lower i come first); then it
    walks its own rows in increasing pair index: a pair inside the block is evaluated
    and summed into both particles (Newton), a cross pair adds its stored force and
    torque to i. Every particle thus receives its pairs in increasing pair index, the
    serial kernel's order: the same bits on any number of threads and for any cut
    into blocks. Pairs inside a block store ``fpair`` and ``pinfo`` (not ``tpair_*``), as
    ``pair_forces_sum`` does. A cross pair apart holds zeros, and adding a zero leaves
    a sum's bits as they are (a running sum from +0 is never -0)."""
    nblk = bounds.shape[0] - 1
    for blk in prange(nblk):
        pair_block(pos, vel, omega, radius, mass, inertia, mat, start, pair_i, pair_j,
                   rev_start, rev_pair, hist, pairtab, elin, length, periodic, dim, thickness,
                   dt, fpair, tpair_i, tpair_j, pinfo, force, torque, bounds[blk],
                   bounds[blk + 1])


@njit(cache=True, inline="always")
def pair_block(pos, vel, omega, radius, mass, inertia, mat, start, pair_i, pair_j, rev_start,
               rev_pair, hist, pairtab, elin, length, periodic, dim, thickness, dt, fpair,
               tpair_i, tpair_j, pinfo, force, torque, b0_, b1):  # pragma: no cover - numba
    """``pair_forces_blocked`` for the block of particles ``b0_:b1``: afterwards their
    ``force`` / ``torque`` hold all their pairs' sums."""
    for k in range(b0_, b1):
        s0 = s1 = s2 = u0 = u1 = u2 = 0.0
        for q in range(rev_start[k], rev_start[k + 1]):
            p = rev_pair[q]
            if pair_i[p] >= b0_:
                break
            s0 += fpair[p, 0]
            s1 += fpair[p, 1]
            s2 += fpair[p, 2]
            u0 += tpair_j[p, 0]
            u1 += tpair_j[p, 1]
            u2 += tpair_j[p, 2]
        force[k, 0] = s0
        force[k, 1] = s1
        force[k, 2] = s2
        torque[k, 0] = u0
        torque[k, 1] = u1
        torque[k, 2] = u2
    for i in range(b0_, b1):
        for p in range(start[i], start[i + 1]):
            j = pair_j[p]
            if j >= b1:  # cross pair: evaluated by pair_forces_cross
                force[i, 0] -= fpair[p, 0]
                force[i, 1] -= fpair[p, 1]
                force[i, 2] -= fpair[p, 2]
                torque[i, 0] += tpair_i[p, 0]
                torque[i, 1] += tpair_i[p, 1]
                torque[i, 2] += tpair_i[p, 2]
                continue
            d0 = min_image(pos[j, 0] - pos[i, 0], length[0], periodic[0])
            d1 = min_image(pos[j, 1] - pos[i, 1], length[1], periodic[1])
            d2 = min_image(pos[j, 2] - pos[i, 2], length[2], periodic[2])
            ri = radius[i]
            rj = radius[j]
            dist2 = d0 * d0 + d1 * d1 + d2 * d2
            rs = ri + rj
            if dist2 > rs * rs * APART and not pinfo[p, 0] > 0.0:
                continue  # apart now and at the last evaluation
            dist = np.sqrt(dist2)
            delta = rs - dist
            if not (delta > 0.0 and dist2 > 0.0):  # apart: clear a contact just ended
                if pinfo[p, 0] > 0.0:
                    for k in range(3):
                        hist[p, k] = 0.0
                        fpair[p, k] = 0.0
                        tpair_i[p, k] = 0.0
                        tpair_j[p, k] = 0.0
                    pinfo[p, 1] = 0.0
                    pinfo[p, 2] = 0.0
                    pinfo[p, 3] = 0.0
                pinfo[p, 0] = delta
                continue
            prop = pairtab[mat[i], mat[j]]
            lin_k, rstar, mstar, istar = _pair_consts(
                prop, ri, rj, mass[i], mass[j], inertia[i], inertia[j], elin[mat[i]],
                elin[mat[j]], dim, thickness)
            (f0, f1, f2, a0, a1, a2, c0, c1, c2, delta, fn, energy, kn, h0, h1,
             h2) = _pair(d0, d1, d2, dist, ri, rj, vel[i, 0], vel[i, 1], vel[i, 2],
                         vel[j, 0], vel[j, 1], vel[j, 2], omega[i, 0], omega[i, 1],
                         omega[i, 2], omega[j, 0], omega[j, 1], omega[j, 2], rstar, mstar,
                         istar, prop, lin_k, hist[p, 0], hist[p, 1], hist[p, 2], dt)
            hist[p, 0] = h0
            hist[p, 1] = h1
            hist[p, 2] = h2
            fpair[p, 0] = f0
            fpair[p, 1] = f1
            fpair[p, 2] = f2
            pinfo[p, 0] = delta
            pinfo[p, 1] = fn
            pinfo[p, 2] = energy
            pinfo[p, 3] = kn
            force[i, 0] -= f0
            force[i, 1] -= f1
            force[i, 2] -= f2
            torque[i, 0] += a0
            torque[i, 1] += a1
            torque[i, 2] += a2
            force[j, 0] += f0
            force[j, 1] += f1
            force[j, 2] += f2
            torque[j, 0] += c0
            torque[j, 1] += c1
            torque[j, 2] += c2


@njit(cache=True, inline="always")
def response_2d(law, prop, n0, n1, delta, v0, v1, w2, rstar, mstar, istar, lin_k, h0, h1,
                dt):
    """``response`` in the plane (disks): the same operations without the terms that are
    exactly zero there (z of the normal, velocity and shear spring; x, y of the relative
    spin ``w2`` = omega_1 - omega_2 about z). Returns (force on body 2 (x, y), rolling
    torque on body 1 (z), normal force, energy, kn, shear spring (x, y)): the values
    ``response`` gives for these inputs (only signs of zeros may differ)."""
    vn = v0 * n0 + v1 * n1
    fn, kt, ct, kn, energy = law_normal(law, prop, delta, vn, rstar, mstar, lin_k)
    hn = h0 * n0 + h1 * n1
    if hn != 0.0:
        len0 = h0 * h0 + h1 * h1
        h0 -= hn * n0
        h1 -= hn * n1
        len1 = h0 * h0 + h1 * h1
        if len1 > 0.0:
            sc = np.sqrt(len0 / len1)
            h0 *= sc
            h1 *= sc
    vt0 = v0 - vn * n0
    vt1 = v1 - vn * n1
    h0 += vt0 * dt
    h1 += vt1 * dt
    ft0 = -kt * h0 - ct * vt0
    ft1 = -kt * h1 - ct * vt1
    ftm2 = ft0 * ft0 + ft1 * ft1
    fmax = prop[P_MU] * (fn if fn > 0.0 else 0.0)
    if ftm2 > fmax * fmax:
        sc = fmax / np.sqrt(ftm2)
        ft0 *= sc
        ft1 *= sc
        if kt > 0.0:
            h0 = -(ft0 + ct * vt0) / kt
            h1 = -(ft1 + ct * vt1) / kt
        else:
            h0 = 0.0
            h1 = 0.0
    energy += 0.5 * kt * (h0 * h0 + h1 * h1)
    r2 = 0.0
    mur = prop[P_MUR]
    if mur > 0.0 and fn > 0.0:
        wm = np.sqrt(w2 * w2)
        if wm > 0.0:
            tq = mur * fn * rstar
            tlim = istar * wm / dt
            if tq > tlim:
                tq = tlim
            r2 = -tq * w2 / wm
    return fn * n0 + ft0, fn * n1 + ft1, r2, fn, energy, kn, h0, h1


@njit(cache=True, inline="always")
def _pair_2d(d0, d1, dist, ri, rj, vi0, vi1, vj0, vj1, wi2, wj2, rstar, mstar, istar, prop,
             lin_k, h0, h1, dt):
    """``_pair`` for two disks in the plane (see ``response_2d``). Returns (force on j
    (x, y), torque on i (z), torque on j (z), overlap, normal force, energy, kn, shear
    spring (x, y))."""
    delta = ri + rj - dist
    inv = 1.0 / dist
    n0 = d0 * inv
    n1 = d1 * inv
    ai = ri - 0.5 * delta
    aj = rj - 0.5 * delta
    v0 = (vj0 + aj * (wj2 * n1)) - (vi0 - ai * (wi2 * n1))
    v1 = (vj1 - aj * (wj2 * n0)) - (vi1 + ai * (wi2 * n0))
    law = int(prop[P_LAW])
    f0, f1, r2, fn, energy, kn, h0, h1 = response_2d(
        law, prop, n0, n1, delta, v0, v1, wi2 - wj2, rstar, mstar, istar, lin_k, h0, h1, dt)
    tz = n0 * f1 - n1 * f0
    return f0, f1, -ai * tz + r2, -aj * tz - r2, delta, fn, energy, kn, h0, h1


@kernel
def pair_forces_sum_2d(pos, vel, omega, radius, mass, inertia, mat, pair_i, pair_j, hist,
                       pairtab, elin, length, periodic, dim, thickness, dt, fpair, tpair_i,
                       tpair_j, pinfo, force, torque, pconst):
    """``pair_forces_sum`` for disks (dim 2, ``FIX_2D``): the same operations without the
    terms that are exactly zero in the plane (``_pair_2d``), so the same values (only
    signs of zeros may differ) in fewer instructions. Leaves the z of ``force`` and
    ``fpair``, the x and y of ``torque`` and the z of ``hist`` as they are (zero).
    ``pconst`` as in ``pair_forces_sum``. Serial build only."""
    n = force.shape[0]
    for i in range(n):
        for k in range(3):
            force[i, k] = 0.0
            torque[i, k] = 0.0
    m = pair_i.shape[0]
    for p in range(m):
        i = pair_i[p]
        j = pair_j[p]
        d0 = min_image(pos[j, 0] - pos[i, 0], length[0], periodic[0])
        d1 = min_image(pos[j, 1] - pos[i, 1], length[1], periodic[1])
        ri = radius[i]
        rj = radius[j]
        dist2 = d0 * d0 + d1 * d1
        rs = ri + rj
        if dist2 > rs * rs * APART and not pinfo[p, 0] > 0.0:
            continue  # apart now and at the last evaluation: nothing to do
        dist = np.sqrt(dist2)
        delta = rs - dist
        if not (delta > 0.0 and dist2 > 0.0):  # apart: clear a contact that just ended
            if pinfo[p, 0] > 0.0:
                for k in range(3):
                    hist[p, k] = 0.0
                    fpair[p, k] = 0.0
                    tpair_i[p, k] = 0.0
                    tpair_j[p, k] = 0.0
                pinfo[p, 1] = 0.0
                pinfo[p, 2] = 0.0
                pinfo[p, 3] = 0.0
            pinfo[p, 0] = delta
            continue
        prop = pairtab[mat[i], mat[j]]
        if pconst is None:  # (a compile-time branch: None is its own type)
            lin_k, rstar, mstar, istar = _pair_consts(
                prop, ri, rj, mass[i], mass[j], inertia[i], inertia[j], elin[mat[i]],
                elin[mat[j]], dim, thickness)
        else:  # the constants given (the compiled multi-step loop)
            lin_k = pconst[p, C_LINK]
            rstar = pconst[p, C_RSTAR]
            mstar = pconst[p, C_MSTAR]
            istar = pconst[p, C_ISTAR]
        f0, f1, a2, b2, delta, fn, energy, kn, h0, h1 = _pair_2d(
            d0, d1, dist, ri, rj, vel[i, 0], vel[i, 1], vel[j, 0], vel[j, 1], omega[i, 2],
            omega[j, 2], rstar, mstar, istar, prop, lin_k, hist[p, 0], hist[p, 1], dt)
        hist[p, 0] = h0
        hist[p, 1] = h1
        fpair[p, 0] = f0
        fpair[p, 1] = f1
        pinfo[p, 0] = delta
        pinfo[p, 1] = fn
        pinfo[p, 2] = energy
        pinfo[p, 3] = kn
        force[i, 0] -= f0
        force[i, 1] -= f1
        torque[i, 2] += a2
        force[j, 0] += f0
        force[j, 1] += f1
        torque[j, 2] += b2
