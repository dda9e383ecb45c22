"""Closed-form checks of the plane-strain FE model (backs ``tribodem validate --solver fe``).

Each check is a dict ``{"name", "value", "reference", "error", "tolerance", "pass"}``;
``error`` is relative (``|value - reference| / |reference|``) unless the name says "(m)".
References (K. L. Johnson, Contact Mechanics, 1985; Lu (2018) section 3.2.5):

* Hertz line contact (eq. 4.45): p0 = sqrt(P E* / (pi R)), a = sqrt(4 P R / (pi E*)).
* Cattaneo-Mindlin line contact (section 7.2): stick zone c / a = sqrt(1 - Q / (mu P)).
* Tangential force against displacement. In 2D the displacement of a loaded body is only
  defined against a datum (log terms of the body size), but the part due to micro-slip is
  local: from the Cattaneo tractions q = mu p0 / a (sqrt(a^2 - x^2) - sqrt(c^2 - x^2)) and the
  plane-strain half-space kernel, the displacement of the loaded edge is
  delta(Q) = C Q + delta_slip(Q), delta_slip = [Q + (mu P - Q) ln(1 - Q / (mu P))] / (pi E*),
  C the model's own full-stick compliance (body size and boundary conditions), measured on the
  first tangential increment. Compared: Q at three imposed displacements from
  delta = C Q + delta_slip(Q), and delta_slip itself (delta - C Q against the formula).
* Gross slip: Q = mu P.
* First yield (von Mises, nu = 0.3, table 4.1 / section 4.2): max sigma_vM = p0 / 1.79 at
  z = 0.70 a: compared p0 / max sigma_vM (integration points of the flat's fine zone, elastic
  run), the depth of the maximum, and p0 / Y at the onset of plastic strain in an
  elastic-plastic run (bilinear EN24T, seed table 5.1).
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import brentq

from tribodem.contact.base import ContactCase, ElasticBody
from tribodem.contact.checks import check
from tribodem.contact.fe.deck import FEMaterial, sliding_contact
from tribodem.contact.fe.model import LineCase, LineRun, run_line_case
from tribodem.contact.fe.options import FEOptions
from tribodem.contact.fe.results import ContactState, ip_coordinates
from tribodem.contact.geometry import cylinder, flat
from tribodem.materials.en24t import EN24T

#: Johnson's von Mises first-yield factor of a line contact (nu = 0.3) and its depth / a
YIELD_FACTOR, YIELD_DEPTH = 1.79, 0.70


def in_contact(state: ContactState, p0: float) -> NDArray[np.bool_]:
    """Nodes carrying more than 0.1 % of p0 (the nodal-force recovery leaves round-off)."""
    return state.pressure > 1e-3 * p0


def half_width_fit(state: ContactState, p0: float) -> tuple[float, float]:
    """Contact half-width and peak pressure from a least-squares fit of p^2 = A - B x^2 over
    the contact nodes inside the outermost ones (Hertz: p^2 = p0^2 (1 - x^2 / a^2)):
    returns (a, p0) = (sqrt(A / B), sqrt(A)) in (m, Pa)."""
    on = np.flatnonzero(in_contact(state, p0))
    inner = on[1:-1]
    x, p = state.x[inner], state.pressure[inner]
    b_, a_ = np.polyfit(x * x, p * p, 1)
    return math.sqrt(a_ / -b_), math.sqrt(a_)


def stick_half_width(state: ContactState, ref: ContactState, p0: float, mu: float,
                     stick_slope: float) -> tuple[float, float]:
    """Stick-zone half-width (m) and the node spacing there. A contact node slips when its
    relative tangential displacement since ``ref`` exceeds the largest elastic displacement
    its stick spring can take, mu p / stick_slope (p its pressure, stick_slope in Pa/m); the
    stick-zone edge is put midway between the outermost stick node and the next node on each
    side (averaged)."""
    on = in_contact(state, p0)
    slip = np.abs(state.slip - ref.slip)
    stick = np.flatnonzero(on & (slip <= mu * state.pressure / stick_slope))
    if stick.size == 0:
        return 0.0, float(np.diff(state.x).min())
    lo, hi = stick.min(), stick.max()
    x = state.x
    left = 0.5 * (x[lo] + x[max(lo - 1, 0)])
    right = 0.5 * (x[hi] + x[min(hi + 1, x.size - 1)])
    return 0.5 * (right - left), float(x[hi] - x[hi - 1])


def slip_displacement(q: float, mu_p: float, e_star: float) -> float:
    """Micro-slip part of the edge displacement of a Cattaneo line contact, m (|q| < mu P)."""
    r = q / mu_p
    return (q + (mu_p - q) * math.log1p(-r)) / (math.pi * e_star)


def von_mises_plane_strain(s: NDArray[np.float64]) -> NDArray[np.float64]:
    """von Mises stress of (sxx, syy, szz, sxy) [..., 4], Pa."""
    sxx, syy, szz, sxy = s[..., 0], s[..., 1], s[..., 2], s[..., 3]
    return np.sqrt(0.5 * ((sxx - syy) ** 2 + (syy - szz) ** 2 + (szz - sxx) ** 2)
                   + 3.0 * sxy**2)


def hertz_checks(run: LineRun) -> list[dict[str, Any]]:
    """p0 (peak nodal pressure) and a (ellipse fit) at the end of the normal load, 2 %."""
    p0, a = run.case.hertz
    st = run.results.contact[run.results.at(2.0)]
    a_fit, _ = half_width_fit(st, p0)
    return [check("hertz_p0", float(st.pressure.max()), p0, 0.02),
            check("hertz_a", a_fit, a, 0.02),
            check("normal_force", float(run.results.normal_force[run.results.at(2.0)]),
                  run.case.load, 1e-3)]


def yield_checks(run: LineRun) -> list[dict[str, Any]]:
    """p0 / max von Mises in the flat (Johnson: 1.79) and the depth of the maximum / a."""
    p0, a = run.case.hertz
    elems, s = run.results.ip_stress(2.0, "FINE")
    lower = np.isin(elems, run.mesh.element_sets["LOWER"])
    xy = ip_coordinates(run.mesh.nodes[run.mesh.elements[elems[lower] - 1]])
    vm = von_mises_plane_strain(s[lower])
    k = np.unravel_index(int(np.argmax(vm)), vm.shape)
    p0_fe = float(run.results.contact[run.results.at(2.0)].pressure.max())
    depth = -float(xy[k][1])
    h = run.mesh.h_fine
    return [check("first_yield_p0_over_vm", p0_fe / float(vm[k]), YIELD_FACTOR, 0.05),
            check("first_yield_depth (m)", depth, YIELD_DEPTH * a, max(0.05 * YIELD_DEPTH * a, h),
                  absolute=True)]


def tangential_checks(run: LineRun, ratios: tuple[float, ...] = (0.35, 0.55, 0.75)
                      ) -> list[dict[str, Any]]:
    """Cattaneo-Mindlin stick zone and Q(delta) at the increments whose Q / (mu P) is nearest
    to ``ratios``, and gross slip at the last increment of the first stroke."""
    case, res = run.case, run.results
    p0, a = case.hertz
    mu, e_star = case.contact.mu, case.e_star
    k_load = res.at(2.0)
    ref_state = res.contact[k_load]
    steps = np.flatnonzero((res.times > 2.0 + 1e-9) & (res.times <= 3.0 + 1e-9))
    mu_p = mu * res.normal_force[k_load]
    qs = -res.tangential_force[steps]  # the pad moves +x: friction on it is -x
    ds = res.ref_displacement[steps, 0]
    out = [check("gross_slip_Q_over_muP", float(qs[-1] / mu_p), 1.0, 0.01)]
    # full-stick compliance of the model, from the first increment
    compliance = (ds[0] - slip_displacement(qs[0], mu_p, e_star)) / qs[0]
    k_t = case.contact.stick_slope(case.lower.young, case.upper.young, run.mesh.h_fine)
    used: set[int] = set()
    for target in ratios:
        cand = [j for j in range(1, steps.size) if j not in used and qs[j] / mu_p < 0.95]
        if not cand:
            break
        j = min(cand, key=lambda jj: abs(qs[jj] / mu_p - target))
        used.add(j)
        r = qs[j] / mu_p
        st = res.contact[int(steps[j])]
        c, dx = stick_half_width(st, ref_state, p0, mu, k_t)
        c_ref = a * math.sqrt(1.0 - r)
        out.append(check(f"mindlin_c (m) at Q/muP={r:.2f}", c, c_ref,
                         max(0.05 * c_ref, dx), absolute=True))
        q_ref = brentq(lambda q, d=ds[j]: compliance * q + slip_displacement(q, mu_p, e_star)
                       - d, 1e-12 * mu_p, mu_p * (1 - 1e-12))
        out.append(check(f"Q(delta={ds[j]:.3g} m)", float(qs[j]), q_ref, 0.03))
        out.append(check(f"slip_displacement (m) at Q/muP={r:.2f}",
                         float(ds[j] - compliance * qs[j]),
                         slip_displacement(qs[j], mu_p, e_star),
                         0.15 * slip_displacement(qs[j], mu_p, e_star), absolute=True))
    return out


def plastic_onset_case(h_over_a: float | None = None) -> LineCase:
    """EN24T with bilinear hardening (Y 680 MPa) loaded to 1.15 x Johnson's first-yield load
    P_y = pi R (1.79 Y)^2 / E* in 20 increments, no tangential step."""
    y = EN24T.yield_strength
    mat = FEMaterial(yield_strength=y)
    kw: dict[str, Any] = {} if h_over_a is None else {"h_over_a": h_over_a}
    probe = LineCase(lower=mat, upper=mat, **kw)
    p_y = math.pi * probe.radius * (YIELD_FACTOR * y) ** 2 / probe.e_star
    return dataclasses.replace(probe, load=1.15 * p_y, load_increments=20)


def plastic_onset_check(run: LineRun) -> list[dict[str, Any]]:
    """Hertz p0 / Y at the onset of plastic strain (PEEQ > 0 anywhere in the fine zones):
    linear extrapolation to zero of the peak PEEQ of the first two plastic increments, kept
    inside the bracket (last elastic, first plastic increment); reference 1.79, 5 %."""
    case, res = run.case, run.results
    y = float(case.lower.yield_strength or 0.0)
    k_load = [k for k, t in enumerate(res.times) if 1.0 + 1e-9 < t <= 2.0 + 1e-9]
    p0 = np.array([math.sqrt(res.normal_force[k] * case.e_star / (math.pi * case.radius))
                   for k in k_load])
    peeq = np.array([res.peeq(float(res.times[k]))[1].max() for k in k_load])
    plastic = np.flatnonzero(peeq > 0.0)
    if plastic.size < 2 or plastic[0] == 0:
        value = float("nan") if plastic.size == 0 else float(p0[plastic[0]])
    else:
        i = int(plastic[0])
        slope = (peeq[i + 1] - peeq[i]) / (p0[i + 1] - p0[i])
        value = float(np.clip(p0[i] - peeq[i] / slope, p0[i - 1], p0[i]))
    out = check("plastic_onset_p0_over_Y", value / y, YIELD_FACTOR, 0.05)
    if not math.isfinite(value):
        out["pass"] = False
    return [out]


def default_case(h_over_a: float | None = None) -> LineCase:
    """The validation case: EN24T pad R 4 mm on a flat, 100 N/mm (p0 1.02 GPa < 1.79 Y:
    elastic), bodies 2 x 40 a wide and 40 a high, stroke 3 um in 10 increments (gross slip
    from about 2 um), with the fretting backend's contact set-up
    (:func:`tribodem.contact.fe.deck.sliding_contact`: node-to-surface)."""
    kw: dict[str, Any] = {} if h_over_a is None else {"h_over_a": h_over_a}
    case = LineCase(load=1e5, delta=3e-6, n_increments=40, half_cycle=True, **kw)
    return dataclasses.replace(case, contact=sliding_contact(case.contact.mu, case.hertz[0]))


def reversal_checks(folder: str | Path, threads: int = 1, timeout: float = 900.0
                    ) -> list[dict[str, Any]]:
    """Gross slip through the reversals of a full cycle whose stroke crosses elements
    (docs/fe.md, "Reversals"): the ``fe`` backend's own job (node-to-surface, one step per
    quarter) on the validation case at h = a/2, A = 2 a (4 elements), 16 increments
    (every one slides 0.5 a, far past the ~3 um where gross slip is reached):
    |Q| / (mu P) at every increment within 1 % of 1 (the worst one reported), and Q opposing
    the pad's motion at every increment (count of wrong signs, 0 allowed)."""
    from tribodem.contact.fe.backend import FEContactSolver

    case = default_case()
    p0, a = case.hertz
    window = 10.0 * a
    pad = ContactCase(upper=cylinder(2.0 * case.radius, axis="y"), lower=flat(),
                      upper_material=ElasticBody(), lower_material=ElasticBody(),
                      load=case.load * window, friction=0.6, amplitude=2.0 * a,
                      n_increments=16, n=64, window=window, contact="line")
    s = FEContactSolver(pad, FEOptions(h_over_a=0.5, threads=threads, timeout=timeout),
                        workdir=Path(folder) / "reversal")
    s.reset()
    s.solve_increment(0.0)
    s.begin_cycle()
    res = s.results
    assert res is not None
    k = [res.at(float(t)) for t in s.cycle_times(1)]
    q = res.tangential_force[k] / (case.contact.mu * res.normal_force[k])
    direction = np.sign(np.diff(np.concatenate([[0.0], s.offsets])))
    worst = int(np.argmax(np.abs(np.abs(q) - 1.0)))
    wrong = int(np.sum(np.sign(q) != -direction))
    return [check(f"reversal_gross_slip_Q_over_muP (worst of 16, increment {worst + 1})",
                  float(abs(q[worst])), 1.0, 0.01),
            check("reversal_Q_sign_errors", float(wrong), 0.0, 0.0, absolute=True)]


