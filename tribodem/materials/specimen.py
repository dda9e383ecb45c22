"""Bonded-particle specimen generation (Sha et al. (2022) section 3.1, figure 4).

Procedure (2D disks of unit thickness):

1. random disks (uniform radii in ``spec.radius_range``, count for area fraction
   ``PHI_TARGET`` = 0.82 in ``width x height``) placed without overlap at reduced radii
   (area fraction ``PHI0`` = 0.35);
2. isotropic compaction by **radius expansion** inside four fixed walls (10 stages to
   full size), then a uniform radius scale (bracketing bisection) until the mean wall
   stress is within a factor 2 of ``compaction_stress`` (default 1 MPa, ~1e-5 E_c:
   overlaps ~1e-5 r; PFC's isotropic-stress installation); frictionless, mass-scaled
   (density x ``MASS_SCALE``: only the quasi-static geometry is kept), local damping
   0.7. Servo walls were tried and limit-cycle at this stiffness-to-stress ratio. The
   radius scale (~0.98) is in ``stats``;
3. deletion of floating particles (PFC's floater test, one pass): particles with fewer
   than 3 contacts (gap below the bond gap; walls count) in the compacted state are
   deleted, then any particle left without a bondable neighbour (iterated). An
   iterated ">= 3 particle contacts" rule unravels a small specimen (boundary particles
   have wall contacts), and with parallel bonds (shear and moment) a particle held by
   one or two bonds is not floating;
4. parallel bonds between every pair with surface gap < ``spec.bond_gap``
   (``install_bonds_by_gap``), walls removed;
5. stress release: the bonded assembly without walls relaxes with local damping 0.7
   (real density) for ``release_steps`` (3000, ~15 elastic-wave transits); the bond
   forces that balance the remaining contact overlaps are kept in
   ``Specimen.bond_state``.

Everything is seeded: the same spec, size and seed give the same specimen.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from tribodem.dem import Box, Material, ParticleState, PlaneWall, Simulation
from tribodem.dem.bonds import ParallelBonds, install_bonds_by_gap
from tribodem.materials.library import MaterialSpec

PHI_TARGET = 0.82  # 2D area fraction of the particle count (before the stress adjustment)
PHI0 = 0.35  # initial area fraction of the random placement
MASS_SCALE = 1.0e4  # density multiplier during compaction only (quasi-static, geometry only)
MIN_CONTACTS = 3  # Sha et al. (2022) section 3.1 (2): floating particles have fewer contacts


@dataclass
class Specimen:
    """A relaxed bonded specimen: particles, bonds (with their released forces), stats.

    ``width``/``height`` (m) are the extents of the particle cloud after release;
    ``bond_state`` is ``ParallelBonds.state()`` after the stress release.
    """

    spec: MaterialSpec
    particles: ParticleState
    bond_i: np.ndarray
    bond_j: np.ndarray
    bond_state: dict[str, np.ndarray]
    width: float
    height: float
    seed: int
    n_generated: int
    n_deleted: int
    compaction_stress: float
    compaction_contacts: np.ndarray
    packed_pos: np.ndarray
    packed_radius: np.ndarray
    stats: dict[str, float] = field(default_factory=dict)

    @property
    def n(self) -> int:
        """Number of particles."""
        return self.particles.n

    @property
    def n_bonds(self) -> int:
        """Number of bonds."""
        return int(self.bond_i.size)

    def bonds_per_particle(self) -> np.ndarray:
        """Bond count of every particle."""
        return np.bincount(np.concatenate([self.bond_i, self.bond_j]), minlength=self.n)

    def with_spec(self, spec: MaterialSpec, release_steps: int = 3000) -> Specimen:
        """The same packing (geometry before bonding) with other micro-parameters: bonds
        re-installed by gap with ``spec`` and released again (used by the calibration,
        so E_c and kratio changes are not confounded with a new random packing)."""
        part, bonds, ke = _release(spec, self.packed_pos, self.packed_radius, release_steps)
        return dataclasses.replace(
            self, spec=spec, particles=part, bond_i=bonds.i.copy(), bond_j=bonds.j.copy(),
            bond_state=bonds.state(), stats={**self.stats, "release_kinetic_energy_J": ke})

    def build(self, walls: list[PlaneWall] | None = None, extra_materials: list[Material]
              | None = None, local_damping: float = 0.0, dt_safety: float = 0.3
              ) -> tuple[Simulation, ParallelBonds]:
        """A new Simulation of this specimen (copied particles, bonds with their released
        forces) plus ``walls``; ``extra_materials`` get indices 1, 2, ... for the walls."""
        p = self.particles
        part = ParticleState(dim=2, pos=p.pos.copy(), radius=p.radius.copy(),
                             density=p.density.copy(), thickness=p.thickness)
        mats = [self.spec.contact_material(), *(extra_materials or [])]
        sim = Simulation(part, mats, _box(part, 0.5 * max(self.width, self.height)),
                         walls=walls, dt_safety=dt_safety, local_damping=local_damping)
        bonds = _bonds(sim, self.spec, self.bond_i, self.bond_j)
        bonds.set_state(self.bond_state)
        sim.add_interaction(bonds)
        return sim, bonds


def _box(p: ParticleState, margin: float) -> Box:
    lo = p.pos.min(axis=0) - margin
    hi = p.pos.max(axis=0) + margin
    lo[2] = hi[2] = 0.0
    return Box(lo, hi)


def _bonds(sim: Simulation, spec: MaterialSpec, i: np.ndarray, j: np.ndarray) -> ParallelBonds:
    return ParallelBonds(sim, i, j, spec.bond_lambda, spec.bond_E, spec.bond_kr,
                         spec.tensile_strength, spec.cohesion)


def _place(rng: np.random.Generator, radii: np.ndarray, w: float, h: float) -> np.ndarray:
    """Random sequential placement without overlap in [0, w] x [0, h] (largest first)."""
    pos = np.zeros((radii.size, 3))
    for k, r in enumerate(radii):
        for _ in range(20_000):
            x = rng.uniform(r, w - r)
            y = rng.uniform(r, h - r)
            if k == 0:
                break
            d2 = (pos[:k, 0] - x) ** 2 + (pos[:k, 1] - y) ** 2
            if np.all(d2 > (radii[:k] + r) ** 2):
                break
        else:
            raise RuntimeError(f"specimen: could not place particle {k} of {radii.size} "
                               f"(area fraction {PHI0} too high for this box)")
        pos[k, 0], pos[k, 1] = x, y
    return pos


def _neighbour_pairs(pos: np.ndarray, radius: np.ndarray, gap: float
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Pairs (i < j) whose surface gap is below ``gap`` (overlaps included)."""
    from scipy.spatial import cKDTree  # here: 0.3 s to import, which every command paid

    tree = cKDTree(pos[:, :2])
    pairs = tree.query_pairs(2.0 * float(radius.max()) + gap, output_type="ndarray")
    if pairs.size == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    i, j = pairs[:, 0].astype(np.int64), pairs[:, 1].astype(np.int64)
    g = np.linalg.norm(pos[j, :2] - pos[i, :2], axis=1) - radius[i] - radius[j]
    keep = g < gap
    return i[keep], j[keep]


