"""3D crossed-cylinder model on CalculiX (Lu (2018) figure 3.4): quarter model.

Geometry (SI, metres): the *upper* cylinder's axis is along y, the *lower* cylinder's along x
(the stroke is along x); they touch at the origin, z up. Under a normal load the problem has
two symmetry planes, x = 0 and y = 0, so a quarter of each body is meshed:

* lower body: ``0 <= x, y <= L``, bottom ``z = -H``, top ``z = -s_l(y)`` with
  ``s_l(y) = R_l - sqrt(R_l^2 - y^2)`` (a portion of the lower cylinder);
* upper body: ``0 <= x, y <= L``, top ``z = H``, bottom ``z = s_u(x)`` with
  ``s_u(x) = R_u - sqrt(R_u^2 - x^2)``.

Mesh: structured 8-node bricks (ccx ``C3D8``) as tensor products of graded 1D lists
(:func:`tribodem.contact.fe.mesh.graded_half`): a uniform fine zone of spacing ``h`` under
the contact (straight vertical node columns ``x = i h, y = j h``, the seed's "node columns"
of figure 3.4), growing by ``growth`` per element outside it; the vertical coordinate of each
column is mapped so the contact row lies on the cylinder and the far row on the flat end.

Boundary conditions: symmetry (u_x = 0 on x = 0, u_y = 0 on y = 0, both bodies); the lower
body's bottom fixed in z; the upper body's top tied to the reference node REF in z
(``*EQUATION``), the normal load P/4 on REF. Steps: seating (REF moved down by 5 % of the
Hertz approach) then the load, friction-free (the Hertz problem; similar materials, so the
normal problem does not depend on friction).

Contact pressure: the nodal contact forces of the upper body's surface nodes are recovered
from the integration-point stresses of its contact layer (f = sum_gp B^T sigma det J w, as in
2D, :mod:`tribodem.contact.fe.results`), divided by the nodes' tributary areas.
"""

from __future__ import annotations

import io
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from tribodem.contact.base import ElasticBody, contact_modulus
from tribodem.contact.fe.ccx import run_ccx
from tribodem.contact.fe.deck import (
    ContactSettings,
    FEMaterial,
    fmt,
    static_step,
    write_ids,
    write_material,
    write_time_points,
)
from tribodem.contact.fe.mesh import graded_half, graded_symmetric
from tribodem.contact.fe.results import read_dat, tributary_length
from tribodem.contact.geometry import HertzSphere

_GP = 1.0 / math.sqrt(3.0)
#: ccx's 2x2x2 Gauss points of C3D8 in its order (xi fastest, then eta, then zeta)
GAUSS_2X2X2 = np.array([[a, b, c] for c in (-_GP, _GP) for b in (-_GP, _GP)
                        for a in (-_GP, _GP)])
#: natural coordinates of the C3D8 nodes (1-4 at zeta = -1 counter-clockwise, 5-8 above)
NODE_XI = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                    [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], dtype=float)


@dataclass(frozen=True)
class CrossedCase:
    """Quarter model of two crossed cylinders of equal radius under a normal load (SI)."""

    load: float = 100.0  #: total normal load P, N (the quarter model carries P / 4)
    radius: float = 4e-3  #: both cylinders' radius, m (seed: 8 mm diameter)
    h_fine: float | None = None  #: fine element size, m (None: a / 6)
    zone_factor: float = 1.5  #: fine zone half-width and depth, in units of a
    size_factor: float = 10.0  #: body extent (x, y, height), in units of a
    growth: float = 1.3  #: element size ratio outside the fine zone
    load_increments: int = 4
    material: FEMaterial = field(default_factory=FEMaterial)
    #: tangential displacement amplitude of the upper body along x, m (0: normal load only,
    #: quarter model; > 0: half model, the cycle 0 -> +d -> 0 -> -d -> 0)
    delta: float = 0.0
    n_increments: int = 8  #: increments of the tangential cycle (multiple of 4)
    half_cycle: bool = False  #: only 0 -> +delta (n_increments / 4 increments)
    #: the interface law: Coulomb mu in the tangential step (seed: 0.6), mu_loading while
    #: seating and loading (ccx refuses 0), normal penalty penalty_factor x E / h and stick
    #: slope stick_factor x that (surface-to-surface, as validated)
    contact: ContactSettings = field(default_factory=ContactSettings)

    @property
    def half(self) -> bool:
        """Half model (symmetric about y = 0 only) when there is a tangential step."""
        return self.delta > 0

    @property
    def e_star(self) -> float:
        """Contact modulus of two bodies of ``material``, Pa."""
        body = ElasticBody(self.material.young, self.material.poisson)
        return contact_modulus(body, body)

    @property
    def hertz(self) -> tuple[float, float]:
        """(p0 Pa, a m) of the case: crossed equal cylinders touch as a sphere of the same
        radius on a flat (Johnson 4.22-4.23)."""
        h = HertzSphere(self.radius, self.load, self.e_star)
        return h.peak_pressure, h.contact_radius


