"""Elastic-plastic half-space backend with friction (DESIGN.md "The fretting FE-DE model").

Model (Lu (2018) section 5.2: bilinear EN24T; replaces the Abaqus elastic-plastic FE
phase), the semi-analytical method of Jacq, Nelias, Lormand and Girodin (J. Tribology 2002)
as Gallego, Nelias and Jacq use it for fretting wear (J. Tribology 2006):

* **Each body its own plastic state** (:class:`~tribodem.contact.plastic_halfspace.
  PlasticHalfSpace`): the upper body on a ``ep_n`` x ``ep_n`` grid fixed in its own
  (window) frame, the lower body on a track grid in the lab frame that covers the stroke
  (``ep_n + 2 ceil(A / dx)`` points along x), ``ep_nz`` layers to ``ep_depth_radii``
  Hertz radii; von Mises, linear isotropic hardening ``sigma_y + h p``.
* **The full surface traction drives plasticity at every increment**: after the contact
  solve of an increment (:class:`HalfSpaceSolver`: pressure p, and the tangential traction
  of its slip regime, q = mu p in gross slip or the Ciavarella-Jaeger partial-slip traction),
  the traction (q, p) on the upper body and (-q, p) on the lower one (plus the debris
  pressure on both) is applied to each body as the increment from the last one (eq 1 of
  :mod:`~tribodem.contact.plastic_halfspace`), at every sampled increment of the stroke and
  at ``load_steps`` steps of the first loading; the plastic strain, the hardening (p) and the
  residual stress and displacement are carried from increment to increment and cycle to
  cycle (never reset by the loop).
* **Coupling**: the residual (plastic) surface displacement of both bodies is added to the
  summed recession (upper: window frame, lower: lab frame under the window), so each
  contact solve sees the plastically conformed surfaces (Jacq et al.: h = h0 + u_e + u_r).
  Staggered: increment k's pressure is solved on the residual displacement after
  increment k - 1 (one plastic solve per body and increment; the lag is one increment of
  the stroke, or one load step while loading). A run whose bodies yielded cannot resume
  from a checkpoint (:meth:`load_state_dict`).
* **Outputs**: per load step and increment the plastic strain increment and the stress
  (contact plus residual) for DFDI (:meth:`plastic_steps`, one :class:`PlasticStep` per
  body); the subsurface stress is the elastic stress of the increment's tractions on the
  window grid plus the residual stress of the plastic state after the increment
  (interpolated from the plastic grid); per cycle the max equivalent plastic strain and its
  depth per body and the cycle's largest increment of it (:meth:`cycle_columns`, the
  ``results.csv`` columns), and in :meth:`report` a ``shakedown`` statement.

Limits: small strains on the undeformed half-space (no geometric non-linearity, no pile-up
geometry beyond the residual displacement); the plastic grid is periodic (images one grid
length away); elastically similar bodies only (one material for both).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar, cast

import numpy as np
from numpy.typing import NDArray

from tribodem.contact.base import (
    BODIES,
    Body,
    Capabilities,
    IncrementResult,
    SubsurfaceStress,
    check_positive,
)
from tribodem.contact.geometry import Recession
from tribodem.contact.halfspace import (
    HalfSpaceSolver,
    estimate_contact_radius,
    max_shear,
    von_mises,
)
from tribodem.contact.options import PlasticOptions, option_table
from tribodem.contact.plastic_halfspace import PlasticHalfSpace, block_average
from tribodem.io.config import ConfigError
from tribodem.materials.en24t import EN24T

if TYPE_CHECKING:
    from typing import Self

    from pydantic import BaseModel
    from scipy.interpolate import RegularGridInterpolator

    from tribodem.contact.base import ContactCase

#: EN24T (seed table 5.1): yield and ultimate tensile strength, Pa.
YIELD_EN24T = EN24T.yield_strength
UTS_EN24T = EN24T.uts
#: Engineering strain at the UTS implied by seed table 6.2 (true 1132 MPa = 1000 (1 + e)).
UTS_STRAIN_EN24T = EN24T.uts_strain


def _grid(points: tuple[NDArray[np.float64], ...], values: NDArray[np.float64],
          **kw: Any) -> RegularGridInterpolator:
    """scipy's ``RegularGridInterpolator``, imported on first use: scipy.interpolate (and
    tamaas.nonlinear_solvers, scipy.optimize) took ~0.7 s to import, which every command
    paid with this module, an exit-2 usage error as well."""
    from scipy.interpolate import RegularGridInterpolator

    return RegularGridInterpolator(points, values, **kw)


def bilinear_hardening(young: float, yield_strength: float, uts: float, uts_strain: float) -> float:
    """Plastic hardening modulus h (Pa) of the bilinear law through (sigma_y / E, sigma_y)
    and (uts_strain, UTS): tangent E_t = (UTS - sigma_y) / (uts_strain - sigma_y / E),
    h = E E_t / (E - E_t) (EN24T defaults: E_t 2.48 GPa, h 2.50 GPa)."""
    for name, v in (("young", young), ("yield_strength", yield_strength), ("uts", uts),
                    ("uts_strain", uts_strain)):
        check_positive(name, v)
    if uts <= yield_strength:
        raise ValueError(f"uts = {uts!r} is not allowed: must exceed yield_strength "
                         f"= {yield_strength!r} Pa")
    ey = yield_strength / young
    if uts_strain <= ey:
        raise ValueError(f"uts_strain = {uts_strain!r} is not allowed: must exceed the yield "
                         f"strain {ey:.4g}")
    et = (uts - yield_strength) / (uts_strain - ey)
    return young * et / (young - et)


@dataclass
class PlasticSubsurfaceStress(SubsurfaceStress):
    """:class:`SubsurfaceStress` plus the plastic state of the body on the same grid."""

    plastic_strain: NDArray[np.float64]  #: plastic strain tensor, -, [nz, n, n, 6] (Voigt)
    cumulated_plastic_strain: NDArray[np.float64]  #: equivalent plastic strain p, -, [nz, n, n]


@dataclass
class PlasticStep:
    """One plastic load step on a [nz, nx, ny] grid under a body.

    ``body`` None: one state shared by both bodies, on a grid at offset 0 (x = y
    coordinates). A backend with a state per body sets ``body`` and ``y``: the upper body's
    grid is in its own (window) frame, the lower body's in the lab frame.
    """

    z: NDArray[np.float64]  #: depths below the body's surface, m, [nz]
    x: NDArray[np.float64]  #: x coordinates, m, [nx] (and y when ``y`` is None)
    dp: NDArray[np.float64]  #: increment of the cumulated plastic strain, -, [nz, nx, ny]
    stress: NDArray[np.float64]  #: Cauchy stress at the end of the step, Pa, [nz, nx, ny, 6]
    load: float  #: normal load at the end of the step, N
    body: str | None = None  #: "upper", "lower", or None: both bodies (one shared state)
    y: NDArray[np.float64] | None = None  #: y coordinates, m, [ny] (None: y = x)


class ElastoPlasticSolver(HalfSpaceSolver):
    """Elastic-plastic first-body solver with friction: the elastic half-space contact
    solve of every increment, then both bodies' plastic states under its full traction.

    Takes every :class:`HalfSpaceSolver` argument plus: ``yield_strength`` Pa (680 MPa),
    ``hardening`` plastic modulus h Pa (None: :func:`bilinear_hardening` from ``uts`` Pa and
    ``uts_strain``), ``ep_n`` plastic grid points per side (32), ``ep_nz`` layers (12),
    ``ep_window_radii`` (5) and ``ep_depth_radii`` (2) Hertz radii, ``load_steps`` (4, the
    first loading), ``ep_tolerance`` (the plastic solve's, 1e-6), ``ep_max_iter`` (300),
    ``amplitude`` (m: the lower body's track grid covers +-amplitude; None: no stroke
    beyond the plastic window), ``shakedown_tolerance`` (a cycle whose largest increment of
    the equivalent plastic strain is below it has shaken down), ``beyond_uts`` (only
    ``"line"``). Both bodies must be of the same material.
    """

    name = "elastic-plastic"
    options: ClassVar[dict[str, type[BaseModel]]] = {"plastic": PlasticOptions}
    capabilities = Capabilities(plastic=True, plastic_every_cycle=True, partial_slip=True,
                                subsurface=True, debris=True, contacts=("point",))

    @classmethod
    def from_case(cls, case: ContactCase, options: Mapping[str, BaseModel] | None = None
                  ) -> Self:
        """The solver on ``case`` with the ``[plastic]`` table's law and plastic grid
        (:class:`~tribodem.contact.options.PlasticOptions`; its defaults when left out), the
        lower body's track grid covering ``case.amplitude``. ``ConfigError`` for
        ``plastic.beyond_uts = 'hold'``: tamaas's linear hardening goes on past the UTS."""
        plastic = option_table(options, "plastic", PlasticOptions)
        if plastic.beyond_uts != "line":
            raise ConfigError(
                f"plastic.beyond_uts = {plastic.beyond_uts!r}: solver = {cls.name!r} "
                "has linear hardening only (it goes on past the UTS); allowed: 'line', or "
                "solver = 'fe' or 'fe3d' with [fe] material = 'elastic-plastic'")
        return cls(case.upper, case.lower, **cls.case_keywords(case),
                   amplitude=case.amplitude, **plastic.model_dump())

    def __init__(
        self,
        upper: Recession | None = None,
        lower: Recession | None = None,
        *,
        yield_strength: float = YIELD_EN24T,
        hardening: float | None = None,
        beyond_uts: str = "line",
        uts: float = UTS_EN24T,
        uts_strain: float = UTS_STRAIN_EN24T,
        ep_n: int = 32,
        ep_nz: int = 12,
        ep_window_radii: float = 5.0,
        ep_depth_radii: float = 2.0,
        load_steps: int = 4,
        ep_tolerance: float = 1e-6,
        ep_max_iter: int = 300,
        amplitude: float | None = None,
        shakedown_tolerance: float = 1e-4,
        **kw: Any,
    ) -> None:
        self._ep_ready = False
        super().__init__(upper, lower, **kw)
        if self.upper_material != self.lower_material:
            raise ValueError(
                "upper_material and lower_material differ: the elastic-plastic solver needs "
                "both bodies of the same material"
            )
        if beyond_uts != "line":
            raise ValueError(f"beyond_uts = {beyond_uts!r} is not allowed: tamaas's linear "
                             "hardening goes on past the UTS; allowed: 'line' (or a ccx "
                             "solver, fe or fe3d, for 'hold')")
        mat = self.upper_material
        self.yield_strength = check_positive("yield_strength", yield_strength)
        if hardening is None:
            hardening = bilinear_hardening(mat.young, yield_strength, uts, uts_strain)
        self.hardening = check_positive("hardening", hardening, allow_zero=True)
        for name, v in (("ep_n", ep_n), ("ep_nz", ep_nz), ("load_steps", load_steps),
                        ("ep_max_iter", ep_max_iter)):
            if int(v) != v or v < 1:
                raise ValueError(f"{name} = {v!r} is not allowed: must be an integer >= 1")
        if ep_n < 8 or ep_n % 2:
            raise ValueError(f"ep_n = {ep_n!r} is not allowed: must be an even integer >= 8")
        if ep_nz < 3:
            raise ValueError(f"ep_nz = {ep_nz!r} is not allowed: must be >= 3")
        self.ep_n, self.ep_nz = int(ep_n), int(ep_nz)
        self.load_steps, self.ep_max_iter = int(load_steps), int(ep_max_iter)
        self.ep_tolerance = check_positive("ep_tolerance", ep_tolerance)
        self.shakedown_tolerance = check_positive("shakedown_tolerance", shakedown_tolerance)
        self.amplitude = 0.0 if amplitude is None else check_positive("amplitude", amplitude)
        #: Hertz contact radius of the unworn surfaces, m (the plastic grid's length unit)
        self.a_hertz = estimate_contact_radius(self.upper, self.lower, self.load, self.modulus)
        # the plastic grid's spacing: a whole number of window cells (the tractions are
        # averaged onto it cell by cell, exactly when every plastic cell holds k x k of them)
        want = check_positive("ep_window_radii", ep_window_radii) * self.a_hertz / self.ep_n
        self._ep_dx = max(1, round(want / self.dx)) * self.dx
        #: side of the upper body's plastic grid, m (``ep_window_radii`` Hertz radii, to a
        #: whole number of window cells per plastic cell)
        self.ep_window = self._ep_dx * self.ep_n
        self.ep_depth = check_positive("ep_depth_radii", ep_depth_radii) * self.a_hertz
        if self.ep_window > self.window:
            raise ValueError(
                f"ep_window_radii = {ep_window_radii!r} gives a plastic window of "
                f"{self.ep_window:.4g} m, larger than the solver window {self.window:.4g} m"
            )
        #: lower track grid: points beyond the window on each side along x
        self.ep_pad = int(math.ceil(self.amplitude / self.ep_dx - 1e-9))
        self._ep_ready = True
        self.reset()

    # -- plastic grids -----------------------------------------------------------------
    @property
    def ep_dx(self) -> float:
        """Plastic grid spacing, m (a whole number of window cells)."""
        return self._ep_dx

    @property
    def ep_coords(self) -> NDArray[np.float64]:
        """Plastic grid x (= y) coordinates of the upper body, m (window frame)."""
        return ((np.arange(self.ep_n) - self.ep_n // 2) * self.ep_dx).astype(np.float64,
                                                                                copy=False)

    @property
    def ep_z(self) -> NDArray[np.float64]:
        """Plastic grid depths, m."""
        return np.linspace(0.0, self.ep_depth, self.ep_nz)

    def _body_grid(self, body: str) -> PlasticHalfSpace:
        mat = self.upper_material
        nx = self.ep_n + (2 * self.ep_pad if body == "lower" else 0)
        x0 = -(self.ep_n // 2 + (self.ep_pad if body == "lower" else 0)) * self.ep_dx
        return PlasticHalfSpace(
            nx, self.ep_n, self.ep_nz, self.ep_dx, self.ep_depth, x0,
            -(self.ep_n // 2) * self.ep_dx, mat.young, mat.poisson, self.yield_strength,
            self.hardening, self.a_hertz, self.ep_tolerance, self.ep_max_iter)

    def reset(self) -> None:
        super().reset()
        if not getattr(self, "_ep_ready", False):
            return
        #: the plastic state of each body
        self.bodies: dict[str, PlasticHalfSpace] = {b: self._body_grid(b) for b in BODIES}
        self._loaded = False
        self._steps: list[PlasticStep] = []
        self._maps: dict[str, RegularGridInterpolator | None] = {b: None for b in BODIES}
        self._cycle_rows: list[dict[str, Any]] = []
        self._cycle_start: dict[str, NDArray[np.float64]] | None = None
        self._cycle_increments = 0
        self._cycle_open = False

    # -- resume ------------------------------------------------------------------------
    def state_dict(self) -> dict[str, Any]:
        """:meth:`HalfSpaceSolver.state_dict` plus both bodies' plastic states, the steps not
        yet collected and the per-cycle records."""
        return {
            **super().state_dict(),
            "ep_loaded": self._loaded,
            "ep_bodies": {b: s.state_dict() for b, s in self.bodies.items()},
            "steps": list(self._steps),
            "cycle_rows": [dict(r) for r in self._cycle_rows],
            "cycle_start": (None if self._cycle_start is None
                            else {b: v.copy() for b, v in self._cycle_start.items()}),
            "cycle_increments": self._cycle_increments,
            "cycle_open": self._cycle_open,
        }

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore :meth:`state_dict` (same grids). ``ConfigError`` for a state that has
        yielded: a :class:`tamaas.Residual` rebuilt from the model's fields does not continue
        the uninterrupted one (its residual 20-50 % apart, measured), so such a run cannot
        resume; rerun it from the start."""
        if any(np.asarray(b["fields"]["cumulated_plastic_strain"]).max() > 0.0
               for b in state["ep_bodies"].values()):
            raise ConfigError(
                "--resume: solver = 'elastic-plastic' cannot resume a run whose bodies have "
                "yielded (tamaas's plastic residual keeps state that a checkpoint does not "
                "carry); allowed: the run again from the start, without --resume")
        super().load_state_dict(state)
        for b, s in self.bodies.items():
            s.load_state_dict(state["ep_bodies"][b])
        self._loaded = bool(state["ep_loaded"])
        self._steps = list(state["steps"])
        self._cycle_rows = [dict(r) for r in state["cycle_rows"]]
        cs = state["cycle_start"]
        self._cycle_start = None if cs is None else {b: np.array(v) for b, v in cs.items()}
        self._cycle_increments = int(state["cycle_increments"])
        self._cycle_open = bool(state["cycle_open"])
        for b in BODIES:
            self._update_map(b)

    # -- the increment -----------------------------------------------------------------
    def _update_map(self, body: str, u: NDArray[np.float64] | None = None) -> None:
        s = self.bodies[body]
        u = s.residual_displacement if u is None else u
        self._maps[body] = (None if not np.any(u) else
                            _grid((s.x, s.y), u, bounds_error=False, fill_value=0.0))

    def gap(self, offset: float) -> NDArray[np.float64]:
        """Summed recession plus both bodies' residual (plastic) surface displacement, m."""
        g = super().gap(offset)
        cw = self.coords
        xw, yw = np.meshgrid(cw, cw, indexing="ij")
        up, lo = self._maps["upper"], self._maps["lower"]
        if up is not None:
            g = g + up(np.stack([xw, yw], -1))
        if lo is not None:
            g = g + lo(np.stack([xw + offset, yw], -1))
        return g

    def _apply(self, pressure: NDArray[np.float64], traction: NDArray[np.float64],
               offset: float, load: float) -> bool:
        """Apply the window's pressure and shear traction on the upper body (Pa) to both
        bodies' plastic grids (the lower body: -traction, at lab x = window x + offset);
        whether either body yielded."""
        yielded = False
        p = pressure + self.debris_pressure
        t = np.concatenate([traction, p[..., None]], axis=-1)
        c0 = float(self.coords[0])
        for body, tt, shift in (("upper", t, 0.0), ("lower", t * np.array([-1.0, -1.0, 1.0]),
                                                    offset)):
            s = self.bodies[body]
            on = block_average(tt, c0 + shift, self.dx, float(s.x[0]), s.dx, s.nx, c0,
                               float(s.y[0]), s.ny)
            lost = abs(float(on[..., 2].sum()) * s.dx**2 - float(p.sum()) * self.dx**2)
            if lost > 1e-6 * max(load, 1e-300):
                raise ValueError(
                    f"the contact at offset {offset:.4g} m reaches beyond the {body} body's "
                    f"plastic grid ({s.nx * s.dx:.4g} x {s.ny * s.dx:.4g} m): increase "
                    "ep_window_radii (or give the stroke's amplitude)")
            dp = s.load(on)
            if dp.max() > 0.0:
                self._steps.append(PlasticStep(z=s.z, x=s.x, y=s.y, dp=dp, stress=s.stress,
                                               load=float(load), body=body))
                self._update_map(body)
                yielded = True
        return yielded

    def _coupled(self, contact: Callable[[], tuple[Any, NDArray[np.float64],
                                                   NDArray[np.float64]]],
                 offset: float, load: float) -> Any:
        """One increment, staggered: ``contact()`` solves the contact on the residual
        displacements after the previous increment and returns (its result, pressure Pa,
        shear traction Pa); the tractions are then applied to both bodies. (Redoing a
        yielding increment from a restored plastic state, Jacq et al.'s inner loop, is not
        done: a :class:`tamaas.Residual` restored from the model's fields does not give the
        residual of the uninterrupted one, 20-50 % apart in the measured case, so the
        restored solve would not continue the state.) Returns the ``contact()`` result."""
        out, p, t = contact()
        self._apply(p, t, offset, load)
        return out

    def _first_loading(self, offset: float) -> None:
        """The first ``load_steps - 1`` steps of the first loading (the last is the first
        increment's own solve): frictionless normal solves at fractions of the load."""
        for k in range(1, self.load_steps):
            load = self.solid_load * k / self.load_steps

            def normal(load: float = load) -> tuple[None, NDArray[np.float64],
                                                    NDArray[np.float64]]:
                p, _ = self._normal(self.gap(offset) + self._debris_u, load)
                return None, p, np.zeros((*p.shape, 2))

            self._coupled(normal, offset, load)
        self._loaded = True

    def begin_cycle(self) -> None:
        """Close the previous cycle's record (:meth:`cycle_columns`) and start a new one (the
        first cycle's record starts at the first loading)."""
        if self._cycle_open and self._cycle_increments:
            self._cycle_rows.append(self.cycle_columns())
        if self._cycle_open or self._cycle_start is None:
            # (the first cycle keeps the start of the first loading: its record includes it)
            self._cycle_start = {b: s.cumulated_plastic_strain for b, s in self.bodies.items()}
        self._cycle_open = True
        self._cycle_increments = 0

    def solve_increment(self, offset: float) -> IncrementResult:
        """:meth:`HalfSpaceSolver.solve_increment` on the plastically conformed surfaces,
        then its full traction applied to both bodies' plastic states (the first call
        loads in ``load_steps`` steps)."""
        if self._cycle_start is None:
            self._cycle_start = {b: s.cumulated_plastic_strain for b, s in self.bodies.items()}
        if not self._loaded:
            self._first_loading(float(offset))
        before = HalfSpaceSolver.state_dict(self)

        def contact() -> tuple[IncrementResult, NDArray[np.float64], NDArray[np.float64]]:
            HalfSpaceSolver.load_state_dict(self, before)
            res = HalfSpaceSolver.solve_increment(self, offset)
            return res, res.pressure, res.traction

        res = self._coupled(contact, float(offset), self.solid_load)
        self._cycle_increments += 1
        return cast("IncrementResult", res)

    def plastic_steps(self) -> list[PlasticStep]:
        """Plastic load steps and increments since the last call, one per body that yielded
        (for DFDI, eq 6.1); clears the list."""
        steps, self._steps = self._steps, []
        return steps

    @property
    def plastic_depth(self) -> float:
        """Depth of the plastic grid, m (``ep_depth_radii`` Hertz radii)."""
        return self.ep_depth

    # -- reports -----------------------------------------------------------------------
    def cycle_columns(self) -> dict[str, float]:
        """The cycle so far (since :meth:`begin_cycle`), per body: ``max_peeq_{body}`` (the
        largest equivalent plastic strain p, -), ``max_peeq_depth_{body}_m`` (its depth, m)
        and ``peeq_increment_{body}`` (the largest increase of p over the cycle, -)."""
        row: dict[str, float] = {}
        for b, s in self.bodies.items():
            pmax, depth, _ = s.peak()
            start = (self._cycle_start or {}).get(b)
            cum = s.cumulated_plastic_strain
            inc = float((cum - start).max()) if start is not None else float(cum.max())
            row |= {f"max_peeq_{b}": pmax, f"max_peeq_depth_{b}_m": depth,
                    f"peeq_increment_{b}": max(inc, 0.0)}
        return row

    def shakedown(self, rows: list[dict[str, Any]]) -> dict[str, Any]:
        """Shakedown statement of the cycle records ``rows``: the first cycle after the
        first whose largest increment of p (both bodies) is below ``shakedown_tolerance``,
        or that none is, with the last cycle's increment."""
        tol = self.shakedown_tolerance
        incs = [max(r["peeq_increment_upper"], r["peeq_increment_lower"]) for r in rows]
        for k, v in enumerate(incs):
            if k >= 1 and v < tol:
                return {"reached": True, "cycle": k + 1, "peeq_increment": v,
                        "tolerance": tol}
        return {"reached": False, "cycles": len(incs),
                "last_peeq_increment": incs[-1] if incs else None, "tolerance": tol}

    def report(self) -> dict[str, Any]:
        """Per cycle :meth:`cycle_columns` (``cycles``, the open cycle included), and the
        ``shakedown`` statement (:meth:`shakedown`)."""
        rows = list(self._cycle_rows)
        if self._cycle_open and self._cycle_increments:
            rows.append(self.cycle_columns())
        return {"cycles": rows, "shakedown": self.shakedown(rows),
                "plastic_grid": {"dx_m": self.ep_dx, "nz": self.ep_nz,
                                 "depth_m": self.ep_depth,
                                 "lower_nx": self.bodies["lower"].nx}}

    # -- fields ------------------------------------------------------------------------
    def _on_window(self, body: Body, values: NDArray[np.float64], offset: float,
                   z: NDArray[np.float64]) -> NDArray[np.float64]:
        """A [nz_ep, nx, ny, ...] field of ``body``'s plastic grid on the window at ``offset``
        (m) and depths ``z`` (m) [len(z), n, n, ...] (zero outside the grid)."""
        s = self.bodies[body]
        cw = self.coords
        shift = offset if body == "lower" else 0.0
        zz, xx, yy = np.meshgrid(z, cw + shift, cw, indexing="ij")
        pts = np.stack([zz, xx, yy], -1)
        v = np.asarray(values, dtype=float)
        if v.ndim == 3:
            return _grid((s.z, s.x, s.y), v, bounds_error=False, fill_value=0.0)(pts)
        return np.stack([_grid((s.z, s.x, s.y), v[..., k], bounds_error=False,
                               fill_value=0.0)(pts) for k in range(v.shape[-1])], -1)

    def plastic_fields(
        self, body: Body, offset: float, z: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(plastic strain [nz, n, n, 6], cumulated plastic strain [nz, n, n]) of ``body`` on
        the window at ``offset`` (m) and depths ``z`` (m); zero outside the plastic grid."""
        s = self.bodies[body]
        return (self._on_window(body, s.plastic_strain, offset, z),
                self._on_window(body, s.cumulated_plastic_strain, offset, z))

    def subsurface_stress(
        self,
        result: IncrementResult,
        body: Body = "lower",
        depth: float | None = None,
        nz: int = 33,
    ) -> PlasticSubsurfaceStress:
        """The elastic stress of the increment's tractions on the window grid plus the
        residual stress of ``body``'s plastic state now (after the last solved increment),
        and the plastic state, on the same grid."""
        st = super().subsurface_stress(result, body, depth=depth, nz=nz)
        s = self.bodies[body]
        stress = st.stress
        if s.cumulated_plastic_strain.max() > 0.0:
            stress = stress + self._on_window(body, s.residual_stress, result.offset, st.z)
        tens, cum = self.plastic_fields(body, result.offset, st.z)
        return PlasticSubsurfaceStress(
            body=st.body, z=st.z, x=st.x, y=st.y, stress=stress, von_mises=von_mises(stress),
            tresca=max_shear(stress), plastic_strain=tens, cumulated_plastic_strain=cum)