def contact_counts(pos: np.ndarray, radius: np.ndarray, gap: float, width: float,
                   height: float) -> np.ndarray:
    """Contacts of every particle (m, gap below ``gap``): particles plus the four walls of
    the ``[0, width] x [0, height]`` compaction box."""
    i, j = _neighbour_pairs(pos, radius, gap)
    deg = np.bincount(np.concatenate([i, j]), minlength=radius.size)
    x, y = pos[:, 0], pos[:, 1]
    for d in (x, width - x, y, height - y):
        deg += (d - radius < gap).astype(np.int64)
    return deg


def prune_floating(pos: np.ndarray, radius: np.ndarray, gap: float, width: float,
                   height: float, min_contacts: int = MIN_CONTACTS) -> np.ndarray:
    """Mask of the particles kept (Sha et al. (2022) 3.1 (2), PFC's floater test, one pass): delete
    those with fewer than ``min_contacts`` contacts (walls included) in the compacted
    state, then (repeatedly) those left without any bondable neighbour."""
    keep = contact_counts(pos, radius, gap, width, height) >= min_contacts
    i, j = _neighbour_pairs(pos, radius, gap)
    while True:
        live = keep[i] & keep[j]
        deg = np.bincount(np.concatenate([i[live], j[live]]), minlength=radius.size)
        drop = keep & (deg == 0)
        if not drop.any():
            return keep
        keep &= ~drop


