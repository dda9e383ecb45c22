"""``fe3d``: the 3D CalculiX crossed-cylinder first body behind the contract (docs/fe3d.md).

The seed's geometry (Lu (2018) figure 3.4): two crossed cylinders of equal radius R, the upper
one's axis along y, the lower one's along x, the stroke along x (a point contact). The mesh is
:func:`tribodem.contact.fe.crossed.crossed_mesh`'s *half* model (y >= 0, symmetry u_y = 0 on
y = 0; the stroke breaks the x = 0 symmetry): 8-node bricks on straight vertical node columns,
the fine zone covering the stroke along x; the lower body's column grid is the upper one's
shifted by h/2 along x (its cylinder's axis: the surface is unchanged), so no slave node of
the node-to-surface pair sits on a master node (with coincident grids the loading diverged).

Mode ``fresh`` (the seed's way, section 3.3), as the 2D backend
(:class:`tribodem.contact.fe.backend.FEContactSolver`): every fretting cycle is one ccx job on
the current worn geometry, virgin unloaded bodies: seating, the normal load (P / 2 on the half
model's reference node), then the cycle 0 -> +A -> 0 -> -A -> 0 with **one step per monotonic
quarter** and **node-to-surface** contact declared once in the model data
(:func:`tribodem.contact.fe.deck.sliding_contact`: the n2s large-clearance tension 1e-5 p0;
surface-to-surface friction is wrong on return strokes once the slide crosses elements,
docs/fe.md "Reversals").

Mode ``primed`` (a continuous fretting test): the same fresh job per cycle, but from the
second cycle on the job runs the previous cycle's second half (0 -> -A -> 0) after the
loading and before the served cycle, so the served cycle starts with the tangential history
a continuous test has there; for elastic bodies that is the steady Mindlin-Deresiewicz loop
4 mu P (A - 0.8 delta*) per cycle instead of the fresh cycle's 4 mu P (A - delta*)
(docs/fe3d.md "fe3d vs half-space"). It costs two more quarters per job. Plastic strain is
primed by that half cycle only (not accumulated over the run).

Worn geometry (seed eqs 3.7-3.8): the worn depth of each body (its recession from
:meth:`set_surfaces` minus the unworn one, the case's) is read on the fretting loop's cells
(upper: its own frame, the window; lower: lab frame, the window plus the stroke) and each
node column (i, j) takes its tributary share of their volume (``[fe] morph = "tributary"``,
:func:`.mesh.tributary_depths`: the mesh loses the maps' volume to rounding), relaxed to
``max_wear_slope`` and smoothed to ``max_wear_kink`` volume for volume (:mod:`.slope`); the
surface node moves into its body by that depth and the fine-section nodes below it are
redistributed proportionally (x, y unchanged, :func:`morph_columns3d`);
:meth:`FE3DContactSolver.worn_volume` is the exact volume lost by the morphed hexahedra.

Fields on the contract's ``n x n`` window (the upper body's frame, base.py), the half model
mirrored to y < 0 (pressure, x traction and x slip even in y; y traction and y slip odd):

* ``pressure``, ``traction``: the contact force on each surface node of the upper body,
  recovered from its contact layer's Gauss-point stresses
  (:func:`tribodem.contact.fe.crossed.element_forces`), over the node's tributary area;
  mapped to the window cells by exact cell averages of their bilinear interpolant (the
  window integral equals the nodal force sum). ``traction`` acts on the **upper** body;
* ``slip``: for each upper surface node, its (x, y) displacement increment minus that of
  the lower body's material point under it at the start of the increment (bilinear over the
  lower surface grid), interpolated bilinearly to the window points inside the contact;
* ``stick``: contact points whose slip increment is at most mu p / k_t (k_t the stick slope).
"""

from __future__ import annotations

import io
import math
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from tribodem.contact.base import (
    BODIES,
    Capabilities,
    IncrementResult,
    Recession,
    WindowTooSmallError,
    checked_debris_pressure,
    mindlin_kappa,
)
from tribodem.contact.elastoplastic import PlasticStep
from tribodem.contact.fe.backend import PLASTIC_LOAD_INCREMENTS, cell_average
from tribodem.contact.fe.base import (
    CcxBackend,
    column_set,
    nodal_mean,
    residual_surfaces,
    traction_quarters,
)
from tribodem.contact.fe.ccx import CcxConvergenceError, FESolverStopped
from tribodem.contact.fe.crossed import (
    GAUSS_2X2X2,
    NODE_XI,
    CrossedCase,
    Mesh3D,
    crossed_mesh,
    dshape,
    element_forces,
    tributary_area,
    write_mesh3d,
    write_ref_tie,
)
from tribodem.contact.fe.deck import (
    ContactSettings,
    FEMaterial,
    fmt,
    static_step,
    write_material,
    write_time_points,
)
from tribodem.contact.fe.jobs import checked_increments
from tribodem.contact.fe.mesh import tributary_depths, worn_depth
from tribodem.contact.fe.options import CONVERGED_SLOPE as CONVERGED_SLOPE
from tribodem.contact.fe.options import FEOptions
from tribodem.contact.fe.results import DatBlock, read_dat
from tribodem.contact.fe.slope import KinkLimit, SlopeLimit, limit_kink, limit_slope, steepest
from tribodem.contact.geometry import HertzSphere

if TYPE_CHECKING:
    from tribodem.contact.base import ContactCase
    from tribodem.contact.options import PlasticOptions

#: default element size at the contact / Hertz radius of the 3D backend (a/3: Hertz p0 and
#: a within 3 % on the window, gross slip within 0.5 %, 4-8 min per +-25 um cycle on the
#: shared 2-core machine, docs/fe3d.md)
FRETTING3D_H_OVER_A = 1.0 / 3.0
#: default bodies' extent / Hertz radius (x and y half-extent and height of each body)
FRETTING3D_SIZE_FACTOR = 8.0
#: element growth outside the fine zone
FRETTING3D_GROWTH = 1.4
#: contact penalty of the 3D backend: normal stiffness = factor x E_min / h, Pa/m
PENALTY_FACTOR = 10.0
#: the first ccx increment of each quarter of the cycle (each starts at a reversal, where
#: the whole contact sticks again) slides this fraction of the Mindlin gross-slip
#: displacement (ccx then grows it). Started at the largest increment, the seed's first
#: elastic-plastic reversal needed 5 cut-backs, ccx's limit (two PARDISO threads: 6, "too
#: many cutbacks"); from 1/4 of it, 1-3; the elastic quick case (+-0.3 mm, 48 increments)
#: stopped at its first reversal after 6 (docs/fe3d.md, measured)
REVERSAL_SLIDE = 0.25
#: modes of :class:`FE3DContactSolver` (``chained`` is the 2D backend's only)
MODES = ("fresh", "primed")
#: how the wear maps become the columns' depths (``[fe] morph``): ``tributary``, each surface
#: node's exact share of every wear-map cell's volume (:func:`.mesh.tributary_depths`);
#: ``projection``, the lumped projection of the interpolated surface sampled at dx / 2
#: (:func:`.mesh.surface_projection`, the base class's)
MORPHS = ("tributary", "projection")

#: trilinear shape functions of the C3D8 nodes at its 2x2x2 Gauss points, [8 gp, 8 nodes];
#: its inverse extrapolates Gauss-point values to the nodes
_N_AT_GP = np.prod(1.0 + GAUSS_2X2X2[:, None, :] * NODE_XI[None, :, :], axis=2) / 8.0
_EXTRAPOLATE3 = np.linalg.inv(_N_AT_GP)


#: mirror signs (y -> -y) of the stress components (ccx order xx, yy, zz, xy, xz, yz) and
#: of a scalar
_STRESS_MIRROR = np.array([1.0, 1.0, 1.0, -1.0, 1.0, -1.0])
_ONE = np.ones(1)


def _projected_area(v: NDArray[np.float64]) -> NDArray[np.float64]:
    """Area (m^2) of quadrilateral faces [m, 4 nodes, 3] projected on the x-y plane (half
    the cross product of the diagonals): the z component of a pressure's force is p times
    it."""
    d1, d2 = v[:, 2, :2] - v[:, 0, :2], v[:, 3, :2] - v[:, 1, :2]
    return 0.5 * np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])


def _voigt(s: NDArray[np.float64], body: str) -> NDArray[np.float64]:
    """ccx-order stress [..., 6] (lab frame, z up) to the contract's frame (z = depth into
    ``body``: xz and yz flip under the lower body), Voigt xx, yy, zz, yz, xz, xy."""
    sign = -1.0 if body == "lower" else 1.0
    voigt = np.empty_like(s)
    voigt[..., 0], voigt[..., 1], voigt[..., 2] = s[..., 0], s[..., 1], s[..., 2]
    voigt[..., 3] = sign * s[..., 5]
    voigt[..., 4] = sign * s[..., 4]
    voigt[..., 5] = s[..., 3]
    return voigt


def _curvatures(f: Recession, h: float = 10e-6) -> tuple[float, float]:
    """(d^2 f / dx^2, d^2 f / dy^2) at the origin by central differences, 1/m."""
    x = np.array([-h, 0.0, h, 0.0, 0.0])
    y = np.array([0.0, 0.0, 0.0, -h, h])
    v = np.asarray(f(x, y), dtype=float)
    return float((v[0] - 2 * v[1] + v[2]) / h**2), float((v[3] - 2 * v[1] + v[4]) / h**2)


