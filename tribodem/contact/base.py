"""The first-body contract (Lu (2018), sections 3.3, 6.1): what every backend gives.

Conventions (SI throughout):

* The stroke is along x. The *lower* body is fixed in the lab frame; the *upper* body is
  displaced by the relative tangential position ``offset`` (m) along x. The solver works on a
  periodic *window* of ``n x n`` points centred on the upper body's origin, so the window
  travels with the upper body: in the upper body's own frame every window point is a fixed
  material point, while on the lower body the window covers lab x in
  ``[offset - W/2, offset + W/2)``.
* ``traction`` is the shear traction (Pa) acting on the **upper** body's surface; the lower
  body carries ``-traction``. In gross slip it opposes the upper body's motion relative to the
  lower body.
* ``slip`` is the increment of relative tangential displacement (m) of the upper surface with
  respect to the lower one during the increment, at contact points (zero elsewhere).
* Dissipated energy density (J/m^2) of an increment is ``-traction . slip`` (>= 0) at each
  point; the same density is deposited on both bodies (frictional work of the interface,
  Fouvry's energy approach, seed chapter 5).
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar, Literal, cast

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel

from tribodem.materials.en24t import EN24T

if TYPE_CHECKING:
    from typing import Self

#: A body's recession below its tangent plane at (x, y), m (callable or height map).
Recession = Callable[[NDArray[np.float64], NDArray[np.float64]], NDArray[np.float64]]

Body = Literal["upper", "lower"]
BODIES: tuple[Body, ...] = ("upper", "lower")

#: Voigt order of the stress components returned by :class:`SubsurfaceStress`.
VOIGT_ORDER = ("xx", "yy", "zz", "yz", "xz", "xy")

#: ``[fe]`` fields whose None (left out) means the backend's own default, which differs
#: between the CalculiX backends (``OWN_DEFAULTS`` of each)
BACKEND_OWN = ("h_over_a", "size_factor", "timeout")


def check_positive(name: str, value: float, allow_zero: bool = False) -> float:
    """``value`` as a float, finite and > 0 (>= 0 with ``allow_zero``); else ``ValueError``
    naming ``name``, the value and the rule."""
    v = float(value)
    ok = v >= 0.0 if allow_zero else v > 0.0
    if not math.isfinite(v) or not ok:
        rule = ">= 0" if allow_zero else "> 0"
        raise ValueError(f"{name} = {value!r} is not allowed: must be finite and {rule}")
    return v


@dataclass(frozen=True)
class ElasticBody:
    """Isotropic elastic first body; defaults are EN24T (seed table 5.1: E 240 GPa, nu 0.3)."""

    young: float = EN24T.young  #: Young's modulus, Pa
    poisson: float = EN24T.poisson  #: Poisson's ratio, -

    def __post_init__(self) -> None:
        check_positive("young", self.young)
        if not (-1.0 < float(self.poisson) < 0.5):
            raise ValueError(f"poisson = {self.poisson!r} is not allowed: must be in (-1, 0.5)")

    @property
    def shear(self) -> float:
        """Shear modulus G = E / (2 (1 + nu)), Pa."""
        return self.young / (2.0 * (1.0 + self.poisson))


def contact_modulus(a: ElasticBody, b: ElasticBody) -> float:
    """Hertz contact modulus E* = 1 / ((1 - nu1^2)/E1 + (1 - nu2^2)/E2), Pa."""
    return 1.0 / ((1 - a.poisson**2) / a.young + (1 - b.poisson**2) / b.young)


def mindlin_kappa(a: ElasticBody, b: ElasticBody) -> float:
    """Mindlin's tangential / normal compliance ratio kappa = sum (2 - nu_i)/G_i /
    (2 sum (1 - nu_i)/G_i) (1.214 for nu = 0.3): gross slip of a Hertz contact after a
    relative tangential displacement delta* = mu kappa d, d the normal approach (Johnson
    1985, eqs 7.42-7.43)."""
    return ((2 - a.poisson) / a.shear + (2 - b.poisson) / b.shear) / (
        2 * ((1 - a.poisson) / a.shear + (1 - b.poisson) / b.shear)
    )


def dundurs_beta(a: ElasticBody, b: ElasticBody) -> float:
    """Dundurs' second constant (0 for elastically similar bodies: no normal-shear coupling)."""
    k1 = (1 - 2 * a.poisson) / a.shear - (1 - 2 * b.poisson) / b.shear
    k2 = (1 - a.poisson) / a.shear + (1 - b.poisson) / b.shear
    return 0.5 * k1 / k2


