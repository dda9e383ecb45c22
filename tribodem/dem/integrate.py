"""Central-difference integrator with damping (Sha et al. (2022) eqs 1-8) and time-step estimates.

``advance`` is the per-particle half of a step (forces gathered, walls, update).
Velocity form of eqs 4-8 (leapfrog): ``(m + eta dt/2) v+ = (m - eta dt/2) v- + F dt`` and
``x+ = x + v+ dt``, likewise for rotation with I and the moment M. ``eta = c m`` with
``c`` the global viscous damping rate (1/s) -- the seed's eta in eq 1 -- and the elastic
term ``-k u`` of eq 1 is the contact force already inside F. PFC local damping
``F_d = -alpha |F| sign(v)`` per degree of freedom is applied before the update.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from tribodem.dem import laws
from tribodem.dem.jit import kernel
from tribodem.dem.laws.table import P_KRATIO, P_LAW
from tribodem.dem.space import min_image
from tribodem.dem.state import FIX_2D

BLOCK = 256  # particles per block: fixed, so block sums do not depend on the thread count


@njit(cache=True, inline="always")
def local_damped(f, v, local):
    """PFC local damping of one degree of freedom: ``f - alpha |f| sign(v)`` (N or N m)."""
    if local > 0.0 and v != 0.0:
        return f - local * abs(f) * (1.0 if v > 0.0 else -1.0)
    return f


@njit(cache=True, inline="always")
def drift_of(pos, ref_pos, radius, ref_radius, i, length, periodic):
    """How far particle i may have come towards a neighbour since the last neighbour build,
    m: its move (minimum image) plus its radius growth (thermal expansion)."""
    dd = 0.0
    for k in range(3):
        dk = min_image(pos[i, k] - ref_pos[i, k], length[k], periodic[k])
        dd += dk * dk
    g = radius[i] - ref_radius[i]
    return np.sqrt(dd) + (g if g > 0.0 else 0.0)


@njit(cache=True, inline="always")
def _update(pos, vel, omega, i, f0, f1, f2, t0, t1, t2, m, inertia, fixed, a, b, local, dt):
    """Central-difference update of particle i for force f and moment t (Sha et al. (2022) eqs 4, 7)
    with DOF fixity and PFC local damping; scalars, so the sums stay in registers. A free
    particle without local damping takes ``advance``'s own written-out paths instead."""
    for k in range(3):
        if fixed & (1 << k):
            continue
        fk = f0 if k == 0 else (f1 if k == 1 else f2)
        v = vel[i, k]
        vel[i, k] = a * v + b * local_damped(fk, v, local) / m
    for k in range(3):
        if fixed & (1 << (k + 3)):
            continue
        tk = t0 if k == 0 else (t1 if k == 1 else t2)
        w = omega[i, k]
        omega[i, k] = a * w + b * local_damped(tk, w, local) / inertia
    for k in range(3):
        pos[i, k] += vel[i, k] * dt


@kernel(chunk=2)
def advance(pos, vel, omega, radius, mass, inertia, fixed, wstart, wforce, wtorque, dt,
            gravity, viscous, local, has_ext, ext_force, ext_torque, force, torque, ref_pos,
            ref_radius, lo, length, periodic, drift):
    """One step for every particle: its pair forces (already summed into ``force`` /
    ``torque`` by the pair kernels, ``contact.pair_forces_sum`` or the blocked pair), the
    wall pass's force and torque (``walls.wall_forces``, particles with near-wall
    candidates ``wstart``), external forces (``has_ext``), gravity, then the
    central-difference update with damping and the periodic wrap. Writes the total
    force/torque without gravity (``force``, ``torque``, N and N m) and per-block
    ``drift`` (largest move plus growth since the last neighbour build, m).
    """
    n = pos.shape[0]
    nblocks = (n + BLOCK - 1) // BLOCK
    for blk in prange(nblocks):
        advance_block(pos, vel, omega, radius, mass, inertia, fixed, wstart, wforce,
                      wtorque, dt, gravity, viscous, local, has_ext, ext_force, ext_torque,
                      force, torque, ref_pos, ref_radius, lo, length, periodic, drift, blk)


