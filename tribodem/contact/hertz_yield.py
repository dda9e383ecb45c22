"""First yield of a Hertz point contact without and with sliding friction (references for
``tribodem validate --solver elastic-plastic``).

* Frictionless (K. L. Johnson, Contact Mechanics, 1985, eq 3.46): on the axis r = 0 under
  p = p0 sqrt(1 - r^2 / a^2), with zeta = z / a,

      sigma_z / p0 = -1 / (1 + zeta^2),
      sigma_r / p0 = sigma_theta / p0 = -(1 + nu) (1 - zeta arctan(1 / zeta))
                                        + 1 / (2 (1 + zeta^2)),

  von Mises sigma_vM = |sigma_r - sigma_z| (axisymmetric); its maximum over zeta gives the
  first yield p0_y = Y / max(sigma_vM / p0) and its depth (nu = 0.3: 1.60 Y at 0.48 a,
  Johnson table 6.1).
* Sliding, q_x = mu p (G. M. Hamilton, "Explicit equations for the stresses beneath a
  sliding spherical contact", Proc. IMechE 197C, 1983): the elastic field is the
  superposition of Boussinesq's (normal) and Cerruti's (tangential) concentrated-force
  solutions (Johnson section 3.2) over the Hertz tractions. Here their closed-form
  displacements

      Boussinesq, unit force along +z at the origin (z into the body, rho^2 = x^2+y^2+z^2):
        u_x = (x z / rho^3 - (1 - 2 nu) x / (rho (rho + z))) / (4 pi G), u_y likewise,
        u_z = (z^2 / rho^3 + 2 (1 - nu) / rho) / (4 pi G);
      Cerruti, unit force along +x:
        u_x = (1 / rho + x^2 / rho^3 + (1 - 2 nu) (1 / (rho + z)
               - x^2 / (rho (rho + z)^2))) / (4 pi G),
        u_y = (x y / rho^3 - (1 - 2 nu) x y / (rho (rho + z)^2)) / (4 pi G),
        u_z = (x z / rho^3 + (1 - 2 nu) x / (rho (rho + z))) / (4 pi G)

  are differentiated (central differences, step 1e-6 rho), turned into stresses by Hooke's
  law and integrated over the contact disc in polar coordinates about the field point
  (trapezoidal rule in the angle, graded Gauss-Legendre panels in the radius up to the disc's
  edge, with s = s_edge (1 - (1 - t)^2) so that the square-root edge of the Hertz traction
  is smooth in t): an evaluation of Hamilton's field independent of the backends' FFT
  influence coefficients. The maximum von Mises stress over the plane y = 0 (the field's
  symmetry plane) inside the contact gives the first yield p0_y and its place; "surface"
  points are evaluated at z = 1e-3 a.

All stresses in units of p0, lengths in units of a.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

#: depth at which the "surface" is evaluated, in units of a
SURFACE_DEPTH = 1e-3


def axis_stress(zeta: NDArray[np.float64] | float, nu: float
                ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(sigma_r, sigma_z) / p0 on the axis of a frictionless Hertz point contact at depths
    ``zeta`` = z / a (Johnson eq 3.46)."""
    z = np.asarray(zeta, dtype=float)
    with np.errstate(divide="ignore"):
        at = np.where(z > 0, z * np.arctan(1.0 / np.where(z > 0, z, 1.0)), 0.0)
    sz = -1.0 / (1.0 + z**2)
    sr = -(1.0 + nu) * (1.0 - at) + 0.5 / (1.0 + z**2)
    return sr, sz


@dataclass(frozen=True)
class FirstYield:
    """First yield of a Hertz point contact: p0_y / Y, where (x / a, z / a on y = 0; x
    along the friction traction) and the peak von Mises stress / p0."""

    p0_over_y: float
    x: float
    depth: float
    vm_over_p0: float

    def load_ratio(self, p0: float, yield_strength: float) -> float:
        """P_y / P for a contact of peak pressure ``p0`` (Pa) at load P: (p0_y / p0)^3."""
        return (self.p0_over_y * yield_strength / p0) ** 3


