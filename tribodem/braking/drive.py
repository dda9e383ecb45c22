"""The braking loop's engine interaction (:class:`SlidingDrive`): load and speed ramps, the
per-step sums (plate force, distance slid, looks at the disc-pad contacts) and the
carrier of the loop's own state into the engine checkpoint.

Once the ramps are over it runs inside the engine's compiled step loop
(:class:`LoopStep`, the same operations as :meth:`SlidingDrive.compute`).
"""

from __future__ import annotations

import json
from typing import Any, NamedTuple

import numpy as np
from numba import njit

from tribodem.braking.checkpoint import LOOP_KEY
from tribodem.braking.model import Interface, plate_force, wall_index
from tribodem.dem import compiled as dem_compiled
from tribodem.dem.engine import cross_group_sum

#: steps between two looks at the disc-pad contacts (``contact_fraction``)
CONTACT_EVERY = 16


def interface_load(iface: Interface) -> float:
    """Load (N) carried through the interface now: the summed normal force of the active
    contacts between a disc particle and a pad particle (matrix or debris)."""
    return iface.sim.cross_group_force()  # the groups are the bodies (DISC, PAD)


class LoopStep(NamedTuple):
    """``SlidingDrive``'s compiled form once the ramps are over: its plate wall's index in
    ``sim.walls``, the backing's reaction ``reaction`` = [N] (``BackingStep.out``) if it
    has one (``backing``), ``acc`` = [summed plate force N, distance slid m], ``n`` =
    [steps], ``contact`` (the look accumulators), the full target (N), the sliding speed
    (m/s), the steps between looks, a buffer for the interface forces."""

    wall: int
    backing: bool
    reaction: np.ndarray
    acc: np.ndarray
    n: np.ndarray
    contact: np.ndarray
    full: float
    speed: float
    every: int
    buf: np.ndarray


@dem_compiled.register(LoopStep)
@njit(cache=True)
def _loop_step(s, c):  # pragma: no cover - numba
    """``SlidingDrive.compute`` after the ramps, in the engine's compiled loop (the same
    operations): the plate force summed, a look at the interface every ``every`` steps,
    the distance slid."""
    if s.backing:
        s.acc[0] += c.wall_nf[s.wall] + s.reaction[0]
    else:
        s.acc[0] += c.wall_nf[s.wall]
    if s.n[0] % s.every == 0:
        buf = s.buf if s.buf.shape[0] >= c.pair_i.shape[0] else np.zeros(c.pair_i.shape[0])
        load = cross_group_sum(c.pinfo, c.pair_i, c.pair_j, c.group, buf)
        s.contact[0] += 1.0
        s.contact[1] += 1.0 if load > 0.0 else 0.0
        s.contact[2] += load / s.full
    s.acc[1] += s.speed * 1.0 * c.dt
    s.n[0] += 1
    return 0


class SlidingDrive:
    """An engine interaction that averages the plate's force on the pad (N) every step --
    wall contacts plus the backing dashpots' reaction --, ramps the load over
    ``ramp_steps`` and the disc's speed (m/s) over ``speed_ramp_steps``, sums the distance
    slid (m) and looks at the disc-pad contacts every ``CONTACT_EVERY`` steps; it carries
    the braking loop's own state (``record``: JSON-able, ``arrays``: numpy) into the engine
    checkpoint through ``state``/``set_state``, so one atomic file holds everything a
    resumed run needs."""

    def __init__(self, iface: Interface, ramp_steps: int = 0, speed_ramp_steps: int = 0,
                 speed: float = 0.0) -> None:
        self.iface = iface
        self.total = 0.0
        self.n = 0
        self.record: dict[str, Any] = {}
        self.arrays: dict[str, np.ndarray] = {}
        self.ramp_steps = ramp_steps
        self.full = iface.target_force
        # contact accounting every CONTACT_EVERY steps: looks, looks with load through the
        # interface, sum of the interface load / target
        self.contact = np.zeros(3)
        self.speed_steps, self.speed = speed_ramp_steps, speed
        self.distance = 0.0  # m slid by the disc's anchored layer
        self._buf = np.zeros(1)  # the compiled form's interface-force buffer (N)
        self.apply()

    def apply(self) -> None:
        """The plate's target after ``n`` steps: ramped linearly over ``ramp_steps``."""
        f = self.full * min(1.0, (self.n + 1) / self.ramp_steps) if self.ramp_steps \
            else self.full
        if self.iface.backing is not None:
            self.iface.backing.target = f
        else:
            self.iface.wall.target_force = f

    def compute(self, sim: Any) -> None:
        """One step: the plate force summed, a look at the contacts every
        ``CONTACT_EVERY`` steps, the disc's speed on its ramp, the distance slid, the
        load ramp's next target."""
        self.total += plate_force(self.iface)
        if self.n % CONTACT_EVERY == 0:
            load = interface_load(self.iface)
            self.contact += (1.0, float(load > 0.0), load / self.full)
        f = min(1.0, (self.n + 1) / self.speed_steps) if self.speed_steps else 1.0
        if self.speed_steps and self.n < self.speed_steps:  # used by this step's advance
            sim.p.vel[self.iface.anchor_disc, 0] = -self.speed * f
        self.distance += self.speed * f * sim.dt
        self.n += 1
        if self.ramp_steps and self.n <= self.ramp_steps:
            self.apply()

    def particles_appended(self, sim: Any, n_old: int) -> None:
        """Engine hook: the drive holds no per-particle state."""

    def compiled(self, sim: Any) -> LoopStep | None:
        """The compiled form (``LoopStep``) once the load and speed ramps are over (the
        ramps step in Python), else ``None``."""
        if (self.ramp_steps and self.n < self.ramp_steps) or (
                self.speed_steps and self.n < self.speed_steps):
            return None
        back = self.iface.backing
        reaction = back.reaction_buffer if back is not None else np.zeros(1)
        m = sim.nl.n_pairs
        if self._buf.shape[0] < m:
            self._buf = np.zeros(m)
        return LoopStep(wall_index(sim, self.iface.wall), back is not None, reaction,
                        np.array([self.total, self.distance]), np.array([self.n]),
                        self.contact, float(self.full), float(self.speed), CONTACT_EVERY,
                        self._buf)

    def after_compiled(self, sim: Any, state: LoopStep) -> None:
        """Copy back the sums and the step count of the compiled loop."""
        self.total = float(state.acc[0])
        self.distance = float(state.acc[1])
        self.n = int(state.n[0])

    @property
    def mean(self) -> float:
        """The plate's mean force on the pad over the steps so far (N)."""
        return self.total / self.n if self.n else float("nan")

    def state(self) -> dict[str, np.ndarray]:
        """The wall-mean accumulator, the loop record (JSON) and the loop's arrays."""
        out = {f"a_{k}": v for k, v in self.arrays.items()}
        out["wall"] = np.array([self.total, float(self.n)])
        out["contact"] = self.contact.copy()
        out["distance"] = np.array([self.distance])
        out[LOOP_KEY] = np.array(json.dumps(self.record))
        return out

    def set_state(self, s: dict[str, np.ndarray]) -> None:
        """Restore what ``state`` returned."""
        self.total, n = (float(x) for x in s["wall"])
        self.n = int(n)
        self.contact = np.array(s["contact"], dtype=np.float64)
        self.distance = float(s["distance"][0])
        self.apply()
        self.record = json.loads(str(s[LOOP_KEY]))
        self.arrays = {k[2:]: np.array(v) for k, v in s.items() if k.startswith("a_")}
