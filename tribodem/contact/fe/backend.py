"""``fe``: the CalculiX finite-element first body behind the first-body contract (docs/fe.md).

A 2D plane-strain cylindrical pad on a flat (a line contact, seed 003 sections 3.2-3.3 with
the seed's 3D crossed cylinders replaced by their plane-strain section). Mode ``fresh`` (the
seed's way, section 3.3): every fretting cycle is one ccx job on the current worn geometry,
starting from virgin, unloaded bodies: seating, the normal load, then the cycle
0 -> +A -> 0 -> -A -> 0 in the loop's ``n_increments`` increments; the job runs once per
cycle (:meth:`FEContactSolver.begin_cycle`, or the first :meth:`solve_increment` of the
cycle) and :meth:`solve_increment` serves its stored increments, checking that the offsets
are the job's.

Worn geometry (seed eqs 3.7-3.8): the worn depth of each body is its recession (given by
:meth:`set_surfaces`) minus its unworn recession (the one given to the constructor),
evaluated at the x of each straight node column of the mesh; the surface node moves into its
body by that depth and the fine-zone nodes below it are redistributed by
:func:`tribodem.contact.fe.mesh.morph_columns`; :meth:`worn_volume` is the exact volume of the
morphed mesh's lost material (no 0.77 correction).

Fields on the contract's window (``n x n`` points, spacing ``dx``; x along the stroke, y
along the cylinder's axis; a line contact is periodic along y, so every field is constant
along y and ``load`` is the total on the window, P' = load / window in N/m):

* FE nodal values along the pad's surface (the pad's material points: the window travels
  with the upper body, window x = the pad node's undeformed x) are mapped to the window
  cells by exact cell averages of their piecewise-linear interpolant (pressure and shear:
  the window integral equals the FE nodal force sum) and by linear interpolation (slip);
* ``traction`` is the shear traction on the **upper** body (the pad): the x component of
  the contact force on the pad's nodes recovered from the element stresses
  (:mod:`tribodem.contact.fe.results`) over their tributary length, as base.py states;
* ``slip`` is the increment of relative tangential displacement of the upper surface with
  respect to the lower one: for each pad node, its x displacement increment minus that of
  the flat's material point under it at the start of the increment (x of the flat point =
  the pad node's deformed x minus the flat's displacement there);
* ``stick``: contact nodes whose slip increment is at most mu p / k_t, the largest elastic
  displacement of the interface's stick spring (k_t the stick slope, Pa/m).

So the energy density ``-traction . slip`` is the frictional work and is >= 0, and in gross
slip ``|Q| = mu P`` (tests/test_fe_backend.py).
"""

from __future__ import annotations

import hashlib
import math
import time
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tribodem.contact.base import (
    BODIES,
    Body,
    Capabilities,
    ElasticBody,
    FirstBodySolver,
    IncrementResult,
    Recession,
    SubsurfaceStress,
    WindowTooSmallError,
    _check_positive,
    contact_modulus,
    cycle_offsets,
)
from tribodem.contact.elastoplastic import PlasticStep
from tribodem.contact.fe.ccx import (
    FESolverStopped,
    ccx_build,
    find_ccx,
)
from tribodem.contact.fe.deck import LoadCase, sliding_contact, write_deck
from tribodem.contact.fe.jobs import CcxJobs, JobRecord, check_stress_depth
from tribodem.contact.fe.mesh import (
    Mesh,
    PadOnFlat,
    cylinder_on_flat,
    hertz_line,
    morph_columns,
    surface_projection,
    worn_depth,
)
from tribodem.contact.fe.mesh import worn_area as mesh_worn_area
from tribodem.contact.fe.results import GAUSS_2X2, FEResults, ip_coordinates, read_results
from tribodem.contact.geometry import cylinder, flat, line_window
from tribodem.contact.halfspace import max_shear, von_mises
from tribodem.materials.en24t import EN24T

#: default element size at the contact / Hertz half-width of the backend: a/4 (p0 within
#: 0.14 %, a within 1.2 % in the convergence study; a/8 costs about 4x more per cycle at
#: large strokes with node-to-surface contact, docs/fe.md)
FRETTING_H_OVER_A = 0.25

#: modes of :class:`FEContactSolver`: ``fresh`` (one job per cycle, virgin bodies: the
#: seed's way) and ``chained`` (cycles continue in one job while the geometry is unchanged)
MODES = ("fresh", "chained")
#: plastic runs: the smallest number of cycle increments ccx may take per cycle, and the
#: load increments (docs/fe.md, "Elastic-plastic cycles": >= 32 cycle increments converge
#: where 16 stalled; the sliding set-up's 10 E/h penalty is the one measured there)
PLASTIC_MIN_INCREMENTS = 32
PLASTIC_LOAD_INCREMENTS = 10
#: ccx element node order (-1,-1), (1,-1), (1,1), (-1,1) -> the nearest of the 2x2 Gauss
#: points (:data:`GAUSS_2X2` order (-,-), (+,-), (-,+), (+,+))
_NEAREST_GAUSS = np.array([0, 1, 3, 2])

#: nodal values of a bilinear quadrilateral from its 2x2 Gauss-point values: the inverse of
#: N_i at the Gauss points (ccx order of :data:`GAUSS_2X2`), [4 nodes, 4 points]
_EXTRAPOLATE = np.linalg.inv(np.array([[0.25 * (1 + xi * xn) * (1 + eta * en)
                                        for xn, en in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
                                       for xi, eta in GAUSS_2X2]))


def _digest(key: tuple[bytes, bytes]) -> str:
    """A short fingerprint of a geometry key (the column wear of both bodies)."""
    return hashlib.sha1(key[0] + key[1]).hexdigest()


def _second_difference(f: Recession, h: float) -> float:
    """d^2 f / dx^2 at the origin (y = 0) by central differences of step ``h`` (m), 1/m."""
    x = np.array([-h, 0.0, h])
    v = np.asarray(f(x, np.zeros(3)), dtype=float)
    return float((v[0] - 2.0 * v[1] + v[2]) / (h * h))


def cell_average(xn: NDArray[np.float64], vn: NDArray[np.float64],
                 centres: NDArray[np.float64], dx: float) -> NDArray[np.float64]:
    """Averages over the cells ``[c - dx/2, c + dx/2]`` of the piecewise-linear interpolant
    of nodal values ``vn`` at sorted ``xn`` (zero outside ``[xn[0], xn[-1]]``): exact, so the
    cell sum times ``dx`` equals the interpolant's integral over the cells."""
    seg = np.diff(xn)
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (vn[1:] + vn[:-1]) * seg)])

    def prim(x: NDArray[np.float64]) -> NDArray[np.float64]:
        xc = np.clip(x, xn[0], xn[-1])
        j = np.clip(np.searchsorted(xn, xc, side="right") - 1, 0, xn.size - 2)
        t = xc - xn[j]
        slope = (vn[j + 1] - vn[j]) / seg[j]
        return cum[j] + vn[j] * t + 0.5 * slope * t * t

    return (prim(centres + 0.5 * dx) - prim(centres - 0.5 * dx)) / dx


