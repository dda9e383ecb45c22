"""The debris third body of the FE-DE fretting model (Lu (2018) sections 3.2.6-3.2.7, 5.4).

Per generation the worn volume of both bodies becomes debris particles (eq 3.10, N_d =
V / (pi d^3 / 6), d = 0.6 um, the fractional remainder carried to the next generation so
the created volume tracks the worn volume to within one particle), placed at random worn
sites (probability proportional to the local worn depth) and tracked across cycles. In a
DE phase (every K cycles) the first bodies are rigid height-map surfaces at the cycle's
loading position (offset 0), the debris is laid on the lower surface as the single layer
the seed reports after compression (figure 3.8; particles that would overlap are stacked),
each particle a rigid clump of one of the three shapes of figure 3.6 (spherical, chunk,
rubbing; :func:`tribodem.dem.clumps.debris_template`, solid volume pi d^3 / 6) at a random
orientation,
and the upper surface is lowered by the boundary-moving servo (eqs 3.2-3.6) until the
debris carries the target load: the first-body pressure at the debris sites, bilinear
shape-function interpolation of the grid values (eqs 3.11-3.15) times each particle's
projected area, capped per grid cell by the cell area (particles cannot carry more than
the area they cover) and in total by ``target_cap`` x the applied load. The forces the
particles put on the lower surface are spread back to the grid nodes (the transpose of
the same bilinear weights, conservative) and handed to the first-body solver as a
prescribed pressure (``HalfSpaceSolver.set_debris_pressure``). A particle is ejected
(leaves the record, its volume counted) when it leaves the solver window.

Assumptions, stated in every summary: gravity is left out (weight ~1e-14 N against contact
forces ~1e-4 N); density scaling multiplies the debris density (static equilibrium does
not depend on it; the simulated DE time does); the debris layer travels with the contact
through the cycle (its pressure map is held in the window frame); the energy the debris
dissipates is not counted as first-body wear.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
from numba import njit
from numpy.typing import NDArray

from tribodem.dem import Box, Material, Simulation
from tribodem.dem.clumps import (
    DEBRIS_SHAPES,
    ClumpTemplate,
    debris_template,
    make_clumps,
    quat_to_matrix,
    random_quaternions,
)
from tribodem.dem.surfaces import HeightMapSurface, bilinear_weights
from tribodem.materials.en24t import EN24T

log = logging.getLogger(__name__)
#: seconds between two notes of a DE phase's progress (INFO: a phase takes minutes)
DE_NOTE_EVERY_S = 20.0

SHAPES = DEBRIS_SHAPES  # spherical, chunk, rubbing (seed figure 3.6; tribodem.dem.clumps)


@dataclass(frozen=True)
class DebrisSettings:
    """Debris and DE-phase parameters (SI; Lu (2018) section 3.2.6 defaults)."""

    diameter: float = 0.6e-6  #: volume-equivalent diameter d of eq 3.10, m
    shares: tuple[float, float, float] = (1 / 3, 1 / 3, 1 / 3)  #: spherical, chunk, rubbing
    volume_correction: float = 1.0  #: the seed's 0.77 over-estimate correction (optional)
    density: float = 7850.0  #: kg/m^3 (EN24T)
    young: float = EN24T.young  #: Pa (seed table 5.1)
    poisson: float = EN24T.poisson
    cor: float = 0.72  #: coefficient of restitution (Marinack et al., seed 3.2.6)
    friction: float = 0.6
    rolling_friction: float = 0.001
    density_scaling: float = 1.0  #: mass scaling of the DE phase (reported)
    local_damping: float = 0.7  #: PFC local damping of the DE phase (quasi-static)
    tolerance: float = 1e-4  #: servo: relative load error at equilibrium
    max_steps: int = 200_000  #: DE steps per phase before giving up (reported)
    ramp_steps: int = 10_000  #: the servo target rises linearly over these steps
    target_cap: float = 0.9  #: the debris carries at most this fraction of the load
    seed: int = 0

    def __post_init__(self) -> None:
        checks: list[tuple[str, Any, bool, str]] = [
            ("diameter", self.diameter, self.diameter > 0, "> 0 m"),
            ("volume_correction", self.volume_correction, 0 < self.volume_correction <= 2,
             "in (0, 2]"),
            ("density", self.density, self.density > 0, "> 0 kg/m^3"),
            ("young", self.young, self.young > 0, "> 0 Pa"),
            ("poisson", self.poisson, -1 < self.poisson < 0.5, "in (-1, 0.5)"),
            ("cor", self.cor, 0 < self.cor <= 1, "in (0, 1]"),
            ("friction", self.friction, self.friction >= 0, ">= 0"),
            ("rolling_friction", self.rolling_friction, self.rolling_friction >= 0, ">= 0"),
            ("density_scaling", self.density_scaling, self.density_scaling >= 1, ">= 1"),
            ("local_damping", self.local_damping, 0 <= self.local_damping < 1, "in [0, 1)"),
            ("tolerance", self.tolerance, 0 < self.tolerance < 0.1, "in (0, 0.1)"),
            ("max_steps", self.max_steps, self.max_steps >= 100, ">= 100"),
            ("ramp_steps", self.ramp_steps, 0 <= self.ramp_steps < self.max_steps,
             "in [0, max_steps)"),
            ("target_cap", self.target_cap, 0 < self.target_cap < 1, "in (0, 1)"),
        ]
        for name, value, ok, rule in checks:
            if not ok:
                raise ValueError(f"debris.{name} = {value!r}: must be {rule}")
        sh = tuple(float(s) for s in self.shares)
        if len(sh) != 3 or min(sh) < 0 or not math.isclose(sum(sh), 1.0, rel_tol=1e-9):
            raise ValueError(f"debris.shares = {self.shares!r}: must be 3 fractions >= 0 "
                             f"summing to 1 ({', '.join(SHAPES)})")

    @property
    def particle_volume(self) -> float:
        """Volume of one debris particle, pi d^3 / 6, m^3 (eq 3.10)."""
        return math.pi * self.diameter**3 / 6.0


def particle_count(volume: float, diameter: float, correction: float = 1.0) -> float:
    """Eq 3.10: number of debris particles N_d = c V / (pi d^3 / 6) (not rounded)."""
    return correction * volume / (math.pi * diameter**3 / 6.0)


# --------------------------------------------------------------------- eqs 3.11-3.15
def shape_function_coefficients(xn: NDArray[np.float64], yn: NDArray[np.float64],
                                fn: NDArray[np.float64]) -> NDArray[np.float64]:
    """a_1..a_4 of eqs 3.11-3.14 from the four nodes (X_k, Y_k, force_k) of one element."""
    a = np.stack([np.ones(4), xn, yn, xn * yn], axis=1)
    return np.linalg.solve(a, fn)


def interpolate(field: NDArray[np.float64], x: NDArray[np.float64], y: NDArray[np.float64],
                x0: float, y0: float, dx: float, dy: float) -> NDArray[np.float64]:
    """Eq 3.15: the grid field (nodal values) at points (x, y) (0 outside the grid)."""
    ii, jj, w = bilinear_weights(x, y, x0, y0, dx, dy, field.shape)
    return (field[ii, jj] * w).sum(axis=1)


def spread(values: NDArray[np.float64], x: NDArray[np.float64], y: NDArray[np.float64],
           x0: float, y0: float, dx: float, dy: float, shape: tuple[int, int]
           ) -> NDArray[np.float64]:
    """Point values (forces, N) onto grid nodes with the same bilinear weights (the
    transpose of :func:`interpolate`; conserves the sum for points inside the grid)."""
    ii, jj, w = bilinear_weights(x, y, x0, y0, dx, dy, shape)
    out = np.zeros(shape)
    np.add.at(out, (ii.ravel(), jj.ravel()), (w * np.asarray(values, float)[:, None]).ravel())
    return out


# --------------------------------------------------------------------- placement
@njit(cache=True)
def _stack_layers(x, y, d, lo_x, lo_y, ncx, ncy):
    """Greedy layer index per particle (in order): one more than the highest layer among
    earlier particles closer than ``d`` in plan view, 0 if none (no 3-D overlap)."""
    n = x.shape[0]
    head = -np.ones(ncx * ncy, dtype=np.int64)
    nxt = -np.ones(n, dtype=np.int64)
    layer = np.zeros(n, dtype=np.int64)
    d2 = d * d
    for i in range(n):
        cx = min(max(int((x[i] - lo_x) / d), 0), ncx - 1)
        cy = min(max(int((y[i] - lo_y) / d), 0), ncy - 1)
        top = -1
        for a in range(max(cx - 1, 0), min(cx + 2, ncx)):
            for b in range(max(cy - 1, 0), min(cy + 2, ncy)):
                j = head[a * ncy + b]
                while j >= 0:
                    dxp = x[i] - x[j]
                    dyp = y[i] - y[j]
                    if dxp * dxp + dyp * dyp < d2 and layer[j] > top:
                        top = layer[j]
                    j = nxt[j]
        layer[i] = top + 1
        c = cx * ncy + cy
        nxt[i] = head[c]
        head[c] = i
    return layer


def stack_layers(xy: NDArray[np.float64], d: float) -> NDArray[np.int64]:
    """Layer index per particle so that particles laid at z = r + layer x d do not
    overlap (in the given order)."""
    if xy.shape[0] == 0:
        return np.zeros(0, dtype=np.int64)
    lo = xy.min(axis=0)
    nc = np.maximum(((xy.max(axis=0) - lo) / d).astype(np.int64) + 1, 1)
    return _stack_layers(xy[:, 0].copy(), xy[:, 1].copy(), d, lo[0], lo[1], int(nc[0]),
                         int(nc[1]))


def spread_single_layer(xy: NDArray[np.float64], d: float, jump: float,
                        rng: np.random.Generator, rounds: int = 60) -> NDArray[np.float64]:
    """Move particles that overlap earlier ones in plan view to random spots near where
    they were (random sequential addition; the reach starts at ``jump`` m and grows 1.5x
    every 5 rounds where the layer is crowded), so they lie as one layer; any still
    overlapping after ``rounds`` are left to be stacked."""
    xy = xy.copy()
    for k in range(rounds):
        bad = stack_layers(xy, d) > 0
        if not bad.any():
            break
        reach = jump * 1.5 ** (k // 5)
        xy[bad] += rng.uniform(-reach, reach, (int(bad.sum()), 2))
    return xy


# --------------------------------------------------------------------- the debris record
@dataclass
class DebrisField:
    """The debris particles between the first bodies (window frame at offset 0, m)."""

    settings: DebrisSettings = field(default_factory=DebrisSettings)
    xy: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 2)))
    shape: NDArray[np.int64] = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    born: NDArray[np.int64] = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    created: int = 0
    ejected: int = 0
    worn_volume: float = 0.0  #: worn volume handed to the debris so far, m^3
    _carry: float = 0.0

    def __post_init__(self) -> None:
        self.rng = np.random.default_rng(self.settings.seed)

    @property
    def n(self) -> int:
        """Particles in the record."""
        return int(self.xy.shape[0])

    @property
    def created_volume(self) -> float:
        """Volume of all particles created, m^3."""
        return self.created * self.settings.particle_volume

    def generate(self, cycle: int, sites: list[tuple[NDArray[np.float64],
                 NDArray[np.float64], NDArray[np.float64]]], cell_area: float) -> int:
        """New particles from newly worn depth maps; returns their number.

        ``sites``: (worn depth increment [nx, ny] m, x [nx], y [ny]) per body, in the
        window frame at offset 0. Eq 3.10 with the remainder carried over.
        """
        s = self.settings
        w = np.concatenate([np.maximum(dv, 0.0).ravel() for dv, _, _ in sites])
        vol = float(w.sum()) * cell_area
        self.worn_volume += vol
        exact = particle_count(vol, s.diameter, s.volume_correction) + self._carry
        k = int(math.floor(exact))
        self._carry = exact - k
        if k == 0 or vol <= 0:
            return 0
        cells = self.rng.choice(w.size, size=k, p=w / w.sum())
        xs, ys = [], []
        for _dv, x, y in sites:
            xx, yy = np.meshgrid(x, y, indexing="ij")
            xs.append(xx.ravel())
            ys.append(yy.ravel())
        cx, cy = np.concatenate(xs)[cells], np.concatenate(ys)[cells]
        h = math.sqrt(cell_area)
        new = np.stack([cx + self.rng.uniform(-0.5, 0.5, k) * h,
                        cy + self.rng.uniform(-0.5, 0.5, k) * h], axis=1)
        self.xy = np.concatenate([self.xy, new])
        self.shape = np.concatenate([self.shape, self.rng.choice(3, size=k, p=s.shares)])
        self.born = np.concatenate([self.born, np.full(k, cycle, dtype=np.int64)])
        self.created += k
        return k

    def eject(self, keep: NDArray[np.bool_]) -> int:
        """Drop the particles not in ``keep``; returns how many left."""
        gone = int((~keep).sum())
        self.xy, self.shape, self.born = self.xy[keep], self.shape[keep], self.born[keep]
        self.ejected += gone
        return gone

    def mass_balance(self) -> dict[str, float]:
        """Worn volume vs debris created, in the record and ejected (m^3)."""
        v = self.settings.particle_volume
        return {"worn_volume_m3": self.worn_volume,
                "debris_volume_created_m3": self.created * v,
                "debris_volume_in_contact_m3": self.n * v,
                "debris_volume_ejected_m3": self.ejected * v,
                "volume_correction": self.settings.volume_correction}


# --------------------------------------------------------------------- the DE phase
def _bounding_radius(t: ClumpTemplate) -> float:
    """Radius of the sphere about the centre of mass enclosing a template, m."""
    return float((np.linalg.norm(t.offsets, axis=1) + t.radii).max())


@dataclass
class DEPhaseResult:
    """Outcome of one DE phase (SI). Histories are sampled every ``chunk`` steps."""

    cycle: int
    particles: int  #: debris particles (clumps) in the record
    active_particles: int  #: those simulated (within reach of the upper surface)
    members: int  #: spheres of the simulated clumps
    target_N: float
    upper_force_N: float
    lower_force_N: float
    rel_error: float
    converged: bool
    steps: int
    dt_s: float
    simulated_time_s: float
    wall_time_s: float
    ejected: int
    loaded_particles: int
    pressure: NDArray[np.float64]  #: debris pressure on the lower body, Pa, window grid
    history: NDArray[np.float64]  #: rows (step, upper force N, lower force N, upper z m)
    positions: NDArray[np.float64]  #: final particle centres, m
    start_positions: NDArray[np.float64]
    particle_force: NDArray[np.float64]  #: force of each particle (body) on the lower body, N
    radius: NDArray[np.float64]  #: volume-equivalent radius of each particle, m
    assumptions: dict[str, Any] = field(default_factory=dict)
    #: total contact pressure at the loading position without / with the debris, Pa (set
    #: by the fretting loop: the same geometry solved both ways)
    pressure_without: NDArray[np.float64] | None = None
    pressure_with: NDArray[np.float64] | None = None
    #: the rigid DE surfaces at equilibrium: grid coordinates (m) and lower / upper surface
    #: elevations z (m) on coords x coords (for STL export, as the seed exchanged geometry)
    coords: NDArray[np.float64] | None = None
    lower_z: NDArray[np.float64] | None = None
    upper_z: NDArray[np.float64] | None = None

    def summary(self) -> dict[str, Any]:
        """Scalars for JSON."""
        keys = ("cycle", "particles", "active_particles", "members", "target_N",
                "upper_force_N", "lower_force_N", "rel_error", "converged", "steps", "dt_s",
                "simulated_time_s", "wall_time_s", "ejected", "loaded_particles")
        out = {k: getattr(self, k) for k in keys}
        if self.pressure_without is not None and self.pressure_with is not None:
            p0, p1 = float(self.pressure_without.max()), float(self.pressure_with.max())
            out |= {"max_pressure_without_debris_Pa": p0, "max_pressure_with_debris_Pa": p1,
                    "max_pressure_change": (p1 - p0) / p0}
        return out | {"assumptions": self.assumptions}


def debris_target(field: DebrisField, pressure: NDArray[np.float64], coords: NDArray,
                  dx: float, load: float) -> float:
    """Load the first bodies carried at the debris sites (eqs 3.11-3.15), N.

    Sum over particles of the interpolated pressure times the projected area pi d^2 / 4,
    capped per grid cell by the cell area and in total by ``target_cap`` x ``load``.
    """
    s = field.settings
    if field.n == 0:
        return 0.0
    c0 = float(coords[0])
    p = interpolate(pressure, field.xy[:, 0], field.xy[:, 1], c0, c0, dx, dx)
    area = math.pi * s.diameter**2 / 4.0
    n = pressure.shape[0]
    ci = np.clip(np.floor((field.xy - c0) / dx + 0.5).astype(np.int64), 0, n - 1)
    cell = ci[:, 0] * n + ci[:, 1]
    covered = np.bincount(cell, minlength=n * n) * area
    scale = np.minimum(1.0, dx * dx / np.maximum(covered, 1e-300))
    f = float((p * area * scale[cell]).sum())
    return min(f, s.target_cap * load)


def run_de_phase(field: DebrisField, lower: NDArray[np.float64], gap: NDArray[np.float64],
                 coords: NDArray[np.float64], target: float, cycle: int = 0,
                 chunk: int = 200) -> DEPhaseResult:
    """Load the debris between two rigid surfaces to ``target`` N and return the forces.

    ``lower`` is the recession (m, >= 0 downwards) of the worn lower body and ``gap`` the
    gap of the first bodies under load (m, 0 in the solid contact), both on the window grid
    ``coords`` x ``coords`` at offset 0. The rigid DE surfaces are the first bodies as
    deformed by the load: lower ``z = -lower``, upper ``z = -lower + gap + s``, ``s`` moved
    by the boundary-moving servo (eqs 3.2-3.6) until the debris carries ``target``. (A rigid
    *undeformed* curved body would put the whole debris load on the few particles at its
    apex; the seed replaced its worn upper body by a flat profile for the DE phase, 5.4.)
    """
    s = field.settings
    t0 = time.perf_counter()
    dx = float(coords[1] - coords[0])
    c0, c1 = float(coords[0]), float(coords[-1])
    n = coords.size
    inside = ((field.xy >= c0) & (field.xy <= c1)).all(axis=1)
    ejected = field.eject(inside)
    if field.n == 0:
        raise ValueError("DE phase: no debris particle inside the solver window")
    templates = [debris_template(sh, s.diameter) for sh in SHAPES]
    rb = max(_bounding_radius(t) for t in templates)
    lower_s = HeightMapSurface(point=[0, 0, 0], normal=[0, 0, 1], heights=-lower, x0=c0,
                               y0=c0, dx=dx, dy=dx, side="below", name="lower")
    field.xy = spread_single_layer(field.xy, 2 * rb, min(dx, 8 * rb), field.rng)
    field.xy = np.clip(field.xy, c0 + rb, c1 - rb)
    xy = field.xy
    layer = stack_layers(xy, 2 * rb)
    quat = random_quaternions(field.n, field.rng)
    below = np.zeros(field.n)  # how far each body reaches below its centre, m
    rot = quat_to_matrix(quat)
    for k, t in enumerate(templates):
        sel = field.shape == k
        if sel.any():
            z = np.einsum("nj,mj->nm", rot[sel][:, 2, :], t.offsets) - t.radii[None, :]
            below[sel] = -z.min(axis=1)
    zl = lower_s.elevation(xy[:, 0], xy[:, 1])
    centres = np.column_stack([xy, zl + below + layer * 2.002 * rb])
    # bodies where the loaded gap exceeds three body sizes cannot reach the upper surface nor
    # be pushed by those that do: they stay where they are, carrying nothing
    active = interpolate(np.asarray(gap, float), xy[:, 0], xy[:, 1], c0, c0, dx, dx) \
        < 3 * 2 * rb
    if not active.any():
        raise ValueError("DE phase: no debris particle inside the contact zone")
    ia = np.flatnonzero(active)
    p, clumps = make_clumps(templates, field.shape[ia], centres[ia], quat[ia],
                            density=s.density * s.density_scaling)
    start = centres.copy()
    mat = Material(name="debris", young=s.young, poisson=s.poisson,
                   density=s.density * s.density_scaling, friction=s.friction,
                   rolling_friction=s.rolling_friction, cor=s.cor)
    r = float(p.radius.min())
    up_h = -np.asarray(lower, dtype=float) + np.asarray(gap, dtype=float)
    mass = float(p.mass.sum())
    upper_s = HeightMapSurface(point=[0, 0, 0], normal=[0, 0, -1], heights=up_h, x0=c0, y0=c0,
                               dx=dx, dy=dx, side="above", mode="boundary",
                               target_force=target, servo_mass=mass, name="upper")
    z_top = float(np.nanmax(p.pos[:, 2] + p.radius
                            - upper_s.elevation(p.pos[:, 0], p.pos[:, 1])))
    upper_s.point[2] = z_top + 0.01 * r
    zmin = float(np.min(-lower)) - 2 * s.diameter
    zmax = z_top + float(up_h.max()) + 4 * s.diameter
    box = Box([c0 - s.diameter, c0 - s.diameter, zmin], [c1 + s.diameter, c1 + s.diameter,
                                                          zmax], [False, False, False])
    sim = Simulation(p, [mat], box, local_damping=s.local_damping, skin=0.2 * r,
                     max_overlap_ratio=0.5)
    upper_s.max_speed = 2e-3 * r / sim.dt
    sim.add_interaction(clumps)
    sim.add_interaction(lower_s)
    sim.add_interaction(upper_s)
    hist: list[tuple[float, float, float, float]] = []
    converged = False
    log.debug("DE phase (cycle %d): %d debris bodies (%d members), target %.4g N, at most %d "
              "steps", cycle, ia.size, p.n, target, s.max_steps)
    noted = time.perf_counter()
    while sim.step_count < s.max_steps:
        k = upper_s.stiffness
        ramp = min(1.0, (sim.step_count + chunk) / max(s.ramp_steps, 1))
        upper_s.target_force = target * ramp
        upper_s.servo_damping = 2.0 * math.sqrt(mass * k) if k > 0 else 0.0
        sim.step(chunk)
        fu, fl = upper_s.normal_force, lower_s.normal_force
        hist.append((sim.step_count, fu, fl, float(upper_s.point[2])))
        err = max(abs(fu - target), abs(fl - target)) / target
        if err < s.tolerance and abs(upper_s.velocity[2]) * sim.dt < 1e-6 * r:
            converged = True
            break
        if time.perf_counter() - noted > DE_NOTE_EVERY_S:
            noted = time.perf_counter()
            log.info("DE phase (cycle %d, %d debris bodies): step %d of at most %d, servo "
                     "force error %.3g (converged below %.3g)", cycle, ia.size,
                     sim.step_count, s.max_steps, err, s.tolerance)
    pf = lower_s.particle_force.copy()
    # force the members push the lower body down with, N; a separating contact's dashpot can
    # pull (the Hertz-Mindlin law is not clipped, as in LIGGGHTS): a contact cannot hold the
    # bodies together, so such pulls are left out of the mapped pressure (reported)
    fz_raw = -pf[:, 2]
    tensile = float(-fz_raw[fz_raw < 0.0].sum())
    fz = np.maximum(fz_raw, 0.0)
    pressure = spread(fz, p.pos[:, 0], p.pos[:, 1], c0, c0, dx, dx, (n, n)) / dx**2
    body_f = np.zeros((field.n, 3))  # force of each body on the lower body, N
    np.add.at(body_f, ia[clumps.body_of[clumps.members]], pf[clumps.members])
    fu, fl = upper_s.normal_force, lower_s.normal_force
    final = centres.copy()
    final[ia] = clumps.pos
    field.xy = final[:, :2].copy()
    return DEPhaseResult(
        cycle=cycle, particles=field.n, active_particles=int(ia.size), members=p.n,
        target_N=target, upper_force_N=fu, lower_force_N=fl,
        rel_error=max(abs(fu - target), abs(fl - target)) / target, converged=converged,
        steps=sim.step_count, dt_s=sim.dt, simulated_time_s=sim.time,
        wall_time_s=time.perf_counter() - t0, ejected=ejected,
        loaded_particles=int((body_f[:, 2] < 0).sum()), pressure=pressure,
        history=np.array(hist), positions=final, start_positions=start,
        particle_force=body_f, radius=np.full(field.n, 0.5 * s.diameter),
        coords=np.asarray(coords, float).copy(), lower_z=-np.asarray(lower, float),
        upper_z=up_h + float(upper_s.point[2]),
        assumptions={"gravity": "left out (weight ~1e-14 N per particle)",
                     "density_scaling": s.density_scaling,
                     "first_bodies": "rigid height maps at offset 0 (loading position)",
                     "tensile_member_forces_left_out_N": tensile,
                     "settings": asdict(s)},
    )
