"""``Simulation``: the step loop that wires the kernels, plus checkpoints and stability checks.

One step: (re)build the neighbour list if needed -> pair contact forces, summed into the
particles -> extra interactions (bonds, thermal, ... added as ``Interaction`` objects) ->
wall contacts -> per particle: the sum of its forces, central-difference update, periodic
wrap -> walls move (servo).
The engine knows nothing about brakes or fretting; applications compose it.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any, Protocol

import numba
import numpy as np
from numba import literal_unroll

from tribodem.dem import laws, neighbors
from tribodem.dem.compiled import (
    N_WPAR,
    W_ALPHA,
    W_DAMPING,
    W_MASS,
    W_MAXSPEED,
    W_MODE,
    W_TARGET,
    NoStep,
    StepContext,
    interaction_step,
    np_sum,
    registered,
)
from tribodem.dem.contact import (
    BLOCKS_PER_THREAD,
    HIST,
    N_PCONST,
    Material,
    pair_block,
    pair_block_bounds,
    pair_constants,
    pair_cross_list,
    pair_forces_blocked,
    pair_forces_cross,
    pair_forces_sum,
    pair_forces_sum_2d,
    pair_table,
)
from tribodem.dem.errors import SimulationUnstable, TimeStepError
from tribodem.dem.integrate import BLOCK, advance, advance_block, critical_step
from tribodem.dem.jit import serial_run
from tribodem.dem.space import Box
from tribodem.dem.state import ParticleState
from tribodem.dem.walls import (
    WALL_MODES,
    PlaneWall,
    near_walls,
    needs_rebuild,
    wall_arrays,
    wall_forces,
)
from tribodem.io.results import write_npz

CHECKPOINT_VERSION = 1
#: steps between two cuts of the threaded pair pass's blocks (``Simulation._block_bounds``)
REBALANCE_EVERY = 100
#: ``numba.parallel_chunksize`` of the threaded compiled loop: 0, equal static shares (the
#: pair blocks are cut for equal work already; interleaved on 2 threads, us per step:
#: settle3d 834 / 889 static against 862 / 934 at chunk 1, dense3d 1,587 against 1,607)
THREADED_CHUNK = 0


@numba.njit(cache=True)
def cross_group_sum(pinfo, pair_i, pair_j, group, out):  # pragma: no cover - numba
    """Summed normal force (N) of the touching pairs (overlap > 0) between different
    groups that push (N > 0): their forces are written into ``out`` in pair order, then
    summed as ``np.sum`` does (``compiled.np_sum``: the same bits)."""
    k = 0
    for p in range(pair_i.shape[0]):
        f = pinfo[p, 1]
        if pinfo[p, 0] > 0.0 and f > 0.0 and group[pair_i[p]] != group[pair_j[p]]:
            out[k] = f
            k += 1
    return np_sum(out, k)


# compiled builds of the kernels the multi-step loop calls (serial: one thread, or small)
_pairs_2d = pair_forces_sum_2d.serial
_pairs_3d = pair_forces_sum.serial
_walls_pass = wall_forces.serial
_advance_serial = advance.serial
# and their threaded builds (the loop of a large system on several threads)
_cross_par = pair_forces_cross.parallel
_walls_par = wall_forces.parallel
_SERVO = WALL_MODES.index("servo")
_BOUNDARY = WALL_MODES.index("boundary")


@numba.njit(cache=True, inline="always")
def _clamp(v, cap):  # pragma: no cover - numba
    """``min(max(v, -cap), cap)`` with Python's builtins' choice of argument."""
    if -cap > v:
        v = -cap
    if cap < v:
        v = cap
    return v


@numba.njit(cache=True)
def _move_walls(c):  # pragma: no cover - numba
    """``PlaneWall.update_motion`` of every wall (same operations): servo velocity from
    the force just measured, then the move."""
    dt = c.dt
    for w in range(c.wall_point.shape[0]):
        mode = int(c.wall_par[w, W_MODE])
        n0 = c.wall_normal[w, 0]
        n1 = c.wall_normal[w, 1]
        n2 = c.wall_normal[w, 2]
        if mode == _SERVO or mode == _BOUNDARY:
            cap = c.wall_par[w, W_MAXSPEED]
            if mode == _SERVO:
                err = c.wall_par[w, W_TARGET] - c.wall_nf[w]
                kn = c.wall_tot[w, 4]
                if kn > 0:
                    v = c.wall_par[w, W_ALPHA] * err / (kn * dt)
                else:
                    v = cap if np.isfinite(cap) else 0.0
            else:
                v = (c.wall_vel[w, 0] * n0 + c.wall_vel[w, 1] * n1 + c.wall_vel[w, 2] * n2)
                a = (c.wall_par[w, W_TARGET] - c.wall_nf[w]
                     - c.wall_par[w, W_DAMPING] * v) / c.wall_par[w, W_MASS]
                v = v + a * dt
            v = _clamp(v, cap)
            c.wall_vel[w, 0] = v * n0
            c.wall_vel[w, 1] = v * n1
            c.wall_vel[w, 2] = v * n2
        for k in range(3):
            c.wall_point[w, k] = c.wall_point[w, k] + c.wall_vel[w, k] * dt


@numba.njit(cache=True)
def _must_rebuild(c):  # pragma: no cover - numba
    """``Simulation._maybe_rebuild``'s test: with walls ``walls.needs_rebuild``, without
    them ``not drift.max() <= skin / 2`` (numpy's max: a NaN drift rebuilds)."""
    if c.wall_point.shape[0]:
        return needs_rebuild(c.drift, c.wall_point, c.wall_normal, c.wall_ref_point,
                             c.wall_ref_normal, c.half_skin)
    dmax = 0.0
    for b in range(c.drift.shape[0]):
        d = c.drift[b]
        if d > dmax or d != d:
            dmax = d
            if d != d:
                break
    return not dmax <= c.half_skin


@numba.njit(cache=True)
def _interactions(states, c):  # pragma: no cover - numba
    """The interactions' compiled steps, in order; the OR of their event codes."""
    ev = 0
    for st in literal_unroll(states):
        ev |= interaction_step(st, c)
    return ev


@numba.njit(cache=True)
def _unstable(c, max_ratio):  # pragma: no cover - numba
    """Would ``Simulation.check_stability`` raise now? (a non-finite position or velocity;
    else the largest overlap / smaller radius of the listed pairs above ``max_ratio``,
    unless a ratio is NaN: numpy's argmax then picks the NaN, which passes)."""
    for i in range(c.pos.shape[0]):
        for k in range(3):
            if not (np.isfinite(c.pos[i, k]) and np.isfinite(c.vel[i, k])):
                return True
    over = False
    for p in range(c.pair_i.shape[0]):
        ri = c.radius[c.pair_i[p]]
        rj = c.radius[c.pair_j[p]]
        ratio = c.pinfo[p, 0] / (ri if ri < rj else rj)
        if ratio != ratio or ri != ri or rj != rj:  # np.minimum keeps a NaN radius
            return False
        if ratio > max_ratio:
            over = True
    return over


#: why ``_run_steps`` returned: the steps asked for are done, a neighbour rebuild is due
#: before the next step, an interaction's step function reported an event, or the
#: stability check failed (``Simulation.check_stability`` then raises)
RUN_DONE, RUN_REBUILD, RUN_EVENT, RUN_UNSTABLE = 0, 1, 2, 3


@numba.njit(cache=True)
def _wall_normal_forces(c):  # pragma: no cover - numba
    """``Simulation._wall_pass``'s normal force of the particles on each wall (N)."""
    for w in range(c.wall_point.shape[0]):
        c.wall_nf[w] = -(c.wall_tot[w, 0] * c.wall_normal[w, 0]
                         + c.wall_tot[w, 1] * c.wall_normal[w, 1]
                         + c.wall_tot[w, 2] * c.wall_normal[w, 2])


@numba.njit(cache=True, parallel=True)
def _pairs_update(pos, vel, omega, radius, mass, inertia, mat, fixed, start, pair_i, pair_j,
                  rev_start, rev_pair, hist, pairtab, elin, length, periodic, dim, thickness,
                  dt, fpair, tpair_i, tpair_j, pinfo, force, torque, wstart, wforce, wtorque,
                  gravity, viscous, local, has_ext, ext_force, ext_torque, ref_pos,
                  ref_radius, lo, drift, bounds):  # pragma: no cover - numba
    """The threaded loop's second pass (after ``pair_forces_cross`` and the walls; no
    interactions), one threaded region: each thread takes its ``BLOCKS_PER_THREAD`` blocks
    of ``bounds`` (``pair_block_bounds``; the cuts between threads fall between update
    blocks), sums their pairs (``contact.pair_block``: afterwards its particles' sums are
    complete, as no other block's pairs reach them but the cross pairs already stored)
    and then updates its particles (``integrate.advance_block``). A thread thus updates
    the particles whose pairs it summed, in the same region: the separate update region
    (equal particle counts, while the pair cuts are by work) handed ~10 % of settle3d's
    particles from one thread to the other every step, which cost 3.5 % when the VM's two
    vCPUs sit on different L3 caches (BENCHMARKS.md, bonded3d on two threads). The same
    operations on each particle as the serial loop: the same bits."""
    nt = (bounds.shape[0] - 1) // BLOCKS_PER_THREAD
    for t in numba.prange(nt):
        for b in range(t * BLOCKS_PER_THREAD, (t + 1) * BLOCKS_PER_THREAD):
            pair_block(pos, vel, omega, radius, mass, inertia, mat, start, pair_i, pair_j,
                       rev_start, rev_pair, hist, pairtab, elin, length, periodic, dim,
                       thickness, dt, fpair, tpair_i, tpair_j, pinfo, force, torque,
                       bounds[b], bounds[b + 1])
        first = bounds[t * BLOCKS_PER_THREAD]  # the thread's particles, cut on blocks
        end = bounds[(t + 1) * BLOCKS_PER_THREAD]
        for blk in range((first + BLOCK - 1) // BLOCK, (end + BLOCK - 1) // BLOCK):
            advance_block(pos, vel, omega, radius, mass, inertia, fixed, wstart, wforce,
                          wtorque, dt, gravity, viscous, local, has_ext, ext_force,
                          ext_torque, force, torque, ref_pos, ref_radius, lo, length,
                          periodic, drift, blk)


@numba.njit(cache=True)
def _run_steps(c, states, nmax, step0, check_every, max_ratio, bounds, xpairs,
               nx):  # pragma: no cover
    """Up to ``nmax`` steps of ``Simulation.step`` in one compiled loop (the same kernels,
    operations and order as the Python loop, so the same bits): pair contacts -> the
    interactions' compiled steps (``states``, in order) -> wall pass and the walls'
    totals -> particle update -> wall motion -> clock (threaded, without interactions:
    cross pairs -> walls -> ``_pairs_update``, the same values). The first step starts at
    once (the caller has just checked the neighbour list); before each later one the
    rebuild test runs and, if due, the loop stops. After every step whose count (from
    ``step0``) is a multiple of ``check_every`` the stability test runs (``_unstable``) and
    stops the loop if it fails. ``bounds``: ``None`` (a compile-time branch) runs every kernel's
    serial build; an array runs their threaded builds, the pairs in those blocks
    (``contact.pair_block_bounds``) with the pairs across them in ``xpairs[:nx[0]]``
    (``contact.pair_cross_list``), both cut again every ``REBALANCE_EVERY`` steps, in place,
    with the caller's ``numba.parallel_chunksize`` (set inside, the loop could not be
    cached: the setter is a ctypes pointer).
    Returns (steps done, ``RUN_*`` reason, the OR of the interactions' event codes)."""
    nw = c.wall_point.shape[0]
    n = c.pos.shape[0]
    k = 0
    why = RUN_DONE
    events = 0
    t = c.clock[0]
    # the pairs' constants, once per call: no compiled step changes radii, masses or
    # materials, and the list is rebuilt only between calls
    pconst = np.empty((c.pair_i.shape[0] if bounds is None else 0, N_PCONST))
    if bounds is None:
        pair_constants(c.radius, c.mass, c.inertia, c.mat, c.pair_i, c.pair_j, c.pairtab,
                       c.elin, c.dim, c.thickness, pconst)
    while k < nmax:
        if k > 0 and _must_rebuild(c):
            why = RUN_REBUILD
            break
        ev = 0
        if bounds is not None:  # threaded (no interactions): the blocked Newton pairs
            if k > 0 and (step0 + k) % REBALANCE_EVERY == 0:
                pair_block_bounds(c.start, c.pinfo, bounds.shape[0] - 1, bounds)
                nx[0] = pair_cross_list(c.pair_i, c.pair_j, bounds, xpairs)
            _cross_par(c.pos, c.vel, c.omega, c.radius, c.mass, c.inertia, c.mat, c.pair_i,
                       c.pair_j, c.hist, c.pairtab, c.elin, c.length, c.periodic, c.dim,
                       c.thickness, c.dt, c.fpair, c.tpair_i, c.tpair_j, c.pinfo, xpairs,
                       nx[0])
            if nw:  # the walls first: they need no pair force
                _walls_par(c.pos, c.vel, c.omega, c.radius, c.mass, c.inertia, c.mat,
                           c.wstart, c.wid, c.wpart, c.wbstart, c.wall_point, c.wall_normal,
                           c.wall_vel, c.wall_mat, c.wall_hist, c.wall_info, c.wsum,
                           c.pairtab, c.elin, c.dim, c.thickness, c.dt, c.wforce, c.wtorque,
                           c.wall_tot)
                _wall_normal_forces(c)
            _pairs_update(c.pos, c.vel, c.omega, c.radius, c.mass, c.inertia, c.mat, c.fixed,
                          c.start, c.pair_i, c.pair_j, c.rev_start, c.rev_pair, c.hist,
                          c.pairtab, c.elin, c.length, c.periodic, c.dim, c.thickness, c.dt,
                          c.fpair, c.tpair_i, c.tpair_j, c.pinfo, c.force, c.torque,
                          c.wstart, c.wforce, c.wtorque, c.gravity, c.viscous, c.local,
                          c.has_ext, c.ext_force, c.ext_torque, c.ref_pos, c.ref_radius,
                          c.lo, c.drift, bounds)
        else:
            if c.dim == 2:
                _pairs_2d(c.pos, c.vel, c.omega, c.radius, c.mass, c.inertia, c.mat,
                          c.pair_i, c.pair_j, c.hist, c.pairtab, c.elin, c.length,
                          c.periodic, c.dim, c.thickness, c.dt, c.fpair, c.tpair_i,
                          c.tpair_j, c.pinfo, c.force, c.torque, pconst)
            else:
                _pairs_3d(c.pos, c.vel, c.omega, c.radius, c.mass, c.inertia, c.mat,
                          c.pair_i, c.pair_j, c.hist, c.pairtab, c.elin, c.length,
                          c.periodic, c.dim, c.thickness, c.dt, c.fpair, c.tpair_i,
                          c.tpair_j, c.pinfo, c.force, c.torque, pconst)
            if c.has_ext:
                for i in range(n):
                    for d in range(3):
                        c.ext_force[i, d] = 0.0
                        c.ext_torque[i, d] = 0.0
                ev = _interactions(states, c)
            if nw:
                _walls_pass(c.pos, c.vel, c.omega, c.radius, c.mass, c.inertia, c.mat,
                            c.wstart, c.wid, c.wpart, c.wbstart, c.wall_point, c.wall_normal,
                            c.wall_vel, c.wall_mat, c.wall_hist, c.wall_info, c.wsum,
                            c.pairtab, c.elin, c.dim, c.thickness, c.dt, c.wforce, c.wtorque,
                            c.wall_tot)
                _wall_normal_forces(c)
            _advance_serial(c.pos, c.vel, c.omega, c.radius, c.mass, c.inertia, c.fixed,
                            c.wstart, c.wforce, c.wtorque, c.dt, c.gravity, c.viscous,
                            c.local, c.has_ext, c.ext_force, c.ext_torque, c.force, c.torque,
                            c.ref_pos, c.ref_radius, c.lo, c.length, c.periodic, c.drift)
        _move_walls(c)
        t += c.dt
        k += 1
        if ev:
            events |= ev
            why = RUN_EVENT
            break
        if (step0 + k) % check_every == 0 and _unstable(c, max_ratio):
            why = RUN_UNSTABLE
            break
    c.clock[0] = t
    return k, why, events


class Interaction(Protocol):
    """An extra force contribution (bonds, thermal loads, ...).

    ``compute(sim)`` runs every step after the pair contacts and adds its forces and
    moments into ``sim.ext_force`` / ``sim.ext_torque`` (zeroed before, N and N m).
    Optional hooks: ``after_advance(sim)`` runs right after the particle update (rigid
    clumps integrate their bodies there); ``filter_pairs(nl)`` returns the neighbour list
    without pairs that must not interact (members of one clump), after every build.

    Compiled form (optional, :mod:`tribodem.dem.compiled`): ``compiled(sim)`` returns the
    state of a registered compiled step that does what ``compute`` does (the same
    operations: the same bits), or ``None`` when it has none now; ``after_compiled(sim,
    state)`` runs whenever the compiled loop returns to Python. ``Simulation.step`` runs
    its steps in one compiled loop while every interaction has one (and no
    ``after_advance`` hook, energy tracking, extra contact law or threaded kernel is in
    play); otherwise step by step in Python.

    Particles added during a run (``Simulation.append_particles``): every interaction
    must declare ``particles_appended(sim, n_old)`` (called after the engine's arrays
    have grown from ``n_old`` to ``sim.p.n``; the new particles have the highest
    indices); one without it cannot take part in such a run (``ValueError``).
    """

    def compute(self, sim: Simulation) -> None: ...


class Recorder(Protocol):
    """Something that samples the simulation (CSV scalars, VTK snapshots)."""

    def sample(self, sim: Simulation) -> None: ...

    def close(self) -> None: ...


class Simulation:
    """A DEM simulation (SI units).

    Parameters: particles, materials (indexed by ``particles.mat`` and wall
    ``material``), box (periodic axes), walls, gravity (m/s^2), ``dt`` (s; ``None`` =
    ``dt_safety`` x critical step), ``viscous_damping`` c (1/s, Sha et al. (2022) eq 1 eta = c m),
    ``local_damping`` alpha (PFC), ``skin`` (m; default 0.2 x mean radius).
    A ``dt`` above the critical step is refused (``TimeStepError``) unless ``force_dt``.
    ``compiled_loop``: run steps in the compiled multi-step loop when every piece allows
    it (see ``Interaction``; the same results as the Python loop, bitwise).
    """

    def __init__(self, particles: ParticleState, materials: list[Material], box: Box,
                 walls: list[PlaneWall] | None = None, gravity: tuple | np.ndarray = (0, 0, 0),
                 dt: float | None = None, dt_safety: float = 0.2, viscous_damping: float = 0.0,
                 local_damping: float = 0.0, skin: float | None = None,
                 force_dt: bool = False, max_overlap_ratio: float = 0.5,
                 check_every: int = 100, track_energy: bool = False) -> None:
        self.p = particles
        self.materials = list(materials)
        self.box = box
        self.walls = list(walls or [])
        self.gravity = np.asarray(gravity, dtype=np.float64).reshape(3)
        self.viscous_damping = float(viscous_damping)
        self.local_damping = float(local_damping)
        self.max_overlap_ratio = float(max_overlap_ratio)
        self.check_every = int(check_every)
        self.track_energy = bool(track_energy)
        self._at_force_eval: tuple[np.ndarray, ...] | None = None
        self.interactions: list[Interaction] = []
        self._after: list = []  # interactions with an after_advance hook
        self._pair_filters: list = []  # interactions with a filter_pairs hook
        self.recorders: list[tuple[int, Recorder]] = []
        #: run steps in the compiled loop (``_run_steps``) whenever every piece has a
        #: compiled form; False: always the Python loop (the same results)
        self.compiled_loop = True
        self.step_count = 0
        self.time = 0.0
        self._validate(dt, dt_safety)
        self.pairtab, self.elin = pair_table(self.materials)
        n = self.p.n
        self.force = np.zeros((n, 3))
        self.torque = np.zeros((n, 3))
        self.skin = float(skin) if skin is not None else 0.2 * float(self.p.radius.mean())
        self.nl = neighbors.build(self.p.pos, self.p.radius, self.skin, box.lo, box.hi,
                                  box.periodic)
        self.hist = np.zeros((self.nl.n_pairs, HIST))
        self._threads: int | None = None  # numba threads, read once per step() call
        self._cross = np.zeros(0)  # cross_group_force's buffer
        self._bounds = np.zeros(0, dtype=np.int64)  # the threaded pair pass's blocks
        self._bounds_key: tuple = (None, 0, False)
        self._xpairs = np.zeros(0, dtype=np.int64)  # the pairs across those blocks
        self._nx = np.zeros(1, dtype=np.int64)  # how many
        #: ``box.length`` as of the current ``step()`` call (read once per call by the
        #: kernels and interactions; a box changed between calls is seen at the next)
        self.box_length = self.box.length
        self._alloc_pairs()
        self.ext_force = np.zeros((n, 3))
        self.ext_torque = np.zeros((n, 3))
        self.wall_hist = np.zeros((len(self.walls), n, HIST))
        self.wall_info = np.zeros((len(self.walls), n, 4))
        nblocks = (n + BLOCK - 1) // BLOCK
        self._wsum = np.zeros((nblocks, len(self.walls), 5))
        self._wtot = np.zeros((len(self.walls), 5))  # the walls' sums over the blocks
        self._wforce = np.zeros((n, 3))
        self._wtorque = np.zeros((n, 3))
        self._walls_now = wall_arrays(self.walls)  # refreshed at the start of every step
        self._build_wall_list()
        self.drift = np.zeros(nblocks)
        self.dt_critical, self.dt_limit_by = critical_step(
            self.p.density, self.p.radius, self.p.mass, self.p.inertia, self.p.mat,
            self.nl.pair_i, self.nl.pair_j, self.pairtab, self.elin, self.materials, self.p.dim,
            self.p.thickness, self.p.pos, self.walls, self.skin)
        self.force_dt = bool(force_dt)
        self._auto_dt = dt is None
        self._dt_safety = float(dt_safety)
        if dt is None:
            self.dt = dt_safety * self.dt_critical
        else:
            if dt > self.dt_critical and not force_dt:
                raise TimeStepError(
                    f"dt = {dt:.6g} s is above the critical time step {self.dt_critical:.6g} s "
                    f"limited by {self.dt_limit_by}; use dt <= {self.dt_critical:.6g} s "
                    "(or force_dt=True)")
            self.dt = float(dt)

    # ------------------------------------------------------------------ setup
    def _validate(self, dt: float | None, dt_safety: float) -> None:
        nm = len(self.materials)
        if nm == 0:
            raise ValueError("simulation: at least one material is needed")
        if self.p.n and (self.p.mat.min() < 0 or self.p.mat.max() >= nm):
            raise ValueError(f"particles: mat index {int(self.p.mat.max())} is out of range: "
                             f"{nm} materials given")
        for w in self.walls:
            if not 0 <= w.material < nm:
                raise ValueError(f"wall '{w.name}': material = {w.material}: must be in "
                                 f"[0, {nm - 1}]")
        if dt is not None and not dt > 0:
            raise ValueError(f"simulation: dt = {dt!r}: must be > 0 s")
        if not 0 < dt_safety <= 1:
            raise ValueError(f"simulation: dt_safety = {dt_safety!r}: must be in (0, 1]")
        if not 0 <= self.local_damping < 1:
            raise ValueError(f"simulation: local_damping = {self.local_damping!r}: must be in "
                             "[0, 1)")
        if not self.viscous_damping >= 0:
            raise ValueError(f"simulation: viscous_damping = {self.viscous_damping!r}: must "
                             "be >= 0 1/s")
        rmax = float(self.p.radius.max()) if self.p.n else 0.0
        for k in range(3):
            if self.box.periodic[k] and self.box.length[k] < 4.0 * rmax * 1.2:
                raise ValueError(f"box: periodic axis {k} length {self.box.length[k]:.4g} m is "
                                 f"below 4.8 x the largest radius ({rmax:.4g} m)")

    def _alloc_pairs(self) -> None:
        m = self.nl.n_pairs
        self.fpair = np.zeros((m, 3))
        self.tpair_i = np.zeros((m, 3))
        self.tpair_j = np.zeros((m, 3))
        self.pinfo = np.zeros((m, 4))
        self.pinfo[:, 0] = 1.0  # unknown yet: the first evaluation clears what is apart
        self._evaluated = False  # pinfo holds no evaluation yet (see _active)

    def add_interaction(self, inter: Interaction) -> None:
        """Add an extra force contribution, evaluated every step after contacts.

        An interaction with ``critical_step(sim)`` (bonds) lowers the critical step: an
        automatic dt follows it; a user dt above it is refused unless ``force_dt``.
        """
        crit = getattr(inter, "critical_step", None)
        if crit is not None:
            dt_c = float(crit(self))
            if dt_c < self.dt_critical:
                self.dt_critical = dt_c
                self.dt_limit_by = f"{type(inter).__name__} stiffness sqrt(m/k)"
                if self._auto_dt:
                    self.dt = self._dt_safety * dt_c
                elif self.dt > dt_c and not self.force_dt:
                    raise TimeStepError(
                        f"dt = {self.dt:.6g} s is above the critical time step {dt_c:.6g} s "
                        f"limited by {self.dt_limit_by}; use dt <= {dt_c:.6g} s "
                        "(or force_dt=True)")
        self.interactions.append(inter)
        if hasattr(inter, "after_advance"):
            self._after.append(inter)
        if hasattr(inter, "filter_pairs"):
            self._pair_filters.append(inter)
            old, old_hist = self.nl, self.hist
            self.nl = inter.filter_pairs(old)
            if self.nl is not old:
                self.hist = np.zeros((self.nl.n_pairs, HIST))
                neighbors.transfer_history.pick(self.p.n)(old.start, old.pair_j, old_hist,
                                                          self.nl.start, self.nl.pair_j,
                                                          self.hist)
                self._alloc_pairs()

    def add_recorder(self, recorder: Recorder, every: int) -> None:
        """Sample ``recorder`` every ``every`` steps (and once at the start)."""
        if every < 1:
            raise ValueError(f"recorder: every = {every!r}: must be >= 1 step")
        self.recorders.append((int(every), recorder))

    def append_particles(self, pos: np.ndarray, radius: np.ndarray, density: np.ndarray,
                         vel: np.ndarray, mat: np.ndarray, group: np.ndarray,
                         fixed: np.ndarray) -> np.ndarray:
        """Add particles between steps (SI; arrays of the new particles, ``pos``/``vel``
        (k, 3)); they take the indices ``n .. n + k - 1``, start without spin, contact
        history or force. The neighbour list is rebuilt at once (the history of the
        existing pairs carried over) and every interaction's ``particles_appended`` hook
        is called (``Interaction``). The time step is kept; the critical step is
        computed again (contacts and every interaction's ``critical_step``) and a step
        above it is refused (``TimeStepError``, the particles stay appended) unless
        ``force_dt``. Returns the new indices."""
        p = self.p
        n_old = p.n
        k = int(np.asarray(radius).size)
        missing = [type(x).__name__ for x in self.interactions
                   if not hasattr(x, "particles_appended")]
        if missing:
            raise ValueError(f"append_particles: interaction(s) {', '.join(missing)} hold "
                             "per-particle state and cannot grow (no particles_appended)")
        new = ParticleState(dim=p.dim, pos=pos, radius=radius, density=density,
                            thickness=p.thickness, vel=vel, mat=mat, group=group, fixed=fixed)
        for name, a in new.arrays().items():
            setattr(p, name, np.concatenate([getattr(p, name), a]))
        p.update_mass()
        n = p.n
        grow = lambda a: np.concatenate([a, np.zeros((k, *a.shape[1:]))])  # noqa: E731
        self.force, self.torque = grow(self.force), grow(self.torque)
        self.ext_force, self.ext_torque = grow(self.ext_force), grow(self.ext_torque)
        self._wforce, self._wtorque = grow(self._wforce), grow(self._wtorque)
        nw = len(self.walls)
        self.wall_hist = np.concatenate([self.wall_hist, np.zeros((nw, k, HIST))], axis=1)
        self.wall_info = np.concatenate([self.wall_info, np.zeros((nw, k, 4))], axis=1)
        nblocks = (n + BLOCK - 1) // BLOCK
        self._wsum = np.zeros((nblocks, nw, 5))
        self.drift = np.zeros(nblocks)
        self._rebuild()
        for inter in self.interactions:
            inter.particles_appended(self, n_old)  # type: ignore[attr-defined]
        crit, by = critical_step(p.density, p.radius, p.mass, p.inertia, p.mat,
                                 self.nl.pair_i, self.nl.pair_j, self.pairtab, self.elin,
                                 self.materials, p.dim, p.thickness, p.pos, self.walls,
                                 self.skin)
        for inter in self.interactions:
            step = getattr(inter, "critical_step", None)
            dt_i = float(step(self)) if step is not None else math.inf
            if dt_i < crit:
                crit, by = dt_i, f"{type(inter).__name__} stiffness sqrt(m/k)"
        self.dt_critical, self.dt_limit_by = crit, by
        if self.dt > crit and not self.force_dt:
            raise TimeStepError(f"append_particles: dt = {self.dt:.6g} s is above the new "
                                f"critical time step {crit:.6g} s limited by {by}")
        return np.arange(n_old, n)

    # ------------------------------------------------------------------ stepping
    def _build_wall_list(self, at: np.ndarray | None = None) -> None:
        """Near-wall candidates (gap below the skin) and each wall's position at the build,
        from the neighbour list's reference state (``at``: the walls' points then; default:
        now), so a checkpoint restores exactly the list of the run it came from."""
        wp, wn, _, _ = wall_arrays(self.walls)
        if at is not None:
            wp = np.asarray(at, dtype=np.float64).reshape(wp.shape)
        self._wstart, self._wid, self._wpart, self._wbstart = near_walls(
            self.nl.ref_pos, self.nl.ref_radius, wp, wn, self.skin, BLOCK)
        self._wall_ref = (wp, wn)
        self._wforce[:] = 0.0
        self._wtorque[:] = 0.0

    def _refresh_walls(self) -> None:
        """The walls' point, normal, velocity and material of this step into the arrays of
        ``_walls_now``, in place (a fresh ``wall_arrays`` if the wall count changed)."""
        wp, wn, wv, wm = self._walls_now
        if wp.shape[0] != len(self.walls):
            self._walls_now = wall_arrays(self.walls)
            return
        for k, w in enumerate(self.walls):
            wp[k] = w.point
            wn[k] = w.normal
            wv[k] = w.velocity
            wm[k] = w.material

    def _maybe_rebuild(self) -> None:
        if self.walls:
            wp0, wn0 = self._wall_ref
            wp, wn, _, _ = self._walls_now
            if not needs_rebuild(self.drift, wp, wn, wp0, wn0, 0.5 * self.skin):
                return
        elif self.drift.max(initial=0.0) <= 0.5 * self.skin:
            return
        self._rebuild()

    def _rebuild(self) -> None:
        """Build the neighbour list now, carrying every listed pair's history over (the
        old list may hold fewer particles: ``append_particles``'s have no old pairs), and
        the near-wall list with it."""
        n = self.p.n
        old, old_hist = self.nl, self.hist
        start = old.start
        if start.size < n + 1:
            start = np.concatenate([start, np.full(n + 1 - start.size, start[-1])])
        self.nl = neighbors.build(self.p.pos, self.p.radius, self.skin, self.box.lo,
                                  self.box.hi, self.box.periodic, old.builds)
        for inter in self._pair_filters:
            self.nl = inter.filter_pairs(self.nl)
        self.hist = np.zeros((self.nl.n_pairs, HIST))
        neighbors.transfer_history.pick(n)(start, old.pair_j, old_hist, self.nl.start,
                                           self.nl.pair_j, self.hist)
        self._alloc_pairs()
        self.drift[:] = 0.0
        self._build_wall_list()

    def _pair_forces(self) -> None:
        """Contacts of the listed pairs, summed into ``force``/``torque`` (Newton pairs, no
        gather pass). On one thread (or a short list) the serial kernel (disks: its planar
        build ``pair_forces_sum_2d``); threaded, blocks of particles in two passes
        (``pair_forces_cross``, then ``pair_forces_blocked``), which sum every particle's
        pairs in the serial kernel's order: the same bits on any number of threads."""
        p = self.p
        args = (p.pos, p.vel, p.omega, p.radius, p.mass, p.inertia, p.mat, self.nl.pair_i,
                self.nl.pair_j, self.hist, self.pairtab, self.elin, self.box_length,
                self.box.periodic, p.dim, p.thickness, self.dt, self.fpair, self.tpair_i,
                self.tpair_j, self.pinfo)
        if serial_run(self.nl.n_pairs, self._threads):
            fn = pair_forces_sum_2d if p.dim == 2 else pair_forces_sum
            laws.active(fn).serial(*args, self.force, self.torque, None)
        else:
            nl = self.nl
            bounds = self._block_bounds()
            laws.active(pair_forces_cross).pick(nl.n_pairs, self._threads)(
                p.pos, p.vel, p.omega, p.radius, p.mass, p.inertia, p.mat, nl.pair_i,
                nl.pair_j, self.hist, self.pairtab, self.elin, self.box_length,
                self.box.periodic, p.dim, p.thickness, self.dt, self.fpair, self.tpair_i,
                self.tpair_j, self.pinfo, self._xpairs, int(self._nx[0]))
            laws.active(pair_forces_blocked).pick(nl.n_pairs, self._threads)(
                p.pos, p.vel, p.omega, p.radius, p.mass, p.inertia, p.mat, nl.start,
                nl.pair_i, nl.pair_j, nl.rev_start, nl.rev_pair, self.hist, self.pairtab,
                self.elin, self.box_length, self.box.periodic, p.dim, p.thickness, self.dt,
                self.fpair, self.tpair_i, self.tpair_j, self.pinfo, self.force, self.torque,
                bounds)
        self._evaluated = True

    def _threaded(self) -> bool:
        """Do the compiled loop's kernels run their threaded builds (``jit.serial_run``
        of the larger of the particle and pair counts)?"""
        return not serial_run(max(self.p.n, self.nl.n_pairs), self._threads)

    def _block_bounds(self) -> np.ndarray:
        """The blocks of the threaded pair pass (``contact.pair_block_bounds``: equal pair
        work, ``BLOCKS_PER_THREAD`` per thread; the pairs across them into ``_xpairs[:_nx[0]]``,
        ``contact.pair_cross_list``), cut again after a neighbour rebuild and
        every ``REBALANCE_EVERY`` steps as contacts move (no result depends on them). A
        cut made on a new list (whose ``pinfo`` holds placeholders) is made again once
        the list has been evaluated."""
        nblk = BLOCKS_PER_THREAD * max(self._threads or numba.get_num_threads(), 1)
        key = (self.nl, nblk, self._evaluated)  # the list itself: ids can be reused
        if (key[0] is not self._bounds_key[0] or key[1:] != self._bounds_key[1:]
                or self.step_count % REBALANCE_EVERY == 0):
            if self._bounds.shape[0] != nblk + 1:
                self._bounds = np.zeros(nblk + 1, dtype=np.int64)
            if self._xpairs.shape[0] != self.nl.n_pairs:
                self._xpairs = np.zeros(self.nl.n_pairs, dtype=np.int64)
            pair_block_bounds(self.nl.start, self.pinfo, nblk, self._bounds)
            self._nx[0] = pair_cross_list(self.nl.pair_i, self.nl.pair_j, self._bounds,
                                          self._xpairs)
            self._bounds_key = key
        return self._bounds

    def _wall_pass(self) -> None:
        """Plane-wall contacts of the near-wall candidates (``walls.wall_forces``); sets each
        wall's measured force, contact count and stiffness (for the servo)."""
        if not self.walls:
            return
        p = self.p
        wp, wn, wv, wm = self._walls_now
        laws.active(wall_forces).pick(p.n, self._threads)(
            p.pos, p.vel, p.omega, p.radius, p.mass, p.inertia, p.mat, self._wstart,
            self._wid, self._wpart, self._wbstart, wp, wn, wv, wm, self.wall_hist,
            self.wall_info, self._wsum, self.pairtab, self.elin, p.dim, p.thickness, self.dt,
            self._wforce, self._wtorque, self._wtot)
        rows = self._wtot.tolist()  # Python floats: cheaper than numpy scalars for a few walls
        for w_id, w in enumerate(self.walls):
            f0, f1, f2, nc, kn = rows[w_id]
            n0, n1, n2 = w.normal.tolist()
            w.force = np.array((f0, f1, f2))
            w.normal_force = -(f0 * n0 + f1 * n1 + f2 * n2)
            w.contacts = int(nc)
            w.stiffness = kn

    def _advance(self) -> None:
        p = self.p
        advance.pick(p.n, self._threads)(
            p.pos, p.vel, p.omega, p.radius, p.mass, p.inertia, p.fixed, self._wstart,
            self._wforce, self._wtorque, self.dt, self.gravity,
            self.viscous_damping, self.local_damping, bool(self.interactions), self.ext_force,
            self.ext_torque, self.force, self.torque, self.nl.ref_pos, self.nl.ref_radius,
            self.box.lo, self.box_length, self.box.periodic, self.drift)

    def step(self, n: int = 1) -> None:
        """Advance ``n`` steps. Raises ``SimulationUnstable`` (recorders flushed) on blow-up.

        A step: neighbour list if needed -> pair contacts -> extra interactions (into
        ``ext_force``/``ext_torque``) -> walls -> per particle: sum, update, wrap ->
        ``after_advance`` hooks (clump bodies) -> walls move (servo uses the wall force
        just measured). Runs of steps go through one compiled loop when every piece has a
        compiled form (``_compiled_states``), else step by step in Python.
        """
        self._threads = numba.get_num_threads()  # once per call: kernels pick builds by it
        self.box_length = self.box.length  # once per call (the property makes an array)
        try:
            if self.step_count == 0 and self.time == 0.0:
                self._sample(force=True)
            done = 0
            while done < n:
                states = self._compiled_states()
                if states is None:
                    self._python_step()
                    done += 1
                else:
                    done += self._compiled_run(states, n - done)
        except SimulationUnstable:
            self.close_recorders()
            raise

    def _python_step(self) -> None:
        """One step, piece by piece in Python."""
        # the walls' arrays of this step (they move only after the update)
        self._refresh_walls()
        self._maybe_rebuild()
        self._pair_forces()
        if self.interactions:
            self.ext_force[:] = 0.0
            self.ext_torque[:] = 0.0
            for inter in self.interactions:
                inter.compute(self)
        if self.track_energy:
            p = self.p
            self._at_force_eval = (p.pos.copy(), p.vel.copy(), p.omega.copy())
        self._wall_pass()
        self._advance()
        for inter in self._after:
            inter.after_advance(self)
        for w in self.walls:
            w.update_motion(self.dt)
        self.step_count += 1
        self.time += self.dt
        if self.step_count % self.check_every == 0:
            self.check_stability()
        self._sample()

    def _compiled_states(self) -> tuple | None:
        """The interactions' compiled states (in order, closed by ``NoStep``) if the next
        steps can run in the compiled loop: the built-in contact laws only, no
        ``after_advance`` hook, no energy tracking, and a compiled form from every
        interaction -- on threads only without interactions (their compiled steps are
        serial; threaded, the Python loop runs their threaded kernels); else ``None``."""
        if (not self.compiled_loop or self.track_energy or self._after
                or len(laws.modules()) != len(laws.BUILTIN)
                or (self.interactions and self._threaded())):
            return None
        states = []
        for inter in self.interactions:
            form = getattr(inter, "compiled", None)
            st = form(self) if form is not None else None
            if st is None or not registered(st):
                return None
            states.append(st)
        states.append(NoStep())
        return tuple(states)

    def _context(self) -> StepContext:
        """The arrays and constants of the compiled loop (shared with this object)."""
        p, nl = self.p, self.nl
        wp, wn, wv, wm = self._walls_now
        nw = len(self.walls)
        wpar = np.zeros((nw, N_WPAR))
        wnf = np.zeros(nw)
        for k, w in enumerate(self.walls):
            wpar[k] = (WALL_MODES.index(w.mode), w.target_force, w.servo_mass,
                       w.servo_damping, w.servo_gain_alpha, w.max_speed)
            wnf[k] = w.normal_force
        ref_p, ref_n = self._wall_ref if nw else (np.zeros((0, 3)), np.zeros((0, 3)))
        return StepContext(
            p.pos, p.vel, p.omega, p.radius, p.mass, p.inertia, p.mat, p.group, p.fixed,
            self.force, self.torque, self.ext_force, self.ext_torque, nl.start, nl.pair_i,
            nl.pair_j, nl.rev_start, nl.rev_pair, nl.ref_pos, nl.ref_radius, self.hist,
            self.pinfo, self.fpair, self.tpair_i, self.tpair_j, self.pairtab, self.elin,
            self._wstart, self._wid, self._wpart, self._wbstart, self.wall_hist,
            self.wall_info, self._wsum, self._wforce, self._wtorque, self._wtot, wp, wn, wv,
            wm, wpar, wnf, ref_p, ref_n, self.drift, self.gravity, self.box.lo,
            self.box_length, self.box.periodic, np.array([self.time]), int(p.dim),
            float(p.thickness), float(self.dt), self.viscous_damping, self.local_damping,
            bool(self.interactions), 0.5 * self.skin)

    def _compiled_run(self, states: tuple, nmax: int) -> int:
        """Steps in the compiled loop (``_run_steps``), at most ``nmax``, up to the next
        event: a neighbour rebuild, an interaction's event, a failed stability check or a
        recorder sample (those run here, in Python, as in ``_python_step``; a passed
        check needs no return). Returns the steps done (>= 1)."""
        c, limit = self._compiled_begin(nmax)
        if self._threaded():
            with numba.parallel_chunksize(THREADED_CHUNK):
                k, _why, _events = _run_steps(c, states, limit, self.step_count,
                                              self.check_every, self.max_overlap_ratio,
                                              self._block_bounds(), self._xpairs, self._nx)
        else:
            k, _why, _events = _run_steps(c, states, limit, self.step_count,
                                          self.check_every, self.max_overlap_ratio, None,
                                          None, None)
        return self._compiled_end(c, states, k)

    def _compiled_begin(self, nmax: int) -> tuple[StepContext, int]:
        """Before a run of the compiled loop: the walls' arrays, a neighbour rebuild if
        due, the context, and how many steps (at most ``nmax``) may run before the next
        recorder sample. ``benchmarks/profile_step.py`` steps kernel by kernel between
        this and :meth:`_compiled_end`."""
        self._refresh_walls()
        self._maybe_rebuild()
        limit = nmax
        for every, _ in self.recorders:
            limit = min(limit, every - self.step_count % every)
        return self._context(), limit

    def _compiled_end(self, c: StepContext, states: tuple, k: int) -> int:
        """After ``k`` steps of the compiled loop on context ``c``: the walls' state and
        totals back into the wall objects, the counters, the interactions'
        ``after_compiled`` hooks, the stability check and the recorders. Returns ``k``."""
        self._evaluated = True
        rows = c.wall_tot.tolist()
        for w_id, w in enumerate(self.walls):
            f0, f1, f2, nc, kn = rows[w_id]
            w.force = np.array((f0, f1, f2))
            w.normal_force = float(c.wall_nf[w_id])
            w.contacts = int(nc)
            w.stiffness = kn
            w.target_force = float(c.wall_par[w_id, W_TARGET])
            w.velocity = c.wall_vel[w_id].copy()
            w.point = c.wall_point[w_id].copy()
        self.step_count += k
        self.time = float(c.clock[0])
        for inter, st in zip(self.interactions, states, strict=False):
            hook = getattr(inter, "after_compiled", None)
            if hook is not None:
                hook(self, st)
        if self.step_count % self.check_every == 0:
            self.check_stability()
        self._sample()
        return k

    def run(self, steps: int, progress: bool = False, chunk: int = 1000) -> None:
        """Advance ``steps`` steps, optionally with a progress bar."""
        if not progress:
            self.step(steps)
            return
        from tqdm import tqdm

        with tqdm(total=steps, unit="step", leave=False) as bar:
            done = 0
            while done < steps:
                k = min(chunk, steps - done)
                self.step(k)
                done += k
                bar.update(k)

    def _sample(self, force: bool = False) -> None:
        for every, rec in self.recorders:
            if force or self.step_count % every == 0:
                rec.sample(self)

    def close_recorders(self) -> None:
        """Flush and close all recorders (outputs so far are kept)."""
        for _, rec in self.recorders:
            rec.close()

    def check_stability(self) -> None:
        """Stop with a reason if positions/velocities are not finite or overlaps run away."""
        p = self.p
        bad = ~np.isfinite(p.pos).all(axis=1) | ~np.isfinite(p.vel).all(axis=1)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise SimulationUnstable(
                f"step {self.step_count} (t = {self.time:.6g} s): particle {i} has a non-finite "
                f"position or velocity; time step {self.dt:.4g} s vs critical "
                f"{self.dt_critical:.4g} s ({self.dt_limit_by})")
        if self.nl.n_pairs:
            rmin = np.minimum(p.radius[self.nl.pair_i], p.radius[self.nl.pair_j])
            ratio = self.pinfo[:, 0] / rmin
            q = int(np.argmax(ratio))
            if ratio[q] > self.max_overlap_ratio:
                raise SimulationUnstable(
                    f"step {self.step_count} (t = {self.time:.6g} s): overlap of pair "
                    f"({int(self.nl.pair_i[q])}, {int(self.nl.pair_j[q])}) is {ratio[q]:.3g} of "
                    f"the smaller radius (limit {self.max_overlap_ratio}): the load is too high "
                    f"for the stiffness or the time step {self.dt:.4g} s is too large")

    # ------------------------------------------------------------------ measurements
    def kinetic_energy(self) -> float:
        """Translational + rotational kinetic energy (J) at the current (half-step) velocities."""
        p = self.p
        with np.errstate(over="ignore", invalid="ignore"):
            return float(0.5 * (p.mass * (p.vel**2).sum(axis=1)).sum()
                         + 0.5 * (p.inertia * (p.omega**2).sum(axis=1)).sum())

    def elastic_energy(self) -> float:
        """Energy stored in contact springs (pairs and walls) at the last force evaluation (J)."""
        e = float(self.pinfo[:, 2].sum())
        for w_id in range(len(self.walls)):
            e += float(self.wall_info[w_id, :, 2].sum())
        return e

    def total_energy(self) -> float:
        """Kinetic + elastic + gravity energy (J) at the last force evaluation (integer step).

        Needs ``track_energy=True``: the leapfrog velocity at the step is the mean of the
        half-step velocities around it.
        """
        if self._at_force_eval is None:
            raise RuntimeError("total_energy needs Simulation(track_energy=True) and one step")
        x, v0, w0 = self._at_force_eval
        p = self.p
        v = 0.5 * (v0 + p.vel)
        w = 0.5 * (w0 + p.omega)
        ke = 0.5 * (p.mass * (v**2).sum(axis=1)).sum() + 0.5 * (p.inertia * (w**2).sum(axis=1)
                                                                 ).sum()
        return float(ke) + self.elastic_energy() - float((p.mass * (x @ self.gravity)).sum())

    def gravity_energy(self) -> float:
        """Potential energy in the gravity field (J), zero at the origin."""
        return float(-(self.p.mass * (self.p.pos @ self.gravity)).sum())

    def _overlaps(self) -> np.ndarray:
        """Overlap of every listed pair, m (> 0 in contact). Before the first force evaluation
        (the sample at step 0) ``pinfo`` holds placeholders, so it comes from geometry."""
        if self._evaluated:
            return self.pinfo[:, 0]
        p, i, j = self.p, self.nl.pair_i, self.nl.pair_j
        d = p.pos[j] - p.pos[i]
        per = np.asarray(self.box.periodic, dtype=bool)
        if per.any():
            L = np.asarray(self.box.length, dtype=float)
            d[:, per] -= L[per] * np.round(d[:, per] / L[per])
        return p.radius[i] + p.radius[j] - np.linalg.norm(d, axis=1)

    def _active(self) -> np.ndarray:
        return self._overlaps() > 0

    def cross_group_force(self) -> float:
        """Summed normal force (N) of the touching pairs whose two particles are in
        different groups and push (normal force > 0): the load through an interface
        between bodies. Equals ``contacts()`` filtered on the groups and summed with numpy
        (same bits), without building the contact arrays."""
        if not self._evaluated:
            c = self.contacts()
            g = self.p.group
            f = c["normal_force"]
            return float(f[(g[c["i"]] != g[c["j"]]) & (f > 0)].sum())
        if self._cross.shape[0] != self.nl.n_pairs:
            self._cross = np.zeros(self.nl.n_pairs)
        return float(cross_group_sum(self.pinfo, self.nl.pair_i, self.nl.pair_j,
                                     self.p.group, self._cross))

    def n_contacts(self) -> int:
        """Particle-particle contacts carrying force (touching, before the first step)."""
        return int(np.count_nonzero(self._active()))

    def contacts(self) -> dict[str, np.ndarray]:
        """Active particle-particle contacts: i, j, overlap (m), normal force (N, + = push),
        force vector on j (N)."""
        ov = self._overlaps()
        act = ov > 0
        return {"i": self.nl.pair_i[act], "j": self.nl.pair_j[act],
                "overlap": ov[act], "normal_force": self.pinfo[act, 1],
                "force": self.fpair[act]}

    def memory(self) -> dict[str, float]:
        """Bytes held per particle (particle, wall and per-particle engine arrays), per listed
        pair (pair list, history, forces) and in total (numpy arrays of the engine)."""
        n, m = max(self.p.n, 1), max(self.nl.n_pairs, 1)
        per_particle = [*self.p.arrays().values(), self.p.mass, self.p.inertia, self.force,
                        self.torque, self.ext_force, self.ext_torque, self.wall_hist,
                        self.wall_info, self._wforce, self._wtorque, self.nl.start,
                        self.nl.rev_start, self.nl.ref_pos, self.nl.ref_radius]
        per_pair = [self.nl.pair_i, self.nl.pair_j, self.nl.rev_pair, self.hist, self.fpair,
                    self.tpair_i, self.tpair_j, self.pinfo]
        bp = sum(a.nbytes for a in per_particle)
        bq = sum(a.nbytes for a in per_pair)
        return {"bytes_per_particle": bp / n, "bytes_per_pair": bq / m,
                "pairs_per_particle": self.nl.n_pairs / n, "total_bytes": float(bp + bq)}

    # ------------------------------------------------------------------ checkpoints
    def save_checkpoint(self, path: str | Path, record: Mapping[str, Any] | None = None
                        ) -> Path:
        """Write the full state atomically (``.npz``): resuming gives bitwise the same run.

        ``record``: what the caller keeps beside the state (JSON-able; a run's resolved
        config, :func:`tribodem.io.record.checkpoint_meta`), read back with
        :func:`read_checkpoint_record`; :meth:`load_checkpoint` does not look at it.
        """
        arrays: dict[str, np.ndarray] = {f"p_{k}": v for k, v in self.p.arrays().items()}
        arrays.update({
            "nl_start": self.nl.start, "nl_pair_i": self.nl.pair_i, "nl_pair_j": self.nl.pair_j,
            "nl_rev_start": self.nl.rev_start, "nl_rev_pair": self.nl.rev_pair,
            "nl_ref_pos": self.nl.ref_pos, "nl_ref_radius": self.nl.ref_radius,
            "hist": self.hist, "wall_hist": self.wall_hist, "wall_info": self.wall_info,
            "pinfo": self.pinfo, "force": self.force, "torque": self.torque,
            "drift": self.drift, "ext_force": self.ext_force, "ext_torque": self.ext_torque,
            "wall_ref_point": self._wall_ref[0] if self.walls else np.zeros((0, 3)),
        })
        for w_id, w in enumerate(self.walls):
            for k, v in w.state().items():
                arrays[f"w{w_id}_{k}"] = v
        for x_id, inter in enumerate(self.interactions):  # bonds, thermal, ...
            if hasattr(inter, "state"):
                for k, v in inter.state().items():
                    arrays[f"x{x_id}_{k}"] = v
        meta = {"version": CHECKPOINT_VERSION, "step": self.step_count, "time": self.time,
                "dt": self.dt, "nl_builds": self.nl.builds, "skin": self.skin,
                "n": self.p.n}
        arrays["meta"] = np.array(json.dumps(meta))
        arrays["time_exact"] = np.array([self.time])
        if record is not None:
            arrays["record"] = np.array(json.dumps(dict(record)))
        return write_npz(path, **arrays)

    def load_checkpoint(self, path: str | Path) -> None:
        """Restore a checkpoint written by ``save_checkpoint`` into this (same-setup) simulation."""
        with np.load(path, allow_pickle=False) as z:
            meta = json.loads(str(z["meta"]))
            if meta.get("version") != CHECKPOINT_VERSION:
                raise ValueError(f"checkpoint '{path}': version {meta.get('version')} is not "
                                 f"supported (expected {CHECKPOINT_VERSION})")
            if meta["n"] != self.p.n:
                raise ValueError(f"checkpoint '{path}': {meta['n']} particles, but the "
                                 f"simulation has {self.p.n}")
            for k in self.p.arrays():
                setattr(self.p, k, z[f"p_{k}"].copy())
            self.p.update_mass()
            self.nl = neighbors.NeighborList(
                z["nl_start"].copy(), z["nl_pair_i"].copy(), z["nl_pair_j"].copy(),
                z["nl_rev_start"].copy(), z["nl_rev_pair"].copy(), z["nl_ref_pos"].copy(),
                z["nl_ref_radius"].copy(), float(meta["skin"]), int(meta["nl_builds"]))
            self.skin = float(meta["skin"])
            self._alloc_pairs()
            self.hist = z["hist"].copy()
            self.wall_hist = z["wall_hist"].copy()
            self.wall_info = z["wall_info"].copy()
            self.pinfo = z["pinfo"].copy()
            self.force = z["force"].copy()
            self.torque = z["torque"].copy()
            self.drift = z["drift"].copy()
            self.ext_force = z["ext_force"].copy()
            self.ext_torque = z["ext_torque"].copy()
            self._build_wall_list(at=z["wall_ref_point"] if "wall_ref_point" in z.files
                                  else None)
            for w_id, w in enumerate(self.walls):
                w.set_state({k: z[f"w{w_id}_{k}"] for k in ("point", "velocity", "force",
                                                            "scalars")})
            for x_id, inter in enumerate(self.interactions):
                if hasattr(inter, "set_state"):
                    pre = f"x{x_id}_"
                    inter.set_state({k[len(pre):]: z[k] for k in z.files if k.startswith(pre)})
            self.step_count = int(meta["step"])
            self._evaluated = self.step_count > 0
            self.time = float(z["time_exact"][0])
            self.dt = float(meta["dt"])


def read_checkpoint_record(path: str | Path) -> dict[str, Any] | None:
    """The ``record`` a checkpoint was saved with (:meth:`Simulation.save_checkpoint`), or
    None when it has none (saved without one, or by an older tribodem). Raises what numpy
    raises for a file that is not a readable ``.npz``."""
    with np.load(path, allow_pickle=False) as z:
        if "record" not in z.files:
            return None
        record = json.loads(str(z["record"]))
    return record if isinstance(record, dict) else None