def _wall_stress(sim: Simulation, w: float, h: float, t: float) -> float:
    """Mean isotropic stress on the four fixed walls (Pa, compression +)."""
    lr = (sim.walls[0].normal_force + sim.walls[1].normal_force) / (2.0 * h * t)
    tb = (sim.walls[2].normal_force + sim.walls[3].normal_force) / (2.0 * w * t)
    return 0.5 * (lr + tb)


def compact_by_radius_scaling(relax: Callable[[np.ndarray, np.ndarray, int],
                                              tuple[np.ndarray, float]],
                              pos: np.ndarray, radii: np.ndarray, f0: float, stress: float,
                              modulus: float, max_iter: int, growth: float = 1.002
                              ) -> tuple[np.ndarray, float, float, int]:
    """Radius expansion from ``f0`` to full size in 10 stages, then a uniform radius scale
    bracketed and bisected until the wall stress (``relax(pos, radii, steps) -> (pos, Pa)``)
    is within a factor 2 of ``stress`` (PFC's isotropic-stress installation).

    Returns (positions, radius scale, final stress Pa, iterations). If the band is not
    reached, the tightest (over-stressed, jammed) state is kept.
    """
    for f in np.linspace(f0, 1.0, 10)[1:]:
        pos, sig = relax(pos, radii * f, 300)
    # bracket [lo (too loose), hi (too tight)], bisect
    lo: float | None = None
    hi: tuple[float, np.ndarray] | None = None
    alpha, n_iter, start = 1.0, 0, pos
    for _ in range(max_iter):
        n_iter += 1
        pos, sig = relax(start, radii * alpha, 600)
        if 0.5 * stress <= sig <= 2.0 * stress:
            break
        if sig > 2.0 * stress:
            hi = (alpha, pos)
        else:
            lo = alpha
        if lo is not None and hi is not None:
            alpha = 0.5 * (lo + hi[0])
        elif hi is not None:
            alpha = hi[0] * (1.0 - min(sig / modulus, 0.02))
        else:
            alpha = alpha * growth
        start = pos if hi is None else hi[1]
    else:
        if hi is not None:
            alpha, pos = hi[0], hi[1]
            pos, sig = relax(pos, radii * alpha, 600)
    return pos, alpha, sig, n_iter


def _compact(spec: MaterialSpec, radii: np.ndarray, pos: np.ndarray, w: float, h: float,
             stress: float, max_iter: int) -> tuple[np.ndarray, np.ndarray, dict[str, float]]:
    """Isotropic compaction by radius expansion inside four fixed walls, then radius
    scaling until the mean wall stress is within a factor 2 of ``stress`` (PFC's
    isotropic-stress installation). Frictionless, mass-scaled, local damping 0.7.
    Returns (pos, radii, stats)."""
    t = spec.thickness
    mat = Material(name="compaction", young=spec.young, poisson=spec.poisson,
                   density=spec.density * MASS_SCALE, friction=0.0,
                   effective_modulus=spec.effective_modulus, kratio=1.0,
                   beta_n=spec.beta_n, law="linear")
    margin = 2.0 * float(radii.max())
    box = Box([-margin, -margin, 0], [w + margin, h + margin, 0])

    def relax(pos: np.ndarray, r: np.ndarray, steps: int) -> tuple[np.ndarray, float]:
        walls = [PlaneWall([0, 0, 0], [1, 0, 0], name="left"),
                 PlaneWall([w, 0, 0], [-1, 0, 0], name="right"),
                 PlaneWall([0, 0, 0], [0, 1, 0], name="bottom"),
                 PlaneWall([0, h, 0], [0, -1, 0], name="top")]
        part = ParticleState(dim=2, pos=pos, radius=r, density=mat.density, thickness=t)
        sim = Simulation(part, [mat], box, walls=walls, local_damping=0.7, dt_safety=0.2)
        sim.step(steps)
        return sim.p.pos.copy(), _wall_stress(sim, w, h, t)

    pos, alpha, sig, n_iter = compact_by_radius_scaling(
        relax, pos, radii, math.sqrt(PHI0 / PHI_TARGET), stress, spec.effective_modulus,
        max_iter)
    return pos, radii * alpha, {"compaction_iterations": float(n_iter),
                                "compaction_stress_Pa": float(sig),
                                "radius_scale": float(alpha)}


