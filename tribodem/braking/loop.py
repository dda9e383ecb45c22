"""The braking run's sliding loop (:class:`BrakingLoop`): the interface, its drive, the
measurement state, the debris outlet, the feed and the thermal boundary, stepped from
sample to sample.

Time mapping (never hidden): the loop integrates ``duration_s`` of sliding step by step at
the physical speed, i.e. a sliding distance ``v x duration_s`` (tens to hundreds of um);
the simulated time IS the braking time it represents (no time scaling). ``until_steady``
slides past ``duration_s`` in blocks of ``STEADY_BLOCK`` of it until the wear rate per
sliding distance is steady (:func:`tribodem.braking.steady.steady_state`), at most
``max_distance_m``. ``ramp_s`` ramps the load on from 0, ``speed_ramp_s`` the disc's speed.
The closed cell of the seed saturates (no debris leaves it); ``outlet_length_m`` lets
debris leave (``braking.outlet``), checked between engine calls at most every quarter cell
width of disc travel, so that the wear reaches a steady flow.

Checkpoints: one file, ``<out>/checkpoint.npz``, written atomically by the engine's
``Simulation.save_checkpoint`` after the first sample, every ``checkpoint_every`` samples
(default ceil(samples / 10): about every 10% of the run) and at the end. Besides the
engine state (particles, neighbour list, contact history, walls, bonds, thermal, the pad
backing) it holds the loop's own state (:meth:`BrakingLoop.state_dict`), carried by the
:class:`~tribodem.braking.drive.SlidingDrive` interaction's ``state()``: steps done, every
sample row so far, the VTK index entries and counters, the figure frames, the reference
positions, the outlet's store, the feeds, the wall time so far and the setup (JSON) the
checkpoint belongs to. A resume (:meth:`BrakingLoop.resume`) rebuilds the interface from
the same setup (the build is deterministic: same seed -> bitwise the same packing; checked
against the stored reference positions), replays the recorded feeds, loads the checkpoint
and continues: the rows, the ``.pvd`` indexes and the summary come out bitwise as in an
uninterrupted run (the ``wall_time*`` fields excepted). ``timeseries.csv`` is rewritten
(atomically) at every checkpoint and at most every 2 s of wall time in between; rows
written after the last checkpoint are recomputed identically on resume.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from tribodem.braking.checkpoint import CHECKPOINT, LOOP_VERSION
from tribodem.braking.conditions import SEED_BRAKING_TIME_S
from tribodem.braking.drive import SlidingDrive, interface_load
from tribodem.braking.feed import Feed
from tribodem.braking.frames import figure_frame, write_snapshot
from tribodem.braking.measure import REMAINING, measure, reference
from tribodem.braking.model import DISC, PAD, Interface, build_interface, plate_force, start_sliding
from tribodem.braking.outlet import Outlet
from tribodem.braking.setup import RunSetup, checkpoint_interval, max_distance, setup_record
from tribodem.braking.steady import (
    STEADY_BLOCK,
    STEADY_CUTS,
    steady_state,
    wear_vs_distance,
    worn_floor,
    worn_through,
)
from tribodem.dem.thermal import Thermal, read_curve
from tribodem.io import runs
from tribodem.io.config import ConfigError
from tribodem.io.results import write_csv
from tribodem.io.runs import RunStopped

#: heat capacities (J/(kg K)) of the thermal boundary option; the seed gives none:
#: handbook values for structural steel and a Cu-based sintered material
HEAT_CAPACITY = {DISC: 460.0, PAD: 400.0}


def add_thermal(iface: Interface, setup: RunSetup, t0: float) -> Thermal:
    """The temperature boundary of ``setup.thermal_curve`` (time s, temperature K) on both
    bodies from simulated time ``t0`` (s) on, added to the simulation; ``stretched``: the
    whole curve over the simulated window instead of the seed's 8 s."""
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


