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
    wall_speed: float = 0.0  # m/s, compression platens (2D case; 3D: the lid of a box)
    lid: bool = False  # 3D: a sixth wall (the lid) at box_hi[2]; walls on the box faces
    bonds: dict = field(default_factory=dict)  # parallel bonds (install_bonds_by_gap kwargs)

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
    particle size of Sha et al. (2022)), so every lattice neighbour starts in contact (overlap
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


def _cubic_block(n: int, s: float, rng: np.random.Generator, jitter: float
                 ) -> tuple[np.ndarray, int, int]:
    """Simple-cubic block of full layers (spacing s, m), x fastest: nx = ny columns, nz
    layers, nx^2 nz = n for the nx nearest to n^(1/3) whose square divides n with
    nz <= 4 nx; otherwise nx = round(n^(1/3)) and only the full layers (fewer than n
    sites). ``jitter`` x s uniform noise on every coordinate."""
    nx = max(2, int(round(n ** (1.0 / 3.0))))
    for cand in sorted(range(2, 2 * nx + 1), key=lambda c: abs(c - nx)):
        if n % (cand * cand) == 0 and n // (cand * cand) <= 4 * cand:
            nx = cand
            break
    nz = max(1, n // (nx * nx))
    m = nx * nx * nz
    idx = np.arange(m)
    i, j, k = idx % nx, (idx // nx) % nx, idx // (nx * nx)
    pos = np.stack([(i + 0.5) * s, (j + 0.5) * s, (k + 0.5) * s], axis=1)
    pos += rng.uniform(-jitter, jitter, size=(m, 3)) * s
    return pos, nx, nz


def dense3d_case(n: int = 20_000, steps: int = 2_000, seed: int = 0) -> BenchCase:
    """Case (c): a dense 3D packing held compressed between six fixed walls, no gravity.

    Simple-cubic lattice of spacing 0.98 mm, radii uniform in [0.498, 0.5] mm, 0.2% jitter:
    every sphere overlaps its six lattice neighbours by about 16-20 um (2% of d), so the
    coordination number is 6 (contacts dominate: about 3 listed pairs per sphere, all
    touching), and the walls on the box faces press the outer layers by about 15 um.
    Hertz-Mindlin, E 10 MPa, nu 0.3, rho 2500, CoR 0.5, mu 0.5 (as settle3d); the stored
    elastic energy rings through the block. dt = 0.2 x Rayleigh step of the smallest
    sphere. Runs on LIGGGHTS with six primitive plane walls (``benchmarks/peers.py``).
    """
    rng = np.random.default_rng(seed)
    s = 0.98e-3
    pos, nx, nz = _cubic_block(n, s, rng, 0.002)
    radii = rng.uniform(0.498e-3, 0.5e-3, size=pos.shape[0])
    young, nu, rho = 1.0e7, 0.3, 2500.0
    dt = 0.2 * float(rayleigh_step(radii.min(), rho, young / (2.0 * (1.0 + nu)), nu))
    inset = 0.5 * s - 0.485e-3  # wall planes 0.485 mm from the outer centres
    lo = np.full(3, inset)
    hi = np.array([nx * s - inset, nx * s - inset, nz * s - inset])
    return BenchCase(
        name="dense3d", dim=3, positions=pos, radii=radii, box_lo=lo, box_hi=hi,
        young=young, poisson=nu, density=rho, cor=0.5, friction=0.5, dt=dt, steps=steps,
        law="hertz", lid=True,
    )


def bonded3d_case(n: int = 20_000, steps: int = 2_000, seed: int = 0) -> BenchCase:
    """Case (d): a bonded 3D block in uniaxial compression (no gravity).

    Simple-cubic lattice of spacing 1.0 mm, radii uniform in [0.49, 0.5] mm, 0.2% jitter;
    every lattice neighbour pair (surface gap below 0.05 mm) carries a linear parallel
    bond (lambda 0.8, E_bond 1 GPa, kratio 1.75, strengths 5 MPa tensile / 5 MPa
    cohesion: about 3 bonds per sphere). Linear contacts (PFC deformability, E 1 GPa,
    kratio 1.75, mu 0.5). Floor fixed, lid at 0.05 m/s down, side walls 0.1 mm away (the
    block may bulge). dt = 0.2 x the bonds' critical step.
    """
    rng = np.random.default_rng(seed)
    s = 1.0e-3
    pos, nx, nz = _cubic_block(n, s, rng, 0.002)
    radii = rng.uniform(0.49e-3, 0.5e-3, size=pos.shape[0])
    young, nu, rho = 1.0e9, 0.3, 2500.0
    kr = 1.75
    # bond: kn = E_b/(r_i + r_j), area pi (0.8 r)^2 -> k = E_b pi 0.64 r^2 / (2 r); contact
    # (linear) kn = pi r^2 E / (2 r): the sum bounds the stiffness of a sphere's neighbours
    r_min, r_max = float(radii.min()), float(radii.max())
    m_min = rho * 4.0 / 3.0 * math.pi * r_min**3
    k_one = (1.0e9 * 0.64 + young) * math.pi * r_max**2 / (2.0 * r_min)
    dt = 0.2 * math.sqrt(m_min / (6.0 * k_one))
    lo = np.array([-0.1e-3, -0.1e-3, 0.5 * s - r_min])
    hi = np.array([nx * s + 0.1e-3, nx * s + 0.1e-3, nz * s - 0.5 * s + r_min])
    return BenchCase(
        name="bonded3d", dim=3, positions=pos, radii=radii, box_lo=lo, box_hi=hi,
        young=young, poisson=nu, density=rho, cor=0.5, friction=0.5, dt=dt, steps=steps,
        law="linear", lid=True, wall_speed=0.05,
        bonds={"gap": 0.05e-3, "lambda_": 0.8, "E_bond": 1.0e9, "kratio": kr,
               "tensile_strength": 5.0e6, "cohesion": 5.0e6},
    )
