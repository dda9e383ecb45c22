"""Linear parallel bond (Potyondy & Cundall 2004; PFC "linearpbond"; Sha et al. (2022) eqs 9-11).

A bond is a finite elastic cylinder (2D: a slab of thickness t) of radius
``Rb = lambda min(r_i, r_j)`` glued between two particles at the contact point
``x_c = x_i + (r_i + g/2) n`` (g the surface gap, n the unit normal from i to j).
Section: area ``A`` (2D ``2 Rb t``, 3D ``pi Rb^2``), moment of inertia ``I`` (2D
``2/3 t Rb^3``, 3D ``pi Rb^4/4``), polar moment ``J`` (3D ``pi Rb^4/2``). Stiffness per
area ``kn = E_bond / (r_i + r_j)`` (Pa/m), ``ks = kn / kratio``.

Incremental update each step (Sha et al. (2022) eqs 9-10; forces and moments start at zero when
the bond is installed): with ``v_c`` the velocity of j minus i at the contact point and
``dtheta = (omega_j - omega_i) dt``,

- ``Fn += -kn A (v_c . n) dt``            (normal force, **+ = compression**)
- ``Fs += -ks A v_c,t dt``                 (shear force vector on j)
- ``Mb += -kn I dtheta_b``                 (bending moment on j, dtheta_b = tangential part)
- ``Mt += -ks J (dtheta . n)``             (3D twisting moment on j, about n)

Before the increments the stored shear force and bending moment are rotated with the
normal (rigid rotation from the old to the new normal, then about the normal by the mean
spin), as PFC does. Force on j: ``Fn n + Fs``; i gets the opposite; moments on j:
``Mb + Mt n`` plus ``(x_c - x_j) x F_j``.

Maximum stresses (Sha et al. (2022) eq 11 as in Potyondy & Cundall 2004, tension positive):
``sigma = -Fn/A + |Mb| Rb/I``, ``tau = |Fs|/A + |Mt| Rb/J`` (2D: no twist). The bond breaks
in tension when ``sigma >= sigma_t`` (checked first), in shear when
``tau >= c - sigma_n tan(phi)`` with ``sigma_n = -Fn/A``. A broken bond carries nothing
from then on (the contact law still acts if the particles overlap); every break is logged.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
from numba import njit, prange

from tribodem.dem import compiled, neighbors
from tribodem.dem.jit import kernel, serial_run
from tribodem.dem.space import min_image
from tribodem.dem.state import checked_per_item

if TYPE_CHECKING:
    from tribodem.dem.engine import Simulation

INTACT, TENSILE, SHEAR = 0, 1, 2
MODES = {"tensile": TENSILE, "shear": SHEAR}
MODE_NAMES = {TENSILE: "tensile", SHEAR: "shear"}
# columns of the per-bond break record written by the kernel
B_X, B_Y, B_Z, B_FN, B_FS, B_MB, B_MT, B_SIGMA, B_TAU = range(9)
N_BREAK = 9


@dataclass(frozen=True)
class BondBreak:
    """One bond break: when, where (bond centre, m), how, which particles, and the load
    carried at the break (N, N m, Pa; ``fn`` + = compression)."""

    time: float
    step: int
    position: tuple[float, float, float]
    mode: str
    i: int
    j: int
    fn: float
    fs: float
    mb: float
    mt: float
    sigma: float
    tau: float


#: below this spin angle per step (rad) ``_cos_sin`` uses its series (to round-off)
WS_SERIES = 1.0e-3


@njit(cache=True, inline="always")
def _cos_sin(ws):
    """(cos ws, sin ws) of a spin angle ws (rad). For ``|ws| < WS_SERIES`` (every bond of
    a sane step: ``|omega| dt`` is ~1e-5 in the benchmark block) the Taylor series to
    ws^4 / ws^5, whose first neglected terms (ws^6/720, ws^7/5040) are below 1e-21
    relative there: the correctly rounded values but for the rarest last-bit ties (libm's
    own are not correctly rounded either); otherwise libm's cos and sin."""
    if abs(ws) < WS_SERIES:
        w2 = ws * ws
        return (1.0 + w2 * (-0.5 + w2 * (1.0 / 24.0)),
                ws + ws * w2 * (-1.0 / 6.0 + w2 * (1.0 / 120.0)))
    return np.cos(ws), np.sin(ws)


@njit(cache=True, inline="always")
def _rotate(arr, b, c, k0, k1, k2, cw, sw, ws, n0, n1, n2):
    """Rotate row b of arr with the contact: from the old normal o to the new n
    (Rodrigues with k = o x n, c = o . n), then about n by the mean spin angle ws."""
    v0, v1, v2 = arr[b, 0], arr[b, 1], arr[b, 2]
    r0, r1, r2 = v0, v1, v2
    if c > -1.0:
        kv = (k0 * v0 + k1 * v1 + k2 * v2) / (1.0 + c)
        r0 = c * v0 + (k1 * v2 - k2 * v1) + kv * k0
        r1 = c * v1 + (k2 * v0 - k0 * v2) + kv * k1
        r2 = c * v2 + (k0 * v1 - k1 * v0) + kv * k2
    if ws != 0.0:
        x0 = cw * r0 + sw * (n1 * r2 - n2 * r1)
        x1 = cw * r1 + sw * (n2 * r0 - n0 * r2)
        x2 = cw * r2 + sw * (n0 * r1 - n1 * r0)
        r0, r1, r2 = x0, x1, x2
    rn = r0 * n0 + r1 * n1 + r2 * n2  # round-off only: keep it tangential
    arr[b, 0] = r0 - rn * n0
    arr[b, 1] = r1 - rn * n1
    arr[b, 2] = r2 - rn * n2


