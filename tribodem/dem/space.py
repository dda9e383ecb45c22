"""The simulation box: bounds and periodic axes (Sha et al. (2022) fig. 7 remapping)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numba import njit


@dataclass
class Box:
    """Axis-aligned box [lo, hi) in m; ``periodic[k]`` makes axis k periodic.

    Non-periodic axes only bound the cell grid (particles may leave them; walls confine).
    """

    lo: np.ndarray
    hi: np.ndarray
    periodic: np.ndarray = field(default_factory=lambda: np.zeros(3, dtype=np.bool_))

    def __post_init__(self) -> None:
        self.lo = np.asarray(self.lo, dtype=np.float64).reshape(3)
        self.hi = np.asarray(self.hi, dtype=np.float64).reshape(3)
        self.periodic = np.asarray(self.periodic, dtype=np.bool_).reshape(3)
        for k in range(3):
            if self.periodic[k] and not self.hi[k] > self.lo[k]:
                raise ValueError(f"box: periodic axis {k} needs hi > lo (got {self.lo[k]}, "
                                 f"{self.hi[k]})")

    @property
    def length(self) -> np.ndarray:
        """Box edge lengths (m); zero-length non-periodic axes are allowed (2D z)."""
        return self.hi - self.lo


@njit(cache=True, inline="always")
def min_image(d: float, length: float, periodic: bool) -> float:
    """Minimum-image component of a separation along one axis (m).

    ``d - L rint(d / L)``; for ``|d| < L/4`` (almost every pair) ``rint`` gives +-0, so
    that is ``d + 0.0`` (the same bits, -0.0 included) without the division."""
    if periodic:
        q = 0.25 * length
        if -q < d < q:
            return d + 0.0
        return d - length * np.rint(d / length)
    return d


def column_order(pos: np.ndarray, x0: float, cell: float) -> np.ndarray:
    """A numbering of particles (a permutation of ``range(len(pos))``) column by column
    along x (columns ``cell`` wide from ``x0``, m), by y within a column: particles
    within ``cell`` of each other then have indices at most about three columns' count
    apart, so the pair and bond passes (which walk the particles' arrays by index) read
    memory that is close together. For a cell much wider than it is high (a periodic
    strip) this keeps a pass's working set in cache where a random numbering misses it
    on nearly every pair. Stable: ties keep their order."""
    col = np.floor((np.asarray(pos[:, 0]) - x0) / cell).astype(np.int64)
    return np.lexsort((pos[:, 1], col))
