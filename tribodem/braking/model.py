"""The braking interface of Sha et al. (2022) section 3.2 / figure 8, built on ``tribodem.dem``.

Geometry: one bonded-particle block compacted in a box periodic in x (walls at its bottom
and top, isotropic stress ``compaction_stress`` as in section 3.1), cut along two random
surface profiles into a disc (Q345B, group 1, below) and a pad (Cu-PM, group 2, above):
particles between the profiles are removed, so both surfaces carry asperities and pits;
the pad is then placed with its lowest point ``clearance`` above the disc's highest point:
braking starts by applying the pad to the already sliding disc, the pressure plate
brings it down, and the asperities meet tip first. Parallel bonds join
every same-body pair with surface gap below the bond gap (section 3.1); the bodies are
not bonded to each other.

Boundary conditions (figure 8):
- periodic in x (figure 7 remapping);
- disc: the particles within one mean diameter of its bottom are anchored (FIX_X | FIX_Y):
  fixed in y (the disc's "pressure wall") and, while sliding, driven in -x at the sliding
  speed (PFC applies the disc's linear speed to its particles; the rest of the disc starts
  at the same velocity and follows through bonds and contacts);
- pad: the particles within one mean diameter of its top are held in x (the support wall)
  and pressed in -y by a pressure wall with the target force ``p W t``
  (pressure x cell width x disk thickness, 2D unit thickness): a ``PlaneWall`` in the
  engine's ``"boundary"`` servo mode (``M a = F_target - F_wall``, Lu (2018) eq 3.6) with a
  small mass ``wall_mass_ratio`` x the pad slab mass and no damping, so its time-mean
  force is the target (PFC's gain servo cannot follow the pad after 47 m/s asperity
  impacts; see docs/braking.md);
- pad backing (``backing``): ``"absorbing"`` (default) ties the pad's top layer to the rest
  of the pad (the 10-20 mm of friction material and its steel back plate the cell omits)
  by Lysmer-Kuhlemeyer dashpots: normal ``rho c_p`` relative to the pressure plate and
  shear ``rho c_s`` relative to the support (vx = 0) per unit area, so stress waves leave
  the cell instead of reflecting from a free back face as tension; ``"support"`` is the
  former rigid x-hold (FIX_X) with a free face in y;
- optional uniform temperature boundary from a curve (section 3.2 eq 13, figure 9).
"""

from __future__ import annotations

import functools
import math
import warnings
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
from numba import njit

from tribodem.dem import Box, Material, ParallelBonds, ParticleState, PlaneWall, Simulation
from tribodem.dem import compiled as dem_compiled
from tribodem.dem.space import column_order
from tribodem.dem.state import FIX_X, FIX_Y
from tribodem.materials.library import CU_PM, Q345B, MaterialSpec
from tribodem.materials.specimen import compact_by_radius_scaling

DISC, PAD = 1, 2  # particle groups
#: group of the particles that left the interface through the debris outlet (``outlet``)
EJECTED = 3
PHI0 = 0.35  # area fraction of the random placement
PHI_TARGET = 0.82  # area fraction of the particle count before the stress adjustment
MASS_SCALE = 1.0e4  # density multiplier during compaction only (geometry only is kept)
#: share of a compacted packing's particles with no neighbour within the bond gap (they get
#: no bond and are dropped from the cell) above which ``build_interface`` reports the
#: packing as loose: 2D jammed polydisperse packings hold ~3-5 % rattlers; the default
#: cell 2.9-4.0 % (seeds 0-3)
LOOSE_MAX = 0.05

#: areal mass (kg/m^2) of what the cell omits above the pad: the seed gives no pad or
#: back-plate size; assumed 15 mm of Cu-PM friction material (5250 kg/m^3) on a 6 mm steel
#: back plate (7850 kg/m^3), typical of high-power (railway) disc-brake pads:
#: 15e-3 x 5250 + 6e-3 x 7850 = 126 kg/m^2, ~270 x the default 108 um pad slab of the cell
PLATE_AREAL_MASS = 126.0

#: micro-parameters (E_c Pa, kratio) from ``tribodem calibrate`` (full, 8 specimens), see
#: docs/braking.md "Results": table 1 E and nu within 1.1% in tribodem's assembly
CALIBRATED = {"q345b": (1.99e11, 1.23), "cu-pm": (1.75e11, 1.20)}


