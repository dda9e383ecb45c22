"""Plane walls: fixed, velocity-controlled and servo (force-controlled) walls.

A wall is an infinite plane through ``point`` with unit ``normal`` pointing to the
particle side; it contacts particle i when the distance d < r_i (overlap r_i - d),
through the same contact laws as particles (wall radius and mass infinite).

Servo modes (the wall moves along its normal, i.e. towards the particles):
- ``"servo"`` (PFC): ``v = G (F_target - F_int)``, ``G = alpha / (sum kn dt)``,
  alpha = 0.25 (the Hertz dashpot stiffens the wall response; PFC's usual 0.5 rang);
- ``"boundary"`` (Lu (2018) eqs 3.2-3.6, boundary-moving method):
  ``a = (F_target - F_int - C v) / M``, ``v += a dt``, ``d = v dt``.
F_int is the normal force the particles press on the wall (N, compressive +).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numba import njit, prange

from tribodem.dem.contact import P_LAW, contact_response, response
from tribodem.dem.jit import kernel

WALL_MODES = ("fixed", "velocity", "servo", "boundary")


@dataclass
class PlaneWall:
    """A plane wall (SI). ``target_force`` (N) is used by the servo modes.

    ``servo_mass`` (kg) and ``servo_damping`` (N s/m) are M and C_c of Lu (2018) eq 3.6;
    ``servo_gain_alpha`` is the PFC gain factor; ``max_speed`` caps servo speed (m/s).
    """

    point: np.ndarray
    normal: np.ndarray
    material: int = 0
    mode: str = "fixed"
    velocity: np.ndarray = field(default_factory=lambda: np.zeros(3))
    target_force: float = 0.0
    servo_mass: float = 1.0
    servo_damping: float = 0.0
    servo_gain_alpha: float = 0.25
    max_speed: float = np.inf
    name: str = "wall"
    # state
    force: np.ndarray = field(default_factory=lambda: np.zeros(3))
    normal_force: float = 0.0
    stiffness: float = 0.0
    contacts: int = 0

    def __post_init__(self) -> None:
        self.point = np.asarray(self.point, dtype=np.float64).reshape(3).copy()
        nrm = np.asarray(self.normal, dtype=np.float64).reshape(3)
        ln = float(np.linalg.norm(nrm))
        if not ln > 0:
            raise ValueError(f"wall '{self.name}': normal = {nrm.tolist()}: must be non-zero")
        self.normal = nrm / ln
        self.velocity = np.asarray(self.velocity, dtype=np.float64).reshape(3).copy()
        self.force = np.asarray(self.force, dtype=np.float64).reshape(3).copy()
        if self.mode not in WALL_MODES:
            raise ValueError(f"wall '{self.name}': mode = {self.mode!r}: must be one of "
                             f"{WALL_MODES}")
        if self.mode == "boundary" and not self.servo_mass > 0:
            raise ValueError(f"wall '{self.name}': servo_mass = {self.servo_mass!r}: must be "
                             "> 0 kg")

    def update_motion(self, dt: float) -> None:
        """Advance the wall one step: servo velocity from the measured force, then move."""
        if self.mode == "servo":
            err = self.target_force - self.normal_force
            if self.stiffness > 0:
                speed = self.servo_gain_alpha * err / (self.stiffness * dt)
            else:  # no contact yet: approach at the cap (or a nominal pace)
                speed = self.max_speed if np.isfinite(self.max_speed) else 0.0
            speed = min(max(float(speed), -self.max_speed), self.max_speed)  # np.clip, 50x faster
            self.velocity = speed * self.normal
        elif self.mode == "boundary":
            # speed towards the particles (the dot product written out, as the compiled
            # loop does: engine._move_walls)
            (v0, v1, v2), (n0, n1, n2) = self.velocity.tolist(), self.normal.tolist()
            v = v0 * n0 + v1 * n1 + v2 * n2
            a = (self.target_force - self.normal_force - self.servo_damping * v) / self.servo_mass
            v = min(max(v + a * dt, -self.max_speed), self.max_speed)
            self.velocity = v * self.normal
        self.point = self.point + self.velocity * dt

    def state(self) -> dict[str, np.ndarray]:
        """Mutable state for checkpoints."""
        return {"point": self.point.copy(), "velocity": self.velocity.copy(),
                "force": self.force.copy(),
                "scalars": np.array([self.normal_force, self.stiffness, self.contacts])}

    def set_state(self, s: dict[str, np.ndarray]) -> None:
        """Restore the state saved by ``state``."""
        self.point = s["point"].copy()
        self.velocity = s["velocity"].copy()
        self.force = s["force"].copy()
        self.normal_force, self.stiffness, c = (float(x) for x in s["scalars"])
        self.contacts = int(c)


class RigidSurface(PlaneWall):
    """A rigid body surface acting as an ``Interaction`` (height map, triangle mesh): a
    :class:`PlaneWall` for its motion (``point`` = rigid displacement, ``normal`` = servo
    direction towards the particles) plus per-particle contact state -- shear history
    ``_hist``, ``_touch`` = (overlap m, normal force N, kn N/m) and ``particle_force`` (N,
    on the surface) -- kept in checkpoints."""

    def _contact_arrays(self, n: int) -> bool:
        """(Re)allocate the per-particle arrays for ``n`` particles; True if they were."""
        if getattr(self, "_hist", None) is not None and self._hist.shape[0] == n:
            return False
        self._hist = np.zeros((n, 3))
        self._touch = np.zeros((n, 3))
        self.particle_force = np.zeros((n, 3))
        return True

    def state(self) -> dict[str, np.ndarray]:
        """Mutable state for checkpoints (motion and contact history)."""
        s = super().state()
        s["hist"] = self._hist.copy()
        s["touch"] = self._touch.copy()
        return s

    def set_state(self, s: dict[str, np.ndarray]) -> None:
        """Restore the state saved by ``state``."""
        super().set_state(s)
        self._hist = s["hist"].copy()
        self._touch = s["touch"].copy()
        self.particle_force = np.zeros_like(self._hist)


@njit(cache=True, inline="always")
def wall_contact(x0, x1, x2, v0, v1, v2, w0, w1, w2, r, m, inertia, mat_i, point, normal, wvel,
                 wmat, hist, pairtab, elin, dim, thickness, dt):
    """Contact of one particle with one plane wall.

    Returns (touching, force on the wall (3, N), torque on the particle (3, N m),
    overlap m, normal force N, energy J, kn N/m); the particle gets minus the force.
    ``hist`` (shear spring of this particle on this wall) is updated in place.
    """
    d = (x0 - point[0]) * normal[0] + (x1 - point[1]) * normal[1] + (x2 - point[2]) * normal[2]
    delta = r - d
    if delta <= 0.0:
        hist[0] = 0.0
        hist[1] = 0.0
        hist[2] = 0.0
        return False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, delta, 0.0, 0.0, 0.0
    # unit normal from the particle (body 1) to the wall (body 2); contact point on the plane
    n0 = -normal[0]
    n1 = -normal[1]
    n2 = -normal[2]
    arm = d
    u0 = wvel[0] - (v0 + arm * (w1 * n2 - w2 * n1))
    u1 = wvel[1] - (v1 + arm * (w2 * n0 - w0 * n2))
    u2 = wvel[2] - (v2 + arm * (w0 * n1 - w1 * n0))
    area = 2.0 * r * thickness if dim == 2 else np.pi * r * r
    # PFC ball-facet: L = r; modulus = harmonic mean of particle and wall moduli
    lin_k = area * 2.0 / (1.0 / elin[mat_i] + 1.0 / elin[wmat]) / r
    prop = pairtab[mat_i, wmat]
    f0, f1, f2, r0, r1, r2, fn, energy, kn = contact_response(
        int(prop[P_LAW]), prop, n0, n1, n2, delta, u0, u1, u2, w0, w1, w2, r, m, inertia,
        lin_k, hist, dt)
    t0 = -arm * (n1 * f2 - n2 * f1) + r0
    t1 = -arm * (n2 * f0 - n0 * f2) + r1
    t2 = -arm * (n0 * f1 - n1 * f0) + r2
    return True, f0, f1, f2, t0, t1, t2, delta, fn, energy, kn


@njit(cache=True, inline="always")
def rigid_surface_contact(i, pos, vel, omega, r, mass, inertia, mat, point, nrm, svel, smat,
                          hist, pairtab, elin, dt, touching, ext_force, ext_torque, fout):
    """Contact of particle i (3D) with a rigid surface through its local tangent plane
    (``point``, unit ``nrm`` towards the particle): the wall law (``wall_contact``); adds
    the particle's force/torque into ``ext_force``/``ext_torque``, writes the force on the
    surface ``fout[i]`` and ``touching[i]`` = (overlap m, normal force N, kn N/m).
    Returns (touching, force on the surface (3, N))."""
    hit, f0, f1, f2, t0, t1, t2, delta, fn, energy, kn = wall_contact(
        pos[i, 0], pos[i, 1], pos[i, 2], vel[i, 0], vel[i, 1], vel[i, 2], omega[i, 0],
        omega[i, 1], omega[i, 2], r, mass[i], inertia[i], mat[i], point, nrm, svel, smat,
        hist[i], pairtab, elin, 3, 1.0, dt)
    touching[i, 0] = delta
    touching[i, 1] = fn
    touching[i, 2] = kn
    if hit:
        ext_force[i, 0] -= f0
        ext_force[i, 1] -= f1
        ext_force[i, 2] -= f2
        ext_torque[i, 0] += t0
        ext_torque[i, 1] += t1
        ext_torque[i, 2] += t2
        fout[i, 0] = f0
        fout[i, 1] = f1
        fout[i, 2] = f2
    return hit, f0, f1, f2


def wall_arrays(walls: list[PlaneWall]) -> tuple[np.ndarray, ...]:
    """Point, normal, velocity (nw, 3) and material (nw,) arrays of the walls for kernels."""
    nw = len(walls)
    if nw == 0:
        z = np.zeros((0, 3))
        return z, z.copy(), z.copy(), np.zeros(0, dtype=np.int64)
    return (np.array([w.point for w in walls]), np.array([w.normal for w in walls]),
            np.array([w.velocity for w in walls]),
            np.array([w.material for w in walls], dtype=np.int64))


@njit(cache=True)
def needs_rebuild(drift, wpoint, wnormal, wpoint0, wnormal0, half_skin):
    """Must the neighbour and near-wall lists be rebuilt? True if a particle block drifted
    more than ``half_skin`` (m; ``drift`` per block from ``advance``), or a wall moved more
    than ``half_skin`` along its normal or turned since the build (points/normals then:
    ``wpoint0``/``wnormal0``). One compiled call instead of a few numpy reductions."""
    for b in range(drift.shape[0]):
        if drift[b] > half_skin:
            return True
    for w in range(wpoint.shape[0]):
        moved = 0.0
        for k in range(3):
            if wnormal[w, k] != wnormal0[w, k]:
                return True
            moved += (wpoint[w, k] - wpoint0[w, k]) * wnormal[w, k]
        if abs(moved) > half_skin:
            return True
    return False


# ---------------------------------------------------------------------------- the wall pass
# Plane walls are their own force pass over a near-wall list built with the neighbour list:
# (particle, wall) candidates whose gap was below the skin at the build. Between builds every
# particle moves less than skin/2 (the neighbour list's trigger) and every wall less than
# skin/2 along its normal (``Simulation._maybe_rebuild``), so no contact is missed.


@njit(cache=True)
def near_walls(pos, radius, wpoint, wnormal, reach, block):
    """Near-wall candidates: the walls within ``reach`` (m, gap = distance - radius) of each
    particle, in wall order (``wid[wstart[i]:wstart[i+1]]``), the particles that have any
    (``wpart``, increasing) and, per block of ``block`` particles, their range in ``wpart``
    (``wpart[bstart[b]:bstart[b+1]]``)."""
    n = pos.shape[0]
    nw = wpoint.shape[0]
    wstart = np.zeros(n + 1, dtype=np.int64)
    npart = 0
    for i in range(n):
        c = 0
        for w in range(nw):
            gap = ((pos[i, 0] - wpoint[w, 0]) * wnormal[w, 0]
                   + (pos[i, 1] - wpoint[w, 1]) * wnormal[w, 1]
                   + (pos[i, 2] - wpoint[w, 2]) * wnormal[w, 2]) - radius[i]
            if gap < reach:
                c += 1
        wstart[i + 1] = wstart[i] + c
        if c:
            npart += 1
    wid = np.empty(wstart[n], dtype=np.int64)
    wpart = np.empty(npart, dtype=np.int64)
    nblocks = (n + block - 1) // block
    bstart = np.zeros(nblocks + 1, dtype=np.int64)
    k = 0
    for i in range(n):
        q = wstart[i]
        for w in range(nw):
            gap = ((pos[i, 0] - wpoint[w, 0]) * wnormal[w, 0]
                   + (pos[i, 1] - wpoint[w, 1]) * wnormal[w, 1]
                   + (pos[i, 2] - wpoint[w, 2]) * wnormal[w, 2]) - radius[i]
            if gap < reach:
                wid[q] = w
                q += 1
        if wstart[i + 1] > wstart[i]:
            wpart[k] = i
            k += 1
            bstart[i // block + 1] = k
    for b in range(nblocks):  # blocks without candidates
        if bstart[b + 1] < bstart[b]:
            bstart[b + 1] = bstart[b]
    return wstart, wid, wpart, bstart


@kernel(chunk=2)
def wall_forces(pos, vel, omega, radius, mass, inertia, mat, wstart, wid, wpart, bstart, wpoint,
                wnormal, wvel, wmat, whist, winfo, wsum, pairtab, elin, dim, thickness, dt,
                wforce, wtorque, wtot):
    """Contacts of the near-wall candidates (``near_walls``): per candidate particle, the
    sum over its walls (in wall order) of the force (N) and torque (N m) on it ->
    ``wforce``/``wtorque`` (other rows are not touched: zero); per-block wall sums
    ``wsum[block, wall] = (Fx, Fy, Fz, touching, sum kn)`` (the blocks of ``bstart``,
    summed in particle order: the same on any number of threads) and their sum over the
    blocks in block order, ``wtot[wall]`` (after the threaded loop); ``winfo[w, i]`` =
    (overlap m, normal force N, energy J, kn N/m) and the shear history ``whist[w, i]``
    updated. The contact is ``wall_contact`` written out with scalars (no array views
    but the history and the property row, so nothing is reference counted per contact)."""
    nw = wpoint.shape[0]
    nblocks = bstart.shape[0] - 1
    for blk in prange(nblocks):
        for w in range(nw):
            for k in range(5):
                wsum[blk, w, k] = 0.0
        for c in range(bstart[blk], bstart[blk + 1]):
            i = wpart[c]
            x0 = pos[i, 0]
            x1 = pos[i, 1]
            x2 = pos[i, 2]
            r = radius[i]
            f0s = f1s = f2s = t0s = t1s = t2s = 0.0
            for q in range(wstart[i], wstart[i + 1]):
                w = wid[q]
                nx = wnormal[w, 0]
                ny = wnormal[w, 1]
                nz = wnormal[w, 2]
                d = (x0 - wpoint[w, 0]) * nx + (x1 - wpoint[w, 1]) * ny + (x2 - wpoint[w, 2]) * nz
                delta = r - d
                if delta <= 0.0:
                    if winfo[w, i, 0] > 0.0:  # apart now, touching before: clear once
                        for k in range(3):
                            whist[w, i, k] = 0.0
                        winfo[w, i, 1] = 0.0
                        winfo[w, i, 2] = 0.0
                        winfo[w, i, 3] = 0.0
                    winfo[w, i, 0] = delta
                    continue
                # unit normal from the particle (body 1) to the wall (body 2)
                n0 = -nx
                n1 = -ny
                n2 = -nz
                w0 = omega[i, 0]
                w1 = omega[i, 1]
                w2 = omega[i, 2]
                arm = d
                u0 = wvel[w, 0] - (vel[i, 0] + arm * (w1 * n2 - w2 * n1))
                u1 = wvel[w, 1] - (vel[i, 1] + arm * (w2 * n0 - w0 * n2))
                u2 = wvel[w, 2] - (vel[i, 2] + arm * (w0 * n1 - w1 * n0))
                area = 2.0 * r * thickness if dim == 2 else np.pi * r * r
                # PFC ball-facet: L = r; modulus = harmonic mean of particle and wall moduli
                lin_k = area * 2.0 / (1.0 / elin[mat[i]] + 1.0 / elin[wmat[w]]) / r
                prop = pairtab[mat[i], wmat[w]]
                f0, f1, f2, r0, r1, r2, fn, energy, kn, h0, h1, h2 = response(
                    int(prop[P_LAW]), prop, n0, n1, n2, delta, u0, u1, u2, w0, w1, w2, r,
                    mass[i], inertia[i], lin_k, whist[w, i, 0], whist[w, i, 1],
                    whist[w, i, 2], dt)
                whist[w, i, 0] = h0
                whist[w, i, 1] = h1
                whist[w, i, 2] = h2
                winfo[w, i, 0] = delta
                winfo[w, i, 1] = fn
                winfo[w, i, 2] = energy
                winfo[w, i, 3] = kn
                f0s -= f0
                f1s -= f1
                f2s -= f2
                t0s += -arm * (n1 * f2 - n2 * f1) + r0
                t1s += -arm * (n2 * f0 - n0 * f2) + r1
                t2s += -arm * (n0 * f1 - n1 * f0) + r2
                wsum[blk, w, 0] += f0
                wsum[blk, w, 1] += f1
                wsum[blk, w, 2] += f2
                wsum[blk, w, 3] += 1.0
                wsum[blk, w, 4] += kn
            wforce[i, 0] = f0s
            wforce[i, 1] = f1s
            wforce[i, 2] = f2s
            wtorque[i, 0] = t0s
            wtorque[i, 1] = t1s
            wtorque[i, 2] = t2s
    for w in range(nw):  # serial, in block order
        for k in range(5):
            acc = 0.0
            for blk in range(nblocks):
                acc += wsum[blk, w, k]
            wtot[w, k] = acc