def _release(spec: MaterialSpec, pos: np.ndarray, radii: np.ndarray, steps: int
             ) -> tuple[ParticleState, ParallelBonds, float]:
    """Bond by gap, no walls, relax with local damping 0.7 (stress release, section 3.1
    (3)-(4)). Returns the relaxed particles, the bonds and the final kinetic energy (J)."""
    part = ParticleState(dim=2, pos=pos, radius=radii, density=spec.density,
                         thickness=spec.thickness)
    span = float(max(np.ptp(pos[:, 0]), np.ptp(pos[:, 1])))
    sim = Simulation(part, [spec.contact_material()], _box(part, 0.5 * span),
                     local_damping=0.7, dt_safety=0.3)
    bonds = install_bonds_by_gap(sim, spec.bond_gap, spec.bond_lambda, spec.bond_E,
                                 spec.bond_kr, spec.tensile_strength, spec.cohesion)
    sim.step(steps)
    if bonds.broken_count():
        raise RuntimeError(f"specimen: {bonds.broken_count()} bonds broke during the stress "
                           "release; lower compaction_stress")
    p = sim.p
    out = ParticleState(dim=2, pos=p.pos.copy(), radius=p.radius.copy(),
                        density=p.density.copy(), thickness=p.thickness)
    state = {k: np.array(v, copy=True) for k, v in bonds.state().items()}
    bonds.set_state(state)
    return out, bonds, sim.kinetic_energy()


def make_specimen(spec: MaterialSpec, width: float, height: float, seed: int = 0,
                  compaction_stress: float = 1.0e6, max_compaction_iter: int = 60,
                  release_steps: int = 3000) -> Specimen:
    """Generate, compact, prune, bond and release a ``width x height`` (m) specimen.

    ``compaction_stress``: isotropic wall stress of the compaction (Pa). See the module
    docstring for the procedure. Raises ValueError on bad sizes.
    """
    rmin, rmax = spec.radius_range
    for name, v in (("width", width), ("height", height)):
        if not v >= 8 * rmax:
            raise ValueError(f"specimen: {name} = {v!r} m: must be >= 8 x the largest radius "
                             f"({8 * rmax:.3g} m)")
    if not compaction_stress > 0:
        raise ValueError(f"specimen: compaction_stress = {compaction_stress!r}: must be > 0 Pa")
    rng = np.random.default_rng(seed)
    mean_area = math.pi * (rmin * rmin + rmin * rmax + rmax * rmax) / 3.0
    n = int(round(PHI_TARGET * width * height / mean_area))
    radii = np.sort(rng.uniform(rmin, rmax, size=n))[::-1].copy()
    f0 = math.sqrt(PHI0 / PHI_TARGET)
    pos = _place(rng, radii * f0, width, height)
    pos, radii, stats = _compact(spec, radii, pos, width, height, compaction_stress,
                                 max_compaction_iter)
    contacts = contact_counts(pos, radii, spec.bond_gap, width, height)
    keep = prune_floating(pos, radii, spec.bond_gap, width, height)
    contacts = contacts[keep]
    if keep.sum() < 0.5 * n:
        raise RuntimeError(f"specimen: {n - int(keep.sum())} of {n} particles would be deleted "
                           f"as floating (compaction stress {stats['compaction_stress_Pa']:.3g} "
                           "Pa): the packing did not jam; try another seed")
    pos, radii = pos[keep], radii[keep]
    pos[:, 0] -= pos[:, 0].min()
    pos[:, 1] -= pos[:, 1].min()
    part, bonds, ke = _release(spec, pos, radii, release_steps)
    stats["release_kinetic_energy_J"] = ke
    p = part
    return Specimen(
        spec=spec, particles=part, bond_i=bonds.i.copy(), bond_j=bonds.j.copy(),
        bond_state=bonds.state(),
        width=float((p.pos[:, 0] + p.radius).max() - (p.pos[:, 0] - p.radius).min()),
        height=float((p.pos[:, 1] + p.radius).max() - (p.pos[:, 1] - p.radius).min()),
        seed=int(seed), n_generated=n, n_deleted=int(n - keep.sum()),
        compaction_stress=float(compaction_stress), compaction_contacts=contacts,
        packed_pos=pos, packed_radius=radii,
        stats=stats)
