"""Material evolution criteria as plug-ins (seed 003 table 3.3, chapter 6; eq 2.6).

Each criterion turns one simulated fretting cycle into a wear depth map (m) per body:
the upper body's spot grid ``[n, n]`` and the lower body's track grid ``[n_track, n]``
(the grids of :class:`tribodem.contact.FrettingCycle`). The wear loop streams every
increment of the cycle to the criterion (``add_increment``) and asks for the depths at
the end (``depths``).

Two kinds:

* **rate** criteria give a depth per cycle directly: ``energy`` (Fouvry, dh = alpha e,
  e the dissipated energy density of the cycle, J/m^2, alpha m^3/J) and ``archard``
  (local Archard, eq 2.6: dh = k p |ds| summed over the increments, k in 1/Pa).
* **threshold** criteria evaluate a stress field on the subsurface grid under each body,
  keep at every material point its maximum over the sampled increments of the cycle
  (seed figure 6.3: "maximum nodal von Mises stress over a whole cycle"), and remove the
  material above the depth where the field falls below the threshold, found by the column
  search with linear interpolation (section 6.3, figure 6.4; :func:`column_search`):
  ``s22`` (|sigma_zz| >= yield), ``von_mises`` (>= yield), ``shear`` (in-plane shear
  D = tau / (0.8 UTS) >= 1, eq 6.9, tau = sqrt(sigma_xz^2 + sigma_yz^2) on planes parallel
  to the surface). ``dfdi`` (eqs 6.1-6.2) needs plastic strain and ``swt`` (eqs 6.3-6.8)
  a Miner sum per material point: both are registered and refuse to run with a message
  naming what is missing.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from tribodem.contact.base import FirstBodySolver, IncrementResult, SubsurfaceStress

#: Fouvry energy wear coefficient of the seed (section 5.2), 1.641e-6 mm^3/J, in m^3/J.
ALPHA_SEED = 1.641e-6 * 1e-9
#: EN24T yield and ultimate tensile strength (seed table 5.1), Pa.
YIELD_EN24T = 680e6
UTS_EN24T = 1000e6


class CriterionUnavailable(ValueError):
    """A registered criterion that cannot run with the chosen solver or options."""


@dataclass
class TrackGrid:
    """The two wear grids of a cycle and the window-to-track mapping.

    Upper body: the solver window itself (``x_upper`` = window coordinates). Lower body:
    ``n + 2 pad`` x-points; window point ``i`` at offset ``s`` sits on track point
    ``pad + i + s / dx`` (between two track points when ``s / dx`` is not an integer).
    """

    n: int
    dx: float
    pad: int

    @property
    def n_track(self) -> int:
        return self.n + 2 * self.pad

    @property
    def x_upper(self) -> NDArray[np.float64]:
        return (np.arange(self.n) - self.n // 2) * self.dx

    @property
    def x_lower(self) -> NDArray[np.float64]:
        return (np.arange(self.n_track) - self.n // 2 - self.pad) * self.dx

    @property
    def y(self) -> NDArray[np.float64]:
        return self.x_upper

    @property
    def cell_area(self) -> float:
        return self.dx * self.dx

    def deposit(self, track: NDArray[np.float64], field: NDArray[np.float64],
                inc: IncrementResult) -> None:
        """Add a window field ``[..., n, n]`` onto ``track`` ``[..., n_track, n]`` at the
        increment's mid position, split linearly between the two neighbouring shifts
        (conservative; same rule as :class:`FrettingCycle`)."""
        shift = 0.5 * (inc.offset + inc.start_offset) / self.dx
        k = int(math.floor(shift))
        w = shift - k
        j0 = self.pad + k
        n = self.n
        track[..., j0 : j0 + n, :] += (1.0 - w) * field
        if w > 0.0:
            track[..., j0 + 1 : j0 + 1 + n, :] += w * field

    def fold_max(self, track: NDArray[np.float64], field: NDArray[np.float64],
                 offset: float) -> None:
        """Pointwise maximum of a window field ``[..., n, n]`` into ``track`` at the nearest
        track shift to ``offset`` (m) (position error <= dx / 2)."""
        j0 = self.pad + int(round(offset / self.dx))
        sl = track[..., j0 : j0 + self.n, :]
        np.maximum(sl, field, out=sl)


def column_search(
    values: NDArray[np.float64], z: NDArray[np.float64], threshold: float
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Wear depth per column by the column search of seed section 6.3 / figure 6.4.

    ``values`` is ``[nz, ...]`` on depths ``z`` (m, increasing from 0 = surface). Going
    down each column from the surface, the depth is where the value, having reached
    ``threshold`` at or above that level, falls below it for the first time; between two
    levels k, k+1 it is ``z_k + (v_k - T) / (v_k - v_{k+1}) (z_{k+1} - z_k)`` (linear
    interpolation). A column that never reaches ``T`` has depth 0. A column still at or
    above ``T`` at the bottom gets ``z[-1]`` and is flagged in the returned mask
    (the grid is too shallow). Returns ``(depth m, saturated mask)`` of shape ``[...]``.
    """
    v = np.asarray(values, dtype=float)
    z = np.asarray(z, dtype=float)
    if v.ndim < 1 or v.shape[0] != z.shape[0] or z.shape[0] < 2:
        raise ValueError(f"values {v.shape} and z {z.shape} must share a first axis of >= 2")
    if np.any(np.diff(z) <= 0):
        raise ValueError("z must be strictly increasing (depth below the surface, m)")
    if not math.isfinite(threshold):
        raise ValueError(f"threshold = {threshold!r} must be finite")
    nz = v.shape[0]
    flat = v.reshape(nz, -1)
    ex = flat >= threshold
    reached = ex.any(axis=0)
    first = np.argmax(ex, axis=0)
    levels = np.arange(nz)[:, None]
    below = (~ex) & (levels > first[None, :])
    has_end = below.any(axis=0)
    k1 = np.argmax(below, axis=0)
    k0 = np.maximum(k1 - 1, 0)
    cols = np.arange(flat.shape[1])
    v0, v1 = flat[k0, cols], flat[k1, cols]
    with np.errstate(divide="ignore", invalid="ignore"):
        frac = np.where(v0 > v1, (v0 - threshold) / (v0 - v1), 0.0)
    depth = z[k0] + np.clip(frac, 0.0, 1.0) * (z[k1] - z[k0])
    saturated = reached & ~has_end
    depth = np.where(saturated, z[-1], np.where(reached & has_end, depth, 0.0))
    shape = v.shape[1:]
    return depth.reshape(shape), saturated.reshape(shape)


