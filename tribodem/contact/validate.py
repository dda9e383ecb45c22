"""Closed-form checks of the first-body backends (``tribodem validate``).

Each check is a dict ``{"name", "value", "reference", "error", "tolerance", "pass"}`` (error
relative). The half-space backend answers (K. L. Johnson, Contact Mechanics, 1985):

- Hertz point contact (sphere R 4 mm on a flat, 100 N, EN24T): p0 = 3P/(2 pi a^2),
  a = (3PR/(4E*))^(1/3) (eqs 4.22-4.23); Hertz line contact (cylinder R 4 mm, P' 1e5 N/m):
  p0 = sqrt(P'E*/(pi R)), a = sqrt(4P'R/(pi E*)) (eq 4.45);
- Cattaneo-Mindlin (point contact, partial slip): tangential force Q = mu P (1 - (1 -
  delta/delta*)^(3/2)) at three displacements and the stick radius c = a (1 - Q/(mu P))^(1/3)
  (eqs 7.43, 7.40), delta* = mu kappa a^2/R;
- gross slip: Q = mu P;
- first yield (von Mises, nu = 0.3): max sigma_vM = 0.62 p0 below the surface, so the load at
  first yield is P_y = P (Y / (0.62 p0))^3 for a point contact (eq 6.6 with table 6.1:
  p0_y = 1.61 Y).

The elastic-plastic backend (:func:`elastic_plastic_checks`): first yield without and with
sliding friction (mu = 0, 0.25, 0.5; Johnson eq 3.46 and Hamilton's field of the sliding
sphere, :mod:`tribodem.contact.hertz_yield`) and the onset of plastic strain around it.
The FE backend's checks (plane strain) are in :mod:`tribodem.contact.fe.validate`.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tribodem.contact.base import ElasticBody, contact_modulus
from tribodem.contact.checks import check
from tribodem.contact.elastoplastic import ElastoPlasticSolver
from tribodem.contact.geometry import HertzSphere, cylinder, flat, sphere
from tribodem.contact.halfspace import HalfSpaceSolver, von_mises
from tribodem.contact.hertz_yield import first_yield_frictionless, first_yield_sliding
from tribodem.materials.en24t import EN24T

LOAD, MU, RADIUS = 100.0, 0.6, 4e-3


def halfspace_checks(n: int = 128) -> list[dict[str, Any]]:
    """Every closed-form check of the half-space backend (``n`` window points per side)."""
    mat = ElasticBody(EN24T.young, EN24T.poisson)
    e_star = contact_modulus(mat, mat)
    hz = HertzSphere(RADIUS, LOAD, e_star)
    out: list[dict[str, Any]] = []
    # the Hertz (parabolic) profiles the closed forms are for
    ball, plane = sphere(RADIUS, exact=False), flat()
    roller = cylinder(2 * RADIUS, axis="y", exact=False)
    s = HalfSpaceSolver(ball, plane, load=LOAD, friction=MU, n=n)
    inc = s.solve_increment(0.0)
    out.append(check("hertz point p0 (Pa)", inc.max_pressure, hz.peak_pressure, 0.02))
    out.append(check("hertz point a (m)", math.sqrt(inc.contact_area / math.pi),
                     hz.contact_radius, 0.02))
    # line contact: the window is periodic along the cylinder (y)
    p_line = 1e5  # N/m
    b = math.sqrt(4 * p_line * RADIUS / (math.pi * e_star))
    w = 10 * b
    sl = HalfSpaceSolver(roller, plane, load=p_line * w, friction=MU, n=n, window=w)
    li = sl.solve_increment(0.0)
    out.append(check("hertz line p0 (Pa)", li.max_pressure,
                     math.sqrt(p_line * e_star / (math.pi * RADIUS)), 0.02))
    row = li.pressure[:, n // 2]
    on = row > 0.05 * row.max()  # fit p^2 = p0^2 (1 - x^2/a^2) over the contact points
    slope, icpt = np.polyfit(sl.coords[on] ** 2, row[on] ** 2, 1)
    out.append(check("hertz line a (m)", math.sqrt(-icpt / slope), b, 0.02))
    # Cattaneo-Mindlin partial slip (Ciavarella-Jaeger regime)
    cj = HalfSpaceSolver(ball, plane, load=LOAD, friction=MU, n=n, regime="ciavarella-jaeger")
    first = cj.solve_increment(0.0)
    d_star = MU * cj.kappa * cj.approach(first.pressure, cj.gap(0.0))
    for frac in (0.3, 0.5, 0.7):
        cj.reset()
        cj.solve_increment(0.0)
        step = cj.solve_increment(frac * d_star)
        q = -float(step.traction[..., 0].sum()) * cj.dx**2
        mindlin = MU * LOAD * (1 - (1 - frac) ** 1.5)
        out.append(check(f"mindlin Q at {frac} delta* (N)", q, mindlin, 0.03))
        assert step.stick is not None  # ciavarella-jaeger: stick and slip
        c = math.sqrt(float(step.stick.sum()) * cj.dx**2 / math.pi)
        out.append(check(f"mindlin stick radius at {frac} delta* (m)", c,
                         hz.contact_radius * (1 - q / (MU * LOAD)) ** (1 / 3), 0.05))
    # gross slip
    s.reset()
    s.solve_increment(0.0)
    g = s.solve_increment(1e-5)
    out.append(check("gross slip Q / (mu P)", -float(g.traction[..., 0].sum()) * s.dx**2
                     / (MU * LOAD), 1.0, 0.01))
    # first yield (frictionless, von Mises): the load at which max sigma_vM reaches Y
    s0 = HalfSpaceSolver(ball, plane, load=LOAD, friction=0.0, n=n)
    i0 = s0.solve_increment(0.0)
    vm = s0.subsurface_stress(i0, "lower", depth=hz.contact_radius, nz=41).von_mises.max()
    p_y = LOAD * (EN24T.yield_strength / vm) ** 3  # sigma ~ p0 ~ P^(1/3)
    p0_y = 1.61 * EN24T.yield_strength  # Johnson table 6.1, nu = 0.3
    p_y_ref = LOAD * (p0_y / hz.peak_pressure) ** 3
    out.append(check("first yield load (N)", p_y, p_y_ref, 0.05))
    return out


#: friction coefficients of the first-yield checks of the elastic-plastic backend
YIELD_FRICTIONS = (0.0, 0.25, 0.5)


def _peak_refined(vm: NDArray[np.float64], z: NDArray[np.float64], x: NDArray[np.float64]
                  ) -> tuple[float, float, float]:
    """(peak, depth m, x m) of a [nz, nx, ny] von Mises field on the plane through its
    maximum: the grid maximum refined by a parabola through it and its two neighbours along
    z and along x (kept on the grid at an edge)."""
    k = np.unravel_index(int(np.argmax(vm)), vm.shape)

    def parabola(f: NDArray[np.float64], i: int, c: NDArray[np.float64]) -> tuple[float, float]:
        if i == 0 or i == len(c) - 1:
            return float(c[i]), float(f[i])
        fm, f0, fp = float(f[i - 1]), float(f[i]), float(f[i + 1])
        d = fm - 2.0 * f0 + fp
        s = 0.0 if d == 0.0 else 0.5 * (fm - fp) / d
        return float(c[i] + s * (c[1] - c[0])), f0 - 0.25 * (fm - fp) * s

    zr, fz = parabola(vm[:, k[1], k[2]], int(k[0]), z)
    xr, fx = parabola(vm[k[0], :, k[2]], int(k[1]), x)
    return max(fz, fx), zr, xr


def _backend_first_yield(mu: float, load: float) -> tuple[float, float, float,
                                                          ElastoPlasticSolver]:
    """The elastic-plastic backend's (first-yield load N, its depth m, its x m along the
    traction) of the sphere R 4 mm on a flat sliding with ``mu`` (gross slip): the von Mises
    maximum of its stress on the lower body's plastic grid at ``load`` (N, elastic: below
    yield), scaled as P_y = P (Y / sigma_vM)^3."""
    s = ElastoPlasticSolver(sphere(RADIUS, exact=False), flat(), load=load, friction=mu,
                            **YIELD_GRID)
    s.solve_increment(0.0)
    s.solve_increment(1e-6)  # gross slip: q = mu p on the lower body along +x
    body = s.bodies["lower"]
    if body.cumulated_plastic_strain.max() > 0.0:
        raise RuntimeError(f"validation load {load} N yields: expected elastic")
    vm, depth, x = _peak_refined(von_mises(body.stress), body.z, body.x)
    p_y = load * (s.yield_strength / vm) ** 3
    scale = (p_y / load) ** (1.0 / 3.0)  # lengths grow as P^(1/3) (Hertz)
    return p_y, depth * scale, x * scale, s


#: the grids of the first-yield checks: the window 12 a on 360 points (a / 30), the plastic
#: grid 10 a on 150 points (a / 15; periodic: on 4 a the images raised the peak von Mises
#: stress by 3 %, on 8 a by 1.2 %; at a / 10 the surface cell at the contact's edge read 2 %
#: high), a / 20 in depth
YIELD_GRID: dict[str, Any] = dict(n=360, window_radii=12.0, tolerance=1e-8, ep_n=150, ep_nz=21,
                                  ep_window_radii=10.0, ep_depth_radii=1.0, load_steps=1)


def elastic_plastic_checks() -> list[dict[str, Any]]:
    """First yield of the Hertz point contact (sphere R 4 mm on a flat, EN24T) on the
    elastic-plastic backend without and with sliding friction (gross slip, q = mu p), mu in
    :data:`YIELD_FRICTIONS`: the first-yield load P_y and its depth (mu = 0, 0.25) or that
    it is at the surface (mu = 0.5), against Johnson's closed form (mu = 0, eq 3.46) and
    Hamilton's field (mu > 0, :mod:`tribodem.contact.hertz_yield`), 5 %; and the onset of
    plastic strain in the backend's plastic state: none at 0.97 P_y, some at 1.03 P_y,
    at the predicted place."""
    mat = ElasticBody(EN24T.young, EN24T.poisson)
    e_star = contact_modulus(mat, mat)
    out: list[dict[str, Any]] = []
    for mu in YIELD_FRICTIONS:
        ref = (first_yield_frictionless(EN24T.poisson) if mu == 0.0
               else first_yield_sliding(mu, EN24T.poisson))
        hz = HertzSphere(RADIUS, LOAD, e_star)
        p_ref = LOAD * ref.load_ratio(hz.peak_pressure, EN24T.yield_strength)
        a_ref = HertzSphere(RADIUS, p_ref, e_star).contact_radius
        p_y, depth, x, _ = _backend_first_yield(mu, 0.5 * p_ref)
        out.append(check(f"first yield load, mu = {mu} (N)", p_y, p_ref, 0.05))
        if ref.depth > 0.0:
            out.append(check(f"first yield depth, mu = {mu} (m)", depth, ref.depth * a_ref,
                             0.05))
        else:  # at the surface: its depth (m, absolute: 5 % of a, one layer is a / 20)
            out.append(check(f"first yield at the surface, mu = {mu}: depth (m)", depth, 0.0,
                             0.05 * a_ref, absolute=True))
        for factor in (0.97, 1.03):
            s = ElastoPlasticSolver(sphere(RADIUS, exact=False), flat(), load=factor * p_y,
                                    friction=mu, **YIELD_GRID)
            s.solve_increment(0.0)
            s.solve_increment(1e-6)
            pmax, zp, xp = s.bodies["lower"].peak()
            yielded = pmax > 0.0
            f3 = factor ** (1.0 / 3.0)
            where = (abs(zp - depth * f3) <= 1.5 * s.ep_depth / (s.ep_nz - 1)
                     and abs(xp - x * f3) <= 1.5 * s.ep_dx)
            ok = (not yielded) if factor < 1.0 else (yielded and where)
            out.append({"name": f"plastic strain at {factor} P_y, mu = {mu} (peak, -)",
                        "value": pmax, "reference": 0.0 if factor < 1.0 else pmax,
                        "error": 0.0 if ok else 1.0, "tolerance": 0.0, "pass": bool(ok)})
    return out