@kernel(chunk=256)
def bond_forces(pos, vel, omega, radius, bi, bj, rb, area, ib, jb, kn, ks, tens, coh, tanphi,
                fn, fs, mb, mt, nrm, mode, newly, brk, fbond, tbi, tbj, dim, dt, length,
                periodic, summed, ext_force, ext_torque):
    """Update every intact bond (prange over bonds; each writes only its own rows).

    fbond[b]: force on j (i gets minus it); tbi/tbj: moments on i and j (N m). A bond that
    breaks this step gets ``mode`` (1 tensile, 2 shear), ``newly = 1``, its load in
    ``brk`` and zero force. Returns the number of new breaks.

    ``summed`` (serial build only: the loop then writes shared rows): instead of storing
    ``fbond``/``tbi``/``tbj``, add each intact bond straight into ``ext_force`` /
    ``ext_torque`` of its two particles (Newton pairs) in increasing bond index -- the
    order in which ``gather_bonds`` adds them after the threaded pass, so both give the
    same bits. ``fbond``/``tbi``/``tbj`` are then left as they were.
    """
    nb = bi.shape[0]
    nnew = 0
    for b in prange(nb):
        if mode[b] != INTACT:
            continue
        i = bi[b]
        j = bj[b]
        d0 = min_image(pos[j, 0] - pos[i, 0], length[0], periodic[0])
        d1 = min_image(pos[j, 1] - pos[i, 1], length[1], periodic[1])
        d2 = min_image(pos[j, 2] - pos[i, 2], length[2], periodic[2])
        dist = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        inv = 1.0 / dist
        n0 = d0 * inv
        n1 = d1 * inv
        n2 = d2 * inv
        # rigid rotation of the stored shear force and bending moment: old -> new normal
        o0, o1, o2 = nrm[b, 0], nrm[b, 1], nrm[b, 2]
        c = o0 * n0 + o1 * n1 + o2 * n2
        k0 = o1 * n2 - o2 * n1
        k1 = o2 * n0 - o0 * n2
        k2 = o0 * n1 - o1 * n0
        # mean spin about the normal (3D; zero in 2D)
        ws = 0.5 * ((omega[i, 0] + omega[j, 0]) * n0 + (omega[i, 1] + omega[j, 1]) * n1
                    + (omega[i, 2] + omega[j, 2]) * n2) * dt
        cw = 1.0
        sw = 0.0
        if ws != 0.0:  # always zero in 2D: _rotate skips the spin then
            cw, sw = _cos_sin(ws)
        _rotate(fs, b, c, k0, k1, k2, cw, sw, ws, n0, n1, n2)
        _rotate(mb, b, c, k0, k1, k2, cw, sw, ws, n0, n1, n2)
        nrm[b, 0] = n0
        nrm[b, 1] = n1
        nrm[b, 2] = n2
        # contact point arms: i -> x_c = a_i n, j -> x_c = -a_j n
        ai = radius[i] + 0.5 * (dist - radius[i] - radius[j])
        aj = dist - ai
        wi0, wi1, wi2 = omega[i, 0], omega[i, 1], omega[i, 2]
        wj0, wj1, wj2 = omega[j, 0], omega[j, 1], omega[j, 2]
        v0 = (vel[j, 0] - aj * (wj1 * n2 - wj2 * n1)) - (vel[i, 0] + ai * (wi1 * n2 - wi2 * n1))
        v1 = (vel[j, 1] - aj * (wj2 * n0 - wj0 * n2)) - (vel[i, 1] + ai * (wi2 * n0 - wi0 * n2))
        v2 = (vel[j, 2] - aj * (wj0 * n1 - wj1 * n0)) - (vel[i, 2] + ai * (wi0 * n1 - wi1 * n0))
        vn = v0 * n0 + v1 * n1 + v2 * n2
        kna = kn[b] * area[b]
        ksa = ks[b] * area[b]
        fn[b] -= kna * vn * dt
        fs[b, 0] -= ksa * (v0 - vn * n0) * dt
        fs[b, 1] -= ksa * (v1 - vn * n1) * dt
        fs[b, 2] -= ksa * (v2 - vn * n2) * dt
        t0 = (wj0 - wi0) * dt
        t1 = (wj1 - wi1) * dt
        t2 = (wj2 - wi2) * dt
        tn = t0 * n0 + t1 * n1 + t2 * n2
        kni = kn[b] * ib[b]
        mb[b, 0] -= kni * (t0 - tn * n0)
        mb[b, 1] -= kni * (t1 - tn * n1)
        mb[b, 2] -= kni * (t2 - tn * n2)
        if dim == 3:
            mt[b] -= ks[b] * jb[b] * tn
        # maximum stresses (Sha et al. (2022) eq 11, Potyondy & Cundall 2004), tension positive
        fsm = np.sqrt(fs[b, 0] ** 2 + fs[b, 1] ** 2 + fs[b, 2] ** 2)
        mbm = np.sqrt(mb[b, 0] ** 2 + mb[b, 1] ** 2 + mb[b, 2] ** 2)
        sig_n = -fn[b] / area[b]
        sigma = sig_n + mbm * rb[b] / ib[b]
        tau = fsm / area[b]
        if dim == 3:
            tau += abs(mt[b]) * rb[b] / jb[b]
        how = INTACT
        if sigma >= tens[b]:
            how = TENSILE
        elif tau >= coh[b] - sig_n * tanphi[b]:
            how = SHEAR
        if how != INTACT:
            mode[b] = how
            newly[b] = 1
            nnew += 1
            brk[b, B_X] = pos[i, 0] + ai * n0
            brk[b, B_Y] = pos[i, 1] + ai * n1
            brk[b, B_Z] = pos[i, 2] + ai * n2
            brk[b, B_FN] = fn[b]
            brk[b, B_FS] = fsm
            brk[b, B_MB] = mbm
            brk[b, B_MT] = abs(mt[b])
            brk[b, B_SIGMA] = sigma
            brk[b, B_TAU] = tau
            fn[b] = 0.0
            mt[b] = 0.0
            for k in range(3):
                fs[b, k] = 0.0
                mb[b, k] = 0.0
                if not summed:
                    fbond[b, k] = 0.0
                    tbi[b, k] = 0.0
                    tbj[b, k] = 0.0
            continue
        f0 = fn[b] * n0 + fs[b, 0]
        f1 = fn[b] * n1 + fs[b, 1]
        f2 = fn[b] * n2 + fs[b, 2]
        # arm x force: j arm -aj n with F; i arm ai n with -F
        cx = n1 * f2 - n2 * f1
        cy = n2 * f0 - n0 * f2
        cz = n0 * f1 - n1 * f0
        m0 = mb[b, 0] + mt[b] * n0
        m1 = mb[b, 1] + mt[b] * n1
        m2 = mb[b, 2] + mt[b] * n2
        if summed:
            ext_force[i, 0] -= f0
            ext_force[i, 1] -= f1
            ext_force[i, 2] -= f2
            ext_torque[i, 0] += -ai * cx - m0
            ext_torque[i, 1] += -ai * cy - m1
            ext_torque[i, 2] += -ai * cz - m2
            ext_force[j, 0] += f0
            ext_force[j, 1] += f1
            ext_force[j, 2] += f2
            ext_torque[j, 0] += -aj * cx + m0
            ext_torque[j, 1] += -aj * cy + m1
            ext_torque[j, 2] += -aj * cz + m2
            continue
        fbond[b, 0] = f0
        fbond[b, 1] = f1
        fbond[b, 2] = f2
        tbj[b, 0] = -aj * cx + m0
        tbj[b, 1] = -aj * cy + m1
        tbj[b, 2] = -aj * cz + m2
        tbi[b, 0] = -ai * cx - m0
        tbi[b, 1] = -ai * cy - m1
        tbi[b, 2] = -ai * cz - m2
    return nnew


# ---------------------------------------------------------------- 3D bonds in batches
#: bonds per batch of ``bond_forces_3d`` (the lanes of its straight-line pass) and
#: batches per parallel task
BW = 64
B_TASK = 16
#: row stride of the batch buffers (not a multiple of 4 KiB: the rows of one lane must
#: not share cache sets)
RS = BW + 8
# rows of a batch's input buffer (pass 1 gathers them): separation (min image), the two
# particles' velocities and spins, radii, then the bond's stored normal, fn, fs, mb, mt
(X_D0, X_D1, X_D2, X_VI0, X_VI1, X_VI2, X_VJ0, X_VJ1, X_VJ2, X_WI0, X_WI1, X_WI2, X_WJ0,
 X_WJ1, X_WJ2, X_RI, X_RJ, X_O0, X_O1, X_O2, X_FN, X_S0, X_S1, X_S2, X_M0, X_M1, X_M2,
 X_MT) = range(28)
N_X = 28 + 10  # then the bond's constants (``bond_consts_3d``, ``K_*``) from row X_K
# rows of the batch's output buffer: the new normal and load, force on j, moments on i
# and j, arm a_i and the lane's verdict (Y_FLAG: 0 intact for sure, 1 near a strength
# limit -> exact test, 2 spin beyond the series -> the general kernel)
(Y_N0, Y_N1, Y_N2, Y_FN, Y_S0, Y_S1, Y_S2, Y_M0, Y_M1, Y_M2, Y_MT, Y_F0, Y_F1, Y_F2,
 Y_TI0, Y_TI1, Y_TI2, Y_TJ0, Y_TJ1, Y_TJ2, Y_AI, Y_FLAG) = range(22)
N_Y = 22
# columns of the per-bond constants (``bond_consts_3d``)
(K_KNA, K_KSA, K_KNI, K_KSJ, K_INVA, K_RBI2, K_RBJ, K_TENS, K_COH, K_TANPHI) = range(10)
N_K = 10
X_K = 28


def bond_consts_3d(rb: np.ndarray, area: np.ndarray, inertia: np.ndarray, polar: np.ndarray,
                   kn: np.ndarray, ks: np.ndarray, tensile: np.ndarray, cohesion: np.ndarray,
                   tan_phi: np.ndarray) -> np.ndarray:
    """(nb, ``N_K``): per-bond constants of ``bond_forces_3d`` (columns ``K_*``): kn A
    (N/m), ks A (N/m), kn I (N m), ks J (N m) -- the products the general kernel forms,
    the same bits --, the strength screen's 1/A (1/m^2), (Rb/I)^2 (1/m^6) and Rb/J
    (1/m^3), and sigma_t, c (Pa), tan phi."""
    return np.ascontiguousarray(np.c_[kn * area, ks * area, kn * inertia, ks * polar,
                                      1.0 / area, (rb / inertia) ** 2, rb / polar, tensile,
                                      cohesion, tan_phi])