def materials(micro: str = "calibrated") -> tuple[MaterialSpec, MaterialSpec]:
    """(disc, pad) specs: ``"calibrated"`` (E_c, kratio of ``tribodem calibrate``) or
    ``"table3"`` (the seed's table 3 values, uncalibrated in tribodem's assembly)."""
    if micro == "table3":
        return Q345B, CU_PM
    if micro == "calibrated":
        return (Q345B.with_micro(*CALIBRATED["q345b"]), CU_PM.with_micro(*CALIBRATED["cu-pm"]))
    raise ValueError(f"micro = {micro!r}: must be 'calibrated' or 'table3'")


@dataclass
class Geometry:
    """Sizes (m) of the interface cell: periodic ``width``, disc and pad heights,
    roughness ``amplitude`` (max |profile|) with sine modes k = ``first_mode``..``modes``
    (wavelengths W/k), packing ``seed``. Start: the pad's lowest point ``clearance`` above the
    disc's highest point (the pad is applied to the sliding disc), ``compaction_stress``
    (Pa) of the packing."""

    width: float = 360e-6
    disc_height: float = 100e-6
    pad_height: float = 100e-6
    amplitude: float = 10e-6
    modes: int = 4
    first_mode: int = 1
    clearance: float = 5e-8
    seed: int = 0
    compaction_stress: float = 1.0e6

    def check(self, rmax: float) -> None:
        """Refuse sizes the model cannot use (ValueError naming the field)."""
        for name in ("width", "disc_height", "pad_height"):
            v = getattr(self, name)
            if not v >= 8 * rmax:
                raise ValueError(f"geometry: {name} = {v!r} m: must be >= 8 x the largest "
                                 f"radius ({8 * rmax:.3g} m)")
        if not 0 <= self.amplitude <= 0.3 * min(self.disc_height, self.pad_height):
            raise ValueError(f"geometry: amplitude = {self.amplitude!r} m: must be in "
                             "[0, 0.3 x the smaller body height]")
        if not 1 <= self.modes <= 64:
            raise ValueError(f"geometry: modes = {self.modes!r}: must be in [1, 64]")
        if not 1 <= self.first_mode <= self.modes:
            raise ValueError(f"geometry: first_mode (config: roughness_first_mode) = "
                             f"{self.first_mode!r}: must be in [1, modes = {self.modes}]")
        if not self.clearance >= 0:
            raise ValueError(f"geometry: clearance = {self.clearance!r} m: must be >= 0")


@dataclass
class Block:
    """A compacted block periodic in x and y (``compact_periodic(periodic_y=True)``):
    centres ``pos`` (m, y in [0, ``height``)), ``radius`` (m), the periods (m)."""

    pos: np.ndarray
    radius: np.ndarray
    width: float
    height: float


@dataclass
class Interface:
    """A built interface: the simulation, its bonds and the pressure wall, plus the
    bookkeeping the measurements need (groups, anchors, packing fraction)."""

    sim: Simulation
    bonds: ParallelBonds
    wall: PlaneWall
    disc: MaterialSpec
    pad: MaterialSpec
    geometry: Geometry
    anchor_disc: np.ndarray
    anchor_pad: np.ndarray
    phi: dict[int, float]
    target_force: float
    stats: dict[str, float] = field(default_factory=dict)
    backing: PadBacking | None = None
    #: the compacted block the bodies were cut from (``block = "periodic"`` only: the
    #: source of the feed, ``braking.feed``) and each particle's place in it (m, (n, 3);
    #: y in the block's periodic continuation, the pad before it was lowered)
    block: Block | None = None
    block_pos: np.ndarray | None = None
    #: depth (m) of the anchored layers: one mean particle diameter of the cell
    anchor_depth: float = 0.0

    @property
    def width(self) -> float:
        """Periodic cell width (m)."""
        return float(self.sim.box.length[0])

    @property
    def anchors(self) -> np.ndarray:
        """Mask of the anchored particles (disc bottom layer and pad top layer)."""
        return self.anchor_disc | self.anchor_pad


