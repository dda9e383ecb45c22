"""Material evolution criteria as plug-ins (Lu (2018) table 3.3, chapter 6; eq 2.6).

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
  to the surface). ``dfdi`` (eqs 6.1-6.2, DFDI >= 1, needs the elastic-plastic solver's
  plastic strain; refused with an elastic one) and ``swt`` (eqs 6.3-6.8, critical plane
  SWT, Miner sum D >= 1) accumulate damage per material point across cycles.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numba import njit, prange
from numpy.typing import NDArray

from tribodem.contact.base import FirstBodySolver, IncrementResult, SubsurfaceStress, require
from tribodem.materials.en24t import EN24T

#: Fouvry energy wear coefficient of the seed (section 5.2), 1.641e-6 mm^3/J, in m^3/J.
ALPHA_SEED = EN24T.energy_wear_coefficient
#: EN24T yield and ultimate tensile strength (seed table 5.1), Pa.
YIELD_EN24T = EN24T.yield_strength
UTS_EN24T = EN24T.uts


class CriterionUnavailable(ValueError):
    """A registered criterion that cannot run with the chosen solver or options."""


@dataclass
class TrackGrid:
    """The two wear grids of a cycle and the window-to-track mapping.

    Upper body: the solver window itself (``x_upper`` = window coordinates). Lower body:
    ``n + 2 pad`` x-points; window point ``i`` at offset ``s`` sits on track point
    ``pad + i + s / dx`` (between two track points when ``s / dx`` is not an integer).
    Along y both grids have the window's ``ny`` points of extent ``dy`` (left out: ``n``
    and ``dx``, a square window; a line contact solved on one cross-section: 1 point that
    stands for the window's side).
    """

    n: int
    dx: float
    pad: int
    ny: int = 0  #: points along y (0: ``n``)
    dy: float = 0.0  #: extent of a point along y, m (0: ``dx``)

    def __post_init__(self) -> None:
        if self.ny <= 0:
            self.ny = self.n
        if self.dy <= 0.0:
            self.dy = self.dx

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
        """Coordinates of the points along y, m (0 for a single cross-section)."""
        return (np.arange(self.ny) - self.ny // 2) * self.dy if self.ny > 1 else np.zeros(1)

    @property
    def cell_area(self) -> float:
        """Surface area one grid point stands for, m^2 (``dx dy``)."""
        return self.dx * self.dy

    @property
    def upper_shape(self) -> tuple[int, int]:
        """Shape of a field on the upper body's grid (the window): ``(n, ny)``."""
        return self.n, self.ny

    @property
    def lower_shape(self) -> tuple[int, int]:
        """Shape of a field on the lower body's track: ``(n_track, ny)``."""
        return self.n_track, self.ny

    def deposit(self, track: NDArray[np.float64], field: NDArray[np.float64],
                inc: IncrementResult) -> None:
        """Add a window field ``[..., n, n]`` onto ``track`` ``[..., n_track, n]`` at the
        position where it was solved, the increment's end offset ``s`` (m), split linearly
        between the two neighbouring track shifts ``floor(s / dx)`` and the next
        (conservative: the sum is kept).

        The increment's field (e.g. pressure x slip) is the integrand of the wear over the
        slide sampled at ``s``: each sample belongs on the lower body where the contact was
        when it was solved (the quadrature of wear = sum over samples of field(x - s_k)).
        The split is the transpose of the linear interpolation through which the solver
        sees the lower body's worn surface at ``s``, so a wear feature is fed back onto
        itself (a stable, self-levelling response). Deposited anywhere else (the
        increment's mid position, half a step away) the feedback of a two-grid-point
        ripple changes sign and the ripple grows into a saw-tooth whenever the step is not
        a whole number of grid points (docs/fretting.md, "Sampling of the stroke")."""
        shift = inc.offset / self.dx
        k = int(math.floor(shift))
        w = shift - k
        j0 = self.pad + k
        n = self.n
        track[..., j0 : j0 + n, :] += (1.0 - w) * field
        if w > 0.0:
            track[..., j0 + 1 : j0 + 1 + n, :] += w * field

    def fold_max(self, track: NDArray[np.float64], field: NDArray[np.float64],
                 offset: float, slide: tuple[float, float] | None = None,
                 prev: tuple[float, NDArray[np.float64]] | None = None) -> None:
        """Pointwise maximum of a window field ``[..., n, n]`` (sampled at ``offset``, m)
        into ``track`` at the nearest track shift (position error <= dx / 2), and with
        ``slide`` (lo, hi, m) at every shift from lo to hi: there the field linearly
        interpolated by position between ``prev`` (an earlier sample's offset and field)
        and this one, beyond both the nearer one's (no ``prev``: this field throughout)."""
        lo, hi = (offset, offset) if slide is None else slide
        s0 = offset if prev is None else prev[0]
        ja = self.pad + int(round(min(lo, s0, offset) / self.dx))
        jb = self.pad + int(round(max(hi, s0, offset) / self.dx))
        span = offset - s0
        for j0 in range(ja, jb + 1):
            sl = track[..., j0 : j0 + self.n, :]
            if prev is None:
                np.maximum(sl, field, out=sl)
                continue
            t = 0.5 if span == 0.0 else ((j0 - self.pad) * self.dx - s0) / span
            t = min(1.0, max(0.0, t))
            np.maximum(sl, prev[1] + t * (field - prev[1]), out=sl)


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


