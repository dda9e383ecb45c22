"""First-body solver interface and the fretting-cycle driver (seed 003, sections 3.3, 6.1).

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
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from numpy.typing import NDArray

Body = Literal["upper", "lower"]
BODIES: tuple[Body, ...] = ("upper", "lower")

#: Voigt order of the stress components returned by :class:`SubsurfaceStress`.
VOIGT_ORDER = ("xx", "yy", "zz", "yz", "xz", "xy")


def _check_positive(name: str, value: float, allow_zero: bool = False) -> float:
    v = float(value)
    ok = v >= 0.0 if allow_zero else v > 0.0
    if not math.isfinite(v) or not ok:
        rule = ">= 0" if allow_zero else "> 0"
        raise ValueError(f"{name} = {value!r} is not allowed: must be finite and {rule}")
    return v


@dataclass(frozen=True)
class ElasticBody:
    """Isotropic elastic first body; defaults are EN24T (seed table 5.1: E 240 GPa, nu 0.3)."""

    young: float = 240e9  #: Young's modulus, Pa
    poisson: float = 0.3  #: Poisson's ratio, -

    def __post_init__(self) -> None:
        _check_positive("young", self.young)
        if not (-1.0 < float(self.poisson) < 0.5):
            raise ValueError(f"poisson = {self.poisson!r} is not allowed: must be in (-1, 0.5)")

    @property
    def shear(self) -> float:
        """Shear modulus G = E / (2 (1 + nu)), Pa."""
        return self.young / (2.0 * (1.0 + self.poisson))


def contact_modulus(a: ElasticBody, b: ElasticBody) -> float:
    """Hertz contact modulus E* = 1 / ((1 - nu1^2)/E1 + (1 - nu2^2)/E2), Pa."""
    return 1.0 / ((1 - a.poisson**2) / a.young + (1 - b.poisson**2) / b.young)


def dundurs_beta(a: ElasticBody, b: ElasticBody) -> float:
    """Dundurs' second constant (0 for elastically similar bodies: no normal-shear coupling)."""
    k1 = (1 - 2 * a.poisson) / a.shear - (1 - 2 * b.poisson) / b.shear
    k2 = (1 - a.poisson) / a.shear + (1 - b.poisson) / b.shear
    return 0.5 * k1 / k2


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


