"""Particle state: a struct of arrays for 2D disks (with thickness) and 3D spheres.

Vectors are always stored with three components; a 2D run keeps z, omega_x and
omega_y at zero (disks move in the x-y plane and spin about z).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

# degree-of-freedom fixity bits (a fixed DOF keeps its prescribed velocity)
FIX_X, FIX_Y, FIX_Z, FIX_RX, FIX_RY, FIX_RZ = 1, 2, 4, 8, 16, 32
FIX_TRANSLATION = FIX_X | FIX_Y | FIX_Z
FIX_ROTATION = FIX_RX | FIX_RY | FIX_RZ
FIX_2D = FIX_Z | FIX_RX | FIX_RY
# marks a member sphere of a rigid clump (``dem.clumps``): its body integrates it
FIX_CLUMP = 64


#: Memory per particle of a run, bytes, for refusing runs that cannot fit: measured
#: 1.16 kB per sphere (settle3d, 200k spheres, ~3 neighbour pairs each, peak RSS) and
#: doubled for dense packings (~7 pairs each) and the output buffers.
BYTES_PER_PARTICLE = 2500.0


@dataclass
class ParticleState:
    """Particles of one simulation (SI units).

    ``dim`` 2 means disks of ``thickness`` (m) in the x-y plane; 3 means spheres.
    ``mat`` indexes the material table; ``group`` is an application label
    (pad, disc, debris, ...); ``fixed`` holds DOF fixity bits (``FIX_*``).
    """

    dim: int
    pos: np.ndarray
    radius: np.ndarray
    density: np.ndarray
    thickness: float = 1.0
    vel: np.ndarray | None = None
    omega: np.ndarray | None = None
    mat: np.ndarray | None = None
    group: np.ndarray | None = None
    fixed: np.ndarray | None = None
    mass: np.ndarray = field(init=False)
    inertia: np.ndarray = field(init=False)

    def __post_init__(self) -> None:
        if self.dim not in (2, 3):
            raise ValueError(f"particles: dim = {self.dim!r}: must be 2 (disks) or 3 (spheres)")
        self.pos = np.ascontiguousarray(self.pos, dtype=np.float64).reshape(-1, 3).copy()
        n = self.pos.shape[0]
        self.radius = _per_particle(self.radius, n, "radius")
        self.density = _per_particle(self.density, n, "density")
        if np.any(~(self.radius > 0)):
            i = int(np.flatnonzero(~(self.radius > 0))[0])
            raise ValueError(f"particles: radius[{i}] = {self.radius[i]!r}: must be > 0 m")
        if np.any(~(self.density > 0)):
            i = int(np.flatnonzero(~(self.density > 0))[0])
            raise ValueError(f"particles: density[{i}] = {self.density[i]!r}: must be > 0")
        if self.dim == 2 and not self.thickness > 0:
            raise ValueError(f"particles: thickness = {self.thickness!r}: must be > 0 m")
        self.vel = _vec(self.vel, n)
        self.omega = _vec(self.omega, n)
        self.mat = _ints(self.mat, n, np.int32)
        self.group = _ints(self.group, n, np.int32)
        self.fixed = _ints(self.fixed, n, np.uint8)
        if self.dim == 2:
            self.pos[:, 2] = 0.0
            self.vel[:, 2] = 0.0
            self.omega[:, :2] = 0.0
            self.fixed |= FIX_2D
        self.update_mass()

    @property
    def n(self) -> int:
        """Number of particles."""
        return self.pos.shape[0]

    def update_mass(self) -> None:
        """Mass (kg) and moment of inertia (kg m^2): disk 1/2 m r^2, sphere 2/5 m r^2."""
        r = self.radius
        if self.dim == 2:
            self.mass = self.density * np.pi * r * r * self.thickness
            self.inertia = 0.5 * self.mass * r * r
        else:
            self.mass = self.density * (4.0 / 3.0) * np.pi * r**3
            self.inertia = 0.4 * self.mass * r * r

    def arrays(self) -> dict[str, np.ndarray]:
        """All per-particle arrays by name (for checkpoints and snapshots)."""
        return {k: getattr(self, k) for k in
                ("pos", "vel", "omega", "radius", "density", "mat", "group", "fixed")}


def _per_particle(x: object, n: int, name: str) -> np.ndarray:
    a = np.asarray(x, dtype=np.float64)
    if a.ndim == 0:
        return np.full(n, float(a))
    if a.shape != (n,):
        raise ValueError(f"particles: {name} has shape {a.shape}, expected ({n},)")
    return a.copy()


def _vec(x: np.ndarray | None, n: int) -> np.ndarray:
    if x is None:
        return np.zeros((n, 3))
    return np.ascontiguousarray(x, dtype=np.float64).reshape(n, 3).copy()


def _ints(x: np.ndarray | None, n: int, dtype: type) -> np.ndarray:
    if x is None:
        return np.zeros(n, dtype=dtype)
    a = np.asarray(x)
    if a.ndim == 0:
        return np.full(n, a, dtype=dtype)
    return a.astype(dtype).reshape(n).copy()


def checked_per_item(x: object, n: int, room: str, name: str, allowed: str,
                     ok: object) -> np.ndarray:
    """A scalar or an (n,) array as a float array of n, every value passing ``ok``;
    otherwise ValueError naming the room, the field, the value and what is allowed."""
    a = np.asarray(x, dtype=np.float64)
    a = np.full(n, float(a)) if a.ndim == 0 else a.reshape(-1).copy()
    if a.shape != (n,):
        raise ValueError(f"{room}: {name} has shape {a.shape}, expected a scalar or ({n},)")
    bad = ~ok(a)  # type: ignore[operator]
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise ValueError(f"{room}: {name} = {float(a[k])!r}: must be {allowed}")
    return a
