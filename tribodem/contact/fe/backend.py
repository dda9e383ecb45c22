"""``fe``: the CalculiX finite-element first body behind the first-body contract (docs/fe.md).

A 2D plane-strain cylindrical pad on a flat (a line contact, Lu (2018) sections 3.2-3.3 with
the seed's 3D crossed cylinders replaced by their plane-strain section). Mode ``fresh`` (the
seed's way, section 3.3): every fretting cycle is one ccx job on the current worn geometry,
starting from virgin, unloaded bodies: seating, the normal load, then the cycle
0 -> +A -> 0 -> -A -> 0 in the loop's ``n_increments`` increments; the job runs once per
cycle (:meth:`FEContactSolver.begin_cycle`, or the first :meth:`solve_increment` of the
cycle) and :meth:`solve_increment` serves its stored increments, checking that the offsets
are the job's.

Worn geometry (seed eqs 3.7-3.8): the worn depth of each body is its recession (given by
:meth:`set_surfaces`) minus its unworn recession (the case's, given to the constructor),
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
    Capabilities,
    IncrementResult,
    Recession,
    WindowTooSmallError,
)
from tribodem.contact.elastoplastic import PlasticStep
from tribodem.contact.fe.base import (
    CcxBackend,
    column_set,
    nodal_mean,
    residual_surfaces,
    traction_quarters,
)
from tribodem.contact.fe.ccx import FESolverStopped
from tribodem.contact.fe.deck import SLIDING_PENALTY, LoadCase, write_deck
from tribodem.contact.fe.mesh import (
    Mesh,
    PadOnFlat,
    cylinder_on_flat,
    hertz_line,
    morph_columns,
)
from tribodem.contact.fe.mesh import worn_area as mesh_worn_area
from tribodem.contact.fe.options import PLASTIC_MIN_INCREMENTS as PLASTIC_MIN_INCREMENTS
from tribodem.contact.fe.options import FEOptions
from tribodem.contact.fe.results import GAUSS_2X2, FEResults, ip_coordinates, read_results
from tribodem.contact.geometry import line_window

#: default element size at the contact / Hertz half-width of the backend: a/4 (p0 within
#: 0.14 %, a within 1.2 % in the convergence study; a/8 costs about 4x more per cycle at
#: large strokes with node-to-surface contact, docs/fe.md)
FRETTING_H_OVER_A = 0.25

#: modes of :class:`FEContactSolver`: ``fresh`` (one job per cycle, virgin bodies: the
#: seed's way) and ``chained`` (cycles continue in one job while the geometry is unchanged)
MODES = ("fresh", "chained")
#: plastic runs: the load increments (docs/fe.md, "Elastic-plastic cycles"; the fewest
#: cycle increments are :data:`.options.PLASTIC_MIN_INCREMENTS`; the sliding set-up's
#: 10 E/h penalty is the one measured there)
PLASTIC_LOAD_INCREMENTS = 10

#: nodal values of a bilinear quadrilateral from its 2x2 Gauss-point values: the inverse of
#: N_i at the Gauss points (ccx order of :data:`GAUSS_2X2`), [4 nodes, 4 points]
_EXTRAPOLATE = np.linalg.inv(np.array([[0.25 * (1 + xi * xn) * (1 + eta * en)
                                        for xn, en in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
                                       for xi, eta in GAUSS_2X2]))


def _digest(key: tuple[bytes, ...]) -> str:
    """A short fingerprint of a geometry key (the column wear of both bodies)."""
    return hashlib.sha1(b"".join(key)).hexdigest()


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


class FEContactSolver(CcxBackend[Mesh]):
    """Plane-strain CalculiX cylinder-on-flat first body (see the module docstring).

    ``case`` (:class:`~tribodem.contact.base.ContactCase`): ``upper``/``lower`` are the
    recessions (m) of a cylinder with its axis along y and of a flat; the pad radius R is
    read from the summed recession's curvature at the origin. ``load``: the total normal
    load on the window, N (P' = load / window, N/m); ``window`` None: ``window_radii``
    Hertz half-widths; ``stress_depth`` None: 4 a and 1.5 x the threshold criteria's default
    depth. The rest as :class:`~tribodem.contact.fe.base.CcxBackend`.

    ``fe`` (:class:`~tribodem.contact.fe.options.FEOptions`, every field but fe3d's
    ``cycle_increments``, ``max_wear_slope``, ``morph`` and ``max_wear_kink``): ``h_over_a``
    (element size at the contact / Hertz half-width; own 0.25) and ``size_factor`` (bodies'
    size / a, >= 10; own 40) of the mesh (the convergence study in docs/fe.md);
    ``threads``, ``timeout`` (s per ccx job; own 1800 s), ``retries`` (after a
    non-convergence: :func:`.jobs.attempt_settings`, halved increments, then a softer
    contact), ``retry_from``, ``loading_friction`` (the friction while seating and loading,
    :data:`.jobs.LOADING_FRICTION`: ``"auto"``, mu for elastic-plastic bodies and 0.001 for
    elastic ones), ``cache`` (a folder of finished jobs).

    ``material``: ``"elastic"`` or ``"elastic-plastic"`` (both bodies bilinear isotropic
    hardening, ``*PLASTIC``, the ``plastic`` table's law: seed table 5.1, or a plastic
    modulus ``hardening``; past the UTS ``beyond_uts`` ``"line"``, the tamaas backend's law,
    or ``"hold"``). Plastic jobs take >= ``plastic_increments`` (32) ccx increments per
    cycle and 10 load increments (docs/fe.md).

    ``mode``: ``"fresh"`` (every cycle one job on virgin bodies) or ``"chained"``: a job runs
    ``chain_cycles`` cycles on the same bodies, so plastic strain and residual stress carry
    over, and serves them one by one while the geometry does not change; when they are used
    up the job is run again from the chain's start with ``chain_cycles`` more; a changed
    geometry (material removed) starts a new chain on virgin bodies (counted in
    :meth:`report`: carrying the plastic state onto a morphed mesh is not done).
    """

    name = "fe"
    contact = "line"
    #: every capability some configuration gives; an instance's own are
    #: :meth:`capabilities_for` its ``material`` and ``mode``
    capabilities = Capabilities(plastic=True, plastic_every_cycle=True, partial_slip=True,
                                subsurface=True, contacts=("line",))
    FE_FIELDS = frozenset(FEOptions.model_fields) - {"cycle_increments", "max_wear_slope",
                                                     "morph", "max_wear_kink"}
    OWN_DEFAULTS = {"h_over_a": FRETTING_H_OVER_A, "size_factor": 40.0, "timeout": 1800.0}
    MODES = MODES
    SOLVES = "a line contact only (2D plane strain)"
    PENALTY_FACTOR = SLIDING_PENALTY
    #: ccx element node order (-1,-1), (1,-1), (1,1), (-1,1) -> the nearest of the 2x2
    #: Gauss points (:data:`GAUSS_2X2` order (-,-), (+,-), (-,+), (+,+))
    NEAREST_GAUSS = np.array([0, 1, 3, 2])
    #: the plastic zone of a Hertz line contact with friction lies within ~a of the surface
    PLASTIC_DEPTH_RADII = 2.0

    @classmethod
    def options_for(cls, names: set[str]) -> str:
        opts = []
        if names & {"plastic", "plastic_every_cycle"}:
            opts.append("fe.material = 'elastic-plastic'")
        if "plastic_every_cycle" in names:
            opts.append("fe.mode = 'chained'")
        return " and ".join(opts)

    def _set_mode(self, fe: FEOptions) -> None:
        """The mode (:data:`MODES`) and, chained, the cycles per job."""
        super()._set_mode(fe)
        chain_cycles = fe.chain_cycles
        if int(chain_cycles) != chain_cycles or chain_cycles < 1:
            raise ValueError(f"chain_cycles = {chain_cycles!r} is not allowed: an integer >= 1")
        self.chain_cycles = int(chain_cycles)

    # -- geometry -------------------------------------------------------------------------
    def _radius_of(self, upper: Recession, lower: Recession) -> float:
        """R = 1 / the upper recession's curvature along x: a cylinder (axis along y) on a
        flat, neither depending on y."""
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
        return 1.0 / k_up

    def _default_window(self, radii: float) -> float:
        return line_window(self.radius, self.load, self.modulus, radii)

    def _check_size_factor(self, size_factor: float) -> None:
        if size_factor < 10.0:
            raise ValueError(f"size_factor = {size_factor!r} is not allowed: the plane-strain "
                             "bodies must be at least 10 half-widths (allowed: >= 10)")

    def _default_stress_depth(self) -> float:
        """4 half-widths and 1.5 x the threshold criteria's default grid depth, 3 sqrt(area /
        pi) of the unworn contact area 2 a W (criteria.py)."""
        a = self.hertz[1]
        return max(4.0 * a, 4.5 * math.sqrt(2.0 * a * self.window / math.pi))

    def _setup(self) -> None:
        self._mesh0 = self._base_mesh()
        self.mesh = self._mesh0
        self._job_cycles = 0  # cycles of the last job
        self._chain_start = 1  # the fretting cycle the last job's first cycle served
        self._pos = 0  # cycles of the last job served
        self._loading_pended = False
        self.chain_restarts = 0  #: chained mode: chains restarted because the geometry changed

    @property
    def load_per_length(self) -> float:
        """P' = load / window, N/m."""
        return self.load / self.window

    @property
    def hertz(self) -> tuple[float, float]:
        """Hertz (p0 Pa, a m) of the unworn line contact (Johnson eq 4.45)."""
        return hertz_line(self.load_per_length, self.radius, self.modulus)

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
        c, pad = self.coords, self.pad
        xe = mesh.nodes[mesh.elements, 0]
        near = depth[mesh.elements].min(axis=1) < self.stress_depth
        for name, body, lo, hi in (("LCOL", "LOWER", c[0] - pad, c[-1] + pad),
                                   ("UCOL", "UPPER", c[0], c[-1])):
            ids = mesh.element_sets[body]
            k = ids - 1
            keep = near[k] & (xe[k].min(axis=1) <= hi) & (xe[k].max(axis=1) >= lo)
            mesh.element_sets[name] = ids[keep]
        return mesh

    def _projection_grid(self, body: str) -> tuple[NDArray[np.float64], None, float]:
        """The x of ``body``'s surface nodes (the line contact's projection is along x)."""
        return self._mesh0.nodes[self._mesh0.columns[body][:, 0], 0], None, np.inf

    def _morph(self, mesh: Mesh, body: str, wear: NDArray[np.float64]) -> Mesh:
        return morph_columns(mesh, body, wear)

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
        folder, mesh, seat, t0 = self._job_start()
        lower, upper = self._materials()
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
        t3 = time.perf_counter()
        res = read_results(run.job, mesh)
        t_read = time.perf_counter() - t3
        rec = self._job_record(folder, mesh, run, refine * base, scale,
                               (t_mesh + t_deck, t_ccx, t_read), cycles)
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
        if self._disp is None or self._disp_of is not self.results:
            self._disp = {(b.set_name, b.time): b.rows for b in self.results.dat
                          if b.kind == "displacements"}
            self._disp_of = self.results
        # the .dat file prints the times rounded (2.16667 for 2 + 1/6): the nearest one
        times = [bt for name, bt in self._disp if name == set_name]
        near = min(times, key=lambda bt: abs(bt - t), default=None)
        if near is None or abs(near - t) > 1e-5 * max(1.0, abs(t)):
            raise FESolverStopped(f"ccx output has no {set_name} displacements at total time "
                                  f"{t:g} (deck {self.jobs[-1].deck if self.jobs else '?'})")
        rows = self._disp[(set_name, near)]
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
    def _nodal_stress(self, body: str, t: float) -> NDArray[np.float64]:
        """(sxx, syy, szz, sxy) at the nodes (Pa, [n_nodes, 4]; NaN off the column set) at
        total time ``t``: each element's 2x2 Gauss-point stresses extrapolated to its nodes
        by the inverse bilinear interpolation, averaged over the elements of a node; on the
        surface nodes syy and sxy are the recovered contact traction (-p, -q)."""
        key = (body, t)
        if key not in self._nodal_cache:
            assert self.results is not None
            elems, ip = self.results.ip_stress(t, column_set(body))
            conn = self.mesh.elements[elems - 1]
            nodal = np.einsum("ik,mkc->mic", _EXTRAPOLATE, ip)  # [m, 4 nodes, 4 comps]
            nodal_avg = nodal_mean(conn, nodal, self.mesh.n_nodes)
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

    def _default_grid_depth(self, result: IncrementResult) -> float:
        """3 half-widths of the contact (area / (2 window)), m."""
        return 3.0 * max(result.contact_area, self.dx**2) / (2.0 * self.window)

    def _stress_on_grid(self, body: str, t: float, x: NDArray[np.float64],
                        z: NDArray[np.float64]) -> NDArray[np.float64]:
        """Nodal stresses (:meth:`_nodal_stress`) interpolated along each straight node
        column by the depth below its (worn) surface node, then linearly between columns,
        constant along y. Frame: x, y (the cylinder's axis, the plane-strain out-of-plane
        direction), z = depth into the body, so sigma_zz is the FE normal stress, sigma_yy
        the out-of-plane one and sigma_xz = -sigma_xy(FE) under the flat, +sigma_xy(FE) in
        the pad: at the surface sigma_xz = q under the flat and -q in the pad, q the shear
        traction on the upper body (the half-space backend's convention)."""
        voigt = self._voigt(self._column_field(body, self._nodal_stress(body, t), x, z), body)
        return np.repeat(voigt[:, :, None, :], self.n, axis=2)

    # -- plastic strain (material = "elastic-plastic") --------------------------------------
    def _peeq_ip(self, body: str, t: float) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
        assert self.results is not None
        return self.results.peeq(t, column_set(body))

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
            dp_nodal = self._peeq_increment(body, t, prev_t)
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
        """What the cycle just served (fretting cycle ``self._cycle + 1``, cycle ``pos`` of
        its job) measured, its row of :meth:`report`'s ``cycles``: max von Mises, max S22
        (compressive and tensile; the FE's vertical normal stress) over the column sets at
        every output time of the cycle (and of the loading in a job's first cycle); with
        plastic bodies the max equivalent plastic strain per body at the cycle's end and
        its depth below the surface, and for the last cycle of the job, after the pad is
        lifted off, the residual pile-up and dent (:func:`.base.residual_surfaces`); the
        largest shear traction in the cycle's first and last quarters and the drop between
        them (:func:`.base.traction_quarters`), |Q| / (mu P) at +A and -A; the ccx attempt
        its job converged on (:meth:`.jobs.CcxJobs._attempt_report`)."""
        assert self.results is not None
        res = self.results
        t_end = float(self.cycle_times(pos)[-1])
        times = [float(t) for t in self.cycle_times(pos)]
        if pos == 1:
            times = [float(t) for t in self._loading_times()] + times
        row: dict[str, Any] = ({"cycle": self._cycle + 1, "job_cycle": pos}
                               | self._attempt_report() | self._peak_stresses(times))
        if self.plastic:
            row |= self._peeq_peaks(t_end)
        if self.plastic and pos == self._job_cycles:
            # the job ends by lifting the pad off: the residual surfaces after the cycle
            # (the pad's relative to its top)
            t_off = t_end + 1.0
            ubot, _, ltop, _ = self._surface_nodes()
            k_off = self._time_index(t_off)
            u_lo = self._displacement("LTOP", ltop, t_off, 2)
            u_up = self._displacement("UBOT", ubot, t_off, 2) - res.ref_displacement[k_off, 1]
            row |= residual_surfaces(u_lo, u_up)
        row |= traction_quarters(np.array([float(np.abs(i.traction[..., 0]).max())
                                           for i in incs]))
        quarter = max(len(incs) // 4, 1)
        qa = [abs(float(res.tangential_force[self._time_index(times[-1 - 3 * quarter])])),
              abs(float(res.tangential_force[self._time_index(times[-1 - quarter])]))]
        row["q_over_mu_p_at_plus_minus_a"] = [v / (self.friction * self.load_per_length)
                                              for v in qa]
        return row

    def _peak_stresses(self, times: list[float]) -> dict[str, float]:
        """Max von Mises and max S22 (compressive and tensile), Pa, over the column sets'
        Gauss points at the total ``times``."""
        assert self.results is not None
        vm_max = s22_c = s22_t = 0.0
        for set_name in ("UCOL", "LCOL"):
            for t in times:
                _, ip = self.results.ip_stress(t, set_name)
                s = ip.reshape(-1, 4)
                vm = np.sqrt(0.5 * ((s[:, 0] - s[:, 1]) ** 2 + (s[:, 1] - s[:, 2]) ** 2
                                    + (s[:, 2] - s[:, 0]) ** 2) + 3.0 * s[:, 3] ** 2)
                vm_max = max(vm_max, float(vm.max()))
                s22_c = max(s22_c, float(-s[:, 1].min()))
                s22_t = max(s22_t, float(s[:, 1].max()))
        return {"max_von_mises_pa": vm_max, "max_s22_compressive_pa": s22_c,
                "max_s22_tensile_pa": s22_t}

    def _peeq_peaks(self, t: float) -> dict[str, float]:
        """Per body the max equivalent plastic strain over its column set's Gauss points at
        total time ``t`` and its depth below the body's (worn) surface, m."""
        assert self.results is not None
        mesh, row = self.mesh, {}
        for body in ("upper", "lower"):
            elems, pe = self.results.peeq(t, column_set(body))
            k = np.unravel_index(int(np.argmax(pe)), pe.shape)
            xy = ip_coordinates(mesh.nodes[mesh.elements[elems[k[0]] - 1]][None])[0, k[1]]
            top = mesh.columns[body][:, 0]
            order = np.argsort(mesh.nodes[top, 0])
            y_surf = np.interp(xy[0], mesh.nodes[top[order], 0], mesh.nodes[top[order], 1])
            row[f"max_peeq_{body}"] = float(pe[k])
            row[f"max_peeq_depth_{body}_m"] = float(abs(xy[1] - y_surf))
        return row

    def _report_extra(self) -> dict[str, Any]:
        """Chained mode's cycles per job (None in fresh mode) and chains restarted."""
        return {"chain_cycles": self.chain_cycles if self.mode == "chained" else None,
                "chain_restarts": self.chain_restarts}

    # -- resume ---------------------------------------------------------------------------
    def _state_extra(self) -> dict[str, Any]:
        """A chained solver saves where it is in its chain (a digest of the chain's
        geometry, the cycles served and run, the chain's first cycle): on resume the chain's
        job is run again and serves the next cycle, as the uninterrupted run would (ccx's
        earlier steps do not depend on later ones); with the chains restarted and the cycle
        reports."""
        chain = None
        if self.mode == "chained" and self._job_key is not None and self.results is not None:
            chain = [_digest(self._job_key), self._pos, self._job_cycles, self._chain_start]
        return {"chain": chain, "chain_restarts": self.chain_restarts,
                "cycle_reports": list(self.cycle_reports)}

    def _load_state_extra(self, state: dict[str, Any]) -> None:
        self.results = None
        chain = state.get("chain")
        self._resume_chain = None if chain is None else (
            str(chain[0]), int(chain[1]), int(chain[2]), int(chain[3]))
        self.chain_restarts = int(state.get("chain_restarts", 0))

    def _refine_unit(self) -> int:
        return self._cycle_refine()

    def _cycle_refine(self) -> int:
        """ccx increments per output increment of a cycle (plastic: at least
        ``plastic_increments`` per cycle); ``jobs.csv``'s refine is an attempt's times it."""
        return math.ceil(self.plastic_increments / self.n_increments) if self.plastic else 1