@dataclass
class Mesh3D:
    """Hexahedral mesh of both quarter bodies and the sets the deck needs (ids 1-based)."""

    nodes: NDArray[np.float64]  #: [n, 3], m
    elements: NDArray[np.int64]  #: 0-based node rows of each C3D8, [m, 8]
    n_lower: int  #: the first n_lower elements are the lower body's
    node_sets: dict[str, NDArray[np.int64]]
    element_sets: dict[str, NDArray[np.int64]]
    #: the upper body's contact layer: element ids and, per element, which of its nodes
    #: (0-based local 0..3, its bottom face) lie on the surface
    h_fine: float
    info: dict[str, float]

    def check(self) -> None:
        """Raise ValueError on an inverted element (negative Jacobian at a Gauss point)."""
        x = self.nodes[self.elements]
        for g in GAUSS_2X2X2:
            det = np.linalg.det(np.einsum("nki,kj->nij", x, dshape(g)))
            if np.any(det <= 0):
                raise ValueError("inverted C3D8 element in the crossed-cylinder mesh")

    def write_vtk(self, path: str | Path) -> Path:
        """The mesh as VTK (meshio), with a ``body`` cell field (0 lower, 1 upper)."""
        import meshio

        body = np.zeros(self.elements.shape[0], dtype=np.int64)
        body[self.n_lower:] = 1
        meshio.Mesh(self.nodes, [("hexahedron", self.elements)],
                    cell_data={"body": [body]}).write(Path(path))
        return Path(path)


def dshape(xi: NDArray[np.float64]) -> NDArray[np.float64]:
    """Derivatives of the 8 trilinear shape functions w.r.t. (xi, eta, zeta), [8, 3]."""
    s = NODE_XI
    d = np.empty((8, 3))
    d[:, 0] = s[:, 0] * (1 + s[:, 1] * xi[1]) * (1 + s[:, 2] * xi[2]) / 8
    d[:, 1] = s[:, 1] * (1 + s[:, 0] * xi[0]) * (1 + s[:, 2] * xi[2]) / 8
    d[:, 2] = s[:, 2] * (1 + s[:, 0] * xi[0]) * (1 + s[:, 1] * xi[1]) / 8
    return d


def _block(xs: NDArray, ys: NDArray, zeta: NDArray, zmap) -> tuple[NDArray, NDArray]:  # noqa: ANN001
    """Nodes (x fastest, then y, then zeta) and C3D8 connectivity of a mapped tensor block;
    ``zmap(x, y, zeta)`` gives z."""
    nx, ny, nz = xs.size, ys.size, zeta.size
    z3, y3, x3 = np.meshgrid(zeta, ys, xs, indexing="ij")
    nodes = np.column_stack([x3.ravel(), y3.ravel(), zmap(x3, y3, z3).ravel()])
    k, j, i = np.meshgrid(np.arange(nz - 1), np.arange(ny - 1), np.arange(nx - 1),
                          indexing="ij")
    n1 = (k * ny * nx + j * nx + i).ravel()
    up = nx * ny
    conn = np.column_stack([n1, n1 + 1, n1 + 1 + nx, n1 + nx,
                            n1 + up, n1 + 1 + up, n1 + 1 + nx + up, n1 + nx + up])
    return nodes, conn.astype(np.int64)