@njit(cache=True, error_model="numpy")
def _bond_lanes(x, y, m, dt):  # pragma: no cover - numba
    """The arithmetic of ``bond_forces`` for the ``m`` bonds of one batch, lane by lane
    without branches (numpy's error model: no zero-division test), so that LLVM runs it
    in SIMD registers: reads the gathered rows ``x`` (``X_*``, then the constants from
    ``X_K``; ``RS`` apart), writes the rows ``y`` (``Y_*``). The same
    operations in the same order as ``bond_forces`` (the same bits); the strength test
    is screened with ``bond_consts_3d``'s reciprocals and squares (no roots, no
    divisions): a lane within 1e-9 of a limit gets flag 1 (``bond_forces_3d`` then runs
    the exact test), a spin angle beyond ``WS_SERIES`` flag 2."""
    for q in range(m):
        d0 = x[X_D0 * RS + q]
        d1 = x[X_D1 * RS + q]
        d2 = x[X_D2 * RS + q]
        dist = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        inv = 1.0 / dist
        n0 = d0 * inv
        n1 = d1 * inv
        n2 = d2 * inv
        o0 = x[X_O0 * RS + q]
        o1 = x[X_O1 * RS + q]
        o2 = x[X_O2 * RS + q]
        s0 = x[X_S0 * RS + q]
        s1 = x[X_S1 * RS + q]
        s2 = x[X_S2 * RS + q]
        m0 = x[X_M0 * RS + q]
        m1 = x[X_M1 * RS + q]
        m2 = x[X_M2 * RS + q]
        c = o0 * n0 + o1 * n1 + o2 * n2
        k0 = o1 * n2 - o2 * n1
        k1 = o2 * n0 - o0 * n2
        k2 = o0 * n1 - o1 * n0
        wi0 = x[X_WI0 * RS + q]
        wi1 = x[X_WI1 * RS + q]
        wi2 = x[X_WI2 * RS + q]
        wj0 = x[X_WJ0 * RS + q]
        wj1 = x[X_WJ1 * RS + q]
        wj2 = x[X_WJ2 * RS + q]
        ws = 0.5 * ((wi0 + wj0) * n0 + (wi1 + wj1) * n1 + (wi2 + wj2) * n2) * dt
        # _rotate of fs and mb: old -> new normal (if c > -1), spin (if ws != 0), tangential
        turn = c > -1.0
        kv = (k0 * s0 + k1 * s1 + k2 * s2) / (1.0 + c)
        r0 = c * s0 + (k1 * s2 - k2 * s1) + kv * k0
        r1 = c * s1 + (k2 * s0 - k0 * s2) + kv * k1
        r2 = c * s2 + (k0 * s1 - k1 * s0) + kv * k2
        r0 = r0 if turn else s0
        r1 = r1 if turn else s1
        r2 = r2 if turn else s2
        kv = (k0 * m0 + k1 * m1 + k2 * m2) / (1.0 + c)
        p0 = c * m0 + (k1 * m2 - k2 * m1) + kv * k0
        p1 = c * m1 + (k2 * m0 - k0 * m2) + kv * k1
        p2 = c * m2 + (k0 * m1 - k1 * m0) + kv * k2
        p0 = p0 if turn else m0
        p1 = p1 if turn else m1
        p2 = p2 if turn else m2
        spin = ws != 0.0
        w2 = ws * ws  # _cos_sin's series
        cw = 1.0 + w2 * (-0.5 + w2 * (1.0 / 24.0))
        sw = ws + ws * w2 * (-1.0 / 6.0 + w2 * (1.0 / 120.0))
        t0 = cw * r0 + sw * (n1 * r2 - n2 * r1)
        t1 = cw * r1 + sw * (n2 * r0 - n0 * r2)
        t2 = cw * r2 + sw * (n0 * r1 - n1 * r0)
        r0 = t0 if spin else r0
        r1 = t1 if spin else r1
        r2 = t2 if spin else r2
        t0 = cw * p0 + sw * (n1 * p2 - n2 * p1)
        t1 = cw * p1 + sw * (n2 * p0 - n0 * p2)
        t2 = cw * p2 + sw * (n0 * p1 - n1 * p0)
        p0 = t0 if spin else p0
        p1 = t1 if spin else p1
        p2 = t2 if spin else p2
        rn = r0 * n0 + r1 * n1 + r2 * n2
        s0 = r0 - rn * n0
        s1 = r1 - rn * n1
        s2 = r2 - rn * n2
        rn = p0 * n0 + p1 * n1 + p2 * n2
        m0 = p0 - rn * n0
        m1 = p1 - rn * n1
        m2 = p2 - rn * n2
        ri = x[X_RI * RS + q]
        ai = ri + 0.5 * (dist - ri - x[X_RJ * RS + q])
        aj = dist - ai
        v0 = ((x[X_VJ0 * RS + q] - aj * (wj1 * n2 - wj2 * n1))
              - (x[X_VI0 * RS + q] + ai * (wi1 * n2 - wi2 * n1)))
        v1 = ((x[X_VJ1 * RS + q] - aj * (wj2 * n0 - wj0 * n2))
              - (x[X_VI1 * RS + q] + ai * (wi2 * n0 - wi0 * n2)))
        v2 = ((x[X_VJ2 * RS + q] - aj * (wj0 * n1 - wj1 * n0))
              - (x[X_VI2 * RS + q] + ai * (wi0 * n1 - wi1 * n0)))
        vn = v0 * n0 + v1 * n1 + v2 * n2
        ksa = x[(X_K + K_KSA) * RS + q]
        fn = x[X_FN * RS + q] - x[(X_K + K_KNA) * RS + q] * vn * dt
        s0 -= ksa * (v0 - vn * n0) * dt
        s1 -= ksa * (v1 - vn * n1) * dt
        s2 -= ksa * (v2 - vn * n2) * dt
        t0 = (wj0 - wi0) * dt
        t1 = (wj1 - wi1) * dt
        t2 = (wj2 - wi2) * dt
        tn = t0 * n0 + t1 * n1 + t2 * n2
        kni = x[(X_K + K_KNI) * RS + q]
        m0 -= kni * (t0 - tn * n0)
        m1 -= kni * (t1 - tn * n1)
        m2 -= kni * (t2 - tn * n2)
        mt = x[X_MT * RS + q] - x[(X_K + K_KSJ) * RS + q] * tn
        # the strength screen (see bond_forces_2d): safely below both limits?
        tens = x[(X_K + K_TENS) * RS + q]
        coh = x[(X_K + K_COH) * RS + q]
        inva = x[(X_K + K_INVA) * RS + q]
        sn_a = -fn * inva
        room_t = tens - sn_a - 1e-9 * (abs(sn_a) + tens)
        bend2 = (m0 * m0 + m1 * m1 + m2 * m2) * x[(X_K + K_RBI2) * RS + q]
        thr = sn_a * x[(X_K + K_TANPHI) * RS + q]
        twist = abs(mt) * x[(X_K + K_RBJ) * RS + q]
        room_s = coh - thr - twist - 1e-9 * (coh + abs(thr) + twist)
        shear2 = (s0 * s0 + s1 * s1 + s2 * s2) * (inva * inva)
        safe = ((room_t > 0.0) & (bend2 * (1.0 + 4e-9) < room_t * room_t)
                & (room_s > 0.0) & (shear2 * (1.0 + 4e-9) < room_s * room_s))
        flag = 0.0 if safe else 1.0
        y[Y_FLAG * RS + q] = flag if abs(ws) < WS_SERIES else 2.0
        y[Y_N0 * RS + q] = n0
        y[Y_N1 * RS + q] = n1
        y[Y_N2 * RS + q] = n2
        y[Y_FN * RS + q] = fn
        y[Y_S0 * RS + q] = s0
        y[Y_S1 * RS + q] = s1
        y[Y_S2 * RS + q] = s2
        y[Y_M0 * RS + q] = m0
        y[Y_M1 * RS + q] = m1
        y[Y_M2 * RS + q] = m2
        y[Y_MT * RS + q] = mt
        f0 = fn * n0 + s0
        f1 = fn * n1 + s1
        f2 = fn * n2 + s2
        cx = n1 * f2 - n2 * f1
        cy = n2 * f0 - n0 * f2
        cz = n0 * f1 - n1 * f0
        g0 = m0 + mt * n0
        g1 = m1 + mt * n1
        g2 = m2 + mt * n2
        y[Y_F0 * RS + q] = f0
        y[Y_F1 * RS + q] = f1
        y[Y_F2 * RS + q] = f2
        y[Y_TI0 * RS + q] = -ai * cx - g0
        y[Y_TI1 * RS + q] = -ai * cy - g1
        y[Y_TI2 * RS + q] = -ai * cz - g2
        y[Y_TJ0 * RS + q] = -aj * cx + g0
        y[Y_TJ1 * RS + q] = -aj * cy + g1
        y[Y_TJ2 * RS + q] = -aj * cz + g2
        y[Y_AI * RS + q] = ai


_bonds_general = bond_forces.serial