def _place_periodic(rng: np.random.Generator, radii: np.ndarray, w: float, h: float,
                    periodic_y: bool = False) -> np.ndarray:
    """Random sequential placement without overlap, periodic in x, in [0, w) x [r, h - r]
    (``periodic_y``: periodic in y too, in [0, w) x [0, h))."""
    pos = np.zeros((radii.size, 3))
    for k, r in enumerate(radii):
        for _ in range(20_000):
            x = rng.uniform(0.0, w)
            y = rng.uniform(0.0, h) if periodic_y else rng.uniform(r, h - r)
            dx = pos[:k, 0] - x
            dx -= w * np.rint(dx / w)
            dy = pos[:k, 1] - y
            if periodic_y:
                dy -= h * np.rint(dy / h)
            if np.all(dx * dx + dy * dy > (radii[:k] + r) ** 2):
                break
        else:
            raise RuntimeError(f"interface: could not place particle {k} of {radii.size}")
        pos[k, 0], pos[k, 1] = x, y
    return pos


def compact_periodic(spec: MaterialSpec, width: float, height: float, seed: int,
                     stress: float = 1.0e6, max_iter: int = 40, gap: float | None = None,
                     periodic_y: bool = False
                     ) -> tuple[np.ndarray, np.ndarray, dict[str, float]]:
    """A dense packing periodic in x between two walls (y = 0, y = ``height``; or
    periodic in y too, ``periodic_y`` below): random
    placement, radius expansion in 10 stages, then a uniform radius scale (bracketing
    bisection) until the mean wall stress is within a factor 2 of ``stress`` (Pa; section
    3.1, PFC's isotropic-stress installation). Frictionless, mass-scaled, local damping
    0.7. Every relaxation runs max(1, round(width / height)) times its nominal steps: the
    walls set the vertical stress only, and across a periodic cell wider than it is high
    the horizontal packing closes in a time that grows with the width (an 864-um cell at
    the nominal steps: 8-25 % of its particles without a neighbour within the bond gap,
    and a wall stress that fell from ~1 MPa to 7-26 kPa when relaxed further, i.e. the
    bisection had read transients). Stats: ``loose_fraction`` (particles without a
    neighbour within ``gap``, m; default the spec's bond gap) and ``relax_scale``.
    A cell much taller than wide also closes slowly (216 x 592 um: 5-50 % loose in 5 of 8
    seeds): while more than ``LOOSE_MAX`` of the particles are loose, the compaction is
    made again from the same placement with relaxations 2x, 4x, 8x longer (packings that
    were jammed at once are unchanged). ``periodic_y``: a block periodic in y too (no
    walls; the stress is the contacts' mean normal stress, the virial sum of N d over
    2 W H t), so that copies of it stacked in y continue it without a seam (the feed of
    fresh body, ``braking.feed``); y in [0, ``height``). Returns (pos, radii, stats)."""
    gap = spec.bond_gap if gap is None else gap
    for longer in (1, 2, 4, 8):
        pos, radii, stats = compact_once(spec, width, height, seed, stress, max_iter, gap,
                                          longer, periodic_y)
        if stats["loose_fraction"] <= LOOSE_MAX:
            break
    return pos, radii, stats


def _relax(pos: np.ndarray, r: np.ndarray, steps: int, *, mat: Material, box: Box,
           width: float, height: float, thickness: float, scale: int, periodic_y: bool
           ) -> tuple[np.ndarray, float]:
    """One relaxation of the compaction (``compact_by_radius_scaling``'s callback): the
    disks at ``pos`` with radii ``r`` (m) for ``steps`` x ``scale`` steps between two
    walls (or periodic in y); returns the positions and the mean stress (Pa) on the walls
    (periodic: the virial stress)."""
    t = thickness
    walls = [] if periodic_y else [PlaneWall([0, 0, 0], [0, 1, 0], name="bottom"),
                                   PlaneWall([0, height, 0], [0, -1, 0], name="top")]
    part = ParticleState(dim=2, pos=pos, radius=r, density=mat.density, thickness=t)
    sim = Simulation(part, [mat], box, walls=walls, local_damping=0.7, dt_safety=0.2)
    sim.step(steps * scale)
    if periodic_y:
        c = sim.contacts()
        dist = r[c["i"]] + r[c["j"]] - c["overlap"]
        sig = float((c["normal_force"] * dist).sum()) / (2.0 * width * height * t)
    else:
        sig = 0.5 * (walls[0].normal_force + walls[1].normal_force) / (width * t)
    return sim.p.pos.copy(), sig