def crossed_mesh(case: CrossedCase, a: float | None = None, shift_lower: float = 0.0
                 ) -> Mesh3D:
    """The quarter (half, with ``case.delta``) mesh of :class:`CrossedCase` (see the module
    docstring); ``a`` (m): the Hertz radius the mesh is sized on (None: ``case.hertz``, both
    bodies of ``case.material``). ``info`` holds the grid: ``nx``, ``ny``, ``nz`` (node
    layers per body) and ``fine_layers`` (node layers of the fine section below the
    surface, the deepest one included in the fretting backend's column morphing).
    ``shift_lower`` (m): the lower body's grid is translated by it along x (its cylinder's
    axis, so its surface is unchanged): with half an element the upper body's surface nodes
    no longer sit over the lower body's nodes (node-to-surface contact then converges,
    docs/fe3d.md)."""
    if a is None:
        _, a = case.hertz
    h = case.h_fine or a / 6.0
    R = case.radius
    L = case.size_factor * a
    if L > 0.5 * R:
        raise ValueError(f"size_factor x a = {L:.3g} m exceeds R / 2: the load is too large "
                         "for the cylinders' radius")
    fine = case.zone_factor * a
    ys = graded_half(fine, h, L, case.growth)
    xs = graded_symmetric(fine + case.delta, h, L + case.delta, case.growth) if case.half \
        else ys.copy()
    depth = graded_half(fine, h, L, case.growth)  # distance from the contact surface
    # lower body: zeta from -L (bottom) to 0 (top, on the cylinder); fine near the top
    zl = -depth[::-1]

    def lower_z(x: NDArray, y: NDArray, zeta: NDArray) -> NDArray:
        s = R - np.sqrt(R * R - y * y)
        return zeta + (1.0 + zeta / L) * (-s)  # zeta = 0 -> -s(y); zeta = -L -> -L

    def upper_z(x: NDArray, y: NDArray, zeta: NDArray) -> NDArray:
        s = R - np.sqrt(R * R - x * x)
        return zeta + (1.0 - zeta / L) * s  # zeta = 0 -> s(x); zeta = L -> L

    nl, cl = _block(xs + shift_lower, ys, zl, lower_z)
    nu, cu = _block(xs, ys, depth, upper_z)
    off = nl.shape[0]
    nodes = np.vstack([nl, nu])
    elements = np.vstack([cl, cu + off])
    ids = np.arange(1, nodes.shape[0] + 1)
    nx = xs.size
    layer = nx * ys.size
    lower_ids, upper_ids = ids[:off], ids[off:]
    sets = {
        "LBOT": lower_ids[:layer],
        "LTOP": lower_ids[off - layer:],
        "UBOT": upper_ids[:layer],
        "UTOP": upper_ids[-layer:],
        "SYMX": ids[np.isclose(nodes[:, 0], 0.0)],
        "SYMY": ids[np.isclose(nodes[:, 1], 0.0)],
    }
    if case.half:
        del sets["SYMX"]
    top = sets["UTOP"]
    sets["REF"] = top[[int(np.argmin(np.hypot(*nodes[top - 1, :2].T)))]]  # x = y = 0
    el = np.arange(1, elements.shape[0] + 1)
    n_low = cl.shape[0]
    n_cell = (nx - 1) * (ys.size - 1)
    cen = nodes[elements].mean(axis=1)
    reach = fine + 4 * a
    top_l = el[n_low - n_cell:n_low]
    bot_u = el[n_low:n_low + n_cell]
    esets = {
        "LOWER": el[:n_low], "UPPER": el[n_low:],
        "UCONT": bot_u[np.hypot(cen[bot_u - 1, 0], cen[bot_u - 1, 1]) < fine + 2 * a],
        "LCONT": top_l[np.hypot(np.maximum(np.abs(cen[top_l - 1, 0] - shift_lower)
                                           - case.delta, 0.0),
                                cen[top_l - 1, 1]) < reach],
    }
    mesh = Mesh3D(nodes=nodes, elements=elements, n_lower=n_low, node_sets=sets,
                  element_sets=esets, h_fine=h,
                  info={"a": a, "radius": R, "extent": L, "fine": fine,
                        "elements": float(elements.shape[0]), "nodes": float(nodes.shape[0]),
                        "nx": float(nx), "ny": float(ys.size), "nz": float(depth.size),
                        "fine_layers": float(math.ceil(fine / h - 1e-9))})
    mesh.check()
    return mesh


