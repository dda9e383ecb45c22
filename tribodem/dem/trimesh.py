"""Rigid triangle-mesh surfaces (first bodies from STL, Lu (2018) section 3.2.6), with
prescribed or servo (force-controlled) motion.

A :class:`TriangleSurface` is a rigid set of triangles (``(n, 3, 3)``, m, in its own frame)
displaced by ``point`` (m, a rigid translation). The particle side is the one the triangle
normals point to (right-hand rule of the vertex order; ``flip=True`` reverses it).

Contact, one per particle per surface: the closest point of every triangle near the
particle (face, edge or vertex region, Ericson's "closest point on triangle") and the
deepest of them is kept. Face region: overlap ``r - (x - a) . n`` along the face normal
(also for a centre pushed behind the face); edge/vertex region: overlap ``r - |x - c|``
along ``x - c`` (a sphere on a ridge or a corner), ignored from behind the face. On a flat
or gently curved mesh a sphere over a shared edge or vertex therefore gets exactly one
contact, the plane's; in a concave crease sharper than the sphere only the deeper face
acts. The contact law is the one of walls (``walls.wall_contact``: Hertz-Mindlin or linear,
Coulomb friction, rolling resistance) with a shear history per particle.

Broad phase: the triangles' bounding boxes, grown by ``reach`` (>= the largest particle
radius), are binned on a uniform grid in the surface frame; a particle looks only at the
triangles of its own cell (a touching triangle is within r of its centre, so it is there).
The grid is rebuilt when a particle radius exceeds ``reach``. Periodic images of the mesh
are not searched: give the mesh the extent the particles can reach.

Motion reuses :class:`tribodem.dem.walls.PlaneWall`'s modes (``"fixed"``, ``"velocity"``,
``"servo"``, ``"boundary"`` = Lu (2018) eqs 3.2-3.6, along ``normal``, the direction towards
the particles); or ``path(t) -> displacement (m)`` prescribes the displacement exactly.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numba import njit, prange

from tribodem.dem import laws
from tribodem.dem.integrate import BLOCK
from tribodem.dem.jit import kernel
from tribodem.dem.walls import RigidSurface, rigid_surface_contact

FACE, EDGE, VERTEX = 0, 1, 2


@njit(cache=True, inline="always")
def closest_point_on_triangle(px, py, pz, t):
    """Closest point of triangle ``t`` (3, 3) to p and its region (0 face, 1 edge, 2 vertex)
    (Ericson, Real-Time Collision Detection, 5.1.5)."""
    ax, ay, az = t[0, 0], t[0, 1], t[0, 2]
    bx, by, bz = t[1, 0], t[1, 1], t[1, 2]
    cx, cy, cz = t[2, 0], t[2, 1], t[2, 2]
    abx, aby, abz = bx - ax, by - ay, bz - az
    acx, acy, acz = cx - ax, cy - ay, cz - az
    apx, apy, apz = px - ax, py - ay, pz - az
    d1 = abx * apx + aby * apy + abz * apz
    d2 = acx * apx + acy * apy + acz * apz
    if d1 <= 0.0 and d2 <= 0.0:
        return ax, ay, az, VERTEX
    bpx, bpy, bpz = px - bx, py - by, pz - bz
    d3 = abx * bpx + aby * bpy + abz * bpz
    d4 = acx * bpx + acy * bpy + acz * bpz
    if d3 >= 0.0 and d4 <= d3:
        return bx, by, bz, VERTEX
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        v = d1 / (d1 - d3)
        return ax + v * abx, ay + v * aby, az + v * abz, EDGE
    cpx, cpy, cpz = px - cx, py - cy, pz - cz
    d5 = abx * cpx + aby * cpy + abz * cpz
    d6 = acx * cpx + acy * cpy + acz * cpz
    if d6 >= 0.0 and d5 <= d6:
        return cx, cy, cz, VERTEX
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        w = d2 / (d2 - d6)
        return ax + w * acx, ay + w * acy, az + w * acz, EDGE
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0:
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        return bx + w * (cx - bx), by + w * (cy - by), bz + w * (cz - bz), EDGE
    den = 1.0 / (va + vb + vc)
    v = vb * den
    w = vc * den
    return (ax + abx * v + acx * w, ay + aby * v + acy * w, az + abz * v + acz * w, FACE)


@njit(cache=True)
def bin_triangles(tri, reach, cell_target, max_cells):
    """Uniform grid over the triangles' boxes grown by ``reach``: (lo (3,), cell size (3,),
    cells per axis (3,), CSR start, triangle ids)."""
    nt = tri.shape[0]
    lo = np.full(3, np.inf)
    hi = np.full(3, -np.inf)
    for t in range(nt):
        for v in range(3):
            for k in range(3):
                x = tri[t, v, k]
                if x < lo[k]:
                    lo[k] = x
                if x > hi[k]:
                    hi[k] = x
    h = cell_target
    ncell = np.ones(3, dtype=np.int64)
    size = np.ones(3)
    while True:
        tot = 1
        for k in range(3):
            lo_k = lo[k] - reach
            ext = hi[k] + reach - lo_k
            nc = int(ext / h)
            if nc < 1:
                nc = 1
            ncell[k] = nc
            size[k] = ext / nc
            tot *= nc
        if tot <= max_cells:
            break
        h *= 1.5
    for k in range(3):
        lo[k] -= reach
    ntot = ncell[0] * ncell[1] * ncell[2]
    cstart = np.zeros(ntot + 1, dtype=np.int64)
    rng = np.empty((nt, 6), dtype=np.int64)
    for t in range(nt):
        for k in range(3):
            mn = min(tri[t, 0, k], tri[t, 1, k], tri[t, 2, k]) - reach
            mx = max(tri[t, 0, k], tri[t, 1, k], tri[t, 2, k]) + reach
            a = int(np.floor((mn - lo[k]) / size[k]))
            b = int(np.floor((mx - lo[k]) / size[k]))
            rng[t, 2 * k] = max(a, 0)
            rng[t, 2 * k + 1] = min(b, ncell[k] - 1)
        for z in range(rng[t, 4], rng[t, 5] + 1):
            for y in range(rng[t, 2], rng[t, 3] + 1):
                for x in range(rng[t, 0], rng[t, 1] + 1):
                    cstart[x + ncell[0] * (y + ncell[1] * z) + 1] += 1
    for c in range(ntot):
        cstart[c + 1] += cstart[c]
    items = np.empty(cstart[ntot], dtype=np.int64)
    fill = cstart[:-1].copy()
    for t in range(nt):
        for z in range(rng[t, 4], rng[t, 5] + 1):
            for y in range(rng[t, 2], rng[t, 3] + 1):
                for x in range(rng[t, 0], rng[t, 1] + 1):
                    c = x + ncell[0] * (y + ncell[1] * z)
                    items[fill[c]] = t
                    fill[c] += 1
    return lo, size, ncell, cstart, items


@kernel(chunk=2)
def trimesh_contacts(pos, vel, omega, radius, mass, inertia, mat, tri, tnorm, off, glo, ginv,
                     ncell, cstart, items, svel, smat, hist, touching, pairtab, elin, dt,
                     ext_force, ext_torque, fout, bsum):
    """Contacts of every particle with one triangle surface (3D).

    Adds the particle forces/torques into ``ext_force``/``ext_torque``; keeps per particle
    the force on the surface ``fout[i]`` (N) and ``touching[i]`` = (overlap m, normal force
    N, kn N/m), zero when apart; ``hist[i]`` is the shear spring (m). Rows of particles
    that stay apart are not written (cleared once when a contact ends). Per block of
    ``BLOCK`` particles ``bsum[blk] = (Fx, Fy, Fz, contacts, sum kn)``, summed in order:
    the totals do not depend on the thread count.
    """
    n = pos.shape[0]
    nblocks = (n + BLOCK - 1) // BLOCK
    for blk in prange(nblocks):
        for k in range(5):
            bsum[blk, k] = 0.0
        for i in range(blk * BLOCK, min(n, (blk + 1) * BLOCK)):
            px = pos[i, 0] - off[0]
            py = pos[i, 1] - off[1]
            pz = pos[i, 2] - off[2]
            r = radius[i]
            best = 0.0
            found = False
            bx = 0.0
            by = 0.0
            bz = 0.0
            n0 = 0.0
            n1 = 0.0
            n2 = 0.0
            ix = int(np.floor((px - glo[0]) * ginv[0]))
            iy = int(np.floor((py - glo[1]) * ginv[1]))
            iz = int(np.floor((pz - glo[2]) * ginv[2]))
            if 0 <= ix < ncell[0] and 0 <= iy < ncell[1] and 0 <= iz < ncell[2]:
                c = ix + ncell[0] * (iy + ncell[1] * iz)
                for q in range(cstart[c], cstart[c + 1]):
                    t = items[q]
                    cx, cy, cz, region = closest_point_on_triangle(px, py, pz, tri[t])
                    tn0, tn1, tn2 = tnorm[t, 0], tnorm[t, 1], tnorm[t, 2]
                    if region == FACE:
                        ds = (px - cx) * tn0 + (py - cy) * tn1 + (pz - cz) * tn2
                        if ds <= -r:
                            continue
                        ov = r - ds
                        m0, m1, m2 = tn0, tn1, tn2
                    else:
                        v0 = px - cx
                        v1 = py - cy
                        v2 = pz - cz
                        if v0 * tn0 + v1 * tn1 + v2 * tn2 < 0.0:
                            continue
                        dist = np.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
                        if dist == 0.0:
                            continue
                        ov = r - dist
                        m0, m1, m2 = v0 / dist, v1 / dist, v2 / dist
                    if ov > best:
                        best = ov
                        found = True
                        bx, by, bz = cx, cy, cz
                        n0, n1, n2 = m0, m1, m2
            if not found:
                if touching[i, 0] != 0.0:  # the contact just ended: clear it once
                    for k in range(3):
                        hist[i, k] = 0.0
                        touching[i, k] = 0.0
                        fout[i, k] = 0.0
                continue
            point = (bx + off[0], by + off[1], bz + off[2])
            nrm = (n0, n1, n2)
            hit, f0, f1, f2 = rigid_surface_contact(
                i, pos, vel, omega, r, mass, inertia, mat, point, nrm, svel, smat, hist,
                pairtab, elin, dt, touching, ext_force, ext_torque, fout)
            if hit:
                bsum[blk, 0] += f0
                bsum[blk, 1] += f1
                bsum[blk, 2] += f2
                bsum[blk, 3] += 1.0
                bsum[blk, 4] += touching[i, 2]
            else:
                fout[i, 0] = 0.0
                fout[i, 1] = 0.0
                fout[i, 2] = 0.0


@dataclass
class TriangleSurface(RigidSurface):
    """A rigid triangle-mesh surface (an ``Interaction``; add with ``sim.add_interaction``).

    ``triangles`` (m, ``(n, 3, 3)``) in the surface frame, e.g. from
    :func:`tribodem.io.stl.read_stl`; ``point`` (m) is its rigid displacement; ``normal`` is
    the servo direction towards the particles (default +z). Motion modes, servo parameters
    and ``target_force`` (N) are those of :class:`PlaneWall`; ``path(t)`` (s -> m), if set,
    prescribes the displacement instead. After each step: ``force`` (N, on the surface),
    ``normal_force`` (N, along -normal, compressive +), ``contacts``, ``stiffness`` (sum kn,
    N/m) and per particle ``particle_force`` (N, on the surface, [n, 3]).
    """

    point: np.ndarray = field(default_factory=lambda: np.zeros(3))
    normal: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    triangles: np.ndarray = field(default_factory=lambda: np.zeros((0, 3, 3)))
    flip: bool = False
    reach: float | None = None
    path: Callable[[float], np.ndarray] | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        t = np.ascontiguousarray(self.triangles, dtype=np.float64)
        if t.ndim != 3 or t.shape[1:] != (3, 3) or t.shape[0] == 0:
            raise ValueError(f"surface '{self.name}': triangles have shape {t.shape}: "
                             "expected (n, 3, 3) with n >= 1")
        if not np.all(np.isfinite(t)):
            raise ValueError(f"surface '{self.name}': triangles contain non-finite values")
        if self.flip:
            t = np.ascontiguousarray(t[:, ::-1])
        nrm = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
        ln = np.linalg.norm(nrm, axis=1)
        good = ln > 1e-12 * max(float(np.abs(t).max()), 1e-300) ** 2
        self.triangles = np.ascontiguousarray(t[good])  # degenerate triangles dropped
        self.tri_normals = np.ascontiguousarray(nrm[good] / ln[good, None])
        if self.reach is not None and not self.reach > 0:
            raise ValueError(f"surface '{self.name}': reach = {self.reach!r}: must be > 0 m")
        self._grid: tuple[np.ndarray, ...] | None = None
        self._contact_arrays(0)
        self._bsum = np.zeros((0, 5))

    def _build_grid(self, rmax: float) -> None:
        reach = max(float(self.reach or 0.0), 1.0001 * rmax)
        self.reach = reach
        edge = np.linalg.norm(self.triangles[:, 1] - self.triangles[:, 0], axis=1).mean()
        self._grid = bin_triangles(self.triangles, reach, max(2.0 * reach, float(edge)),
                                   4_000_000)

    def _move(self, sim) -> None:  # noqa: ANN001 - Simulation
        if self.path is not None:
            t = sim.time
            self.point = np.asarray(self.path(t), dtype=np.float64).reshape(3).copy()
            nxt = np.asarray(self.path(t + sim.dt), dtype=np.float64).reshape(3)
            self.velocity = (nxt - self.point) / sim.dt
        elif sim.step_count > 0:
            self.update_motion(sim.dt)

    def compute(self, sim) -> None:  # noqa: ANN001 - Simulation (engine protocol)
        """Move (servo on the force measured last step, or the path), then add the contact
        forces of this step."""
        p = sim.p
        n = p.n
        if p.dim != 3:
            raise ValueError(f"surface '{self.name}': triangle surfaces are 3D only")
        fresh = self._contact_arrays(n)
        if not fresh or self.path is not None:
            self._move(sim)
        rmax = float(p.radius.max()) if n else 0.0
        if self._grid is None or rmax > float(self.reach):
            self._build_grid(rmax)
        glo, gsize, ncell, cstart, items = self._grid
        nblocks = (n + BLOCK - 1) // BLOCK
        if self._bsum.shape[0] != nblocks:
            self._bsum = np.zeros((nblocks, 5))
        laws.active(trimesh_contacts).pick(n)(
            p.pos, p.vel, p.omega, p.radius, p.mass, p.inertia, p.mat, self.triangles,
            self.tri_normals, self.point, glo, 1.0 / gsize, ncell, cstart, items,
            self.velocity, self.material, self._hist, self._touch, sim.pairtab, sim.elin,
            sim.dt, sim.ext_force, sim.ext_torque, self.particle_force, self._bsum)
        tot = self._bsum.sum(axis=0)
        self.force = tot[:3].copy()
        self.normal_force = -float(self.force @ self.normal)
        self.contacts = int(tot[3])
        self.stiffness = float(tot[4])

    def world_triangles(self) -> np.ndarray:
        """The triangles at the current displacement (m), e.g. for ``write_stl``."""
        return self.triangles + self.point

