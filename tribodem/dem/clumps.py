"""Rigid multi-sphere bodies (clumps) for debris shapes (Lu (2018) section 3.2.6, figure 3.6).

A clump is a rigid body made of overlapping member spheres ("grouping several spheres").
Members are ordinary particles of the :class:`~tribodem.dem.state.ParticleState`, so pair
contacts, neighbour lists, walls and surfaces see them unchanged. They carry the fixity bits
``FIX_TRANSLATION | FIX_ROTATION | FIX_CLUMP``: ``integrate.advance`` gathers their force
and torque (``sim.force``/``sim.torque``) but leaves their velocities alone; then
:meth:`Clumps.after_advance` (called by ``Simulation.step`` right after the particle update)
sums the member forces and moments about the body centre of mass, integrates the body and
writes the members' positions, velocities and spins. Pairs of members of the same clump are
removed from the neighbour list (:meth:`Clumps.filter_pairs`).

Integrator (stated): translation is the engine's central difference in velocity form with
the same viscous (``(M + eta dt/2) V+ = (M - eta dt/2) V- + F dt``) and PFC local
damping. Rotation is the symplectic, time-reversible NO_SQUISH / DLM splitting of the free
rigid rotor (Dullweber, Leimkuhler & McLachlan 1997; Miller et al. 2002 -- the scheme of
LAMMPS ``fix rigid``) in leapfrog form: the world angular momentum is kicked by the torque,
``L(n+1/2) = a L(n-1/2) + b T(n)`` (the same damping factors: the viscous torque is
``-c I omega = -c L``), then the quaternion and the body-frame momentum are carried over
``dt`` by the exact rotations about the principal axes in the symmetric sequence
``x(dt/2) y(dt/2) z(dt) y(dt/2) x(dt/2)`` (Euler's equations with the principal inertia);
each rotation in Cayley form (exactly orthogonal, angle ``2 atan(phi/2)`` for
``phi = pi_k h / I_k``: the exact flow of a slightly modified free-rotor Hamiltonian, so
the scheme stays symplectic; no trigonometric calls in the hot loop).
Torque-free, ``L`` is conserved to round-off and the kinetic energy error stays bounded,
``O((omega dt)^2)``.

Masses: the body mass is ``rho`` times the volume of the UNION of its members (computed by
:func:`union_properties`, error ~1e-10); members get the density ``rho V_union / sum V_i``
so that the member masses add up to the body mass (mass reports such as ``p.mass.sum()``
stay right; member masses also enter the contact dashpots, as for spheres of that size).
Member kinetic energies from ``Simulation.kinetic_energy`` are not the body's: use
:meth:`Clumps.kinetic_energy`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache

import numpy as np
from numba import njit, prange

from tribodem.dem.integrate import BLOCK, drift_of, local_damped
from tribodem.dem.jit import kernel
from tribodem.dem.neighbors import NeighborList, reverse_index
from tribodem.dem.state import FIX_CLUMP, FIX_ROTATION, FIX_TRANSLATION, ParticleState

DEBRIS_SHAPES = ("spherical", "chunk", "rubbing")
MEMBER_FIX = FIX_TRANSLATION | FIX_ROTATION | FIX_CLUMP

# ------------------------------------------------------------------ union of spheres


def _exposed_arcs(centre_rel: np.ndarray, rad: np.ndarray, ri: float, ct: float, st: float
                  ) -> list[tuple[float, float]]:
    """Azimuth intervals of the latitude circle (cos theta = ct) of sphere i (radius ri)
    not covered by the other spheres (centres relative to sphere i, radii ``rad``)."""
    arcs: list[tuple[float, float]] = []
    for d, rj in zip(centre_rel, rad, strict=True):
        dd = float(d @ d)
        h = (ri * ri + dd - rj * rj) / (2.0 * ri)  # covered where n . d > h
        rho = math.hypot(d[0], d[1])
        amp = st * rho
        base = ct * d[2]
        if amp <= 1e-300 * max(1.0, abs(h)):
            if base > h:
                return []
            continue
        c = (h - base) / amp
        if c >= 1.0:
            continue
        if c <= -1.0:
            return []
        w = math.acos(c)
        p0 = math.atan2(d[1], d[0])
        arcs.append((p0 - w, p0 + w))
    # covered arcs -> [0, 2 pi) pieces, merged, complemented
    two_pi = 2.0 * math.pi
    pieces: list[tuple[float, float]] = []
    for a, b in arcs:
        a0 = a % two_pi
        b0 = a0 + (b - a)
        if b0 > two_pi:
            pieces.append((a0, two_pi))
            pieces.append((0.0, b0 - two_pi))
        else:
            pieces.append((a0, b0))
    pieces.sort()
    free: list[tuple[float, float]] = []
    cur = 0.0
    for a, b in pieces:
        if a > cur:
            free.append((cur, a))
        cur = max(cur, b)
    if cur < two_pi:
        free.append((cur, two_pi))
    return free


def union_properties(centres: np.ndarray, radii: np.ndarray, n_theta: int = 48,
                     n_phi: int = 24) -> tuple[float, np.ndarray, np.ndarray]:
    """Volume (m^3), centroid (m) and second-moment tensor ``int x x^T dV`` about the centroid
    (m^5) of the union of spheres.

    Divergence theorem over the exposed parts of the sphere surfaces:
    ``V = 1/3 oint x.n dS``, ``int x dV = 1/4 oint x (x.n) dS``,
    ``int x x^T dV = 1/5 oint x x^T (x.n) dS``. On each sphere the exposed azimuth arcs of
    a latitude are exact (circle-cap intersections); azimuth and polar angle are integrated
    by Gauss-Legendre, the polar angle piecewise between the caps' tangent latitudes with a
    cosine map that removes the square-root endpoint behaviour. Relative error ~1e-10.
    """
    c = np.asarray(centres, dtype=np.float64).reshape(-1, 3)
    r = np.asarray(radii, dtype=np.float64).reshape(-1)
    m = r.size
    ut, wt = np.polynomial.legendre.leggauss(n_theta)
    up, wp = np.polynomial.legendre.leggauss(n_phi)
    vol = 0.0
    s1 = np.zeros(3)
    s2 = np.zeros((3, 3))
    for i in range(m):
        others = [j for j in range(m) if j != i]
        rel = c[others] - c[i]
        rad = r[others]
        # break points in theta: the latitudes where the cap circles start / end
        brk = [0.0, math.pi]
        for d, rj in zip(rel, rad, strict=True):
            dist = float(np.linalg.norm(d))
            if dist + r[i] <= rj:  # sphere i inside j: no exposed surface
                brk = []
                break
            if dist == 0.0 or dist >= r[i] + rj or dist + rj <= r[i]:
                continue
            cos_a = (r[i] ** 2 + dist * dist - rj * rj) / (2.0 * r[i] * dist)
            alpha = math.acos(min(1.0, max(-1.0, cos_a)))
            th = math.acos(min(1.0, max(-1.0, d[2] / dist)))
            brk += [th - alpha, th + alpha]
        if not brk:
            continue
        bb = np.unique(np.clip(brk, 0.0, math.pi))
        for t0, t1 in zip(bb[:-1], bb[1:], strict=True):
            if t1 - t0 < 1e-15:
                continue
            # theta = t0 + (t1 - t0) (1 - cos(pi s)) / 2, s in [0, 1]
            s = 0.5 * (ut + 1.0)
            theta = t0 + (t1 - t0) * 0.5 * (1.0 - np.cos(np.pi * s))
            jac = (t1 - t0) * 0.5 * np.pi * np.sin(np.pi * s) * 0.5 * wt
            for th, wth in zip(theta, jac, strict=True):
                ct, st = math.cos(th), math.sin(th)
                for a, b in _exposed_arcs(rel, rad, float(r[i]), ct, st):
                    phi = a + (b - a) * 0.5 * (up + 1.0)
                    wph = (b - a) * 0.5 * wp
                    nrm = np.stack([st * np.cos(phi), st * np.sin(phi), np.full_like(phi, ct)],
                                   axis=1)
                    x = c[i] + r[i] * nrm
                    xn = (x * nrm).sum(axis=1)
                    w = wph * wth * r[i] ** 2 * st * xn
                    vol += w.sum() / 3.0
                    s1 += (x * w[:, None]).sum(axis=0) / 4.0
                    s2 += np.einsum("p,pk,pl->kl", w, x, x) / 5.0
    if not vol > 0:
        raise ValueError("union_properties: the union of the spheres has no volume")
    cen = s1 / vol
    second = s2 - vol * np.outer(cen, cen)
    return float(vol), cen, 0.5 * (second + second.T)


# ------------------------------------------------------------------ templates


@dataclass(frozen=True)
class ClumpTemplate:
    """A clump shape in its principal body frame (SI).

    ``offsets`` (m, [k, 3]) are the member centres relative to the body centre of mass along
    the principal axes; ``radii`` (m); ``volume`` (m^3) of the union of the members;
    ``inertia_per_density`` (m^5, [3]) the principal moments of inertia divided by density.
    """

    name: str
    offsets: np.ndarray
    radii: np.ndarray
    volume: float
    inertia_per_density: np.ndarray

    @property
    def members(self) -> int:
        """Number of member spheres."""
        return int(self.radii.size)

    @property
    def member_volume(self) -> float:
        """Sum of the member sphere volumes (m^3, counts overlaps twice)."""
        return float((4.0 / 3.0) * np.pi * (self.radii**3).sum())

    def scaled(self, factor: float) -> ClumpTemplate:
        """The same shape scaled by ``factor`` (lengths)."""
        return ClumpTemplate(self.name, self.offsets * factor, self.radii * factor,
                             self.volume * factor**3, self.inertia_per_density * factor**5)


def make_template(centres: np.ndarray, radii: np.ndarray, name: str = "clump") -> ClumpTemplate:
    """A template from arbitrary member centres and radii (m): centre of mass at the origin,
    members rotated onto the principal axes (ascending principal moments)."""
    c = np.asarray(centres, dtype=np.float64).reshape(-1, 3)
    r = np.asarray(radii, dtype=np.float64).reshape(-1)
    if c.shape[0] != r.size or r.size == 0:
        raise ValueError(f"clump template '{name}': {c.shape[0]} centres but {r.size} radii")
    if np.any(~(r > 0)):
        raise ValueError(f"clump template '{name}': radii must be > 0 m")
    vol, cen, second = union_properties(c, r)
    tensor = np.trace(second) * np.eye(3) - second  # inertia / density
    mom, axes = np.linalg.eigh(tensor)
    if np.linalg.det(axes) < 0:
        axes[:, 2] *= -1.0
    offsets = (c - cen) @ axes  # body frame: columns of axes are the principal directions
    offsets[np.abs(offsets) < 1e-15 * float(r.max())] = 0.0
    return ClumpTemplate(name, offsets, r.copy(), vol, mom)


# unit shapes (member radius 1); see debris_template for the choice
_UNIT_SHAPES: dict[str, tuple[np.ndarray, np.ndarray]] = {
    "spherical": (np.zeros((1, 3)), np.ones(1)),
    # regular tetrahedron of edge 1.5 r: a compact blocky lump, isotropic inertia
    "chunk": (1.5 / math.sqrt(8.0) * np.array([[1.0, 1.0, 1.0], [1.0, -1.0, -1.0],
                                                [-1.0, 1.0, -1.0], [-1.0, -1.0, 1.0]]),
              np.ones(4)),
    # three spheres in a row, spacing 1.1 r: a rod / flake of aspect ratio 2.1
    "rubbing": (np.array([[-1.1, 0.0, 0.0], [0.0, 0.0, 0.0], [1.1, 0.0, 0.0]]), np.ones(3)),
}


@cache
def _unit_template(shape: str) -> ClumpTemplate:
    c, r = _UNIT_SHAPES[shape]
    return make_template(c, r, shape)


def debris_template(shape: str, diameter: float) -> ClumpTemplate:
    """Debris clump of Lu (2018) figure 3.6 with the solid volume of a sphere of ``diameter``
    (m): union volume ``pi d^3 / 6`` (worn volume -> debris mass is conserved).

    Shapes (figure 3.6 gives pictures only; tribodem's choice): ``"spherical"`` one
    sphere; ``"chunk"`` four equal spheres on a regular tetrahedron of edge 1.5 r (compact,
    blocky, isotropic inertia); ``"rubbing"`` three equal spheres in a row, spacing 1.1 r
    (an elongated rod/flake, length 4.2 r, aspect ratio 2.1; neighbours overlap, the end
    spheres do not).
    """
    if shape not in DEBRIS_SHAPES:
        raise ValueError(f"debris_template: shape = {shape!r}: must be one of {DEBRIS_SHAPES}")
    if not diameter > 0:
        raise ValueError(f"debris_template: diameter = {diameter!r}: must be > 0 m")
    unit = _unit_template(shape)
    target = math.pi * diameter**3 / 6.0
    return unit.scaled((target / unit.volume) ** (1.0 / 3.0))


# ------------------------------------------------------------------ quaternions


def random_quaternions(n: int, rng: np.random.Generator) -> np.ndarray:
    """``n`` uniformly random unit quaternions (w, x, y, z) (Shoemake)."""
    u = rng.random((n, 3))
    a, b = np.sqrt(1.0 - u[:, 0]), np.sqrt(u[:, 0])
    t1, t2 = 2.0 * np.pi * u[:, 1], 2.0 * np.pi * u[:, 2]
    return np.stack([b * np.cos(t2), a * np.sin(t1), a * np.cos(t1), b * np.sin(t2)], axis=1)


def quat_to_matrix(q: np.ndarray) -> np.ndarray:
    """Rotation matrices (body -> world) of unit quaternions (w, x, y, z), [n, 3, 3]."""
    q = np.asarray(q, dtype=np.float64).reshape(-1, 4)
    w, x, y, z = q.T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
    ], axis=1)


@njit(cache=True, inline="always")
def _rot(w, x, y, z):
    """Rotation matrix (row-major 9-tuple, body -> world) of a unit quaternion."""
    return (1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
            2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
            2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y))


@njit(cache=True, inline="always")
def _free_rotate(w, x, y, z, p0, p1, p2, hi0, hi1, hi2, k):
    """Free rotation about body axis k (Cayley form): q <- q (x) (1, u e_k) (not normalised;
    the caller normalises once), pi <- rot_k(theta)^T pi with tan(theta/2) = u = phi/2,
    phi = pi_k h / I_k (``hi`` = h / I). An exact rotation (|pi| and the world momentum are
    kept to round-off), the exact flow of a slightly modified free-rotor Hamiltonian
    (theta = phi (1 - phi^2/12 + ...)); no trigonometry, one division."""
    if k == 0:
        u = 0.5 * p0 * hi0
    elif k == 1:
        u = 0.5 * p1 * hi1
    else:
        u = 0.5 * p2 * hi2
    den = 1.0 / (1.0 + u * u)
    c = (1.0 - u * u) * den  # cos theta
    s = 2.0 * u * den  # sin theta
    if k == 0:
        return (w - x * u, x + w * u, y + z * u, z - y * u,
                p0, c * p1 + s * p2, -s * p1 + c * p2)
    if k == 1:
        return (w - y * u, x - z * u, y + w * u, z + x * u,
                c * p0 - s * p2, p1, s * p0 + c * p2)
    return (w - z * u, x + y * u, y - x * u, z + w * u,
            c * p0 + s * p1, -s * p0 + c * p1, p2)


@njit(cache=True, inline="always")
def _wrap(x, lo, length, periodic):
    """x wrapped into [lo, lo + length) on a periodic axis (as ``advance`` does)."""
    if periodic:
        d = x - lo
        if d < 0.0 or d >= length:
            d -= length * np.floor(d / length)
            if d >= length:
                d -= length
            return lo + d
    return x


@kernel
def clump_advance(pos, vel, omega, force, torque, mstart, members, offsets, bmass, binv,
                  bpos, bvel, bquat, bangmom, bomega, gravity, a, b, local, dt, lo, length,
                  periodic):
    """Integrate every clump body one step and write its members (prange over bodies).

    ``force``/``torque`` (N, N m): member totals without gravity (from ``advance``);
    body gravity ``M g`` acts at the centre of mass; ``binv`` = 1 / principal inertia.
    ``a``, ``b``: the engine's viscous damping factors; ``local``: PFC local damping alpha.
    """
    nb = bpos.shape[0]
    for c in prange(nb):
        m00, m01, m02, m10, m11, m12, m20, m21, m22 = _rot(bquat[c, 0], bquat[c, 1],
                                                           bquat[c, 2], bquat[c, 3])
        f0 = bmass[c] * gravity[0]
        f1 = bmass[c] * gravity[1]
        f2 = bmass[c] * gravity[2]
        t0 = 0.0
        t1 = 0.0
        t2 = 0.0
        for s in range(mstart[c], mstart[c + 1]):
            i = members[s]
            o0, o1, o2 = offsets[s, 0], offsets[s, 1], offsets[s, 2]
            r0 = m00 * o0 + m01 * o1 + m02 * o2
            r1 = m10 * o0 + m11 * o1 + m12 * o2
            r2 = m20 * o0 + m21 * o1 + m22 * o2
            g0, g1, g2 = force[i, 0], force[i, 1], force[i, 2]
            f0 += g0
            f1 += g1
            f2 += g2
            t0 += torque[i, 0] + r1 * g2 - r2 * g1
            t1 += torque[i, 1] + r2 * g0 - r0 * g2
            t2 += torque[i, 2] + r0 * g1 - r1 * g0
        f0 = local_damped(f0, bvel[c, 0], local)
        f1 = local_damped(f1, bvel[c, 1], local)
        f2 = local_damped(f2, bvel[c, 2], local)
        t0 = local_damped(t0, bomega[c, 0], local)
        t1 = local_damped(t1, bomega[c, 1], local)
        t2 = local_damped(t2, bomega[c, 2], local)
        inv_m = b / bmass[c]
        bvel[c, 0] = a * bvel[c, 0] + f0 * inv_m
        bvel[c, 1] = a * bvel[c, 1] + f1 * inv_m
        bvel[c, 2] = a * bvel[c, 2] + f2 * inv_m
        for k in range(3):
            bpos[c, k] = _wrap(bpos[c, k] + bvel[c, k] * dt, lo[k], length[k], periodic[k])
        l0 = a * bangmom[c, 0] + b * t0
        l1 = a * bangmom[c, 1] + b * t1
        l2 = a * bangmom[c, 2] + b * t2
        bangmom[c, 0] = l0
        bangmom[c, 1] = l1
        bangmom[c, 2] = l2
        # body-frame momentum pi = R^T L; free-rotor splitting x(h/2) y(h/2) z(h) y(h/2) x(h/2)
        p0 = m00 * l0 + m10 * l1 + m20 * l2
        p1 = m01 * l0 + m11 * l1 + m21 * l2
        p2 = m02 * l0 + m12 * l1 + m22 * l2
        j0, j1, j2 = binv[c, 0], binv[c, 1], binv[c, 2]  # 1 / principal inertia
        w, x, y, z = bquat[c, 0], bquat[c, 1], bquat[c, 2], bquat[c, 3]
        h0 = 0.5 * dt * j0
        h1 = 0.5 * dt * j1
        w, x, y, z, p0, p1, p2 = _free_rotate(w, x, y, z, p0, p1, p2, h0, h1, 0.0, 0)
        w, x, y, z, p0, p1, p2 = _free_rotate(w, x, y, z, p0, p1, p2, h0, h1, 0.0, 1)
        w, x, y, z, p0, p1, p2 = _free_rotate(w, x, y, z, p0, p1, p2, 0.0, 0.0, dt * j2, 2)
        w, x, y, z, p0, p1, p2 = _free_rotate(w, x, y, z, p0, p1, p2, h0, h1, 0.0, 1)
        w, x, y, z, p0, p1, p2 = _free_rotate(w, x, y, z, p0, p1, p2, h0, h1, 0.0, 0)
        qn = 1.0 / np.sqrt(w * w + x * x + y * y + z * z)
        w *= qn
        x *= qn
        y *= qn
        z *= qn
        bquat[c, 0] = w
        bquat[c, 1] = x
        bquat[c, 2] = y
        bquat[c, 3] = z
        m00, m01, m02, m10, m11, m12, m20, m21, m22 = _rot(w, x, y, z)
        wb0 = p0 * j0
        wb1 = p1 * j1
        wb2 = p2 * j2
        w0 = m00 * wb0 + m01 * wb1 + m02 * wb2
        w1 = m10 * wb0 + m11 * wb1 + m12 * wb2
        w2 = m20 * wb0 + m21 * wb1 + m22 * wb2
        bomega[c, 0] = w0
        bomega[c, 1] = w1
        bomega[c, 2] = w2
        x0, x1, x2 = bpos[c, 0], bpos[c, 1], bpos[c, 2]
        v0, v1, v2 = bvel[c, 0], bvel[c, 1], bvel[c, 2]
        for s in range(mstart[c], mstart[c + 1]):
            i = members[s]
            o0, o1, o2 = offsets[s, 0], offsets[s, 1], offsets[s, 2]
            r0 = m00 * o0 + m01 * o1 + m02 * o2
            r1 = m10 * o0 + m11 * o1 + m12 * o2
            r2 = m20 * o0 + m21 * o1 + m22 * o2
            pos[i, 0] = _wrap(x0 + r0, lo[0], length[0], periodic[0])
            pos[i, 1] = _wrap(x1 + r1, lo[1], length[1], periodic[1])
            pos[i, 2] = _wrap(x2 + r2, lo[2], length[2], periodic[2])
            vel[i, 0] = v0 + w1 * r2 - w2 * r1
            vel[i, 1] = v1 + w2 * r0 - w0 * r2
            vel[i, 2] = v2 + w0 * r1 - w1 * r0
            omega[i, 0] = w0
            omega[i, 1] = w1
            omega[i, 2] = w2


@kernel
def member_drift(pos, radius, fixed, ref_pos, ref_radius, lo, length, periodic, drift):
    """Raise the per-block drift (m) of ``advance`` with the members' true new positions."""
    n = pos.shape[0]
    nblocks = (n + BLOCK - 1) // BLOCK
    for blk in prange(nblocks):
        dmax = drift[blk]
        for i in range(blk * BLOCK, min(n, (blk + 1) * BLOCK)):
            if not fixed[i] & FIX_CLUMP:
                continue
            dd = drift_of(pos, ref_pos, radius, ref_radius, i, length, periodic)
            if dd > dmax:
                dmax = dd
        drift[blk] = dmax


# ------------------------------------------------------------------ the bodies


class Clumps:
    """Rigid clump bodies over member particles (an engine ``Interaction``; SI units).

    Bodies ``c``: members ``members[mstart[c]:mstart[c+1]]`` (particle indices) at body-frame
    ``offsets`` (m); ``mass`` (kg); principal ``inertia`` (kg m^2, [nb, 3]); centre of mass
    ``pos`` (m), ``quat`` (w, x, y, z: body -> world), ``vel`` (m/s), angular momentum
    ``angmom`` (N m s, world) and ``omega`` (rad/s, world). ``kind`` is the template index
    of each body (informative). Add with ``sim.add_interaction(clumps)``.
    """

    def __init__(self, n_particles: int, mstart: np.ndarray, members: np.ndarray,
                 offsets: np.ndarray, mass: np.ndarray, inertia: np.ndarray, pos: np.ndarray,
                 quat: np.ndarray, vel: np.ndarray | None = None,
                 omega: np.ndarray | None = None, kind: np.ndarray | None = None) -> None:
        self.n_particles = int(n_particles)
        self.mstart = np.ascontiguousarray(mstart, dtype=np.int64)
        self.members = np.ascontiguousarray(members, dtype=np.int64)
        self.offsets = np.ascontiguousarray(offsets, dtype=np.float64).reshape(-1, 3)
        self.mass = np.ascontiguousarray(mass, dtype=np.float64).copy()
        self.inertia = np.ascontiguousarray(inertia, dtype=np.float64).reshape(-1, 3).copy()
        self._inv_inertia = 1.0 / self.inertia
        nb = self.mass.size
        self.pos = np.ascontiguousarray(pos, dtype=np.float64).reshape(nb, 3).copy()
        q = np.ascontiguousarray(quat, dtype=np.float64).reshape(nb, 4)
        self.quat = q / np.linalg.norm(q, axis=1, keepdims=True)
        self.vel = np.zeros((nb, 3)) if vel is None else \
            np.ascontiguousarray(vel, dtype=np.float64).reshape(nb, 3).copy()
        self.omega = np.zeros((nb, 3)) if omega is None else \
            np.ascontiguousarray(omega, dtype=np.float64).reshape(nb, 3).copy()
        self.kind = np.zeros(nb, dtype=np.int64) if kind is None else np.asarray(kind, np.int64)
        if self.mstart.shape != (nb + 1,) or self.mstart[-1] != self.members.size:
            raise ValueError("clumps: mstart must have one entry per body plus one, ending at "
                             "the number of members")
        if self.offsets.shape[0] != self.members.size:
            raise ValueError("clumps: one offset per member is needed")
        if np.any(~(self.mass > 0)) or np.any(~(self.inertia > 0)):
            raise ValueError("clumps: body mass and principal inertia must be > 0")
        if self.members.size and (self.members.min() < 0
                                  or self.members.max() >= self.n_particles):
            raise ValueError("clumps: a member index is out of range")
        self.body_of = np.full(self.n_particles, -1, dtype=np.int64)
        self.body_of[self.members] = np.repeat(np.arange(nb), np.diff(self.mstart))
        if np.count_nonzero(self.body_of >= 0) != self.members.size:
            raise ValueError("clumps: a particle is a member of two clumps")
        rm = quat_to_matrix(self.quat)
        self.angmom = np.einsum("bij,bj,bkj,bk->bi", rm, self.inertia, rm, self.omega)

    @property
    def n(self) -> int:
        """Number of bodies."""
        return int(self.mass.size)

    # --------------------------------------------------------------- engine hooks
    def compute(self, sim) -> None:  # noqa: ANN001 - Simulation (engine protocol)
        """No force of its own (members gather theirs in ``advance``); checks the setup once."""
        if getattr(self, "_checked", False):
            return
        if sim.p.dim != 3:
            raise ValueError("clumps: 3D only (dim = 3)")
        if sim.p.n != self.n_particles:
            raise ValueError(f"clumps: built for {self.n_particles} particles, the simulation "
                             f"has {sim.p.n}")
        bad = (sim.p.fixed[self.members] & MEMBER_FIX) != MEMBER_FIX
        if bad.any():
            i = int(self.members[np.flatnonzero(bad)[0]])
            raise ValueError(f"clumps: member particle {i} lacks the fixity bits "
                             "FIX_TRANSLATION | FIX_ROTATION | FIX_CLUMP")
        self._checked = True

    def filter_pairs(self, nl: NeighborList) -> NeighborList:
        """The neighbour list without pairs of members of the same clump."""
        if nl.start.size - 1 != self.n_particles:
            raise ValueError(f"clumps: built for {self.n_particles} particles, the neighbour "
                             f"list has {nl.start.size - 1}")
        bi = self.body_of[nl.pair_i]
        keep = (bi < 0) | (bi != self.body_of[nl.pair_j])
        if keep.all():
            return nl
        n = nl.start.size - 1
        pi = nl.pair_i[keep]
        pj = nl.pair_j[keep]
        start = np.zeros(n + 1, dtype=np.int64)
        np.cumsum(np.bincount(pi, minlength=n), out=start[1:])
        rs, rp = reverse_index(n, pj)
        return NeighborList(start, pi, pj, rs, rp, nl.ref_pos, nl.ref_radius, nl.skin,
                            nl.builds)

    def after_advance(self, sim) -> None:  # noqa: ANN001 - Simulation (engine protocol)
        """Integrate the bodies from the member forces of this step; move the members."""
        p = sim.p
        h = 0.5 * sim.viscous_damping * sim.dt
        a = (1.0 - h) / (1.0 + h)
        b = sim.dt / (1.0 + h)
        box = sim.box
        clump_advance.pick(self.members.size)(
            p.pos, p.vel, p.omega, sim.force, sim.torque, self.mstart, self.members,
            self.offsets, self.mass, self._inv_inertia, self.pos, self.vel, self.quat, self.angmom,
            self.omega, sim.gravity, a, b, sim.local_damping, sim.dt, box.lo, box.length,
            box.periodic)
        member_drift.pick(p.n)(p.pos, p.radius, p.fixed, sim.nl.ref_pos, sim.nl.ref_radius,
                               box.lo, box.length, box.periodic, sim.drift)

    # --------------------------------------------------------------- measurements
    def kinetic_energy(self) -> float:
        """Translational + rotational kinetic energy of the bodies (J, half-step values)."""
        return float(0.5 * (self.mass * (self.vel**2).sum(axis=1)).sum()
                     + 0.5 * (self.omega * self.angmom).sum())

    def member_positions(self) -> np.ndarray:
        """Unwrapped member centres from the body state (m), in member order."""
        nb = np.diff(self.mstart)
        rm = np.repeat(quat_to_matrix(self.quat), nb, axis=0)
        return np.repeat(self.pos, nb, axis=0) + np.einsum("mij,mj->mi", rm, self.offsets)

    def state(self) -> dict[str, np.ndarray]:
        """Body state for checkpoints."""
        return {"pos": self.pos.copy(), "vel": self.vel.copy(), "quat": self.quat.copy(),
                "angmom": self.angmom.copy(), "omega": self.omega.copy()}

    def set_state(self, s: dict[str, np.ndarray]) -> None:
        """Restore the body state saved by ``state``."""
        for k in ("pos", "vel", "quat", "angmom", "omega"):
            v = np.ascontiguousarray(s[k], dtype=np.float64)
            if v.shape != getattr(self, k).shape:
                raise ValueError(f"clumps: checkpoint '{k}' has shape {v.shape}, expected "
                                 f"{getattr(self, k).shape}")
            setattr(self, k, v.copy())


def make_clumps(templates: Sequence[ClumpTemplate], kind: np.ndarray, pos: np.ndarray,
                quat: np.ndarray | None = None, density: float = 7850.0, mat: int = 0,
                group: int = 0, vel: np.ndarray | None = None,
                omega: np.ndarray | None = None, base: ParticleState | None = None
                ) -> tuple[ParticleState, Clumps]:
    """Particles and bodies of N clumps (3D): clump ``c`` is ``templates[kind[c]]`` with its
    centre of mass at ``pos[c]`` (m), orientation ``quat[c]`` (w, x, y, z; default
    identity), velocity ``vel`` (m/s) and spin ``omega`` (rad/s, world).

    Body mass ``density V_union``; members (appended after the particles of ``base``, if
    given, contiguous per clump) get density ``density V_union / sum V_members``, ``mat``,
    ``group`` and the fixity ``FIX_TRANSLATION | FIX_ROTATION | FIX_CLUMP``. Vectorised:
    one pass per template.
    """
    kind = np.asarray(kind, dtype=np.int64).reshape(-1)
    nb = kind.size
    if nb and (kind.min() < 0 or kind.max() >= len(templates)):
        raise ValueError(f"make_clumps: kind must index the {len(templates)} templates")
    if base is not None and base.dim != 3:
        raise ValueError("make_clumps: clumps are 3D; base particles have dim 2")
    pos = np.asarray(pos, dtype=np.float64).reshape(nb, 3)
    quat = np.tile([1.0, 0.0, 0.0, 0.0], (nb, 1)) if quat is None else \
        np.asarray(quat, dtype=np.float64).reshape(nb, 4)
    quat = quat / np.linalg.norm(quat, axis=1, keepdims=True)
    vel = np.zeros((nb, 3)) if vel is None else np.asarray(vel, dtype=np.float64).reshape(nb, 3)
    omega = np.zeros((nb, 3)) if omega is None else \
        np.asarray(omega, dtype=np.float64).reshape(nb, 3)
    counts = np.array([t.members for t in templates], dtype=np.int64)[kind]
    n0 = 0 if base is None else base.n
    mstart = np.zeros(nb + 1, dtype=np.int64)
    np.cumsum(counts, out=mstart[1:])
    m = int(mstart[-1])
    mpos = np.zeros((m, 3))
    mvel = np.zeros((m, 3))
    mrad = np.zeros(m)
    mrho = np.zeros(m)
    offsets = np.zeros((m, 3))
    bmass = np.zeros(nb)
    binert = np.zeros((nb, 3))
    rm = quat_to_matrix(quat)
    for t_id, t in enumerate(templates):
        sel = np.flatnonzero(kind == t_id)
        if sel.size == 0:
            continue
        k = t.members
        slot = (mstart[sel][:, None] + np.arange(k)[None, :]).reshape(-1)
        world = np.einsum("cij,kj->cki", rm[sel], t.offsets)  # [c, k, 3]
        offsets[slot] = np.tile(t.offsets, (sel.size, 1))
        mpos[slot] = (pos[sel][:, None, :] + world).reshape(-1, 3)
        mvel[slot] = (vel[sel][:, None, :] + np.cross(omega[sel][:, None, :], world)
                      ).reshape(-1, 3)
        mrad[slot] = np.tile(t.radii, sel.size)
        mrho[slot] = density * t.volume / t.member_volume
        bmass[sel] = density * t.volume
        binert[sel] = density * t.inertia_per_density
    momega = np.repeat(omega, counts, axis=0)
    fixed = np.full(m, MEMBER_FIX, dtype=np.uint8)
    if base is None:
        p = ParticleState(dim=3, pos=mpos, radius=mrad, density=mrho, vel=mvel, omega=momega,
                          mat=np.full(m, mat), group=np.full(m, group), fixed=fixed)
    else:
        b = base.arrays()
        p = ParticleState(dim=3, pos=np.vstack([b["pos"], mpos]),
                          radius=np.concatenate([b["radius"], mrad]),
                          density=np.concatenate([b["density"], mrho]),
                          vel=np.vstack([b["vel"], mvel]),
                          omega=np.vstack([b["omega"], momega]),
                          mat=np.concatenate([b["mat"], np.full(m, mat, dtype=np.int32)]),
                          group=np.concatenate([b["group"], np.full(m, group, dtype=np.int32)]),
                          fixed=np.concatenate([b["fixed"], fixed]))
    clumps = Clumps(n0 + m, mstart, np.arange(n0, n0 + m), offsets, bmass, binert, pos, quat,
                    vel, omega, kind)
    return p, clumps