def write_mesh3d(out: io.StringIO, mesh: Mesh3D, element_sets: tuple[str, ...]) -> None:
    """Write the mesh of a 3D deck: the nodes (m, ``NSET=NALL``), the C3D8 elements of both
    bodies (``ELSET=LOWER``, ``UPPER``), every node set, the element sets ``element_sets``
    and the contact surfaces ``SUP`` (the upper body's ``UCONT`` faces S1) and ``SLOW`` (the
    lower body's ``LCONT`` faces S2)."""
    out.write("*NODE, NSET=NALL\n")
    for k, (x, y, z) in enumerate(mesh.nodes, start=1):
        out.write(f"{k}, {fmt(x)}, {fmt(y)}, {fmt(z)}\n")
    for name, rows, first in (("LOWER", mesh.elements[:mesh.n_lower], 1),
                              ("UPPER", mesh.elements[mesh.n_lower:], mesh.n_lower + 1)):
        out.write(f"*ELEMENT, TYPE=C3D8, ELSET={name}\n")
        for k, c in enumerate(rows + 1, start=first):
            out.write(f"{k}, " + ", ".join(str(int(v)) for v in c) + "\n")
    for name, ids in mesh.node_sets.items():
        out.write(f"*NSET, NSET={name}\n")
        write_ids(out, ids)
    for name in element_sets:
        out.write(f"*ELSET, ELSET={name}\n")
        write_ids(out, mesh.element_sets[name])
    # faces: C3D8 S1 = nodes 1-2-3-4 (zeta = -1, the upper body's bottom), S2 = 5-8-7-6 (top)
    out.write("*SURFACE, NAME=SUP, TYPE=ELEMENT\nUCONT, S1\n")
    out.write("*SURFACE, NAME=SLOW, TYPE=ELEMENT\nLCONT, S2\n")


def write_ref_tie(out: io.StringIO, mesh: Mesh3D, dofs: tuple[int, ...]) -> int:
    """Write the ``*EQUATION`` tying the degrees of freedom ``dofs`` of every node of the
    upper body's top (``UTOP``) to the reference node ``REF``; returns REF's id."""
    ref = int(mesh.node_sets["REF"][0])
    out.write("*EQUATION\n")
    for n in mesh.node_sets["UTOP"]:
        if int(n) != ref:
            for d in dofs:
                out.write(f"2\n{int(n)}, {d}, 1., {ref}, {d}, -1.\n")
    return ref