@kernel
def bond_forces_3d(pos, vel, omega, radius, bi, bj, rb, area, ib, jb, kn, ks, tens, coh,
                   tanphi, fn, fs, mb, mt, nrm, mode, newly, brk, fbond, tbi, tbj, dt, length,
                   periodic, summed, ext_force, ext_torque, kc):
    """``bond_forces`` for spheres (dim 3) in batches of ``BW`` bonds: the same values
    (bits), ~1.4x faster (72 -> 50 ns per bond on bonded3d). Arguments as there (no
    ``dim``), plus ``kc`` (``bond_consts_3d`` of the same bonds). Per batch: (1) gather
    the particles' and the bonds' state into a buffer, (2) ``_bond_lanes``: the
    arithmetic in SIMD lanes, (3) per bond in increasing index, as ``bond_forces``: skip
    broken bonds, the exact strength test where the screen left a doubt (break, log and
    zero as there), store the state and sum the bond into its particles (``summed``) or
    store it for ``gather_bonds``. A bond whose spin angle is beyond ``WS_SERIES`` runs
    through the general kernel itself. prange over tasks of ``B_TASK`` batches; each
    bond writes only its own rows unless ``summed`` (serial build). Returns the number
    of breaks."""
    nb = bi.shape[0]
    nbat = (nb + BW - 1) // BW
    ntask = (nbat + B_TASK - 1) // B_TASK
    nnew = 0
    for task in prange(ntask):
        x = np.empty(N_X * RS)
        y = np.empty(N_Y * RS)
        for bat in range(task * B_TASK, min(nbat, (task + 1) * B_TASK)):
            b0 = bat * BW
            m = min(BW, nb - b0)
            for q in range(m):
                b = b0 + q
                i = bi[b]
                j = bj[b]
                x[X_D0 * RS + q] = min_image(pos[j, 0] - pos[i, 0], length[0], periodic[0])
                x[X_D1 * RS + q] = min_image(pos[j, 1] - pos[i, 1], length[1], periodic[1])
                x[X_D2 * RS + q] = min_image(pos[j, 2] - pos[i, 2], length[2], periodic[2])
                x[X_VI0 * RS + q] = vel[i, 0]
                x[X_VI1 * RS + q] = vel[i, 1]
                x[X_VI2 * RS + q] = vel[i, 2]
                x[X_VJ0 * RS + q] = vel[j, 0]
                x[X_VJ1 * RS + q] = vel[j, 1]
                x[X_VJ2 * RS + q] = vel[j, 2]
                x[X_WI0 * RS + q] = omega[i, 0]
                x[X_WI1 * RS + q] = omega[i, 1]
                x[X_WI2 * RS + q] = omega[i, 2]
                x[X_WJ0 * RS + q] = omega[j, 0]
                x[X_WJ1 * RS + q] = omega[j, 1]
                x[X_WJ2 * RS + q] = omega[j, 2]
                x[X_RI * RS + q] = radius[i]
                x[X_RJ * RS + q] = radius[j]
                x[X_O0 * RS + q] = nrm[b, 0]
                x[X_O1 * RS + q] = nrm[b, 1]
                x[X_O2 * RS + q] = nrm[b, 2]
                x[X_FN * RS + q] = fn[b]
                x[X_S0 * RS + q] = fs[b, 0]
                x[X_S1 * RS + q] = fs[b, 1]
                x[X_S2 * RS + q] = fs[b, 2]
                x[X_M0 * RS + q] = mb[b, 0]
                x[X_M1 * RS + q] = mb[b, 1]
                x[X_M2 * RS + q] = mb[b, 2]
                x[X_MT * RS + q] = mt[b]
                for k in range(N_K):
                    x[(X_K + k) * RS + q] = kc[b, k]
            _bond_lanes(x, y, m, dt)
            for q in range(m):
                b = b0 + q
                if mode[b] != INTACT:
                    continue
                flag = y[Y_FLAG * RS + q]
                if flag == 2.0:  # a large spin angle: libm's cos and sin
                    nnew += _bonds_general(
                        pos, vel, omega, radius, bi[b:b + 1], bj[b:b + 1], rb[b:b + 1],
                        area[b:b + 1], ib[b:b + 1], jb[b:b + 1], kn[b:b + 1], ks[b:b + 1],
                        tens[b:b + 1], coh[b:b + 1], tanphi[b:b + 1], fn[b:b + 1],
                        fs[b:b + 1], mb[b:b + 1], mt[b:b + 1], nrm[b:b + 1], mode[b:b + 1],
                        newly[b:b + 1], brk[b:b + 1], fbond[b:b + 1], tbi[b:b + 1],
                        tbj[b:b + 1], 3, dt, length, periodic, summed, ext_force, ext_torque)
                    continue
                i = bi[b]
                j = bj[b]
                n0 = y[Y_N0 * RS + q]
                n1 = y[Y_N1 * RS + q]
                n2 = y[Y_N2 * RS + q]
                nrm[b, 0] = n0
                nrm[b, 1] = n1
                nrm[b, 2] = n2
                fnb = y[Y_FN * RS + q]
                s0 = y[Y_S0 * RS + q]
                s1 = y[Y_S1 * RS + q]
                s2 = y[Y_S2 * RS + q]
                m0 = y[Y_M0 * RS + q]
                m1 = y[Y_M1 * RS + q]
                m2 = y[Y_M2 * RS + q]
                mtb = y[Y_MT * RS + q]
                how = INTACT
                if flag != 0.0:  # bond_forces's test, exactly
                    fsm = np.sqrt(s0 ** 2 + s1 ** 2 + s2 ** 2)
                    mbm = np.sqrt(m0 ** 2 + m1 ** 2 + m2 ** 2)
                    sig_n = -fnb / area[b]
                    sigma = sig_n + mbm * rb[b] / ib[b]
                    tau = fsm / area[b]
                    tau += abs(mtb) * rb[b] / jb[b]
                    if sigma >= tens[b]:
                        how = TENSILE
                    elif tau >= coh[b] - sig_n * tanphi[b]:
                        how = SHEAR
                    if how != INTACT:
                        ai = y[Y_AI * RS + q]
                        mode[b] = how
                        newly[b] = 1
                        nnew += 1
                        brk[b, B_X] = pos[i, 0] + ai * n0
                        brk[b, B_Y] = pos[i, 1] + ai * n1
                        brk[b, B_Z] = pos[i, 2] + ai * n2
                        brk[b, B_FN] = fnb
                        brk[b, B_FS] = fsm
                        brk[b, B_MB] = mbm
                        brk[b, B_MT] = abs(mtb)
                        brk[b, B_SIGMA] = sigma
                        brk[b, B_TAU] = tau
                        fn[b] = 0.0
                        mt[b] = 0.0
                        for k in range(3):
                            fs[b, k] = 0.0
                            mb[b, k] = 0.0
                            if not summed:
                                fbond[b, k] = 0.0
                                tbi[b, k] = 0.0
                                tbj[b, k] = 0.0
                        continue
                fn[b] = fnb
                fs[b, 0] = s0
                fs[b, 1] = s1
                fs[b, 2] = s2
                mb[b, 0] = m0
                mb[b, 1] = m1
                mb[b, 2] = m2
                mt[b] = mtb
                f0 = y[Y_F0 * RS + q]
                f1 = y[Y_F1 * RS + q]
                f2 = y[Y_F2 * RS + q]
                if summed:
                    ext_force[i, 0] -= f0
                    ext_force[i, 1] -= f1
                    ext_force[i, 2] -= f2
                    ext_torque[i, 0] += y[Y_TI0 * RS + q]
                    ext_torque[i, 1] += y[Y_TI1 * RS + q]
                    ext_torque[i, 2] += y[Y_TI2 * RS + q]
                    ext_force[j, 0] += f0
                    ext_force[j, 1] += f1
                    ext_force[j, 2] += f2
                    ext_torque[j, 0] += y[Y_TJ0 * RS + q]
                    ext_torque[j, 1] += y[Y_TJ1 * RS + q]
                    ext_torque[j, 2] += y[Y_TJ2 * RS + q]
                    continue
                fbond[b, 0] = f0
                fbond[b, 1] = f1
                fbond[b, 2] = f2
                tbi[b, 0] = y[Y_TI0 * RS + q]
                tbi[b, 1] = y[Y_TI1 * RS + q]
                tbi[b, 2] = y[Y_TI2 * RS + q]
                tbj[b, 0] = y[Y_TJ0 * RS + q]
                tbj[b, 1] = y[Y_TJ1 * RS + q]
                tbj[b, 2] = y[Y_TJ2 * RS + q]
    return nnew


@kernel(chunk=256)
def bond_forces_2d(pos, vel, omega, radius, bi, bj, rb, area, ib, kn, ks, tens, coh, tanphi,
                   fn, fs, mb, nrm, mode, newly, brk, fbond, tbi, tbj, dt, length, periodic,
                   summed, ext_force, ext_torque, screen=None):
    """``bond_forces`` for disks (dim 2), the same operations without the terms that are
    exactly zero in the plane (z of positions, velocities, normals, shear forces, x and y
    of spins and bending moments: ``ParticleState`` fixes them, ``FIX_2D``): the same
    values as ``bond_forces`` (only the sign of zero components may differ), in about
    half the instructions. Arguments as there (no twist: no ``jb``, ``mt``, ``dim``);
    the x and y of ``mb`` and the z of ``fs`` are left as they are (zero).

    ``screen`` (optional, ``bond_screen``: 1/A and Rb/I per bond): the strength test
    first runs with these reciprocals (multiplications) and, only when a stress comes
    within 1e-9 of its limit, as the exact divisions: a bond far from breaking (nearly
    all) is then known intact without them. The decisions, hence the results, are the
    same bits (the reciprocals' few-ulp error is far inside the margin)."""
    nb = bi.shape[0]
    nnew = 0
    for b in prange(nb):
        if mode[b] != INTACT:
            continue
        i = bi[b]
        j = bj[b]
        d0 = min_image(pos[j, 0] - pos[i, 0], length[0], periodic[0])
        d1 = min_image(pos[j, 1] - pos[i, 1], length[1], periodic[1])
        dist = np.sqrt(d0 * d0 + d1 * d1)
        inv = 1.0 / dist
        n0 = d0 * inv
        n1 = d1 * inv
        # rigid rotation old -> new normal about z (k = o x n = (0, 0, k2)); no spin term
        o0, o1 = nrm[b, 0], nrm[b, 1]
        c = o0 * n0 + o1 * n1
        k2 = o0 * n1 - o1 * n0
        s0, s1 = fs[b, 0], fs[b, 1]
        mz = mb[b, 2]
        if c > -1.0:  # _rotate: the shear force turns with the normal, kv = 0 for it
            r0 = c * s0 - k2 * s1
            r1 = c * s1 + k2 * s0
            mz = c * mz + k2 * mz / (1.0 + c) * k2
        else:
            r0 = s0
            r1 = s1
        rn = r0 * n0 + r1 * n1  # round-off only: keep it tangential
        s0 = r0 - rn * n0
        s1 = r1 - rn * n1
        nrm[b, 0] = n0
        nrm[b, 1] = n1
        # contact point arms: i -> x_c = a_i n, j -> x_c = -a_j n
        ai = radius[i] + 0.5 * (dist - radius[i] - radius[j])
        aj = dist - ai
        wi2 = omega[i, 2]
        wj2 = omega[j, 2]
        v0 = (vel[j, 0] + aj * (wj2 * n1)) - (vel[i, 0] - ai * (wi2 * n1))
        v1 = (vel[j, 1] - aj * (wj2 * n0)) - (vel[i, 1] + ai * (wi2 * n0))
        vn = v0 * n0 + v1 * n1
        kna = kn[b] * area[b]
        ksa = ks[b] * area[b]
        fnb = fn[b] - kna * vn * dt
        s0 -= ksa * (v0 - vn * n0) * dt
        s1 -= ksa * (v1 - vn * n1) * dt
        mz -= kn[b] * ib[b] * ((wj2 - wi2) * dt)
        # maximum stresses (Sha et al. (2022) eq 11, Potyondy & Cundall 2004), tension positive
        fsm = np.sqrt(s0 ** 2 + s1 ** 2)
        how = INTACT
        exact = True
        mbm = sig_n = sigma = tau = 0.0
        if screen is not None:  # (a compile-time branch: None is its own type)
            sn_a = -fnb * screen[b, 0]
            bend_a = abs(mz) * screen[b, 1]
            tau_a = fsm * screen[b, 0]
            thr_a = sn_a * tanphi[b]
            exact = not (sn_a + bend_a < tens[b] - 1e-9 * (abs(sn_a) + bend_a + tens[b])
                         and tau_a < coh[b] - thr_a - 1e-9 * (tau_a + coh[b] + abs(thr_a)))
        if exact:
            mbm = np.sqrt(mz ** 2)
            sig_n = -fnb / area[b]
            sigma = sig_n + mbm * rb[b] / ib[b]
            tau = fsm / area[b]
            if sigma >= tens[b]:
                how = TENSILE
            elif tau >= coh[b] - sig_n * tanphi[b]:
                how = SHEAR
        if how != INTACT:
            mode[b] = how
            newly[b] = 1
            nnew += 1
            brk[b, B_X] = pos[i, 0] + ai * n0
            brk[b, B_Y] = pos[i, 1] + ai * n1
            brk[b, B_Z] = pos[i, 2]
            brk[b, B_FN] = fnb
            brk[b, B_FS] = fsm
            brk[b, B_MB] = mbm
            brk[b, B_MT] = 0.0
            brk[b, B_SIGMA] = sigma
            brk[b, B_TAU] = tau
            fn[b] = 0.0
            for k in range(3):
                fs[b, k] = 0.0
                mb[b, k] = 0.0
                if not summed:
                    fbond[b, k] = 0.0
                    tbi[b, k] = 0.0
                    tbj[b, k] = 0.0
            continue
        fn[b] = fnb
        fs[b, 0] = s0
        fs[b, 1] = s1
        mb[b, 2] = mz
        f0 = fnb * n0 + s0
        f1 = fnb * n1 + s1
        cz = n0 * f1 - n1 * f0  # arm x force about z
        if summed:
            ext_force[i, 0] -= f0
            ext_force[i, 1] -= f1
            ext_torque[i, 2] += -ai * cz - mz
            ext_force[j, 0] += f0
            ext_force[j, 1] += f1
            ext_torque[j, 2] += -aj * cz + mz
            continue
        fbond[b, 0] = f0
        fbond[b, 1] = f1
        fbond[b, 2] = 0.0
        tbj[b, 0] = 0.0
        tbj[b, 1] = 0.0
        tbj[b, 2] = -aj * cz + mz
        tbi[b, 0] = 0.0
        tbi[b, 1] = 0.0
        tbi[b, 2] = -ai * cz - mz
    return nnew


