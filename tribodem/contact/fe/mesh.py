"""Graded plane-strain mesh of a cylindrical pad on a flat block (numpy only, deterministic).

Geometry (SI, metres), x along the stroke, y up, unit thickness (plane strain):

* lower body: the rectangle ``[-W_l, W_l] x [-H_l, 0]``, top face ``y = 0`` (the flat);
* upper body: a circular-segment pad of radius ``R``: bottom ``y = s(x) = R - sqrt(R^2 - x^2)``
  (touching the flat at ``x = 0``), vertical sides ``x = +-W_u``, flat top ``y = H_u``.

Both bodies are structured grids of 4-node quadrilaterals (ccx ``CPE4``) built as tensor
products of two graded 1D coordinate lists: a uniform fine zone of spacing ``h`` under the
contact (straight node columns ``x = i h``; half-width ``zone_factor a + stroke`` on the flat,
``zone_factor a`` on the pad, depth ``depth_factor a``), then geometric growth by ``growth``
per element away from it. In the pad the vertical coordinate is mapped so that the bottom row
of nodes lies on the arc and the top row on ``y = H_u``.

Node and element numbers are 1-based in the sets below (the ccx convention); ``nodes`` and
``elements`` arrays are 0-based rows (node ``k`` is row ``k - 1``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from tribodem.contact.base import Recession

if TYPE_CHECKING:
    import meshio

#: ccx face label of each quadrilateral edge (nodes 1-2, 2-3, 3-4, 4-1 counter-clockwise)
FACES = ("S1", "S2", "S3", "S4")


def hertz_line(load: float, radius: float, e_star: float) -> tuple[float, float]:
    """Hertz line contact (plane strain): (p0, a) in (Pa, m) for a load per unit length
    ``load`` (N/m) on a cylinder of radius ``radius`` (m) against a flat, contact modulus
    ``e_star`` (Pa): p0 = sqrt(P E* / (pi R)), a = sqrt(4 P R / (pi E*)) (Johnson 4.45)."""
    p0 = math.sqrt(load * e_star / (math.pi * radius))
    a = math.sqrt(4.0 * load * radius / (math.pi * e_star))
    return p0, a


def graded_half(fine: float, h: float, total: float, growth: float) -> NDArray[np.float64]:
    """Coordinates 0 .. ``total`` (m): uniform spacing ``h`` up to >= ``fine``, then spacings
    growing by ``growth`` per element; the last spacing is merged so the list ends at ``total``
    without a sliver (the last element is at most ``growth`` times the one before)."""
    if not (0 < h <= fine < total) or growth < 1.0:
        raise ValueError(f"graded_half: need 0 < h <= fine < total and growth >= 1, got "
                         f"h={h!r}, fine={fine!r}, total={total!r}, growth={growth!r}")
    n_fine = int(math.ceil(fine / h - 1e-9))
    xs = list(np.arange(n_fine + 1) * h)
    step = h
    while xs[-1] < total:
        step *= growth
        xs.append(xs[-1] + step)
    if len(xs) > n_fine + 2 and xs[-1] - total > 0.5 * step:
        xs.pop()  # drop the overshooting point, stretch the previous element instead
    xs[-1] = total
    return np.asarray(xs, dtype=float)


def graded_symmetric(fine: float, h: float, total: float, growth: float) -> NDArray[np.float64]:
    """Symmetric graded coordinates ``-total .. total`` (m) with a node at 0."""
    half = graded_half(fine, h, total, growth)
    return np.concatenate([-half[:0:-1], half])


@dataclass
class Mesh:
    """2D quadrilateral mesh of the two bodies with the sets the deck needs."""

    nodes: NDArray[np.float64]  #: node coordinates (x, y), m, [n_nodes, 2]
    elements: NDArray[np.int64]  #: 0-based node rows of each CPE4, counter-clockwise, [n, 4]
    node_sets: dict[str, NDArray[np.int64]] = field(default_factory=dict)  #: 1-based ids
    element_sets: dict[str, NDArray[np.int64]] = field(default_factory=dict)  #: 1-based ids
    #: element-face surfaces: name -> (1-based element ids, face index 0..3 -> S1..S4)
    surfaces: dict[str, tuple[NDArray[np.int64], int]] = field(default_factory=dict)
    h_fine: float = 0.0  #: element size in the fine zone, m
    info: dict[str, float] = field(default_factory=dict)  #: geometry parameters, SI
    #: straight node columns per body (``"lower"``, ``"upper"``): 0-based node rows
    #: [n_columns, n_layers], surface node first, going into the body; columns sorted by x
    columns: dict[str, NDArray[np.int64]] = field(default_factory=dict)
    #: node layers of the fine zone below the surface: column node ``fine_layers`` is the
    #: bottom of the fine section (``H`` of seed eq 3.7), the last node morphing moves
    fine_layers: int = 0

    @property
    def n_nodes(self) -> int:
        return int(self.nodes.shape[0])

    @property
    def n_elements(self) -> int:
        return int(self.elements.shape[0])

    def check(self) -> None:
        """Raise ValueError on inverted or degenerate elements (signed area <= 0)."""
        p = self.nodes[self.elements]  # [n, 4, 2]
        x, y = p[..., 0], p[..., 1]
        area = 0.5 * np.sum(x * np.roll(y, -1, axis=1) - np.roll(x, -1, axis=1) * y, axis=1)
        bad = np.flatnonzero(area <= 0.0)
        if bad.size:
            raise ValueError(f"{bad.size} elements with non-positive area (first: {bad[0] + 1})")

    def to_meshio(self) -> meshio.Mesh:
        """A :class:`meshio.Mesh` (z = 0) with a ``body`` cell field (0 lower, 1 upper)."""
        import meshio

        pts = np.column_stack([self.nodes, np.zeros(self.n_nodes)])
        body = np.zeros(self.n_elements, dtype=np.int64)
        body[self.element_sets["UPPER"] - 1] = 1
        return meshio.Mesh(pts, [("quad", self.elements)], cell_data={"body": [body]})

    def write_vtk(self, path: str | Path) -> Path:
        """Write the mesh to a VTK/VTU file (format from the suffix, via meshio)."""
        path = Path(path)
        self.to_meshio().write(path)
        return path


def _grid(xs: NDArray[np.float64], ys: NDArray[np.float64]) -> tuple[NDArray[np.float64],
                                                                     NDArray[np.int64]]:
    """Nodes (row-major: x fastest) and CCW quads of the tensor grid ``xs x ys``."""
    nx, ny = xs.size, ys.size
    xx, yy = np.meshgrid(xs, ys)  # [ny, nx]
    nodes = np.column_stack([xx.ravel(), yy.ravel()])
    i, j = np.meshgrid(np.arange(nx - 1), np.arange(ny - 1))
    n1 = (j * nx + i).ravel()
    quads = np.column_stack([n1, n1 + 1, n1 + 1 + nx, n1 + nx]).astype(np.int64)
    return nodes, quads


@dataclass(frozen=True)
class PadOnFlat:
    """Parameters of :func:`cylinder_on_flat` (SI). ``a`` is the Hertz half-width that sets
    the fine zone (use :func:`hertz_line` of the intended load)."""

    radius: float = 4e-3  #: pad radius R, m (seed: 8 mm diameter cylinders)
    a: float = 62e-6  #: expected contact half-width, m
    h_fine: float = 5e-6  #: element size in the fine zone, m
    stroke: float = 0.0  #: tangential amplitude the flat's fine zone must cover, m
    zone_factor: float = 1.75  #: fine zone half-width on the pad, in units of a
    depth_factor: float = 1.5  #: fine zone depth, in units of a
    size_factor: float = 20.0  #: body half-width and height, in units of a (pad <= 0.4 R)
    growth: float = 1.2  #: size ratio of neighbouring elements outside the fine zone


def cylinder_on_flat(p: PadOnFlat) -> Mesh:
    """Mesh of the pad (upper) on the flat (lower); see the module docstring.

    Node sets: ``LBOT`` (flat bottom, fixed), ``UTOP`` (pad top, tied), ``REF`` (the pad top
    node at x = 0, carries the load), ``LTOP`` / ``UBOT`` (contact faces' nodes).
    Element sets: ``LOWER``, ``UPPER``, ``LFINE``, ``UFINE`` (fine zones), ``UCONT`` (the
    pad's bottom row), ``LCONT`` (the flat's top row under the master surface).
    Surfaces: ``SFLAT`` (flat top faces, master), ``SPAD`` (pad arc faces, slave).
    """
    h, a, R = p.h_fine, p.a, p.radius
    half_l = max(p.size_factor * a, p.zone_factor * a + p.stroke + 10 * a)
    half_u = min(p.size_factor * a, 0.4 * R)  # a segment of the cylinder, at most 0.8 R wide
    if half_u <= p.zone_factor * a + 2 * p.h_fine:
        raise ValueError(f"pad half-width {half_u:.3g} m leaves no room outside the fine zone: "
                         "the contact is too wide for the radius")
    fine_l = p.zone_factor * a + p.stroke
    fine_u = p.zone_factor * a
    depth = p.depth_factor * a
    # lower body
    xl = graded_symmetric(fine_l, h, half_l, p.growth)
    yl = -graded_half(depth, h, p.size_factor * a, p.growth)[::-1]
    nodes_l, quads_l = _grid(xl, yl)
    # upper body: eta = height above the arc, mapped to [s(x), H_u]
    xu = graded_symmetric(fine_u, h, half_u, p.growth)
    h_top = p.size_factor * a
    eta = graded_half(depth, h, h_top, p.growth)
    s = R - np.sqrt(R * R - xu * xu)
    xx, ee = np.meshgrid(xu, eta)
    yy = s[None, :] + ee * (h_top - s[None, :]) / h_top
    nodes_u = np.column_stack([xx.ravel(), yy.ravel()])
    _, quads_u = _grid(xu, eta)
    off = nodes_l.shape[0]
    nodes = np.vstack([nodes_l, nodes_u])
    elements = np.vstack([quads_l, quads_u + off])
    nxl, nxu = xl.size, xu.size
    n_el_l = quads_l.shape[0]
    ids = np.arange(1, nodes.shape[0] + 1)
    node_sets = {
        "LBOT": ids[:nxl],
        "LTOP": ids[off - nxl:off],
        "UBOT": ids[off:off + nxu],
        "UTOP": ids[nodes.shape[0] - nxu:],
    }
    node_sets["REF"] = node_sets["UTOP"][[int(np.argmin(np.abs(xu)))]]
    el_ids = np.arange(1, elements.shape[0] + 1)
    cen = nodes[elements].mean(axis=1)
    lower = el_ids[:n_el_l]
    upper = el_ids[n_el_l:]
    in_fine_l = (np.abs(cen[:n_el_l, 0]) < fine_l + h) & (cen[:n_el_l, 1] > -depth - h)
    in_fine_u = (np.abs(cen[n_el_l:, 0]) < fine_u + h) & (cen[n_el_l:, 1] < depth + h)
    # contact faces: the flat's top row (S3) and the pad's bottom row (S1), cut to a margin
    top_row = lower[-(nxl - 1):]
    bot_row = upper[:nxu - 1]
    flat_faces = top_row[np.abs(cen[top_row - 1, 0]) < fine_l + 8 * a]
    pad_faces = bot_row[np.abs(cen[bot_row - 1, 0]) < fine_u + 2 * a]
    nyl, nyu = yl.size, eta.size
    col_l = ((nyl - 1 - np.arange(nyl))[None, :] * nxl + np.arange(nxl)[:, None]).astype(np.int64)
    col_u = (off + np.arange(nyu)[None, :] * nxu + np.arange(nxu)[:, None]).astype(np.int64)
    mesh = Mesh(
        nodes=nodes,
        elements=elements,
        node_sets=node_sets,
        element_sets={"LOWER": lower, "UPPER": upper, "LFINE": lower[in_fine_l],
                      "UFINE": upper[in_fine_u], "UCONT": bot_row, "LCONT": flat_faces},
        surfaces={"SFLAT": (flat_faces, 2), "SPAD": (pad_faces, 0)},
        h_fine=h,
        info={"radius": R, "a": a, "half_lower": half_l, "half_upper": half_u,
              "height_lower": p.size_factor * a, "height_upper": h_top, "fine_lower": fine_l,
              "fine_upper": fine_u, "fine_depth": depth},
        columns={"lower": col_l, "upper": col_u},
        fine_layers=int(math.ceil(depth / h - 1e-9)),
    )
    mesh.check()
    return mesh


def surface_profile(mesh: Mesh, body: str) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(x, y) of the surface nodes of ``body`` (``"lower"``/``"upper"``), sorted by x, m."""
    top = mesh.columns[body][:, 0]
    return mesh.nodes[top, 0].copy(), mesh.nodes[top, 1].copy()


def morph_columns(mesh: Mesh, body: str, wear: NDArray[np.float64]) -> Mesh:
    """A copy of ``mesh`` with the surface of ``body`` receded by ``wear`` (m, one value per
    column of ``mesh.columns[body]``, >= 0) by node-column morphing (seed eqs 3.7-3.8).

    Each surface node moves along its straight column, *into* the body (the flat's down, the
    pad's up), by its worn depth dW; the nodes below it down to the bottom of the fine section
    (``fine_layers`` nodes deeper, at distance H) are moved by eq 3.8,
    ``y_i = y_b + m (y_i - y_b)`` with ``m = (H - dW) / H`` (eq 3.7) and ``y_b`` the fine
    section's bottom node (fixed), so every element of the column keeps the same fraction of
    the column's height and the mesh keeps its aspect (nothing moves sideways). The worn
    area is then exactly :func:`worn_area` (the columns are vertical). ``ValueError`` when a
    worn depth reaches H (the fine section would invert)."""
    wear = np.asarray(wear, dtype=float)
    cols = mesh.columns[body]
    if wear.shape != (cols.shape[0],):
        raise ValueError(f"wear has shape {wear.shape}: expected ({cols.shape[0]},), one depth "
                         f"per column of the {body} body")
    if np.any(wear < 0) or not np.all(np.isfinite(wear)):
        raise ValueError("wear depths must be finite and >= 0 (m)")
    k = mesh.fine_layers
    nodes = mesh.nodes.copy()
    fine = cols[:, :k + 1]  # [n_col, k + 1]: surface .. fine bottom
    y = nodes[fine, 1]
    yb = y[:, -1:]
    height = np.abs(y[:, :1] - yb)  # H per column
    if np.any(wear >= height[:, 0]):
        j = int(np.argmax(wear / height[:, 0]))
        raise ValueError(f"worn depth {wear[j]:.4g} m at x = {nodes[cols[j, 0], 0]:.4g} m "
                         f"reaches the fine section's depth H = {height[j, 0]:.4g} m of the "
                         f"{body} body: the mesh cannot be morphed further (a deeper fine zone "
                         "is needed)")
    m = (height - wear[:, None]) / height  # eq 3.7
    nodes[fine, 1] = yb + m * (y - yb)  # eq 3.8
    out = Mesh(nodes=nodes, elements=mesh.elements, node_sets=mesh.node_sets,
               element_sets=mesh.element_sets, surfaces=mesh.surfaces, h_fine=mesh.h_fine,
               info=dict(mesh.info), columns=mesh.columns, fine_layers=mesh.fine_layers)
    out.check()
    return out


def _hat_samples(x: NDArray[np.float64], lo: float, hi: float, step: float
                 ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Sample points on the sorted node line ``x`` (midpoints of equal sub-intervals of each
    element, at most ``step`` m wide where the element meets ``[lo, hi]``, one elsewhere)
    and the weight of each sample for each node, [n_nodes, n_samples]: the node's linear
    shape function times the sub-interval's length (a row sums to the node's tributary
    length)."""
    width = np.diff(x)
    meets = (x[1:] >= lo) & (x[:-1] <= hi)
    m = np.where(meets, np.maximum(np.ceil(width / step), 1.0), 1.0).astype(np.int64)
    first = np.concatenate([[0], np.cumsum(m)[:-1]])
    k = np.repeat(np.arange(width.size), m)  # the element of each sample
    t = (np.arange(k.size) - first[k] + 0.5) / m[k]
    dl = width[k] / m[k]
    weights = np.zeros((x.size, k.size))
    cols = np.arange(k.size)
    weights[k, cols] = (1.0 - t) * dl
    weights[k + 1, cols] = t * dl
    return x[k] + t * width[k], weights


def worn_depth(now: Recession, base: Recession) -> Recession:
    """(x, y) -> the recession ``now`` minus the unworn ``base`` clipped at zero, m: the
    worn depth (a pile-up is not negative wear)."""
    def depth(x: NDArray[np.float64], y: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.maximum(np.asarray(now(x, y), dtype=float)
                          - np.asarray(base(x, y), dtype=float), 0.0)
    return depth


def surface_projection(depth: Recession, xs: NDArray[np.float64], ys: NDArray[np.float64] | None,
                       box: tuple[float, float, float, float], step: float
                       ) -> NDArray[np.float64]:
    """Nodal values of ``depth(x, y)`` (m) on the grid ``xs`` x ``ys`` ([ny, nx]; ``ys`` None:
    a line of nodes along ``xs`` at y = 0, [nx]) by the lumped L2 projection onto the
    surface's bilinear (linear) shape functions: w_i = int phi_i depth dA / int phi_i dA, by
    the midpoint rule on sub-cells at most ``step`` m wide inside ``box`` = (x_lo, x_hi,
    y_lo, y_hi), m (``depth`` is zero outside it).

    Node-column morphing (eqs 3.7-3.8) with these depths removes exactly the sampled volume
    (the shape functions sum to one, and the morphed surface's volume is the sum of nodal
    depths times int phi_i dA, the tributary areas), and features shorter than the
    elements are damped (a wave two elements long keeps 4 / pi^2 = 0.4 of its amplitude):
    sampled at the nodes alone a scar a few elements wide lost the wrong volume (+-50 % on
    a 44-um mesh) and its rim became kinks the sliding contact catches on."""
    x_lo, x_hi, y_lo, y_hi = box
    px, wx = _hat_samples(np.asarray(xs, dtype=float), x_lo, x_hi, step)
    if ys is None:
        py, wy = np.zeros(1), np.ones((1, 1))
    else:
        py, wy = _hat_samples(np.asarray(ys, dtype=float), y_lo, y_hi, step)
    x, y = np.meshgrid(px, py)
    inside = (x >= x_lo) & (x <= x_hi) & (y >= y_lo) & (y <= y_hi)
    w = np.zeros_like(x)
    w[inside] = np.asarray(depth(x[inside], y[inside]), dtype=float)
    out = (wy @ w @ wx.T) / np.outer(wy.sum(axis=1), wx.sum(axis=1))
    return out[0] if ys is None else out


def worn_area(original: Mesh, morphed: Mesh, body: str) -> float:
    """Area (m^2 per metre of thickness: the worn volume per unit length, m^3/m) between the
    original and the morphed surface of ``body``: the surfaces are the polylines through the
    surface nodes, which share their x (vertical columns), so the area is exactly the
    trapezoidal sum of the nodal depths."""
    x, y0 = surface_profile(original, body)
    _, y1 = surface_profile(morphed, body)
    d = np.abs(y1 - y0)
    return float(np.sum(0.5 * (d[1:] + d[:-1]) * np.diff(x)))


def element_areas(mesh: Mesh) -> NDArray[np.float64]:
    """Signed area of every quadrilateral (shoelace), m^2 [n_elements]."""
    p = mesh.nodes[mesh.elements]
    x, y = p[..., 0], p[..., 1]
    return 0.5 * np.sum(x * np.roll(y, -1, axis=1) - np.roll(x, -1, axis=1) * y, axis=1)


def hat_integrals(nodes: NDArray[np.float64], lo: NDArray[np.float64], hi: NDArray[np.float64]
                  ) -> NDArray[np.float64]:
    """Exact integrals (m) of the piecewise-linear hat functions phi_i of the sorted node
    line ``nodes`` (m; phi_i = 1 at node i, 0 at the others, linear between, zero outside
    [nodes[0], nodes[-1]]: the end nodes have one half only) over the intervals
    [lo_k, hi_k] (m, lo <= hi): [n_nodes, n_intervals],
    int_lo^hi phi_i dx = Phi_i(hi) - Phi_i(lo) with the antiderivative
    Phi_i(x) = (x - x_{i-1})^2 / (2 h_l) on [x_{i-1}, x_i],
    h_l / 2 + h_r / 2 - (x_{i+1} - x)^2 / (2 h_r) on [x_i, x_{i+1}] (h_l, h_r the element
    lengths left and right of node i), constant outside. A column sums to the length of
    [lo, hi] inside the node line (the hats are a partition of unity there)."""
    x = np.asarray(nodes, dtype=float)
    h = np.diff(x)
    hl = np.concatenate([[0.0], h])[:, None]  # element left of node i (0 at the first)
    hr = np.concatenate([h, [0.0]])[:, None]
    xi = x[:, None]

    def antiderivative(t: NDArray[np.float64]) -> NDArray[np.float64]:
        t = np.asarray(t, dtype=float)[None, :]
        left = np.clip(t - (xi - hl), 0.0, hl)  # distance into the left element
        right = np.clip((xi + hr) - t, 0.0, hr)  # distance left before the right end
        with np.errstate(divide="ignore", invalid="ignore"):
            f_left = np.where(hl > 0, left * left / (2.0 * np.where(hl > 0, hl, 1.0)), 0.0)
            f_right = np.where(hr > 0, right * right / (2.0 * np.where(hr > 0, hr, 1.0)), 0.0)
        # Phi = (rising part so far) + (falling part so far) = f_left + (h_r / 2 - f_right)
        # on the right of x_i; left of x_i, right = h_r and the second term is 0
        return f_left + 0.5 * hr - f_right

    return antiderivative(hi) - antiderivative(lo)


def tributary_depths(depth: NDArray[np.float64], x: NDArray[np.float64],
                     y: NDArray[np.float64], dx: float, dy: float, xs: NDArray[np.float64],
                     ys: NDArray[np.float64], fold_y: bool = False) -> NDArray[np.float64]:
    """Nodal depths (m, [len(ys), len(xs)]) that carry a wear map's volume node by node:
    the map ``depth`` (m, [len(y), len(x)], >= 0) is piecewise constant on cells of
    ``dx`` x ``dy`` (m) centred on its points ``x`` x ``y`` (m; the fretting loop's grids,
    whose volume is sum(depth) dx dy); each cell's volume goes to the surface nodes of the
    grid ``xs`` x ``ys`` (m, sorted) in proportion to the integral of their bilinear shape
    function over the cell (exact, :func:`hat_integrals`), and each node's depth is its
    share over its tributary area: w_i = sum_k d_k int_cell_k phi_i dA / int phi_i dA.

    Node-column morphing (eqs 3.7-3.8) with these depths removes exactly the map's volume,
    sum_i w_i A_i = sum_k d_k dx dy (the shape functions are a partition of unity over the
    cells; to rounding), and every depth is a weighted mean of the cells it touches (>= 0,
    at most the deepest). ``fold_y``: the node grid is the half model y >= 0 (``ys[0]`` =
    0) of a body symmetric about y = 0: the map is folded onto it, (d(x, y) + d(x, -y)) / 2,
    so the half carries exactly half the map's volume, symmetric or not. ``ValueError``
    when a worn cell reaches outside the node grid (its volume would be lost)."""
    d = np.asarray(depth, dtype=float)
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    if d.shape != (y.size, x.size):
        raise ValueError(f"depth has shape {d.shape}: expected ({y.size}, {x.size}) (y, x)")
    wx = hat_integrals(xs, x - 0.5 * dx, x + 0.5 * dx)
    if fold_y:
        wy = 0.5 * (hat_integrals(ys, y - 0.5 * dy, y + 0.5 * dy)
                    + hat_integrals(ys, -y - 0.5 * dy, -y + 0.5 * dy))
    else:
        wy = hat_integrals(ys, y - 0.5 * dy, y + 0.5 * dy)
    worn = d > 0.0
    cover = np.outer(wy.sum(axis=0) / dy, wx.sum(axis=0) / dx)
    if np.any(worn & (np.abs(cover - (0.5 if fold_y else 1.0)) > 1e-9)):
        j, i = np.argwhere(worn & (np.abs(cover - (0.5 if fold_y else 1.0)) > 1e-9))[0]
        raise ValueError(f"worn cell at (x, y) = ({x[i]:.4g}, {y[j]:.4g}) m is not inside "
                         f"the mesh's surface grid x in [{xs[0]:.4g}, {xs[-1]:.4g}], y in "
                         f"[{ys[0]:.4g}, {ys[-1]:.4g}] m: its volume would be lost")
    lx = hat_integrals(xs, np.array([xs[0]]), np.array([xs[-1]]))[:, 0]
    ly = hat_integrals(ys, np.array([ys[0]]), np.array([ys[-1]]))[:, 0]
    return (wy @ d @ wx.T) / np.outer(ly, lx)