def write_crossed_deck(path: str | Path, mesh: Mesh3D, case: CrossedCase) -> Path:
    """The ccx deck (``.inp``): seating, the normal load, and with ``case.delta`` the
    tangential cycle of REF along x (as the 2D deck, :mod:`tribodem.contact.fe.deck`)."""
    m = case.material
    out = io.StringIO()
    out.write("*HEADING\ntribodem fe: crossed cylinders, "
              f"{'half' if case.half else 'quarter'} model\n")
    write_mesh3d(out, mesh, ("UCONT", "LCONT"))
    write_material(out, "M", m)
    out.write("*SOLID SECTION, ELSET=LOWER, MATERIAL=M\n*SOLID SECTION, ELSET=UPPER, "
              "MATERIAL=M\n")
    ref = write_ref_tie(out, mesh, (1, 3) if case.half else (3,))
    c = case.contact
    k_n = c.normal_penalty(m.young, m.young, mesh.h_fine)
    out.write("*SURFACE INTERACTION, NAME=SI\n")
    out.write(f"*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR\n{fmt(k_n)}\n")
    friction = case.half and c.mu > 0
    if friction:
        out.write(f"*FRICTION\n{c.mu_loading}, "
                  f"{fmt(c.stick_slope(m.young, m.young, mesh.h_fine, loading=True))}\n")
    out.write("*CONTACT PAIR, INTERACTION=SI, TYPE=SURFACE TO SURFACE\nSUP, SLOW\n")
    out.write("*AMPLITUDE, NAME=STROKE\n0., 0., 1., 1., 2., 0., 3., -1.\n4., 0.\n")
    fixed = "*BOUNDARY\nSYMY, 2, 2\nLBOT, 1, 3\n" if case.half else \
        "*BOUNDARY\nSYMX, 1, 1\nSYMY, 2, 2\nLBOT, 3, 3\n"
    hold = f"{ref}, 1, 1, 0.\n" if case.half else ""
    n = max(int(case.load_increments), 1)
    write_time_points(out, "TLOAD", np.arange(1, n + 1) / n)
    nt = int(case.n_increments)
    if case.half:
        if nt < 4 or nt % 4:
            raise ValueError(f"n_increments = {nt!r}: must be a multiple of 4, >= 4")
        steps = nt // 4 if case.half_cycle else nt
        write_time_points(out, "TCYCLE", np.arange(1, steps + 1) * (4.0 / nt))
    out.write(fixed)
    _, a = case.hertz
    seat = 0.05 * a * a / case.radius  # 5 % of the Hertz approach a^2 / R
    out.write("*STEP, INC=200\n" + static_step(0.5, 1.0, 1e-4, 0.5))
    out.write(f"*BOUNDARY\n{hold}{ref}, 3, 3, {fmt(-seat)}\n*END STEP\n")
    dt = 1.0 / n
    outputs = ("*NODE PRINT, NSET=LBOT, TOTALS=ONLY, TIME POINTS={tp}\nRF\n"
               "*NODE PRINT, NSET=REF, TIME POINTS={tp}\nU\n"
               "*NODE PRINT, NSET=UBOT, TIME POINTS={tp}\nU\n"
               "*NODE PRINT, NSET=LTOP, TIME POINTS={tp}\nU\n"
               "*EL PRINT, ELSET=UCONT, TIME POINTS={tp}\nS\n")
    out.write("*STEP, INC=1000\n" + static_step(dt, 1.0, dt * 1e-4, dt))
    out.write("*BOUNDARY, OP=NEW\n" + fixed.split("\n", 1)[1] + hold)
    out.write(f"*CLOAD\n{ref}, 3, {fmt(-case.load / (2.0 if case.half else 4.0))}\n")
    out.write(outputs.format(tp="TLOAD") + "*END STEP\n")
    if case.half:
        dt = 4.0 / nt
        total = 1.0 if case.half_cycle else 4.0
        out.write("*STEP, INC=10000\n" + static_step(dt, total, dt * 1e-4, dt))
        if friction:
            out.write("*CHANGE FRICTION, INTERACTION=SI\n"
                      f"*FRICTION\n{c.mu}, "
                      f"{fmt(c.stick_slope(m.young, m.young, mesh.h_fine))}\n")
        out.write(f"*BOUNDARY, AMPLITUDE=STROKE\n{ref}, 1, 1, {fmt(case.delta)}\n")
        out.write(outputs.format(tp="TCYCLE") + "*END STEP\n")
    path = Path(path)
    path.write_text(out.getvalue())
    return path


def element_forces(x: NDArray[np.float64], stress: NDArray[np.float64]
                   ) -> NDArray[np.float64]:
    """Element nodal forces f = sum_gp B^T sigma det(J) w (N; small strain, exact for the
    ccx solution up to the printed digits) of C3D8 elements with node coordinates ``x``
    [m, 8, 3] and Gauss-point stresses ``stress`` [m, 8, 6] in ccx order (xx, yy, zz, xy,
    xz, yz) -> [m, 8, 3]. At a free surface node the sum over its elements is the external
    (contact) force on it."""
    sig = np.empty(stress.shape[:2] + (3, 3))
    for (i, j), c in (((0, 0), 0), ((1, 1), 1), ((2, 2), 2), ((0, 1), 3), ((0, 2), 4),
                      ((1, 2), 5)):
        sig[..., i, j] = sig[..., j, i] = stress[..., c]
    f = np.zeros(x.shape)
    for g, xi in enumerate(GAUSS_2X2X2):
        dn = dshape(xi)  # [8, 3]
        jac = np.einsum("mki,kj->mij", x, dn)  # d x_i / d xi_j
        grad = np.einsum("kj,mji->mki", dn, np.linalg.inv(jac))  # d N_k / d x_i
        f += np.einsum("mki,mil->mkl", grad, sig[:, g]) * np.linalg.det(jac)[:, None, None]
    return f


def surface_forces(mesh: Mesh3D, elems: NDArray[np.int64], stress: NDArray[np.float64]
                   ) -> dict[int, NDArray[np.float64]]:
    """Nodal forces (N) the contact layer's stresses put on its surface nodes
    (:func:`element_forces`); ``stress`` [n_elem, 8, 6] in ccx order (xx, yy, zz, xy, xz,
    yz). Returns {node id (1-based): force [3]} for the bottom nodes (local 1-4)."""
    conn = mesh.elements[np.asarray(elems, dtype=np.int64) - 1]
    f = element_forces(mesh.nodes[conn], stress)
    total = np.zeros((mesh.nodes.shape[0], 3))
    np.add.at(total, conn[:, :4], f[:, :4])
    ids = np.unique(conn[:, :4])
    return {int(i) + 1: total[i] for i in ids}