# ---------------------------------------------------------------- 2D bonds in batches
# rows of a 2D batch's input buffer (``bond_forces_2d_lanes`` gathers them): separation
# (min image), the two particles' in-plane velocities and spins about z, radii, then the
# bond's stored normal, fn, fs and bending moment (z), then its constants from row P_K
(P_D0, P_D1, P_VI0, P_VI1, P_VJ0, P_VJ1, P_WI, P_WJ, P_RI, P_RJ, P_O0, P_O1, P_FN, P_S0,
 P_S1, P_MZ) = range(16)
P_K = 16
# columns of the per-bond constants of disks (``bond_consts_2d``)
(K2_KNA, K2_KSA, K2_KNI, K2_INVA, K2_RBI, K2_TENS, K2_COH, K2_TANPHI) = range(8)
N_K2 = 8
N_P = P_K + N_K2
# rows of its output buffer: the new normal and load, force on j, moments on i and j
# (z), arm a_i, |Fs|, and the lane's verdict (0 intact for sure, 1 near a strength limit)
(Q_N0, Q_N1, Q_FN, Q_S0, Q_S1, Q_MZ, Q_F0, Q_F1, Q_TI, Q_TJ, Q_AI, Q_FSM, Q_FLAG) = range(13)
N_Q = 13


def bond_consts_2d(rb: np.ndarray, area: np.ndarray, inertia: np.ndarray, kn: np.ndarray,
                   ks: np.ndarray, tensile: np.ndarray, cohesion: np.ndarray,
                   tan_phi: np.ndarray) -> np.ndarray:
    """(nb, ``N_K2``): per-bond constants of ``bond_forces_2d_lanes`` (columns ``K2_*``):
    kn A, ks A (N/m), kn I (N m) -- the products ``bond_forces_2d`` forms, the same
    bits --, its screen's 1/A (1/m^2) and Rb/I (1/m^3) (``bond_screen``), sigma_t, c (Pa)
    and tan phi: one row of 64 bytes per bond instead of eight streams."""
    return np.ascontiguousarray(np.c_[kn * area, ks * area, kn * inertia, 1.0 / area,
                                      rb / inertia, tensile, cohesion, tan_phi])


@njit(cache=True, error_model="numpy")
def _bond_lanes_2d(x, y, m, dt):  # pragma: no cover - numba
    """The arithmetic of ``bond_forces_2d`` (with its screen) for the ``m`` bonds of one
    batch, lane by lane without branches, so that LLVM runs it in SIMD registers: reads
    the gathered rows ``x`` (``P_*``, the constants from ``P_K``; ``RS`` apart), writes
    the rows ``y`` (``Q_*``). The same operations in the same order as
    ``bond_forces_2d`` (the same bits); the branches there are selects here (both sides
    computed, numpy's error model: a division by ``1 + c = 0`` makes a discarded inf).
    Flag 1: the screen left a doubt, ``bond_forces_2d_lanes`` runs the exact test."""
    for q in range(m):
        d0 = x[P_D0 * RS + q]
        d1 = x[P_D1 * RS + q]
        dist = np.sqrt(d0 * d0 + d1 * d1)
        inv = 1.0 / dist
        n0 = d0 * inv
        n1 = d1 * inv
        o0 = x[P_O0 * RS + q]
        o1 = x[P_O1 * RS + q]
        c = o0 * n0 + o1 * n1
        k2 = o0 * n1 - o1 * n0
        s0 = x[P_S0 * RS + q]
        s1 = x[P_S1 * RS + q]
        mz = x[P_MZ * RS + q]
        turn = c > -1.0
        r0 = c * s0 - k2 * s1
        r1 = c * s1 + k2 * s0
        mzr = c * mz + k2 * mz / (1.0 + c) * k2
        r0 = r0 if turn else s0
        r1 = r1 if turn else s1
        mz = mzr if turn else mz
        rn = r0 * n0 + r1 * n1
        s0 = r0 - rn * n0
        s1 = r1 - rn * n1
        ri = x[P_RI * RS + q]
        ai = ri + 0.5 * (dist - ri - x[P_RJ * RS + q])
        aj = dist - ai
        wi2 = x[P_WI * RS + q]
        wj2 = x[P_WJ * RS + q]
        v0 = (x[P_VJ0 * RS + q] + aj * (wj2 * n1)) - (x[P_VI0 * RS + q] - ai * (wi2 * n1))
        v1 = (x[P_VJ1 * RS + q] - aj * (wj2 * n0)) - (x[P_VI1 * RS + q] + ai * (wi2 * n0))
        vn = v0 * n0 + v1 * n1
        ksa = x[(P_K + K2_KSA) * RS + q]
        fnb = x[P_FN * RS + q] - x[(P_K + K2_KNA) * RS + q] * vn * dt
        s0 -= ksa * (v0 - vn * n0) * dt
        s1 -= ksa * (v1 - vn * n1) * dt
        mz -= x[(P_K + K2_KNI) * RS + q] * ((wj2 - wi2) * dt)
        fsm = np.sqrt(s0 ** 2 + s1 ** 2)
        inva = x[(P_K + K2_INVA) * RS + q]
        tens = x[(P_K + K2_TENS) * RS + q]
        coh = x[(P_K + K2_COH) * RS + q]
        sn_a = -fnb * inva
        bend_a = abs(mz) * x[(P_K + K2_RBI) * RS + q]
        tau_a = fsm * inva
        thr_a = sn_a * x[(P_K + K2_TANPHI) * RS + q]
        safe = ((sn_a + bend_a < tens - 1e-9 * (abs(sn_a) + bend_a + tens))
                & (tau_a < coh - thr_a - 1e-9 * (tau_a + coh + abs(thr_a))))
        y[Q_FLAG * RS + q] = 0.0 if safe else 1.0
        f0 = fnb * n0 + s0
        f1 = fnb * n1 + s1
        cz = n0 * f1 - n1 * f0
        y[Q_N0 * RS + q] = n0
        y[Q_N1 * RS + q] = n1
        y[Q_FN * RS + q] = fnb
        y[Q_S0 * RS + q] = s0
        y[Q_S1 * RS + q] = s1
        y[Q_MZ * RS + q] = mz
        y[Q_F0 * RS + q] = f0
        y[Q_F1 * RS + q] = f1
        y[Q_TI * RS + q] = -ai * cz - mz
        y[Q_TJ * RS + q] = -aj * cz + mz
        y[Q_AI * RS + q] = ai
        y[Q_FSM * RS + q] = fsm


