"""Plane-strain stress under piecewise-constant strip tractions on an elastic half-plane.

Frame: x along the surface, z >= 0 the depth into the body, the surface z = 0 loaded by a
pressure p(x) (Pa, compressive, along +z into the body) and a shear traction q(x) (Pa,
along +x on the body), both constant on each strip [e_j, e_{j+1}] of a list of edges.

Closed forms (K. L. Johnson, *Contact Mechanics*, 1985, chapter 2 "Line loading of an
elastic half-space": the Flamant fields of a concentrated normal force, eq 2.15, and of a
concentrated tangential force, eq 2.20, integrated over a strip of uniform traction, the
uniform-strip forms of section 2.6). With, for the field point (x, z) and the strip edges
x1 < x2, theta_i = atan2(x - x_i, z) (the angle from the z axis, in (-pi/2, pi/2); so
theta_1 > theta_2) and r_i the distance to edge i:

* uniform pressure p::

      sigma_xx = -(p/pi) [(theta1 - theta2) - (sin 2theta1 - sin 2theta2)/2]
      sigma_zz = -(p/pi) [(theta1 - theta2) + (sin 2theta1 - sin 2theta2)/2]
      tau_xz   = -(p/pi) [sin^2 theta1 - sin^2 theta2]

* uniform shear q (along +x on the body)::

      sigma_xx = -(q/pi) [2 ln(r1/r2) - (sin^2 theta1 - sin^2 theta2)]
      sigma_zz = -(q/pi) [sin^2 theta1 - sin^2 theta2]
      tau_xz   = -(q/pi) [(theta1 - theta2) - (sin 2theta1 - sin 2theta2)/2]

so that at the surface sigma_zz = -p and tau_xz = -q under the strip (the traction on the
surface of outward normal -z is (-tau_xz, -sigma_zz) = (q, p)). Plane strain:
sigma_yy = nu (sigma_xx + sigma_zz). Every term is a difference of one function of the two
edges, so the sum over strips is one sum over edges weighted by the traction jumps there
(Abel summation): O(points x loaded edges), compiled (numba).

A field point on a strip edge at z = 0 is singular (sigma_xx diverges logarithmically under
a jump of shear) and gives nan; cell centres and points below the surface are regular.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray


@njit(cache=True)
def _strip_stress_kernel(x: NDArray[np.float64], z: NDArray[np.float64],
                         edges: NDArray[np.float64], jumps_p: NDArray[np.float64],
                         jumps_q: NDArray[np.float64], loaded: NDArray[np.int64],
                         out: NDArray[np.float64]) -> None:
    """out[a] = (sigma_xx, sigma_zz, tau_xz) at (x[a], z[a]) from the traction jumps
    (right strip minus left strip) at the edges ``loaded``."""
    inv_pi = 1.0 / math.pi
    for a in range(x.size):
        xa = x[a]
        za = z[a]
        sxx = 0.0
        szz = 0.0
        sxz = 0.0
        for k in range(loaded.size):
            e = loaded[k]
            dp = jumps_p[e]
            dq = jumps_q[e]
            xe = xa - edges[e]
            r2 = xe * xe + za * za
            th = math.atan2(xe, za)
            if r2 > 0.0:
                s2h = xe * za / r2  # sin(2 theta) / 2
                ss = xe * xe / r2  # sin^2 theta
                lr = math.log(r2)  # 2 ln r
            else:
                s2h = math.nan
                ss = math.nan
                lr = math.nan
            sxx -= dp * (th - s2h) + dq * (lr - ss)
            szz -= dp * (th + s2h) + dq * ss
            sxz -= dp * ss + dq * (th - s2h)
        out[a, 0] = sxx * inv_pi
        out[a, 1] = szz * inv_pi
        out[a, 2] = sxz * inv_pi


def strip_stress(
    x: ArrayLike,
    z: ArrayLike,
    edges: ArrayLike,
    pressure: ArrayLike,
    shear: ArrayLike | None = None,
    poisson: float = 0.3,
) -> NDArray[np.float64]:
    """Plane-strain stress (Pa) at the points (x, z) (m, z >= 0 depth; broadcast together)
    of a half-plane under strip tractions: ``pressure`` and ``shear`` (Pa, along +x on the
    body) constant on strip j = [edges[j], edges[j+1]] (``edges`` increasing, m).

    Returns ``[..., 4]``: sigma_xx, sigma_yy = nu (sigma_xx + sigma_zz), sigma_zz, tau_xz
    (Johnson 1985 ch. 2, the uniform-strip closed forms in the module docstring, summed
    over the strips).
    """
    xb, zb = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(z, dtype=float))
    e = np.ascontiguousarray(edges, dtype=float)
    p = np.asarray(pressure, dtype=float)
    q = np.zeros_like(p) if shear is None else np.asarray(shear, dtype=float)
    if e.ndim != 1 or p.shape != (e.size - 1,) or q.shape != p.shape:
        raise ValueError(f"edges {e.shape}, pressure {p.shape}, shear {q.shape}: need "
                         "m + 1 edges for m strips")
    if e.size > 1 and not np.all(np.diff(e) > 0):
        raise ValueError("edges must be strictly increasing")
    if np.any(zb < 0):
        raise ValueError("z must be >= 0 (depth into the body)")
    jp = np.zeros(e.size)
    jq = np.zeros(e.size)
    jp[:-1] += p
    jp[1:] -= p
    jq[:-1] += q
    jq[1:] -= q
    loaded = np.flatnonzero((jp != 0.0) | (jq != 0.0)).astype(np.int64)
    xs = np.ascontiguousarray(xb.ravel())
    zs = np.ascontiguousarray(zb.ravel())
    out = np.empty((xs.size, 3))
    _strip_stress_kernel(xs, zs, e, jp, jq, loaded, out)
    res = np.empty((xs.size, 4))
    res[:, 0] = out[:, 0]
    res[:, 1] = poisson * (out[:, 0] + out[:, 1])
    res[:, 2] = out[:, 1]
    res[:, 3] = out[:, 2]
    return res.reshape(xb.shape + (4,))


def plane_strain_voigt(s4: NDArray[np.float64]) -> NDArray[np.float64]:
    """[..., 4] (xx, yy, zz, xz) of :func:`strip_stress` -> Voigt [..., 6] in
    :data:`tribodem.contact.base.VOIGT_ORDER` (xx, yy, zz, yz, xz, xy; yz = xy = 0)."""
    out = np.zeros(s4.shape[:-1] + (6,))
    out[..., 0:3] = s4[..., 0:3]
    out[..., 4] = s4[..., 3]
    return out


def plane_strain_von_mises(s4: NDArray[np.float64]) -> NDArray[np.float64]:
    """Von Mises stress sqrt(3 J2) of [..., 4] (xx, yy, zz, xz) plane-strain stresses, Pa."""
    sx, sy, sz, t = s4[..., 0], s4[..., 1], s4[..., 2], s4[..., 3]
    j2 = ((sx - sy) ** 2 + (sy - sz) ** 2 + (sz - sx) ** 2) / 6.0 + t**2
    return np.sqrt(3.0 * j2)


def plane_strain_tresca(s4: NDArray[np.float64]) -> NDArray[np.float64]:
    """Maximum shear (s1 - s3)/2 of [..., 4] (xx, yy, zz, xz) plane-strain stresses, Pa:
    the in-plane principal stresses c +- R (c = (sxx + szz)/2, R = sqrt(((sxx - szz)/2)^2
    + txz^2)) and the out-of-plane sigma_yy."""
    sx, sy, sz, t = s4[..., 0], s4[..., 1], s4[..., 2], s4[..., 3]
    c = 0.5 * (sx + sz)
    r = np.hypot(0.5 * (sx - sz), t)
    hi = np.maximum(c + r, sy)
    lo = np.minimum(c - r, sy)
    return 0.5 * (hi - lo)
