"""One braking-interface run: build, load, slide, measure, write results.

Time mapping (DESIGN.md, never hidden): the run integrates ``duration_s`` of sliding
step by step at the physical speed, i.e. a sliding distance ``v x duration_s`` (tens to
hundreds of um). The simulated time IS the braking time it represents
(``equivalent_braking_time_s = simulated_time_s``, no time scaling). The seed's 8 s of
braking (377 m at 47 m/s) is out of reach; the summary reports the fraction simulated and,
separately labelled, a linear extrapolation of the mean wear depth to 8 s from the steady
wear rate (least-squares slope over the second half of the run).

Steady state (issue 15): ``until_steady`` slides past ``duration_s`` in blocks of 20% of
it until ``steady_state`` holds on the wear depth against the sliding distance (the
last-third rate within ``steady_tolerance`` of the middle-third rate, on the run and on
the run cut to 90 % and 80 % of its distance: ``STEADY_CUTS``), at most
``max_distance_m``; every summary reports ``wear_rate_steady_m_per_m``, the run-in distance
and depth, and ``contact_fraction`` (share of looks, one every ``CONTACT_EVERY`` steps, at
which a disc-pad contact carries load). ``ramp_s`` ramps the load on from 0. The closed
cell of the seed saturates (no debris leaves it); ``outlet_length_m`` lets debris leave
(``braking.outlet``), checked between engine calls at most every quarter cell width of
disc travel, so that the wear reaches a steady flow.

Checkpoints and resuming (``run_braking(..., resume=True)``, ``tribodem braking run
--resume``): one file, ``<out>/checkpoint.npz``, written atomically by the engine's
``Simulation.save_checkpoint`` after the first sample, every ``checkpoint_every`` samples
(default ceil(samples / 10): about every 10% of the run) and at the end. Besides the
engine state (particles, neighbour list, contact history, walls, bonds, thermal, the pad
backing) it holds the braking loop's own state, carried by the ``_Loop`` interaction's
``state()``: steps done, every sample row so far, the VTK index entries and counters, the
figure frames, the reference positions, the wall-mean accumulator, the wall-time so far
and the setup (JSON) the checkpoint belongs to. A resume rebuilds the interface from the
same setup (the build is deterministic: same seed -> bitwise the same packing; checked
against the stored reference positions), loads the checkpoint and continues: the rows,
the ``.pvd`` indexes and the summary come out bitwise as in an uninterrupted run (the
``wall_time*`` fields excepted). A setup that differs from the checkpoint's (anything but
``checkpoint_every`` and ``figures``) or a checkpoint that cannot be read is refused with
``ConfigError`` before any output is touched. ``timeseries.csv`` is rewritten (atomically)
at every checkpoint and at most every 2 s of wall time in between; rows written after the
last checkpoint are recomputed identically on resume.
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
from numba import njit

from tribodem.braking.conditions import SEED_BRAKING_TIME_S, pressure_to_load, speed_to_rpm
from tribodem.braking.feed import Feed
from tribodem.braking.measure import Reference, force_chains, measure, reference
from tribodem.braking.model import (
    DISC,
    EJECTED,
    PAD,
    Geometry,
    Interface,
    build_interface,
    plate_force,
    start_sliding,
    wall_index,
)
from tribodem.braking.outlet import Outlet
from tribodem.dem import compiled as dem_compiled
from tribodem.dem.engine import cross_group_sum
from tribodem.dem.thermal import Thermal, read_curve
from tribodem.io import runs
from tribodem.io.config import ConfigError
from tribodem.io.results import write_csv, write_json
from tribodem.io.runs import RunStopped
from tribodem.io.vtk import write_lines, write_points, write_pvd

#: heat capacities (J/(kg K)) of the thermal boundary option; the seed gives none:
#: handbook values for structural steel and a Cu-based sintered material
HEAT_CAPACITY = {DISC: 460.0, PAD: 400.0}

#: the run's checkpoint in its output folder (see the module docstring)
CHECKPOINT = "checkpoint.npz"
LOOP_VERSION = 2
LOOP_KEY = "braking_loop"
#: ``RunSetup`` fields a resumed run may change: they do not change the results
RESUME_FREE = ("checkpoint_every", "figures")


#: a body is worn through when its remaining thickness (``measure``: intact matrix and
#: delaminated slab outside the anchored layer, solid area over ``phi W``) falls below this
#: many of its mean particle diameters (the default of ``RunSetup.worn_through_diameters``):
#: the anchored boundary layer, not the body, then meets the sliding interface, so the cell
#: no longer models the surface zone of a thick pad or disc. The run stops there (exit 3,
#: every output written). With the debris outlet the bodies are consumed at the wear rate
#: (session 29: the 72-um disc of the default cell within 5-12 mm in 9 of 22 runs)
WORN_THROUGH = 2.0
#: the measured columns added after checkpoints were first written whose rows of an older
#: checkpoint are unknown (nan), not zero
REMAINING = ("remaining_thickness_disc_m", "remaining_thickness_pad_m")


@dataclass
class RunSetup:
    """Everything a run needs (SI). ``condition`` is the table 4 index or ``None``."""

    pressure_Pa: float
    speed_m_s: float
    duration_s: float
    geometry: Geometry = field(default_factory=Geometry)
    condition: int | None = None
    micro: str = "calibrated"
    samples: int = 100
    vtk_snapshots: int = 6
    wall_mass_ratio: float = 0.05
    backing: str = "absorbing"
    plate_areal_mass: float | None = None
    local_damping: float = 0.0
    dt_safety: float = 0.3
    thermal_curve: Path | None = None
    thermal_time_map: str = "simulated"
    figures: bool = True
    checkpoint_every: int = 0  # samples between checkpoints; 0: ceil(samples / 10)
    #: slide past ``duration_s`` until the wear rate per sliding distance is steady
    #: (``steady_state``), in blocks of 20% of ``duration_s``, at most ``max_distance_m``
    until_steady: bool = False
    max_distance_m: float = 0.0  # 0: 5 x the distance of duration_s
    steady_tolerance: float = 0.15
    #: applying the load: the full target at once (``0``) or ramped linearly from 0 over
    #: ``ramp_s`` seconds of sliding (the pad applied as a hydraulic pressure builds up)
    ramp_s: float = 0.0
    #: sliding ramped up: the disc starts at rest under the pad (full load) and its speed
    #: rises linearly to ``speed_m_s`` over ``speed_ramp_s`` seconds (0: at speed at once)
    speed_ramp_s: float = 0.0
    #: debris outlet (``outlet``): a debris component leaves the cell once carried this
    #: far (m) along the sliding relative to the pad; 0 = closed cell (seed 000)
    outlet_length_m: float = 0.0
    #: stop when a body's remaining thickness falls below this many of its mean particle
    #: diameters (``WORN_THROUGH``); 0 = never stop
    worn_through_diameters: float = WORN_THROUGH
    #: feed fresh body behind a worn one (``braking.feed``; the bodies are then cut from a
    #: block periodic in y)
    feed: bool = False


class LoopStep(NamedTuple):
    """``_Loop``'s compiled form once the ramps are over: its plate wall's index in
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
    """``_Loop.compute`` after the ramps, in the engine's compiled loop (the same
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


class _Loop:
    """An engine interaction that averages the plate's force on the pad (N) every step --
    wall contacts plus the backing dashpots' reaction -- and carries the braking loop's own
    state (``record``: JSON-able, ``arrays``: numpy) into the engine checkpoint through
    ``state``/``set_state``, so one atomic file holds everything a resumed run needs."""

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
        """Engine hook: the loop holds no per-particle state."""

    def compiled(self, sim: Any) -> LoopStep | None:
        """The compiled form (``LoopStep``) once the load and speed ramps are over (the
        ramps step in Python), else ``None``."""
        if (self.ramp_steps and self.n < self.ramp_steps) or (
                self.speed_steps and self.n < self.speed_steps):
            return None
        back = self.iface.backing
        reaction = back._out if back is not None else np.zeros(1)
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


#: steps between two looks at the disc-pad contacts (``contact_fraction``)
CONTACT_EVERY = 16
#: ``contact_fraction`` from which the interface counts as closed (issue 15: a pad under
#: hydraulic pressure is in contact >= 90 % of the time); below it the summary's
#: assumptions say that the rates average contact episodes
CLOSED_CONTACT = 0.9


def interface_load(iface: Interface) -> float:
    """Load (N) carried through the interface now: the summed normal force of the active
    contacts between a disc particle and a pad particle (matrix or debris)."""
    return iface.sim.cross_group_force()  # the groups are the bodies (DISC, PAD)


def _slope(x: np.ndarray, y: np.ndarray) -> float:
    return float(np.polyfit(x, y, 1)[0]) if x.size >= 2 and np.ptp(x) > 0 else float("nan")


#: the steady-state test must hold on the run and on the run cut to these fractions of
#: its distance: a single pass can be luck on a depth that moves in steps (session 25,
#: ten 16-mm runs: the test alone passed in 9, at 3-14 mm, reporting rates 0.3-74x those
#: of the runs' second halves; with the cuts it passed in none)
STEADY_CUTS = (1.0, 0.9, 0.8)
#: ``until_steady`` slides on in blocks of this fraction of ``duration_s`` between tests
STEADY_BLOCK = 0.2


def worn_floor(ref: Reference, diameters: float = WORN_THROUGH) -> dict[str, float]:
    """Per body ("disc", "pad") the remaining thickness (m) below which it is worn
    through: ``diameters`` (``RunSetup.worn_through_diameters``) mean particle diameters
    of that body (0: never)."""
    return {name: diameters * 2.0 * float(ref.radius[ref.group == body].mean())
            for body, name in ((DISC, "disc"), (PAD, "pad"))}


def _worn_text(worn: dict[str, Any]) -> str:
    """The start of the sentence saying where a body was worn through (``worn_through``),
    for the stop's message and the summary's note; its parenthesis is left open."""
    return (f"the {worn['body']} was worn through after "
            f"{1e3 * worn['sliding_distance_m']:.3g} mm of sliding (remaining thickness "
            f"{1e6 * worn['remaining_thickness_m']:.3g} um < {1e6 * worn['floor_m']:.3g} um")


def worn_through(row: dict[str, float], floor: dict[str, float]) -> dict[str, Any] | None:
    """The first body worn through in a measurement row (``worn_floor``), or None."""
    for name, f in floor.items():
        left = row.get(f"remaining_thickness_{name}_m", float("inf"))
        if left < f:
            return {"body": name, "sliding_distance_m": row["sliding_distance_m"],
                    "remaining_thickness_m": left, "floor_m": f}
    return None


def _thirds(s: np.ndarray, h: np.ndarray, tol: float) -> tuple[bool, float, float]:
    """(the last third's rate within ``tol`` of the middle third's, positive; the two
    rates, m/m) on one series."""
    a, b = s[-1] / 3.0, 2.0 * s[-1] / 3.0
    mid, last = (s >= a) & (s <= b), s >= b
    r_mid, r_last = _slope(s[mid], h[mid]), _slope(s[last], h[last])
    return bool(r_mid > 0 and abs(r_last - r_mid) <= tol * r_mid), r_mid, r_last


def steady_state(s: np.ndarray, h: np.ndarray, tol: float = 0.15,
                 cuts: tuple[float, ...] = (1.0,)) -> dict[str, Any]:
    """The steady-state test on the wear depth ``h`` (m) against the sliding distance
    ``s`` (m): least-squares rates over the middle and the last third of the distance;
    steady when the middle-third rate is positive and the last-third rate lies within
    ``tol`` of it -- on the series cut to each fraction in ``cuts`` of its distance (the
    runs use ``STEADY_CUTS``: the whole run, 90 % and 80 % of it). The steady rate (m of
    wear per m slid) is the slope over the last two thirds of the whole series; the run-in
    is its first third (its distance, and the depth at its end)."""
    s, h = np.asarray(s, dtype=float), np.asarray(h, dtype=float)
    nan = float("nan")
    if s.size < 6 or not s[-1] > 0:
        return {"steady": False, "rate": nan, "rate_mid": nan, "rate_last": nan,
                "run_in_distance": nan, "run_in_depth": nan}
    ok, r_mid, r_last = _thirds(s, h, tol)
    for f in cuts:
        if not ok:
            break
        if f < 1.0:  # the whole series (1.0) was just tested
            m = s <= f * s[-1] * (1.0 + 1e-12)
            ok = bool(m.sum() >= 6 and _thirds(s[m], h[m], tol)[0])
    a = s[-1] / 3.0
    after = s >= a
    return {"steady": bool(ok), "rate": _slope(s[after], h[after]), "rate_mid": r_mid,
            "rate_last": r_last, "run_in_distance": a,
            "run_in_depth": float(np.interp(a, s, h))}


def differences(old: dict[str, Any], new: dict[str, Any], prefix: str = ""
                ) -> list[tuple[str, Any, Any]]:
    """(dotted name, old, new) of every entry that differs between two nested dicts."""
    out: list[tuple[str, Any, Any]] = []
    for k in sorted(set(old) | set(new), key=str):
        a, b = old.get(k), new.get(k)
        name = f"{prefix}{k}"
        if isinstance(a, dict) and isinstance(b, dict):
            out += differences(a, b, name + ".")
        elif a != b:
            out.append((name, a, b))
    return out


def setup_record(setup: RunSetup) -> dict[str, Any]:
    """The setup as JSON data, without the fields a resumed run may change."""
    d = asdict(setup)
    for k in RESUME_FREE:
        d.pop(k)
    d["thermal_curve"] = None if setup.thermal_curve is None else str(setup.thermal_curve)
    return json.loads(json.dumps(d))


def read_checkpoint(path: str | Path) -> dict[str, Any]:
    """The braking-loop record of a run's checkpoint. Every array is read (zip CRC), so a
    truncated or corrupt file is refused (``ConfigError``) before any work."""
    path = Path(path)
    try:
        with np.load(path, allow_pickle=False) as z:
            for k in z.files:
                z[k]  # noqa: B018 - read it: checks the CRC
            keys = [k for k in z.files if k.endswith("_" + LOOP_KEY)]
            if not keys:
                raise ValueError("it holds no braking-run state (not a braking checkpoint)")
            rec = json.loads(str(z[keys[0]]))
    except Exception as err:  # noqa: BLE001 - any unreadable file
        raise ConfigError(f"checkpoint '{path}' cannot be read: {err}") from None
    if rec.get("version") != LOOP_VERSION:
        raise ConfigError(f"checkpoint '{path}' cannot be read: braking-loop version "
                          f"{rec.get('version')!r}, expected {LOOP_VERSION}")
    return rec


#: setup fields added after checkpoints were first written, with the value the run of an
#: older checkpoint (which does not record them) had -- or, for the worn-through guard,
#: resumes with (a run that had no guard gets the default one from its next sample on)
ADDED_FIELDS: dict[tuple[str, ...], Any] = {("geometry", "first_mode"): 1,
                                             ("outlet_length_m",): 0.0,
                                             ("worn_through_diameters",): WORN_THROUGH,
                                             ("feed",): False}


def check_resumable(rec: dict[str, Any], setup: RunSetup, path: str | Path) -> None:
    """``ConfigError`` naming the first setup field that differs from the checkpoint's run
    (only ``checkpoint_every`` and ``figures`` may change); an older checkpoint's missing
    fields count as their ``ADDED_FIELDS`` values."""
    recorded = json.loads(json.dumps(rec["setup"]))
    for path, value in ADDED_FIELDS.items():
        d = recorded
        for key in path[:-1]:
            d = d.get(key, {})
        d.setdefault(path[-1], value)
    diff = differences(recorded, setup_record(setup))
    if diff:
        name, old, new = diff[0]
        raise ConfigError(
            f"--resume: {name} = {new!r} differs from the checkpointed run's {old!r} "
            f"('{path}'); allowed: the same value (only {', '.join(RESUME_FREE)} may change)")


def checkpoint_interval(setup: RunSetup) -> int:
    """Samples between checkpoints: ``checkpoint_every``, or (0) ceil(samples / 10), i.e.
    about every 10% of the run."""
    return setup.checkpoint_every or max(1, math.ceil(setup.samples / 10))


def body_displacement(iface: Interface, ref: Reference, slid: float) -> np.ndarray:
    """Displacement (m, (n, 3)) in each body's frame: the disc's rigid sliding ``slid``
    (m, in -x) removed; x by minimum image."""
    p = iface.sim.p
    u = p.pos - ref.pos
    u[p.group == DISC, 0] += slid
    w = ref.width
    u[:, 0] -= w * np.rint(u[:, 0] / w)
    return u


def _thermal(iface: Interface, setup: RunSetup, t0: float) -> Thermal:
    times, temps = read_curve(setup.thermal_curve)  # type: ignore[arg-type]
    if setup.thermal_time_map == "stretched":  # the whole curve over the simulated window
        times = times * (setup.duration_s / SEED_BRAKING_TIME_S)
    sim = iface.sim
    g = sim.p.group
    th = Thermal(sim, heat_capacity=np.where(g == PAD, HEAT_CAPACITY[PAD], HEAT_CAPACITY[DISC]),
                 expansion=np.where(g == PAD, iface.pad.expansion, iface.disc.expansion),
                 temperature=float(np.interp(times[0], times, temps)), bonds=iface.bonds)
    for body in (DISC, PAD):
        th.add_boundary(sim, body, times + t0, temps)
    sim.add_interaction(th)
    return th


def _snapshot(out: Path, iface: Interface, ref: Reference, slid: float, k: int, t: float,
              entries: list[tuple[float, str]], chain_entries: list[tuple[float, str]]
              ) -> None:
    from tribodem.braking.measure import classify

    p = iface.sim.p
    matrix, lab = classify(iface)
    name = f"particles_{k:04d}.vtu"
    write_points(out / name, p.pos, {
        "radius": p.radius, "velocity": p.vel, "displacement": body_displacement(iface, ref,
                                                                                 slid),
        "body": p.group, "detached": (~matrix).astype(np.int32), "component": lab})
    entries.append((t, name))
    write_pvd(out / "particles.pvd", entries)
    ch = force_chains(iface)
    f = ch["force"]
    cname = f"chains_{k:04d}.vtu"
    write_lines(out / cname, p.pos, np.stack([ch["i"], ch["j"]], axis=1), {
        "normal_force": f, "strong": (np.abs(f) > np.abs(f).mean()).astype(np.int32)
        if f.size else np.zeros(0, dtype=np.int32)})
    chain_entries.append((t, cname))
    write_pvd(out / "chains.pvd", chain_entries)


def wear_extrapolation(t: np.ndarray, h: np.ndarray, target_s: float) -> tuple[float, float]:
    """(steady wear rate m/s, depth at ``target_s`` m): least-squares slope of h(t) over
    the second half of the record, extrapolated linearly from the last point."""
    half = t >= 0.5 * t[-1]
    if half.sum() < 2:
        return float("nan"), float("nan")
    rate = float(np.polyfit(t[half], h[half], 1)[0])
    return rate, float(h[-1] + max(rate, 0.0) * (target_s - t[-1]))


def run_braking(setup: RunSetup, out: Path | None = None, *, resume: bool = False,
                progress: bool = False, config: dict[str, Any] | None = None,
                should_stop: Callable[[], bool] | None = None) -> dict[str, Any]:
    """Run one braking interface simulation; write results to ``out`` (if given) and
    return the summary dict.

    With ``out``: ``timeseries.csv`` is rewritten as the run goes (at every checkpoint and
    at most every 2 s of wall time), a checkpoint ``out/checkpoint.npz`` is written after
    the first sample, every ``checkpoint_interval(setup)`` samples and at the end, and
    ``resume`` continues from it (bitwise the run an uninterrupted call gives; the
    wall-time fields excepted). Without ``resume`` an earlier run in ``out`` is replaced.
    An instability (``RunStopped``) is re-raised after the rows so far and a summary with
    ``status = "stopped"`` are written. ``progress``: a bar over the sliding steps.
    ``config``: the command's resolved config (JSON-able), kept in the checkpoint.
    ``should_stop``: polled after every sample (a sweep's stop event); when it says yes the
    run writes a checkpoint and stops (``RunStopped``), to be resumed later. A body worn
    through (``WORN_THROUGH``) ends the run at that sample: every output is written with
    ``status = "worn_through"``, then ``RunStopped`` says which body and where.
    """
    for name, v in (("pressure_Pa", setup.pressure_Pa), ("speed_m_s", setup.speed_m_s),
                    ("duration_s", setup.duration_s)):
        if not v > 0:
            raise ValueError(f"{name} = {v!r}: must be > 0")
    if setup.thermal_time_map not in ("simulated", "stretched"):
        raise ValueError(f"thermal_time_map = {setup.thermal_time_map!r}: must be "
                         "'simulated' or 'stretched'")
    if setup.feed and setup.thermal_curve is not None:
        raise ValueError("feed with a thermal_curve: the feed does not carry temperatures")
    ck = out / CHECKPOINT if out is not None else None
    saved: dict[str, Any] | None = None
    if resume:
        if ck is None:
            raise ValueError("run_braking: resume needs the output folder 'out'")
        if not ck.is_file():
            raise ConfigError(f"--resume: no checkpoint at '{ck}'")
        saved = read_checkpoint(ck)
        check_resumable(saved, setup, ck)
    t_wall = time.perf_counter()
    iface = build_interface(setup.geometry, setup.pressure_Pa, setup.micro,
                            setup.wall_mass_ratio, setup.dt_safety, setup.local_damping,
                            setup.backing, setup.plate_areal_mass,
                            block="periodic" if setup.feed else "walls")
    t_build = time.perf_counter() - t_wall
    sim = iface.sim
    n0 = sim.p.n
    t0 = sim.time
    if setup.thermal_curve is not None:
        _thermal(iface, setup, t0)
    start_sliding(iface, setup.speed_m_s)
    ref = reference(iface)
    floor = worn_floor(ref, setup.worn_through_diameters)
    outlet = Outlet(iface, setup.outlet_length_m) if setup.outlet_length_m > 0 else None
    feed = Feed(iface, ref) if setup.feed else None
    # outlet checks at most every quarter cell of disc travel (exact minimum images)
    outlet_every = max(1, int(0.25 * iface.width / (setup.speed_m_s * sim.dt)))
    speed_steps = int(math.ceil(setup.speed_ramp_s / sim.dt)) if setup.speed_ramp_s > 0 else 0
    if speed_steps:  # the disc starts at rest under the pad
        sim.p.vel[sim.p.group == DISC, 0] = 0.0
    loop = _Loop(iface, int(math.ceil(setup.ramp_s / sim.dt)) if setup.ramp_s > 0 else 0,
                 speed_steps, setup.speed_m_s)
    sim.add_interaction(loop)
    wall_y0 = float(iface.wall.point[1])
    min_steps = max(1, int(math.ceil(setup.duration_s / sim.dt)))
    total_steps = min_steps
    cap_steps = max(min_steps, int(math.ceil(max_distance(setup) / (setup.speed_m_s * sim.dt)
                                             + speed_steps / 2))) if setup.until_steady \
        else min_steps

    def slid_now() -> float:
        return loop.distance if speed_steps else setup.speed_m_s * (sim.time - t0)
    block = max(1, int(math.ceil(STEADY_BLOCK * min_steps)))
    ended = False
    every = max(1, total_steps // max(1, setup.samples))
    ck_every = checkpoint_interval(setup)
    vtk_at = set(np.linspace(0, total_steps, max(setup.vtk_snapshots, 0)).astype(int).tolist()
                 ) if setup.vtk_snapshots else set()
    rows: list[dict[str, float]] = []
    entries: list[tuple[float, str]] = []
    chain_entries: list[tuple[float, str]] = []
    frames: dict[str, dict[str, np.ndarray]] = {}
    seen: set[int] = set()
    done = 0
    k_vtk = 0
    wall_before = {"build": t_build, "sliding": 0.0, "total": 0.0}  # earlier sessions

    def sample() -> None:
        nonlocal k_vtk
        t = sim.time - t0
        slid = slid_now()
        row = {"time_s": t, "sliding_distance_m": slid,
               "wall_force_N": plate_force(iface),
               "wall_pressure_Pa": plate_force(iface) / (iface.width * iface.disc.thickness),
               "wall_displacement_m": float(iface.wall.point[1]) - wall_y0,
               "kinetic_energy_J": sim.kinetic_energy(),
               "interface_force_N": interface_load(iface)}
        row.update(measure(iface, ref, slid))
        if rows and list(rows[0]) != list(row):  # a checkpoint of an older version
            rows[:] = [{k: r.get(k, float("nan") if k in REMAINING else 0.0)
                        for k in row} for r in rows]
        rows.append({k: float(v) for k, v in row.items()})
        if out is not None and any(done >= s and s not in seen for s in vtk_at):
            for s in vtk_at:
                if done >= s:
                    seen.add(s)
            _snapshot(out / "vtk", iface, ref, slid, k_vtk, t, entries, chain_entries)
            k_vtk += 1

    last_csv = time.monotonic()

    def write_rows() -> None:
        nonlocal last_csv
        assert out is not None
        write_csv(out / "timeseries.csv", list(rows[0]), [list(r.values()) for r in rows])
        last_csv = time.monotonic()

    t_slide = time.perf_counter()

    def save_checkpoint() -> None:
        assert ck is not None
        cols = list(rows[0])
        loop.record = {
            "version": LOOP_VERSION, "setup": setup_record(setup), "config": config,
            "done": done,
            "total_steps": total_steps, "min_steps": min_steps, "cap_steps": cap_steps,
            "every": every, "n0": n0, "t0": t0,
            "wall_y0": wall_y0, "k_vtk": k_vtk, "seen": sorted(seen),
            "entries": entries, "chain_entries": chain_entries, "columns": cols,
            "frames": {k: sorted(v) for k, v in frames.items()},
            "finished": ended,
            "feed": feed.state() if feed is not None else None,
            "wall_time_build_s": wall_before["build"],
            "wall_time_sliding_s": wall_before["sliding"] + time.perf_counter() - t_slide,
            "wall_time_s": wall_before["total"] + time.perf_counter() - t_wall,
        }
        arrays = {"rows": np.array([[r[c] for c in cols] for r in rows], dtype=np.float64),
                  "ref_pos": ref.pos, "ref_radius": ref.radius}
        if outlet is not None:
            arrays.update(outlet.state())
        for name, fr in frames.items():
            for key, v in fr.items():
                arrays[f"frame_{name}_{key}"] = np.asarray(v)
        loop.arrays = arrays
        sim.save_checkpoint(ck)
        runs.checkpoint_written(ck)

    if saved is not None:
        assert ck is not None
        if feed is not None:  # the particles and bonds the feeds added, then their state
            feed.replay(iface, saved["feed"], outlet)
        try:
            sim.load_checkpoint(ck)
        except Exception as err:  # noqa: BLE001 - a foreign or damaged checkpoint
            raise ConfigError(f"checkpoint '{ck}' cannot be used: {err}") from None
        r = loop.record
        a = loop.arrays
        if (r["min_steps"], r["cap_steps"], r["every"], r["n0"]) != (
                min_steps, cap_steps, every, n0) or not (
                np.array_equal(a["ref_pos"], ref.pos)
                and np.array_equal(a["ref_radius"], ref.radius)):
            raise ConfigError(f"checkpoint '{ck}' cannot be used: the interface rebuilt from "
                              "the same setup differs from the checkpointed one (packing not "
                              "reproduced on this machine); allowed: resume where it was made")
        done, k_vtk, seen = int(r["done"]), int(r["k_vtk"]), set(r["seen"])
        total_steps, ended = int(r["total_steps"]), bool(r["finished"])
        entries[:] = [(float(t), str(f)) for t, f in r["entries"]]
        chain_entries[:] = [(float(t), str(f)) for t, f in r["chain_entries"]]
        rows[:] = [dict(zip(r["columns"], (float(x) for x in row), strict=True))
                   for row in a["rows"]]
        for name, keys in r["frames"].items():
            frames[name] = {k: a[f"frame_{name}_{k}"] for k in keys}
        if outlet is not None:
            outlet.set_state(a)
        t0, wall_y0 = float(r["t0"]), float(r["wall_y0"])
        wall_before = {"build": float(r["wall_time_build_s"]),
                       "sliding": float(r["wall_time_sliding_s"]),
                       "total": float(r["wall_time_s"])}
        runs.checkpoint_written(ck)
    else:
        if out is not None:  # a new run replaces an earlier one in this folder
            out.mkdir(parents=True, exist_ok=True)
            for name in (CHECKPOINT, "summary.json"):
                (out / name).unlink(missing_ok=True)
        sample()
        if feed is not None:
            feed.begin(rows[0])
        frames["start"] = _frame(iface, ref, 0.0)
        if out is not None:
            save_checkpoint()
            write_rows()
    resumed_finished = ended
    t_slide = time.perf_counter()
    try:
        with runs.progress(total_steps, "step", "braking run", enabled=progress,
                           initial=done) as bar:
            while not ended:
                if done >= total_steps:
                    if (not setup.until_steady or done >= cap_steps or steady_state(
                            *_wear_vs_distance(rows), setup.steady_tolerance,
                            STEADY_CUTS)["steady"]):
                        ended = True
                        break
                    total_steps = min(cap_steps, total_steps + block)  # slide further
                    bar.total = total_steps
                    getattr(bar, "refresh", lambda: None)()
                k = min(every, total_steps - done)
                if outlet is None:
                    sim.step(k)
                else:
                    for m in [outlet_every] * (k // outlet_every) + [k % outlet_every]:
                        if m:
                            sim.step(m)
                            outlet.check(iface)
                done += k
                sample()
                if worn_through(rows[-1], floor) is not None:
                    ended = True  # the cell no longer models a thick body: stop here
                    break
                if feed is not None:
                    for body, slabs in feed.due(rows[-1]).items():
                        for _ in range(slabs):
                            feed.apply(iface, body, outlet)
                if "early" not in frames and done >= 0.1 * total_steps:
                    frames["early"] = _frame(iface, ref, slid_now())
                bar.update(k)
                if out is None or done >= total_steps:
                    continue
                if (len(rows) - 1) % ck_every == 0:
                    save_checkpoint()
                    write_rows()
                elif time.monotonic() - last_csv > 2.0:
                    write_rows()
                if should_stop is not None and should_stop():
                    save_checkpoint()
                    raise RunStopped("stopped by its sweep (the sweep was interrupted); "
                                     "the checkpoint resumes it")
    except RunStopped as err:
        if out is not None:
            write_rows()
            write_json(out / "summary.json", {
                "status": "stopped", "stopped_reason": str(err), "condition": setup.condition,
                "pressure_Pa": setup.pressure_Pa, "sliding_speed_m_s": setup.speed_m_s,
                "steps": done, "steps_planned": total_steps,
                "simulated_time_s": rows[-1]["time_s"],
                "last_checkpoint": str(ck) if ck is not None and ck.is_file() else None})
        raise
    if "end" not in frames:
        frames["end"] = _frame(iface, ref, slid_now())
    if out is not None and not resumed_finished:
        save_checkpoint()  # the finished state: a later --resume only reports it
    slide_wall = wall_before["sliding"] + time.perf_counter() - t_slide
    last = rows[-1]
    p = sim.p
    # the domain: above the disc's anchored (y-fixed) bottom layer, below the pressure wall
    rmax = float(p.radius.max())
    y_lo = float(p.pos[iface.anchor_disc, 1].min()) - rmax
    y_hi = float(iface.wall.point[1]) + rmax
    inside = (np.isfinite(p.pos).all(axis=1) & (p.pos[:, 1] >= y_lo)
              & (p.pos[:, 1] <= y_hi) & (p.group != EJECTED))
    t_sim = sim.time - t0
    tt = np.array([r["time_s"] for r in rows])
    hh = np.array([r["wear_depth_mean_m"] for r in rows])
    rate, h8 = wear_extrapolation(tt, hh, SEED_BRAKING_TIME_S)
    st = steady_state(*_wear_vs_distance(rows), setup.steady_tolerance, STEADY_CUTS)
    looks = max(loop.contact[0], 1.0)
    worn = worn_through(last, floor)
    summary: dict[str, Any] = {
        "status": "worn_through" if worn else "finished",
        "worn_through": worn,
        "condition": setup.condition,
        "load_kN": pressure_to_load(setup.pressure_Pa),
        "pressure_Pa": setup.pressure_Pa,
        "speed_rpm": speed_to_rpm(setup.speed_m_s),
        "sliding_speed_m_s": setup.speed_m_s,
        "simulated_sliding_distance_m": slid_now(),
        "simulated_time_s": t_sim,
        "equivalent_braking_time_s": t_sim,
        "seed_braking_time_s": SEED_BRAKING_TIME_S,
        "fraction_of_seed_braking": t_sim / SEED_BRAKING_TIME_S,
        "time_mapping": "identity: every simulated second is one second of braking at the "
                        "condition's speed (no time or mass scaling)",
        **{k: last[k] for k in (
            "wear_depth_mean_m", "wear_depth_max_m", "wear_depth_mean_disc_m",
            "wear_depth_max_disc_m", "wear_depth_mean_pad_m", "wear_depth_max_pad_m",
            "broken_bonds", "broken_bonds_tensile", "broken_bonds_shear", "debris_particles",
            "debris_particles_disc", "debris_particles_pad", "worn_particles_disc",
            "worn_particles_pad", "debris_clusters",
            "debris_clusters_multi", "matrix_particles", "force_chains",
            "strong_force_chains", "weak_force_chains", "tensile_force_chains",
            "compressive_force_chains", "transfer_layer_thickness_m", "wear_range_disc_m",
            "wear_range_pad_m", "wear_range_ratio", "debris_max_vertical_displacement_m",
            "delaminated_particles_pad", "delaminated_depth_pad_m",
            "delaminated_particles_disc", "delaminated_depth_disc_m",
            "ejected_particles_pad", "ejected_depth_pad_m", "ejected_particles_disc",
            "ejected_depth_disc_m")},
        # nan when resumed from a finished checkpoint older than the column
        **{k: last.get(k, float("nan")) for k in REMAINING},
        "worn_through_floor_m": floor,
        "feed": feed.summary() if feed is not None else None,
        "outlet_length_m": setup.outlet_length_m,
        "steady_wear_rate_m_s": rate,
        "wear_rate_steady_m_per_m": st["rate"],
        "wear_rate_middle_third_m_per_m": st["rate_mid"],
        "wear_rate_last_third_m_per_m": st["rate_last"],
        "steady_reached": st["steady"],
        "steady_rule": f"least-squares wear-depth rate per sliding distance over the last "
                       f"third within +-{100 * setup.steady_tolerance:g}% of the middle "
                       "third's (positive), on the run and on the run cut to "
                       f"{', '.join(f'{f:.0%}' for f in STEADY_CUTS[1:])} of its distance; "
                       "steady rate = slope over the last two thirds; run-in = the first "
                       "third",
        "run_in_distance_m": st["run_in_distance"],
        "run_in_depth_m": st["run_in_depth"],
        "sliding_distance_cap_m": cap_steps * sim.dt * setup.speed_m_s,
        "contact_fraction": loop.contact[1] / looks,
        "contact_fraction_definition": f"fraction of steps (one look every {CONTACT_EVERY}) "
                                       "at which disc and pad particles (matrix or debris) "
                                       "are in contact with a positive normal force, i.e. "
                                       "the interface carries load",
        "interface_load_ratio_mean": loop.contact[2] / looks,
        "ramp_s": setup.ramp_s,
        "speed_ramp_s": setup.speed_ramp_s,
        "wear_depth_mean_extrapolated_8s_m": h8,
        "particles_initial": n0,
        "particles_final": int(inside.sum()),
        "bonds_initial": iface.bonds.n_bonds,
        "target_force_N": iface.target_force,
        "backing": setup.backing,
        "plate_areal_mass_kg_m2": setup.plate_areal_mass,
        "plate_mass_kg": iface.stats["plate_mass_kg"],
        "plate_travel_m": wall_y0 - float(iface.wall.point[1]),
        "mean_wall_force_N": loop.mean,
        "mean_wall_pressure_Pa": loop.mean / (iface.width * iface.disc.thickness),
        "mean_wall_pressure_ratio": loop.mean / iface.target_force,
        "steps": done,
        "dt_s": sim.dt,
        "dt_limited_by": sim.dt_limit_by,
        "cell_width_m": iface.width,
        "disc_height_m": setup.geometry.disc_height,
        "pad_height_m": setup.geometry.pad_height,
        "roughness_amplitude_m": setup.geometry.amplitude,
        "roughness_modes": [setup.geometry.first_mode, setup.geometry.modes],
        "packing_fraction": iface.phi[DISC],
        "build_stats": iface.stats,
        "micro_parameters": {"disc": iface.disc.micro_dict(), "pad": iface.pad.micro_dict(),
                             "set": setup.micro},
        "thermal_curve": str(setup.thermal_curve) if setup.thermal_curve else None,
        "thermal_time_map": setup.thermal_time_map if setup.thermal_curve else None,
        "wall_time_build_s": wall_before["build"],
        "wall_time_sliding_s": slide_wall,
        "wall_time_s": wall_before["total"] + time.perf_counter() - t_wall,
        "assumptions": _assumptions(setup),
    }
    summary["assumptions"] += _outcome_notes(summary)
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
        write_csv(out / "timeseries.csv", list(rows[0]), [list(r.values()) for r in rows])
        write_json(out / "summary.json", summary)
        if setup.figures:
            from tribodem.braking.plots import plot_run

            plot_run(out, rows, frames, iface, summary)
    if worn:
        raise RunStopped(
            f"{_worn_text(worn)} = {setup.worn_through_diameters:g} particle diameters): "
            "the run stopped there, its outputs "
            f"are written{' in ' + repr(str(out)) if out is not None else ''}; allowed: a "
            f"thicker body ([geometry] {worn['body']}_height_m), a shorter run, or "
            "[run] worn_through_diameters = 0 to slide on through the anchored layer")
    return summary


def max_distance(setup: RunSetup) -> float:
    """The cap on the sliding distance (m) of a run that slides until steady."""
    return setup.max_distance_m or 5.0 * setup.speed_m_s * setup.duration_s


def _wear_vs_distance(rows: list[dict[str, float]]) -> tuple[np.ndarray, np.ndarray]:
    return (np.array([r["sliding_distance_m"] for r in rows]),
            np.array([r["wear_depth_mean_m"] for r in rows]))


def _frame(iface: Interface, ref: Reference, slid: float) -> dict[str, np.ndarray]:
    from tribodem.braking.measure import classify

    p = iface.sim.p
    matrix, _ = classify(iface)
    ch = force_chains(iface)
    return {"pos": p.pos.copy(), "radius": p.radius.copy(), "vel": p.vel.copy(),
            "disp": body_displacement(iface, ref, slid), "group": p.group.copy(),
            "detached": ~matrix, "chain_i": ch["i"], "chain_j": ch["j"],
            "chain_f": ch["force"], "slid": np.array(slid)}


def _outcome_notes(summary: dict[str, Any]) -> list[str]:
    """What the run's own outcome means for its rates: a body worn through, an interface
    open for long spells (``contact_fraction`` < ``CLOSED_CONTACT``), a steady-state rule
    that did not pass."""
    notes = []
    worn = summary.get("worn_through")
    if worn:
        notes.append(
            f"{_worn_text(worn)} of intact body outside its anchored layer): the run "
            "stopped there; every value is up to that point, and the cell no longer models "
            "the surface zone of a thick body (docs/braking.md 'Bodies worn through')")
    cf = summary["contact_fraction"]
    if cf < CLOSED_CONTACT:
        notes.append(
            f"interface in contact {100 * cf:.0f} % of the sliding time (closed: >= "
            f"{100 * CLOSED_CONTACT:.0f} %): the pad flies between asperity impacts (the "
            "cell is narrower than the pad's load-sharing length), so the wear rates average "
            "contact episodes, not a closed sliding contact; wider cells ([geometry] "
            "width_m) close it (docs/braking.md)")
    for body in ("pad", "disc"):
        if summary.get(f"delaminated_particles_{body}", 0) > 0:
            notes.append(
                f"the {body} cracked through parallel to its surface: a slab as wide as the "
                f"cell ({summary[f'delaminated_particles_{body}']:.0f} particles, "
                f"{1e6 * summary[f'delaminated_depth_{body}_m']:.1f} um of intact material) "
                "is detached but spans the periodic cell, so it is reported as delaminated, "
                "not as debris or wear (its size is the cell's; docs/braking.md "
                "'Measurements')")
    if not summary["steady_reached"]:
        notes.append(
            "steady-state rule not passed within the distance slid: "
            "wear_rate_steady_m_per_m is the slope over the last two thirds of a rate still "
            "changing (compare wear_rate_middle_third_m_per_m and "
            "wear_rate_last_third_m_per_m)" + (
                "" if summary["outlet_length_m"] > 0 else
                "; in the closed periodic cell the rate falls towards zero over ~10-16 mm as "
                "the debris layer takes up the sliding (no debris leaves the cell): the "
                "depth of a short run is a run-in depth (docs/braking.md 'Long slides'); "
                "[run] outlet_length_m lets debris leave"))
    return notes


def _assumptions(setup: RunSetup) -> list[str]:
    a = [
        "2D disks of unit thickness (1 m); forces per metre; pressure = wall force / "
        "(cell width x 1 m)",
        "load and speed from table 4 via the implied pad area 0.03939 m^2 and friction "
        "radius 0.375 m",
        "time mapping: identity (simulated time = braking time represented); the seed's 8 s "
        "is not reached; wear_depth_mean_extrapolated_8s_m extrapolates the steady wear "
        "rate (slope over the second half of the run) linearly in time = in sliding "
        "distance at constant speed; it is an extrapolation, not a simulation",
        "pressure wall: a pressure plate (engine 'boundary' servo, seed 003 eq 3.6), no "
        "damping, of mass " + (
            f"{setup.plate_areal_mass} kg/m^2 x W x t (the omitted pad and back plate: 15 mm "
            "Cu-PM + 6 mm steel assumed, the seed gives no sizes)"
            if setup.plate_areal_mass else
            f"{setup.wall_mass_ratio} x the cell's pad mass") +
        "; its mean force tends to the target by momentum balance",
        "disc: anchored bottom layer fixed in y and driven at -v in x, the rest of the disc "
        "starts at -v; pad: top layer " + (
            "tied to the rest of the pad by non-reflecting (Lysmer) dashpots, rho c_p "
            "relative to the plate in y and rho c_s in x (the support)"
            if setup.backing == "absorbing" else "held in x (support wall), free face in y"),
        "rough surfaces: independent random profiles (sine modes of wavelengths W/k, k = "
        f"{setup.geometry.first_mode}..{setup.geometry.modes}, amplitudes ~ U(0.3, 1)/k, "
        "max |h| = the amplitude) cut from one compacted block; pad lowered vertically to "
        "first contact",
        "wear depth = detached solid area / (packing fraction x width), pad (the seed "
        "analyses the pad); detached = not connected by intact bonds to an anchored layer",
    ]
    if setup.micro == "calibrated":
        a.append("micro-parameters: E_c and kratio from tribodem calibrate (docs/braking.md), "
                 "table 3 strengths, damping, friction")
    else:
        a.append("micro-parameters: the seed's table 3 values, uncalibrated in tribodem "
                 "(E ~ 88/79 GPa instead of 201/178 GPa)")
    if setup.outlet_length_m > 0:
        a.append(f"debris outlet: a debris component leaves the cell (ejected, counted as "
                 f"worn) once carried {1e6 * setup.outlet_length_m:g} um along the sliding "
                 "relative to the pad (the residence length: the contact plateau it crosses; "
                 "not given by the seed, whose cell is closed); docs/braking.md 'Debris "
                 "outlet'")
    else:
        a.append("closed cell (the seed's): no debris leaves; the third body accumulates")
    if setup.feed:
        a.append("feed: the bodies are cut from a block compacted periodic in x and y; "
                 "whenever a body's remaining thickness has fallen by one slab (3 mean "
                 "particle diameters) a slab of the block's continuation is added behind "
                 "its anchored layer, which moves to the slab's outer face (the surface "
                 "zone of a thick pad and disc; summary 'feed'; docs/braking.md 'Feed')")
    if setup.thermal_curve is None:
        a.append("no temperature boundary (the seed's figure 9 curve is not given in the "
                 "text; over microseconds any 8 s curve changes by ~1e-6 of its range)")
    return a