@kernel
def bond_forces_2d_lanes(pos, vel, omega, radius, bi, bj, rb, area, ib, tens, coh, tanphi,
                         fn, fs, mb, nrm, mode, newly, brk, fbond, tbi, tbj, dt, length,
                         periodic, summed, ext_force, ext_torque, kc):
    """``bond_forces_2d`` (with its screen) in batches of ``BW`` bonds: the same values
    (bits). Arguments as there, the stiffnesses and screens in ``kc``
    (``bond_consts_2d`` of the same bonds). Per batch: (1) gather the particles' and the
    bonds' state into a buffer, (2) ``_bond_lanes_2d``: the arithmetic in SIMD lanes,
    (3) per bond in increasing index, as ``bond_forces_2d``: skip broken bonds, the
    exact strength test where the screen left a doubt (break, log and zero as there),
    store the state and sum the bond into its particles (``summed``) or store it for
    ``gather_bonds``. prange over tasks of ``B_TASK`` batches; each bond writes only its
    own rows unless ``summed`` (serial build). Returns the number of breaks."""
    nb = bi.shape[0]
    nbat = (nb + BW - 1) // BW
    ntask = (nbat + B_TASK - 1) // B_TASK
    nnew = 0
    for task in prange(ntask):
        x = np.empty(N_P * RS)
        y = np.empty(N_Q * RS)
        for bat in range(task * B_TASK, min(nbat, (task + 1) * B_TASK)):
            b0 = bat * BW
            m = min(BW, nb - b0)
            for q in range(m):
                b = b0 + q
                i = bi[b]
                j = bj[b]
                x[P_D0 * RS + q] = min_image(pos[j, 0] - pos[i, 0], length[0], periodic[0])
                x[P_D1 * RS + q] = min_image(pos[j, 1] - pos[i, 1], length[1], periodic[1])
                x[P_VI0 * RS + q] = vel[i, 0]
                x[P_VI1 * RS + q] = vel[i, 1]
                x[P_VJ0 * RS + q] = vel[j, 0]
                x[P_VJ1 * RS + q] = vel[j, 1]
                x[P_WI * RS + q] = omega[i, 2]
                x[P_WJ * RS + q] = omega[j, 2]
                x[P_RI * RS + q] = radius[i]
                x[P_RJ * RS + q] = radius[j]
                x[P_O0 * RS + q] = nrm[b, 0]
                x[P_O1 * RS + q] = nrm[b, 1]
                x[P_FN * RS + q] = fn[b]
                x[P_S0 * RS + q] = fs[b, 0]
                x[P_S1 * RS + q] = fs[b, 1]
                x[P_MZ * RS + q] = mb[b, 2]
                for k in range(N_K2):
                    x[(P_K + k) * RS + q] = kc[b, k]
            _bond_lanes_2d(x, y, m, dt)
            for q in range(m):
                b = b0 + q
                if mode[b] != INTACT:
                    continue
                i = bi[b]
                j = bj[b]
                n0 = y[Q_N0 * RS + q]
                n1 = y[Q_N1 * RS + q]
                nrm[b, 0] = n0
                nrm[b, 1] = n1
                fnb = y[Q_FN * RS + q]
                mz = y[Q_MZ * RS + q]
                how = INTACT
                if y[Q_FLAG * RS + q] != 0.0:  # bond_forces_2d's exact test
                    fsm = y[Q_FSM * RS + q]
                    mbm = np.sqrt(mz ** 2)
                    sig_n = -fnb / area[b]
                    sigma = sig_n + mbm * rb[b] / ib[b]
                    tau = fsm / area[b]
                    if sigma >= tens[b]:
                        how = TENSILE
                    elif tau >= coh[b] - sig_n * tanphi[b]:
                        how = SHEAR
                    if how != INTACT:
                        ai = y[Q_AI * RS + q]
                        mode[b] = how
                        newly[b] = 1
                        nnew += 1
                        brk[b, B_X] = pos[i, 0] + ai * n0
                        brk[b, B_Y] = pos[i, 1] + ai * n1
                        brk[b, B_Z] = pos[i, 2]
                        brk[b, B_FN] = fnb
                        brk[b, B_FS] = fsm
                        brk[b, B_MB] = mbm
                        brk[b, B_MT] = 0.0
                        brk[b, B_SIGMA] = sigma
                        brk[b, B_TAU] = tau
                        fn[b] = 0.0
                        for k in range(3):
                            fs[b, k] = 0.0
                            mb[b, k] = 0.0
                            if not summed:
                                fbond[b, k] = 0.0
                                tbi[b, k] = 0.0
                                tbj[b, k] = 0.0
                        continue
                fn[b] = fnb
                fs[b, 0] = y[Q_S0 * RS + q]
                fs[b, 1] = y[Q_S1 * RS + q]
                mb[b, 2] = mz
                f0 = y[Q_F0 * RS + q]
                f1 = y[Q_F1 * RS + q]
                if summed:
                    ext_force[i, 0] -= f0
                    ext_force[i, 1] -= f1
                    ext_torque[i, 2] += y[Q_TI * RS + q]
                    ext_force[j, 0] += f0
                    ext_force[j, 1] += f1
                    ext_torque[j, 2] += y[Q_TJ * RS + q]
                    continue
                fbond[b, 0] = f0
                fbond[b, 1] = f1
                fbond[b, 2] = 0.0
                tbj[b, 0] = 0.0
                tbj[b, 1] = 0.0
                tbj[b, 2] = y[Q_TJ * RS + q]
                tbi[b, 0] = 0.0
                tbi[b, 1] = 0.0
                tbi[b, 2] = y[Q_TI * RS + q]
    return nnew


@kernel
def gather_bonds(cstart, cbond, bi, mode, fbond, tbi, tbj, ext_force, ext_torque):
    """Add bond forces/moments to each particle (prange over particles, fixed order).

    ``cbond[cstart[p]:cstart[p+1]]`` lists p's bonds in increasing bond index
    (``bond_csr(..., by_bond=True)``): the order of the serial ``bond_forces(summed=True)``.
    Broken bonds add nothing (as there).
    """
    n = cstart.shape[0] - 1
    for p in prange(n):
        for q in range(cstart[p], cstart[p + 1]):
            b = cbond[q]
            if mode[b] != INTACT:
                continue
            if bi[b] == p:
                for k in range(3):
                    ext_force[p, k] -= fbond[b, k]
                    ext_torque[p, k] += tbi[b, k]
            else:
                for k in range(3):
                    ext_force[p, k] += fbond[b, k]
                    ext_torque[p, k] += tbj[b, k]


class BondStep(NamedTuple):
    """``ParallelBonds``'s compiled form for disks (arrays shared with it; see
    ``compiled``)."""

    i: np.ndarray
    j: np.ndarray
    rb: np.ndarray
    area: np.ndarray
    inertia: np.ndarray
    polar: np.ndarray
    kn: np.ndarray
    ks: np.ndarray
    tensile: np.ndarray
    cohesion: np.ndarray
    tan_phi: np.ndarray
    fn: np.ndarray
    fs: np.ndarray
    mb: np.ndarray
    mt: np.ndarray
    normal: np.ndarray
    mode: np.ndarray
    newly: np.ndarray
    brk: np.ndarray
    fbond: np.ndarray
    tbi: np.ndarray
    tbj: np.ndarray
    kc: np.ndarray


class BondStep3D(NamedTuple):
    """``ParallelBonds``'s compiled form for spheres (arrays shared with it). A class of
    its own: a compiled loop of disks then never links the 3D kernel (linked, unused, it
    made the braking cell's loop ~35 % slower)."""

    i: np.ndarray
    j: np.ndarray
    rb: np.ndarray
    area: np.ndarray
    inertia: np.ndarray
    polar: np.ndarray
    kn: np.ndarray
    ks: np.ndarray
    tensile: np.ndarray
    cohesion: np.ndarray
    tan_phi: np.ndarray
    fn: np.ndarray
    fs: np.ndarray
    mb: np.ndarray
    mt: np.ndarray
    normal: np.ndarray
    mode: np.ndarray
    newly: np.ndarray
    brk: np.ndarray
    fbond: np.ndarray
    tbi: np.ndarray
    tbj: np.ndarray
    kc: np.ndarray


#: the compiled steps' event code: bonds broke this step (logged by ``after_compiled``)
BONDS_BROKE = 1
_bonds_2d = bond_forces_2d_lanes.serial
_bonds_3d = bond_forces_3d.serial


@compiled.register(BondStep)
@njit(cache=True)
def _bond_step(s, c):  # pragma: no cover - numba
    """``ParallelBonds.compute`` for disks on its serial build (``bond_forces_2d_lanes``,
    summed into ``c.ext_force`` / ``c.ext_torque``); ``BONDS_BROKE`` when a bond broke."""
    nnew = _bonds_2d(c.pos, c.vel, c.omega, c.radius, s.i, s.j, s.rb, s.area, s.inertia,
                     s.tensile, s.cohesion, s.tan_phi, s.fn, s.fs, s.mb, s.normal, s.mode,
                     s.newly, s.brk, s.fbond, s.tbi, s.tbj, c.dt, c.length, c.periodic, True,
                     c.ext_force, c.ext_torque, s.kc)
    return BONDS_BROKE if nnew else 0


