"""What the two CalculiX backends (``fe``: 2D plane strain, ``fe3d``: 3D crossed cylinders)
share: :class:`CcxBackend`, built from a :class:`~tribodem.contact.base.ContactCase` and the
``[fe]`` / ``[plastic]`` option tables.

It owns the option handling (which ``[fe]`` fields a backend takes, its own defaults for
the ones left out, the checks), the case (surfaces, materials, load, window, the cycle),
the bodies' material and plastic law, the retry and loading-friction set-up, the shared
state of the jobs (their records, the served increments, the nodal caches), the worn
geometry's column projection and morphing, the subsurface-stress and plastic-step grids,
and the shared parts of :meth:`~CcxBackend.report`, :meth:`~CcxBackend.state_dict` and
:meth:`~CcxBackend.load_state_dict`. A backend adds its mesh, deck, reading and mapping.
"""

from __future__ import annotations

import math
import time
from abc import abstractmethod
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar, Generic, Protocol, TypeVar

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel

from tribodem.contact.base import (
    BODIES,
    Body,
    Capabilities,
    ElasticBody,
    FirstBodySolver,
    IncrementResult,
    Recession,
    SubsurfaceStress,
    check_positive,
    contact_modulus,
    cycle_offsets,
)
from tribodem.contact.elastoplastic import PlasticStep
from tribodem.contact.fe.ccx import CcxRun, FESolverStopped, ccx_build, find_ccx
from tribodem.contact.fe.deck import ContactSettings, FEMaterial, sliding_contact
from tribodem.contact.fe.jobs import (
    LOADING_FRICTION,
    MATERIALS,
    RETRY_FROM,
    CcxJobs,
    JobRecord,
    check_stress_depth,
    checked_increments,
)
from tribodem.contact.fe.mesh import surface_projection, worn_depth
from tribodem.contact.fe.options import BACKEND_OWN, FEOptions
from tribodem.contact.halfspace import max_shear, von_mises
from tribodem.contact.options import PlasticOptions, option_table
from tribodem.io.config import ConfigError
from tribodem.io.runs import check_threads

if TYPE_CHECKING:
    from typing import Self

    from tribodem.contact.base import ContactCase


class FEMesh(Protocol):
    """What the shared code reads of a backend's mesh (2D :class:`~.mesh.Mesh` or 3D
    :class:`~.crossed.Mesh3D`)."""

    nodes: NDArray[np.float64]  #: node coordinates, m, [n_nodes, dim]
    elements: NDArray[np.int64]  #: 0-based node rows of each element
    h_fine: float  #: element size at the contact, m


MeshT = TypeVar("MeshT", bound=FEMesh)


def column_set(body: str) -> str:
    """The element set of ``body``'s printed node columns (``UCOL`` / ``LCOL``)."""
    return "LCOL" if body == "lower" else "UCOL"


