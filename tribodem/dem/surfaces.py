"""Rigid first-body surfaces from height maps (Lu (2018) section 3.2.6: first bodies rigid
in the DE phase), with prescribed or servo (force-controlled) motion.

A :class:`HeightMapSurface` is the surface ``z = z0 + heights(x - x0, y - y0)`` of a rigid
body, sampled on a regular grid and interpolated bilinearly. The body lies on one side:
``side = "below"`` (a lower first body: particles above it) or ``"above"`` (an upper first
body: particles below it). A particle touches it through the local tangent plane at its
own (x, y): distance ``d = (z_p - z_s(x_p, y_p)) n_z`` with ``n`` the unit surface normal
towards the particle side; overlap ``r - d``. This is exact for a plane and first-order
accurate for curved surfaces whose radius of curvature is much larger than the particle
radius (first bodies of mm radius, debris of um size). Particles outside the grid do not
touch. The contact law is the one of walls (``walls.wall_contact``: Hertz-Mindlin or linear,
Coulomb friction, rolling resistance), with a shear history per particle.

Motion reuses :class:`tribodem.dem.walls.PlaneWall`'s modes: ``point`` is the rigid
displacement of the map (m), ``normal`` is the direction towards the particles (+z below,
-z above), ``"boundary"`` is the boundary-moving servo of Lu (2018) eqs 3.2-3.6.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numba import prange
from numpy.typing import NDArray

from tribodem.dem import laws
from tribodem.dem.jit import kernel
from tribodem.dem.walls import RigidSurface, rigid_surface_contact

SIDES = ("below", "above")


@kernel
def heightmap_contacts(pos, vel, omega, radius, mass, inertia, mat, heights, x0, y0, dx, dy,
                       sgn, off, svel, smat, hist, touching, pairtab, elin, dt, ext_force,
                       ext_torque, fout):
    """Contacts of every particle with one height-map surface (3D).

    Adds the particle forces/torques into ``ext_force``/``ext_torque``; writes per particle
    the force on the surface ``fout[i]`` (N), ``touching[i]`` = (overlap m, normal force N,
    kn N/m); ``hist[i]`` is the shear spring (m).
    """
    n = pos.shape[0]
    nx = heights.shape[0]
    ny = heights.shape[1]
    for i in prange(n):
        fout[i, 0] = 0.0
        fout[i, 1] = 0.0
        fout[i, 2] = 0.0
        u = (pos[i, 0] - off[0] - x0) / dx
        v = (pos[i, 1] - off[1] - y0) / dy
        iu = int(np.floor(u))
        iv = int(np.floor(v))
        if iu < 0 or iv < 0 or iu >= nx - 1 or iv >= ny - 1:
            hist[i, 0] = 0.0
            hist[i, 1] = 0.0
            hist[i, 2] = 0.0
            touching[i, 0] = -1.0
            touching[i, 1] = 0.0
            touching[i, 2] = 0.0
            continue
        fu = u - iu
        fv = v - iv
        h00 = heights[iu, iv]
        h10 = heights[iu + 1, iv]
        h01 = heights[iu, iv + 1]
        h11 = heights[iu + 1, iv + 1]
        zs = ((1 - fu) * (1 - fv) * h00 + fu * (1 - fv) * h10 + (1 - fu) * fv * h01
              + fu * fv * h11 + off[2])
        hx = ((1 - fv) * (h10 - h00) + fv * (h11 - h01)) / dx
        hy = ((1 - fu) * (h01 - h00) + fu * (h11 - h10)) / dy
        ln = np.sqrt(hx * hx + hy * hy + 1.0)
        nrm = (-sgn * hx / ln, -sgn * hy / ln, sgn / ln)
        gap = (pos[i, 2] - zs) * nrm[2] - radius[i]
        if gap >= 0.0 and touching[i, 0] <= 0.0:
            hist[i, 0] = 0.0
            hist[i, 1] = 0.0
            hist[i, 2] = 0.0
            touching[i, 0] = -gap
            touching[i, 1] = 0.0
            touching[i, 2] = 0.0
            continue
        point = (pos[i, 0], pos[i, 1], zs)
        rigid_surface_contact(i, pos, vel, omega, radius[i], mass, inertia, mat, point, nrm,
                              svel, smat, hist, pairtab, elin, dt, touching, ext_force,
                              ext_torque, fout)


def bilinear_weights(x: NDArray[np.float64], y: NDArray[np.float64], x0: float, y0: float,
                     dx: float, dy: float, shape: tuple[int, int]
                     ) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.float64]]:
    """Node indices (i, j: [m, 4]) and weights ([m, 4]) of points in a regular grid.

    For a value field this is Lu (2018) eq 3.15 (the shape function through the element's
    four nodal values evaluated at (x, y)); points outside the grid get zero weights.
    """
    u = (np.asarray(x, float) - x0) / dx
    v = (np.asarray(y, float) - y0) / dy
    nx, ny = shape
    iu = np.floor(u).astype(np.int64)
    iv = np.floor(v).astype(np.int64)
    inside = (iu >= 0) & (iv >= 0) & (iu < nx - 1) & (iv < ny - 1)
    iu = np.clip(iu, 0, nx - 2)
    iv = np.clip(iv, 0, ny - 2)
    fu, fv = u - iu, v - iv
    w = np.stack([(1 - fu) * (1 - fv), fu * (1 - fv), (1 - fu) * fv, fu * fv], axis=1)
    w *= inside[:, None]
    ii = np.stack([iu, iu + 1, iu, iu + 1], axis=1)
    jj = np.stack([iv, iv, iv + 1, iv + 1], axis=1)
    return ii, jj, w


@dataclass
class HeightMapSurface(RigidSurface):
    """A rigid height-map surface (an ``Interaction``; add with ``sim.add_interaction``).

    ``heights[i, j]`` (m) is the surface elevation at ``(x0 + i dx, y0 + j dy)`` in the
    surface's own frame; ``point`` (m) is its rigid displacement; ``side`` says where the
    body is. Motion modes, servo parameters and ``target_force`` (N) are those of
    :class:`PlaneWall`. After each step: ``force`` (N, on the surface), ``normal_force``
    (N, compressive +), ``contacts``, ``stiffness`` (sum kn, N/m) and per particle
    ``particle_force`` (N, on the surface, [n, 3]).
    """

    heights: np.ndarray = field(default_factory=lambda: np.zeros((2, 2)))
    x0: float = 0.0
    y0: float = 0.0
    dx: float = 1.0
    dy: float = 1.0
    side: str = "below"

    def __post_init__(self) -> None:
        if self.side not in SIDES:
            raise ValueError(f"surface '{self.name}': side = {self.side!r}: must be one of "
                             f"{SIDES}")
        self.normal = np.array([0.0, 0.0, 1.0 if self.side == "below" else -1.0])
        super().__post_init__()
        h = np.ascontiguousarray(self.heights, dtype=np.float64)
        if h.ndim != 2 or min(h.shape) < 2:
            raise ValueError(f"surface '{self.name}': heights has shape {h.shape}: must be "
                             "2-D with >= 2 points per side")
        if not np.all(np.isfinite(h)):
            raise ValueError(f"surface '{self.name}': heights contains non-finite values")
        for nm in ("dx", "dy"):
            if not float(getattr(self, nm)) > 0:
                raise ValueError(f"surface '{self.name}': {nm} = {getattr(self, nm)!r}: must "
                                 "be > 0 m")
        self.heights = h
        self._contact_arrays(0)

    def elevation(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Surface z (m) at lab (x, y) with the current displacement (NaN outside the grid)."""
        ii, jj, w = bilinear_weights(np.asarray(x, float) - self.point[0],
                                     np.asarray(y, float) - self.point[1], self.x0, self.y0,
                                     self.dx, self.dy, self.heights.shape)
        z = (self.heights[ii, jj] * w).sum(axis=1)
        return np.where(w.any(axis=1), z + self.point[2], np.nan)

    def compute(self, sim) -> None:  # noqa: ANN001 - Simulation (engine protocol)
        """Move (servo on the force measured last step), then add the contact forces."""
        p = sim.p
        n = p.n
        if not self._contact_arrays(n) and sim.step_count > 0:
            self.update_motion(sim.dt)
        sgn = 1.0 if self.side == "below" else -1.0
        laws.active(heightmap_contacts).pick(n)(
            p.pos, p.vel, p.omega, p.radius, p.mass, p.inertia, p.mat, self.heights,
            self.x0, self.y0, self.dx, self.dy, sgn, self.point, self.velocity, self.material,
            self._hist, self._touch, sim.pairtab, sim.elin, sim.dt, sim.ext_force,
            sim.ext_torque, self.particle_force)
        self.force = self.particle_force.sum(axis=0)
        self.normal_force = -float(self.force @ self.normal)
        hit = self._touch[:, 0] > 0.0
        self.contacts = int(hit.sum())
        self.stiffness = float(self._touch[hit, 2].sum())