@compiled.register(BondStep3D)
@njit(cache=True)
def _bond_step_3d(s, c):  # pragma: no cover - numba
    """``ParallelBonds.compute`` for spheres on its serial build (``bond_forces_3d``,
    summed into ``c.ext_force`` / ``c.ext_torque``); ``BONDS_BROKE`` when a bond broke."""
    nnew = _bonds_3d(c.pos, c.vel, c.omega, c.radius, s.i, s.j, s.rb, s.area, s.inertia,
                     s.polar, s.kn, s.ks, s.tensile, s.cohesion, s.tan_phi, s.fn, s.fs,
                     s.mb, s.mt, s.normal, s.mode, s.newly, s.brk, s.fbond, s.tbi, s.tbj,
                     c.dt, c.length, c.periodic, True, c.ext_force, c.ext_torque, s.kc)
    return BONDS_BROKE if nnew else 0


def bond_screen(area: np.ndarray, rb: np.ndarray, inertia: np.ndarray) -> np.ndarray:
    """(nb, 2): 1/A (1/m^2) and Rb/I (1/m^3) per bond, for ``bond_forces_2d``'s screen."""
    return np.ascontiguousarray(np.c_[1.0 / area, rb / inertia])


def bond_csr(bi: np.ndarray, bj: np.ndarray, n: int, by_bond: bool = False
             ) -> tuple[np.ndarray, np.ndarray]:
    """Per-particle bond index (CSR): ``cbond[cstart[p]:cstart[p+1]]`` are p's bonds: the
    bonds where p is i, then those where it is j (``by_bond``: in increasing bond index)."""
    ends = np.concatenate([bi, bj])
    ids = np.concatenate([np.arange(bi.size), np.arange(bj.size)]).astype(np.int64)
    order = np.lexsort((ids, ends)) if by_bond else np.argsort(ends, kind="stable")
    cstart = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(np.bincount(ends, minlength=n), out=cstart[1:])
    return cstart, ids[order]


def _per_bond(x: object, n: int, name: str, allowed: str, ok: object) -> np.ndarray:
    return checked_per_item(x, n, "bonds", name, allowed, ok)