class FEContactSolver(CcxJobs, FirstBodySolver):
    """Plane-strain CalculiX cylinder-on-flat first body (see the module docstring).

    ``upper``/``lower``: recessions (m) of a cylinder with its axis along y and of a flat
    (default: R = 4 mm); the pad radius R is read from the summed recession's curvature at
    the origin. ``load``: total normal load on the window, N (P' = load / window, N/m);
    ``friction``: Coulomb mu; ``n``, ``window`` (m; None: ``window_radii`` Hertz
    half-widths); ``amplitude`` (m) and ``n_increments`` of the loop's cycle (the job's
    output times); ``h_over_a`` (element size at the contact / Hertz half-width) and
    ``size_factor`` (bodies' size / a) of the mesh (defaults from the convergence study in
    docs/fe.md); ``stress_depth`` (m): how deep the column stresses are printed (None: 4 a
    and 1.5 x the threshold criteria's default depth); ``threads``, ``timeout`` (s per ccx
    job), ``retries`` (after a non-convergence: :func:`.jobs.attempt_settings`, halved
    increments, then a softer contact); ``loading_friction``: the friction while seating
    and loading (:data:`.jobs.LOADING_FRICTION`: ``"auto"``, mu for elastic-plastic
    bodies and 0.001 for elastic ones);
    ``workdir``: the folder of the jobs (``cycle_0001/`` ...; None: a new temporary
    folder). ``regime`` and ``tolerance``
    are the half-space's options and are not used (the FE interface always has partial slip
    and its own Newton tolerances).

    ``material``: ``"elastic"`` or ``"elastic-plastic"`` (both bodies bilinear isotropic
    hardening, ``*PLASTIC``: ``yield_strength``, ``uts``, ``uts_strain`` (Pa, Pa, -) of seed
    table 5.1, or a plastic modulus ``hardening`` h in Pa; past the UTS ``beyond_uts``:
    ``"line"``, the same line (the tamaas backend's law), or ``"hold"``; the tamaas EPIC grid
    options ``ep_*``, ``load_steps`` are accepted and not used: the mesh is the grid). Plastic jobs
    take >= ``plastic_increments`` (32) ccx increments per cycle and 10 load increments
    (docs/fe.md).

    ``mode``: ``"fresh"`` (every cycle one job on virgin bodies) or ``"chained"``: a job runs
    ``chain_cycles`` cycles on the same bodies, so plastic strain and residual stress carry
    over, and serves them one by one while the geometry does not change; when they are used
    up the job is run again from the chain's start with ``chain_cycles`` more; a changed
    geometry (material removed) starts a new chain on virgin bodies (counted in
    :meth:`report`: carrying the plastic state onto a morphed mesh is not done).
    """

    #: every capability some configuration gives; an instance's own are
    #: :meth:`capabilities_for` its ``material`` and ``mode``
    name = "fe"
    capabilities = Capabilities(plastic=True, plastic_every_cycle=True, partial_slip=True,
                                subsurface=True, contacts=("line",))

    @classmethod
    def capabilities_for(cls, options: dict[str, Any]) -> Capabilities:
        """``plastic`` with ``material = "elastic-plastic"``; ``plastic_every_cycle`` only
        in ``chained`` mode (a fresh job restarts from virgin material every cycle, so its
        plastic strain would be the first cycle's again and again)."""
        plastic = options.get("material", "elastic") == "elastic-plastic"
        chained = options.get("mode", "fresh") == "chained"
        return Capabilities(plastic=plastic, plastic_every_cycle=plastic and chained,
                            partial_slip=True, subsurface=True, contacts=("line",))

    @classmethod
    def options_for(cls, names: set[str]) -> str:
        opts = []
        if names & {"plastic", "plastic_every_cycle"}:
            opts.append("fe.material = 'elastic-plastic'")
        if "plastic_every_cycle" in names:
            opts.append("fe.mode = 'chained'")
        return " and ".join(opts)

    def __init__(
        self,
        upper: Recession | None = None,
        lower: Recession | None = None,
        load: float | None = None,
        friction: float = 0.6,
        upper_material: ElasticBody | None = None,
        lower_material: ElasticBody | None = None,
        n: int = 64,
        window: float | None = None,
        window_radii: float = 10.0,
        contact: str = "line",
        amplitude: float = 0.1e-3,
        n_increments: int = 16,
        mode: str = "fresh",
        material: str = "elastic",
        chain_cycles: int = 5,
        plastic_increments: int = PLASTIC_MIN_INCREMENTS,
        yield_strength: float = EN24T.yield_strength,
        uts: float = EN24T.uts,
        uts_strain: float = EN24T.uts_strain,
        hardening: float | None = None,
        beyond_uts: str = "line",
        h_over_a: float = FRETTING_H_OVER_A,
        size_factor: float = 40.0,
        threads: int = 1,
        timeout: float = 1800.0,
        retries: int = 1,
        retry_from: str = "first",
        loading_friction: str = "auto",
        cache: str | Path | None = None,
        workdir: str | Path | None = None,
        executable: str | None = None,
        stress_depth: float | None = None,
        regime: str = "gross",
        tolerance: float | None = None,
        ep_n: int | None = None,
        ep_nz: int | None = None,
        ep_window_radii: float | None = None,
        ep_depth_radii: float | None = None,
        load_steps: int | None = None,
        ep_tolerance: float | None = None,
    ) -> None:
        # half-space and EPIC-grid options (see the class docstring)
        del regime, tolerance, ep_n, ep_nz, ep_window_radii, ep_depth_radii, load_steps
        del ep_tolerance
        if (upper is None) != (lower is None):
            raise ValueError("upper and lower must both be given or both be None (defaults)")
        if upper is None or lower is None:
            upper, lower = cylinder(8e-3, axis="y"), flat()
        if contact != "line":
            raise ValueError(f"contact = {contact!r} is not allowed: the fe backend solves a "
                             "line contact only (2D plane strain); allowed: 'line'")
        if mode not in MODES:
            raise ValueError(f"mode = {mode!r} is not allowed: allowed: {', '.join(MODES)}")
        if int(chain_cycles) != chain_cycles or chain_cycles < 1:
            raise ValueError(f"chain_cycles = {chain_cycles!r} is not allowed: an integer >= 1")
        self.mode = mode
        self.chain_cycles = int(chain_cycles)
        self._set_material(material, plastic_increments, yield_strength, uts, uts_strain,
                           hardening, beyond_uts)
        self.capabilities = self.capabilities_for({"material": material, "mode": mode})
        self.executable = find_ccx(executable)  # CcxNotFoundError names the install command
        self.upper, self.lower = upper, lower
        self._base_upper, self._base_lower = upper, lower
        self.friction = _check_positive("friction", friction, allow_zero=True)
        self.upper_material = upper_material or ElasticBody()
        self.lower_material = lower_material or ElasticBody()
        self.modulus = contact_modulus(self.upper_material, self.lower_material)
        if int(n) != n or n < 16 or n % 2:
            raise ValueError(f"n = {n!r} is not allowed: must be an even integer >= 16")
        self.n = int(n)
        self.contact = "line"
        # geometry: a cylinder (axis along y) on a flat
        h = 10e-6
        k_up, k_lo = _second_difference(upper, h), _second_difference(lower, h)
        if not k_up > 0:
            raise ValueError(f"the upper body's recession has no positive curvature along x "
                             f"({k_up:.3g} 1/m): the fe backend models a cylinder on a flat")
        if abs(k_lo) > 1e-6 * k_up:
            raise ValueError(f"the lower body's recession is curved along x ({k_lo:.3g} 1/m): "
                             "the fe backend models a cylinder on a flat")
        ys = np.array([-1e-3, 0.0, 1e-3])
        for name, f in (("upper", upper), ("lower", lower)):
            v = np.asarray(f(np.full(3, 50e-6), ys), dtype=float)
            if float(np.ptp(v)) > 1e-12 * max(abs(float(v[1])), 1e-9):
                raise ValueError(f"the {name} body's recession depends on y: a line contact's "
                                 "surfaces must not (cylinder axis along y)")
        self.radius = 1.0 / k_up
        if load is None:
            load = 1e5 * (window if window is not None else 1e-3)
        self.load = _check_positive("load", load)
        if window is None:
            window = line_window(self.radius, self.load,
                                 self.modulus, _check_positive("window_radii", window_radii))
        self.dx = _check_positive("window", window) / self.n
        self.amplitude = _check_positive("amplitude", amplitude)
        self.offsets = cycle_offsets(self.amplitude, n_increments)
        self.n_increments = int(n_increments)
        self.h_over_a = _check_positive("h_over_a", h_over_a)
        self.size_factor = _check_positive("size_factor", size_factor)
        if self.size_factor < 10.0:
            raise ValueError(f"size_factor = {size_factor!r} is not allowed: the plane-strain "
                             "bodies must be at least 10 half-widths (allowed: >= 10)")
        if int(threads) != threads or threads < 1:
            raise ValueError(f"threads = {threads!r} is not allowed: an integer >= 1")
        self.threads = int(threads)
        self.timeout = _check_positive("timeout", timeout)
        if int(retries) != retries or retries < 0:
            raise ValueError(f"retries = {retries!r} is not allowed: an integer >= 0")
        self.retries = int(retries)
        self._set_retry_from(retry_from)
        #: folder of finished ccx jobs keyed by deck (:func:`.jobs.run_job`; None: no cache)
        self.cache: Path | None = None if cache is None else Path(cache)
        self.workdir: Path | None = None if workdir is None else Path(workdir)
        #: node-to-surface contact, the pair declared once (docs/fe.md, "Reversals": ccx
        #: 2.20's surface-to-surface friction loses 30-40 % of mu P on the return strokes)
        #: depth (m) down to which the stresses of the window's node columns are printed:
        #: given, else 4 half-widths and 1.5 x the threshold criteria's default grid depth,
        #: 3 sqrt(area / pi) of the unworn contact area 2 a W (criteria.py)
        a = self.hertz[1]
        self.stress_depth = (_check_positive("stress_depth", stress_depth)
                             if stress_depth is not None else
                             max(4.0 * a, 4.5 * math.sqrt(2.0 * a * self.window / math.pi)))
        self.settings = sliding_contact(self.friction, self.hertz[0])
        self._set_loading_friction(loading_friction)
        self.jobs: list[JobRecord] = []  #: every ccx job run, in order
        self._mesh0 = self._base_mesh()
        self._job_key: tuple[bytes, bytes] | None = None
        self.reset()
        self._cycle = 0  # cycles served (the job folder's number is the next one)
        self._served: list[IncrementResult] = []
        self.mesh: Mesh = self._mesh0  #: the (morphed) mesh of the last job
        self._job_cycles = 0  # cycles of the last job
        self._chain_start = 1  # the fretting cycle the last job's first cycle served
        self._pos = 0  # cycles of the last job served
        self._loading_pended = False
        self._pending: list[PlasticStep] = []
        self._nodal_cache: dict[tuple[str, float], NDArray[np.float64]] = {}
        self._peeq_cache: dict[tuple[str, float], NDArray[np.float64]] = {}
        self.chain_restarts = 0  #: chained mode: chains restarted because the geometry changed
        self.cycle_reports: list[dict[str, Any]] = []  #: :meth:`_cycle_report` per cycle

    # -- geometry -------------------------------------------------------------------------
    @property
    def load_per_length(self) -> float:
        """P' = load / window, N/m."""
        return self.load / self.window

    @property
    def hertz(self) -> tuple[float, float]:
        """Hertz (p0 Pa, a m) of the unworn line contact (Johnson eq 4.45)."""
        return hertz_line(self.load_per_length, self.radius, self.modulus)

    @property
    def plastic_depth(self) -> float:
        """Depth of the grid of :meth:`plastic_steps`, m: 2 Hertz half-widths (the plastic
        zone of a Hertz line contact with friction lies within ~a of the surface), at most
        the printed column depth."""
        return min(2.0 * self.hertz[1], self.stress_depth)

    def _base_mesh(self) -> Mesh:
        """The unworn mesh, with the element sets ``UCOL``/``LCOL`` of the node columns under
        the window (lower: the window plus the stroke) down to :attr:`stress_depth`."""
        a = self.hertz[1]
        mesh = cylinder_on_flat(PadOnFlat(radius=self.radius, a=a, h_fine=self.h_over_a * a,
                                          stroke=self.amplitude, size_factor=self.size_factor))
        depth = np.full(mesh.n_nodes, np.inf)
        for body in ("lower", "upper"):
            cols = mesh.columns[body]
            depth[cols] = np.abs(mesh.nodes[cols, 1] - mesh.nodes[cols[:, :1], 1])
        c = self.coords
        pad = (math.ceil(self.amplitude / self.dx) + 1) * self.dx
        xe = mesh.nodes[mesh.elements, 0]
        near = depth[mesh.elements].min(axis=1) < self.stress_depth
        for name, body, lo, hi in (("LCOL", "LOWER", c[0] - pad, c[-1] + pad),
                                   ("UCOL", "UPPER", c[0], c[-1])):
            ids = mesh.element_sets[body]
            k = ids - 1
            keep = near[k] & (xe[k].min(axis=1) <= hi) & (xe[k].max(axis=1) >= lo)
            mesh.element_sets[name] = ids[keep]
        return mesh

    def column_wear(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Worn depth (m, >= 0) of each node column of the (upper, lower) mesh: the lumped
        projection (:func:`surface_projection`, sampled at dx / 2) of the current recession
        minus the unworn one at y = 0 (pad frame for the upper body, lab frame for the lower
        one, clipped at zero) onto the surface nodes; zero outside the window (upper) and
        outside the window plus the stroke (lower), where the surfaces are not given. The
        morphed mesh so loses the loop's worn area."""
        out = []
        c = self.coords
        pad = (math.ceil(self.amplitude / self.dx) + 1) * self.dx  # the loop's track grid
        for body, now, base, lo, hi in (
                ("upper", self.upper, self._base_upper, c[0], c[-1]),
                ("lower", self.lower, self._base_lower, c[0] - pad, c[-1] + pad)):
            x = self._mesh0.nodes[self._mesh0.columns[body][:, 0], 0]
            out.append(surface_projection(worn_depth(now, base), x, None,
                                      (lo, hi, -np.inf, np.inf), 0.5 * self.dx))
        return out[0], out[1]

    def morphed_mesh(self) -> Mesh:
        """The unworn mesh with both surfaces receded by :meth:`column_wear` (eqs 3.7-3.8)."""
        wu, wl = self.column_wear()
        try:
            m = morph_columns(self._mesh0, "upper", wu) if wu.any() else self._mesh0
            return morph_columns(m, "lower", wl) if wl.any() else m
        except ValueError as err:
            raise FESolverStopped(f"mesh morphing: {err}") from None

    def worn_volume(self, body: str, mesh: Mesh | None = None) -> float:
        """Worn volume of ``body`` on the window's length, m^3: the exact area between the
        unworn and the morphed surface of ``mesh`` (default: the last job's) times the
        window side along the cylinder's axis."""
        mesh = self.mesh if mesh is None else mesh
        return mesh_worn_area(self._mesh0, mesh, body) * self.window

    def _seat(self, mesh: Mesh) -> float:
        """Seating displacement, m: the smallest rigid gap between the (worn) surfaces plus
        5 % of a^2 / (2 R) (the unworn contact: 5 %, as in :mod:`.deck`)."""
        a = self.hertz[1]
        xu, yu = mesh.nodes[mesh.columns["upper"][:, 0]].T
        xl, yl = mesh.nodes[mesh.columns["lower"][:, 0]].T
        order = np.argsort(xl)
        gap = yu - np.interp(xu, xl[order], yl[order])
        return float(gap.min()) + 0.05 * a * a / (2.0 * self.radius)

    # -- the contract ---------------------------------------------------------------------
    def reset(self) -> None:
        """Forget the load history: the next ``solve_increment(0.0)`` is a first loading
        (in ``chained`` mode on virgin bodies: a new chain)."""
        self._k: int | None = None  # next increment of the cycle in progress (None: none)
        self._loaded = False
        if self.mode == "chained":
            self._job_key = None

    def _start_cycle(self) -> None:
        key = self._key()
        same = key == self._job_key and self.results is not None
        resume = self._resume_chain
        self._resume_chain = None
        if resume is not None and self.mode == "chained" and _digest(key) == resume[0]:
            pos, cycles = resume[1] + 1, resume[2]  # replay the chain, as long as it was
            self._run_job(cycles if pos <= cycles else cycles + self.chain_cycles,
                          chain_start=resume[3])
        elif self._fresh_for_cycle and same:
            pos = 1
        elif self.mode == "chained" and same and self._pos < self._job_cycles:
            pos = self._pos + 1
        elif self.mode == "chained" and same:  # the chain's job is used up: run it longer
            pos = self._pos + 1
            self._run_job(self._job_cycles + self.chain_cycles, chain_start=self._chain_start)
        else:
            if self.mode == "chained" and (self._job_key is not None or resume is not None):
                self.chain_restarts += 1  # the geometry changed: virgin bodies again
            self._run_job(self.chain_cycles if self.mode == "chained" else 1,
                          chain_start=self._cycle + 1)
            pos = 1
        self._fresh_for_cycle = False
        self._serve_cycle(pos)
        self._cycle += 1
        self._k = 0

    def _load(self) -> IncrementResult:
        if self._key() != self._job_key or self.results is None:
            self._run_job(self.chain_cycles if self.mode == "chained" else 1,
                          chain_start=self._cycle + 1)
        return self._serve_loading()

    # -- the job ---------------------------------------------------------------------------
    results: FEResults | None = None  #: the parsed results of the last job
    _resume_chain: tuple[str, int, int, int] | None = None

    def _run_job(self, cycles: int = 1, chain_start: int = 1) -> None:
        """Mesh, morph, write, run (retrying with smaller increments) and read one job of
        ``cycles`` cycles after the loading; ``chain_start``: the fretting cycle its first
        cycle serves."""
        t0 = time.perf_counter()
        folder = self._folder()
        folder.mkdir(parents=True, exist_ok=True)
        mesh = self.morphed_mesh()
        lower, upper = self._materials()
        seat = self._seat(mesh)
        t_mesh = time.perf_counter() - t0
        base = self._cycle_refine()

        def write(refine: int, name: str, scale: float) -> Path:
            case = LoadCase(load=self.load_per_length, delta=self.amplitude,
                            n_increments=self.n_increments, seat=seat, refine=refine,
                            cycle_refine=base,
                            split_cycle=True, cycles=int(cycles), unload=self.plastic,
                            load_increments=PLASTIC_LOAD_INCREMENTS if self.plastic else 5)
            return write_deck(folder / f"{name}.inp", mesh, case, lower, upper,
                              self._scaled_settings(scale), fine_stress=False,
                              stress_sets=("LCOL", "UCOL"))

        run, refine, scale, t_deck, t_ccx = self._run_attempts(write)
        t_mesh += t_deck
        t3 = time.perf_counter()
        res = read_results(run.job, mesh)
        t_read = time.perf_counter() - t3
        rec = JobRecord(cycle=self._cycle + 1, folder=folder, deck=run.job.with_suffix(".inp"),
                        cached=run.cached,
                        elements=mesh.n_elements, refine=refine * base, penalty_scale=scale,
                        seconds_mesh=t_mesh,
                        seconds_ccx=t_ccx, seconds_read=t_read, cycles=int(cycles),
                        worn_volume_upper=self.worn_volume("upper", mesh),
                        worn_volume_lower=self.worn_volume("lower", mesh))
        self.mesh = mesh
        self.results = res
        self._job_key = self._key()
        self._job_cycles = int(cycles)
        self._chain_start = int(chain_start)
        self._pos = 0
        self._loading_pended = False
        self._nodal_cache = {}
        self._peeq_cache = {}
        self._time_of = {}  # total time of each increment served from this job
        self.jobs.append(rec)
        self._write_profile()

    def _time_index(self, t: float) -> int:
        assert self.results is not None
        k = int(np.argmin(np.abs(self.results.times - t)))
        if abs(self.results.times[k] - t) > 1e-6:
            raise FESolverStopped(f"ccx output has no result at total time {t:g} (deck "
                                  f"{self.jobs[-1].deck if self.jobs else '?'})")
        return k

    def cycle_times(self, pos: int) -> NDArray[np.float64]:
        """Total times of the ends of cycle ``pos``'s increments (the job's cycle ``pos``,
        1-based, starts at 2 + 4 (pos - 1))."""
        return 2.0 + 4.0 * (pos - 1) + 4.0 * np.arange(1, self.n_increments + 1) \
            / self.n_increments

    def _surface_nodes(self) -> tuple[NDArray[np.int64], NDArray[np.float64],
                                      NDArray[np.int64], NDArray[np.float64]]:
        """The pad's (UBOT) and the flat's (LTOP) surface nodes sorted by x, and their x."""
        mesh = self.mesh
        ubot, ltop = mesh.node_sets["UBOT"], mesh.node_sets["LTOP"]
        xu0, xl0 = mesh.nodes[ubot - 1, 0], mesh.nodes[ltop - 1, 0]
        ou, ol = np.argsort(xu0), np.argsort(xl0)
        return ubot[ou], xu0[ou], ltop[ol], xl0[ol]

    def _displacement(self, set_name: str, ids: NDArray[np.int64], t: float,
                      comp: int = 1) -> NDArray[np.float64]:
        """Displacement component ``comp`` (1: x, 2: y) of nodes ``ids`` at total time ``t``."""
        assert self.results is not None
        key = (set_name, t)
        if self._disp is None or self._disp_of is not self.results:
            self._disp = {(b.set_name, b.time): b.rows for b in self.results.dat
                          if b.kind == "displacements"}
            self._disp_of = self.results
        rows = self._disp[key]
        order = np.argsort(rows[:, 0])
        j = order[np.searchsorted(rows[order, 0], ids)]
        return rows[j, comp]

    _disp: dict[tuple[str, float], NDArray[np.float64]] | None = None
    _disp_of: FEResults | None = None

    def _increment(self, t: float, prev_t: float | None, off: float, start: float
                   ) -> IncrementResult:
        """The window fields at total time ``t``; ``prev_t`` None: the loading (no slip)."""
        assert self.results is not None
        n, dx, c = self.n, self.dx, self.coords
        ubot, xu0, ltop, xl0 = self._surface_nodes()
        st = self.results.contact[self._time_index(t)]
        # recovered nodal tractions carry round-off of the 7 printed digits (~1e-7 p0):
        # nodes below 1e-5 of the peak pressure are out of contact
        p_node = np.where(st.pressure > 1e-5 * st.pressure.max(), st.pressure, 0.0)
        q_node = np.where(p_node > 0.0, st.shear, 0.0)
        p = cell_average(xu0, p_node, c, dx)
        q = cell_average(xu0, q_node, c, dx)
        contact_x = p > 0.0
        if p[0] > 0.0 or p[-1] > 0.0:
            raise WindowTooSmallError(
                f"the FE contact reaches the window edge (window {self.window:.4g} m, n "
                f"{n}): enlarge contact.window")
        if prev_t is None:
            slip_x = np.zeros(n)
            q = np.zeros(n)  # the loading: no sliding (friction 0.001 while loading)
            stick = None
            direction = 0.0
        else:
            k_t = self._stick_slope()
            u_up0 = self._displacement("UBOT", ubot, prev_t)
            u_up1 = self._displacement("UBOT", ubot, t)
            u_lo0 = self._displacement("LTOP", ltop, prev_t)
            u_lo1 = self._displacement("LTOP", ltop, t)
            x_flat = xu0 + u_up0 - np.interp(xu0 + u_up0, xl0, u_lo0)
            du_lo = np.interp(x_flat, xl0, u_lo1) - np.interp(x_flat, xl0, u_lo0)
            s_node = np.where(p_node > 0.0, (u_up1 - u_up0) - du_lo, 0.0)
            # slip on the window from the contact nodes only: the window's contact reaches
            # up to one node beyond the FE contact (the pressure's linear interpolant), and
            # interpolating towards a free node's zero slip there lost sliding distance
            on = p_node > 0.0
            s_on = np.interp(c, xu0[on], s_node[on]) if on.any() else np.zeros(n)
            slip_x = np.where(contact_x, s_on, 0.0)
            stick_node = (p_node > 0.0) & (np.abs(s_node) <= self.friction * p_node / k_t)
            stick = np.interp(c, xu0, stick_node.astype(float)) > 0.5
            stick = np.repeat((stick & contact_x)[:, None], n, axis=1)
            direction = math.copysign(1.0, off - start)
        p2 = np.repeat(p[:, None], n, axis=1)
        traction = np.zeros((n, n, 2))
        traction[..., 0] = q[:, None]
        slip = np.zeros((n, n, 2))
        slip[..., 0] = slip_x[:, None]
        cell = dx * dx
        inc = IncrementResult(
            offset=off, start_offset=start, direction=direction, pressure=p2,
            traction=traction, slip=slip, contact_area=float(contact_x.sum()) * n * cell,
            normal_load=float(p2.sum()) * cell, stick=stick)
        self._time_of[id(inc)] = t
        return inc

    def _loading_times(self) -> NDArray[np.float64]:
        assert self.results is not None
        t = self.results.times
        return t[(t > 1.0 + 1e-9) & (t <= 2.0 + 1e-9)]

    def _serve_loading(self) -> IncrementResult:
        """The loaded state (total time 2) of the current job; its plastic steps pended."""
        t0 = time.perf_counter()
        inc = self._increment(2.0, None, 0.0, 0.0)
        self._pend_loading()
        self._add_map_time(time.perf_counter() - t0)
        return inc

    def _pend_loading(self) -> None:
        if self.plastic and not self._loading_pended:
            prev: float | None = None
            for t in self._loading_times():
                self._pending.extend(self._plastic_step(float(t), prev))
                prev = float(t)
        self._loading_pended = True

    def _serve_cycle(self, pos: int) -> None:
        """Map cycle ``pos`` of the current job to the window (and its plastic steps)."""
        t0 = time.perf_counter()
        if pos == 1:
            self._pend_loading()  # a job's first cycle comes with its loading
        times = self.cycle_times(pos)
        prev = 2.0 + 4.0 * (pos - 1)
        out = []
        for j, t in enumerate(times):
            off = float(self.offsets[j])
            start = float(self.offsets[j - 1]) if j >= 1 else 0.0
            out.append(self._increment(float(t), prev, off, start))
            if self.plastic:
                self._pending.extend(self._plastic_step(float(t), prev))
            prev = float(t)
        self._served = out
        self._pos = pos
        self.cycle_reports.append(self._cycle_report(pos, out))
        self._add_map_time(time.perf_counter() - t0)

    def _add_map_time(self, seconds: float) -> None:
        if self.jobs:
            self.jobs[-1].seconds_map += seconds
            self._write_profile()

    # -- subsurface stress ----------------------------------------------------------------
    _time_of: dict[int, float] = {}

    def _nodal_stress(self, body: str, t: float) -> NDArray[np.float64]:
        """(sxx, syy, szz, sxy) at the nodes (Pa, [n_nodes, 4]; NaN off the column set) at
        total time ``t``: each element's 2x2 Gauss-point stresses extrapolated to its nodes
        by the inverse bilinear interpolation, averaged over the elements of a node; on the
        surface nodes syy and sxy are the recovered contact traction (-p, -q)."""
        key = (body, t)
        if key not in self._nodal_cache:
            elems, ip = self.results.ip_stress(t, "LCOL" if body == "lower" else "UCOL")
            conn = self.mesh.elements[elems - 1]
            nodal = np.einsum("ik,mkc->mic", _EXTRAPOLATE, ip)  # [m, 4 nodes, 4 comps]
            total = np.zeros((self.mesh.n_nodes, 4))
            count = np.zeros(self.mesh.n_nodes)
            np.add.at(total, conn, nodal)
            np.add.at(count, conn, 1.0)
            with np.errstate(invalid="ignore", divide="ignore"):
                nodal_avg = total / count[:, None]
            # at the surface the traction is known: sigma_YY = -p and sigma_xY = -q (the
            # contact traction on the pad, p and q, acts as (-q, -p) on the flat's outward
            # normal +Y and (q, p) on the pad's -Y); the Gauss-point extrapolation overshoots
            # there in the steep Hertz gradient (measured +9 % of p0 at h = a/4)
            k = int(np.argmin(np.abs(self.results.times - t)))
            st = self.results.contact[k]
            top = self.mesh.columns[body][:, 0]
            xt = self.mesh.nodes[top, 0]
            if body == "lower":
                xt = xt - self.results.ref_displacement[k, 0]  # under the pad's node
            p = np.interp(xt, st.x, np.maximum(st.pressure, 0.0), left=0.0, right=0.0)
            q = np.interp(xt, st.x, st.shear, left=0.0, right=0.0)
            known = np.isfinite(nodal_avg[top, 0])
            nodal_avg[top[known], 1] = -p[known]
            nodal_avg[top[known], 3] = -q[known]
            self._nodal_cache = {key: nodal_avg}
        return self._nodal_cache[key]

    def _column_field(self, body: str, nodal: NDArray[np.float64], x: NDArray[np.float64],
                      z: NDArray[np.float64], what: str = "stresses") -> NDArray[np.float64]:
        """Nodal values ``nodal`` [n_nodes, C] (NaN off the printed columns) on the grid
        (depth ``z`` below the worn surface, ``x`` in the body's mesh frame), [nz, nx, C]:
        linear along each straight node column by the depth below its surface node, then
        linear between columns."""
        cols = self.mesh.columns[body]
        xs = self.mesh.nodes[cols[:, 0], 0]
        j = np.clip(np.searchsorted(xs, x, side="right") - 1, 0, xs.size - 2)
        w = np.clip((x - xs[j]) / (xs[j + 1] - xs[j]), 0.0, 1.0)
        need = np.unique(np.concatenate([j, j + 1]))
        prof = np.zeros((xs.size, z.size, nodal.shape[1]))
        for c in need:
            nodes = cols[c]
            d = np.abs(self.mesh.nodes[nodes, 1] - self.mesh.nodes[nodes[0], 1])
            v = nodal[nodes]
            ok = np.isfinite(v[:, 0])
            if not ok[0] or d[ok].max() < z[-1] * (1 - 1e-9):
                raise ValueError(f"no column {what} under x = {xs[c]:.4g} m down to depth "
                                 f"{z[-1]:.4g} m on the {body} body")
            prof[c] = np.stack([np.interp(z, d[ok], v[ok, k]) for k in range(v.shape[1])],
                               axis=-1)
        out = (1 - w)[:, None, None] * prof[j] + w[:, None, None] * prof[j + 1]
        return np.moveaxis(out, 0, 1)  # [nz, nx, C]

    @staticmethod
    def _voigt(s2: NDArray[np.float64], body: str) -> NDArray[np.float64]:
        """FE (sxx, sYY, szz, sxY) [..., 4] -> the contract's Voigt stress [..., 6] (x, y =
        the cylinder's axis, z = depth into the body: sigma_xz = -sxY under the flat)."""
        sign = -1.0 if body == "lower" else 1.0
        voigt = np.zeros(s2.shape[:-1] + (6,))
        voigt[..., 0] = s2[..., 0]
        voigt[..., 1] = s2[..., 2]
        voigt[..., 2] = s2[..., 1]
        voigt[..., 4] = sign * s2[..., 3]
        return voigt

    def subsurface_stress(self, result: IncrementResult, body: Body = "lower",
                          depth: float | None = None, nz: int = 33) -> SubsurfaceStress:
        """Stress under ``body`` for an increment this solver served (the current cycle's
        job), on ``nz`` depths 0..``depth`` (m; default 3 half-widths, area / (2 window))
        and the window's x (lower body: lab x = window x + ``result.offset``), constant along
        y. Nodal stresses (:meth:`_nodal_stress`) are interpolated along each straight node
        column by the depth below its (worn) surface node, then linearly between columns.
        Frame: x, y (the cylinder's axis, the plane-strain out-of-plane direction), z =
        depth into the body, so sigma_zz is the FE normal stress, sigma_yy the out-of-plane
        one and sigma_xz = -sigma_xy(FE) under the flat, +sigma_xy(FE) in the pad: at the
        surface sigma_xz = q under the flat and -q in the pad, q the shear traction on the
        upper body (the half-space backend's convention)."""
        if body not in BODIES:
            raise ValueError(f"body = {body!r} is not allowed: use 'upper' or 'lower'")
        t = self._time_of.get(id(result))
        if t is None:
            raise ValueError("result is not an increment of the fe solver's current job "
                             "(subsurface stress is kept for the current cycle only)")
        if int(nz) != nz or nz < 2:
            raise ValueError(f"nz = {nz!r} is not allowed: must be an integer >= 2")
        if depth is None:
            depth = 3.0 * max(result.contact_area, self.dx**2) / (2.0 * self.window)
        depth = _check_positive("depth", depth)
        check_stress_depth(depth, self.stress_depth, self.name)  # else exit 3, saying how
        x = self.coords + (result.offset if body == "lower" else 0.0)
        z = np.linspace(0.0, depth, int(nz))
        voigt = self._voigt(self._column_field(body, self._nodal_stress(body, t), x, z), body)
        stress = np.repeat(voigt[:, :, None, :], self.n, axis=2)
        return SubsurfaceStress(body=body, z=z, x=self.coords, y=self.coords, stress=stress,
                                von_mises=von_mises(stress), tresca=max_shear(stress))

    # -- plastic strain (material = "elastic-plastic") --------------------------------------
    def _nodal_peeq(self, body: str, t: float) -> NDArray[np.float64]:
        """Equivalent plastic strain at the nodes at total time ``t``, [n_nodes, 1] (NaN
        off the column set): each node takes the mean, over the elements around it, of
        the element's Gauss point nearest to it (no extrapolation: >= 0, no overshoot at
        the surface where plastic strain is steepest)."""
        key = (body, t)
        if key not in self._peeq_cache:
            assert self.results is not None
            elems, ip = self.results.peeq(t, "LCOL" if body == "lower" else "UCOL")
            conn = self.mesh.elements[elems - 1]
            total = np.zeros(self.mesh.n_nodes)
            count = np.zeros(self.mesh.n_nodes)
            np.add.at(total, conn, ip[:, _NEAREST_GAUSS])
            np.add.at(count, conn, 1.0)
            with np.errstate(invalid="ignore", divide="ignore"):
                self._peeq_cache[key] = (total / count)[:, None]
        return self._peeq_cache[key]

    def _plastic_step(self, t: float, prev_t: float | None) -> list[PlasticStep]:
        """The plastic step ending at total time ``t`` from ``prev_t`` (None: from the
        virgin state), one per body, on [33, nx, 2] grids (constant along the cylinder's
        axis y; the two y points span the window twice)."""
        z = np.linspace(0.0, self.plastic_depth, 33)
        y = np.array([-self.window, self.window])
        k = self._time_index(t)
        assert self.results is not None
        load = float(abs(self.results.normal_force[k])) * self.window
        steps = []
        for body in BODIES:
            x = self._plastic_grid_x(body)
            now = self._nodal_peeq(body, t)
            dp_nodal = now if prev_t is None else now - self._nodal_peeq(body, prev_t)
            dp = np.maximum(self._column_field(body, dp_nodal, x, z, "plastic strain")[..., 0],
                            0.0)
            stress = self._voigt(self._column_field(body, self._nodal_stress(body, t), x, z),
                                 body)
            steps.append(PlasticStep(z=z, x=x, y=y, body=body, load=load,
                                     dp=np.repeat(dp[:, :, None], 2, axis=2),
                                     stress=np.repeat(stress[:, :, None, :], 2, axis=2)))
        return steps

    # -- what a cycle measured -------------------------------------------------------------
    def _cycle_report(self, pos: int, incs: list[IncrementResult]) -> dict[str, Any]:
        """Peak stresses, plastic strain, pile-up and traction of the cycle just served
        (fretting cycle ``self._cycle + 1``, cycle ``pos`` of its job); see :meth:`report`."""
        assert self.results is not None
        res, mesh = self.results, self.mesh
        t_end = float(self.cycle_times(pos)[-1])
        times = [float(t) for t in self.cycle_times(pos)]
        if pos == 1:
            times = [float(t) for t in self._loading_times()] + times
        row: dict[str, Any] = ({"cycle": self._cycle + 1, "job_cycle": pos}
                               | self._attempt_report())
        vm_max = s22_c = s22_t = 0.0
        for set_name in ("UCOL", "LCOL"):
            for t in times:
                _, ip = res.ip_stress(t, set_name)
                s = ip.reshape(-1, 4)
                vm = np.sqrt(0.5 * ((s[:, 0] - s[:, 1]) ** 2 + (s[:, 1] - s[:, 2]) ** 2
                                    + (s[:, 2] - s[:, 0]) ** 2) + 3.0 * s[:, 3] ** 2)
                vm_max = max(vm_max, float(vm.max()))
                s22_c = max(s22_c, float(-s[:, 1].min()))
                s22_t = max(s22_t, float(s[:, 1].max()))
        row |= {"max_von_mises_pa": vm_max, "max_s22_compressive_pa": s22_c,
                "max_s22_tensile_pa": s22_t}
        if self.plastic:
            for body, set_name in (("upper", "UCOL"), ("lower", "LCOL")):
                elems, pe = res.peeq(t_end, set_name)
                k = np.unravel_index(int(np.argmax(pe)), pe.shape)
                xy = ip_coordinates(mesh.nodes[mesh.elements[elems[k[0]] - 1]][None])[0, k[1]]
                top = mesh.columns[body][:, 0]
                order = np.argsort(mesh.nodes[top, 0])
                y_surf = np.interp(xy[0], mesh.nodes[top[order], 0], mesh.nodes[top[order], 1])
                row[f"max_peeq_{body}"] = float(pe[k])
                row[f"max_peeq_depth_{body}_m"] = float(abs(xy[1] - y_surf))
        if self.plastic and pos == self._job_cycles:
            # the job ends by lifting the pad off: the residual surfaces after the cycle.
            # Pile-up: the largest rise of the flat's surface above its undeformed level
            # (and of the pad's surface towards the flat, relative to the pad's top); dent:
            # the deepest residual depression
            t_off = t_end + 1.0
            ubot, _, ltop, _ = self._surface_nodes()
            k_off = self._time_index(t_off)
            u_lo = self._displacement("LTOP", ltop, t_off, 2)
            u_up = self._displacement("UBOT", ubot, t_off, 2) - res.ref_displacement[k_off, 1]
            row |= {"pile_up_lower_m": float(max(u_lo.max(), 0.0)),
                    "dent_lower_m": float(max(-u_lo.min(), 0.0)),
                    "pile_up_upper_m": float(max(-u_up.min(), 0.0)),
                    "dent_upper_m": float(max(u_up.max(), 0.0))}
        q = np.array([float(np.abs(i.traction[..., 0]).max()) for i in incs])
        quarter = max(len(incs) // 4, 1)
        first, last = float(q[:quarter].max()), float(q[-quarter:].max())
        row |= {"max_traction_first_quarter_pa": first, "max_traction_last_quarter_pa": last,
                "traction_drop": (last - first) / first if first > 0 else 0.0}
        qa = [abs(float(res.tangential_force[self._time_index(times[-1 - 3 * quarter])])),
              abs(float(res.tangential_force[self._time_index(times[-1 - quarter])]))]
        row["q_over_mu_p_at_plus_minus_a"] = [v / (self.friction * self.load_per_length)
                                              for v in qa]
        return row

    def report(self) -> dict[str, Any]:
        """For summary.json: mode, material, jobs and their mean time profile, chains
        restarted, and per served cycle (:meth:`_cycle_report`): max von Mises, max S22
        (compressive and tensile; the FE's vertical normal stress) over the column sets at
        every output time of the cycle (and of the loading in a job's first cycle), max
        equivalent plastic strain per body at the cycle's end and its depth below the
        surface; for the last cycle of a plastic job, after the pad is lifted off, the
        residual pile-up (largest rise of the flat's surface above its undeformed level,
        of the pad's towards the flat) and dent (deepest residual depression); the largest
        shear traction in
        the cycle's first and last quarters and the drop between them (last / first - 1),
        |Q| / (mu P) at +A and -A; the ccx attempt its job converged on
        (:meth:`.jobs.CcxJobs._attempt_report`)."""
        return {"backend": "fe", "mode": self.mode, "material": self.material,
                "plastic_law": self._law_report(),
                "ccx": ccx_build(self.executable),
                "chain_cycles": self.chain_cycles if self.mode == "chained" else None,
                "chain_restarts": self.chain_restarts, "profile": self.profile(),
                "cycles": list(self.cycle_reports)}

    # -- resume ---------------------------------------------------------------------------
    def state_dict(self) -> dict[str, Any]:
        """Between cycles a fresh-mode solver holds no load history (every cycle is a new job
        on virgin bodies): the cycle counter, whether the bodies were loaded, the work
        folder and the cycle reports. A chained solver also saves where it is in its chain
        (a digest of the chain's geometry, the cycles served and run, the chain's first
        cycle): on resume the chain's job is run again and serves the next cycle, as the
        uninterrupted run would (ccx's earlier steps do not depend on later ones). The
        surfaces are set by their owner."""
        chain = None
        if self.mode == "chained" and self._job_key is not None and self.results is not None:
            chain = [_digest(self._job_key), self._pos, self._job_cycles, self._chain_start]
        return {"cycle": self._cycle, "loaded": self._loaded, "mode": self.mode,
                "material": self.material, "chain": chain,
                "chain_restarts": self.chain_restarts,
                "cycle_reports": list(self.cycle_reports),
                "last_attempt": self._last_attempt,
                "workdir": None if self.workdir is None else str(self.workdir)}

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore :meth:`state_dict` (the next cycle runs its own job)."""
        if state.get("mode", "fresh") != self.mode:
            raise ValueError(f"saved fe mode {state.get('mode')!r}, this solver {self.mode!r}")
        if state.get("material", "elastic") != self.material:
            raise ValueError(f"saved fe material {state.get('material')!r}, this solver "
                             f"{self.material!r}")
        self._cycle = int(state["cycle"])
        self._loaded = bool(state["loaded"])
        self._k = None
        self._job_key = None
        self.results = None
        self._served = []
        self._pending = []
        chain = state.get("chain")
        self._resume_chain = None if chain is None else (
            str(chain[0]), int(chain[1]), int(chain[2]), int(chain[3]))
        self.chain_restarts = int(state.get("chain_restarts", 0))
        self.cycle_reports = list(state.get("cycle_reports", []))
        if self.workdir is None and state.get("workdir"):
            self.workdir = Path(state["workdir"])
        self._restore_last_attempt(state, self._cycle_refine())

    def _cycle_refine(self) -> int:
        """ccx increments per output increment of a cycle (plastic: at least
        ``plastic_increments`` per cycle); ``jobs.csv``'s refine is an attempt's times it."""
        return math.ceil(self.plastic_increments / self.n_increments) if self.plastic else 1