def nodal_mean(conn: NDArray[np.int64], values: NDArray[np.float64], n_nodes: int
               ) -> NDArray[np.float64]:
    """Per node, the mean of ``values`` [m elements, k nodes, ...] over the elements ``conn``
    [m, k] (0-based node rows) around it: [n_nodes, ...], NaN at a node of no element."""
    total = np.zeros((n_nodes,) + values.shape[2:])
    count = np.zeros(n_nodes)
    np.add.at(total, conn, values)
    np.add.at(count, conn, 1.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        return total / count.reshape((-1,) + (1,) * (values.ndim - 2))


def traction_quarters(q: NDArray[np.float64]) -> dict[str, float]:
    """The largest shear traction (Pa) of a cycle's first and last quarters of increments
    (``q`` per increment) and the drop between them (last / first - 1; 0 without traction)."""
    quarter = max(len(q) // 4, 1)
    first, last = float(q[:quarter].max()), float(q[-quarter:].max())
    return {"max_traction_first_quarter_pa": first, "max_traction_last_quarter_pa": last,
            "traction_drop": (last - first) / first if first > 0 else 0.0}


def residual_surfaces(u_lower: NDArray[np.float64], u_upper: NDArray[np.float64]
                      ) -> dict[str, float]:
    """Pile-up and dent (m) after the upper body is lifted off, from the vertical residual
    displacements of the lower surface's nodes (up positive) and of the upper surface's
    relative to its reference (towards the lower body negative): the largest rise of each
    surface towards the other body and its deepest depression."""
    return {"pile_up_lower_m": float(max(u_lower.max(), 0.0)),
            "dent_lower_m": float(max(-u_lower.min(), 0.0)),
            "pile_up_upper_m": float(max(-u_upper.min(), 0.0)),
            "dent_upper_m": float(max(u_upper.max(), 0.0))}


def _subclasses(cls: type) -> list[type]:
    """Every subclass of ``cls``, at any depth."""
    out = []
    for sub in cls.__subclasses__():
        out += [sub, *_subclasses(sub)]
    return out


class CcxBackend(CcxJobs, FirstBodySolver, Generic[MeshT]):
    """A CalculiX first body: one ccx job per cycle on the worn geometry (see the backends,
    :class:`~tribodem.contact.fe.backend.FEContactSolver` and
    :class:`~tribodem.contact.fe.backend3d.FE3DContactSolver`).

    ``case``: the surfaces (recessions, m; the backend checks they are its geometry and
    reads the radius R from their curvatures), the bodies' elastic constants, the normal
    load (N), friction, the loop's cycle (``amplitude`` m, ``n_increments``: the job's
    output times), the window (``n`` points; ``window`` m, None: ``window_radii`` Hertz
    radii or half-widths), ``stress_depth`` (m: how deep the column stresses are printed;
    None: the backend's default) and ``contact`` (the backend's own only). The case's
    ``regime`` and ``tolerance`` are the half-space's and are not used: the FE interface has
    partial slip and its own Newton tolerances.

    ``fe`` (:class:`~tribodem.contact.fe.options.FEOptions`): the fields of
    :attr:`FE_FIELDS`; another field set away from its default is a ``ConfigError``;
    ``h_over_a``, ``size_factor`` and ``timeout`` left None are the backend's own
    (:attr:`OWN_DEFAULTS`). ``plastic`` (:class:`~tribodem.contact.options.PlasticOptions`):
    the law of ``fe.material = "elastic-plastic"`` (``yield_strength``, ``uts``,
    ``uts_strain``, ``hardening`` and ``beyond_uts``; the EPIC grid fields are not used, the
    mesh is the grid). ``executable``: the ccx to run (None: :func:`.ccx.find_ccx`'s);
    ``workdir``: the jobs' folder (``cycle_0001/`` ...; None: a new temporary folder).
    """

    options: ClassVar[dict[str, type[BaseModel]]] = {"fe": FEOptions, "plastic": PlasticOptions}
    runs_ccx: ClassVar[bool] = True
    #: the ``[fe]`` fields the backend takes (any other must stay at its default)
    FE_FIELDS: ClassVar[frozenset[str]]
    #: the backend's own values of the ``[fe]`` fields :data:`.options.BACKEND_OWN` left None
    OWN_DEFAULTS: ClassVar[dict[str, float]]
    #: the modes the backend runs (``[fe] mode``)
    MODES: ClassVar[tuple[str, ...]]
    #: what the backend solves, for a refused ``contact``
    SOLVES: ClassVar[str]
    #: contact normal penalty factor: normal stiffness = factor x E_min / h, Pa/m
    PENALTY_FACTOR: ClassVar[float]
    #: the Gauss point nearest each node of an element (the element's node order)
    NEAREST_GAUSS: ClassVar[NDArray[np.int64]]
    #: depth of the plastic-step grid in Hertz radii (half-widths), before the printed depth
    PLASTIC_DEPTH_RADII: ClassVar[float]

    radius: float  #: the radius R read from the surfaces' curvatures, m
    mode: str  #: ``[fe] mode``
    material: str  #: ``[fe] material``
    plastic_law: FEMaterial  #: the bodies' plastic law (``[plastic]``)
    plastic_increments: int  #: the fewest ccx increments per plastic cycle
    h_over_a: float  #: element size at the contact / Hertz radius (half-width)
    size_factor: float  #: bodies' size / Hertz radius (half-width)
    stress_depth: float  #: depth of the printed column stresses, m
    mesh: MeshT  #: the (morphed) mesh of the last job
    _mesh0: MeshT  #: the unworn mesh
    _base_upper: Recession  #: the unworn surfaces (the constructor's)
    _base_lower: Recession
    _nodal_cache: dict[tuple[str, float], NDArray[np.float64]]
    _peeq_cache: dict[tuple[str, float], NDArray[np.float64]]
    _time_of: dict[int, float]  #: total time of each increment served from the last job
    _job_key: tuple[bytes, ...] | None

    def __init__(self, case: ContactCase, fe: FEOptions | None = None,
                 plastic: PlasticOptions | None = None, *, executable: str | None = None,
                 workdir: str | Path | None = None, window_radii: float = 10.0) -> None:
        fe = FEOptions() if fe is None else fe
        plastic = PlasticOptions() if plastic is None else plastic
        self.check_fe_fields(fe)
        contact = self.case_keywords(case).get("contact", self.contact)
        if contact != self.contact:
            raise ValueError(f"contact = {contact!r} is not allowed: the {self.name} backend "
                             f"solves {self.SOLVES}; allowed: {self.contact!r}")
        self._set_mode(fe)
        self._set_material(fe.material, fe.plastic_increments, plastic)
        self.capabilities = self.capabilities_for({"fe": fe})
        self.executable = find_ccx(executable)  # CcxNotFoundError names the install command
        self._set_case(case, window_radii)
        self._set_mesh_options(fe)
        self._set_job_options(fe, workdir)
        self.stress_depth = (check_positive("stress_depth", case.stress_depth)
                             if case.stress_depth is not None else self._default_stress_depth())
        #: node-to-surface contact, the pair declared once (docs/fe.md, "Reversals": ccx
        #: 2.20's surface-to-surface friction loses 30-40 % of mu P on the return strokes),
        #: n2s tension 1e-5 p0, the backend's normal penalty, stick slope 0.1 x the penalty
        self.settings: ContactSettings = sliding_contact(self.friction, self.hertz[0],
                                                         penalty_factor=self.PENALTY_FACTOR)
        self._set_loading_friction(fe.loading_friction)
        self.jobs: list[JobRecord] = []  #: every ccx job run, in order
        self._cycle = 0  # cycles served (the job folder's number is the next one)
        self._job_key = None
        self._served: list[IncrementResult] = []
        self._pending: list[PlasticStep] = []
        self._fresh_for_cycle = False
        self._time_of = {}
        self._nodal_cache = {}
        self._peeq_cache = {}
        self.cycle_reports: list[dict[str, Any]] = []  #: :meth:`_cycle_report` per cycle
        self._setup()
        self.reset()

    # -- options ---------------------------------------------------------------------------
    @classmethod
    def from_case(cls, case: ContactCase, options: Mapping[str, BaseModel] | None = None
                  ) -> Self:
        """The backend on ``case`` with the ``[fe]`` and ``[plastic]`` tables of ``options``
        (their defaults when left out): ``fe.threads`` 0 is every core (``ConfigError`` for
        more than the machine has), then the constructor."""
        fe = option_table(options, "fe", FEOptions)
        fe = fe.model_copy(update={"threads": check_threads(fe.threads,
                                                            "fe.threads (--threads)")})
        return cls(case, fe, option_table(options, "plastic", PlasticOptions))

    @classmethod
    def check_fe_fields(cls, fe: FEOptions) -> None:
        """Refuse (``ConfigError``, naming the backends that take it) an ``[fe]`` field this
        backend does not take (not in :attr:`FE_FIELDS`) set away from its default; the
        backends named are the CalculiX backends (the subclasses of this one) by name."""
        for k, field in FEOptions.model_fields.items():
            value = getattr(fe, k)
            if k in cls.FE_FIELDS or (value is None and k in BACKEND_OWN):
                continue
            if value != field.default:
                has = sorted({b.name for b in _subclasses(CcxBackend) if k in b.FE_FIELDS})
                raise ConfigError(f"fe.{k} = {value!r}: solver = {cls.name!r} does not "
                                  f"take it; allowed: leave fe.{k} out (solver = "
                                  f"{' or '.join(repr(n) for n in has)} has it)")

    @classmethod
    def capabilities_for(cls, options: Mapping[str, BaseModel] | None = None
                         ) -> Capabilities:
        """``plastic`` with ``fe.material = "elastic-plastic"``; ``plastic_every_cycle``
        where the backend has it, only in ``chained`` mode (a fresh job restarts from virgin
        material every cycle, so its plastic strain would be the first cycle's again)."""
        fe = option_table(options, "fe", FEOptions)
        plastic = fe.material == "elastic-plastic"
        every = cls.capabilities.plastic_every_cycle and plastic and fe.mode == "chained"
        return replace(cls.capabilities, plastic=plastic, plastic_every_cycle=every)

    @classmethod
    def effective_options(cls, options: Mapping[str, Mapping[str, Any]]
                          ) -> dict[str, dict[str, Any]]:
        """The tables as given, with ``[fe]``'s :data:`.options.BACKEND_OWN` fields as this
        backend takes them: left None (or out), :attr:`OWN_DEFAULTS`."""
        out = super().effective_options(options)
        fe = options.get("fe")
        if fe is not None:
            out["fe"] |= {k: own if fe.get(k) is None else fe[k]
                          for k, own in cls.OWN_DEFAULTS.items()}
        return out

    def _own(self, fe: FEOptions, key: str) -> float:
        """``[fe]`` field ``key`` of :data:`.options.BACKEND_OWN`, else the backend's own."""
        value = getattr(fe, key)
        return self.OWN_DEFAULTS[key] if value is None else float(value)

    def _set_mode(self, fe: FEOptions) -> None:
        """Check and keep ``fe.mode`` (:attr:`MODES`)."""
        if fe.mode not in self.MODES:
            raise ValueError(f"mode = {fe.mode!r} is not allowed for the {self.name} backend: "
                             f"allowed: {', '.join(self.MODES)}")
        self.mode = fe.mode

    def _set_material(self, material: str, plastic_increments: int,
                      plastic: PlasticOptions) -> None:
        """Check and keep the bodies' material (:data:`.jobs.MATERIALS`) and plastic law
        (Pa, Pa, -, Pa, and past the UTS :data:`~tribodem.contact.fe.deck.BEYOND_UTS`;
        ``ValueError`` on an impossible one) and the fewest ccx increments per plastic
        cycle."""
        if material not in MATERIALS:
            raise ValueError(f"material = {material!r} is not allowed: allowed: "
                             f"{', '.join(MATERIALS)}")
        self.material = material
        self.plastic = material == "elastic-plastic"
        self.plastic_increments = checked_increments("plastic_increments", plastic_increments)
        self.plastic_law = FEMaterial(
            yield_strength=check_positive("yield_strength", plastic.yield_strength),
            uts=check_positive("uts", plastic.uts),
            uts_strain=check_positive("uts_strain", plastic.uts_strain),
            hardening=plastic.hardening, beyond_uts=plastic.beyond_uts)
        if self.plastic:
            self.plastic_law.plastic_table()  # ValueError on an impossible law

    def _set_case(self, case: ContactCase, window_radii: float) -> None:
        """The surfaces, bodies, load, window and cycle of ``case`` (``ValueError`` on one
        the backend cannot solve)."""
        self.upper, self.lower = case.upper, case.lower
        self._base_upper, self._base_lower = case.upper, case.lower
        self.friction = check_positive("friction", case.friction, allow_zero=True)
        self.upper_material = case.upper_material
        self.lower_material = case.lower_material
        self.modulus = contact_modulus(self.upper_material, self.lower_material)
        n = case.n
        if int(n) != n or n < 16 or n % 2:
            raise ValueError(f"n = {n!r} is not allowed: must be an even integer >= 16")
        self.n = int(n)
        self.radius = self._radius_of(case.upper, case.lower)
        self.load = check_positive("load", case.load)
        window = case.window
        if window is None:
            window = self._default_window(check_positive("window_radii", window_radii))
        self.dx = check_positive("window", window) / self.n
        self.amplitude = check_positive("amplitude", case.amplitude)
        self.offsets = cycle_offsets(self.amplitude, case.n_increments)
        self.n_increments = int(case.n_increments)

    def _set_mesh_options(self, fe: FEOptions) -> None:
        """The mesh's ``h_over_a`` and ``size_factor`` (the backend's own when left out)."""
        self.h_over_a = check_positive("h_over_a", self._own(fe, "h_over_a"))
        self.size_factor = check_positive("size_factor", self._own(fe, "size_factor"))
        self._check_size_factor(self.size_factor)

    def _set_job_options(self, fe: FEOptions, workdir: str | Path | None) -> None:
        """How the jobs run: threads, time limit, retries, the job cache and the folder."""
        if int(fe.threads) != fe.threads or fe.threads < 1:
            raise ValueError(f"threads = {fe.threads!r} is not allowed: an integer >= 1")
        self.threads = int(fe.threads)
        self.timeout = check_positive("timeout", self._own(fe, "timeout"))
        if int(fe.retries) != fe.retries or fe.retries < 0:
            raise ValueError(f"retries = {fe.retries!r} is not allowed: an integer >= 0")
        self.retries = int(fe.retries)
        if fe.retry_from not in RETRY_FROM:
            raise ValueError(f"retry_from = {fe.retry_from!r} is not allowed: allowed: "
                             f"{', '.join(RETRY_FROM)}")
        self.retry_from = fe.retry_from
        #: folder of finished ccx jobs keyed by deck (:func:`.jobs.run_job`; None: no cache)
        self.cache: Path | None = None if fe.cache is None else Path(fe.cache)
        self.workdir = None if workdir is None else Path(workdir)

    def _set_loading_friction(self, loading_friction: str) -> None:
        """Check ``loading_friction`` (:data:`.jobs.LOADING_FRICTION`) and set the seating
        and loading friction of ``settings`` from it (``full`` with mu = 0 keeps the low
        value: ccx refuses a zero coefficient)."""
        if loading_friction not in LOADING_FRICTION:
            raise ValueError(f"loading_friction = {loading_friction!r} is not allowed: "
                             f"allowed: {', '.join(LOADING_FRICTION)}")
        if loading_friction == "auto":
            loading_friction = "full" if self.plastic else "low"
        self.loading_friction = loading_friction
        if loading_friction == "full":
            self.settings = replace(self.settings,
                                    mu_loading=max(self.friction, self.settings.mu_loading))

    # -- what each backend defines ---------------------------------------------------------
    @property
    @abstractmethod
    def hertz(self) -> tuple[float, float]:
        """Hertz (p0 Pa, a m) of the unworn contact."""

    @abstractmethod
    def _radius_of(self, upper: Recession, lower: Recession) -> float:
        """The radius R (m) of the backend's geometry read from the surfaces' curvatures
        (``ValueError`` when they are not its geometry)."""

    @abstractmethod
    def _default_window(self, radii: float) -> float:
        """The window side (m) of ``radii`` Hertz radii (half-widths) of the unworn contact."""

    @abstractmethod
    def _check_size_factor(self, size_factor: float) -> None:
        """``ValueError`` for bodies the backend cannot mesh."""

    @abstractmethod
    def _default_stress_depth(self) -> float:
        """How deep the column stresses are printed when the case leaves it out, m."""

    @abstractmethod
    def _setup(self) -> None:
        """The unworn mesh (``_mesh0``, ``mesh``), what the mapping reads of it and the
        backend's own state (called at the end of the constructor, before ``reset``)."""

    @abstractmethod
    def _morph(self, mesh: MeshT, body: str, wear: NDArray[np.float64]) -> MeshT:
        """``mesh`` with ``body``'s surface receded by ``wear`` (m, one depth per column)."""

    @abstractmethod
    def _projection_grid(self, body: str) -> tuple[NDArray[np.float64],
                                                    NDArray[np.float64] | None, float]:
        """(x of the columns, y of the columns or None for a line contact, the largest y
        the surfaces are given at) of ``body``'s surface nodes, m."""

    @abstractmethod
    def _seat(self, mesh: MeshT) -> float:
        """Seating displacement, m: the smallest rigid gap between the (worn) surfaces plus
        5 % of the Hertz approach."""

    @abstractmethod
    def worn_volume(self, body: str, mesh: MeshT | None = None) -> float:
        """Worn volume of ``body`` on the window, m^3 (default: the last job's mesh)."""

    @abstractmethod
    def _peeq_ip(self, body: str, t: float) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
        """(elements, equivalent plastic strain at their Gauss points) of ``body``'s column
        set at total time ``t``."""

    @abstractmethod
    def _default_grid_depth(self, result: IncrementResult) -> float:
        """Depth of the subsurface grid when none is asked for, m."""

    @abstractmethod
    def _stress_on_grid(self, body: str, t: float, x: NDArray[np.float64],
                        z: NDArray[np.float64]) -> NDArray[np.float64]:
        """The stress (Pa, the contract's Voigt order) under ``body`` at total time ``t`` on
        the grid of depths ``z`` and ``x`` by the window's y, [nz, nx, n, 6]."""

    def _relaxed(self, body: str, wear: NDArray[np.float64]) -> NDArray[np.float64]:
        """The column wear a backend carries into its mesh (default: as projected)."""
        del body
        return wear

    def _refine_unit(self) -> int:
        """ccx increments per output increment of a job's own (``jobs.csv``'s refine is an
        attempt's refinement times it; default 1)."""
        return 1

    # -- geometry --------------------------------------------------------------------------
    @property
    def pad(self) -> float:
        """Half-length the lower body's track extends beyond the window along x, m (the
        loop's track grid: ceil(A / dx) + 1 cells)."""
        return (math.ceil(self.amplitude / self.dx) + 1) * self.dx

    @property
    def plastic_depth(self) -> float:
        """Depth of the grid of :meth:`plastic_steps`, m: :attr:`PLASTIC_DEPTH_RADII` Hertz
        radii (half-widths), at most the printed column depth."""
        return min(self.PLASTIC_DEPTH_RADII * self.hertz[1], self.stress_depth)

    def column_wear(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Worn depth (m, >= 0) of each node column of the (upper, lower) mesh: the current
        recession minus the unworn one (upper: its own frame, lower: lab frame, clipped at
        zero) carried onto the surface nodes (:meth:`_column_depths`: by default the lumped
        projection, :func:`surface_projection`, sampled at dx / 2); zero outside the window
        (upper) and the window plus the stroke (lower) along x, and beyond the window's last
        point along y, where the loop gives no surface. The morphed mesh so loses the loop's
        worn volume (what a backend does to it then: :meth:`_relaxed`)."""
        c = self.coords
        out = []
        for body, now, base, lo, hi in (
                ("upper", self.upper, self._base_upper, c[0], c[-1]),
                ("lower", self.lower, self._base_lower, c[0] - self.pad, c[-1] + self.pad)):
            out.append(self._relaxed(body, self._column_depths(body, now, base, lo, hi)))
        return out[0], out[1]

    def _column_depths(self, body: str, now: Recession, base: Recession, lo: float,
                       hi: float) -> NDArray[np.float64]:
        """``body``'s worn depth (m, >= 0) at its node columns, before :meth:`_relaxed`:
        the lumped projection of ``now`` minus ``base`` (clipped at zero) onto the surface
        nodes, sampled at dx / 2 on x in [``lo``, ``hi``] (m) and y up to the window's last
        point (:func:`surface_projection`)."""
        xs, ys, y_hi = self._projection_grid(body)
        return surface_projection(worn_depth(now, base), xs, ys, (lo, hi, -np.inf, y_hi),
                                  0.5 * self.dx)

    def morphed_mesh(self) -> MeshT:
        """The unworn mesh with both surfaces receded by :meth:`column_wear` (eqs 3.7-3.8;
        :class:`FESolverStopped` when the fine section cannot take the depth)."""
        wu, wl = self.column_wear()
        try:
            m = self._morph(self._mesh0, "upper", wu) if wu.any() else self._mesh0
            return self._morph(m, "lower", wl) if wl.any() else m
        except ValueError as err:
            raise FESolverStopped(f"mesh morphing: {err}") from None

    # -- the jobs --------------------------------------------------------------------------
    def _materials(self) -> tuple[FEMaterial, FEMaterial]:
        """The (lower, upper) ccx materials: elastic constants, with the plastic law."""
        law = self.plastic_law
        y = law.yield_strength if self.plastic else None

        def material(body: ElasticBody) -> FEMaterial:
            return FEMaterial(body.young, body.poisson, yield_strength=y, uts=law.uts,
                              uts_strain=law.uts_strain, hardening=law.hardening,
                              beyond_uts=law.beyond_uts)

        return material(self.lower_material), material(self.upper_material)

    def _job_start(self) -> tuple[Path, MeshT, float, float]:
        """Start a job: (its folder, made; the morphed mesh; the seating displacement, m;
        the ``perf_counter`` at the start, s)."""
        t0 = time.perf_counter()
        folder = self._folder()
        folder.mkdir(parents=True, exist_ok=True)
        mesh = self.morphed_mesh()
        return folder, mesh, self._seat(mesh), t0

    def _job_record(self, folder: Path, mesh: MeshT, run: CcxRun, refine: int, scale: float,
                    seconds: tuple[float, float, float], cycles: int = 1) -> JobRecord:
        """The record of a job run in ``folder`` on ``mesh`` (its converged attempt's
        ``refine`` and penalty ``scale``; ``seconds`` meshing, ccx and reading)."""
        return JobRecord(cycle=self._cycle + 1, folder=folder, deck=run.job.with_suffix(".inp"),
                         cached=run.cached, elements=int(mesh.elements.shape[0]),
                         refine=refine, penalty_scale=scale, seconds_mesh=seconds[0],
                         seconds_ccx=seconds[1], seconds_read=seconds[2], cycles=int(cycles),
                         worn_volume_upper=self.worn_volume("upper", mesh),
                         worn_volume_lower=self.worn_volume("lower", mesh))

    # -- subsurface stress and plastic strain ----------------------------------------------
    def subsurface_stress(self, result: IncrementResult, body: Body = "lower",
                          depth: float | None = None, nz: int = 33) -> SubsurfaceStress:
        """Stress under ``body`` for an increment this solver served (the current cycle's
        job), on ``nz`` depths 0..``depth`` (m; default :meth:`_default_grid_depth`) and the
        window's (x, y) (lower body: lab x = window x + ``result.offset``); frame x, y, z =
        depth into the body (:meth:`_stress_on_grid`). A depth beyond the printed columns
        stops the run (:func:`.jobs.check_stress_depth`)."""
        if body not in BODIES:
            raise ValueError(f"body = {body!r} is not allowed: use 'upper' or 'lower'")
        t = self._time_of.get(id(result))
        if t is None:
            raise ValueError(f"result is not an increment of the {self.name} solver's current "
                             "job (subsurface stress is kept for the current cycle only)")
        if int(nz) != nz or nz < 2:
            raise ValueError(f"nz = {nz!r} is not allowed: must be an integer >= 2")
        if depth is None:
            depth = self._default_grid_depth(result)
        depth = check_positive("depth", depth)
        check_stress_depth(depth, self.stress_depth, self.name)  # else exit 3, saying how
        x = self.coords + (result.offset if body == "lower" else 0.0)
        z = np.linspace(0.0, depth, int(nz))
        stress = self._stress_on_grid(body, t, x, z)
        return SubsurfaceStress(body=body, z=z, x=self.coords, y=self.coords, stress=stress,
                                von_mises=von_mises(stress), tresca=max_shear(stress))

    def _nodal_peeq(self, body: str, t: float) -> NDArray[np.float64]:
        """Equivalent plastic strain at the nodes at total time ``t``, [n_nodes, 1] (NaN off
        the column set): each node takes the mean, over the elements around it, of the
        element's Gauss point nearest to it (no extrapolation: >= 0, no overshoot at the
        surface where plastic strain is steepest)."""
        key = (body, t)
        if key not in self._peeq_cache:
            elems, ip = self._peeq_ip(body, t)
            conn = self.mesh.elements[elems - 1]
            peeq = nodal_mean(conn, ip[:, self.NEAREST_GAUSS], self.mesh.nodes.shape[0])
            self._peeq_cache[key] = peeq[:, None]
        return self._peeq_cache[key]

    def _peeq_increment(self, body: str, t: float, prev: float | None) -> NDArray[np.float64]:
        """The nodal equivalent plastic strain gained from total time ``prev`` (None: the
        virgin state) to ``t``, [n_nodes, 1]."""
        now = self._nodal_peeq(body, t)
        return now if prev is None else now - self._nodal_peeq(body, prev)

    # -- what the run measured, and resume -------------------------------------------------
    def _report_extra(self) -> dict[str, Any]:
        """The backend's own entries of :meth:`report` (after ``ccx``)."""
        return {}

    def report(self) -> dict[str, Any]:
        """For summary.json: the backend, mode, material, the plastic law the jobs ran, the
        ccx build, the backend's own entries (:meth:`_report_extra`), the jobs' mean time
        profile (s) and per served cycle its report (:meth:`_cycle_report`; with the ccx
        attempt its job converged on, :meth:`.jobs.CcxJobs._attempt_report`)."""
        return {"backend": self.name, "mode": self.mode, "material": self.material,
                "plastic_law": self._law_report(), "ccx": ccx_build(self.executable),
                **self._report_extra(),
                "profile": self.profile(), "cycles": list(self.cycle_reports)}

    def _law_report(self) -> dict[str, Any] | None:
        """For summary.json: the plastic law the jobs ran (None for elastic bodies): Y,
        the plastic modulus h (Pa), what happens past the UTS and ccx's ``*PLASTIC`` rows
        (true stress Pa, equivalent plastic strain; held after the last)."""
        if not self.plastic:
            return None
        rows = self.plastic_law.plastic_table()
        (y, _), (s1, p1) = rows[0], rows[-1]
        return {"yield_strength_pa": y, "hardening_pa": (s1 - y) / p1 if p1 > 0 else 0.0,
                "beyond_uts": self.plastic_law.beyond_uts,
                "plastic_table": [[s, e] for s, e in rows]}

    def _state_extra(self) -> dict[str, Any]:
        """The backend's own entries of :meth:`state_dict` (the cycle reports among them)."""
        return {"cycle_reports": list(self.cycle_reports)}

    def state_dict(self) -> dict[str, Any]:
        """Between cycles a solver holds no load history the next job needs (every job
        starts from virgin bodies): the cycle counter, whether the bodies were loaded, the
        mode and material, the backend's own entries (:meth:`_state_extra`), the attempt the
        last job converged on and the work folder. The surfaces are set by their owner."""
        return {"cycle": self._cycle, "loaded": self._loaded, "mode": self.mode,
                "material": self.material, **self._state_extra(),
                "last_attempt": self._last_attempt,
                "workdir": None if self.workdir is None else str(self.workdir)}

    def _load_state_extra(self, state: dict[str, Any]) -> None:
        """Restore the backend's own entries of a saved state (default: nothing)."""
        del state

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore :meth:`state_dict` (the next cycle runs its own job); a state of another
        mode or material is a ``ValueError``."""
        for key, default in (("mode", "fresh"), ("material", "elastic")):
            if state.get(key, default) != getattr(self, key):
                raise ValueError(f"saved {self.name} {key} {state.get(key)!r}, this solver "
                                 f"{getattr(self, key)!r}")
        self._cycle = int(state["cycle"])
        self._loaded = bool(state["loaded"])
        self._k = None
        self._job_key = None
        self._served = []
        self._pending = []
        self.cycle_reports = list(state.get("cycle_reports", []))
        self._load_state_extra(state)
        if self.workdir is None and state.get("workdir"):
            self.workdir = Path(state["workdir"])
        self._restore_last_attempt(state, self._refine_unit())