def hex_volumes(nodes: NDArray[np.float64], elements: NDArray[np.int64]) -> NDArray[np.float64]:
    """Volumes (m^3) of C3D8 elements by the 2x2x2 Gauss rule (exact for hexahedra with
    vertical straight edges over rectangles, the det J being bilinear in (xi, eta) there)."""
    x = nodes[elements]
    vol = np.zeros(elements.shape[0])
    for xi in GAUSS_2X2X2:
        vol += np.linalg.det(np.einsum("mki,kj->mij", x, dshape(xi)))
    return vol


def mesh_columns(mesh: Mesh3D) -> dict[str, NDArray[np.int64]]:
    """Node rows (0-based) of the straight vertical columns of both bodies of a
    :func:`crossed_mesh`: {body: [ny, nx, nz]}, index 0 on the contact surface."""
    nx, ny, nz = (int(mesh.info[k]) for k in ("nx", "ny", "nz"))
    layer = nx * ny
    lower = np.arange(nz * layer).reshape(nz, ny, nx)[::-1].transpose(1, 2, 0)
    upper = (nz * layer + np.arange(nz * layer)).reshape(nz, ny, nx).transpose(1, 2, 0)
    return {"lower": lower, "upper": upper}


def morph_columns3d(mesh: Mesh3D, body: str, wear: NDArray[np.float64]) -> Mesh3D:
    """A copy of ``mesh`` with the surface of ``body`` receded by ``wear`` (m, [ny, nx], one
    depth per column (j, i), >= 0) by node-column morphing (seed eqs 3.7-3.8): the surface
    node moves along its vertical column into the body by dW, the fine-section nodes below
    it down to the fine section's bottom node z_b (fixed; H below the surface) move by
    z_i = z_b + m (z_i - z_b), m = (H - dW) / H; x and y never change. ``ValueError`` when a
    depth reaches H (the fine section would invert)."""
    cols = mesh_columns(mesh)[body]
    wear = np.asarray(wear, dtype=float)
    if wear.shape != cols.shape[:2]:
        raise ValueError(f"wear has shape {wear.shape}: expected {cols.shape[:2]} (ny, nx)")
    if np.any(wear < 0) or not np.all(np.isfinite(wear)):
        raise ValueError("wear depths must be finite and >= 0 (m)")
    k = int(mesh.info["fine_layers"])
    nodes = mesh.nodes.copy()
    fine = cols[..., :k + 1]
    z = nodes[fine, 2]
    zb = z[..., -1:]
    height = np.abs(z[..., :1] - zb)
    if np.any(wear >= height[..., 0]):
        j, i = np.unravel_index(int(np.argmax(wear / height[..., 0])), wear.shape)
        raise ValueError(f"worn depth {wear[j, i]:.4g} m at (x, y) = "
                         f"({nodes[cols[j, i, 0], 0]:.4g}, {nodes[cols[j, i, 0], 1]:.4g}) m "
                         f"reaches the fine section's depth H = {height[j, i, 0]:.4g} m of the "
                         f"{body} body: the mesh cannot be morphed further")
    nodes[fine, 2] = zb + (height - wear[..., None]) / height * (z - zb)  # eqs 3.7-3.8
    out = Mesh3D(nodes=nodes, elements=mesh.elements, n_lower=mesh.n_lower,
                 node_sets=mesh.node_sets, element_sets=mesh.element_sets,
                 h_fine=mesh.h_fine, info=dict(mesh.info))
    out.check()
    return out


def _grid(mesh: Mesh3D, body: str) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The (xs, ys) of a body's column grid (ys >= 0, the half model), m."""
    surf = mesh.nodes[mesh_columns(mesh)[body][..., 0]]
    return surf[0, :, 0].copy(), surf[:, 0, 1].copy()


def _mirror(a: NDArray[np.float64], sign: float = 1.0) -> NDArray[np.float64]:
    """A half-model field [ny, ...] (y >= 0, row 0 on y = 0) on the full grid [2 ny - 1, ...]
    (``sign`` -1 for a component odd in y)."""
    return np.concatenate([sign * a[:0:-1], a], axis=0)


def _bilinear(xs: NDArray[np.float64], ys: NDArray[np.float64], f: NDArray[np.float64],
              x: NDArray[np.float64], y: NDArray[np.float64]) -> NDArray[np.float64]:
    """Bilinear interpolation of ``f`` [ny, nx, ...] on the sorted grid (xs, ys) at the points
    (x, y) (clamped to the grid), [n_points, ...]."""
    i = np.clip(np.searchsorted(xs, x, side="right") - 1, 0, xs.size - 2)
    j = np.clip(np.searchsorted(ys, y, side="right") - 1, 0, ys.size - 2)
    tx = np.clip((x - xs[i]) / (xs[i + 1] - xs[i]), 0.0, 1.0)
    ty = np.clip((y - ys[j]) / (ys[j + 1] - ys[j]), 0.0, 1.0)
    ex = tuple([slice(None)] + [None] * (f.ndim - 2))
    tx, ty = tx[ex], ty[ex]
    return ((1 - ty) * ((1 - tx) * f[j, i] + tx * f[j, i + 1])
            + ty * ((1 - tx) * f[j + 1, i] + tx * f[j + 1, i + 1]))


def _operator(xn: NDArray[np.float64], centres: NDArray[np.float64], dx: float,
              average: bool) -> NDArray[np.float64]:
    """Linear map [n_centres, n_nodes] from nodal values on ``xn`` to the window: exact cell
    averages of the piecewise-linear interpolant (``average``) or its point values."""
    eye = np.eye(xn.size)
    if average:
        return np.stack([cell_average(xn, e, centres, dx) for e in eye], axis=1)
    return np.stack([np.interp(centres, xn, e, left=0.0, right=0.0) for e in eye], axis=1)