@dataclass(frozen=True)
class ContactCase:
    """The resolved first-body case every backend is built from (SI)."""

    upper: Recession  #: recession of the upper body below its tangent plane, m
    lower: Recession  #: recession of the lower body, m
    upper_material: ElasticBody  #: the upper body's elastic constants
    lower_material: ElasticBody  #: the lower body's elastic constants
    load: float  #: total normal load on the window, N
    friction: float  #: Coulomb friction coefficient, -
    amplitude: float  #: displacement amplitude of the cycle, m
    n_increments: int  #: increments per cycle (a multiple of 4)
    n: int  #: window points per side
    window: float | None  #: window side, m (None: the backend's estimate)
    regime: str = "gross"  #: half-space slip regime ("gross" or "ciavarella-jaeger")
    tolerance: float = 1e-6  #: half-space normal solver (PKR) tolerance, -
    #: "point" / "line" of an analytic geometry, None for height maps (found from them)
    contact: str | None = None
    #: depth of the subsurface stress grid the criterion asks for, m (None: the backend's)
    stress_depth: float | None = None


@dataclass
class IncrementResult:
    """Solution of one increment of relative tangential position, on the solver window."""

    offset: float  #: relative tangential position of the upper body at the end, m
    start_offset: float  #: position at the start of the increment, m
    direction: float  #: sign of the sliding increment (+1, -1; 0 for the initial loading)
    pressure: NDArray[np.float64]  #: contact pressure, Pa, [n, n]
    traction: NDArray[np.float64]  #: shear traction on the upper body, Pa, [n, n, 2]
    slip: NDArray[np.float64]  #: relative slip increment (upper w.r.t. lower), m, [n, n, 2]
    contact_area: float  #: m^2
    normal_load: float  #: integral of the pressure, N
    stick: NDArray[np.bool_] | None = None  #: stick points (None: gross slip everywhere)

    @property
    def energy_density(self) -> NDArray[np.float64]:
        """Energy dissipated in this increment per unit area, J/m^2, [n, n]."""
        return np.maximum(-np.einsum("ijk,ijk->ij", self.traction, self.slip), 0.0)

    @property
    def max_pressure(self) -> float:
        """Peak pressure, Pa."""
        return float(self.pressure.max())

    @property
    def max_traction(self) -> float:
        """Peak shear traction magnitude, Pa."""
        return float(np.hypot(self.traction[..., 0], self.traction[..., 1]).max())


@dataclass
class SubsurfaceStress:
    """Stress tensor on a [nz, n, n] grid under one body (local frame, z = depth into it)."""

    body: Body
    z: NDArray[np.float64]  #: depths, m, [nz] (z[0] = 0 is the surface)
    x: NDArray[np.float64]  #: window x coordinates (relative to the window centre), m
    y: NDArray[np.float64]  #: window y coordinates, m
    stress: NDArray[np.float64]  #: Cauchy stress, Pa, [nz, n, n, 6] in :data:`VOIGT_ORDER`
    von_mises: NDArray[np.float64]  #: von Mises stress, Pa, [nz, n, n]
    tresca: NDArray[np.float64]  #: maximum shear stress (s1 - s3)/2, Pa, [nz, n, n]


@dataclass(frozen=True)
class Capabilities:
    """What a first-body backend can give; criteria and the loop check it before any work.

    ``plastic``: equivalent plastic strain increments (:meth:`FirstBodySolver.plastic_steps`);
    ``plastic_every_cycle``: plastic strain solved in every cycle, not only at the first
    loading (what accumulating criteria such as DFDI need over more than one cycle);
    ``partial_slip``: stick/slip inside the contact (else gross slip q = mu p everywhere);
    ``subsurface``: stress below the surface (:meth:`FirstBodySolver.subsurface_stress`);
    ``debris``: a prescribed extra surface pressure (the debris third body);
    ``contacts``: the contact geometries it solves (``"point"``, ``"line"``);
    ``repeatable``: a cycle can be solved again on updated surfaces with no state advancing
    but the tractions' memory (no plastic strain, no job files): the fretting loop may
    split a cycle's wear into sub-cycles (``FrettingLoop(update_tolerance=...)``).
    """

    plastic: bool = False
    plastic_every_cycle: bool = False
    partial_slip: bool = False
    subsurface: bool = True
    debris: bool = False
    contacts: tuple[str, ...] = ("point",)
    repeatable: bool = False

    def names(self) -> set[str]:
        """The capabilities that hold, by name (``plastic``, ``subsurface``, ...)."""
        return {k for k in ("plastic", "plastic_every_cycle", "partial_slip", "subsurface",
                            "debris")
                if getattr(self, k)} | {f"{c}_contact" for c in self.contacts}


