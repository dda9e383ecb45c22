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

The FE backend's checks (plane strain) are in :mod:`tribodem.contact.fe.validate`.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from tribodem.contact.base import ElasticBody, contact_modulus
from tribodem.contact.checks import check
from tribodem.contact.geometry import HertzSphere, cylinder, flat, sphere
from tribodem.contact.halfspace import HalfSpaceSolver
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