class FE3DContactSolver(CcxBackend[Mesh3D]):
    """3D CalculiX crossed-cylinder first body, half model (see the module docstring).

    ``case`` (:class:`~tribodem.contact.base.ContactCase`): ``upper``/``lower`` are the
    recessions (m) of a cylinder with its axis along y and one with its axis along x, of
    equal radius R (read from their curvatures at the origin; the seed's R = 4 mm);
    ``load``: normal load, N; ``window`` None: ``window_radii`` Hertz radii;
    ``stress_depth`` None: 4.5 a, 1.5 x the threshold criteria's default grid depth 3 a. The
    rest as :class:`~tribodem.contact.fe.base.CcxBackend`; ``growth``: the mesh's element
    growth outside the fine zone.

    ``fe`` (:class:`~tribodem.contact.fe.options.FEOptions`, every field; ``chain_cycles``
    is taken and not used, mode ``chained`` being the 2D backend's): ``h_over_a`` (element
    size at the contact / Hertz radius a; own 1/3), ``size_factor`` (bodies' extent / a, at
    most R / (2 a); own 8); ``threads``, ``timeout`` (s per ccx job; own 14400 s),
    ``retries`` (after a non-convergence: :func:`.jobs.attempt_settings`, halved
    increments, then a softer contact), ``retry_from``, ``loading_friction`` (the friction
    while seating and loading, :data:`.jobs.LOADING_FRICTION`: ``"auto"``, mu for
    elastic-plastic bodies and 0.001 for elastic ones), ``cache``; ``max_wear_slope``: the
    steepest worn-depth step / column spacing the morphed mesh carries
    (:func:`.slope.limit_slope`, volume kept; default :data:`CONVERGED_SLOPE`; None: the
    criterion's surface as projected); ``morph``: how the wear maps become column depths
    (:data:`MORPHS`); ``max_wear_kink``: the largest change of slope at a node the morphed
    mesh carries (:func:`.slope.limit_kink`, volume kept; default
    :data:`~.options.DEFAULT_KINK`; None: no smoothing); ``cycle_increments``: the fewest
    ccx increments per cycle, the output times staying the loop's ``n_increments`` (None:
    ``n_increments``, and ``plastic_increments`` for elastic-plastic bodies; the quick
    preset's 64 took 443 -> 299 Newton iterations a cycle, docs/fe3d.md "Contact set-up",
    quick preset);
    ``mode`` ``"fresh"`` or ``"primed"``; ``material`` ``"elastic"`` or
    ``"elastic-plastic"`` (the ``plastic`` table's law, bilinear EN24T by default, fresh
    cycles; ``beyond_uts``: past the UTS the hardening line goes on, ``"line"``, or the
    flow stress is held, ``"hold"``).
    """

    name = "fe3d"
    contact = "point"
    #: the class's widest capabilities; an instance's are :meth:`capabilities_for` its
    #: ``material`` (fresh mode only: plastic strain of one cycle at a time; never
    #: ``plastic_every_cycle``: the 2D backend's ``chained`` mode is not built in 3D)
    capabilities = Capabilities(plastic=True, partial_slip=True, subsurface=True, debris=True,
                                contacts=("point",))
    FE_FIELDS = frozenset(FEOptions.model_fields)
    OWN_DEFAULTS = {"h_over_a": FRETTING3D_H_OVER_A, "size_factor": FRETTING3D_SIZE_FACTOR,
                    "timeout": 14400.0}
    MODES = MODES
    SOLVES = "crossed cylinders (a point contact)"
    #: penalty 10 E / h (50 E / h, the 2D value, made the reversals' stick/slip states
    #: flip for ever at h = a/2: measured, docs/fe3d.md)
    PENALTY_FACTOR = PENALTY_FACTOR
    #: the Gauss point nearest each C3D8 node (the one in the node's octant), [8 nodes]
    NEAREST_GAUSS = np.argmax(NODE_XI @ GAUSS_2X2X2.T, axis=1)
    #: first yield of a point contact at 0.48 a, shallower with friction
    PLASTIC_DEPTH_RADII = 1.5

    @classmethod
    def options_for(cls, names: set[str]) -> str:
        return "fe.material = 'elastic-plastic'" if names == {"plastic"} else ""
    #: ccx SMALL SLIDING (pair slave nodes and master faces once per increment): off, the
    #: loading diverged with it (measured, docs/fe3d.md); the lower grid is shifted by h/2
    #: along x instead, so no slave node sits on a master node
    small_sliding: bool = False

    def __init__(self, case: ContactCase, fe: FEOptions | None = None,
                 plastic: PlasticOptions | None = None, *, executable: str | None = None,
                 workdir: str | Path | None = None, window_radii: float = 10.0,
                 growth: float = FRETTING3D_GROWTH) -> None:
        self.growth = growth  # checked with the mesh's other options
        super().__init__(case, fe, plastic, executable=executable, workdir=workdir,
                         window_radii=window_radii)

    # -- options and geometry -------------------------------------------------------------
    def _set_mesh_options(self, fe: FEOptions) -> None:
        """The fewest ccx increments per cycle, the mesh's size and its growth."""
        #: ccx increments per output increment of the cycle: at least ``cycle_increments``
        #: (any material) and, plastic, ``plastic_increments`` per cycle
        self.cycle_increments = (None if fe.cycle_increments is None else
                                 checked_increments("cycle_increments", fe.cycle_increments))
        fewest = max(self.plastic_increments if self.plastic else 1,
                     self.cycle_increments or 1)
        self.cycle_refine = math.ceil(fewest / self.n_increments)
        super()._set_mesh_options(fe)
        growth = self.growth
        self.growth = float(growth)
        if not (math.isfinite(self.growth) and self.growth >= 1.0):
            raise ValueError(f"growth = {growth!r} is not allowed: must be >= 1")

    def _set_job_options(self, fe: FEOptions, workdir: str | Path | None) -> None:
        """How the jobs run, and the worn surface's slope limit."""
        super()._set_job_options(fe, workdir)
        max_wear_slope = fe.max_wear_slope
        if max_wear_slope is not None and not (math.isfinite(max_wear_slope)
                                               and max_wear_slope > 0.0):
            raise ValueError(f"max_wear_slope = {max_wear_slope!r} is not allowed: a number "
                             "> 0 (the steepest step / column spacing the mesh carries) or "
                             "None (off)")
        #: the steepest worn-depth step / column spacing the morphed mesh carries (None: the
        #: criterion's surface as projected; :func:`.slope.limit_slope`)
        self.max_wear_slope = None if max_wear_slope is None else float(max_wear_slope)
        kink = fe.max_wear_kink
        if kink is not None and not (math.isfinite(kink) and kink > 0.0):
            raise ValueError(f"max_wear_kink = {kink!r} is not allowed: a number > 0 (the "
                             "largest change of slope at a node the mesh carries) or None "
                             "(off)")
        #: the largest change of slope at a node column the morphed mesh carries (None: no
        #: smoothing; :func:`.slope.limit_kink`)
        self.max_wear_kink = None if kink is None else float(kink)
        if fe.morph not in MORPHS:
            raise ValueError(f"morph = {fe.morph!r} is not allowed: allowed: "
                             + ", ".join(MORPHS))
        #: how the wear maps become column depths (:data:`MORPHS`)
        self.morph = fe.morph

    def _radius_of(self, upper: Recession, lower: Recession) -> float:
        """R = 2 / (the upper's curvature along x + the lower's along y): crossed cylinders
        of equal radius (the upper curved along x only, the lower along y only)."""
        ux, uy = _curvatures(upper)
        lx, ly = _curvatures(lower)
        if not (ux > 0 and ly > 0) or abs(uy) > 1e-6 * ux or abs(lx) > 1e-6 * ly:
            raise ValueError(
                "the fe3d backend models crossed cylinders: the upper body curved along x only "
                f"(axis along y) and the lower along y only (axis along x); got curvatures "
                f"upper ({ux:.3g}, {uy:.3g}), lower ({lx:.3g}, {ly:.3g}) 1/m")
        if abs(ux / ly - 1.0) > 1e-3:
            raise ValueError(f"the fe3d backend models cylinders of equal radius; got R = "
                             f"{1 / ux:.4g} and {1 / ly:.4g} m")
        return 2.0 / (ux + ly)

    def _default_window(self, radii: float) -> float:
        return radii * self.hertz[1]

    def _check_size_factor(self, size_factor: float) -> None:
        a = self.hertz[1]
        if size_factor * a > 0.5 * self.radius:
            raise ValueError(f"size_factor = {size_factor!r} is not allowed: the bodies' extent "
                             f"size_factor x a = {size_factor * a:.4g} m must not exceed "
                             f"R / 2 = {0.5 * self.radius:.4g} m (allowed: <= "
                             f"{0.5 * self.radius / a:.3g})")

    def _default_stress_depth(self) -> float:
        return 4.5 * self.hertz[1]

    def _setup(self) -> None:
        self._mesh0 = self._base_mesh()
        self._cols = mesh_columns(self._mesh0)
        self._grids: dict[str, tuple[NDArray[np.float64], NDArray[np.float64]]] = {
            b: _grid(self._mesh0, b) for b in BODIES}
        self._xs, self._ys = self._grids["upper"]
        self._xl = self._grids["lower"][0]
        self._ys_full = _mirror(self._ys, -1.0)
        c = self.coords
        if self._xs[-1] < c[-1] or self._ys[-1] < c[-1]:
            raise ValueError(f"the window (side {self.window:.4g} m) is wider than the mesh "
                             f"(half-extent {self._ys[-1]:.4g} m): raise size_factor or give "
                             "a smaller window")
        self._avg_x = _operator(self._xs, c, self.dx, True)
        self._avg_y = _operator(self._ys_full, c, self.dx, True)
        self._pt_x = _operator(self._xs, c, self.dx, False)
        self._pt_y = _operator(self._ys_full, c, self.dx, False)
        self._areas: dict[str, NDArray[np.float64]] = {
            b: tributary_area(*np.meshgrid(xs, ys), xs, ys) for b, (xs, ys) in self._grids.items()}
        self._area = self._areas["upper"]
        # the upper surface nodes all of whose bottom-layer elements are in UCONT (the
        # tractions are recovered there; elsewhere the element sums are incomplete)
        m0 = self._mesh0
        n_cell = (self._xs.size - 1) * (self._ys.size - 1)
        bottom = m0.elements[m0.n_lower:m0.n_lower + n_cell, :4]
        ucont = m0.elements[m0.element_sets["UCONT"] - 1, :4]
        count = np.zeros(m0.nodes.shape[0])
        np.add.at(count, bottom, 1.0)
        np.add.at(count, ucont, -1.0)
        self._complete = count[self._cols["upper"][..., 0]] == 0.0
        #: per body, what ``max_wear_slope`` did to the last :meth:`column_wear`
        self.slope_limits: dict[str, SlopeLimit] = {}
        #: per body, what ``max_wear_kink`` did to the last :meth:`column_wear`
        self.kink_limits: dict[str, KinkLimit] = {}
        self._loaded_result: IncrementResult | None = None
        self._debris_pressure = np.zeros((self.n, self.n))  # prescribed debris pressure, Pa
        self._debris_load = 0.0
        self.mesh = self._mesh0

    @property
    def hertz(self) -> tuple[float, float]:
        """Hertz (p0 Pa, a m) of the unworn contact (a sphere of radius R on a flat)."""
        hz = HertzSphere(self.radius, self.load, self.modulus)
        return hz.peak_pressure, hz.contact_radius

    def _base_mesh(self) -> Mesh3D:
        """The unworn half mesh with the element sets ``UCOL``/``LCOL`` of the columns under
        the window (lower: plus the stroke) down to :attr:`stress_depth`."""
        a = self.hertz[1]
        h = self.h_over_a * a
        case = CrossedCase(load=self.load, radius=self.radius, h_fine=h,
                           size_factor=self.size_factor, growth=self.growth,
                           delta=self.amplitude)
        mesh = crossed_mesh(case, a=a, shift_lower=0.5 * h)
        cols = mesh_columns(mesh)
        depth = np.full(mesh.nodes.shape[0], np.inf)
        for body in BODIES:
            cb = cols[body]
            depth[cb] = np.abs(mesh.nodes[cb, 2] - mesh.nodes[cb[..., :1], 2])
        c = self.coords
        xe = mesh.nodes[mesh.elements, 0]
        ye = mesh.nodes[mesh.elements, 1]

        def outer(grid: NDArray[np.float64], lo: float, hi: float) -> tuple[float, float]:
            """The grid nodes enclosing [lo, hi] (the columns the interpolation uses)."""
            i = max(int(np.searchsorted(grid, lo, side="right")) - 1, 0)
            j = min(int(np.searchsorted(grid, hi, side="left")), grid.size - 1)
            return float(grid[i]), float(grid[j])

        el = np.arange(1, mesh.elements.shape[0] + 1)
        lower = el <= mesh.n_lower
        for name, body, lo, hi in (("LCOL", "lower", c[0] - self.pad, c[-1] + self.pad),
                                   ("UCOL", "upper", c[0], c[-1])):
            xs, ys = _grid(mesh, body)
            lo, hi = outer(xs, lo, hi)
            y_hi = outer(ys, 0.0, c[-1])[1]
            keep = ((lower if body == "lower" else ~lower)
                    & (depth[mesh.elements].min(axis=1) < self.stress_depth)
                    & (ye.min(axis=1) <= y_hi) & (xe.min(axis=1) <= hi)
                    & (xe.max(axis=1) >= lo))
            mesh.element_sets[name] = el[keep]
        return mesh

    def _projection_grid(self, body: str) -> tuple[NDArray[np.float64], NDArray[np.float64],
                                                    float]:
        """``body``'s column grid (x, y >= 0 of the half model), given up to the window's
        last point along y."""
        xs, ys = self._grids[body]
        return xs, ys, float(self.coords[-1])

    def _column_depths(self, body: str, now: Recession, base: Recession, lo: float,
                       hi: float) -> NDArray[np.float64]:
        """``morph = "tributary"``: the worn depth ``now - base`` (clipped at zero) read on
        the fretting loop's cells (the window's points for the upper body, the track's, the
        window widened by :attr:`pad`, for the lower; at a cell's centre the loop's height
        map returns its own value) and carried onto the half model's columns by each
        node's exact share of every cell's volume, y folded onto y >= 0
        (:func:`.mesh.tributary_depths`): the morphed mesh loses sum(d) dx^2, the loop's
        worn volume, to rounding. ``"projection"``: the base class's lumped projection
        (``lo``, ``hi``: the x range, m)."""
        if self.morph == "projection":
            return super()._column_depths(body, now, base, lo, hi)
        c, dx = self.coords, self.dx
        k = int(round(self.pad / dx)) if body == "lower" else 0
        x = (np.arange(c.size + 2 * k) - c.size // 2 - k) * dx
        gx, gy = np.meshgrid(x, c)
        d = worn_depth(now, base)(gx.ravel(), gy.ravel()).reshape(gx.shape)
        xs, ys = self._grids[body]
        try:
            return tributary_depths(d, x, c, dx, dx, xs, ys, fold_y=True)
        except ValueError as err:
            raise FESolverStopped(f"mesh morphing ({body} body): {err}") from None

    def _relaxed(self, body: str, wear: NDArray[np.float64]) -> NDArray[np.float64]:
        """With ``max_wear_slope`` the depths relaxed, volume for volume, until no step
        between neighbouring columns is steeper (:func:`.slope.limit_slope`), then with
        ``max_wear_kink`` smoothed, volume for volume, until no node's change of slope
        exceeds it, the slope limit kept (:func:`.slope.limit_kink`, the y = 0 row a
        symmetry line); what they did per body in :attr:`slope_limits` and
        :attr:`kink_limits`."""
        if self.max_wear_slope is not None and wear.any():
            wear, lim = limit_slope(wear, *self._grids[body], self._areas[body],
                                    self.max_wear_slope)
            self.slope_limits[body] = lim
        if self.max_wear_kink is not None and wear.any():
            slope = np.inf if self.max_wear_slope is None else self.max_wear_slope
            wear, kl = limit_kink(wear, *self._grids[body], self._areas[body],
                                  self.max_wear_kink, slope, mirror_y0=True)
            self.kink_limits[body] = kl
        return wear

    def _morph(self, mesh: Mesh3D, body: str, wear: NDArray[np.float64]) -> Mesh3D:
        return morph_columns3d(mesh, body, wear)

    def worn_volume(self, body: str, mesh: Mesh3D | None = None) -> float:
        """Worn volume of ``body`` (m^3, both halves): the exact volume between the unworn and
        the morphed surface of ``mesh`` (default: the last job's). The columns are vertical
        over rectangles and the surfaces bilinear per cell, so it is the sum of the columns'
        surface displacement times their tributary areas (= the hexahedra's volume loss)."""
        mesh = self.mesh if mesh is None else mesh
        top = self._cols[body][..., 0]
        dz = np.abs(mesh.nodes[top, 2] - self._mesh0.nodes[top, 2])
        return 2.0 * float((dz * self._areas[body]).sum())

    def _seat(self, mesh: Mesh3D) -> float:
        """Seating displacement, m: the smallest rigid gap between the (worn) surfaces (under
        each upper surface node, the lower surface bilinear between its nodes) plus 5 % of
        the Hertz approach a^2 / R."""
        a = self.hertz[1]
        up = mesh.nodes[self._cols["upper"][..., 0]]
        z_lo = mesh.nodes[self._cols["lower"][..., 0], 2]
        inside = (up[..., 0] >= self._xl[0]) & (up[..., 0] <= self._xl[-1])
        below = _bilinear(self._xl, self._ys, z_lo, up[..., 0][inside], up[..., 1][inside])
        gap = up[..., 2][inside] - below
        return float(gap.min()) + 0.05 * a * a / self.radius

    @property
    def gross_slip_displacement(self) -> float:
        """Cattaneo-Mindlin relative tangential displacement at the onset of gross slip of
        the circular contact, m: delta* = mu kappa a^2 / R (``mindlin_kappa``; = 3 mu P /
        (16 a) ((2 - nu1) / G1 + (2 - nu2) / G2), Johnson 1985 eq. 7.42 with both bodies'
        compliances; a the Hertz radius). A reversal of the stroke takes 2 delta* to slide
        again."""
        a = self.hertz[1]
        kappa = mindlin_kappa(self.upper_material, self.lower_material)
        return self.friction * kappa * a * a / self.radius

    # -- the deck ---------------------------------------------------------------------------
    def write_deck(self, path: str | Path, mesh: Mesh3D, seat: float, refine: int = 1,
                   penalty_scale: float = 1.0) -> Path:
        """The ccx deck: half model, node-to-surface pair once (:meth:`_write_model`),
        seating (REF down by ``seat`` m, friction 0.001), the load P / 2 on REF (automatic
        increments <= 1/4), the cycle as one step per quarter (REF x ramped to +A, 0, -A, 0,
        increments <= 4 / n_increments, divided by ``refine``), outputs at the loop's
        offsets (:meth:`_outputs`); ``penalty_scale``: a retry's softer contact."""
        s = self._scaled_settings(penalty_scale)
        lo_m, up_m = self._materials()
        out = io.StringIO()
        ref = self._write_model(out, mesh, s, lo_m, up_m)
        n_load = PLASTIC_LOAD_INCREMENTS if self.plastic else 4
        q = self.n_increments // 4
        write_time_points(out, "TLOAD", np.arange(1, 5) / 4.0)  # outputs: 4 per load step
        write_time_points(out, "TQUARTER", np.arange(1, q + 1) / q)
        fixed = "SYMY, 2, 2\nLBOT, 1, 3\n"
        out.write("*BOUNDARY\n" + fixed)

        def friction(value: float, loading: bool) -> str:
            k_t = s.stick_slope(lo_m.young, up_m.young, mesh.h_fine, loading)
            return f"*CHANGE FRICTION, INTERACTION=SI\n*FRICTION\n{value}, {fmt(k_t)}\n"

        refine = max(int(refine), 1)
        out.write("*STEP, INC=200\n" + static_step(0.5, 1.0, 1e-4, 0.5))
        out.write(friction(s.mu_loading, True))
        out.write(f"*BOUNDARY\n{ref}, 1, 1, 0.\n{ref}, 3, 3, {fmt(-seat)}\n*END STEP\n")
        dt = 1.0 / (n_load * refine)
        out.write("*STEP, INC=1000\n" + static_step(dt, 1.0, dt * 1e-4, dt))
        out.write("*BOUNDARY, OP=NEW\n" + fixed + f"{ref}, 1, 1, 0.\n")
        out.write(f"*CLOAD\n{ref}, 3, {fmt(-self.load / 2.0)}\n")
        debris = self._debris_faces(mesh) if self._debris_load > 0.0 else ""
        out.write(debris)
        out.write(self._outputs("TLOAD") + "*END STEP\n")
        dt = 4.0 / (self.n_increments * refine * self.cycle_refine)
        # each quarter starts at a reversal: first slide REVERSAL_SLIDE delta
        dt0 = min(dt, REVERSAL_SLIDE * self.gross_slip_displacement / self.amplitude)
        targets: tuple[float, ...] = (self.amplitude, 0.0, -self.amplitude, 0.0)
        if self._primed():  # the previous cycle's second half: a continuous test's history
            targets = (-self.amplitude, 0.0) + targets
        for k, target in enumerate(targets):
            out.write("*STEP, INC=10000\n" + static_step(dt0, 1.0, min(dt0, dt * 1e-4), dt))
            if k == 0:
                out.write(friction(s.mu, False))
            out.write(f"*BOUNDARY\n{ref}, 1, 1, {fmt(target)}\n")
            out.write(self._outputs("TQUARTER") + "*END STEP\n")
        if self.plastic:  # lift the upper body off, load removed: the residual surfaces
            a = self.hertz[1]
            dt = 1.0 / (n_load * refine)
            out.write("*STEP, INC=1000\n" + static_step(dt, 1.0, dt * 1e-4, dt))
            out.write("*BOUNDARY, OP=NEW\n" + fixed + f"{ref}, 1, 1, 0.\n"
                      f"{ref}, 3, 3, {fmt(2.0 * a * a / self.radius)}\n"
                      f"*CLOAD, OP=NEW\n{ref}, 3, 0.\n")
            if debris:  # the debris go with the load
                out.write(self._debris_faces(mesh, scale=0.0, header="*DLOAD, OP=NEW"))
            out.write(self._outputs("TLOAD") + "*END STEP\n")
        path = Path(path)
        path.write_text(out.getvalue())
        return path

    def _write_model(self, out: io.StringIO, mesh: Mesh3D, s: ContactSettings,
                     lower: FEMaterial, upper: FEMaterial) -> int:
        """The deck's model data: the mesh with the column sets ``UCOL``/``LCOL``, the two
        materials, the upper body's top tied to REF in x and z, the interface law ``s``
        (linear penalty with the n2s tension, friction with its stick slope) and the contact
        pair; returns REF's node id."""
        out.write("*HEADING\ntribodem fe3d: crossed cylinders, half model (y >= 0)\n")
        write_mesh3d(out, mesh, ("UCONT", "LCONT", "UCOL", "LCOL"))
        write_material(out, "MLOWER", lower)
        write_material(out, "MUPPER", upper)
        out.write("*SOLID SECTION, ELSET=LOWER, MATERIAL=MLOWER\n"
                  "*SOLID SECTION, ELSET=UPPER, MATERIAL=MUPPER\n")
        ref = write_ref_tie(out, mesh, (1, 3))
        k_n = s.normal_penalty(lower.young, upper.young, mesh.h_fine)
        tension = "" if s.tension is None else f", {fmt(s.tension)}"
        out.write("*SURFACE INTERACTION, NAME=SI\n")
        out.write(f"*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR\n{fmt(k_n)}{tension}\n")
        mu = max(s.mu, s.mu_loading)
        k_t = s.stick_slope(lower.young, upper.young, mesh.h_fine)
        out.write(f"*FRICTION\n{mu}, {fmt(k_t)}\n")
        sliding = ", SMALL SLIDING" if self.small_sliding else ""
        out.write(f"*CONTACT PAIR, INTERACTION=SI, TYPE={s.formulation}{sliding}\nSUP, SLOW\n")
        return ref

    def _outputs(self, tp: str) -> str:
        """The ``.dat`` outputs at the time points ``tp``: the support's total reaction,
        REF, both contact faces' displacements, the Gauss-point stresses of the upper
        contact layer (``UCONT``, the tractions) and of the column sets ``UCOL``/``LCOL``
        (and their PEEQ with plastic bodies)."""
        return (f"*NODE PRINT, NSET=LBOT, TOTALS=ONLY, TIME POINTS={tp}\nRF\n"
                f"*NODE PRINT, NSET=REF, TIME POINTS={tp}\nU\n"
                f"*NODE PRINT, NSET=UBOT, TIME POINTS={tp}\nU\n"
                f"*NODE PRINT, NSET=LTOP, TIME POINTS={tp}\nU\n"
                f"*EL PRINT, ELSET=UCONT, TIME POINTS={tp}\nS\n"
                f"*EL PRINT, ELSET=UCOL, TIME POINTS={tp}\nS\n"
                f"*EL PRINT, ELSET=LCOL, TIME POINTS={tp}\nS\n"
                + (f"*EL PRINT, ELSET=UCOL, TIME POINTS={tp}\nPEEQ\n"
                   f"*EL PRINT, ELSET=LCOL, TIME POINTS={tp}\nPEEQ\n"
                   if self.plastic else ""))

    # -- the contract ---------------------------------------------------------------------
    def reset(self) -> None:
        """Forget the load history: the next ``solve_increment(0.0)`` is a first loading
        (a prescribed debris pressure is kept)."""
        self._k: int | None = None
        self._loaded = False

    def _key(self) -> tuple[bytes, ...]:
        """The geometry, the debris pressure and the priming a job was run with."""
        return (*super()._key(), self.debris_pressure.tobytes(),
                b"primed" if self._primed() else b"")

    def _primed(self) -> bool:
        """Whether the next job primes its cycle (mode ``primed``, from the second cycle)."""
        return self.mode == "primed" and self._cycle >= 1

    # -- debris third body (Lu (2018) section 3.2.7: forces mapped back) --------------------
    def set_debris_pressure(self, pressure: NDArray[np.float64] | None) -> None:
        """Prescribe the debris pressure on the window (the upper body's frame at offset 0),
        Pa [n, n] (None clears). The next job loads both contact faces with it, as a face
        pressure at each face's centre (``*DLOAD``, applied with the normal load and kept
        through the cycle; the lower body's at the lab position under the window at offset
        0, where the debris phase ran): the bodies are pushed apart and the solid contact
        carries ``load - debris_load``. Kept until cleared (``reset`` keeps it too)."""
        n = self.n
        if pressure is None:
            self._debris_pressure = np.zeros((n, n))
            self._debris_load = 0.0
            return
        self._debris_pressure, self._debris_load = checked_debris_pressure(
            pressure, n, self.dx, self.load)

    def _debris_at(self, x: NDArray[np.float64], y: NDArray[np.float64]
                   ) -> NDArray[np.float64]:
        """The debris pressure (Pa) at window-frame points (bilinear; 0 outside)."""
        from scipy.interpolate import RegularGridInterpolator

        c = self.coords
        f = RegularGridInterpolator((c, c), self._debris_pressure, bounds_error=False,
                                    fill_value=0.0)
        return f(np.stack([x, y], axis=-1))

    def _debris_face_loads(self, mesh: Mesh3D) -> dict[str, tuple[NDArray[np.int64],
                                                                   NDArray[np.float64],
                                                                   NDArray[np.int64]]]:
        """Per contact set (upper: UCONT face 1, lower: LCONT face 2): the elements, the
        debris pressure on each face (Pa) and the face's 4 nodes (0-based). The pressure is
        the window's at the face's centre (bilinear; zero outside the window), scaled so that
        the faces carry the window's debris load exactly (both halves of the model): the
        force the debris phase mapped back is conserved."""
        out = {}
        for name, nodes in (("UCONT", slice(0, 4)), ("LCONT", slice(4, 8))):
            ids = mesh.element_sets[name]
            conn = mesh.elements[ids - 1][:, nodes]
            centre = mesh.nodes[conn].mean(axis=1)
            p = self._debris_at(centre[:, 0], centre[:, 1])
            area = _projected_area(mesh.nodes[conn])
            total = 2.0 * float((p * area).sum())
            out[name] = (ids, p * (self._debris_load / total if total > 0 else 0.0), conn)
        return out

    def _debris_faces(self, mesh: Mesh3D, scale: float = 1.0, header: str = "*DLOAD") -> str:
        """``header`` (``*DLOAD``, or ``*DLOAD, OP=NEW`` to replace the step's loads) and the
        debris pressure (times ``scale``) on the contact faces of both bodies
        (:meth:`_debris_face_loads`)."""
        lines = [header]
        for (ids, p, _), face in zip(self._debris_face_loads(mesh).values(), (1, 2),
                                     strict=True):
            lines += [f"{int(e)}, P{face}, {fmt(scale * v)}"
                      for e, v in zip(ids, p, strict=True) if v > 0.0]
        return "\n".join(lines) + "\n"

    def loaded_solution(self, offset: float = 0.0, debris: bool = False
                        ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(pressure Pa, gap m) on the window under the full load at offset 0 (the only
        offset a fresh job loads at), without or with the prescribed debris pressure (then
        the returned pressure is solid + debris): from the loaded state of a job on the
        current geometry (run if the last job is not that one; the next cycle reuses it when
        it matches). The gap is the deformed one: under each upper surface node, its height
        minus the lower surface's at the same (x, y), both displaced."""
        if float(offset) != 0.0:
            raise ValueError(f"offset = {offset!r}: the fe3d loaded solution is at offset 0")
        keep = (self._debris_pressure, self._debris_load)
        if not debris:
            self._debris_pressure, self._debris_load = np.zeros((self.n, self.n)), 0.0
        try:
            if self._key() != self._job_key or not self._served:
                self._run_job()
                self._fresh_for_cycle = True  # the next cycle may reuse this job
            st = self._state_of[min(self._state_of)]  # the loaded state (total time 2)
            assert self._loaded_result is not None
            p = self._loaded_result.pressure.copy()
        finally:
            self._debris_pressure, self._debris_load = keep
        up = self.mesh.nodes[self._cols["upper"][..., 0]] + st["u_up"]
        lo = self.mesh.nodes[self._cols["lower"][..., 0]] + st["u_lo"]
        z_lo = _bilinear(self._xl, self._ys, lo[..., 2][..., None],
                         up[..., 0].ravel(), np.abs(up[..., 1]).ravel())[:, 0]
        gap = np.maximum(up[..., 2] - z_lo.reshape(up.shape[:2]), 0.0)
        gap_w = self._window(gap, 1.0, False)
        return (p + self.debris_pressure if debris else p), gap_w

    def _start_cycle(self) -> None:
        if not (self._key() == self._job_key and self._served and self._fresh_for_cycle):
            self._run_job()
        self._fresh_for_cycle = False
        self._cycle += 1
        self._k = 0

    def _load(self) -> IncrementResult:
        if self._key() != self._job_key or not self._served:
            self._run_job()
        assert self._loaded_result is not None
        return self._loaded_result

    # -- the job --------------------------------------------------------------------------
    def _run_job(self) -> None:
        """Mesh, morph, write, run (retrying with smaller increments) and read one job."""
        folder, mesh, seat, t0 = self._job_start()
        t_mesh = time.perf_counter() - t0
        try:
            run, refine, scale, t_deck, t_ccx = self._run_attempts(
                lambda refine, name, scale: self.write_deck(folder / f"{name}.inp", mesh,
                                                            seat, refine, scale))
        except CcxConvergenceError as err:
            hint = self._steepness_hint()
            if hint:
                raise FESolverStopped(f"{err}\n{hint}") from None
            raise
        t3 = time.perf_counter()
        blocks = read_dat(run.dat)
        states = self._read(blocks, mesh)
        t_read = time.perf_counter() - t3
        rec = self._job_record(folder, mesh, run, refine, scale,
                               (t_mesh + t_deck, t_ccx, t_read))
        t4 = time.perf_counter()
        self.mesh = mesh
        self._blocks = blocks
        self._states = states
        self._serve(states)
        self._peeq_cache = {}
        if self.plastic:
            self._pending = self._plastic_steps_of_job()
        self.cycle_reports.append(self._cycle_report())
        rec.seconds_map = time.perf_counter() - t4
        self._job_key = self._key()
        self.jobs.append(rec)
        self._write_profile()

    def _read(self, blocks: list[DatBlock], mesh: Mesh3D) -> list[dict[str, Any]]:
        """Per output time of the loaded state and the cycle: total time, forces on the
        upper body (N, both halves), nodal tractions on the upper surface (Pa, [ny, nx]:
        p, qx, qy), the displacements of both contact faces ([ny, nx, 3], m) and of REF."""
        start = 4.0 if self._primed() else 2.0  # the served cycle's start (total time)
        want = np.concatenate([[2.0], [start] if start > 2.0 else [],
                               start + 4.0 * np.arange(1, self.n_increments + 1)
                               / self.n_increments])
        by = {(b.kind, b.set_name, round(b.time, 9)): b for b in blocks}
        times = np.array(sorted({round(b.time, 9) for b in blocks if b.kind == "total force"}))
        ubot = self._cols["upper"][..., 0]
        ltop = self._cols["lower"][..., 0]
        n_nodes = mesh.nodes.shape[0]
        states = []
        debris_nodes: float | NDArray[np.float64] = 0.0
        if self._debris_load > 0.0:  # the debris face loads on the upper surface nodes
            ids, p, conn = self._debris_face_loads(mesh)["UCONT"]
            area = _projected_area(mesh.nodes[conn])  # the z force of p on a face
            f = np.zeros(n_nodes)
            np.add.at(f, conn, np.repeat((p * area / 4.0)[:, None], 4, axis=1))
            debris_nodes = np.where(self._complete, f[ubot], 0.0) / self._area
        for t in want:
            k = int(np.argmin(np.abs(times - t))) if times.size else -1
            if k < 0 or abs(times[k] - t) > 1e-6:
                raise FESolverStopped(f"ccx output has no result at total time {t:g} (deck "
                                      f"{self.workdir})")
            tk = float(times[k])
            rows = by[("stresses", "UCONT", tk)].rows
            elems = rows[:, 0].astype(np.int64).reshape(-1, 8)[:, 0]
            conn = mesh.elements[elems - 1]
            f = element_forces(mesh.nodes[conn], rows[:, 2:8].reshape(-1, 8, 6))
            total = np.zeros((n_nodes, 3))
            np.add.at(total, conn[:, :4], f[:, :4])
            u = np.zeros((n_nodes + 1, 3))
            for name in ("UBOT", "LTOP", "REF"):
                r = by[("displacements", name, tk)].rows
                u[r[:, 0].astype(np.int64)] = r[:, 1:4]
            fn = np.where(self._complete[..., None], total[ubot], 0.0) / self._area[..., None]
            if self._debris_load > 0.0:  # the face loads are in the recovered nodal forces:
                fn[..., 2] -= debris_nodes  # what is left is the solid contact's
            fn[0, :, 1] = 0.0  # y = 0: the symmetry plane's reaction, no contact traction
            rf = by[("total force", "LBOT", tk)].rows[0, :3]
            states.append({"time": tk, "p": fn[..., 2], "qx": fn[..., 0], "qy": fn[..., 1],
                           "u_up": u[ubot + 1], "u_lo": u[ltop + 1],
                           "u_ref": u[int(mesh.node_sets["REF"][0])],
                           "force": np.array([2.0, 0.0, 2.0]) * rf})
        return states

    def _window(self, half: NDArray[np.float64], sign: float, average: bool
                ) -> NDArray[np.float64]:
        """A nodal field of the half surface grid [ny, nx] on the window [n (x), n (y)]."""
        full = _mirror(half, sign)  # [2 ny - 1, nx]
        if average:
            return self._avg_x @ full.T @ self._avg_y.T
        return self._pt_x @ full.T @ self._pt_y.T

    def _serve(self, states: list[dict[str, Any]]) -> None:
        """Map the job's surface fields to the window: the loaded state and the increments
        (a primed job's states: the loaded state, the served cycle's start, its increments;
        the start is the first increment's reference only)."""
        cycle_start = states[1] if self._primed() else None
        if cycle_start is not None:
            states = [states[0], *states[2:]]
        n, cell = self.n, self.dx * self.dx
        xs, xl, ys_full = self._xs, self._xl, self._ys_full
        k_t = self._stick_slope()
        out: list[IncrementResult] = []
        xg, yg = np.meshgrid(xs, self._ys)  # [ny, nx] undeformed upper surface nodes
        prev: dict[str, Any] | None = None
        for j, st in enumerate(states):
            if j == 1 and cycle_start is not None:
                prev = cycle_start
            p_node = np.where(st["p"] > 1e-5 * st["p"].max(), st["p"], 0.0)
            on = p_node > 0.0
            p = self._window(p_node, 1.0, True)
            p = np.where(p > 0.0, p, 0.0)
            contact = p > 0.0
            if contact[0].any() or contact[-1].any() or contact[:, 0].any() or \
                    contact[:, -1].any():
                raise WindowTooSmallError(
                    f"the FE contact reaches the window edge (window {self.window:.4g} m, n "
                    f"{n}): enlarge contact.window")
            traction = np.zeros((n, n, 2))
            slip = np.zeros((n, n, 2))
            stick = None
            if j == 0:
                start, off, direction = 0.0, 0.0, 0.0
            else:
                assert prev is not None
                traction[..., 0] = self._window(np.where(on, st["qx"], 0.0), 1.0, True)
                traction[..., 1] = self._window(np.where(on, st["qy"], 0.0), -1.0, True)
                lo0 = _mirror(prev["u_lo"][..., :2], 1.0)
                lo0[: self._ys.size - 1, :, 1] *= -1.0  # u_y is odd in y
                lo1 = _mirror(st["u_lo"][..., :2], 1.0)
                lo1[: self._ys.size - 1, :, 1] *= -1.0
                up0, up1 = prev["u_up"][..., :2], st["u_up"][..., :2]
                # the lower body's material point under each upper node at the start
                px, py = xg + up0[..., 0], yg + up0[..., 1]
                u_at = _bilinear(xl, ys_full, lo0, px.ravel(), py.ravel()).reshape(up0.shape)
                fx, fy = (px - u_at[..., 0]).ravel(), (py - u_at[..., 1]).ravel()
                du_lo = (_bilinear(xl, ys_full, lo1, fx, fy)
                         - _bilinear(xl, ys_full, lo0, fx, fy)).reshape(up0.shape)
                s_node = np.where(on[..., None], (up1 - up0) - du_lo, 0.0)
                # interpolation weights renormalized over the contact nodes: the window's
                # contact (cell averages of the bilinear pressure) reaches one node further
                # than the FE contact, and a plain interpolation towards the zero slip of the
                # free nodes there lost 4.6 % of the sliding distance (h = a/3, measured)
                weight = self._window(on.astype(float), 1.0, False)
                inside = contact & (weight > 0.0)
                with np.errstate(invalid="ignore", divide="ignore"):
                    for comp, sign in ((0, 1.0), (1, -1.0)):
                        v = self._window(s_node[..., comp], sign, False) / weight
                        slip[..., comp] = np.where(inside, v, 0.0)
                    stick_node = on & (np.hypot(s_node[..., 0], s_node[..., 1])
                                       <= self.friction * p_node / k_t)
                    stick = inside & (self._window(stick_node.astype(float), 1.0, False)
                                      / weight > 0.5)
                off = float(self.offsets[j - 1])
                start = float(self.offsets[j - 2]) if j >= 2 else 0.0
                direction = math.copysign(1.0, off - start)
            prev = st
            out.append(IncrementResult(
                offset=off, start_offset=start, direction=direction, pressure=p,
                traction=traction, slip=slip,
                contact_area=float((self._window(on.astype(float), 1.0, False) >= 0.5).sum())
                * cell,
                normal_load=float(p.sum()) * cell, stick=stick))
        self._loaded_result = out[0]
        self._served = out[1:]
        self._time_of = {id(inc): float(st["time"]) for inc, st in zip(out, states, strict=True)}
        self._state_of = {float(st["time"]): st for st in states}
        self._nodal_cache = {}

    # -- subsurface stress ----------------------------------------------------------------
    def _nodal_stress(self, body: str, t: float) -> NDArray[np.float64]:
        """Stress at the nodes (Pa, [n_nodes, 6] ccx order xx, yy, zz, xy, xz, yz; NaN off
        the column set) at total time ``t``: each element's Gauss-point stresses
        extrapolated to its nodes (inverse trilinear map), averaged over the elements of a
        node; on the surface nodes sigma_zz, sigma_xz, sigma_yz are the recovered contact
        traction (the extrapolation overshoots in the steep Hertz gradient)."""
        key = (body, t)
        if key not in self._nodal_cache:
            rows = self._block("stresses", column_set(body), t).rows
            elems = rows[:, 0].astype(np.int64).reshape(-1, 8)[:, 0]
            conn = self.mesh.elements[elems - 1]
            nodal = np.einsum("kg,mgc->mkc", _EXTRAPOLATE3, rows[:, 2:8].reshape(-1, 8, 6))
            avg = nodal_mean(conn, nodal, self.mesh.nodes.shape[0])
            st = self._state_of[t]
            top = self._cols[body][..., 0]
            p = np.where(st["p"] > 1e-5 * st["p"].max(), st["p"], 0.0)
            q = np.stack([np.where(p > 0, st["qx"], 0.0), np.where(p > 0, st["qy"], 0.0),
                          p], axis=-1)
            if body == "lower":  # the traction under each lower node: the upper node at
                # undeformed x - u_ref (the lower surface node's position in the upper frame)
                q_full = _mirror(q, 1.0)
                q_full[: self._ys.size - 1, :, 1] *= -1.0
                xg, yg = np.meshgrid(self._xl, self._ys)
                q = _bilinear(self._xs, self._ys_full, q_full, (xg - st["u_ref"][0]).ravel(),
                              yg.ravel()).reshape(q.shape)
                q[(xg - st["u_ref"][0] < self._xs[0]) | (xg - st["u_ref"][0] > self._xs[-1])] = 0
            # traction on the upper body (qx, qy, p) = -sigma . e_z at the interface, the same
            # lab-frame sigma on both sides: sigma_xz = -qx, sigma_yz = -qy, sigma_zz = -p
            known = np.isfinite(avg[top, 0])
            avg[top[known], 4] = -q[known, 0]
            avg[top[known], 5] = -q[known, 1]
            avg[top[known], 2] = -q[known, 2]
            self._nodal_cache = {key: avg}
        return self._nodal_cache[key]

    def _default_grid_depth(self, result: IncrementResult) -> float:
        """3 contact radii, 3 sqrt(area / pi), m."""
        return 3.0 * math.sqrt(max(result.contact_area, self.dx**2) / math.pi)

    def _stress_on_grid(self, body: str, t: float, x: NDArray[np.float64],
                        z: NDArray[np.float64]) -> NDArray[np.float64]:
        """Nodal stresses (:meth:`_nodal_stress`) interpolated along each straight node
        column (i, j) by the depth below its (worn) surface node, then bilinearly between
        columns; y < 0 from the mirror (sigma_xy, sigma_yz odd). Frame: x, y, z = depth into
        the body: sigma_xz = qx under the lower body and -qx in the upper one at the surface
        (the half-space backend's convention)."""
        s = self._column_grid(body, self._nodal_stress(body, t), _STRESS_MIRROR, x, z,
                              "stresses")
        return _voigt(s, body)

    def _column_grid(self, body: str, nodal: NDArray[np.float64], mirror: NDArray[np.float64],
                     x: NDArray[np.float64], z: NDArray[np.float64], what: str
                     ) -> NDArray[np.float64]:
        """A nodal field [n_nodes, c] (NaN off the column set) under ``body`` on the grid
        (z depths below the worn surface, x, the window's y), [nz, nx, ny, c]: linear along
        each straight node column by the depth below its surface node, then bilinear between
        columns; y < 0 from the mirror (component signs ``mirror``). ``ValueError`` where the
        grid leaves the printed columns."""
        cols = self._cols[body]  # [ny, nx, nl]
        zc = self.mesh.nodes[cols, 2]
        d = np.abs(zc - zc[..., :1])  # depth below the surface node, increasing
        v = nodal[cols]  # [ny, nx, nl, c]
        ok = np.isfinite(v[..., 0])
        # first nl with the depth: k such that d[k] <= z < d[k + 1]
        k = np.clip((d[..., None, :] <= z[:, None]).sum(axis=-1) - 1, 0, d.shape[-1] - 2)
        d0 = np.take_along_axis(d, k, axis=-1)
        d1 = np.take_along_axis(d, k + 1, axis=-1)
        w = np.clip((z - d0) / (d1 - d0), 0.0, 1.0)[..., None]
        v0 = np.take_along_axis(v, k[..., None], axis=2)
        v1 = np.take_along_axis(v, (k + 1)[..., None], axis=2)
        prof = (1 - w) * v0 + w * v1  # [ny, nx, nz, c]
        good = np.take_along_axis(ok, k, axis=-1) & np.take_along_axis(ok, k + 1, axis=-1)
        full = np.concatenate([prof[:0:-1] * mirror, prof], axis=0)
        gfull = np.concatenate([good[:0:-1], good], axis=0)
        y = self.coords
        X, Y = np.meshgrid(x, y, indexing="ij")
        xb = self._grids[body][0]
        c = v.shape[-1]
        out = _bilinear(xb, self._ys_full, full.reshape(full.shape[0], full.shape[1], -1),
                        X.ravel(), Y.ravel()).reshape(x.size, y.size, z.size, c)
        gi = _bilinear(xb, self._ys_full,
                       gfull.astype(float).reshape(gfull.shape[0], gfull.shape[1], -1),
                       X.ravel(), Y.ravel())
        if np.any(gi < 1.0 - 1e-12):
            raise ValueError(f"no column {what} under the window down to depth "
                             f"{z[-1]:.4g} m on the {body} body")
        return np.moveaxis(out, 2, 0)

    def _peeq_ip(self, body: str, t: float) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
        """(elements, PEEQ at their 8 Gauss points [m, 8]) of ``body``'s column set at ``t``."""
        rows = self._block("equivalent plastic strain", column_set(body), t).rows
        return rows[:, 0].astype(np.int64).reshape(-1, 8)[:, 0], rows[:, 2].reshape(-1, 8)

    def _peeq_peak(self, body: str, t: float) -> tuple[float, float]:
        """(max equivalent plastic strain over ``body``'s column set at ``t`` (Gauss points),
        its depth below the body's (worn) surface, m)."""
        elems, pe = self._peeq_ip(body, t)
        e, g = np.unravel_index(int(np.argmax(pe)), pe.shape)
        xyz = _N_AT_GP[g] @ self.mesh.nodes[self.mesh.elements[elems[e] - 1]]
        xs, ys = self._grids[body]
        z_top = self.mesh.nodes[self._cols[body][..., 0], 2][..., None]
        z_surf = _bilinear(xs, ys, z_top, np.array([xyz[0]]), np.array([abs(xyz[1])]))[0, 0]
        return float(pe[e, g]), float(abs(xyz[2] - z_surf))

    def _plastic_steps_of_job(self) -> list[PlasticStep]:
        """The job's plastic steps, one per body per output increment: the loading (from the
        virgin state to the load) and each increment of the cycle, on [17, nx, n] grids
        down to :attr:`plastic_depth` (upper: window frame; lower: lab frame over the window
        plus the stroke, y the window's)."""
        z = np.linspace(0.0, self.plastic_depth, 17)
        steps: list[PlasticStep] = []
        times = sorted(self._state_of)
        prev: float | None = None
        for t in times:
            load = float(abs(self._state_of[t]["force"][2]))
            for body in BODIES:
                x = self._plastic_grid_x(body)
                dp_nodal = self._peeq_increment(body, t, prev)
                dp = np.maximum(self._column_grid(body, dp_nodal, _ONE, x, z,
                                                  "plastic strain")[..., 0], 0.0)
                stress = _voigt(self._column_grid(body, self._nodal_stress(body, t),
                                                  _STRESS_MIRROR, x, z, "stresses"), body)
                steps.append(PlasticStep(z=z, x=x, y=self.coords, body=body, load=load,
                                         dp=dp, stress=stress))
            prev = t
        return steps

    # -- what a cycle measured -------------------------------------------------------------
    def _cycle_report(self) -> dict[str, Any]:
        """What the job just run (one fretting cycle from virgin bodies) measured, its row of
        :meth:`report`'s ``cycles``: max von Mises and max S22 (the vertical normal stress,
        ccx S33; compressive and tensile) over the column sets' Gauss points at the loaded
        state and every output increment (:meth:`_peak_stresses`); with plastic bodies the
        max equivalent plastic strain per body and its depth at the cycle's end and at the
        loaded state (``max_peeq_loaded_*``: Johnson's first yield, below the surface), the
        residual pile-up and dent after lifting the upper body off
        (:func:`.base.residual_surfaces`); the largest shear traction in the cycle's first
        and last quarters and the drop between them (:func:`.base.traction_quarters`),
        |Q| / (mu P) at +A and -A; the ccx attempt the cycle's job converged on
        (:meth:`.jobs.CcxJobs._attempt_report`); with ``max_wear_slope``, what the slope
        limit did to the job's surfaces."""
        times = sorted(self._state_of)
        row: dict[str, Any] = ({"cycle": self._cycle + 1} | self._attempt_report()
                               | self._peak_stresses(times))
        if self.plastic:
            for body in BODIES:
                for label, t in (("", times[-1]), ("loaded_", times[0])):
                    peak, depth = self._peeq_peak(body, t)
                    row[f"max_peeq_{label}{body}"] = peak
                    row[f"max_peeq_{label}depth_{body}_m"] = depth
            # after lifting the upper body off (the upper surface relative to REF)
            t_off = max(b.time for b in self._blocks if b.kind == "displacements")
            u = {name: self._block("displacements", name, t_off).rows
                 for name in ("UBOT", "LTOP", "REF")}
            row |= residual_surfaces(u["LTOP"][:, 3], u["UBOT"][:, 3] - u["REF"][0, 3])
        row |= traction_quarters(np.array([float(np.hypot(*np.moveaxis(i.traction, -1, 0)).max())
                                           for i in self._served]))
        quarter = max(len(self._served) // 4, 1)
        fx = [abs(float(self._state_of[times[k]]["force"][0])) for k in (quarter, 3 * quarter)]
        row["q_over_mu_p_at_plus_minus_a"] = [v / (self.friction * self.load) for v in fx]
        if self.max_wear_slope is not None and self.slope_limits:
            # the job's surfaces are the criterion's relaxed to max_wear_slope: say how much
            row["wear_slope_limit"] = {
                "max_wear_slope": self.max_wear_slope,
                **{body: {"steepest_before": lim.steepest_before,
                          "steepest_after": lim.steepest_after,
                          "moved_volume_m3": 2.0 * lim.moved_volume,  # both halves
                          "worn_volume_m3": self.worn_volume(body), "converged": lim.converged}
                   for body, lim in self.slope_limits.items()}}
        if self.max_wear_kink is not None and self.kink_limits:
            # and smoothed to max_wear_kink: the largest change of slope before and after
            row["wear_kink_limit"] = {
                "max_wear_kink": self.max_wear_kink,
                **{body: {"kink_before": kl.kink_before, "kink_after": kl.kink_after,
                          "steepest_after": kl.steepest_after,
                          "moved_volume_m3": 2.0 * kl.moved_volume,  # both halves
                          "worn_volume_m3": self.worn_volume(body), "converged": kl.converged}
                   for body, kl in self.kink_limits.items()}}
        row["morph"] = self.morph
        return row

    def _peak_stresses(self, times: list[float]) -> dict[str, float]:
        """Max von Mises and max S33 (compressive, with the upper body's x offset where it
        sits, and tensile) over the column sets' Gauss points at the total ``times`` (the
        first the loaded state: its peaks too), Pa."""
        peaks = np.zeros((len(times), 3))  # per output time: von Mises, -S33, S33
        for name in ("UCOL", "LCOL"):
            for k, t in enumerate(times):
                sv = self._block("stresses", name, t).rows[:, 2:8]
                vm = np.sqrt(0.5 * ((sv[:, 0] - sv[:, 1]) ** 2 + (sv[:, 1] - sv[:, 2]) ** 2
                                    + (sv[:, 2] - sv[:, 0]) ** 2)
                             + 3.0 * (sv[:, 3] ** 2 + sv[:, 4] ** 2 + sv[:, 5] ** 2))
                peaks[k] = np.maximum(peaks[k], (vm.max(), -sv[:, 2].min(), sv[:, 2].max()))
        k_c = int(np.argmax(peaks[:, 1]))
        return {"max_von_mises_pa": float(peaks[:, 0].max()),
                "max_s22_compressive_pa": float(peaks[k_c, 1]),
                "max_s22_tensile_pa": float(peaks[:, 2].max()),
                # where the cycle's peak compression sits (the upper body's x offset, m),
                # and the peaks at the loaded state before sliding (seed: 1.6 / 1.4 GPa)
                "max_s22_compressive_offset_m": float(self._state_of[times[k_c]]["u_ref"][0]),
                "max_von_mises_loaded_pa": float(peaks[0, 0]),
                "max_s22_compressive_loaded_pa": float(peaks[0, 1])}

    def _block(self, kind: str, set_name: str, t: float) -> DatBlock:
        """The last job's ``.dat`` block of ``kind`` for set ``set_name`` at total time
        ``t``."""
        return next(b for b in self._blocks if b.kind == kind and b.set_name == set_name
                    and abs(b.time - t) < 1e-9)

    def _steepness_hint(self) -> str:
        """What to do when a job on worn surfaces steeper than :data:`CONVERGED_SLOPE` did
        not converge ('' when they are not, or a slope limit is set)."""
        if self.max_wear_slope is not None:
            return ""
        steep = {body: float(steepest(w, *self._grids[body]))
                 for body, w in zip(BODIES, self.column_wear(), strict=True)}
        if max(steep.values()) <= CONVERGED_SLOPE:
            return ""
        return ("the worn surfaces step by up to "
                + ", ".join(f"{v:.2f} ({b})" for b, v in steep.items())
                + f" x the spacing of neighbouring node columns; ccx's contact converged here "
                f"on up to {CONVERGED_SLOPE:g} (docs/fe3d.md 'Worn geometry'): to go on, "
                f"set [fe] max_wear_slope = {CONVERGED_SLOPE:g} (the default, here 'off') "
                "in the config and --resume (the mesh's worn depth relaxed to that slope, the "
                "worn volume kept), or run a finer mesh (fe.h_over_a)")

    def _worn_surface_reading(self) -> str:
        """Which worn surface the jobs' meshes carry (for summary.json)."""
        text = ("the criterion's worn depth maps, each node column moved by its exact share "
                "of the maps' cell volumes over its tributary area (fe.morph = 'tributary'; "
                "the mesh loses the maps' volume to rounding)" if self.morph == "tributary"
                else "the criterion's worn depth, lumped-projected onto the node columns "
                "(fe.morph = 'projection')") + " (eqs 3.7-3.8)"
        if self.max_wear_slope is not None:
            text += (f", then relaxed volume for volume until no step between neighbouring "
                     f"columns is steeper than {self.max_wear_slope:g} x their spacing "
                     "(fe.max_wear_slope; per cycle 'wear_slope_limit': the steepest step "
                     "before and after and the volume moved)")
        if self.max_wear_kink is not None:
            text += (f", then smoothed volume for volume until no node's change of slope "
                     f"exceeds {self.max_wear_kink:g} (fe.max_wear_kink; per cycle "
                     "'wear_kink_limit': the largest before and after and the volume moved)")
        if self.max_wear_slope is not None or self.max_wear_kink is not None:
            text += ": the FE geometry is smoother than the scar the loop reports"
        return text

    def _report_extra(self) -> dict[str, Any]:
        """The mesh (elements, fine element size m, size factor), the slope limit and which
        worn surface the meshes carry."""
        return {"fe3d": {"elements": int(self._mesh0.elements.shape[0]),
                         "h_fine_m": self._mesh0.h_fine, "size_factor": self.size_factor,
                         "max_wear_slope": self.max_wear_slope,
                         "max_wear_kink": self.max_wear_kink, "morph": self.morph,
                         "worn_surface": self._worn_surface_reading()}}

    # -- resume ---------------------------------------------------------------------------
    def _state_extra(self) -> dict[str, Any]:
        """The cycle reports and the prescribed debris pressure (Pa) and load (N)."""
        return {"cycle_reports": list(self.cycle_reports),
                "debris_pressure": self.debris_pressure.copy(), "debris_load": self._debris_load}

    def _load_state_extra(self, state: dict[str, Any]) -> None:
        if "debris_pressure" in state:
            self._debris_pressure = np.array(state["debris_pressure"], dtype=float)
            self._debris_load = float(state["debris_load"])