#: What each capability name means (for messages).
CAPABILITY_TEXT = {
    "plastic": "plastic (the equivalent plastic strain)",
    "plastic_every_cycle": "plastic_every_cycle (plastic strain solved in every cycle, not "
                           "only at the first loading)",
    "partial_slip": "partial_slip (stick and slip inside the contact)",
    "subsurface": "subsurface (the stress below the surface)",
    "debris": "debris (a prescribed debris pressure)",
    "point_contact": "point_contact",
    "line_contact": "line_contact (plane strain)",
}


class WindowTooSmallError(RuntimeError):
    """The contact reaches the edge of the solver's window (the run stops early)."""


class Unsupported(NotImplementedError):
    """A contract method outside the backend's declared capabilities."""


class FirstBodySolver(ABC):
    """One first-body contact solver: the only thing the fretting loop and the criteria use.

    A backend is one module in :mod:`tribodem.contact` plus a line in
    :data:`tribodem.contact.BACKENDS`. It owns the two surfaces, the materials, the normal
    load and its grid; the driver sets the worn surfaces, then asks for one increment of
    relative tangential position at a time, in path order (the solver may keep load history
    between calls). The contract:

    - data: ``n``, ``dx`` (window grid), ``load`` (N), ``modulus`` (E*, Pa), ``contact``
      (``"point"`` or ``"line"``),
      ``upper``/``lower`` (recessions, m:
      the surfaces the next solve sees), ``capabilities``;
    - :meth:`set_surfaces` (worn geometry), :meth:`reset`, :meth:`begin_cycle`,
      :meth:`solve_increment`;
    - fields: surface fields in :class:`IncrementResult`; :meth:`subsurface_stress`
      (capability ``subsurface``); :meth:`plastic_steps` and :attr:`plastic_depth`
      (``plastic``);
    - debris (``debris``): :meth:`set_debris_pressure`, :attr:`debris_pressure`,
      :attr:`debris_load`, :meth:`loaded_solution`;
    - resume: :meth:`state_dict` / :meth:`load_state_dict`;
    - building and options: :meth:`from_case` (a :class:`ContactCase`
      and the config tables of :attr:`options`), :meth:`capabilities_for` (the capabilities
      of a configured instance), :meth:`options_for`, :meth:`effective_options`;
    - reports: :meth:`report` (for summary.json).
    """

    #: the backend's name in :data:`tribodem.contact.BACKENDS` (for messages)
    name: ClassVar[str] = ""
    #: the config tables the backend reads, by TOML table name, and their models
    #: (:meth:`from_case` takes them)
    options: ClassVar[dict[str, type[BaseModel]]] = {}
    #: whether the backend runs CalculiX jobs (then a run gives it a :attr:`workdir`)
    runs_ccx: ClassVar[bool] = False
    #: the folder of the backend's own files (the ccx jobs; None: none, or a temporary one)
    workdir: Path | None = None
    #: what this backend can give (class attribute of each backend)
    capabilities: Capabilities = Capabilities()
    #: window grid spacing (m) and number of points per side
    dx: float
    n: int
    #: normal load, N
    load: float
    #: contact modulus E* of the two bodies, Pa (the scale of elastic deformation)
    modulus: float
    #: the contact being solved: "point" or "line" (plane strain, periodic along y)
    contact: str = "point"
    #: recessions of the two surfaces (m), as the next solve sees them
    upper: Recession
    lower: Recession

    @property
    def window(self) -> float:
        """Side of the square periodic solution window, m."""
        return self.dx * self.n

    @property
    def coords(self) -> NDArray[np.float64]:
        """Window point coordinates along x or y relative to the window centre, m."""
        return ((np.arange(self.n) - self.n // 2) * self.dx).astype(np.float64, copy=False)

    @property
    def ny(self) -> int:
        """Window points along y: ``n`` (a square window), 1 for a backend that solves one
        cross-section of a line contact (its fields are ``[n, 1]``)."""
        return self.n

    @property
    def dy(self) -> float:
        """Extent along y of one window point, m: ``dx``, or the window's side for a
        cross-section that stands for the whole window (so that a field x ``dx dy``
        integrates over the same area in both)."""
        return self.dx

    @property
    def coords_y(self) -> NDArray[np.float64]:
        """Window point coordinates along y, m (``coords``; ``[0]`` for a cross-section)."""
        return self.coords if self.ny == self.n else np.zeros(self.ny)

    @classmethod
    def from_case(cls, case: ContactCase, options: Mapping[str, BaseModel] | None = None
                  ) -> Self:
        """The backend on ``case``, configured by ``options`` (config tables by TOML name,
        those of :attr:`options`; a table left out takes its model's defaults).

        ``tribodem.io.config.ConfigError`` for an option the backend cannot use (naming the
        dotted field, the value and what is allowed), ``ValueError`` for a case it cannot
        solve, ``tribodem.contact.fe.ccx.CcxNotFoundError`` for a ccx backend without ccx.
        Default: the constructor called as ``cls(upper, lower, **case_keywords(case))``."""
        del options
        factory = cast("Callable[..., Self]", cls)
        return factory(case.upper, case.lower, **cls.case_keywords(case))

    @classmethod
    def case_keywords(cls, case: ContactCase) -> dict[str, Any]:
        """The contract's constructor keywords of ``case``: ``load`` (N), ``friction``,
        ``upper_material``, ``lower_material``, ``n``, ``window`` (m or None), ``regime``,
        ``tolerance``, and ``contact`` for a backend that solves line contacts and an
        analytic geometry (None, found from the surfaces, otherwise)."""
        kw: dict[str, Any] = dict(
            load=case.load, friction=case.friction, upper_material=case.upper_material,
            lower_material=case.lower_material, n=case.n, window=case.window,
            regime=case.regime, tolerance=case.tolerance)
        if "line" in cls.capabilities.contacts and case.contact is not None:
            kw["contact"] = case.contact
        return kw

    @classmethod
    def capabilities_for(cls, options: Mapping[str, BaseModel] | None = None
                         ) -> Capabilities:
        """What an instance built with ``options`` (config tables by TOML name, as
        :meth:`from_case` takes them) can give; checked before any work. Default:
        :attr:`capabilities` (no option changes it)."""
        del options
        return cls.capabilities

    @classmethod
    def effective_options(cls, options: Mapping[str, Mapping[str, Any]]
                          ) -> dict[str, dict[str, Any]]:
        """The option tables ``options`` (JSON dicts by TOML name) as this backend takes
        them, for telling whether two recorded configs make the same run. Default: every
        table as given, but the ``[fe]`` fields whose None means a ccx backend's own default
        (:data:`BACKEND_OWN`) left out: they do nothing here."""

        out = {table: dict(fields) for table, fields in options.items()}
        if "fe" in out:
            out["fe"] = {k: v for k, v in out["fe"].items() if k not in BACKEND_OWN}
        return out

    @classmethod
    def options_for(cls, names: set[str]) -> str:
        """The options under which this backend gives the capabilities ``names`` it lacks
        as configured (for messages; "" when no option gives them)."""
        del names
        return ""

    def report(self) -> dict[str, Any]:
        """What the backend measured over the run besides the surface fields (e.g. peak
        stresses, plastic strain, timings), for summary.json; default: nothing."""
        return {}

    def cycle_columns(self) -> dict[str, float]:
        """Per-cycle numbers the backend measured over the cycle just solved, for the
        ``results.csv`` row of that cycle (e.g. the elastic-plastic half-space's maximum
        equivalent plastic strain and its depth per body); default: none."""
        return {}

    def set_surfaces(self, upper: Recession, lower: Recession) -> None:
        """Give the (worn) surfaces the next increments see (recessions, m)."""
        self.upper, self.lower = upper, lower

    @abstractmethod
    def reset(self) -> None:
        """Forget the load history (start a new loading from the unloaded state)."""

    def begin_cycle(self) -> None:  # noqa: B027 - a hook, empty by default
        """Called at the start of every cycle, after :meth:`set_surfaces` (default: nothing)."""

    @abstractmethod
    def solve_increment(self, offset: float) -> IncrementResult:
        """Move the upper body to ``offset`` (m) from the previous position and solve."""

    def subsurface_stress(
        self, result: IncrementResult, body: Body, depth: float, nz: int
    ) -> SubsurfaceStress:
        """Stress under ``body`` (0 <= z <= depth, m, ``nz`` levels) for a solved increment."""
        raise Unsupported(f"{type(self).__name__} gives no subsurface stress")

    # -- plastic strain (capability ``plastic``)
    def plastic_steps(self) -> list[Any]:
        """The plastic strain increments solved since the last call (then forgotten)."""
        raise Unsupported(f"{type(self).__name__} gives no plastic strain")

    @property
    def plastic_depth(self) -> float:
        """Depth of the grid on which plastic strain is solved, m."""
        raise Unsupported(f"{type(self).__name__} gives no plastic strain")

    # -- debris third body (capability ``debris``): a backend that takes a debris pressure
    # keeps it in these two attributes (``set_debris_pressure``), read by the properties
    _debris_pressure: NDArray[np.float64] | None = None
    _debris_load: float = 0.0

    @property
    def debris_pressure(self) -> NDArray[np.float64]:
        """The prescribed debris pressure on the window, Pa [n, n] (zeros when none)."""
        if self._debris_pressure is None:
            return np.zeros((self.n, self.n))
        return self._debris_pressure

    @property
    def debris_load(self) -> float:
        """Load carried by the debris, N."""
        return self._debris_load

    def set_debris_pressure(self, pressure: NDArray[np.float64] | None) -> None:
        """Prescribe the debris pressure, Pa [n, n] (None clears)."""
        raise Unsupported(f"{type(self).__name__} takes no debris pressure")

    def loaded_solution(self, offset: float = 0.0, debris: bool = False
                        ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(pressure Pa, gap m) of the normal contact at ``offset`` under the full load,
        without or with the debris pressure, leaving the load history untouched."""
        raise Unsupported(f"{type(self).__name__} gives no separate loaded solution")

    # -- resume
    def state_dict(self) -> dict[str, Any]:
        """Everything needed to continue bitwise after :meth:`load_state_dict`."""
        raise Unsupported(f"{type(self).__name__} cannot save its state")

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore a state saved by :meth:`state_dict`."""
        raise Unsupported(f"{type(self).__name__} cannot restore a state")


def checked_debris_pressure(pressure: NDArray[np.float64], n: int, dx: float, load: float
                            ) -> tuple[NDArray[np.float64], float]:
    """(a copy of ``pressure``, its load N) for ``set_debris_pressure``: finite, >= 0 Pa, on
    the n x n window of spacing ``dx`` (m), carrying less than the applied ``load`` (N);
    ``ValueError`` saying what is wrong otherwise."""
    pd = np.asarray(pressure, dtype=float)
    if pd.shape != (n, n) or not np.all(np.isfinite(pd)) or pd.min() < 0:
        raise ValueError(f"debris pressure: shape {pd.shape}, min {np.nanmin(pd):.3g}: "
                         f"must be finite, >= 0 Pa, shape ({n}, {n})")
    debris_load = float(pd.sum() * dx**2)
    if debris_load >= load:
        raise ValueError(f"debris load {debris_load:.4g} N >= applied load {load:.4g} N: "
                         "the solid-solid contact would carry nothing")
    return pd.copy(), debris_load


def require(solver: FirstBodySolver, needs: frozenset[str] | set[str], who: str) -> None:
    """Refuse (``ValueError`` naming ``who``, the backend and what is missing) a solver that
    lacks a capability in ``needs``."""
    missing = set(needs) - solver.capabilities.names()
    if missing:
        raise ValueError(
            f"{who} needs {', '.join(CAPABILITY_TEXT.get(m, m) for m in sorted(missing))}, "
            "which the first-body solver "
            f"'{type(solver).__name__}' does not give (it gives: "
            f"{', '.join(sorted(solver.capabilities.names()))})")


def cycle_offsets(amplitude: float, n_increments: int) -> NDArray[np.float64]:
    """Positions ending each increment of one cycle 0 -> +A -> 0 -> -A -> 0, m.

    ``n_increments`` must be a positive multiple of 4 (equal steps of 4 A / n).
    """
    check_positive("amplitude", amplitude)
    if int(n_increments) != n_increments or n_increments < 4 or n_increments % 4:
        raise ValueError(
            f"n_increments = {n_increments!r} is not allowed: must be a multiple of 4, >= 4"
        )
    q = int(n_increments) // 4
    up = np.arange(1, q + 1) / q
    return amplitude * np.concatenate([up, 1 - up, -up, -1 + up])