class FirstBodySolver(ABC):
    """One first-body contact solver (DESIGN.md: backend 1 half-space, backend 2 FE).

    A solver owns the two surfaces, the materials, the normal load and its grid; a driver
    asks it for one increment of relative tangential position at a time, in path order (the
    solver may keep load history between calls).
    """

    #: window grid spacing (m) and number of points per side
    dx: float
    n: int

    @property
    def window(self) -> float:
        """Side of the square periodic solution window, m."""
        return self.dx * self.n

    @property
    def coords(self) -> NDArray[np.float64]:
        """Window point coordinates along x or y relative to the window centre, m."""
        return (np.arange(self.n) - self.n // 2) * self.dx

    @abstractmethod
    def reset(self) -> None:
        """Forget the load history (start a new loading from the unloaded state)."""

    @abstractmethod
    def solve_increment(self, offset: float) -> IncrementResult:
        """Move the upper body to ``offset`` (m) from the previous position and solve."""

    @abstractmethod
    def subsurface_stress(
        self, result: IncrementResult, body: Body, depth: float, nz: int
    ) -> SubsurfaceStress:
        """Stress under ``body`` (0 <= z <= depth, m, ``nz`` levels) for a solved increment."""


def cycle_offsets(amplitude: float, n_increments: int) -> NDArray[np.float64]:
    """Positions ending each increment of one cycle 0 -> +A -> 0 -> -A -> 0, m.

    ``n_increments`` must be a positive multiple of 4 (equal steps of 4 A / n).
    """
    _check_positive("amplitude", amplitude)
    if int(n_increments) != n_increments or n_increments < 4 or n_increments % 4:
        raise ValueError(
            f"n_increments = {n_increments!r} is not allowed: must be a multiple of 4, >= 4"
        )
    q = int(n_increments) // 4
    up = np.arange(1, q + 1) / q
    return amplitude * np.concatenate([up, 1 - up, -up, -1 + up])


@dataclass
class CycleResult:
    """Accumulated results of one or more fretting cycles."""

    x_upper: NDArray[np.float64]  #: upper-body grid x (own frame), m, [n]
    x_lower: NDArray[np.float64]  #: lower-body track grid x (lab frame), m, [n_track]
    y: NDArray[np.float64]  #: y coordinates shared by both grids, m, [n]
    energy_upper: NDArray[np.float64]  #: dissipated energy density, J/m^2, [n, n]
    energy_lower: NDArray[np.float64]  #: dissipated energy density, J/m^2, [n_track, n]
    increments: list[IncrementResult] = field(default_factory=list)
    cycles: int = 0

    @property
    def cell_area(self) -> float:
        """Area of one grid cell, m^2."""
        return float((self.x_upper[1] - self.x_upper[0]) * (self.y[1] - self.y[0]))

    def dissipated_energy(self, body: Body) -> float:
        """Total energy dissipated on ``body`` (integral of its density map), J."""
        if body not in BODIES:
            raise ValueError(f"body = {body!r} is not allowed: use 'upper' or 'lower'")
        e = self.energy_upper if body == "upper" else self.energy_lower
        return float(e.sum() * self.cell_area)


class FrettingCycle:
    """Drive a solver through fretting cycles and accumulate energy maps on both bodies.

    The upper body's map is the window itself (fixed material points); the lower body's
    map is a track of ``n + 2 K`` x-points (``K = ceil(A / dx) + 1``) covering every window
    position; each increment's density is deposited on it at the window's lab position
    with linear interpolation between the two neighbouring grid shifts (conservative).
    """

    def __init__(
        self,
        solver: FirstBodySolver,
        amplitude: float = 0.3e-3,
        n_increments: int = 48,
        keep_increments: bool = False,
    ) -> None:
        self.solver = solver
        self.amplitude = _check_positive("amplitude", amplitude)
        self.offsets = cycle_offsets(amplitude, n_increments)
        self.keep_increments = keep_increments
        self.pad = int(math.ceil(self.amplitude / solver.dx)) + 1
        n = solver.n
        self.x_upper = solver.coords
        self.x_lower = (np.arange(n + 2 * self.pad) - n // 2 - self.pad) * solver.dx
        self.y = solver.coords.copy()
        self._loaded = False
        self.result = CycleResult(
            x_upper=self.x_upper,
            x_lower=self.x_lower,
            y=self.y,
            energy_upper=np.zeros((n, n)),
            energy_lower=np.zeros((n + 2 * self.pad, n)),
        )

    def _deposit(self, inc: IncrementResult) -> None:
        e = inc.energy_density
        n = self.solver.n
        self.result.energy_upper += e
        # deposited at the increment's mid position (midpoint rule along the track)
        shift = 0.5 * (inc.offset + inc.start_offset) / self.solver.dx
        k = int(math.floor(shift))
        w = shift - k
        j0 = self.pad + k
        self.result.energy_lower[j0 : j0 + n] += (1.0 - w) * e
        if w > 0.0:
            self.result.energy_lower[j0 + 1 : j0 + 1 + n] += w * e

    def load(self) -> IncrementResult:
        """Apply the normal load at offset 0 (no sliding, no dissipation)."""
        self.solver.reset()
        inc = self.solver.solve_increment(0.0)
        self._loaded = True
        if self.keep_increments:
            self.result.increments.append(inc)
        return inc

    def run(self, n_cycles: int = 1) -> CycleResult:
        """Run ``n_cycles`` cycles (loading first if needed); returns the accumulated maps."""
        if int(n_cycles) != n_cycles or n_cycles < 1:
            raise ValueError(f"n_cycles = {n_cycles!r} is not allowed: must be an integer >= 1")
        if not self._loaded:
            self.load()
        for _ in range(int(n_cycles)):
            for s in self.offsets:
                inc = self.solver.solve_increment(float(s))
                self._deposit(inc)
                if self.keep_increments:
                    self.result.increments.append(inc)
            self.result.cycles += 1
        return self.result
