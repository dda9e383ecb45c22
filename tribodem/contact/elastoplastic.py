"""Elastic-plastic half-space backend on tamaas EPIC (DESIGN.md "The fretting FE-DE model").

Model (Lu (2018) section 5.2: bilinear EN24T; replaces the Abaqus elastic-plastic FE phase):

* Two bodies of the *same* elastic-plastic material under the same normal pressure have the
  same elastic-plastic response (a half-space's state depends only on its surface traction
  history), so the normal problem is one EN24T half-space (E, nu, von Mises yield
  ``sigma_y + h p``, ``p`` the cumulated plastic strain) pressed by a rigid surface equal to
  *half* the summed recession. It is solved by :class:`tamaas.EPICSolver`
  (:class:`tamaas.PolonskyKeerRey` around :class:`tamaas.Residual` with
  :class:`tamaas.materials.IsotropicHardening`, :class:`DFSANECXXSolver`) on a coarse
  ``volume_2d`` grid (``ep_n`` x ``ep_n`` points over ``ep_window_radii`` Hertz radii,
  ``ep_nz`` layers down to ``ep_depth_radii`` radii), non-dimensionally (length: Hertz
  radius a_H, stress: E / (1 - nu^2)).
* Load-stepped (``load_steps`` equal steps) on the first loading. The per-cycle reload of
  the persistent plastic state at full load on the worn geometry (:meth:`begin_cycle`,
  ``reload_cycles=True``) is off by default: it ratchets in tamaas 2.9 (see there), so the
  plastic state and the conformed surfaces are frozen after the first loading.
* The permanent (plastic) surface displacement ``u_p`` (Mindlin displacement of C : eps_p) is
  added to the recession of *both* bodies (upper: window frame, lower: lab frame at offset
  0), so the elastic fine-grid increments of :class:`HalfSpaceSolver` (pressure, gross slip
  or Ciavarella-Jaeger traction, energy) run on the plastically conformed surfaces: elastic
  reloading of an elastic-plastic body whose plastic strain does not change.
* Plastic strain and cumulated plastic strain are exposed on the subsurface grid
  (:class:`PlasticSubsurfaceStress`) and, per load step, for the DFDI criterion
  (:meth:`pop_plastic_steps`).

Limits: tamaas EPIC is frictionless, so the plastic strain is that of the normal load (the
shear traction's contribution to plastic flow is neglected); plasticity is computed at
offset 0 only (the lower track away from the centre of the stroke stays elastic); residual
stresses are not added to the subsurface stress (it is the elastic stress of the contact
tractions on the conformed surfaces).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
import tamaas as tm
from numpy.typing import NDArray

from tribodem.contact.base import (
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
    model_fields,
    set_model_fields,
)
from tribodem.contact.options import PlasticOptions, option_table
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


def _mandel_to_voigt(a: NDArray[np.float64]) -> NDArray[np.float64]:
    """tamaas 2.9 (xx, yy, zz, xy, xz, yz; shear x sqrt 2) -> (xx, yy, zz, yz, xz, xy)."""
    out = np.asarray(a, dtype=float)[..., [0, 1, 2, 5, 4, 3]].copy()
    out[..., 3:] /= math.sqrt(2.0)
    return out


@dataclass
class PlasticSubsurfaceStress(SubsurfaceStress):
    """:class:`SubsurfaceStress` plus the plastic state of the body on the same grid."""

    plastic_strain: NDArray[np.float64]  #: plastic strain tensor, -, [nz, n, n, 6] (Voigt)
    cumulated_plastic_strain: NDArray[np.float64]  #: equivalent plastic strain p, -, [nz, n, n]


@dataclass
class PlasticStep:
    """One plastic load step on a [nz, nx, ny] grid under a body.

    EPIC (``body`` None): one state shared by both bodies, on the coarse grid at offset 0
    (x = y coordinates). A backend with a state per body (``fe``) sets ``body`` and ``y``:
    the upper body's grid is in its own (window) frame, the lower body's in the lab frame.
    """

    z: NDArray[np.float64]  #: depths below the body's surface, m, [nz]
    x: NDArray[np.float64]  #: x coordinates, m, [nx] (and y when ``y`` is None)
    dp: NDArray[np.float64]  #: increment of the cumulated plastic strain, -, [nz, nx, ny]
    stress: NDArray[np.float64]  #: Cauchy stress at the end of the step, Pa, [nz, nx, ny, 6]
    load: float  #: normal load at the end of the step, N
    body: str | None = None  #: "upper", "lower", or None: both bodies (one shared state)
    y: NDArray[np.float64] | None = None  #: y coordinates, m, [ny] (None: y = x)


class ElastoPlasticSolver(HalfSpaceSolver):
    """Elastic-plastic first-body solver: EPIC at loading / cycle start, elastic increments.

    Takes every :class:`HalfSpaceSolver` argument plus: ``yield_strength`` Pa (680 MPa),
    ``hardening`` plastic modulus h Pa (None: :func:`bilinear_hardening` from ``uts`` Pa and
    ``uts_strain``), ``ep_n`` coarse points per side (32), ``ep_nz`` layers (12),
    ``ep_window_radii`` (5) and ``ep_depth_radii`` (2) Hertz radii, ``load_steps`` (4),
    ``ep_tolerance`` (EPIC fixed point, 1e-6), ``ep_max_iter`` (300), ``reload_cycles``
    (False), ``beyond_uts`` (only ``"line"``: the hardening line goes on past the UTS).
    Both bodies must be of the same material.
    """

    name = "elastic-plastic"
    options: ClassVar[dict[str, type[BaseModel]]] = {"plastic": PlasticOptions}
    capabilities = Capabilities(plastic=True, partial_slip=True, subsurface=True, debris=True,
                                contacts=("point",))

    @classmethod
    def from_case(cls, case: ContactCase, options: Mapping[str, BaseModel] | None = None
                  ) -> Self:
        """The solver on ``case`` with the ``[plastic]`` table's law and EP grid
        (:class:`~tribodem.contact.options.PlasticOptions`; its defaults when left out).
        ``ConfigError`` for ``plastic.beyond_uts = 'hold'``: tamaas's linear hardening goes
        on past the UTS."""
        plastic = option_table(options, "plastic", PlasticOptions)
        if plastic.beyond_uts != "line":
            raise ConfigError(
                f"plastic.beyond_uts = {plastic.beyond_uts!r}: solver = {cls.name!r} "
                "has linear hardening only (it goes on past the UTS); allowed: 'line', or "
                "solver = 'fe' or 'fe3d' with [fe] material = 'elastic-plastic'")
        return cls(case.upper, case.lower, **cls.case_keywords(case), **plastic.model_dump())

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
        reload_cycles: bool = False,
        **kw: Any,
    ) -> None:
        self._ep_ready = False
        super().__init__(upper, lower, **kw)
        if self.upper_material != self.lower_material:
            raise ValueError(
                "upper_material and lower_material differ: the elastic-plastic solver needs "
                "both bodies of the same material (same traction -> same plastic state)"
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
        #: re-solve EPIC at full load at every cycle start (off: ratchets in tamaas 2.9)
        self.reload_cycles = bool(reload_cycles)
        #: Hertz contact radius of the unworn surfaces, m (the EP length unit)
        self.a_hertz = estimate_contact_radius(self.upper, self.lower, self.load, self.modulus)
        self.ep_window = check_positive("ep_window_radii", ep_window_radii) * self.a_hertz
        self.ep_depth = check_positive("ep_depth_radii", ep_depth_radii) * self.a_hertz
        if self.ep_window > self.window:
            raise ValueError(
                f"ep_window_radii = {ep_window_radii!r} gives an EP window of "
                f"{self.ep_window:.4g} m, larger than the solver window {self.window:.4g} m"
            )
        #: single-body plane-strain modulus E / (1 - nu^2), Pa (the EP stress unit)
        self.ep_modulus = mat.young / (1.0 - mat.poisson**2)
        self._ep_ready = True
        self.reset()

    # -- coarse EP model -------------------------------------------------------------
    @property
    def ep_dx(self) -> float:
        """Coarse EP grid spacing, m."""
        return self.ep_window / self.ep_n

    @property
    def ep_coords(self) -> NDArray[np.float64]:
        """Coarse EP grid x (= y) coordinates, m (lab frame at offset 0)."""
        return ((np.arange(self.ep_n) - self.ep_n // 2) * self.ep_dx).astype(np.float64,
                                                                                copy=False)

    @property
    def ep_z(self) -> NDArray[np.float64]:
        """Coarse EP grid depths, m."""
        return np.linspace(0.0, self.ep_depth, self.ep_nz)

    def reset(self) -> None:
        super().reset()
        if not getattr(self, "_ep_ready", False):
            return
        a = self.a_hertz
        lx = self.ep_window / a
        self._ep = tm.ModelFactory.createModel(
            tm.model_type.volume_2d, [self.ep_depth / a, lx, lx],
            [self.ep_nz, self.ep_n, self.ep_n])
        mat = self.upper_material
        self._ep.E = mat.young / self.ep_modulus
        self._ep.nu = mat.poisson
        self._ep_mat = tm.materials.IsotropicHardening(
            self._ep, sigma_y=self.yield_strength / self.ep_modulus,
            hardening=self.hardening / self.ep_modulus)
        self._ep_res = tm.Residual(self._ep, self._ep_mat)
        import tamaas.nonlinear_solvers  # here, not with the module: see _grid

        self._ep_nl = tamaas.nonlinear_solvers.DFSANECXXSolver(self._ep_res)
        # separate model for the Mindlin post-processing: registering or applying volume
        # operators on the EPIC model itself corrupts its next solve (measured: ratcheting)
        self._aux = tm.ModelFactory.createModel(
            tm.model_type.volume_2d, [self.ep_depth / a, lx, lx],
            [self.ep_nz, self.ep_n, self.ep_n])
        self._aux.E, self._aux.nu = self._ep.E, self._ep.nu
        tm.ModelFactory.registerVolumeOperators(self._aux)
        # one contact solver and one EPIC for the whole run: EPIC keeps the residual
        # (plastic) displacement between solves; the surface is updated in place
        self._ep_surface = np.zeros((self.ep_n, self.ep_n))
        self._ep_contact = tm.PolonskyKeerRey(self._ep, self._ep_surface, 1e-12)
        self._ep_contact.max_iter = 10000
        self._epic = tm.EPICSolver(self._ep_contact, self._ep_nl, self.ep_tolerance, 0.3)
        self._epic.max_iter = self.ep_max_iter
        self._ep_loaded = False
        self._plastic_map: RegularGridInterpolator | None = None
        self._steps: list[PlasticStep] = []
        #: EPIC pressure of the last elastic-plastic solve, Pa, [ep_n, ep_n]
        self.ep_pressure: NDArray[np.float64] | None = None
        #: plastic surface displacement of each body, m, [ep_n, ep_n]
        self.plastic_displacement: NDArray[np.float64] | None = None

    def state_dict(self) -> dict[str, Any]:
        """:meth:`HalfSpaceSolver.state_dict` plus the plastic state: the EPIC model's fields
        (plastic strain, cumulated plastic strain, stress, ...), the EP surface, the plastic
        surface displacement and the load steps not yet collected.

        EPIC's own residual displacement is not reachable from Python, so a run with
        ``reload_cycles`` (EPIC re-solved every cycle) cannot be checkpointed
        (``NotImplementedError``); without it EPIC runs only at the first loading.
        """
        if self.reload_cycles and self._ep_loaded:
            raise NotImplementedError("reload_cycles = True: EPIC's internal residual "
                                      "displacement cannot be saved; no checkpoint")
        return {
            **super().state_dict(),
            "ep_loaded": self._ep_loaded,
            "ep": model_fields(self._ep),
            "aux": model_fields(self._aux),
            "ep_surface": self._ep_surface.copy(),
            "ep_pressure": None if self.ep_pressure is None else self.ep_pressure.copy(),
            "plastic_displacement": (None if self.plastic_displacement is None
                                     else self.plastic_displacement.copy()),
            "steps": list(self._steps),
        }

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore :meth:`state_dict` (same grids)."""
        super().load_state_dict(state)
        set_model_fields(self._ep, state["ep"])
        set_model_fields(self._aux, state["aux"])
        self._ep_surface[...] = state["ep_surface"]
        self._ep_loaded = bool(state["ep_loaded"])
        self._steps = list(state["steps"])
        pe, up = state["ep_pressure"], state["plastic_displacement"]
        self.ep_pressure = None if pe is None else np.array(pe, dtype=float)
        self.plastic_displacement = None if up is None else np.array(up, dtype=float)
        self._plastic_map = None
        if self.plastic_displacement is not None:
            c = self.ep_coords
            self._plastic_map = _grid((c, c), self.plastic_displacement,
                                      bounds_error=False, fill_value=0.0)

    def begin_cycle(self) -> None:
        """Elastic-plastic normal solve at offset 0 on the current (worn) surfaces.

        First call after :meth:`reset`: ``load_steps`` load steps from zero. Later calls do
        nothing unless ``reload_cycles``: then one reload at full load from the persistent
        plastic state on the worn geometry (off by default: with tamaas 2.9 the reload of an
        unchanged geometry ratchets, peak 1579 -> 1932 -> 2114 MPa, p 0.0063 -> 0.0108 ->
        0.0139, instead of shaking down). Updates the plastic surface displacement.
        """
        if self._ep_loaded and not self.reload_cycles:
            return
        a, es = self.a_hertz, self.ep_modulus
        c = self.ep_coords
        xc, yc = np.meshgrid(c, c, indexing="ij")
        g = np.asarray(self.upper(xc, yc) + self.lower(xc, yc), dtype=float)
        half = 0.5 * (g - g.min()) / a
        self._ep_surface[...] = -half
        epic = self._epic
        loads = ([self.load] if self._ep_loaded else
                 [self.load * (k + 1) / self.load_steps for k in range(self.load_steps)])
        area = (self.ep_window / a) ** 2
        for load in loads:
            before = np.array(self._ep["cumulated_plastic_strain"], dtype=float)
            epic.solve(load / (area * a * a * es))
            after = np.array(self._ep["cumulated_plastic_strain"], dtype=float)
            self._steps.append(PlasticStep(
                z=self.ep_z, x=c.copy(), dp=np.maximum(after - before, 0.0),
                stress=_mandel_to_voigt(self._ep["stress"]) * es, load=float(load)))
        self._ep_loaded = True
        p = np.array(self._ep.traction, dtype=float)[..., 2]
        if np.any(p[0] > 0) or np.any(p[-1] > 0) or np.any(p[:, 0] > 0) or np.any(p[:, -1] > 0):
            raise ValueError(
                f"the elastic-plastic contact touches the EP window edge ({self.ep_window:.4g} m):"
                " increase ep_window_radii"
            )
        self.ep_pressure = p * es
        # plastic surface displacement: Mindlin displacement of the plastic eigenstress
        # C : eps_p (= total minus elastic displacement of p, checked; robust over steps)
        eps_p = np.array(self._ep["plastic_strain"], dtype=float)
        eig = np.zeros_like(eps_p)
        self._aux.operators["hooke"](eps_p, eig)
        disp = np.zeros(self._aux.displacement.shape)
        self._aux.operators["mindlin"](eig, disp)
        up = disp[0, ..., 2]
        border = np.concatenate([up[0], up[-1], up[:, 0], up[:, -1]]).mean()
        up = (up - border) * a
        self.plastic_displacement = up
        self._plastic_map = _grid((c, c), up, bounds_error=False, fill_value=0.0)

    def gap(self, offset: float) -> NDArray[np.float64]:
        """Summed recession plus both bodies' plastic surface displacement, m, [n, n]."""
        g = super().gap(offset)
        if self._plastic_map is None:
            return g
        cw = self.coords
        xw, yw = np.meshgrid(cw, cw, indexing="ij")
        up = self._plastic_map(np.stack([xw, yw], -1))
        lo = self._plastic_map(np.stack([xw + offset, yw], -1))
        return g + up + lo

    def solve_increment(self, offset: float) -> IncrementResult:
        if not self._ep_loaded:
            self.begin_cycle()
        return super().solve_increment(offset)

    def plastic_steps(self) -> list[PlasticStep]:
        """EPIC load steps since the last call (for DFDI, eq 6.1); clears the list."""
        steps, self._steps = self._steps, []
        return steps

    @property
    def plastic_depth(self) -> float:
        """Depth of the EP grid, m (``ep_depth_radii`` Hertz radii)."""
        return self.ep_depth

    def plastic_fields(
        self, body: Body, offset: float, z: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(plastic strain [nz, n, n, 6], cumulated plastic strain [nz, n, n]) of ``body`` on
        the window at ``offset`` (m) and depths ``z`` (m); zero outside the EP grid."""
        n = self.n
        if not self._ep_loaded:
            return np.zeros((len(z), n, n, 6)), np.zeros((len(z), n, n))
        c = self.ep_coords
        cw = self.coords
        shift = offset if body == "lower" else 0.0
        zz, xx, yy = np.meshgrid(z, cw + shift, cw, indexing="ij")
        pts = np.stack([zz, xx, yy], -1)
        cum = _grid(
            (self.ep_z, c, c), np.array(self._ep["cumulated_plastic_strain"], dtype=float),
            bounds_error=False, fill_value=0.0)(pts)
        eps = _mandel_to_voigt(self._ep["plastic_strain"])
        tens = np.stack([_grid((self.ep_z, c, c), eps[..., k], bounds_error=False,
                               fill_value=0.0)(pts) for k in range(6)], -1)
        return tens, cum

    def subsurface_stress(
        self,
        result: IncrementResult,
        body: Body = "lower",
        depth: float | None = None,
        nz: int = 33,
    ) -> PlasticSubsurfaceStress:
        """Elastic stress of the increment's tractions plus the plastic state (same grid)."""
        st = super().subsurface_stress(result, body, depth=depth, nz=nz)
        tens, cum = self.plastic_fields(body, result.offset, st.z)
        return PlasticSubsurfaceStress(
            body=st.body, z=st.z, x=st.x, y=st.y, stress=st.stress, von_mises=st.von_mises,
            tresca=st.tresca, plastic_strain=tens, cumulated_plastic_strain=cum)