def _check_stress_grid(depth: float | None, nz: int) -> None:
    """Validate the subsurface grid of a stress-based criterion (depth m or None, levels)."""
    if depth is not None and not (math.isfinite(depth) and depth > 0):
        raise ValueError(f"depth = {depth!r} is not allowed: must be > 0 m (or None)")
    if int(nz) != nz or nz < 2:
        raise ValueError(f"nz = {nz!r} is not allowed: must be an integer >= 2")


class Criterion(ABC):
    """One material evolution criterion (plug-in). Subclasses register by ``name``."""

    name: ClassVar[str] = "base"
    kind: ClassVar[str] = "rate"  #: "rate" or "threshold"
    #: first-body capabilities it needs (:class:`tribodem.contact.Capabilities` names)
    requires: ClassVar[frozenset[str]] = frozenset()
    #: what it needs besides ``requires`` in a run of more than one cycle
    requires_over_cycles: ClassVar[frozenset[str]] = frozenset()
    #: attributes not carried from one cycle to the next (remade by :meth:`begin_cycle`),
    #: left out of :meth:`state`
    _SCRATCH: ClassVar[frozenset[str]] = frozenset(
        {"grid", "solver", "_up", "_lo", "_h_up", "_h_lo", "_idx"})

    def state(self) -> dict[str, Any]:
        """Everything the criterion carries across cycles (Miner sums, DFDI, the grid depth
        fixed at the first cycle, last-cycle diagnostics), picklable, for a checkpoint."""
        return {k: v for k, v in vars(self).items() if k not in self._SCRATCH}

    def set_state(self, state: dict[str, Any]) -> None:
        """Restore :meth:`state` (the next :meth:`begin_cycle` remakes the scratch)."""
        vars(self).update(state)

    def set_increments(self, n_increments: int) -> None:  # noqa: B027 - optional hook
        """Told how many sliding increments a cycle has (default: not needed)."""

    def check_solver(self, solver: FirstBodySolver) -> None:
        """Refuse (``CriterionUnavailable``, naming both) a solver lacking what it needs."""
        try:
            require(solver, self.requires, f"criterion '{self.name}'")
        except ValueError as err:
            raise CriterionUnavailable(str(err)) from None

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


