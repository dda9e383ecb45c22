"""First-body surface geometries as recession maps (seed 003 section 3.3.1, figure 3.4).

A surface is described by its *recession* ``g(x, y)`` (m): the distance from the body's
surface to the common tangent plane at the initial contact point, positive away from the
other body. The gap at rigid approach zero is ``g_upper(x - offset, y) + g_lower(x, y)``
(upper body displaced by ``offset`` along x); wear adds the worn depth to the recession.

A surface is either a callable ``g(x, y)`` on arrays (m -> m) or a :class:`HeightMap`
sampled on a regular grid (linear interpolation); a 1-D profile extruded along one axis
is made with :func:`extruded_profile`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.interpolate import RegularGridInterpolator

from tribodem.contact.base import Recession  # noqa: E402 - one definition, in the contract


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
        interp = RegularGridInterpolator(
            (self.x0 + self.dx * np.arange(nx), self.y0 + self.dy * np.arange(ny)),
            self.values,
            bounds_error=False,
            fill_value=None,
        )
        pts = np.stack([np.clip(x, xmin, xmax), np.clip(y, ymin, ymax)], axis=-1)
        return interp(pts)


def cylinder(diameter: float = 8e-3, axis: str = "x", exact: bool = True) -> Recession:
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


def crossed_cylinders(diameter: float = 8e-3, exact: bool = True) -> tuple[Recession, Recession]:
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