def compact_once(spec: MaterialSpec, width: float, height: float, seed: int, stress: float,
                 max_iter: int, gap: float, longer: int, periodic_y: bool = False
                 ) -> tuple[np.ndarray, np.ndarray, dict[str, float]]:
    """One compaction of ``compact_periodic`` with relaxations ``longer`` x its nominal
    steps."""
    rng = np.random.default_rng(seed)
    rmin, rmax = spec.radius_range
    mean_area = math.pi * (rmin * rmin + rmin * rmax + rmax * rmax) / 3.0
    n = int(round(PHI_TARGET * width * height / mean_area))
    radii = np.sort(rng.uniform(rmin, rmax, size=n))[::-1].copy()
    f0 = math.sqrt(PHI0 / PHI_TARGET)
    pos = _place_periodic(rng, radii * f0, width, height, periodic_y)
    t = spec.thickness
    mat = Material(name="compaction", young=spec.young, poisson=spec.poisson,
                   density=spec.density * MASS_SCALE, friction=0.0,
                   effective_modulus=spec.effective_modulus, kratio=1.0, beta_n=spec.beta_n,
                   law="linear")
    if periodic_y:
        box = Box([0.0, 0.0, 0.0], [width, height, 0.0], [True, True, False])
    else:
        box = Box([0.0, -2 * rmax, 0.0], [width, height + 2 * rmax, 0.0], [True, False, False])

    scale = max(1, round(width / height)) * longer * (4 if periodic_y else 1)
    relax = functools.partial(_relax, mat=mat, box=box, width=width, height=height,
                              thickness=t, scale=scale, periodic_y=periodic_y)
    pos, alpha, sig, n_iter = compact_by_radius_scaling(
        relax, pos, radii, f0, stress, spec.effective_modulus, max_iter, growth=1.004)
    if periodic_y:
        pos[:, 1] = np.mod(pos[:, 1], height)
    i, j, _ = pairs_periodic(pos, radii * alpha, width, gap,
                              height if periodic_y else None)
    deg = np.bincount(np.concatenate([i, j]), minlength=n)
    return pos, radii * alpha, {"compaction_iterations": float(n_iter),
                                "compaction_stress_Pa": float(sig),
                                "radius_scale": float(alpha), "generated": float(n),
                                "relax_scale": float(scale),
                                "loose_fraction": float(np.count_nonzero(deg == 0)) / n}


def rough_profile(rng: np.random.Generator, width: float, amplitude: float, modes: int,
                  first: int = 1) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A random periodic profile: sine modes k = first..modes (wavelength W/k), amplitudes
    U(0.3, 1)/k (proportional to the wavelength), random phases, scaled so max |h| =
    ``amplitude``. Returns (k, amplitude per mode, phase per mode) for
    ``profile_height``. A cell n times wider with ``first`` = n and ``modes`` n times
    larger has the narrow cell's wavelengths and relative amplitudes (its asperities);
    with ``first`` = 1 its longest waves take the amplitude and the asperities shrink ~n
    times."""
    k = np.arange(first, modes + 1, dtype=float)
    a = rng.uniform(0.3, 1.0, size=k.size) / k
    ph = rng.uniform(0.0, 2.0 * math.pi, size=k.size)
    x = np.linspace(0.0, width, 2049)
    h = (a[None, :] * np.sin(2 * math.pi * k[None, :] * x[:, None] / width + ph)).sum(axis=1)
    scale = amplitude / max(float(np.abs(h).max()), 1e-300)
    return k, a * scale, ph


def profile_height(x: np.ndarray, width: float, prof: tuple[np.ndarray, ...]) -> np.ndarray:
    """Height (m) of a ``rough_profile`` at ``x`` (m)."""
    k, a, ph = prof
    return (a[None, :] * np.sin(2 * math.pi * k[None, :] * np.asarray(x)[:, None] / width
                                + ph)).sum(axis=1)


def pairs_periodic(pos: np.ndarray, radius: np.ndarray, width: float, gap: float,
                   height: float | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pairs (i < j) with surface gap < ``gap`` (m), periodic in x (and in y with period
    ``height`` when given); returns (i, j, gap)."""
    if height is None:
        y0 = pos[:, 1].min()
        span = float(np.ptp(pos[:, 1])) + 10 * float(radius.max()) + 1.0
        pts = np.stack([np.mod(pos[:, 0], width), pos[:, 1] - y0 + 1e-9], axis=1)
    else:
        span = height
        pts = np.stack([np.mod(pos[:, 0], width), np.mod(pos[:, 1], height)], axis=1)
        pts[pts[:, 1] >= height, 1] = 0.0  # mod's round-off at the period
    from scipy.spatial import cKDTree  # here: 0.3 s to import, which every command paid

    tree = cKDTree(pts, boxsize=[width, span])
    pairs = tree.query_pairs(2.0 * float(radius.max()) + max(gap, 0.0) + 1e-12,
                             output_type="ndarray")
    if pairs.size == 0:
        z = np.zeros(0, dtype=np.int64)
        return z, z.copy(), np.zeros(0)
    i, j = pairs[:, 0].astype(np.int64), pairs[:, 1].astype(np.int64)
    d = pos[j, :2] - pos[i, :2]
    d[:, 0] -= width * np.rint(d[:, 0] / width)
    if height is not None:
        d[:, 1] -= height * np.rint(d[:, 1] / height)
    g = np.linalg.norm(d, axis=1) - radius[i] - radius[j]
    keep = g < gap
    return i[keep], j[keep], g[keep]