@njit(cache=True, inline="always")
def advance_block(pos, vel, omega, radius, mass, inertia, fixed, wstart, wforce, wtorque,
                  dt, gravity, viscous, local, has_ext, ext_force, ext_torque, force, torque,
                  ref_pos, ref_radius, lo, length, periodic, drift,
                  blk):  # pragma: no cover - numba
    """``advance`` for the particles of block ``blk`` (``BLOCK`` particles): the same
    arguments; writes ``drift[blk]``."""
    n = pos.shape[0]
    h = 0.5 * viscous * dt
    a = (1.0 - h) / (1.0 + h)
    b = dt / (1.0 + h)
    g0 = gravity[0]
    g1 = gravity[1]
    g2 = gravity[2]
    wrap = periodic[0] or periodic[1] or periodic[2]
    dmax = 0.0
    dmax2 = 0.0
    for i in range(blk * BLOCK, min(n, (blk + 1) * BLOCK)):
        f0 = force[i, 0]
        f1 = force[i, 1]
        f2 = force[i, 2]
        t0 = torque[i, 0]
        t1 = torque[i, 1]
        t2 = torque[i, 2]
        if wstart[i + 1] > wstart[i]:
            f0 += wforce[i, 0]
            f1 += wforce[i, 1]
            f2 += wforce[i, 2]
            t0 += wtorque[i, 0]
            t1 += wtorque[i, 1]
            t2 += wtorque[i, 2]
        if has_ext:
            f0 += ext_force[i, 0]
            f1 += ext_force[i, 1]
            f2 += ext_force[i, 2]
            t0 += ext_torque[i, 0]
            t1 += ext_torque[i, 1]
            t2 += ext_torque[i, 2]
        force[i, 0] = f0
        force[i, 1] = f1
        force[i, 2] = f2
        torque[i, 0] = t0
        torque[i, 1] = t1
        torque[i, 2] = t2
        m = mass[i]
        fx = fixed[i]
        if fx == FIX_2D and local == 0.0:
            # a free disk (x, y, rz; z, rx, ry fixed): ``_update``'s general path
            # written out for it (the same operations, without its per-DOF loops)
            vel[i, 0] = a * vel[i, 0] + b * (f0 + m * g0) / m
            vel[i, 1] = a * vel[i, 1] + b * (f1 + m * g1) / m
            omega[i, 2] = a * omega[i, 2] + b * t2 / inertia[i]
            pos[i, 0] += vel[i, 0] * dt
            pos[i, 1] += vel[i, 1] * dt
            pos[i, 2] += vel[i, 2] * dt
        elif fx == 0 and local == 0.0:
            # a free sphere (no fixity, no local damping), written out with every load
            # before the first store (through the inlined ``_update``, with the arrays
            # handed to it, the serial build ran 1.8x slower)
            bm = b / m
            v0 = a * vel[i, 0] + bm * (f0 + m * g0)
            v1 = a * vel[i, 1] + bm * (f1 + m * g1)
            v2 = a * vel[i, 2] + bm * (f2 + m * g2)
            bi = b / inertia[i]
            w0 = a * omega[i, 0] + bi * t0
            w1 = a * omega[i, 1] + bi * t1
            w2 = a * omega[i, 2] + bi * t2
            x0 = pos[i, 0] + v0 * dt
            x1 = pos[i, 1] + v1 * dt
            x2 = pos[i, 2] + v2 * dt
            vel[i, 0] = v0
            vel[i, 1] = v1
            vel[i, 2] = v2
            omega[i, 0] = w0
            omega[i, 1] = w1
            omega[i, 2] = w2
            pos[i, 0] = x0
            pos[i, 1] = x1
            pos[i, 2] = x2
        else:
            _update(pos, vel, omega, i, f0 + m * g0, f1 + m * g1, f2 + m * g2, t0, t1,
                    t2, m, inertia[i], fx, a, b, local, dt)
        if wrap:
            for k in range(3):
                if periodic[k]:
                    x = pos[i, k] - lo[k]
                    if x < 0.0 or x >= length[k]:
                        x -= length[k] * np.floor(x / length[k])
                        if x >= length[k]:
                            x -= length[k]
                        pos[i, k] = lo[k] + x
        # drift_of without a square root per particle: sqrt is monotonic, so the
        # largest move is the root of the largest squared move (growth kept apart)
        dd = 0.0
        for k in range(3):
            dk = min_image(pos[i, k] - ref_pos[i, k], length[k], periodic[k])
            dd += dk * dk
        g = radius[i] - ref_radius[i]
        if g > 0.0:
            dg = np.sqrt(dd) + g
            if dg > dmax:
                dmax = dg
        elif dd > dmax2:
            dmax2 = dd
    dmove = np.sqrt(dmax2)
    drift[blk] = dmax if dmax > dmove else dmove


