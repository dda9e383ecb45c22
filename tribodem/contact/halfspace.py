"""Half-space BEM backend on tamaas (DESIGN.md "The fretting FE-DE model", backend 1).

Model (Lu (2018) sections 3.3 and 6.1, replacing the Abaqus FE phase):

* Normal problem: frictionless elastic contact of the two surfaces, reduced to a rigid
  surface (the summed recessions) on an elastic half-space of contact modulus
  E* = 1 / ((1 - nu1^2)/E1 + (1 - nu2^2)/E2), solved under load control by
  :class:`tamaas.PolonskyKeerRey` on a periodic square window of ``n x n`` points that moves
  with the upper body. Non-dimensional inside (length: window side, stress: E*).
* Tangential problem, gross slip (stroke >> contact radius, the default): q = mu p opposing
  the relative sliding direction; exact for elastically similar bodies (Dundurs beta = 0, no
  normal-tangential coupling). Slip increment = rigid relative displacement increment at
  every contact point (the elastic tangential compliance, a few um against a 600 um stroke,
  is neglected).
* Tangential problem, ``regime="ciavarella-jaeger"``: partial slip after every reversal by
  the Ciavarella-Jaeger superposition q = q_rev - s f mu (p - p*) (f = 1 on first loading,
  2 after a reversal, s the sliding sign), p* the normal solution of the same gap at the
  reduced true approach d* = d - |offset - offset_rev| / (f mu kappa), stick zone = contact
  of p*; kappa = sum (2 - nu_i)/G_i / (2 sum (1 - nu_i)/G_i) is Mindlin's tangential to
  normal compliance ratio (3-D superposition approximate: Cerruti's nu x^2/r^3 term is
  neglected, as in Mindlin's solution). Accumulated slip since the reversal:
  f mu kappa gap*(x) in partial slip, offset change - f mu kappa (d - g(x)) in gross slip,
  so the dissipated energy includes the elastic tangential compliance exactly (within the
  approximation) whatever the increment size. Gross slip reached after 2 mu kappa d.
* Line contact (``contact="line"``, e.g. a cylinder with its axis along y on a flat): when
  the summed recession does not depend on y, the periodic window is an infinitely long
  contact along y (plane strain) and tamaas's periodic BEM solves it as it is; ``load`` is
  the total load on the window, i.e. P' = load / window per unit length. Only the x edges
  are checked for the contact (it touches both y edges by design). The rigid approach of a
  line contact is undefined on a half-space (logarithmic), so the Ciavarella-Jaeger regime
  (built on the point-contact approach) and the debris pressure are refused for it.
* Subsurface stress under each body: tamaas ``volume_2d`` model with the Boussinesq-Cerruti
  gradient and Hooke operators applied to that body's surface traction (normal + shear).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, ClassVar, Literal

import numpy as np
import tamaas as tm
from numpy.typing import NDArray
from pydantic import BaseModel

from tribodem.contact.base import (
    BODIES,
    Body,
    Capabilities,
    ContactCase,
    ElasticBody,
    FirstBodySolver,
    IncrementResult,
    SubsurfaceStress,
    WindowTooSmallError,
    check_positive,
    checked_debris_pressure,
    contact_modulus,
    dundurs_beta,
    mindlin_kappa,
)
from tribodem.contact.geometry import HertzSphere, Recession, crossed_cylinders, line_window
from tribodem.contact.line import LineContactSolver
from tribodem.contact.options import ElasticOptions, option_table

tm.set_log_level(tm.LogLevel.error)

REGIMES = ("gross", "ciavarella-jaeger")

#: offsets whose normal solution is kept as the initial guess for the next visit
_WARM_STARTS = 64


def model_fields(model: tm.Model) -> dict[str, NDArray[np.float64]]:
    """Copies of every field of a tamaas model (tamaas objects cannot be pickled)."""
    return {k: np.array(model[k], dtype=float) for k in list(model)}


def set_model_fields(model: tm.Model, fields: dict[str, NDArray[np.float64]]) -> None:
    """Write :func:`model_fields` back into a model of the same discretisation, in place."""
    have = set(model)
    for k, v in fields.items():
        if k not in have:  # registered by a solver on first use (e.g. 'gap')
            model[k] = np.array(v, dtype=float)
            continue
        dst = model[k]
        if np.shape(dst) != np.shape(v):
            raise ValueError(f"tamaas field {k!r}: shape {np.shape(v)} does not fit "
                             f"{np.shape(dst)}")
        dst[...] = v


def _curvatures(upper: Recession, lower: Recession) -> tuple[float, float]:
    """Curvatures (kx, ky) (1/m) of the summed recession at the origin (10 um differences)."""
    h = 1e-5
    z = np.zeros(1)

    def g(x: float, y: float) -> float:
        xs, ys = z + x, z + y
        return float(upper(xs, ys)[0] + lower(xs, ys)[0])

    kx = (g(h, 0) + g(-h, 0) - 2 * g(0, 0)) / h**2
    ky = (g(0, h) + g(0, -h) - 2 * g(0, 0)) / h**2
    return kx, ky


def estimate_contact_radius(
    upper: Recession, lower: Recession, load: float, modulus: float
) -> float:
    """Hertz contact radius from the curvatures of the summed recession at the origin, m."""
    kx, ky = _curvatures(upper, lower)
    if not (kx > 0 and ky > 0):
        raise ValueError(
            "window is None but the summed recession has no positive curvature at the origin "
            f"(kx = {kx:.3g}, ky = {ky:.3g} 1/m): give window (m) explicitly"
        )
    return HertzSphere(1.0 / math.sqrt(kx * ky), load, modulus).contact_radius


class HalfSpaceSolver(FirstBodySolver):
    """Elastic half-space first-body solver (tamaas); SI in and out.

    Defaults: crossed cylinders of 8 mm diameter (axes: upper along y, lower along x, stroke
    along x), 100 N, friction 0.6, EN24T on both sides, 256 x 256 window of 10 Hertz contact
    radii (about 1.3 mm, dx about 5.1 um), ``regime="gross"``.

    ``upper``/``lower`` are recessions (callables or :class:`HeightMap`, m); ``load`` N;
    ``window`` (m) is the side of the periodic window; when None it is ``window_radii``
    Hertz radii estimated from the summed recession's curvature at the origin (10 um
    finite differences: give ``window`` explicitly for coarse height maps). ``regime`` is
    ``"gross"`` (q = mu p) or ``"ciavarella-jaeger"`` (partial slip after reversals).

    ``contact``: ``"point"``, ``"line"`` or None (found: a line contact when the summed
    recession on the window does not depend on y). For a line contact ``load`` is the total
    load on the window (P' = load / window, N/m), the default window holds ``window_radii``
    Hertz half-widths (W^3 = k^2 4 P R / (pi E*)), only the x edges are checked, and
    ``regime`` must be ``"gross"``.
    """

    name = "elastic"
    capabilities = Capabilities(partial_slip=True, subsurface=True, debris=True,
                                contacts=("point", "line"), repeatable=True)
    options: ClassVar[dict[str, type[BaseModel]]] = {"elastic": ElasticOptions}

    @classmethod
    def from_case(cls, case: ContactCase, options: Mapping[str, BaseModel] | None = None
                  ) -> FirstBodySolver:
        """The elastic backend on ``case``. A line contact of an analytic geometry
        (``case.contact == "line"``, a cylinder on a flat) is solved on one cross-section
        with the plane-strain influence function (:class:`LineContactSolver`) unless
        ``[elastic] line_model = "periodic-2d"`` (:class:`ElasticOptions`) asks for this
        class's n x n window periodic along the cylinder's axis; everything else here."""
        elastic = option_table(options, "elastic", ElasticOptions)
        if cls is HalfSpaceSolver and case.contact == "line" and \
                elastic.line_model == "plane-strain":
            return LineContactSolver.from_case(case)
        return super().from_case(case, options)

    def __init__(
        self,
        upper: Recession | None = None,
        lower: Recession | None = None,
        load: float = 100.0,
        friction: float = 0.6,
        upper_material: ElasticBody | None = None,
        lower_material: ElasticBody | None = None,
        n: int = 256,
        window: float | None = None,
        window_radii: float = 10.0,
        tolerance: float = 1e-10,
        regime: str = "gross",
        contact: Literal["point", "line"] | None = None,
    ) -> None:
        if (upper is None) != (lower is None):
            raise ValueError("upper and lower must both be given or both be None (defaults)")
        if upper is None or lower is None:
            upper, lower = crossed_cylinders()
        self.upper, self.lower = upper, lower
        self.load = check_positive("load", load)
        self.friction = check_positive("friction", friction, allow_zero=True)
        self.upper_material = upper_material or ElasticBody()
        self.lower_material = lower_material or ElasticBody()
        if int(n) != n or n < 16 or n % 2:
            raise ValueError(f"n = {n!r} is not allowed: must be an even integer >= 16")
        self.n = int(n)
        if regime not in REGIMES:
            raise ValueError(
                f"regime = {regime!r} is not allowed: use 'gross' (q = mu p) or "
                "'ciavarella-jaeger' (partial slip after reversals)"
            )
        self.regime = regime
        self.tolerance = check_positive("tolerance", tolerance)
        self.modulus = contact_modulus(self.upper_material, self.lower_material)
        self.beta = dundurs_beta(self.upper_material, self.lower_material)
        if contact not in (None, "point", "line"):
            raise ValueError(f"contact = {contact!r} is not allowed: use 'point', 'line' or "
                             "None (found from the surfaces)")
        if window is None:
            k = check_positive("window_radii", window_radii)
            kx, ky = _curvatures(upper, lower)
            if contact == "line" or (contact is None and kx > 0 and ky == 0.0):
                if not kx > 0:
                    raise ValueError("window is None but the line contact's summed recession "
                                     f"has no positive curvature along x (kx = {kx:.3g} 1/m):"
                                     " give window (m) explicitly")
                window = line_window(1.0 / kx, self.load, self.modulus, k)
            else:
                window = k * estimate_contact_radius(upper, lower, self.load, self.modulus)
        self.dx = check_positive("window", window) / self.n
        g0 = HalfSpaceSolver.gap(self, 0.0)  # the surfaces alone (no subclass additions)
        along_y = float(np.ptp(g0, axis=1).max())
        flat_y = along_y <= 1e-12 * max(float(np.ptp(g0)), 1e-300)
        if contact == "line" and not flat_y:
            raise ValueError(f"contact = 'line' but the summed recession varies by {along_y:.3g}"
                             " m along y on the window: a line contact's surfaces must not "
                             "depend on y (axis along y)")
        #: the contact type: "line" (periodic along y, plane strain) or "point"
        self.contact: Literal["point", "line"] = contact or ("line" if flat_y else "point")
        if self.contact not in type(self).capabilities.contacts:
            raise ValueError(f"a {self.contact} contact is not solved by {type(self).__name__}"
                             f" (it solves: {', '.join(type(self).capabilities.contacts)})")
        if self.contact == "line" and self.regime != "gross":
            raise ValueError(f"regime = {self.regime!r} is not allowed for a line contact: the "
                             "Ciavarella-Jaeger superposition here uses the point contact's "
                             "rigid approach, undefined for a line contact; use 'gross'")
        self._model = tm.ModelFactory.createModel(
            tm.model_type.basic_2d, [1.0, 1.0], [self.n, self.n]
        )
        self._model.E = 1.0
        self._model.nu = 0.0
        self._model_star = tm.ModelFactory.createModel(self._model)
        #: Mindlin tangential / normal compliance ratio kappa (1.214 for nu = 0.3)
        self.kappa = mindlin_kappa(self.upper_material, self.lower_material)
        c = np.arange(-self.n + 1, self.n) * self.dx
        xe, ye = np.meshgrid(c, c, indexing="ij")
        self._kernel = _cell_integral(xe, ye, self.dx)  # int over a cell of 1/r, m
        self.set_debris_pressure(None)
        self.reset()

    def reset(self) -> None:
        self._offset: float | None = None
        self._direction = 0.0
        self._model.traction[:] = 0.0
        self._rev_offset = 0.0
        self._rev_traction = np.zeros((self.n, self.n))
        self._factor = 1.0
        self._slip_acc = np.zeros((self.n, self.n))
        self._traction = np.zeros((self.n, self.n))
        # normal solution (model traction) last found at each offset: the initial guess when
        # that offset comes back (next cycle's geometry differs only by one cycle's wear)
        self._warm: dict[float, NDArray[np.float64]] = {}

    def state_dict(self) -> dict[str, Any]:
        """The load history, for a checkpoint: everything :meth:`reset` clears plus the
        debris pressure and the tamaas models' fields (the warm starts of the normal
        solves), as floats and numpy arrays. The surfaces (``upper``, ``lower``) are not
        included: their owner sets them. :meth:`load_state_dict` restores it bitwise."""
        keys = list(self._warm)
        n = self.n
        return {
            "offset": self._offset, "direction": self._direction,
            "rev_offset": self._rev_offset, "rev_traction": self._rev_traction.copy(),
            "factor": self._factor, "slip_acc": self._slip_acc.copy(),
            "traction": self._traction.copy(),
            "warm_keys": np.array(keys, dtype=float),
            "warm": (np.stack([self._warm[k] for k in keys]) if keys
                     else np.zeros((0, n, n))),
            "model": model_fields(self._model),
            "model_star": model_fields(self._model_star),
            "debris_pressure": self.debris_pressure.copy(), "debris_load": self.debris_load,
            "debris_u": self._debris_u.copy(),
        }

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore :meth:`state_dict` (same grid: ``ValueError`` otherwise)."""
        n = self.n
        if np.shape(state["traction"]) != (n, n):
            raise ValueError(f"solver state of shape {np.shape(state['traction'])} does not "
                             f"fit this solver's ({n}, {n}) window")
        self._offset = state["offset"]
        self._direction = float(state["direction"])
        self._rev_offset = float(state["rev_offset"])
        self._rev_traction = np.array(state["rev_traction"], dtype=float)
        self._factor = float(state["factor"])
        self._slip_acc = np.array(state["slip_acc"], dtype=float)
        self._traction = np.array(state["traction"], dtype=float)
        self._warm = {float(k): np.array(w, dtype=float)
                      for k, w in zip(state["warm_keys"], state["warm"], strict=True)}
        set_model_fields(self._model, state["model"])
        set_model_fields(self._model_star, state["model_star"])
        self._debris_pressure = np.array(state["debris_pressure"], dtype=float)
        self._debris_load = float(state["debris_load"])
        self._debris_u = np.array(state["debris_u"], dtype=float)

    def set_debris_pressure(self, pressure: NDArray[np.float64] | None) -> None:
        """Prescribe the debris (third-body) pressure on the window, Pa [n, n] (None clears).

        Lu (2018) section 3.2.7 (forces mapped back): the debris load acts on both bodies;
        their elastic displacement under it, u_d = (1 / (pi E*)) int p_d / r dA (exact cell
        integrals, not periodic), opens the gap, and the solid-solid contact carries the rest
        of the load, ``load - debris_load``. Kept until cleared (``reset`` keeps it too).
        """
        n = self.n
        if pressure is None:
            self._debris_pressure = np.zeros((n, n))
            self._debris_load = 0.0
            self._debris_u = np.zeros((n, n))
            return
        if self.contact == "line":
            raise ValueError("a debris pressure is not available for a line contact (its "
                             "displacement here is the non-periodic point-contact integral)")
        from scipy.signal import fftconvolve  # here: scipy.signal takes 0.5 s to import

        pd, self._debris_load = checked_debris_pressure(pressure, n, self.dx, self.load)
        self._debris_pressure = pd
        u = fftconvolve(pd, self._kernel, mode="full")[n - 1 : 2 * n - 1, n - 1 : 2 * n - 1]
        self._debris_u = u / (math.pi * self.modulus)

    def loaded_solution(
        self, offset: float = 0.0, debris: bool = False
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(pressure Pa, gap m) of the normal contact at ``offset`` under the full load,
        without (``debris=False``) or with the prescribed debris pressure (the returned
        pressure is then solid + debris). Leaves the cycle's load history untouched."""
        if not debris:
            return self._normal(self.gap(offset), self.load, self._model_star)
        p, gap = self._normal(self.gap(offset) + self._debris_u, self.solid_load,
                              self._model_star)
        return p + self.debris_pressure, gap

    @property
    def solid_load(self) -> float:
        """Load carried by the solid-solid contact: applied minus debris load, N."""
        return self.load - self.debris_load

    def approach(self, pressure: NDArray[np.float64], gap: NDArray[np.float64]) -> float:
        """True (non-periodic) half-space rigid approach d of a solution, m.

        d = g(x0) - min g + u(x0) at the peak-pressure point x0, with u the sum of both
        bodies' normal displacements, (1 / (pi E*)) int p / r dA, cell by cell exactly.
        """
        i, j = np.unravel_index(int(np.argmax(pressure)), pressure.shape)
        n = self.n
        k = self._kernel[n - 1 - i : 2 * n - 1 - i, n - 1 - j : 2 * n - 1 - j]
        u = float((k * pressure).sum()) / (math.pi * self.modulus)
        return float(gap[i, j] - gap.min()) + u

    def gap(self, offset: float) -> NDArray[np.float64]:
        """Summed recession on the window with the upper body at ``offset`` (m), [n, n], m."""
        c = self.coords
        xw, yw = np.meshgrid(c, c, indexing="ij")
        return np.asarray(self.upper(xw, yw) + self.lower(xw + offset, yw), dtype=float)

    def _normal(
        self, g: NDArray[np.float64], load: float, model: tm.Model | None = None
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Pressure (Pa) and gap (m) of the load-controlled normal problem on gap ``g``."""
        model = self._model if model is None else model
        gt = (g - g.min()) / self.window
        surface = np.ascontiguousarray(-gt)
        solver = tm.PolonskyKeerRey(model, surface, self.tolerance)
        solver.max_iter = 10000
        solver.solve(load / (self.window**2 * self.modulus))
        p = np.array(model.traction, dtype=float) * self.modulus
        gap = np.array(model.displacement, dtype=float) + gt
        gap = np.where(p > 0.0, 0.0, np.maximum(gap - gap[p > 0.0].mean(), 0.0)) * self.window
        return p, gap

    def _check_window(self, p: NDArray[np.float64], offset: float) -> None:
        """Refuse a contact on the window edge: all four for a point contact, the two x
        edges for a line contact (periodic along y by design)."""
        edge = max(p[0].max(), p[-1].max())
        if self.contact == "point":
            edge = max(edge, p[:, 0].max(), p[:, -1].max())
        if edge > 0.0:
            raise WindowTooSmallError(
                f"contact touches the window edge at offset {offset:.4g} m (window "
                f"{self.window:.4g} m, n {self.n}): enlarge window"
            )

    def _reduced(
        self, g: NDArray[np.float64], d_star: float, load: float, d: float
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Normal solution (p*, gap*) of gap ``g`` at true approach ``d_star`` < d, m."""
        lo, hi = 0.0, load  # bracket on the load; d(P) is increasing
        p_star = load * (d_star / d) ** 1.5
        for _ in range(40):
            p, gap = self._normal(g, p_star, self._model_star)
            dd = self.approach(p, gap)
            if abs(dd - d_star) <= 1e-6 * d:
                break
            if dd > d_star:
                hi = p_star
            else:
                lo = p_star
            guess = p_star * (d_star / dd) ** 1.5
            p_star = guess if lo < guess < hi else 0.5 * (lo + hi)
        return p, gap

    def solve_increment(self, offset: float) -> IncrementResult:
        offset = float(offset)
        if not math.isfinite(offset):
            raise ValueError(f"offset = {offset!r} is not allowed: must be finite (m)")
        start = offset if self._offset is None else self._offset
        step = offset - start
        if step != 0.0:
            new_dir = math.copysign(1.0, step)
            if self._direction != 0.0 and new_dir != self._direction:
                # reversal: Masing memory of the last reversal point and its traction
                self._rev_offset, self._factor = start, 2.0
                self._rev_traction = self._traction.copy()
                self._slip_acc[:] = 0.0
            self._direction = new_dir
        g = self.gap(offset) + self._debris_u
        key = round(offset / self.dx, 9)
        warm = self._warm.get(key)
        if warm is not None:
            self._model.traction[:] = warm
        p, gap = self._normal(g, self.solid_load)
        if key in self._warm or len(self._warm) < _WARM_STARTS:
            self._warm[key] = np.array(self._model.traction, dtype=float)
        self._check_window(p, offset)
        contact = p > 0.0
        qx = np.zeros_like(p)
        slip_x = np.zeros_like(p)
        stick = None
        if self._direction != 0.0 and self.regime == "gross":
            qx = -self.friction * p * self._direction
            slip_x[contact] = step
        elif self._direction != 0.0:
            qx, acc, stick = self._ciavarella_jaeger(g, p, gap, offset)
            slip_x = np.where(contact, self._direction * (acc - self._slip_acc), 0.0)
            self._slip_acc = acc
        self._traction = qx
        self._offset = offset
        cell = self.dx**2
        return IncrementResult(
            offset=offset,
            start_offset=start,
            direction=self._direction,
            pressure=p,
            traction=np.stack([qx, np.zeros_like(qx)], axis=-1),
            slip=np.stack([slip_x, np.zeros_like(slip_x)], axis=-1),
            contact_area=float(contact.sum() * cell),
            normal_load=float(p.sum() * cell),
            stick=stick,
        )

    def _ciavarella_jaeger(
        self,
        g: NDArray[np.float64],
        p: NDArray[np.float64],
        gap: NDArray[np.float64],
        offset: float,
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_]]:
        """(q_x on the upper body, accumulated slip since reversal, stick mask)."""
        mu, f, s = self.friction, self._factor, self._direction
        travel = abs(offset - self._rev_offset)
        d = self.approach(p, gap)
        d_star = d - travel / (f * mu * self.kappa) if mu > 0 else -1.0
        gt = g - g.min()
        if d_star <= 0.0:  # gross slip
            qx = -s * mu * p
            acc = np.where(p > 0, np.maximum(travel - f * mu * self.kappa * (d - gt), 0.0), 0.0)
            return qx, acc, np.zeros(p.shape, dtype=bool)
        if travel == 0.0:
            return self._rev_traction.copy(), np.zeros_like(p), p > 0
        p_star, gap_star = self._reduced(g, d_star, self.solid_load, d)
        qx = self._rev_traction - s * f * mu * (p - p_star)
        qx = np.clip(qx, -mu * p, mu * p)
        acc = np.where(p > 0, f * mu * self.kappa * gap_star, 0.0)
        return qx, acc, p_star > 0

    def subsurface_stress(
        self,
        result: IncrementResult,
        body: Body = "lower",
        depth: float | None = None,
        nz: int = 33,
    ) -> SubsurfaceStress:
        """Stress under ``body`` for a solved increment (frame: x, y, z = depth into body).

        ``depth`` defaults to 3 equivalent contact radii sqrt(area / pi) (line contact: 3
        half-widths, area / (2 window)). The lower body's
        window centre lies at lab x = ``result.offset``. Shear traction applied: ``traction``
        on the upper body, ``-traction`` on the lower one.
        """
        if body not in BODIES:
            raise ValueError(f"body = {body!r} is not allowed: use 'upper' or 'lower'")
        if int(nz) != nz or nz < 2:
            raise ValueError(f"nz = {nz!r} is not allowed: must be an integer >= 2")
        if result.pressure.shape != (self.n, self.n):
            raise ValueError(
                f"result.pressure has shape {result.pressure.shape}: expected ({self.n}, "
                f"{self.n}) from this solver"
            )
        if depth is None and self.contact == "line":
            depth = 3.0 * max(result.contact_area, self.dx**2) / (2.0 * self.window)
        elif depth is None:
            depth = 3.0 * math.sqrt(max(result.contact_area, self.dx**2) / math.pi)
        depth = check_positive("depth", depth)
        mat = self.upper_material if body == "upper" else self.lower_material
        sign = 1.0 if body == "upper" else -1.0
        nz = int(nz)
        vol = tm.ModelFactory.createModel(
            tm.model_type.volume_2d, [depth / self.window, 1.0, 1.0], [nz, self.n, self.n]
        )
        vol.E = 1.0
        vol.nu = mat.poisson
        tm.ModelFactory.registerVolumeOperators(vol)
        vol.traction[..., 0] = sign * result.traction[..., 0] / self.modulus
        vol.traction[..., 1] = sign * result.traction[..., 1] / self.modulus
        vol.traction[..., 2] = result.pressure / self.modulus
        vol.operators["boussinesq_gradient"](vol.traction, vol["strain"])
        vol.operators["hooke"](vol["strain"], vol["stress"])
        raw = np.asarray(vol["stress"])
        # tamaas 2.9 order: xx, yy, zz, xy, xz, yz, shear in Mandel notation (x sqrt 2);
        # reorder to VOIGT_ORDER (xx, yy, zz, yz, xz, xy) with true shear components.
        stress = raw[..., [0, 1, 2, 5, 4, 3]] * self.modulus
        del raw, vol
        stress[..., 3:] /= math.sqrt(2.0)
        return SubsurfaceStress(
            body=body,
            z=np.linspace(0.0, depth, nz),
            x=self.coords,
            y=self.coords,
            stress=stress,
            von_mises=von_mises(stress),
            tresca=max_shear(stress),
        )


def _cell_integral(x: NDArray[np.float64], y: NDArray[np.float64], h: float) -> NDArray[np.float64]:
    """Integral of 1/r over the square cell of side ``h`` centred at (x, y), m."""

    def prim(u: NDArray[np.float64], v: NDArray[np.float64]) -> NDArray[np.float64]:
        r = np.hypot(u, v)
        with np.errstate(divide="ignore", invalid="ignore"):
            a = np.where(u != 0, u * np.log((v + r) / np.abs(u)), 0.0)
            b = np.where(v != 0, v * np.log((u + r) / np.abs(v)), 0.0)
        return np.nan_to_num(a) + np.nan_to_num(b)

    x1, x2, y1, y2 = x - h / 2, x + h / 2, y - h / 2, y + h / 2
    return prim(x2, y2) - prim(x1, y2) - prim(x2, y1) + prim(x1, y1)


def von_mises(stress: NDArray[np.float64]) -> NDArray[np.float64]:
    """Von Mises stress of Voigt stresses [..., 6] (xx, yy, zz, yz, xz, xy), Pa."""
    s = stress
    j2 = (
        (s[..., 0] - s[..., 1]) ** 2 + (s[..., 1] - s[..., 2]) ** 2 + (s[..., 2] - s[..., 0]) ** 2
    ) / 6.0 + (s[..., 3:] ** 2).sum(-1)
    return np.sqrt(3.0 * j2)


def max_shear(stress: NDArray[np.float64]) -> NDArray[np.float64]:
    """Maximum shear (Tresca) stress (s1 - s3) / 2 of Voigt stresses [..., 6], Pa."""
    s = np.asarray(stress, dtype=float)
    flat = s.reshape(-1, 6)
    out = np.empty(flat.shape[0])
    chunk = 1 << 16
    for i in range(0, flat.shape[0], chunk):
        c = flat[i : i + chunk]
        t = np.empty((c.shape[0], 3, 3))
        t[:, 0, 0], t[:, 1, 1], t[:, 2, 2] = c[:, 0], c[:, 1], c[:, 2]
        t[:, 1, 2] = t[:, 2, 1] = c[:, 3]
        t[:, 0, 2] = t[:, 2, 0] = c[:, 4]
        t[:, 0, 1] = t[:, 1, 0] = c[:, 5]
        ev = np.linalg.eigvalsh(t)
        out[i : i + chunk] = 0.5 * (ev[:, -1] - ev[:, 0])
    return out.reshape(s.shape[:-1])