@njit(cache=True)
def _dashpots(vel, idx, v_plate, c_n, c_t, ext_force, dv):  # pragma: no cover - numba
    """The backing dashpots of particles ``idx``: ``F_y -= c_n (v_y - v_plate)``,
    ``F_x -= c_t v_x`` into ``ext_force`` (N); ``dv`` gets each ``v_y - v_plate`` (m/s).
    One compiled call instead of numpy's fancy indexing (same operations, same bits)."""
    for k in range(idx.shape[0]):
        p = idx[k]
        d = vel[p, 1] - v_plate
        dv[k] = d
        ext_force[p, 1] -= c_n * d
        ext_force[p, 0] -= c_t * vel[p, 0]


class BackingStep(NamedTuple):
    """``PadBacking``'s compiled form: its dashpots (``idx``, ``c_n``, ``c_t``), the index
    of its wall in ``sim.walls``, the plate's full drive ``target`` (N) and ``out`` =
    [the dashpots' reaction, N] (shared with the braking loop's compiled form)."""

    idx: np.ndarray
    wall: int
    c_n: float
    c_t: float
    target: float
    out: np.ndarray
    dv: np.ndarray


@dem_compiled.register(BackingStep)
@njit(cache=True)
def _backing_step(s, c):  # pragma: no cover - numba
    """``PadBacking.compute`` in the engine's compiled loop (the same operations)."""
    _dashpots(c.vel, s.idx, c.wall_vel[s.wall, 1], s.c_n, s.c_t, c.ext_force, s.dv)
    r = s.c_n * dem_compiled.np_sum(s.dv, s.dv.shape[0])
    s.out[0] = r
    c.wall_par[s.wall, dem_compiled.W_TARGET] = s.target - r
    return 0


def wall_index(sim: Simulation, wall: PlaneWall) -> int:
    """Index of ``wall`` (this object) in ``sim.walls``; ValueError if it is not there."""
    for k, w in enumerate(sim.walls):
        if w is wall:
            return k
    raise ValueError(f"wall '{wall.name}' is not a wall of this simulation")