def rayleigh_step(radius: float | np.ndarray, density: float | np.ndarray, shear_modulus: float,
                  poisson: float) -> float | np.ndarray:
    """Rayleigh time step (s), Lu (2018) eq 2.17: pi R sqrt(rho/G) / (0.163 nu + 0.8766).

    Works element-wise on arrays of radii and densities.
    """
    return math.pi * radius * np.sqrt(density / shear_modulus) / (0.163 * poisson + 0.8766)


def critical_step(density: np.ndarray, radius: np.ndarray, mass: np.ndarray,
                  inertia: np.ndarray, mat: np.ndarray, pair_i: np.ndarray, pair_j: np.ndarray,
                  pairtab: np.ndarray, elin: np.ndarray, materials: list, dim: int,
                  thickness: float, pos: np.ndarray, walls: list, reach: float
                  ) -> tuple[float, str]:
    """Critical time step (s) and a description of the contact pair that limits it.

    Linear pairs: ``sqrt(m_min / k_max)`` with ``k`` the normal, shear (kn/kratio) and
    rotational (ks r^2 against I) stiffnesses of every listed pair (PFC's estimate; the
    exact two-body limit is 2 sqrt(m*/k)). Particle-wall pairs (particles within
    ``reach`` of a wall): the same with kn = A E / r. Hertz: the Rayleigh step (eq 2.17)
    of the smaller particle of the pair, or of the smallest Hertz particle on its own.
    """
    best = math.inf
    what = "no contacts"
    # per law id: True when its step is the stiffness estimate sqrt(m/k), else Rayleigh
    stiff_law = np.array([m.TIME_STEP == "stiffness" for m in laws.modules()])
    rr = radius
    ray_p = np.full(rr.size, np.inf)
    for m_id, m in enumerate(materials):
        sel = mat == m_id
        ray_p[sel] = rayleigh_step(rr[sel], density[sel], m.shear_modulus, m.poisson)
    if pair_i.size:
        i, j = pair_i, pair_j
        law = pairtab[mat[i], mat[j], P_LAW]
        rmin = np.minimum(rr[i], rr[j])
        a = 2.0 * rmin * thickness if dim == 2 else np.pi * rmin * rmin
        kn = a / (rr[i] / elin[mat[i]] + rr[j] / elin[mat[j]])
        ks = kn / pairtab[mat[i], mat[j], P_KRATIO]
        mmin = np.minimum(mass[i], mass[j])
        rot = np.minimum(inertia[i] / (ks * rr[i] ** 2), inertia[j] / (ks * rr[j] ** 2))
        lin = np.sqrt(np.minimum(mmin / np.maximum(kn, ks), rot))
        small = np.where(rr[i] <= rr[j], i, j)
        stiff = stiff_law[law.astype(np.int64)]
        dtp = np.where(stiff, lin, ray_p[small])
        p = int(np.argmin(dtp))
        best = float(dtp[p])
        kind = "stiffness sqrt(m/k)" if stiff[p] else "Rayleigh (eq 2.17)"
        what = (f"pair ({int(i[p])}, {int(j[p])}) with radii {rr[i[p]]:.4g}, "
                f"{rr[j[p]]:.4g} m [{kind}]")
    for w in walls:
        near = np.flatnonzero((pos - w.point) @ w.normal < rr + reach)
        if near.size == 0:
            continue
        law = pairtab[mat[near], w.material, P_LAW]
        area = 2.0 * rr[near] * thickness if dim == 2 else np.pi * rr[near] ** 2
        kn = area * 2.0 / (1.0 / elin[mat[near]] + 1.0 / elin[w.material]) / rr[near]
        ks = kn / pairtab[mat[near], w.material, P_KRATIO]
        lin = np.sqrt(np.minimum(mass[near] / np.maximum(kn, ks),
                                 inertia[near] / (ks * rr[near] ** 2)))
        stiff = stiff_law[law.astype(np.int64)]
        dtw = np.where(stiff, lin, ray_p[near])
        q = int(np.argmin(dtw))
        if dtw[q] < best:
            best = float(dtw[q])
            kind = "stiffness sqrt(m/k)" if stiff[q] else "Rayleigh (eq 2.17)"
            what = (f"pair (particle {int(near[q])}, wall '{w.name}') with radius "
                    f"{rr[near[q]]:.4g} m [{kind}]")
    rayleigh = np.flatnonzero(~stiff_law[pairtab[mat, mat, P_LAW].astype(np.int64)])
    if rayleigh.size:
        s = int(rayleigh[np.argmin(ray_p[rayleigh])])
        if ray_p[s] < best:
            best = float(ray_p[s])
            what = f"particle {s} (radius {rr[s]:.4g} m) [Rayleigh (eq 2.17)]"
    return best, what