def first_yield_frictionless(nu: float) -> FirstYield:
    """Johnson's first yield of the frictionless Hertz point contact (eq 3.46 maximised
    over the depth by golden-section search; nu = 0.3: p0_y = 1.60 Y at z = 0.48 a)."""
    lo, hi = 0.05, 2.0
    g = (math.sqrt(5.0) - 1.0) / 2.0

    def vm(z: float) -> float:
        sr, sz = axis_stress(z, nu)
        return float(abs(sr - sz))

    for _ in range(80):
        c, d = hi - g * (hi - lo), lo + g * (hi - lo)
        if vm(c) > vm(d):
            hi = d
        else:
            lo = c
    z = 0.5 * (lo + hi)
    return FirstYield(p0_over_y=1.0 / vm(z), x=0.0, depth=z, vm_over_p0=vm(z))


def _green(dx: NDArray[np.float64], dy: NDArray[np.float64], z: NDArray[np.float64],
           nu: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Displacements [..., 3] at (dx, dy, z) of unit Boussinesq (normal) and Cerruti (x)
    forces at the origin, with 4 pi G = 1."""
    rho = np.sqrt(dx * dx + dy * dy + z * z)
    rz = rho + z
    k = 1.0 - 2.0 * nu
    r3 = rho**3
    bx = dx * z / r3 - k * dx / (rho * rz)
    by = dy * z / r3 - k * dy / (rho * rz)
    bz = z * z / r3 + 2.0 * (1.0 - nu) / rho
    cx = 1.0 / rho + dx * dx / r3 + k * (1.0 / rz - dx * dx / (rho * rz * rz))
    cy = dx * dy / r3 - k * dx * dy / (rho * rz * rz)
    cz = dx * z / r3 + k * dx / (rho * rz)
    return np.stack([bx, by, bz], -1), np.stack([cx, cy, cz], -1)


def point_force_stress(dx: NDArray[np.float64], dy: NDArray[np.float64],
                       z: NDArray[np.float64], nu: float
                       ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Stresses [..., 3, 3] at (dx, dy, z) of a unit normal (Boussinesq) and a unit
    tangential x (Cerruti) force at the origin of the surface: Hooke's law on the central
    differences of :func:`_green` (shear modulus 1/(4 pi) with 4 pi G = 1 there, i.e.
    stresses per unit force)."""
    dx, dy, z = (np.asarray(v, dtype=float) for v in (dx, dy, z))
    rho = np.sqrt(dx * dx + dy * dy + z * z)
    h = 1e-6 * rho
    grads = []
    for which in range(2):
        g = np.empty((*rho.shape, 3, 3))  # g[..., i, j] = d u_i / d x_j
        for j in range(3):
            d = [np.zeros_like(rho) for _ in range(3)]
            d[j] = h
            up = _green(dx + d[0], dy + d[1], z + d[2], nu)[which]
            dn = _green(dx - d[0], dy - d[1], z - d[2], nu)[which]
            g[..., :, j] = (up - dn) / (2.0 * h)[..., None]
        grads.append(g)
    shear = 1.0 / (4.0 * math.pi)
    lam = 2.0 * shear * nu / (1.0 - 2.0 * nu)
    out = []
    for g in grads:
        eps = 0.5 * (g + np.swapaxes(g, -1, -2))
        tr = np.trace(eps, axis1=-2, axis2=-1)
        out.append(lam * tr[..., None, None] * np.eye(3) + 2.0 * shear * eps)
    return out[0], out[1]


def _gauss_panels(t0: float, n_gauss: int = 8) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Nodes and weights on [0, 1]: Gauss-Legendre panels [0, t0], [t0, 2 t0], ... doubling."""
    edges = [0.0, t0]
    while edges[-1] < 1.0:
        edges.append(min(1.0, 2.0 * edges[-1]))
    xg, wg = np.polynomial.legendre.leggauss(n_gauss)
    nodes, weights = [], []
    for lo, hi in zip(edges[:-1], edges[1:], strict=True):
        nodes.append(0.5 * (hi - lo) * xg + 0.5 * (hi + lo))
        weights.append(0.5 * (hi - lo) * wg)
    return np.concatenate(nodes), np.concatenate(weights)


def sliding_hertz_stress(x: float, z: float, mu: float, nu: float, n_theta: int = 128
                         ) -> NDArray[np.float64]:
    """Stress / p0 [3, 3] at (x, 0, z) (units of a; |x| < 1, z > 0) under the Hertz
    pressure p = p0 sqrt(1 - r^2) and the traction q_x = mu p on the body (quadrature of
    :func:`point_force_stress`, see the module docstring)."""
    if not (abs(x) < 1.0 and z > 0.0):
        raise ValueError(f"(x, z) = ({x!r}, {z!r}) is not allowed: need |x| < 1 and z > 0")
    th = 2.0 * math.pi * np.arange(n_theta) / n_theta
    c, s = np.cos(th), np.sin(th)
    s_edge = -x * c + np.sqrt(1.0 - (x * s) ** 2)  # distance to the disc's edge
    t, wt = _gauss_panels(min(0.05, z / (20.0 * float(s_edge.max()))))
    # s = s_edge (1 - (1 - t)^2): ds = 2 s_edge (1 - t) dt
    rad = s_edge[:, None] * (1.0 - (1.0 - t[None, :]) ** 2)
    jac = 2.0 * s_edge[:, None] * (1.0 - t[None, :]) * wt[None, :] * (2.0 * math.pi / n_theta)
    xi = x + rad * c[:, None]
    eta = rad * s[:, None]
    p = np.sqrt(np.maximum(1.0 - xi * xi - eta * eta, 0.0))
    sb, sc = point_force_stress(x - xi, -eta, np.full_like(xi, z), nu)
    w = (jac * rad)[..., None, None]
    return ((sb * p[..., None, None] + mu * sc * p[..., None, None]) * w).sum(axis=(0, 1))


def von_mises_tensor(s: NDArray[np.float64]) -> float:
    """Von Mises stress of a 3 x 3 stress tensor."""
    dev = s - np.trace(s) / 3.0 * np.eye(3)
    return float(math.sqrt(1.5 * float((dev * dev).sum())))


def first_yield_sliding(mu: float, nu: float) -> FirstYield:
    """Hamilton's first yield of the sliding Hertz point contact (q_x = mu p): the maximum
    von Mises stress on y = 0 inside the contact, by a grid search (x / a in [-0.9, 0.9]
    by 0.1, z / a from the surface to 0.8) refined by coordinate bisection to 1e-3 a."""
    zs = [SURFACE_DEPTH, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.8]
    best = (-1.0, 0.0, 0.0)
    for xv in np.arange(-0.9, 0.901, 0.1):
        for zv in zs:
            v = von_mises_tensor(sliding_hertz_stress(float(xv), zv, mu, nu))
            if v > best[0]:
                best = (v, float(xv), zv)
    v, xb, zb = best
    step = 0.05
    while step >= 1e-3:
        moved = False
        for dxv, dzv in ((step, 0.0), (-step, 0.0), (0.0, step), (0.0, -step)):
            xn, zn = xb + dxv, max(SURFACE_DEPTH, zb + dzv)
            if abs(xn) >= 0.999 or (xn, zn) == (xb, zb):
                continue
            vn = von_mises_tensor(sliding_hertz_stress(xn, zn, mu, nu))
            if vn > v:
                v, xb, zb, moved = vn, xn, zn, True
        if not moved:
            step *= 0.5
    depth = 0.0 if zb <= SURFACE_DEPTH else zb
    return FirstYield(p0_over_y=1.0 / v, x=xb, depth=depth, vm_over_p0=v)