class PadBacking:
    """Non-reflecting (Lysmer-Kuhlemeyer) backing of the pad's top layer (an engine
    ``Interaction``): the rest of the pad as a semi-infinite elastic medium.

    Each anchored pad particle i of tributary area ``A = W t / n`` (m^2) gets
    ``F_y = -rho c_p A (v_y - v_plate)`` and ``F_x = -rho c_s A v_x`` (N), with the pad's
    table 1 density and the plane-strain wave speeds of its table 1 E and nu. The plate
    feels the reaction of the normal dashpots (momentum is conserved); the shear dashpots
    react on the support. The plate's total force on the pad (contact + dashpots) is
    ``force`` (N, +: pushing the pad down)."""

    def __init__(self, sim: Simulation, wall: PlaneWall, idx: np.ndarray, spec: MaterialSpec,
                 width: float) -> None:
        e, nu, rho = spec.young, spec.poisson, spec.density
        c_p = math.sqrt(e * (1 - nu) / (rho * (1 + nu) * (1 - 2 * nu)))
        c_s = math.sqrt(e / (2 * rho * (1 + nu)))
        area = width * spec.thickness / max(idx.size, 1)
        self.idx = idx
        self.wall = wall
        self.c_n = rho * c_p * area  # N s/m per particle
        self.c_t = rho * c_s * area
        self.target = float(wall.target_force)
        self.reaction = 0.0  # N, the dashpots' push on the plate (+: up, against the load)
        self.c_p, self.c_s = c_p, c_s
        self._dv = np.zeros(idx.size)  # each dashpot's normal speed (m/s), reused
        self._out = np.zeros(1)  # the compiled form's reaction (N)

    def set_anchors(self, idx: np.ndarray) -> None:
        """Move the dashpots to the particles ``idx`` (a new top layer, ``braking.feed``):
        each takes the tributary area ``W t / n`` of the new layer."""
        scale = max(self.idx.size, 1) / max(idx.size, 1)
        self.idx = np.asarray(idx, dtype=np.int64)
        self.c_n *= scale
        self.c_t *= scale
        self._dv = np.zeros(self.idx.size)

    def particles_appended(self, sim: Simulation, n_old: int) -> None:
        """Engine hook: the dashpots keep their particles (``set_anchors`` moves them)."""

    def compute(self, sim: Simulation) -> None:
        """Add the dashpot forces; set the plate's drive to target minus their reaction."""
        if self._dv.size != self.idx.size:
            self._dv = np.zeros(self.idx.size)
        _dashpots(sim.p.vel, self.idx, float(self.wall.velocity[1]), self.c_n, self.c_t,
                  sim.ext_force, self._dv)
        self.reaction = float(self.c_n * self._dv.sum())  # numpy's sum, as before
        self.wall.target_force = self.target - self.reaction

    def compiled(self, sim: Simulation) -> BackingStep:
        """The compiled form (``BackingStep``, see ``tribodem.dem.compiled``)."""
        if self._dv.size != self.idx.size:
            self._dv = np.zeros(self.idx.size)
        self._out[0] = self.reaction
        return BackingStep(self.idx, wall_index(sim, self.wall), float(self.c_n),
                           float(self.c_t), float(self.target), self._out, self._dv)

    def after_compiled(self, sim: Simulation, state: BackingStep) -> None:
        """The reaction of the compiled loop's last step (the plate's drive is a wall
        state, copied back by the engine)."""
        self.reaction = float(state.out[0])

    @property
    def reaction_buffer(self) -> np.ndarray:
        """The one-entry array (N) the compiled form writes the dashpots' reaction to; a
        compiled piece that sums the plate force reads it in the same step."""
        return self._out

    @property
    def force(self) -> float:
        """Total force of the plate on the pad now (N): wall contacts + dashpots."""
        return float(self.wall.normal_force + self.reaction)

    def state(self) -> dict[str, np.ndarray]:
        """For checkpoints: the dashpots' last reaction and the plate's drive (N)."""
        return {"backing": np.array([self.reaction, float(self.wall.target_force)])}

    def set_state(self, s: dict[str, np.ndarray]) -> None:
        """Restore what ``state`` returned."""
        self.reaction, self.wall.target_force = (float(x) for x in s["backing"])


def _check_build(pressure_Pa: float, wall_mass_ratio: float, backing: str,
                 plate_areal_mass: float | None, block: str) -> None:
    """``ValueError`` naming the first argument of :func:`build_interface` it cannot use."""
    if block not in ("walls", "periodic"):
        raise ValueError(f"block = {block!r}: must be 'walls' or 'periodic'")
    if not pressure_Pa > 0:
        raise ValueError(f"pressure_Pa = {pressure_Pa!r}: must be > 0 Pa")
    if not 0 < wall_mass_ratio <= 1000:
        raise ValueError(f"wall_mass_ratio = {wall_mass_ratio!r}: must be in (0, 1000]")
    if plate_areal_mass is not None and not plate_areal_mass > 0:
        raise ValueError(f"plate_areal_mass = {plate_areal_mass!r}: must be > 0 kg/m^2")
    if backing not in ("absorbing", "support"):
        raise ValueError(f"backing = {backing!r}: must be 'absorbing' or 'support'")


