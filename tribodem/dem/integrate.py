"""Central-difference integrator with damping (seed 000 eqs 1-8) and time-step estimates.

Velocity form of eqs 4-8 (leapfrog): ``(m + eta dt/2) v+ = (m - eta dt/2) v- + F dt`` and
``x+ = x + v+ dt``, likewise for rotation with I and the moment M. ``eta = c m`` with
``c`` the global viscous damping rate (1/s) -- the seed's eta in eq 1 -- and the elastic
term ``-k u`` of eq 1 is the contact force already inside F. PFC local damping
``F_d = -alpha |F| sign(v)`` per degree of freedom is applied before the update.
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from tribodem.dem.contact import LINEAR, P_KRATIO, P_LAW
from tribodem.dem.jit import kernel


@kernel
def central_difference(pos, vel, omega, force, torque, mass, inertia, fixed, gravity, dt,
                       viscous, local, dim):
    """One step for all particles (in place). Fixed DOFs keep their velocity."""
    n = pos.shape[0]
    h = 0.5 * viscous * dt
    a = (1.0 - h) / (1.0 + h)
    b = dt / (1.0 + h)
    for i in prange(n):
        m = mass[i]
        fx = fixed[i]
        for k in range(3):
            if fx & (1 << k):
                continue
            f = force[i, k] + m * gravity[k]
            v = vel[i, k]
            if local > 0.0 and v != 0.0:
                f -= local * abs(f) * (1.0 if v > 0.0 else -1.0)
            vel[i, k] = a * v + b * f / m
        for k in range(3):
            if fx & (1 << (k + 3)):
                continue
            t = torque[i, k]
            w = omega[i, k]
            if local > 0.0 and w != 0.0:
                t -= local * abs(t) * (1.0 if w > 0.0 else -1.0)
            omega[i, k] = a * w + b * t / inertia[i]
        for k in range(3):
            pos[i, k] += vel[i, k] * dt


def rayleigh_step(radius: float, density: float, shear_modulus: float, poisson: float) -> float:
    """Rayleigh time step (s), seed 003 eq 2.17: pi R sqrt(rho/G) / (0.163 nu + 0.8766)."""
    return math.pi * radius * math.sqrt(density / shear_modulus) / (0.163 * poisson + 0.8766)


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
    rr = radius
    ray_p = np.full(rr.size, np.inf)
    for m_id, m in enumerate(materials):
        sel = mat == m_id
        ray_p[sel] = (math.pi * rr[sel] * np.sqrt(density[sel] / m.shear_modulus)
                      / (0.163 * m.poisson + 0.8766))
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
        dtp = np.where(law == LINEAR, lin, ray_p[small])
        p = int(np.argmin(dtp))
        best = float(dtp[p])
        kind = "linear sqrt(m/k)" if law[p] == LINEAR else "Hertz Rayleigh (eq 2.17)"
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
        dtw = np.where(law == LINEAR, lin, ray_p[near])
        q = int(np.argmin(dtw))
        if dtw[q] < best:
            best = float(dtw[q])
            kind = "linear sqrt(m/k)" if law[q] == LINEAR else "Hertz Rayleigh (eq 2.17)"
            what = (f"pair (particle {int(near[q])}, wall '{w.name}') with radius "
                    f"{rr[near[q]]:.4g} m [{kind}]")
    hertz = np.flatnonzero(pairtab[mat, mat, P_LAW] != LINEAR)
    if hertz.size:
        s = int(hertz[np.argmin(ray_p[hertz])])
        if ray_p[s] < best:
            best = float(ray_p[s])
            what = f"particle {s} (radius {rr[s]:.4g} m) [Hertz Rayleigh (eq 2.17)]"
    return best, what