@dataclass
class SurfaceState:
    """The upper body's contact surface at one output time (SI; one row per surface node)."""

    time: float  #: ccx total time (seating (0, 1], load (1, 2], cycle (2, 6])
    normal_force: float  #: P on the whole contact (symmetry restored), N
    tangential_force: float  #: Q along x on the upper body, N
    xy: NDArray[np.float64]  #: undeformed node positions, m, [n, 2]
    pressure: NDArray[np.float64]  #: Pa, [n]
    shear: NDArray[np.float64]  #: x traction on the upper body, Pa, [n]
    ux_rel: NDArray[np.float64]  #: u_x(upper) - u_x(lower) at the same column, m, [n]
    area: NDArray[np.float64]  #: tributary area of each node, m^2, [n]

    def hertz_fit(self) -> tuple[float, float]:
        """(p0, a): the peak nodal pressure and the radius of the least-squares fit of
        p^2 = p0^2 (1 - r^2 / a^2) over the nodes above 5 % of the peak (Pa, m)."""
        p, r = self.pressure, np.hypot(self.xy[:, 0], self.xy[:, 1])
        p0 = float(p.max())
        ok = p > 0.05 * p0
        A = np.column_stack([np.ones(int(ok.sum())), r[ok] ** 2])
        c, *_ = np.linalg.lstsq(A, p[ok] ** 2, rcond=None)
        return p0, (math.sqrt(-c[0] / c[1]) if c[1] < 0 < c[0] else float("nan"))


@dataclass
class CrossedRun:
    """One ccx run of the crossed-cylinder model: mesh, every output time, timings."""

    case: CrossedCase
    mesh: Mesh3D
    states: list[SurfaceState]
    ccx_s: float
    folder: Path

    @property
    def loaded(self) -> SurfaceState:
        """The state at the end of the normal load (total time 2)."""
        return min(self.states, key=lambda st: abs(st.time - 2.0))


def tributary_area(x: NDArray, y: NDArray, xs: NDArray, ys: NDArray) -> NDArray[np.float64]:
    """Area (m^2) each node of the surface grid ``xs x ys`` stands for (half cells on the
    grid's edges, in particular on the symmetry planes)."""
    ix = np.searchsorted(xs, x - 1e-9 * np.ptp(xs))
    iy = np.searchsorted(ys, y - 1e-9 * np.ptp(ys))
    return tributary_length(xs)[ix] * tributary_length(ys)[iy]


def read_crossed(folder: Path, mesh: Mesh3D, case: CrossedCase) -> list[SurfaceState]:
    """Every output time of ``crossed.dat``: forces, contact tractions, relative slip."""
    blocks = read_dat(folder / "crossed.dat")
    copies = 2.0 if case.half else 4.0
    ubot = mesh.node_sets["UBOT"]
    xs = np.unique(np.round(mesh.nodes[ubot - 1, 0], 15))
    ys = np.unique(np.round(mesh.nodes[ubot - 1, 1], 15))
    ltop = mesh.node_sets["LTOP"]
    states = []
    # the support's reaction on the lower body equals the contact force on the upper body
    for rf in (b for b in blocks if b.kind == "total force"):
        t = rf.time
        st = next(b for b in blocks if b.kind == "stresses" and b.set_name == "UCONT"
                  and b.time == t)
        disp = {b.set_name: b.rows for b in blocks if b.kind == "displacements"
                and b.time == t}
        rows = st.rows  # element, integration point, sxx, syy, szz, sxy, sxz, syz
        elems = rows[:, 0].astype(np.int64).reshape(-1, 8)[:, 0]
        forces = surface_forces(mesh, elems, rows[:, 2:8].reshape(-1, 8, 6))
        ids = np.array(sorted(forces))
        f = np.array([forces[i] for i in ids])
        xy = mesh.nodes[ids - 1, :2]
        area = tributary_area(xy[:, 0], xy[:, 1], xs, ys)
        ux = {int(r[0]): r[1] for r in disp["UBOT"]}
        lx = {int(r[0]): r[1] for r in disp["LTOP"]}
        # the lower body's top node of the same column (same undeformed x, y)
        lower_of = dict(zip(ubot.tolist(), ltop.tolist(), strict=True))
        rel = np.array([ux[int(i)] - lx[lower_of[int(i)]] for i in ids])
        states.append(SurfaceState(
            time=t, normal_force=copies * float(rf.rows[0, 2]),
            tangential_force=copies * float(rf.rows[0, 0]), xy=xy,
            pressure=f[:, 2] / area, shear=f[:, 0] / area, ux_rel=rel, area=area))
    return states