class ParallelBonds:
    """Linear parallel bonds between particle pairs (an engine ``Interaction``).

    ``i``, ``j``: bonded particles; ``lambda_``: bond radius multiplier (Rb = lambda
    min(r_i, r_j)); ``E_bond``: bond effective modulus (Pa); ``kratio`` kn/ks;
    ``tensile_strength`` sigma_t and ``cohesion`` c (Pa); ``friction_angle`` phi (deg).
    Scalars or one value per bond. Geometry and stiffness are fixed at construction from
    the current radii and positions; forces start at zero.
    """

    def __init__(self, sim: Simulation, i: np.ndarray, j: np.ndarray, lambda_: float,
                 E_bond: float | np.ndarray, kratio: float | np.ndarray,
                 tensile_strength: float | np.ndarray, cohesion: float | np.ndarray,
                 friction_angle: float | np.ndarray = 0.0) -> None:
        p = sim.p
        self.dim = p.dim
        self.n_particles = p.n
        bi = np.asarray(i, dtype=np.int64).reshape(-1)
        bj = np.asarray(j, dtype=np.int64).reshape(-1)
        if bi.shape != bj.shape:
            raise ValueError(f"bonds: i has {bi.size} entries but j has {bj.size}")
        nb = bi.size
        if nb and (min(bi.min(), bj.min()) < 0 or max(bi.max(), bj.max()) >= p.n):
            raise ValueError(f"bonds: particle indices must be in [0, {p.n - 1}]")
        if np.any(bi == bj):
            k = int(np.flatnonzero(bi == bj)[0])
            raise ValueError(f"bonds: bond {k} joins particle {int(bi[k])} to itself")
        if not (isinstance(lambda_, (int, float)) and lambda_ > 0):
            raise ValueError(f"bonds: lambda_ = {lambda_!r}: must be a number > 0")
        swap = bi > bj  # store i < j (like the neighbour list)
        self.i = np.where(swap, bj, bi)
        self.j = np.where(swap, bi, bj)
        e = _per_bond(E_bond, nb, "E_bond", "> 0 Pa", lambda a: a > 0)
        kr = _per_bond(kratio, nb, "kratio", "> 0", lambda a: a > 0)
        self.tensile = _per_bond(tensile_strength, nb, "tensile_strength", "> 0 Pa",
                                 lambda a: a > 0)
        self.cohesion = _per_bond(cohesion, nb, "cohesion", "> 0 Pa", lambda a: a > 0)
        phi = _per_bond(friction_angle, nb, "friction_angle", "in [0, 90) degrees",
                        lambda a: (a >= 0) & (a < 90))
        self.tan_phi = np.tan(np.radians(phi))
        ri, rj = p.radius[self.i], p.radius[self.j]
        self.rb = float(lambda_) * np.minimum(ri, rj)
        if self.dim == 2:
            t = p.thickness
            self.area = 2.0 * self.rb * t
            self.inertia = 2.0 / 3.0 * t * self.rb**3
            self.polar = np.zeros(nb)
        else:
            self.area = np.pi * self.rb**2
            self.inertia = np.pi * self.rb**4 / 4.0
            self.polar = np.pi * self.rb**4 / 2.0
        self.kn = e / (ri + rj)
        self.ks = self.kn / kr
        d = p.pos[self.j] - p.pos[self.i]
        for k in range(3):
            if sim.box.periodic[k]:
                d[:, k] -= sim.box.length[k] * np.rint(d[:, k] / sim.box.length[k])
        self.length = np.sqrt((d * d).sum(axis=1))
        if np.any(self.length == 0.0):
            raise ValueError("bonds: a bonded pair has coincident centres")
        self.normal = d / self.length[:, None]
        self.fn = np.zeros(nb)
        self.fs = np.zeros((nb, 3))
        self.mb = np.zeros((nb, 3))
        self.mt = np.zeros(nb)
        self.mode = np.zeros(nb, dtype=np.int8)
        self.newly = np.zeros(nb, dtype=np.int8)
        self.brk = np.zeros((nb, N_BREAK))
        self.fbond = np.zeros((nb, 3))
        self.tbi = np.zeros((nb, 3))
        self.tbj = np.zeros((nb, 3))
        self.log: list[BondBreak] = []
        self.cstart, self.cbond = bond_csr(self.i, self.j, p.n)
        self.gstart, self.gbond = bond_csr(self.i, self.j, p.n, by_bond=True)
        self.screen = bond_screen(self.area, self.rb, self.inertia)
        self.kc = self._consts()

    def _consts(self) -> np.ndarray:
        """The per-bond constants of the batched kernels: ``bond_consts_2d`` (disks) or
        ``bond_consts_3d`` (spheres) of these bonds. Like ``screen``, made at construction
        and by ``set_state``: after changing a bond's geometry, stiffness or strength in
        place, call it again (``self.kc = self._consts()``)."""
        if self.dim == 2:
            return bond_consts_2d(self.rb, self.area, self.inertia, self.kn, self.ks,
                                  self.tensile, self.cohesion, self.tan_phi)
        return bond_consts_3d(self.rb, self.area, self.inertia, self.polar, self.kn, self.ks,
                              self.tensile, self.cohesion, self.tan_phi)

    # ------------------------------------------------------------------ interaction
    @property
    def n_bonds(self) -> int:
        """Number of bonds (intact and broken)."""
        return int(self.i.size)

    @property
    def intact(self) -> np.ndarray:
        """Boolean mask of intact bonds."""
        return self.mode == INTACT

    def compute(self, sim: Simulation) -> None:
        """Update the bonds, break what exceeds its strength, add forces to ``ext_*``."""
        nb = self.i.size
        if nb == 0:
            return
        p = sim.p
        threads = sim._threads
        summed = serial_run(nb, threads)
        length = sim.box_length
        if self.dim == 2:
            nnew = bond_forces_2d_lanes.pick(nb, threads)(
                p.pos, p.vel, p.omega, p.radius, self.i, self.j, self.rb, self.area,
                self.inertia, self.tensile, self.cohesion, self.tan_phi, self.fn, self.fs,
                self.mb, self.normal, self.mode, self.newly, self.brk, self.fbond, self.tbi,
                self.tbj, sim.dt, length, sim.box.periodic, summed, sim.ext_force,
                sim.ext_torque, self.kc)
        else:
            nnew = bond_forces_3d.pick(nb, threads)(
                p.pos, p.vel, p.omega, p.radius, self.i, self.j, self.rb, self.area,
                self.inertia, self.polar, self.kn, self.ks, self.tensile, self.cohesion,
                self.tan_phi, self.fn, self.fs, self.mb, self.mt, self.normal, self.mode,
                self.newly, self.brk, self.fbond, self.tbi, self.tbj, sim.dt, length,
                sim.box.periodic, summed, sim.ext_force, sim.ext_torque, self.kc)
        if nnew:
            # the kernel runs before the step counter advances: the break belongs to step + 1
            self._log_breaks(sim.time + sim.dt, sim.step_count + 1)
        if not summed:  # threaded: each bond stored, gathered per particle in bond order
            gather_bonds.pick(p.n, threads)(self.gstart, self.gbond, self.i, self.mode,
                                            self.fbond, self.tbi, self.tbj, sim.ext_force,
                                            sim.ext_torque)

    def compiled(self, sim: Simulation) -> BondStep | BondStep3D | None:
        """The compiled form (``BondStep`` for disks, ``BondStep3D`` for spheres) when the
        bonds run on their serial build (summed straight into the particles), else
        ``None``."""
        if not serial_run(self.i.size, sim._threads):
            return None
        arrays = (self.i, self.j, self.rb, self.area, self.inertia, self.polar, self.kn,
                  self.ks, self.tensile, self.cohesion, self.tan_phi, self.fn, self.fs,
                  self.mb, self.mt, self.normal, self.mode, self.newly, self.brk, self.fbond,
                  self.tbi, self.tbj)
        if self.dim == 2:
            return BondStep(*arrays, self.kc)
        return BondStep3D(*arrays, self.kc)

    def after_compiled(self, sim: Simulation, state: BondStep | BondStep3D) -> None:
        """Log the breaks of the compiled loop's last step (it stops after a break)."""
        if self.newly.any():
            self._log_breaks(sim.time, sim.step_count)

    def _log_breaks(self, time: float, step: int) -> None:
        """Log the bonds marked ``newly`` as broken at ``time`` (s), step ``step``."""
        for b in np.flatnonzero(self.newly):
            r = self.brk[b]
            self.log.append(BondBreak(
                time=time, step=step,
                position=(float(r[B_X]), float(r[B_Y]), float(r[B_Z])),
                mode=MODE_NAMES[int(self.mode[b])], i=int(self.i[b]), j=int(self.j[b]),
                fn=float(r[B_FN]), fs=float(r[B_FS]), mb=float(r[B_MB]), mt=float(r[B_MT]),
                sigma=float(r[B_SIGMA]), tau=float(r[B_TAU])))
        self.newly[:] = 0

    def broken_count(self, mode: str | None = None) -> int:
        """Number of broken bonds, all or of one mode ("tensile" or "shear")."""
        if mode is None:
            return int(np.count_nonzero(self.mode != INTACT))
        if mode not in MODES:
            raise ValueError(f"bonds: mode = {mode!r}: must be one of {sorted(MODES)} or None")
        return int(np.count_nonzero(self.mode == MODES[mode]))

    def stresses(self) -> tuple[np.ndarray, np.ndarray]:
        """Current maximum stresses (sigma, tau) per bond (Pa, eq 11; broken bonds: 0)."""
        mbm = np.linalg.norm(self.mb, axis=1)
        sigma = -self.fn / self.area + mbm * self.rb / self.inertia
        tau = np.linalg.norm(self.fs, axis=1) / self.area
        if self.dim == 3:
            tau = tau + np.abs(self.mt) * self.rb / self.polar
        return sigma, tau

    def critical_step(self, sim: Simulation) -> float:
        """Critical time step (s) from bond stiffness: ``sqrt(m/k)`` over bond ends with k
        the summed translational (kn A, ks A) and rotational stiffness of a particle's
        bonds (as PFC's estimate); inf without bonds."""
        if self.n_bonds == 0:
            return math.inf
        p = sim.p
        n = p.n
        kt = np.zeros(n)
        kr = np.zeros(n)
        kmax = np.maximum(self.kn, self.ks) * self.area
        krot = self.kn * self.inertia + self.ks * self.area * (0.5 * self.length) ** 2
        for ends in (self.i, self.j):
            np.add.at(kt, ends, kmax)
            np.add.at(kr, ends, krot)
        sel = kt > 0
        dt_t = np.sqrt(p.mass[sel] / kt[sel]).min()
        dt_r = np.sqrt(p.inertia[sel] / kr[sel]).min()
        return float(min(dt_t, dt_r))

    def thermal_load(self, dT: np.ndarray, alpha: np.ndarray) -> None:
        """Constrained thermal expansion of intact bonds (Sha et al. (2022) eq 13): the normal force
        grows by ``kn A alpha L dT`` (+ = compression here; ``-kn A alpha L dT`` in PFC's
        tension-positive sign), with dT and alpha the means over the two particles."""
        if self.n_bonds == 0:
            return
        db = 0.5 * (dT[self.i] + dT[self.j])
        ab = 0.5 * (alpha[self.i] + alpha[self.j])
        self.fn += np.where(self.intact, self.kn * self.area * ab * self.length * db, 0.0)

    # ------------------------------------------------------------------ growing runs
    def particles_appended(self, sim: Simulation, n_old: int) -> None:
        """Engine hook (``Simulation.append_particles``): the bonds keep their indices;
        the per-particle bond lists grow to the new particle count."""
        self.n_particles = sim.p.n
        self._index()

    def extend(self, more: ParallelBonds) -> np.ndarray:
        """Append the bonds of ``more`` (made on the same simulation, not added to it):
        they start at zero force from the geometry ``more`` was made on. Returns the new
        bonds' indices."""
        if more.dim != self.dim:
            raise ValueError("bonds: cannot extend disks' bonds with spheres' (or back)")
        nb0 = self.n_bonds
        for k in (*self._ARRAYS, "newly", "brk"):
            setattr(self, k, np.concatenate([getattr(self, k), getattr(more, k)]))
        self.n_particles = max(self.n_particles, more.n_particles)
        self._index()
        return np.arange(nb0, self.n_bonds)

    def _index(self) -> None:
        """The per-particle bond lists and the per-bond screens of the current arrays."""
        self.cstart, self.cbond = bond_csr(self.i, self.j, self.n_particles)
        self.gstart, self.gbond = bond_csr(self.i, self.j, self.n_particles, by_bond=True)
        self.screen = bond_screen(self.area, self.rb, self.inertia)
        self.kc = self._consts()

    # ------------------------------------------------------------------ checkpoints
    _ARRAYS = ("i", "j", "rb", "area", "inertia", "polar", "kn", "ks", "tensile", "cohesion",
               "tan_phi", "length", "normal", "fn", "fs", "mb", "mt", "mode", "fbond", "tbi",
               "tbj")
    _LOG_F = ("time", "fn", "fs", "mb", "mt", "sigma", "tau")

    def state(self) -> dict[str, np.ndarray]:
        """All bond arrays and the break log, for checkpoints."""
        out = {k: getattr(self, k) for k in self._ARRAYS}
        lg = self.log
        for k in self._LOG_F:
            out[f"log_{k}"] = np.array([getattr(r, k) for r in lg], dtype=np.float64)
        out["log_step"] = np.array([r.step for r in lg], dtype=np.int64)
        out["log_ij"] = np.array([(r.i, r.j) for r in lg], dtype=np.int64).reshape(-1, 2)
        out["log_mode"] = np.array([MODES[r.mode] for r in lg], dtype=np.int8)
        out["log_pos"] = np.array([r.position for r in lg], dtype=np.float64).reshape(-1, 3)
        return out

    def set_state(self, state: dict[str, np.ndarray]) -> None:
        """Restore what ``state`` returned (same particle count)."""
        for k in self._ARRAYS:
            setattr(self, k, np.array(state[k]))
        nb = self.i.size
        self.newly = np.zeros(nb, dtype=np.int8)
        self.brk = np.zeros((nb, N_BREAK))
        self._index()
        self.log = []
        for q in range(state["log_step"].size):
            f = {k: float(state[f"log_{k}"][q]) for k in self._LOG_F}
            self.log.append(BondBreak(
                step=int(state["log_step"][q]),
                position=tuple(float(x) for x in state["log_pos"][q]),  # type: ignore[arg-type]
                mode=MODE_NAMES[int(state["log_mode"][q])], i=int(state["log_ij"][q, 0]),
                j=int(state["log_ij"][q, 1]), **f))


def install_bonds_by_gap(sim: Simulation, gap: float, lambda_: float, E_bond: float,
                         kratio: float, tensile_strength: float, cohesion: float,
                         friction_angle: float = 0.0, groups: list[int] | None = None
                         ) -> ParallelBonds:
    """Bond every pair whose surface gap is below ``gap`` (m; overlapping pairs too) and add
    the bonds to ``sim`` as an interaction.

    ``groups``: bond only pairs whose two particles share a group in this list (``None``:
    all pairs). See ``ParallelBonds`` for the other parameters (Pa, degrees).
    """
    if not (isinstance(gap, (int, float)) and gap >= 0):
        raise ValueError(f"bonds: gap = {gap!r}: must be a number >= 0 m")
    p = sim.p
    nl = neighbors.build(p.pos, p.radius, max(float(gap), 1e-12 * float(p.radius.max())),
                         sim.box.lo, sim.box.hi, sim.box.periodic)
    i, j = nl.pair_i.astype(np.int64), nl.pair_j.astype(np.int64)
    d = p.pos[j] - p.pos[i]
    for k in range(3):
        if sim.box.periodic[k]:
            d[:, k] -= sim.box.length[k] * np.rint(d[:, k] / sim.box.length[k])
    g = np.sqrt((d * d).sum(axis=1)) - p.radius[i] - p.radius[j]
    keep = g < gap
    if groups is not None:
        gi, gj = p.group[i], p.group[j]
        keep &= (gi == gj) & np.isin(gi, np.asarray(list(groups), dtype=np.int64))
    bonds = ParallelBonds(sim, i[keep], j[keep], lambda_, E_bond, kratio, tensile_strength,
                          cohesion, friction_angle)
    sim.add_interaction(bonds)
    return bonds