class BrakingLoop:
    """One braking run's sliding loop on a freshly built interface.

    Construction builds the interface of ``setup`` (the deterministic packing), adds the
    thermal boundary, starts the sliding and adds the :class:`SlidingDrive`; then either
    :meth:`start` (a new run: the first sample and checkpoint) or :meth:`resume` (from
    ``out/checkpoint.npz``), then :meth:`run` (sample after sample until the planned, the
    steady or the worn-through end) and :meth:`finish`. ``out``: the run's folder (None:
    nothing written, no checkpoints); ``config``: the resolved config (JSON-able) kept in
    the checkpoint; ``should_stop``: polled after every sample past a checkpoint's
    decision (a sweep's stop event): yes -> checkpoint and ``RunStopped``.
    """

    def __init__(self, setup: RunSetup, out: Path | None = None, *,
                 config: dict[str, Any] | None = None,
                 should_stop: Callable[[], bool] | None = None) -> None:
        self.setup, self.out, self.config, self.should_stop = setup, out, config, should_stop
        self.checkpoint = out / CHECKPOINT if out is not None else None
        self._t_wall = time.perf_counter()
        iface = build_interface(setup.geometry, setup.pressure_Pa, setup.micro,
                                setup.wall_mass_ratio, setup.dt_safety, setup.local_damping,
                                setup.backing, setup.plate_areal_mass,
                                block="periodic" if setup.feed else "walls")
        t_build = time.perf_counter() - self._t_wall
        self.iface, self.sim = iface, iface.sim
        sim = iface.sim
        self.n0 = sim.p.n  # particles at the start
        self.t0 = sim.time  # s, simulated time at the start of sliding
        self.thermal = add_thermal(iface, setup, self.t0) \
            if setup.thermal_curve is not None else None
        start_sliding(iface, setup.speed_m_s)
        self.ref = reference(iface)
        self.floor = worn_floor(self.ref, setup.worn_through_diameters)
        self.outlet = Outlet(iface, setup.outlet_length_m) if setup.outlet_length_m > 0 \
            else None
        self.feed = Feed(iface, self.ref) if setup.feed else None
        # outlet checks at most every quarter cell of disc travel (exact minimum images)
        self.outlet_every = max(1, int(0.25 * iface.width / (setup.speed_m_s * sim.dt)))
        self.speed_steps = int(math.ceil(setup.speed_ramp_s / sim.dt)) \
            if setup.speed_ramp_s > 0 else 0
        if self.speed_steps:  # the disc starts at rest under the pad
            sim.p.vel[sim.p.group == DISC, 0] = 0.0
        self.drive = SlidingDrive(
            iface, int(math.ceil(setup.ramp_s / sim.dt)) if setup.ramp_s > 0 else 0,
            self.speed_steps, setup.speed_m_s)
        sim.add_interaction(self.drive)
        self.wall_y0 = float(iface.wall.point[1])  # m, the plate's height at the start
        self._plan_steps()
        self.rows: list[dict[str, float]] = []
        self.entries: list[tuple[float, str]] = []  # (time s, file) of the particle VTKs
        self.chain_entries: list[tuple[float, str]] = []  # of the force-chain VTKs
        self.frames: dict[str, dict[str, np.ndarray]] = {}
        self.seen: set[int] = set()  # the VTK steps already written
        self.done = 0  # sliding steps done
        self.k_vtk = 0  # VTK snapshots written
        self.ended = self.resumed_finished = False
        self.wall_before = {"build": t_build, "sliding": 0.0, "total": 0.0}  # earlier runs
        self._last_csv = time.monotonic()
        self._t_slide = time.perf_counter()
        self._slide_wall = 0.0

    def _plan_steps(self) -> None:
        """The step plan: at least ``min_steps`` (``duration_s``), at most ``cap_steps``
        (``until_steady``: the distance cap), extended in ``block``s; a sample every
        ``every`` steps, a checkpoint every ``ck_every`` samples, the VTK steps."""
        setup, dt = self.setup, self.sim.dt
        self.min_steps = max(1, int(math.ceil(setup.duration_s / dt)))
        self.total_steps = self.min_steps
        self.cap_steps = max(self.min_steps, int(math.ceil(
            max_distance(setup) / (setup.speed_m_s * dt) + self.speed_steps / 2))) \
            if setup.until_steady else self.min_steps
        self.block = max(1, int(math.ceil(STEADY_BLOCK * self.min_steps)))
        self.every = max(1, self.total_steps // max(1, setup.samples))
        self.ck_every = checkpoint_interval(setup)
        self.vtk_at = set(np.linspace(0, self.total_steps, max(setup.vtk_snapshots, 0))
                          .astype(int).tolist()) if setup.vtk_snapshots else set()

    def slid(self) -> float:
        """The disc's sliding distance since the start (m)."""
        if self.speed_steps:
            return self.drive.distance
        return self.setup.speed_m_s * (self.sim.time - self.t0)

    def sample(self) -> dict[str, float]:
        """Measure now: one row (time s, distance m, plate force N and pressure Pa, plate
        displacement m, kinetic energy J, interface load N, ``measure``'s quantities)
        appended to ``rows`` and returned; a VTK snapshot when one is due."""
        iface, sim = self.iface, self.sim
        t = sim.time - self.t0
        slid = self.slid()
        row = {"time_s": t, "sliding_distance_m": slid,
               "wall_force_N": plate_force(iface),
               "wall_pressure_Pa": plate_force(iface) / (iface.width * iface.disc.thickness),
               "wall_displacement_m": float(iface.wall.point[1]) - self.wall_y0,
               "kinetic_energy_J": sim.kinetic_energy(),
               "interface_force_N": interface_load(iface)}
        row.update(measure(iface, self.ref, slid))
        rows = self.rows
        if rows and list(rows[0]) != list(row):  # a checkpoint of an older version
            rows[:] = [{k: r.get(k, float("nan") if k in REMAINING else 0.0)
                        for k in row} for r in rows]
        rows.append({k: float(v) for k, v in row.items()})
        if self.out is not None and any(self.done >= s and s not in self.seen
                                        for s in self.vtk_at):
            for s in self.vtk_at:
                if self.done >= s:
                    self.seen.add(s)
            write_snapshot(self.out / "vtk", iface, self.ref, slid, self.k_vtk, t,
                           self.entries, self.chain_entries)
            self.k_vtk += 1
        return rows[-1]

    def write_rows(self) -> None:
        """Rewrite ``out/timeseries.csv`` with every row so far (atomically)."""
        assert self.out is not None
        rows = self.rows
        write_csv(self.out / "timeseries.csv", list(rows[0]), [list(r.values()) for r in rows])
        self._last_csv = time.monotonic()

    def state_dict(self) -> dict[str, Any]:
        """The loop's own state: ``record`` (JSON data: the setup, the step plan and
        counters, the VTK indexes, the feeds, the wall times in s) and ``arrays`` (the
        rows, the reference packing, the outlet's store, the figure frames)."""
        cols = list(self.rows[0])
        wb = self.wall_before
        record = {
            "version": LOOP_VERSION, "setup": setup_record(self.setup), "config": self.config,
            "done": self.done,
            "total_steps": self.total_steps, "min_steps": self.min_steps,
            "cap_steps": self.cap_steps, "every": self.every, "n0": self.n0, "t0": self.t0,
            "wall_y0": self.wall_y0, "k_vtk": self.k_vtk, "seen": sorted(self.seen),
            "entries": self.entries, "chain_entries": self.chain_entries, "columns": cols,
            "frames": {k: sorted(v) for k, v in self.frames.items()},
            "finished": self.ended,
            "feed": self.feed.state() if self.feed is not None else None,
            "wall_time_build_s": wb["build"],
            "wall_time_sliding_s": wb["sliding"] + time.perf_counter() - self._t_slide,
            "wall_time_s": wb["total"] + time.perf_counter() - self._t_wall,
        }
        arrays = {"rows": np.array([[r[c] for c in cols] for r in self.rows],
                                   dtype=np.float64),
                  "ref_pos": self.ref.pos, "ref_radius": self.ref.radius}
        if self.outlet is not None:
            arrays.update(self.outlet.state())
        for name, fr in self.frames.items():
            for key, v in fr.items():
                arrays[f"frame_{name}_{key}"] = np.asarray(v)
        return {"record": record, "arrays": arrays}

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore what :meth:`state_dict` returned, on an interface rebuilt from the same
        setup (``ConfigError`` when the rebuilt packing or step plan differs)."""
        r, a = state["record"], state["arrays"]
        if (r["min_steps"], r["cap_steps"], r["every"], r["n0"]) != (
                self.min_steps, self.cap_steps, self.every, self.n0) or not (
                np.array_equal(a["ref_pos"], self.ref.pos)
                and np.array_equal(a["ref_radius"], self.ref.radius)):
            raise ConfigError(f"checkpoint '{self.checkpoint}' cannot be used: the interface "
                              "rebuilt from the same setup differs from the checkpointed one "
                              "(packing not reproduced on this machine); allowed: resume "
                              "where it was made")
        self.done, self.k_vtk, self.seen = int(r["done"]), int(r["k_vtk"]), set(r["seen"])
        self.total_steps, self.ended = int(r["total_steps"]), bool(r["finished"])
        self.entries[:] = [(float(t), str(f)) for t, f in r["entries"]]
        self.chain_entries[:] = [(float(t), str(f)) for t, f in r["chain_entries"]]
        self.rows[:] = [dict(zip(r["columns"], (float(x) for x in row), strict=True))
                        for row in a["rows"]]
        for name, keys in r["frames"].items():
            self.frames[name] = {k: a[f"frame_{name}_{k}"] for k in keys}
        if self.outlet is not None:
            self.outlet.set_state(a)
        self.t0, self.wall_y0 = float(r["t0"]), float(r["wall_y0"])
        self.wall_before = {"build": float(r["wall_time_build_s"]),
                            "sliding": float(r["wall_time_sliding_s"]),
                            "total": float(r["wall_time_s"])}

    def save_checkpoint(self) -> None:
        """Write ``out/checkpoint.npz``: the engine state with :meth:`state_dict` in the
        drive's state."""
        assert self.checkpoint is not None
        state = self.state_dict()
        self.drive.record, self.drive.arrays = state["record"], state["arrays"]
        self.sim.save_checkpoint(self.checkpoint)
        runs.checkpoint_written(self.checkpoint)

    def start(self) -> None:
        """A new run: an earlier run's summary and checkpoint in ``out`` removed, the first
        sample, the start frame, the first checkpoint and rows."""
        if self.out is not None:  # a new run replaces an earlier one in this folder
            self.out.mkdir(parents=True, exist_ok=True)
            for name in (CHECKPOINT, "summary.json"):
                (self.out / name).unlink(missing_ok=True)
        self.sample()
        if self.feed is not None:
            self.feed.begin(self.rows[0])
        self.frames["start"] = figure_frame(self.iface, self.ref, 0.0)
        if self.out is not None:
            self.save_checkpoint()
            self.write_rows()

    def resume(self, saved: dict[str, Any]) -> None:
        """Continue from ``out/checkpoint.npz`` (``saved``: its record, read and checked
        against the setup before the build): the recorded feeds replayed, the checkpoint
        loaded (``ConfigError`` when it cannot be), the loop state restored."""
        ck = self.checkpoint
        if ck is None:
            raise ValueError("BrakingLoop.resume: needs the output folder 'out'")
        if self.feed is not None:  # the particles and bonds the feeds added, then their state
            self.feed.replay(self.iface, saved["feed"], self.outlet)
        try:
            self.sim.load_checkpoint(ck)
        except Exception as err:  # noqa: BLE001 - a foreign or damaged checkpoint
            raise ConfigError(f"checkpoint '{ck}' cannot be used: {err}") from None
        self.load_state_dict({"record": self.drive.record, "arrays": self.drive.arrays})
        runs.checkpoint_written(ck)

    def _slide(self, k: int) -> None:
        """``k`` engine steps; with the outlet in chunks of at most ``outlet_every``, each
        followed by an outlet check."""
        if self.outlet is None:
            self.sim.step(k)
            return
        for m in [self.outlet_every] * (k // self.outlet_every) + [k % self.outlet_every]:
            if m:
                self.sim.step(m)
                self.outlet.check(self.iface)

    def _extend(self) -> bool:
        """At the planned end: whether to slide on (``until_steady``, below the cap and not
        yet steady: the plan grows by one block) or stop."""
        s = self.setup
        if (not s.until_steady or self.done >= self.cap_steps or steady_state(
                *wear_vs_distance(self.rows), s.steady_tolerance, STEADY_CUTS)["steady"]):
            return False
        self.total_steps = min(self.cap_steps, self.total_steps + self.block)  # slide on
        return True

    def step_sample(self) -> int:
        """Slide to the next sample and measure; returns the steps done. A body worn
        through ends the loop there (``ended``); otherwise the due feeds are added and
        the early frame taken."""
        k = min(self.every, self.total_steps - self.done)
        self._slide(k)
        self.done += k
        self.sample()
        if worn_through(self.rows[-1], self.floor) is not None:
            self.ended = True  # the cell no longer models a thick body: stop here
            return k
        if self.feed is not None:
            for body, slabs in self.feed.due(self.rows[-1]).items():
                for _ in range(slabs):
                    self.feed.apply(self.iface, body, self.outlet)
        if "early" not in self.frames and self.done >= 0.1 * self.total_steps:
            self.frames["early"] = figure_frame(self.iface, self.ref, self.slid())
        return k

    def _keep(self) -> None:
        """After a sample before the end: a checkpoint and the rows when due, the rows at
        most every 2 s of wall time; a stop asked for: checkpoint, then ``RunStopped``."""
        if self.out is None or self.done >= self.total_steps:
            return
        if (len(self.rows) - 1) % self.ck_every == 0:
            self.save_checkpoint()
            self.write_rows()
        elif time.monotonic() - self._last_csv > 2.0:
            self.write_rows()
        if self.should_stop is not None and self.should_stop():
            self.save_checkpoint()
            raise RunStopped("stopped by its sweep (the sweep was interrupted); "
                             "the checkpoint resumes it")

    def run(self, progress: bool = False) -> None:
        """Slide sample after sample until the end (the planned steps; with
        ``until_steady`` the steady state or the distance cap; a body worn through);
        ``progress``: a bar over the sliding steps. A loop resumed from a finished
        checkpoint does nothing."""
        self.resumed_finished = self.ended
        self._t_slide = time.perf_counter()
        with runs.progress(self.total_steps, "step", "braking run", enabled=progress,
                           initial=self.done) as bar:
            while not self.ended:
                if self.done >= self.total_steps:
                    if not self._extend():
                        self.ended = True
                        break
                    bar.total = self.total_steps
                    getattr(bar, "refresh", lambda: None)()
                k = self.step_sample()
                if self.ended:
                    break
                bar.update(k)
                self._keep()

    def finish(self) -> None:
        """After :meth:`run`: the end frame and the finished state's checkpoint (a later
        resume only reports it)."""
        if "end" not in self.frames:
            self.frames["end"] = figure_frame(self.iface, self.ref, self.slid())
        if self.out is not None and not self.resumed_finished:
            self.save_checkpoint()  # the finished state: a later --resume only reports it
        self._slide_wall = self.wall_before["sliding"] + time.perf_counter() - self._t_slide

    def wall_times(self) -> dict[str, float]:
        """Wall-clock seconds of the run, a resumed run's earlier parts included: ``build``
        (the interface), ``sliding`` (up to :meth:`finish`) and ``total`` (until now)."""
        return {"build": self.wall_before["build"], "sliding": self._slide_wall,
                "total": self.wall_before["total"] + time.perf_counter() - self._t_wall}