class RateCriterion(Criterion):
    """A local rate law: each increment adds ``coefficient x local_rate(inc)`` (m) to the
    wear depth of every point, with one coefficient per body (:attr:`coefficients`); the
    lower body gets the field on its track."""

    @property
    @abstractmethod
    def coefficients(self) -> tuple[float, float]:
        """Wear coefficients (upper, lower) multiplying the accumulated field."""

    @abstractmethod
    def local_rate(self, inc: IncrementResult) -> NDArray[np.float64]:
        """The increment's field on the window, [n, n]."""

    def begin_cycle(self, grid: TrackGrid, solver: FirstBodySolver) -> None:
        super().begin_cycle(grid, solver)
        self._up = np.zeros(grid.upper_shape)
        self._lo = np.zeros(grid.lower_shape)

    def add_increment(self, index: int, inc: IncrementResult) -> None:
        f = self.local_rate(inc)
        self._up += f
        self.grid.deposit(self._lo, f, inc)

    def depths(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        cu, cl = self.coefficients
        return cu * self._up, cl * self._lo


def _coefficient(name: str, v: float) -> float:
    if not (math.isfinite(v) and v >= 0):
        raise ValueError(f"{name} = {v!r} is not allowed: must be finite and >= 0")
    return float(v)


class EnergyCriterion(RateCriterion):
    """Fouvry's energy law (seed eqs 2.7-2.8): W_v = alpha x sum E_d, per surface point.

    Eq 2.7 relates the *total* worn volume (both bodies) to the energy dissipated by the
    interface. The loop shares it: the upper body loses ``share_upper x alpha x e`` (m) and
    the lower ``(1 - share_upper) x alpha x e`` at each point (e in J/m^2, the same density
    on both bodies), so their volumes add up to alpha x the dissipated energy. Default share
    0.5 (two bodies of one material, as in the seed's EN24T/EN24T tests). ``alpha`` in
    m^3/J (default 1.641e-6 mm^3/J, seed section 5.2).
    """

    name = "energy"

    def __init__(self, alpha: float = ALPHA_SEED, share_upper: float = 0.5) -> None:
        self.alpha = _coefficient("alpha", alpha)
        if not 0.0 <= share_upper <= 1.0:
            raise ValueError(f"share_upper = {share_upper!r} is not allowed: must be in [0, 1]")
        self.share_upper = float(share_upper)

    @property
    def coefficients(self) -> tuple[float, float]:
        return self.alpha * self.share_upper, self.alpha * (1.0 - self.share_upper)

    def local_rate(self, inc: IncrementResult) -> NDArray[np.float64]:
        return inc.energy_density

    def params(self) -> dict[str, Any]:
        return {"alpha_m3_per_J": self.alpha, "share_upper": self.share_upper,
                "convention": "eq 2.7 total volume (upper + lower) = alpha x dissipated "
                              "energy, shared share_upper : 1 - share_upper"}


#: Archard k per body (1/Pa) by default: alpha mu / 2 with the seed's alpha and mu = 0.6,
#: the same wear as ``energy`` (equal share) in gross slip.
ARCHARD_K = ALPHA_SEED * 0.6 / 2


class ArchardCriterion(RateCriterion):
    """Local Archard law (seed eq 2.6) on each body: dh = k_body p |ds| per increment.

    ``k_upper``/``k_lower`` in 1/Pa (m^2/N): each body's worn volume is k_body x P x sliding
    distance in gross slip. ``k`` sets both. Default :data:`ARCHARD_K` each.
    """

    name = "archard"

    def __init__(self, k: float | None = None, k_upper: float | None = None,
                 k_lower: float | None = None) -> None:
        both = ARCHARD_K if k is None else _coefficient("k", k)
        self.k_upper = both if k_upper is None else _coefficient("k_upper", k_upper)
        self.k_lower = both if k_lower is None else _coefficient("k_lower", k_lower)

    @property
    def coefficients(self) -> tuple[float, float]:
        return self.k_upper, self.k_lower

    def local_rate(self, inc: IncrementResult) -> NDArray[np.float64]:
        return inc.pressure * np.hypot(inc.slip[..., 0], inc.slip[..., 1])

    def params(self) -> dict[str, Any]:
        return {"k_upper_per_Pa": self.k_upper, "k_lower_per_Pa": self.k_lower,
                "convention": "each body: volume = k_body x P x sliding distance"}


class ThresholdCriterion(Criterion):
    """Stress-threshold criterion with the column search (seed section 6.3, figure 6.4).

    The field is evaluated under both bodies at ``samples`` increments spread evenly over
    the cycle's slide (the last increment of each of ``samples`` equal segments; with the
    default 8 of 48 increments: +-A/2, +-A and the two passes through 0, both directions),
    on ``nz`` levels down to ``depth`` (m; None: 3 equivalent contact radii sqrt(area/pi)
    of the first sampled increment of the run, then fixed). The per-point maximum over the
    samples (upper: window points; lower: the track) goes through :func:`column_search`.
    On the lower body's track every shift the contact passed between two samples gets
    their fields interpolated to it (``TrackGrid.fold_max``'s ``slide``; the cycle's first
    sample holds its own over its slide): a track point between two sampled
    positions gets the field the contact carried over it, not the tails of two distant
    samples (measured on the seed's shear case, 2 half-space cycles: 8 samples folded at
    their own shifts only left the lower worn volume 21 % under 48, interpolated 0.3 %
    over; docs/fretting.md "Sampled increments").
    """

    kind = "threshold"
    unit: ClassVar[str] = "Pa"
    requires = frozenset({"subsurface"})

    def __init__(self, threshold: float, depth: float | None = None, nz: int = 33,
                 samples: int = 8) -> None:
        if not (math.isfinite(threshold) and threshold > 0):
            raise ValueError(f"threshold = {threshold!r} is not allowed: must be > 0")
        _check_stress_grid(depth, nz)
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
        self._up = np.full((self.nz, *grid.upper_shape), -np.inf)
        self._lo = np.full((self.nz, *grid.lower_shape), -np.inf)
        self._z: NDArray[np.float64] | None = None
        self._seg: tuple[float, float] | None = None  # slide since the last sample, m
        self._prev: tuple[float, NDArray[np.float64]] | None = None  # its offset, lower field

    def _depth_for(self, inc: IncrementResult) -> float:
        # None: 3 equivalent contact radii of the first sampled increment of the run,
        # then kept for every later cycle (the grid must not shrink with the contact)
        if self.depth is None:
            self.depth = 3.0 * math.sqrt(max(inc.contact_area, self.grid.dx**2) / math.pi)
        return self.depth

    def add_increment(self, index: int, inc: IncrementResult) -> None:
        lo, hi = sorted((inc.start_offset, inc.offset))
        if self._seg is not None:
            lo, hi = min(lo, self._seg[0]), max(hi, self._seg[1])
        if index not in self._idx:
            self._seg = (lo, hi)
            return
        self._seg = None
        depth = self._depth_for(inc)
        for body in ("upper", "lower"):
            st = self.solver.subsurface_stress(inc, body, depth=depth, nz=self.nz)
            self._z = st.z
            f = self.field(st)
            if body == "upper":
                np.maximum(self._up, f, out=self._up)
            else:  # the slide since the previous sample, interpolated between the two
                self.grid.fold_max(self._lo, f, inc.offset, (lo, hi), self._prev)
                self._prev = (inc.offset, f.copy())  # the solver may reuse its array

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


def _shift_up(field: NDArray[np.float64], z: NDArray[np.float64],
              removed: NDArray[np.float64]) -> NDArray[np.float64]:
    """Damage field ``[nz, ...]`` on depths below the surface after removing ``removed`` (m)
    of material from each column: new(z) = old(z + removed), zero below the grid."""
    if not np.any(removed > 0):
        return field
    nz = field.shape[0]
    flat = field.reshape(nz, -1)
    h = removed.reshape(-1)
    dz = z[1] - z[0]
    q = (z[:, None] + h[None, :]) / dz  # fractional level index of the material now at z
    k = np.floor(q).astype(int)
    w = q - k
    cols = np.arange(flat.shape[1])[None, :]
    k0 = np.clip(k, 0, nz - 1)
    k1 = np.clip(k + 1, 0, nz - 1)
    out = (1 - w) * flat[k0, cols] + w * flat[k1, cols]
    out[k >= nz - 1] = 0.0
    return out.reshape(field.shape)


def _remove_damaged(crit: Any, info: dict[str, Any]
                    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Wear where an accumulated damage sum (``crit._d_up``/``_d_lo`` on depths ``crit._z``:
    DFDI, Miner's SWT sum) has reached 1, by the column search; then the sums are shifted up
    by the worn depth (the new surface carries the damage of the material below it).
    Sets ``crit._last_info`` = ``info`` plus the grid diagnostics; returns (upper, lower) m."""
    du, su = column_search(crit._d_up, crit._z, 1.0)
    dl, sl = column_search(crit._d_lo, crit._z, 1.0)
    crit._last_info = {**info, "saturated_columns_upper": int(su.sum()),
                       "saturated_columns_lower": int(sl.sum()),
                       "grid_depth_m": float(crit._z[-1])}
    crit._d_up = _shift_up(crit._d_up, crit._z, du)
    crit._d_lo = _shift_up(crit._d_lo, crit._z, dl)
    return du, dl


#: readings of eq 6.2's triaxiality (:class:`DFDICriterion`)
DFDI_TRIAXIALITY = ("local", "seed-script")


class DFDICriterion(Criterion):
    """Ductile failure damage indicator (seed eqs 6.1-6.2), threshold DFDI >= 1.

    DFDI = sum over the plastic load steps of dp / eps_f (eq 6.1, p the equivalent
    (cumulated) plastic strain), eps_f = 1.65 eps0 exp(-3 sigma_m / (2 sigma_eq)) (eq 6.2,
    sigma_m mean stress, sigma_eq von Mises, both at the end of the step). Accumulated over
    cycles per material point on a [nz, ...] grid under each body (the damaged layer moves
    up as wear removes material); wear depth by :func:`column_search` at DFDI = 1.
    ``eps0`` default 0.118, the seed's own script's (appendix IV; the text gives no number).
    ``triaxiality``: ``"local"`` (eq 6.2 as written: each point's sigma_m / sigma_eq) or
    ``"seed-script"`` (what appendix IV computes: sigma_m is the mean of the principal
    stresses' ranges over the cycle and sigma_eq the *sum over all nodes* of the von Mises
    ranges, so the exponent is ~0 and eps_f = 1.65 eps0 everywhere; DFDI is then the peak
    equivalent plastic strain / (1.65 eps0)). Needs a solver with the
    ``plastic`` capability (:class:`tribodem.contact.ElastoPlasticSolver` and ``fe`` with
    ``material = "elastic-plastic"``: one plastic state per body, :attr:`PlasticStep.body`).
    """

    name = "dfdi"
    kind = "threshold"
    requires = frozenset({"plastic"})
    requires_over_cycles = frozenset({"plastic_every_cycle"})

    def __init__(self, eps0: float = EN24T.dfdi_eps0, depth: float | None = None,
                 nz: int = 33, triaxiality: str = "local") -> None:
        if not (math.isfinite(eps0) and eps0 > 0):
            raise ValueError(f"eps0 = {eps0!r} is not allowed: must be > 0 (failure strain)")
        if triaxiality not in DFDI_TRIAXIALITY:
            raise ValueError(f"triaxiality = {triaxiality!r} is not allowed: allowed: "
                             f"{', '.join(DFDI_TRIAXIALITY)}")
        _check_stress_grid(depth, nz)
        self.eps0 = float(eps0)
        self.triaxiality = triaxiality
        self.depth = depth
        self.nz = int(nz)
        self._d_up: NDArray[np.float64] | None = None
        self._d_lo: NDArray[np.float64] | None = None
        self._last_info: dict[str, Any] = {}

    def failure_strain(self, stress: NDArray[np.float64]) -> NDArray[np.float64]:
        """eps_f of eq 6.2 for Voigt stresses [..., 6] (xx, yy, zz, yz, xz, xy), -."""
        s = np.asarray(stress, dtype=float)
        if self.triaxiality == "seed-script":  # appendix IV: the exponent's ratio is ~0
            return np.full(s.shape[:-1], 1.65 * self.eps0)
        sm = s[..., :3].mean(-1)
        dev = s[..., :3] - sm[..., None]
        seq = np.sqrt(1.5 * (dev**2).sum(-1) + 3.0 * (s[..., 3:] ** 2).sum(-1))
        with np.errstate(divide="ignore", invalid="ignore"):
            tri = np.where(seq > 0, sm / seq, 0.0)
        return 1.65 * self.eps0 * np.exp(-1.5 * tri)

    def damage_increment(self, dp: NDArray[np.float64],
                         stress: NDArray[np.float64]) -> NDArray[np.float64]:
        """dDFDI = dp / eps_f (eq 6.1) of one step, [...]."""
        return np.asarray(dp, dtype=float) / self.failure_strain(stress)

    def begin_cycle(self, grid: TrackGrid, solver: FirstBodySolver) -> None:
        self.check_solver(solver)
        super().begin_cycle(grid, solver)
        if self.depth is None:
            self.depth = float(solver.plastic_depth)
        self._z = np.linspace(0.0, self.depth, self.nz)
        if self._d_up is None:
            self._d_up = np.zeros((self.nz, *grid.upper_shape))
            self._d_lo = np.zeros((self.nz, *grid.lower_shape))

    def add_increment(self, index: int, inc: IncrementResult) -> None:
        """Plastic flow happens in the solver's load steps (collected in ``depths``)."""

    def depths(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        from scipy.interpolate import RegularGridInterpolator

        assert self._d_up is not None and self._d_lo is not None
        g = self.grid
        steps = self.solver.plastic_steps()

        def on_grid(group: list[Any], x: NDArray[np.float64]) -> NDArray[np.float64]:
            dd = sum(self.damage_increment(st.dp, st.stress) for st in group)
            st = group[0]
            y = st.x if st.y is None else st.y
            interp = RegularGridInterpolator((st.z, st.x, y), dd, bounds_error=False,
                                             fill_value=0.0)
            zz, xx, yy = np.meshgrid(self._z, x, g.y, indexing="ij")
            return interp(np.stack([zz, xx, yy], -1))

        shared = [st for st in steps if st.body is None]
        if shared:
            # both bodies carry the same plastic state (same traction, same material);
            # the EP solve is at offset 0: upper window frame, lower track at shift 0
            field = on_grid(shared, g.x_upper)
            self._d_up += field
            self._d_lo[:, g.pad : g.pad + g.n, :] += field
        # a state per body (fe): the upper's in its window frame, the lower's in the lab
        for body, x, acc in (("upper", g.x_upper, self._d_up), ("lower", g.x_lower,
                                                                 self._d_lo)):
            own = [st for st in steps if st.body == body]
            if own:
                acc += on_grid(own, x)
        return _remove_damaged(self, {"max_dfdi_upper": float(self._d_up.max()),
                                      "max_dfdi_lower": float(self._d_lo.max())})

    def info(self) -> dict[str, Any]:
        return dict(self._last_info)

    def params(self) -> dict[str, Any]:
        return {"eps0": self.eps0, "depth_m": self.depth, "nz": self.nz,
                "triaxiality": self.triaxiality}


#: Seed table 6.2 (SWT, Mitchell method): b, sigma'_f (Pa), sigma_T (Pa), eps'_f, c.
SWT_TABLE_6_2 = dict(EN24T.swt)


def swt_rhs(two_n: NDArray[np.float64] | float, young: float, b: float, sigma_f: float,
            eps_f: float, c: float) -> NDArray[np.float64]:
    """Right side of eq 6.3: sigma_f'^2 / E (2N)^2b + sigma_f' eps_f' (2N)^(b+c), Pa."""
    x = np.asarray(two_n, dtype=float)
    return sigma_f**2 / young * x ** (2 * b) + sigma_f * eps_f * x ** (b + c)


def swt_life(swt: NDArray[np.float64] | float, young: float = EN24T.young,
             b: float = SWT_TABLE_6_2["b"], sigma_f: float = SWT_TABLE_6_2["sigma_f"],
             eps_f: float = SWT_TABLE_6_2["eps_f"], c: float = SWT_TABLE_6_2["c"]
             ) -> NDArray[np.float64]:
    """Cycles to crack initiation N_i solving eq 6.3 for SWT (Pa), inverted by bisection on
    ln(2N) (the right side decreases with N for b, c < 0). SWT <= 0 gives inf; SWT above
    the 2N = 1 value gives N = 0.5."""
    if not (b < 0 and c < 0):
        raise ValueError(f"b = {b!r}, c = {c!r} are not allowed: both exponents must be < 0")
    s = np.atleast_1d(np.asarray(swt, dtype=float))
    out = np.full(s.shape, np.inf)
    top = float(swt_rhs(1.0, young, b, sigma_f, eps_f, c))
    pos = s > 0
    lo = np.zeros(s.shape)
    hi = np.full(s.shape, 200.0)  # ln(2N) <= 200: N up to ~1e86
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        big = swt_rhs(np.exp(mid), young, b, sigma_f, eps_f, c) > s
        lo = np.where(big, mid, lo)
        hi = np.where(big, hi, mid)
    n = 0.5 * np.exp(0.5 * (lo + hi))
    out[pos] = np.where(s[pos] >= top, 0.5, n[pos])
    return out.reshape(np.shape(swt))


def plane_normals(step_deg: float = 5.0) -> NDArray[np.float64]:
    """Candidate plane normals n(theta, phi) of eq 6.4, theta and phi in [0, 180) deg by
    ``step_deg``, [n_planes, 3]."""
    ang = np.deg2rad(np.arange(0.0, 180.0, step_deg))
    th, ph = np.meshgrid(ang, ang, indexing="ij")
    n = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], -1)
    return n.reshape(-1, 3)


def critical_plane_swt(history: NDArray[np.float64], young: float, poisson: float,
                       normals: NDArray[np.float64]) -> NDArray[np.float64]:
    """Maximum over candidate planes of SWT = sigma_max Delta eps / 2 (eqs 6.3, 6.5-6.6), Pa.

    ``history`` [T, P, 6]: Voigt stresses (xx, yy, zz, yz, xz, xy, Pa) of P points at T
    instants. On each plane sigma_n(t) = n.sigma.n (eq 6.5) and the elastic normal strain
    eps_n = ((1 + nu) sigma_n - nu tr sigma) / E (eq 6.6 with Hooke's law); sigma_max =
    max_t sigma_n, Delta eps = max_t eps_n - min_t eps_n; planes with sigma_max <= 0 give 0.
    A numba kernel: the points in threads, the planes in the innermost loop.
    """
    h = np.asarray(history, dtype=float)
    nx, ny, nzv = normals[:, 0], normals[:, 1], normals[:, 2]
    proj = np.ascontiguousarray(
        np.stack([nx * nx, ny * ny, nzv * nzv, 2 * ny * nzv, 2 * nx * nzv, 2 * nx * ny]))
    out = np.zeros(h.shape[1])
    _critical_plane_swt(h, proj, float(young), float(poisson), out)
    return out


@njit(parallel=True, cache=True)
def _critical_plane_swt(h, proj, young, poisson, out):  # pragma: no cover - numba
    """``critical_plane_swt`` on ``h`` [T, P, 6] and ``proj`` [6, planes] into ``out`` [P]."""
    npl = proj.shape[1]
    for p in prange(h.shape[1]):
        smax = np.full(npl, -np.inf)
        emax = np.full(npl, -np.inf)
        emin = np.full(npl, np.inf)
        for t in range(h.shape[0]):
            s0, s1, s2, s3, s4, s5 = h[t, p, 0], h[t, p, 1], h[t, p, 2], h[t, p, 3], \
                h[t, p, 4], h[t, p, 5]
            tr = s0 + s1 + s2
            for q in range(npl):
                sn = (s0 * proj[0, q] + s1 * proj[1, q] + s2 * proj[2, q] + s3 * proj[3, q]
                      + s4 * proj[4, q] + s5 * proj[5, q])
                en = ((1.0 + poisson) * sn - poisson * tr) / young
                smax[q] = max(smax[q], sn)
                emax[q] = max(emax[q], en)
                emin[q] = min(emin[q], en)
        best = 0.0
        for q in range(npl):
            if smax[q] > 0.0:
                best = max(best, 0.5 * smax[q] * (emax[q] - emin[q]))
        out[p] = best


class SWTCriterion(ThresholdCriterion):
    """Smith-Watson-Topper critical plane with Miner's sum (seed eqs 6.3-6.8), D >= 1.

    Per material point: the stress history of the cycle (``samples`` increments), SWT on
    the critical plane among 5 deg candidate planes (eqs 6.4-6.6), N_i from eq 6.3 with
    table 6.2 constants (b -0.103, sigma_f' 2349 MPa, eps_f' 1.22, c -0.6; E 240 GPa,
    nu 0.3), Miner damage D += 1/N_i per cycle (eq 6.8). Wear where D >= 1 by
    :func:`column_search`; ``info()`` projects the cycles to first wear per body at the
    current damage rate. The lower body's history is taken on the track (nearest shift;
    zero stress where the window is elsewhere). Strain: elastic (Hooke) of the stress.
    """

    name = "swt"
    unit = "-"

    def __init__(self, young: float = EN24T.young, poisson: float = EN24T.poisson,
                 b: float = SWT_TABLE_6_2["b"], sigma_f: float = SWT_TABLE_6_2["sigma_f"],
                 eps_f: float = SWT_TABLE_6_2["eps_f"], c: float = SWT_TABLE_6_2["c"],
                 plane_step: float = 5.0, nz: int = 17, **kw: Any) -> None:
        if not (math.isfinite(young) and young > 0):
            raise ValueError(f"young = {young!r} is not allowed: must be > 0 Pa")
        if not (-1 < poisson < 0.5):
            raise ValueError(f"poisson = {poisson!r} is not allowed: must be in (-1, 0.5)")
        if not (0 < plane_step <= 90):
            raise ValueError(f"plane_step = {plane_step!r} is not allowed: must be in (0, 90] deg")
        if not (sigma_f > 0 and eps_f > 0 and b < 0 and c < 0):
            raise ValueError("SWT constants not allowed: need sigma_f > 0, eps_f > 0, b < 0, c < 0")
        super().__init__(1.0, nz=nz, **kw)
        self.young, self.poisson = float(young), float(poisson)
        self.consts = {"b": b, "sigma_f": sigma_f, "eps_f": eps_f, "c": c}
        self.plane_step = float(plane_step)
        self.normals = plane_normals(plane_step)
        self._d_up: NDArray[np.float64] | None = None
        self._d_lo: NDArray[np.float64] | None = None
        self.cycles_done = 0

    def field(self, st: SubsurfaceStress) -> NDArray[np.float64]:  # pragma: no cover
        return st.stress

    def begin_cycle(self, grid: TrackGrid, solver: FirstBodySolver) -> None:
        Criterion.begin_cycle(self, grid, solver)
        if self._n_increments == 0:
            raise RuntimeError("set_increments() must be called before the first cycle")
        self._idx = sorted(self.sample_indices())
        s = len(self._idx)
        self._h_up = np.zeros((s, self.nz, *grid.upper_shape, 6), dtype=np.float32)
        self._h_lo = np.zeros((s, self.nz, *grid.lower_shape, 6), dtype=np.float32)
        self._z = None
        if self._d_up is None:
            self._d_up = np.zeros((self.nz, *grid.upper_shape))
            self._d_lo = np.zeros((self.nz, *grid.lower_shape))

    def add_increment(self, index: int, inc: IncrementResult) -> None:
        if index not in self._idx:
            return
        k = self._idx.index(index)
        depth = self._depth_for(inc)
        g = self.grid
        for body in ("upper", "lower"):
            st = self.solver.subsurface_stress(inc, body, depth=depth, nz=self.nz)
            self._z = st.z
            if body == "upper":
                self._h_up[k] = st.stress
            else:
                j0 = g.pad + int(round(inc.offset / g.dx))
                self._h_lo[k, :, j0 : j0 + g.n, :] = st.stress

    def damage_rate(self, history: NDArray[np.float64]) -> NDArray[np.float64]:
        """1 / N_i per cycle of a history [T, ...spatial, 6] (eqs 6.3-6.6), shape [...]."""
        h = np.asarray(history, dtype=float)
        shape = h.shape[1:-1]
        flat = h.reshape(h.shape[0], -1, 6)
        amp = np.abs(flat).max(axis=(0, 2))
        keep = amp > 1e-6 * max(float(amp.max(initial=0.0)), 1e-300)
        swt = np.zeros(flat.shape[1])
        swt[keep] = critical_plane_swt(flat[:, keep], self.young, self.poisson, self.normals)
        n = swt_life(swt, self.young, **self.consts)
        return (1.0 / n).reshape(shape)

    def depths(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        assert self._z is not None, "no sampled increment in this cycle"
        assert self._d_up is not None and self._d_lo is not None
        r_up = self.damage_rate(self._h_up)
        r_lo = self.damage_rate(self._h_lo)
        self._d_up = self._d_up + r_up
        self._d_lo = self._d_lo + r_lo
        self.cycles_done += 1

        def first_wear(d: NDArray[np.float64], r: NDArray[np.float64]) -> float:
            if np.any(d >= 1.0):
                return float(self.cycles_done)
            with np.errstate(divide="ignore"):
                left = np.where(r > 0, (1.0 - d) / r, np.inf)
            return float(self.cycles_done + left.min())

        # the upper body's contact centre (section 6.6: "the material at the centre of the
        # contact zone obtained very small values"): the grid's central 2 x 2 columns
        c, cy = self.grid.n // 2, self.grid.ny // 2
        centre = (slice(None), slice(c - 1, c + 1), slice(max(cy - 1, 0), cy + 1))
        return _remove_damaged(self, {
            "cycles_to_first_wear_upper": first_wear(self._d_up, r_up),
            "cycles_to_first_wear_upper_centre": first_wear(self._d_up[centre], r_up[centre]),
            "cycles_to_first_wear_lower": first_wear(self._d_lo, r_lo),
            "max_damage_rate_upper": float(r_up.max()),
            "max_damage_rate_lower": float(r_lo.max()),
            "miner_sum_max_upper": float(self._d_up.max()),
            "miner_sum_max_lower": float(self._d_lo.max()),
        })

    def params(self) -> dict[str, Any]:
        return {**super().params(), "young_Pa": self.young, "poisson": self.poisson,
                **self.consts, "plane_step_deg": self.plane_step}


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