class Criterion(ABC):
    """One material evolution criterion (plug-in). Subclasses register by ``name``."""

    name: ClassVar[str] = "base"
    kind: ClassVar[str] = "rate"  #: "rate" or "threshold"

    def begin_cycle(self, grid: TrackGrid, solver: FirstBodySolver) -> None:
        """Reset the per-cycle accumulators."""
        self.grid = grid
        self.solver = solver

    @abstractmethod
    def add_increment(self, index: int, inc: IncrementResult) -> None:
        """Stream one solved increment (``index`` 0-based within the cycle's slide)."""

    @abstractmethod
    def depths(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Wear depth of this cycle (m): (upper ``[n, n]``, lower ``[n_track, n]``)."""

    def params(self) -> dict[str, Any]:
        """Parameters for reports."""
        return {}

    def info(self) -> dict[str, Any]:
        """Diagnostics of the last cycle (for reports)."""
        return {}


class EnergyCriterion(Criterion):
    """Fouvry's energy law per surface point: dh = alpha e (m), e in J/m^2 (seed eq 2.7).

    Each body loses ``alpha`` times the interface energy dissipated on it (the density is
    the same on both bodies), so each body's worn volume is alpha times the dissipated
    energy. ``alpha`` in m^3/J (default 1.641e-6 mm^3/J, seed section 5.2).
    """

    name = "energy"

    def __init__(self, alpha: float = ALPHA_SEED) -> None:
        if not (math.isfinite(alpha) and alpha >= 0):
            raise ValueError(f"alpha = {alpha!r} is not allowed: must be finite and >= 0 m^3/J")
        self.alpha = float(alpha)

    def begin_cycle(self, grid: TrackGrid, solver: FirstBodySolver) -> None:
        super().begin_cycle(grid, solver)
        self._up = np.zeros((grid.n, grid.n))
        self._lo = np.zeros((grid.n_track, grid.n))

    def add_increment(self, index: int, inc: IncrementResult) -> None:
        e = inc.energy_density
        self._up += e
        self.grid.deposit(self._lo, e, inc)

    def depths(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        return self.alpha * self._up, self.alpha * self._lo

    def params(self) -> dict[str, Any]:
        return {"alpha_m3_per_J": self.alpha}


class ArchardCriterion(Criterion):
    """Local Archard law (seed eq 2.6): dh = k p |ds| per increment, k in 1/Pa (m^2/N).

    Default k = alpha mu (1.641e-6 mm^3/J x 0.6): the same wear as ``energy`` in gross slip.
    """

    name = "archard"

    def __init__(self, k: float = ALPHA_SEED * 0.6) -> None:
        if not (math.isfinite(k) and k >= 0):
            raise ValueError(f"k = {k!r} is not allowed: must be finite and >= 0 (1/Pa)")
        self.k = float(k)

    def begin_cycle(self, grid: TrackGrid, solver: FirstBodySolver) -> None:
        super().begin_cycle(grid, solver)
        self._up = np.zeros((grid.n, grid.n))
        self._lo = np.zeros((grid.n_track, grid.n))

    def add_increment(self, index: int, inc: IncrementResult) -> None:
        ps = inc.pressure * np.hypot(inc.slip[..., 0], inc.slip[..., 1])
        self._up += ps
        self.grid.deposit(self._lo, ps, inc)

    def depths(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        return self.k * self._up, self.k * self._lo

    def params(self) -> dict[str, Any]:
        return {"k_per_Pa": self.k}


class ThresholdCriterion(Criterion):
    """Stress-threshold criterion with the column search (seed section 6.3, figure 6.4).

    The field is evaluated under both bodies at ``samples`` increments spread evenly over
    the cycle's slide (the last increment of each of ``samples`` equal segments; with the
    default 8 of 48 increments: +-A/2, +-A and the two passes through 0, both directions),
    on ``nz`` levels down to ``depth`` (m; None: 3 equivalent contact radii sqrt(area/pi)
    of the first sampled increment of the run, then fixed). The per-point maximum over the
    samples (upper: window points; lower: the track, at the nearest shift) goes through
    :func:`column_search`.
    """

    kind = "threshold"
    unit: ClassVar[str] = "Pa"

    def __init__(self, threshold: float, depth: float | None = None, nz: int = 33,
                 samples: int = 8) -> None:
        if not (math.isfinite(threshold) and threshold > 0):
            raise ValueError(f"threshold = {threshold!r} is not allowed: must be > 0")
        if depth is not None and not (math.isfinite(depth) and depth > 0):
            raise ValueError(f"depth = {depth!r} is not allowed: must be > 0 m (or None)")
        if int(nz) != nz or nz < 2:
            raise ValueError(f"nz = {nz!r} is not allowed: must be an integer >= 2")
        if int(samples) != samples or samples < 1:
            raise ValueError(f"samples = {samples!r} is not allowed: must be an integer >= 1")
        self.threshold = float(threshold)
        self.depth = depth
        self.nz = int(nz)
        self.samples = int(samples)
        self._n_increments = 0
        self._last_info: dict[str, Any] = {}

    def set_increments(self, n_increments: int) -> None:
        """Tell the criterion how many sliding increments a cycle has."""
        if self.samples > n_increments:
            raise ValueError(
                f"samples = {self.samples} is not allowed: at most n_increments = {n_increments}"
            )
        self._n_increments = int(n_increments)

    def sample_indices(self) -> set[int]:
        n, m = self._n_increments, self.samples
        return {(k + 1) * n // m - 1 for k in range(m)}

    @abstractmethod
    def field(self, st: SubsurfaceStress) -> NDArray[np.float64]:
        """Criterion value on the subsurface grid ``[nz, n, n]`` (compared to threshold)."""

    def begin_cycle(self, grid: TrackGrid, solver: FirstBodySolver) -> None:
        super().begin_cycle(grid, solver)
        if self._n_increments == 0:
            raise RuntimeError("set_increments() must be called before the first cycle")
        self._idx = self.sample_indices()
        self._up = np.full((self.nz, grid.n, grid.n), -np.inf)
        self._lo = np.full((self.nz, grid.n_track, grid.n), -np.inf)
        self._z: NDArray[np.float64] | None = None

    def _depth_for(self, inc: IncrementResult) -> float:
        # None: 3 equivalent contact radii of the first sampled increment of the run,
        # then kept for every later cycle (the grid must not shrink with the contact)
        if self.depth is None:
            self.depth = 3.0 * math.sqrt(max(inc.contact_area, self.grid.dx**2) / math.pi)
        return self.depth

    def add_increment(self, index: int, inc: IncrementResult) -> None:
        if index not in self._idx:
            return
        depth = self._depth_for(inc)
        for body in ("upper", "lower"):
            st = self.solver.subsurface_stress(inc, body, depth=depth, nz=self.nz)
            self._z = st.z
            f = self.field(st)
            if body == "upper":
                np.maximum(self._up, f, out=self._up)
            else:
                self.grid.fold_max(self._lo, f, inc.offset)

    def depths(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        assert self._z is not None, "no sampled increment in this cycle"
        du, su = column_search(self._up, self._z, self.threshold)
        dl, sl = column_search(self._lo, self._z, self.threshold)
        self._last_info = {
            "grid_depth_m": float(self._z[-1]),
            "max_value_upper": float(self._up.max()),
            "max_value_lower": float(self._lo.max()),
            "saturated_columns_upper": int(su.sum()),
            "saturated_columns_lower": int(sl.sum()),
        }
        return du, dl

    def info(self) -> dict[str, Any]:
        return dict(self._last_info)

    def params(self) -> dict[str, Any]:
        return {"threshold": self.threshold, "unit": self.unit, "depth_m": self.depth,
                "nz": self.nz, "samples": self.samples}


class VonMisesCriterion(ThresholdCriterion):
    """von Mises stress >= yield (seed section 6.3); threshold Pa, default 680 MPa."""

    name = "von_mises"

    def __init__(self, yield_strength: float = YIELD_EN24T, **kw: Any) -> None:
        super().__init__(yield_strength, **kw)

    def field(self, st: SubsurfaceStress) -> NDArray[np.float64]:
        return st.von_mises


class S22Criterion(ThresholdCriterion):
    """Internal vertical stress |sigma_zz| >= yield (seed section 6.4, "S22"), Pa.

    The magnitude is used: under contact sigma_zz is compressive (about -p at the surface);
    the seed's "maximal S22 ... 1400 MPa" is a magnitude.
    """

    name = "s22"

    def __init__(self, yield_strength: float = YIELD_EN24T, **kw: Any) -> None:
        super().__init__(yield_strength, **kw)

    def field(self, st: SubsurfaceStress) -> NDArray[np.float64]:
        return np.abs(st.stress[..., 2])


class ShearCriterion(ThresholdCriterion):
    """In-plane shear damage D = tau / (0.8 UTS) >= 1 (seed eq 6.9, section 6.7).

    tau = sqrt(sigma_xz^2 + sigma_yz^2): the shear on planes parallel to the contact
    (the seed's tau_xy with y normal to the surface); S_us = 0.8 UTS, UTS default 1000 MPa.
    """

    name = "shear"
    unit = "-"

    def __init__(self, uts: float = UTS_EN24T, **kw: Any) -> None:
        if not (math.isfinite(uts) and uts > 0):
            raise ValueError(f"uts = {uts!r} is not allowed: must be > 0 Pa")
        self.uts = float(uts)
        super().__init__(1.0, **kw)

    def field(self, st: SubsurfaceStress) -> NDArray[np.float64]:
        tau = np.hypot(st.stress[..., 4], st.stress[..., 3])
        return tau / (0.8 * self.uts)

    def params(self) -> dict[str, Any]:
        return {**super().params(), "uts_Pa": self.uts}


class _Unavailable(Criterion):
    reason: ClassVar[str] = ""

    def __init__(self, **kw: Any) -> None:
        raise CriterionUnavailable(f"criterion '{self.name}' cannot run: {self.reason}")

    def add_increment(self, index: int, inc: IncrementResult) -> None:  # pragma: no cover
        raise NotImplementedError

    def depths(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:  # pragma: no cover
        raise NotImplementedError


class DFDICriterion(_Unavailable):
    """Ductile failure damage indicator (seed eqs 6.1-6.2): needs plastic strain."""

    name = "dfdi"
    kind = "threshold"
    reason = ("it needs the equivalent plastic strain (eqs 6.1-6.2), which only an "
              "elastic-plastic first-body solver provides; the elastic-plastic solver "
              "(tamaas EPICSolver) is not implemented yet")


class SWTCriterion(_Unavailable):
    """Smith-Watson-Topper critical plane with Miner's sum (seed eqs 6.3-6.8)."""

    name = "swt"
    kind = "threshold"
    reason = ("the SWT critical-plane criterion (eqs 6.3-6.8: 5 deg planes, Miner sum per "
              "material point, table 6.2 constants) is not implemented yet")


CRITERIA: dict[str, type[Criterion]] = {
    "energy": EnergyCriterion,
    "archard": ArchardCriterion,
    "s22": S22Criterion,
    "von_mises": VonMisesCriterion,
    "shear": ShearCriterion,
    "dfdi": DFDICriterion,
    "swt": SWTCriterion,
}


def make_criterion(name: str, **params: Any) -> Criterion:
    """Build a criterion by name (``CRITERIA``); unknown names raise ``ValueError``."""
    try:
        cls = CRITERIA[name]
    except KeyError:
        raise ValueError(
            f"unknown criterion {name!r}; allowed: {', '.join(CRITERIA)}"
        ) from None
    return cls(**params)