def _cut_bodies(pos: np.ndarray, radii: np.ndarray, g: Geometry, gap: float
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray,
                           np.ndarray, float, float]:
    """The compacted block (positions, radii, m) cut along two random profiles into the
    disc (below) and the pad (above), the particles between them removed, the same-body
    pairs within the bond gap ``gap`` (m) bonded, the particles left without a bond
    dropped. Returns positions, radii, groups, each particle's index in the block, the
    bonds' ends (i, j), the pad's lift (m: the profiles' largest overlap) and the count
    of particles removed."""
    w = g.width
    rng = np.random.default_rng(g.seed + 7919)
    prof_d = rough_profile(rng, w, g.amplitude, g.modes, g.first_mode)
    prof_p = rough_profile(rng, w, g.amplitude, g.modes, g.first_mode)
    x, y = pos[:, 0], pos[:, 1]
    y_mid = g.disc_height + g.amplitude
    hd = y_mid + profile_height(x, w, prof_d)
    xs = np.linspace(0.0, w, 2049)
    lift = float((profile_height(xs, w, prof_d) - profile_height(xs, w, prof_p)).max())
    hp = y_mid + lift + profile_height(x, w, prof_p)
    is_disc = y < hd
    is_pad = y > hp
    keep = is_disc | is_pad
    src = np.flatnonzero(keep)  # each kept particle's index in the block
    pos, radii, is_pad = pos[keep], radii[keep], is_pad[keep]
    group = np.where(is_pad, PAD, DISC).astype(np.int32)
    # bonds: same-body pairs within the bond gap (section 3.1); bodies not bonded together
    bi, bj, _ = pairs_periodic(pos, radii, w, gap)
    same = group[bi] == group[bj]
    bi, bj = bi[same], bj[same]
    # drop particles without a bond (floaters of the cut)
    deg = np.bincount(np.concatenate([bi, bj]), minlength=radii.size)
    ok = deg > 0
    idx = np.cumsum(ok) - 1
    keep2 = ok[bi] & ok[bj]
    bi, bj = idx[bi[keep2]], idx[bj[keep2]]
    removed = float(keep.size - keep.sum() + (~ok).sum())
    return pos[ok], radii[ok], group[ok], src[ok], bi, bj, lift, removed