def validate_fe(folder: str | Path, threads: int = 1, timeout: float = 900.0,
                h_over_a: float | None = None, plastic: bool = True,
                reversals: bool = True) -> list[dict[str, Any]]:
    """Run :func:`default_case` (and :func:`plastic_onset_case`, :func:`reversal_checks`)
    in sub-folders ``elastic`` (``plastic``, ``reversal``) of ``folder``; return every
    check."""
    folder = Path(folder)
    run = run_line_case(default_case(h_over_a), folder / "elastic", threads=threads,
                        timeout=timeout)
    out = hertz_checks(run) + yield_checks(run) + tangential_checks(run)
    if reversals:
        out += reversal_checks(folder, threads=threads, timeout=timeout)
    if plastic:
        prun = run_line_case(plastic_onset_case(h_over_a), folder / "plastic", threads=threads,
                             timeout=timeout)
        out += plastic_onset_check(prun)
    return out


def main(argv: list[str] | None = None) -> int:
    """``python -m tribodem.contact.fe.validate [folder] [--threads N]``: run the checks,
    print one JSON line each; exit status 1 if any fails."""
    import argparse
    import json
    import tempfile

    ap = argparse.ArgumentParser(description="closed-form checks of the ccx FE backend")
    ap.add_argument("folder", nargs="?", help="keep the ccx jobs here (default: temporary)")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--h-over-a", type=float, default=None)
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="tribodem_fe_") as tmp:
        checks = validate_fe(args.folder or tmp, threads=args.threads, h_over_a=args.h_over_a)
    for c in checks:
        print(json.dumps(c))
    return 0 if all(c["pass"] for c in checks) else 1


if __name__ == "__main__":
    raise SystemExit(main())