def run_crossed(case: CrossedCase, folder: str | Path, threads: int = 1,
                timeout: float = 3600.0) -> CrossedRun:
    """Mesh, deck, ccx, read (the folder keeps the deck, log, .dat and ``mesh.vtu``)."""
    import time

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    mesh = crossed_mesh(case)
    mesh.write_vtk(folder / "mesh.vtu")
    deck = write_crossed_deck(folder / "crossed.inp", mesh, case)
    t0 = time.perf_counter()
    run_ccx(deck, threads=threads, timeout=timeout)
    ccx_s = time.perf_counter() - t0
    return CrossedRun(case=case, mesh=mesh, states=read_crossed(folder, mesh, case),
                      ccx_s=ccx_s, folder=folder)


def mindlin_stick_radius(state: SurfaceState, ref: SurfaceState, mu: float,
                         stick_slope: float, h: float) -> float:
    """Radius of the stick zone (m) on the y = 0 line: a node sticks while its relative
    displacement since the end of the load ``ref`` is within mu p / stick_slope (the most its
    stick spring can take); the edge is put half an element beyond the outermost stick node
    (as in 2D, docs/fe.md)."""
    on_line = np.abs(state.xy[:, 1]) < 1e-9 * h
    x = state.xy[on_line, 0]
    p = state.pressure[on_line]
    move = np.abs(state.ux_rel[on_line] - ref.ux_rel[on_line])
    stick = (p > 1e-3 * p.max()) & (move <= mu * np.maximum(p, 0.0) / stick_slope * 1.0001)
    if not stick.any():
        return 0.0
    return float(np.abs(x[stick]).max()) + 0.5 * h


def crossed_checks(folder: str | Path, threads: int = 1, h_factor: float = 4.0
                   ) -> list[dict[str, object]]:
    """Closed-form checks of the 3D crossed-cylinder model (Johnson 1985): Hertz point
    contact (eqs 4.22-4.23) on the quarter model; on the half model with friction mu,
    tangential displacement 0 -> 5 um in 4 increments (gross slip from ~3.2 um): the
    Cattaneo-Mindlin stick radius c = a (1 - Q / (mu P))^(1/3) (section 7.2, tolerance 5 %
    or one element) and gross slip Q = mu P."""
    from tribodem.contact.checks import check

    base = CrossedCase()
    p0, a = base.hertz
    h = a / h_factor
    normal = run_crossed(CrossedCase(h_fine=h), Path(folder) / "crossed_normal", threads)
    st = normal.loaded
    p_fe, a_fe = st.hertz_fit()
    out = [check("3D Hertz p0 (crossed cylinders, peak nodal pressure)", p_fe, p0, 0.02),
           check("3D Hertz a (crossed cylinders, fit of p^2)", a_fe, a, 0.02),
           check("3D contact force = P", st.normal_force, base.load, 1e-3)]
    case = CrossedCase(h_fine=h, delta=5e-6, n_increments=16, half_cycle=True)
    tang = run_crossed(case, Path(folder) / "crossed_tangential", threads)
    ref = tang.loaded
    mu = case.contact.mu
    slope = case.contact.stick_slope(case.material.young, case.material.young, h)
    for s in tang.states:
        if s.time <= 2.0 + 1e-9:
            continue
        ratio = abs(s.tangential_force) / (mu * s.normal_force)
        if ratio < 0.97:
            c_fe = mindlin_stick_radius(s, ref, mu, slope, h)
            c_ref = a * (1.0 - ratio) ** (1.0 / 3.0)
            out.append(check(f"3D Mindlin stick radius (m) at Q/(mu P) = {ratio:.2f}",
                             c_fe, c_ref, max(0.05 * c_ref, h), absolute=True))
    last = tang.states[-1]
    out.append(check("3D gross slip Q = mu P (delta = 5 um)", abs(last.tangential_force),
                     mu * last.normal_force, 0.01))
    return out