def build_interface(geometry: Geometry, pressure_Pa: float, micro: str = "calibrated",
                    wall_mass_ratio: float = 0.05, dt_safety: float = 0.3,
                    local_damping: float = 0.0, backing: str = "absorbing",
                    plate_areal_mass: float | None = None, block: str = "walls") -> Interface:
    """Build the figure 8 interface (see the module docstring) with the pressure target
    ``pressure_Pa x width x thickness`` (N). The plate's mass is ``plate_areal_mass``
    (kg/m^2) x W x t when given (the omitted pad and back plate), else
    ``wall_mass_ratio`` x the cell's pad mass. Particles start at rest; ``start_sliding``
    sets the disc moving, the pressure plate then applies the pad. ``block``: the block
    the bodies are cut from is compacted between two walls (``"walls"``, section 3.1) or
    periodic in y too (``"periodic"``: the disc's bottom face and the pad's top face are
    then one seamless plane of the block, so copies of it continue either body without a
    seam: the feed, ``braking.feed``)."""
    _check_build(pressure_Pa, wall_mass_ratio, backing, plate_areal_mass, block)
    disc, pad = materials(micro)
    rmax = max(disc.radius_range[1], pad.radius_range[1])
    geometry.check(rmax)
    g = geometry
    w = g.width
    total = g.disc_height + g.pad_height + 2.0 * g.amplitude
    # one block, compacted with the disc's stiffness (both materials differ by ~12% in E_c;
    # the packing geometry only is kept)
    gap = max(disc.bond_gap, pad.bond_gap)
    periodic = block == "periodic"
    pos, radii, stats = compact_periodic(disc, w, total, g.seed, g.compaction_stress, gap=gap,
                                         periodic_y=periodic)
    # numbered column by column along the sliding (the packing itself unchanged): the
    # step's passes then read nearby memory (BENCHMARKS.md, "Braking cell")
    order = column_order(pos, 0.0, 2.0 * rmax)
    pos, radii = pos[order], radii[order]
    blk = Block(pos.copy(), radii.copy(), w, total) if periodic else None
    if stats["loose_fraction"] > LOOSE_MAX:
        warnings.warn(f"interface packing (seed {g.seed}, width {w:.4g} m): "
                      f"{100 * stats['loose_fraction']:.1f} % of the particles have no "
                      f"neighbour within the bond gap and are dropped (a jammed packing: "
                      f"<= {100 * LOOSE_MAX:.0f} %)", stacklevel=2)
    phi_c = float(math.pi * (radii**2).sum() / (w * total))
    pos, radii, group, src, bi, bj, lift, removed = _cut_bodies(pos, radii, g, gap)
    block_pos = blk.pos[src].copy() if blk is not None else None
    # pad down rigidly until the closest disc-pad surface gap is the clearance
    pd = group == PAD
    # braking starts with the pad applied to the already sliding disc: its lowest point a
    # clearance above the disc's highest point
    gap = float((pos[pd, 1] - radii[pd]).min() - (pos[~pd, 1] + radii[~pd]).max())
    pos[pd, 1] -= gap - g.clearance
    # anchors: one mean diameter from the outer faces
    dm = 2.0 * float(radii.mean())
    bottom = float((pos[~pd, 1] - radii[~pd]).min())
    top = float((pos[pd, 1] + radii[pd]).max())
    anchor_disc = (~pd) & (pos[:, 1] - radii < bottom + dm)
    anchor_pad = pd & (pos[:, 1] + radii > top - dm)
    pad_fix = FIX_X if backing == "support" else 0
    fixed = np.where(anchor_disc, FIX_X | FIX_Y, 0) | np.where(anchor_pad, pad_fix, 0)
    dens = np.where(pd, pad.density, disc.density)
    part = ParticleState(dim=2, pos=pos, radius=radii, density=dens, thickness=disc.thickness,
                         mat=np.where(pd, 1, 0), group=group, fixed=fixed)
    target = pressure_Pa * w * disc.thickness
    pad_mass = float((dens[pd] * math.pi * radii[pd] ** 2).sum() * disc.thickness)
    plate_mass = (wall_mass_ratio * pad_mass if plate_areal_mass is None
                  else plate_areal_mass * w * disc.thickness)
    wall = PlaneWall([0.0, top, 0.0], [0.0, -1.0, 0.0], material=1, mode="boundary",
                     target_force=target, servo_mass=plate_mass,
                     name="pressure")
    margin = 4.0 * rmax + 2.0 * g.amplitude
    box = Box([0.0, bottom - margin, 0.0], [w, top + margin, 0.0], [True, False, False])
    sim = Simulation(part, [disc.contact_material(), pad.contact_material()], box,
                     walls=[wall], dt_safety=dt_safety, local_damping=local_damping)
    bi, bj = np.minimum(bi, bj), np.maximum(bi, bj)
    bond_order = np.lexsort((bj, bi))  # bonds in particle order: nearby memory too
    bi, bj = bi[bond_order], bj[bond_order]
    on_pad = group[bi] == PAD
    pick = lambda a, b: np.where(on_pad, b, a)  # noqa: E731
    bonds = ParallelBonds(sim, bi, bj, disc.bond_lambda,
                          pick(disc.bond_E, pad.bond_E), pick(disc.bond_kr, pad.bond_kr),
                          pick(disc.tensile_strength, pad.tensile_strength),
                          pick(disc.cohesion, pad.cohesion))
    sim.add_interaction(bonds)
    back = None
    if backing == "absorbing":
        back = PadBacking(sim, wall, np.flatnonzero(anchor_pad), pad, w)
        sim.add_interaction(back)
    stats.update({"removed_by_cut": removed,
                  "particles": float(part.n), "bonds": float(bonds.n_bonds),
                  "bonds_per_particle": 2.0 * bonds.n_bonds / part.n,
                  "profile_lift_m": lift, "packing_fraction": phi_c,
                  "pad_mass_kg": pad_mass, "plate_mass_kg": plate_mass})
    phi = {DISC: phi_c, PAD: phi_c}
    return Interface(sim=sim, bonds=bonds, wall=wall, disc=disc, pad=pad, geometry=g,
                     anchor_disc=anchor_disc, anchor_pad=anchor_pad, phi=phi,
                     target_force=target, stats=stats, backing=back, block=blk,
                     block_pos=block_pos, anchor_depth=dm)


def cross_contacts(iface: Interface) -> int:
    """Active disc-pad contacts (N > 0) between particles of the two bodies' groups."""
    c = iface.sim.contacts()
    g = iface.sim.p.group
    return int(np.count_nonzero((g[c["i"]] != g[c["j"]]) & (c["normal_force"] > 0)))


def start_sliding(iface: Interface, speed_m_s: float) -> None:
    """Set the disc moving in -x at ``speed_m_s`` (its anchored bottom layer keeps it)."""
    if not speed_m_s > 0:
        raise ValueError(f"speed_m_s = {speed_m_s!r}: must be > 0 m/s")
    p = iface.sim.p
    d = p.group == DISC
    p.vel[d, 0] = -speed_m_s
    p.vel[iface.anchor_disc, 1] = 0.0
    p.vel[iface.anchor_pad, 0] = 0.0


def plate_force(iface: Interface) -> float:
    """Total force (N) the pressure plate applies to the pad now: wall contacts plus the
    backing dashpots' reaction (absorbing backing)."""
    if iface.backing is not None:
        return iface.backing.force
    return float(iface.wall.normal_force)

