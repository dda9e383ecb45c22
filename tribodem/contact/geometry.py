"""First-body surface geometries as recession maps (Lu (2018) section 3.3.1, figure 3.4).

A surface is described by its *recession* ``g(x, y)`` (m): the distance from the body's
surface to the common tangent plane at the initial contact point, positive away from the
other body. The gap at rigid approach zero is ``g_upper(x - offset, y) + g_lower(x, y)``
(upper body displaced by ``offset`` along x); wear adds the worn depth to the recession.

A surface is either a callable ``g(x, y)`` on arrays (m -> m) or a :class:`HeightMap`
sampled on a regular grid (linear interpolation); a 1-D profile extruded along one axis
is made with :func:`extruded_profile`.

The fretting cases (``[contact] geometry`` of ``tribodem fretting run``) are the dataclasses
:class:`CrossedCylinders`, :class:`SphereOnFlat`, :class:`CylinderOnFlat` (line contact),
:class:`FlatPunch` and :class:`HeightMaps`; each default is defined once, as the dataclass
field default (all radii in m). The shaped body is the *upper* one (its contact stays at the
window centre), the flat is the lower one.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tribodem.contact.base import Recession  # noqa: E402 - one definition, in the contract

#: Lu (2018) specimens: 8 mm diameter cylinders (radius 4 mm), the default of every curved body.
SEED_RADIUS = 4e-3

Contact = Literal["point", "line"]


@dataclass(frozen=True)
class HeightMap:
    """Recession map on a regular grid: ``values[i, j]`` at ``(x0 + i dx, y0 + j dy)``, m."""

    values: NDArray[np.float64]
    dx: float
    dy: float
    x0: float
    y0: float

    def __post_init__(self) -> None:
        v = np.asarray(self.values, dtype=float)
        if v.ndim != 2 or min(v.shape) < 2:
            raise ValueError(
                f"values has shape {v.shape}: a height map must be 2-D with >= 2 points per side"
            )
        if not np.all(np.isfinite(v)):
            raise ValueError("values contains non-finite entries: all heights must be finite")
        for name in ("dx", "dy"):
            d = float(getattr(self, name))
            if not (math.isfinite(d) and d > 0):
                raise ValueError(f"{name} = {d!r} is not allowed: grid spacing must be > 0")
        object.__setattr__(self, "values", v)

    @classmethod
    def centred(cls, values: ArrayLike, dx: float, dy: float | None = None) -> HeightMap:
        """Height map whose grid is centred on (0, 0)."""
        v = np.asarray(values, dtype=float)
        dy = dx if dy is None else dy
        return cls(v, dx, dy, -(v.shape[0] - 1) * dx / 2, -(v.shape[1] - 1) * dy / 2)

    @property
    def extent(self) -> tuple[float, float, float, float]:
        """(xmin, xmax, ymin, ymax), m."""
        nx, ny = self.values.shape
        return (self.x0, self.x0 + (nx - 1) * self.dx, self.y0, self.y0 + (ny - 1) * self.dy)

    def __call__(self, x: NDArray[np.float64], y: NDArray[np.float64]) -> NDArray[np.float64]:
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        xmin, xmax, ymin, ymax = self.extent
        tol = 1e-9 * max(self.dx, self.dy)
        if (
            x.min() < xmin - tol
            or x.max() > xmax + tol
            or y.min() < ymin - tol
            or (y.max() > ymax + tol)
        ):
            raise ValueError(
                f"height map covers x in [{xmin:.4g}, {xmax:.4g}] m, y in [{ymin:.4g}, "
                f"{ymax:.4g}] m but was sampled on x in [{x.min():.4g}, {x.max():.4g}], "
                f"y in [{y.min():.4g}, {y.max():.4g}]: make the map cover the window "
                "(and, for the lower body, the whole track)"
            )
        nx, ny = self.values.shape
        from scipy.interpolate import RegularGridInterpolator  # here: 0.6 s to import

        interp = RegularGridInterpolator(
            (self.x0 + self.dx * np.arange(nx), self.y0 + self.dy * np.arange(ny)),
            self.values,
            bounds_error=False,
            fill_value=None,
        )
        pts = np.stack([np.clip(x, xmin, xmax), np.clip(y, ymin, ymax)], axis=-1)
        return interp(pts)


def cylinder(diameter: float = 2 * SEED_RADIUS, axis: str = "x", exact: bool = True) -> Recession:
    """Recession of a cylinder of ``diameter`` (m) with its axis along ``axis`` ('x' or 'y').

    ``exact`` uses the circle ``R - sqrt(R^2 - r^2)`` (clipped at r = R), else the Hertz
    parabola ``r^2 / (2 R)``; ``r`` is the distance to the axis in the tangent plane.
    """
    if not (math.isfinite(diameter) and diameter > 0):
        raise ValueError(f"diameter = {diameter!r} is not allowed: must be > 0 (m)")
    if axis not in ("x", "y"):
        raise ValueError(f"axis = {axis!r} is not allowed: use 'x' or 'y'")
    radius = diameter / 2.0

    def recession(x: NDArray[np.float64], y: NDArray[np.float64]) -> NDArray[np.float64]:
        r = np.asarray(y if axis == "x" else x, dtype=float)
        r = np.broadcast_to(r, np.broadcast_shapes(np.shape(x), np.shape(y)))
        if not exact:
            return r**2 / (2 * radius)
        rr = np.minimum(np.abs(r), radius)
        return radius - np.sqrt(radius**2 - rr**2)

    return recession


def crossed_cylinders(
    diameter: float = 2 * SEED_RADIUS, exact: bool = True
) -> tuple[Recession, Recession]:
    """(upper, lower) recessions of two crossed cylinders of equal ``diameter`` (m).

    The stroke is along x. The upper cylinder's axis is along y, so its contact spot is
    fixed in its own frame; the lower cylinder's axis is along x, so the contact travels
    along its generator (the wear track). Equivalent to a sphere of R = D/2 on a flat.
    """
    return cylinder(diameter, axis="y", exact=exact), cylinder(diameter, axis="x", exact=exact)


def extruded_profile(
    profile: Callable[[NDArray[np.float64]], NDArray[np.float64]], along: str = "y"
) -> Recession:
    """Recession from a 1-D profile ``g(s)`` (m -> m), extruded along ``along`` ('x'/'y')."""
    if along not in ("x", "y"):
        raise ValueError(f"along = {along!r} is not allowed: use 'x' or 'y'")

    def recession(x: NDArray[np.float64], y: NDArray[np.float64]) -> NDArray[np.float64]:
        s = np.asarray(x if along == "y" else y, dtype=float)
        return np.broadcast_to(profile(s), np.broadcast_shapes(np.shape(x), np.shape(y)))

    return recession


@dataclass(frozen=True)
class HertzSphere:
    """Hertz solution of a sphere of radius R on a flat (Johnson, Contact Mechanics, 4.2)."""

    radius: float  #: equivalent radius, m
    load: float  #: normal load, N
    modulus: float  #: contact modulus E*, Pa

    @property
    def contact_radius(self) -> float:
        """a = (3 P R / (4 E*))^(1/3), m."""
        return (3 * self.load * self.radius / (4 * self.modulus)) ** (1 / 3)

    @property
    def peak_pressure(self) -> float:
        """p0 = 3 P / (2 pi a^2), Pa."""
        return 3 * self.load / (2 * math.pi * self.contact_radius**2)

    @property
    def approach(self) -> float:
        """Rigid approach d = a^2 / R, m."""
        return self.contact_radius**2 / self.radius

    def pressure(self, r: NDArray[np.float64]) -> NDArray[np.float64]:
        """p(r) = p0 sqrt(1 - r^2/a^2) inside the contact, Pa."""
        a = self.contact_radius
        return self.peak_pressure * np.sqrt(np.clip(1 - (np.asarray(r) / a) ** 2, 0, None))

    def axis_max_shear(self, poisson: float, z: NDArray[np.float64]) -> NDArray[np.float64]:
        """Maximum shear (sigma_1 - sigma_3)/2 on the axis at depths ``z`` (m), Pa (eq 3.72)."""
        a, p0 = self.contact_radius, self.peak_pressure
        zeta = np.maximum(np.asarray(z, dtype=float) / a, 1e-12)
        sz = -p0 / (1 + zeta**2)
        sr = -p0 * ((1 + poisson) * (1 - zeta * np.arctan(1 / zeta)) - 0.5 / (1 + zeta**2))
        return 0.5 * np.abs(sr - sz)


def _positive(name: str, value: float) -> float:
    v = float(value)
    if not (math.isfinite(v) and v > 0):
        raise ValueError(f"{name} = {value!r} is not allowed: must be finite and > 0 (m)")
    return v


def flat() -> Recession:
    """Recession of a flat body: zero everywhere, m."""

    def recession(x: NDArray[np.float64], y: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.zeros(np.broadcast_shapes(np.shape(x), np.shape(y)))

    return recession


def sphere(radius: float = SEED_RADIUS, exact: bool = True) -> Recession:
    """Recession of a sphere of ``radius`` (m) touching at the origin: the circle
    ``R - sqrt(R^2 - r^2)`` (clipped at r = R) or, ``exact=False``, ``r^2 / (2 R)``, m."""
    radius = _positive("radius", radius)

    def recession(x: NDArray[np.float64], y: NDArray[np.float64]) -> NDArray[np.float64]:
        r = np.hypot(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
        if not exact:
            return r**2 / (2 * radius)
        rr = np.minimum(r, radius)
        return radius - np.sqrt(radius**2 - rr**2)

    return recession


def rounded_punch(punch_radius: float, edge_radius: float, exact: bool = True) -> Recession:
    """Recession of an axisymmetric flat punch: a flat face of radius ``punch_radius`` (m)
    blended into the side by a toroidal edge of radius ``edge_radius`` (m): 0 for
    r <= b, ``R_e - sqrt(R_e^2 - (r - b)^2)`` (clipped at r - b = R_e; ``exact=False``:
    ``(r - b)^2 / (2 R_e)``) beyond, m."""
    b = _positive("punch_radius", punch_radius)
    re = _positive("edge_radius", edge_radius)

    def recession(x: NDArray[np.float64], y: NDArray[np.float64]) -> NDArray[np.float64]:
        s = np.maximum(np.hypot(np.asarray(x, dtype=float), np.asarray(y, dtype=float)) - b,
                       0.0)
        if not exact:
            return s**2 / (2 * re)
        s = np.minimum(s, re)
        return re - np.sqrt(re**2 - s**2)

    return recession


@dataclass(frozen=True)
class HertzCylinder:
    """Hertz line contact (plane strain) of a cylinder of radius R on a flat per unit length
    (Johnson, Contact Mechanics, 4.3): the 2-D counterpart of :class:`HertzSphere`."""

    radius: float  #: equivalent radius, m
    load_per_length: float  #: normal load per unit length P', N/m
    modulus: float  #: contact modulus E*, Pa

    @property
    def half_width(self) -> float:
        """a = sqrt(4 P' R / (pi E*)), m."""
        return math.sqrt(4 * self.load_per_length * self.radius / (math.pi * self.modulus))

    @property
    def peak_pressure(self) -> float:
        """p0 = sqrt(P' E* / (pi R)) = 2 P' / (pi a), Pa."""
        return math.sqrt(self.load_per_length * self.modulus / (math.pi * self.radius))

    def pressure(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """p(x) = p0 sqrt(1 - x^2/a^2) inside the contact, Pa."""
        a = self.half_width
        return self.peak_pressure * np.sqrt(np.clip(1 - (np.asarray(x) / a) ** 2, 0, None))


def line_window(radius: float, load: float, modulus: float, half_widths: float) -> float:
    """Side W (m) of the window that holds ``half_widths`` Hertz half-widths of a line
    contact whose *total* load on the window is ``load`` (N), so P' = load / W:
    W = k a(P / W) gives W^3 = k^2 4 P R / (pi E*)."""
    return (half_widths**2 * 4 * load * radius / (math.pi * modulus)) ** (1 / 3)


def punch_load(a: float, punch_radius: float, edge_radius: float, modulus: float) -> float:
    """Load (N) that makes the rounded flat punch's contact radius ``a`` >= b (m): Sneddon's
    P = 2 E* int_0^a r^2 g'(r) / sqrt(a^2 - r^2) dr with g' = (r - b) / R_e beyond b
    (Ciavarella, Hills, Monno 1998; parabolic edge), in closed form."""
    b, re = punch_radius, edge_radius
    if a <= b:
        return 0.0
    c = math.sqrt(1 - (b / a) ** 2)
    t0 = math.asin(b / a)
    return 2 * modulus / re * (a**3 * (c - c**3 / 3)
                               - a**2 * b * (math.pi / 4 - t0 / 2 + (b / a) * c / 2))


def punch_contact_radius(punch_radius: float, edge_radius: float, load: float,
                         modulus: float) -> float:
    """Contact radius a (m) of the rounded flat punch under ``load`` (N): the root of
    :func:`punch_load` (a > b; Hertz-like growth beyond the flat face)."""
    b, re = punch_radius, edge_radius
    hi = max(2 * b, (3 * load * re / (4 * modulus)) ** (1 / 3)) + b
    from scipy.optimize import brentq  # here: 0.4 s to import, which every command paid

    return float(brentq(lambda a: punch_load(a, b, re, modulus) - load, b, hi, xtol=1e-15,
                        rtol=1e-12))


def elliptical_semi_axes(radius_x: float, radius_y: float, load: float,
                         modulus: float) -> tuple[float, float]:
    """Approximate Hertz semi-axes (a_x, a_y) (m) of a point contact whose summed recession
    has radii ``radius_x`` (curvature in the x-z plane) and ``radius_y``: a_x a_y = c^2 with
    c the Hertz radius of R_e = sqrt(R_x R_y) and a_x / a_y = (R_x / R_y)^(2/3) (Johnson,
    Contact Mechanics, 4.2, eq 4.41 approximation; exact for R_x = R_y)."""
    c = HertzSphere(math.sqrt(radius_x * radius_y), load, modulus).contact_radius
    k = (radius_x / radius_y) ** (1 / 3)
    return c * k, c / k


@dataclass(frozen=True)
class CrossedCylinders:
    """Lu (2018) case: upper cylinder's axis along y (radius ``radius_upper``, m), lower
    cylinder's axis along x (``radius_lower``, m); stroke along x. Point contact."""

    radius_upper: float = SEED_RADIUS
    radius_lower: float = SEED_RADIUS
    name = "crossed_cylinders"
    contact: ClassVar[Contact] = "point"

    def __post_init__(self) -> None:
        _positive("radius_upper", self.radius_upper)
        _positive("radius_lower", self.radius_lower)

    def recessions(self) -> tuple[Recession, Recession]:
        """(upper, lower) recessions, m."""
        return (cylinder(2 * self.radius_upper, axis="y"),
                cylinder(2 * self.radius_lower, axis="x"))

    def contact_size(self, load: float, modulus: float) -> tuple[float, float]:
        """Hertz semi-axes (a_x, a_y), m, under ``load`` (N) and E* ``modulus`` (Pa)."""
        return elliptical_semi_axes(self.radius_upper, self.radius_lower, load, modulus)


@dataclass(frozen=True)
class SphereOnFlat:
    """A sphere of ``radius`` (m, the upper body) on a flat lower body. Point contact."""

    radius: float = SEED_RADIUS
    name = "sphere_on_flat"
    contact: ClassVar[Contact] = "point"

    def __post_init__(self) -> None:
        _positive("radius", self.radius)

    def recessions(self) -> tuple[Recession, Recession]:
        """(upper, lower) recessions, m."""
        return sphere(self.radius), flat()

    def contact_size(self, load: float, modulus: float) -> tuple[float, float]:
        """Hertz radius (a, a), m."""
        a = HertzSphere(self.radius, load, modulus).contact_radius
        return a, a


@dataclass(frozen=True)
class CylinderOnFlat:
    """A cylinder of ``radius`` (m, the upper body) with its axis along y on a flat: a line
    contact, periodic along y (an infinitely long cylinder, plane strain); the stroke (x)
    is across the axis."""

    radius: float = SEED_RADIUS
    name = "cylinder_on_flat"
    contact: ClassVar[Contact] = "line"

    def __post_init__(self) -> None:
        _positive("radius", self.radius)

    def recessions(self) -> tuple[Recession, Recession]:
        """(upper, lower) recessions, m."""
        return cylinder(2 * self.radius, axis="y"), flat()

    def hertz(self, load_per_length: float, modulus: float) -> HertzCylinder:
        """Hertz line contact under P' (N/m) and E* (Pa)."""
        return HertzCylinder(self.radius, load_per_length, modulus)


@dataclass(frozen=True)
class FlatPunch:
    """An axisymmetric flat punch (the upper body) with a flat face of radius
    ``punch_radius`` (m) and rounded edges of radius ``edge_radius`` (m) on a flat. Point
    contact (the contact radius a > punch_radius grows with the load)."""

    punch_radius: float = 0.25e-3
    edge_radius: float = SEED_RADIUS
    name = "flat_punch"
    contact: ClassVar[Contact] = "point"

    def __post_init__(self) -> None:
        _positive("punch_radius", self.punch_radius)
        _positive("edge_radius", self.edge_radius)

    def recessions(self) -> tuple[Recession, Recession]:
        """(upper, lower) recessions, m."""
        return rounded_punch(self.punch_radius, self.edge_radius), flat()

    def contact_size(self, load: float, modulus: float) -> tuple[float, float]:
        """Contact radius (a, a), m (:func:`punch_contact_radius`)."""
        a = punch_contact_radius(self.punch_radius, self.edge_radius, load, modulus)
        return a, a


@dataclass(frozen=True)
class HeightMaps:
    """Measured or made surfaces: a :class:`HeightMap` recession for either body (None: a
    flat). The contact type is found from the maps (y-independent: a line contact)."""

    upper: HeightMap | None = None
    lower: HeightMap | None = None
    name = "height_map"

    def __post_init__(self) -> None:
        if self.upper is None and self.lower is None:
            raise ValueError("height_map needs upper_map or lower_map (or both)")

    def recessions(self) -> tuple[Recession, Recession]:
        """(upper, lower) recessions, m."""
        return (self.upper if self.upper is not None else flat(),
                self.lower if self.lower is not None else flat())


def heights_to_recession(z: ArrayLike, body: str) -> NDArray[np.float64]:
    """Recession (m) of a body from its surface heights ``z`` (m, lab frame, +z from the
    lower body towards the upper one): upper ``z - min z``, lower ``max z - z``."""
    v = np.asarray(z, dtype=float)
    if body not in ("upper", "lower"):
        raise ValueError(f"body = {body!r} is not allowed: use 'upper' or 'lower'")
    if v.ndim != 2 or min(v.shape) < 2:
        raise ValueError(f"has shape {v.shape}: a height map must be a 2-D grid with >= 2 "
                         "points per side (rows along x, columns along y)")
    bad = ~np.isfinite(v)
    if bad.any():
        i, j = np.argwhere(bad)[0]
        raise ValueError(f"has {int(bad.sum())} non-finite value(s) (first: {v[i, j]!r} at "
                         f"row {i}, column {j}): all heights must be finite (m)")
    return v - v.min() if body == "upper" else v.max() - v


def load_height_map(path: str | Path, body: str, dx: float | None = None) -> HeightMap:
    """Read a body's surface heights (m, lab frame: +z towards the upper body) and return its
    recession as a :class:`HeightMap` centred on the window origin.

    ``.csv``/``.txt`` (comma separated) and ``.npy``: a grid ``z[i, j]`` at
    ``(i dx, j dx)`` (rows along x, the stroke), ``dx`` (m) required. ``.stl``
    (:func:`tribodem.io.stl.read_stl`): a height-field triangulation, sampled linearly on a
    grid of spacing ``dx`` (default: the median spacing of its distinct x coordinates).
    ``ValueError`` (saying what is wrong) for an unreadable file, NaN, a wrong shape.
    """
    p = Path(path)
    suffix = p.suffix.lower()
    if not p.is_file():
        raise ValueError("no such file")
    if suffix == ".stl":
        from tribodem.io.stl import read_stl  # noqa: PLC0415 - only for STL maps

        tri = read_stl(p)
        pts = np.unique(tri.reshape(-1, 3), axis=0)
        if pts.shape[0] < 4 or not np.all(np.isfinite(pts)):
            raise ValueError(f"STL with {pts.shape[0]} distinct vertices (or non-finite "
                             "ones): not a height field")
        if dx is None:
            xs = np.unique(pts[:, 0])
            dx = float(np.median(np.diff(xs))) if xs.size > 1 else 0.0
        step = _positive("map_dx", dx)
        (x0, y0), (x1, y1) = pts[:, :2].min(0), pts[:, :2].max(0)
        nx, ny = int(round((x1 - x0) / step)) + 1, int(round((y1 - y0) / step)) + 1
        if min(nx, ny) < 2:
            raise ValueError(f"STL spans {x1 - x0:.4g} x {y1 - y0:.4g} m: less than two "
                             f"points of map_dx {step:.4g} m per side")
        gx, gy = np.meshgrid(x0 + step * np.arange(nx), y0 + step * np.arange(ny),
                             indexing="ij")
        from scipy.interpolate import LinearNDInterpolator  # here: 0.6 s to import

        z = LinearNDInterpolator(pts[:, :2], pts[:, 2])(np.clip(gx, x0, x1),
                                                         np.clip(gy, y0, y1))
        if not np.all(np.isfinite(z)):
            raise ValueError("STL is not a height field over its bounding rectangle "
                             "(holes or a non-rectangular outline)")
    elif suffix in (".csv", ".txt", ".npy"):
        if dx is None:
            raise ValueError("a CSV or NPY height map needs map_dx (grid spacing, m)")
        step = _positive("map_dx", dx)
        try:
            z = (np.load(p, allow_pickle=False) if suffix == ".npy"
                 else np.loadtxt(p, delimiter=",", ndmin=2))
        except (OSError, ValueError) as err:
            raise ValueError(f"cannot be read: {err}") from None
    else:
        raise ValueError(f"unknown format {suffix!r}: allowed .csv, .txt, .npy, .stl")
    return HeightMap.centred(heights_to_recession(z, body), step)


#: A fretting case's geometry (``[contact] geometry``).
Geometry = CrossedCylinders | SphereOnFlat | CylinderOnFlat | FlatPunch | HeightMaps

#: The geometries by their config name; each default is the dataclass's field default.
GEOMETRIES: dict[str, type[Geometry]] = {
    g.name: g for g in (CrossedCylinders, SphereOnFlat, CylinderOnFlat, FlatPunch, HeightMaps)
}
