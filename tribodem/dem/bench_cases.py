"""Benchmark cases shared by ``tribodem bench dem`` and the peer scripts in ``benchmarks/``.

Each case is plain data (positions, radii, box, material, time step), so Yade and LIGGGHTS
are fed exactly the same particles as tribodem.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from tribodem.dem.integrate import rayleigh_step


@dataclass
class BenchCase:
    """A benchmark scenario: initial particles, container and material, all SI."""

    name: str
    dim: int
    positions: np.ndarray  # (N, 3) m
    radii: np.ndarray  # (N,) m
    box_lo: np.ndarray  # (3,) m
    box_hi: np.ndarray  # (3,) m
    young: float  # Pa
    poisson: float
    density: float  # kg/m^3
    cor: float  # coefficient of restitution (Hertz) / unused for linear
    friction: float
    dt: float  # s
    steps: int
    gravity: np.ndarray = field(default_factory=lambda: np.zeros(3))  # m/s^2
    thickness: float = 1.0  # m, 2D disks only
    law: str = "hertz"
    wall_speed: float = 0.0  # m/s, compression platens (2D case)

    @property
    def n(self) -> int:
        return int(self.radii.size)


def settle3d_case(n: int = 20_000, steps: int = 2_000, seed: int = 0) -> BenchCase:
    """Case (a): n Hertz-Mindlin spheres settling under gravity in an open-top box.

    Simple-cubic lattice, spacing 1.0 mm, 40 x 40 columns (fewer below 16,000), radii uniform in
    [0.475, 0.5] mm (no initial overlap), a 1% jitter; E 10 MPa, nu 0.3, rho 2500,
    CoR 0.5, mu 0.5; dt = 0.2 x Rayleigh step of the smallest sphere. Walls: floor
    z = 0 and four side walls; no lid.
    """
    rng = np.random.default_rng(seed)
    s = 1.0e-3
    nx = ny = 40 if n >= 16_000 else max(2, int(math.ceil(math.sqrt(n / 10))))
    nz = int(math.ceil(n / (nx * ny)))
    idx = np.arange(n)
    i, j, k = idx % nx, (idx // nx) % ny, idx // (nx * ny)
    pos = np.stack([(i + 0.5) * s, (j + 0.5) * s, (k + 0.5) * s], axis=1)
    pos[:, :2] += rng.uniform(-0.01, 0.01, size=(n, 2)) * s
    radii = rng.uniform(0.475e-3, 0.5e-3, size=n)
    young, nu, rho = 1.0e7, 0.3, 2500.0
    dt = 0.2 * float(rayleigh_step(radii.min(), rho, young / (2.0 * (1.0 + nu)), nu))
    return BenchCase(
        name="settle3d", dim=3, positions=pos, radii=radii,
        box_lo=np.zeros(3), box_hi=np.array([nx * s, ny * s, (nz + 2) * s]),
        young=young, poisson=nu, density=rho, cor=0.5, friction=0.5, dt=dt, steps=steps,
        gravity=np.array([0.0, 0.0, -9.81]), law="hertz",
    )


def compress2d_case(n: int = 50_000, steps: int = 2_000, seed: int = 0) -> BenchCase:
    """Case (b): n linear-contact disks (unit thickness) compressed by two platens.

    Square lattice of spacing 7.15 um with radii uniform in [3.58, 3.6] um (the braking
    particle size of seed 000), so every lattice neighbour starts in contact (overlap
    0.01-0.05 um); E 200 GPa (PFC deformability kn = 2 r t E*/(r1+r2)),
    rho 7850; the top and bottom platens approach at 0.1 m/s each (the seed's calibration
    speed); dt = 0.2 x sqrt(m_min / kn_max).
    """
    rng = np.random.default_rng(seed)
    s = 7.15e-6
    nx = int(math.ceil(math.sqrt(n)))
    ny = int(math.ceil(n / nx))
    idx = np.arange(n)
    i, j = idx % nx, idx // nx
    pos = np.stack([(i + 0.5) * s, (j + 0.5) * s, np.zeros(n)], axis=1)
    pos[:, :2] += rng.uniform(-0.001, 0.001, size=(n, 2)) * s
    radii = rng.uniform(3.58e-6, 3.6e-6, size=n)
    young, nu, rho = 2.0e11, 0.3, 7850.0
    t = 1.0
    m_min = rho * math.pi * radii.min() ** 2 * t
    kn_max = 2.0 * radii.max() * t * young / (2.0 * radii.min())
    dt = 0.2 * math.sqrt(m_min / kn_max)
    return BenchCase(
        name="compress2d", dim=2, positions=pos, radii=radii,
        box_lo=np.zeros(3), box_hi=np.array([nx * s, ny * s, 0.0]),
        young=young, poisson=nu, density=rho, cor=0.5, friction=0.5, dt=dt, steps=steps,
        thickness=t, law="linear", wall_speed=0.1,
    )
