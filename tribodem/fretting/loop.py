"""The fretting wear loop (Lu (2018) figure 3.1 without debris; sections 3.3.3, 6.3).

Per simulated cycle: move the upper body through 0 -> +A -> 0 -> -A -> 0 with the first-body
solver on the *current* worn surfaces, stream every increment to the criterion, get the
cycle's wear depth on both bodies (upper spot grid, lower track grid), add it to the
cumulative wear maps and to the recessions the solver sees (geometry update: the surface
recedes by the worn depth, the half-space analogue of eqs 3.7-3.8), integrate the worn
volume exactly on the grids (sum of depth x cell area) and record the cycle.

Sub-cycles: the geometry is updated once a cycle, an explicit step of the wear equation in
the cycle count. A cycle whose wear changes the depth anywhere by more than
``update_tolerance`` x the contact's elastic approach is a step too long for it: on a grid
fine enough to resolve the scar's edge, the edge points take the load the worn points
shed and overshoot into pits one cell wide. Such a cycle is solved again in ``m`` passes
on the surfaces as they wear (m = ceil(increment / (tolerance x approach))), each pass
adding 1/m of its cycle's wear: the same total k P s, with the geometry following it. Only
for rate criteria (Archard, energy: the wear of a pass is linear in its duration) on
backends whose cycles can be repeated (``Capabilities.repeatable``) and without debris;
elsewhere a cycle over the tolerance is counted and stated in the summary.

Cycle-jumping (:mod:`tribodem.cyclejump`): the state is the pair of cumulative wear-depth
maps (flattened into one array). After each simulated cycle the strategy may skip ``n``
cycles; the maps are extrapolated element by element and ``n`` rows with ``jumped = 1``
are recorded (maps interpolated linearly across the jump, per-cycle quantities such as the
dissipated energy carried from the last simulated cycle).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tribodem.contact.base import FirstBodySolver, WindowTooSmallError, cycle_offsets, require
from tribodem.contact.fe.ccx import FESolverStopped
from tribodem.contact.geometry import HeightMap, Recession
from tribodem.cyclejump import JumpStrategy
from tribodem.fretting.criteria import Criterion, CriterionUnavailable, RateCriterion, TrackGrid
from tribodem.fretting.debris import DebrisField, DEPhaseResult, debris_target, run_de_phase

#: Columns of ``results.csv`` (one row per simulated or jumped cycle).
RESULT_COLUMNS = (
    "cycle",
    "jumped",
    "wear_depth_upper_m",
    "wear_depth_lower_m",
    "wear_volume_upper_m3",
    "wear_volume_lower_m3",
    "dissipated_energy_J",
    "max_pressure_Pa",
    "max_traction_Pa",
    "contact_area_m2",
)
#: Extra columns when the first body measures its plastic state per cycle
#: (:meth:`~tribodem.contact.base.FirstBodySolver.cycle_columns`: ``elastic-plastic``).
PLASTIC_COLUMNS = (
    "max_peeq_upper",
    "max_peeq_depth_upper_m",
    "peeq_increment_upper",
    "max_peeq_lower",
    "max_peeq_depth_lower_m",
    "peeq_increment_lower",
)
#: Extra columns when the debris third body is on (Lu (2018) sections 3.2.6-3.2.7).
DEBRIS_COLUMNS = (
    "debris_particles",
    "debris_load_fraction",
    "max_pressure_with_debris_Pa",
    "load_balance_error",
    "de_phase",
)


class WornProfile:
    """A wear profile along x on a single cross-section (a line contact solved on one
    section, grids ``[n, 1]``): ``wear(x, y)`` interpolated linearly along x, the same at
    every y; 0 outside the profile is refused like a :class:`HeightMap` refuses points
    off its map."""

    def __init__(self, values: NDArray[np.float64], dx: float, x0: float) -> None:
        self.values = np.asarray(values, dtype=float).reshape(-1)
        self.x = x0 + dx * np.arange(self.values.size)
        self.dx = dx

    def __call__(self, x: NDArray[np.float64], y: NDArray[np.float64]) -> NDArray[np.float64]:
        x = np.asarray(x, dtype=float)
        tol = 1e-9 * self.dx
        if x.min() < self.x[0] - tol or x.max() > self.x[-1] + tol:
            raise ValueError(f"wear profile covers x in [{self.x[0]:.4g}, {self.x[-1]:.4g}] m "
                             f"but was sampled on [{x.min():.4g}, {x.max():.4g}] m")
        return np.interp(x, self.x, self.values) + 0.0 * np.asarray(y, dtype=float)


class WornSurface:
    """Recession of a worn body: ``base(x, y) + wear(x, y)`` (m), wear a :class:`HeightMap`."""

    def __init__(self, base: Recession, wear: HeightMap) -> None:
        self.base = base
        self.wear = wear

    def __call__(self, x: NDArray[np.float64], y: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.asarray(self.base(x, y), dtype=float) + self.wear(x, y)


@dataclass
class FrettingHistory:
    """Outcome of :meth:`FrettingLoop.run`. SI units."""

    rows: list[dict[str, Any]]
    grid: TrackGrid
    wear_upper: NDArray[np.float64]  #: cumulative wear depth, m, [n, n]
    wear_lower: NDArray[np.float64]  #: cumulative wear depth, m, [n_track, n]
    profiles_upper: list[NDArray[np.float64]]  #: wear at the central section, m
    profiles_lower: list[NDArray[np.float64]]
    base_upper: NDArray[np.float64]  #: unworn recession at the central section, m
    base_lower: NDArray[np.float64]
    #: the cycles of the profiles: five spread over the run (those ``profiles.png`` plots,
    #: for every number of cycles the run was asked for) and the newest
    profile_cycles: list[int] = field(default_factory=list)
    cycles_simulated: int = 0
    cycles_jumped: int = 0
    wall_time_s: float = 0.0
    stopped: str | None = None  #: reason the run stopped early (None: completed)
    criterion_info: dict[str, Any] = field(default_factory=dict)
    de_phases: list[DEPhaseResult] = field(default_factory=list)  #: debris DE phases run
    debris: DebrisField | None = None

    @property
    def cumulative_energy(self) -> float:
        """Interface energy dissipated over all recorded cycles, J."""
        return float(sum(r["dissipated_energy_J"] for r in self.rows))

    def volume(self, body: str) -> float:
        """Exact worn volume of ``body`` on its grid (sum of depth x cell area), m^3."""
        w = self.wear_upper if body == "upper" else self.wear_lower
        return float(w.sum() * self.grid.cell_area)

    def summary(self) -> dict[str, Any]:
        """Totals for ``summary.json``."""
        last = self.rows[-1] if self.rows else {}
        return {
            "cycles": int(last.get("cycle", 0)),
            "cycles_simulated": self.cycles_simulated,
            "cycles_jumped": self.cycles_jumped,
            "wall_time_s": self.wall_time_s,
            "stopped": self.stopped,
            "wear_volume_upper_m3": self.volume("upper"),
            "wear_volume_lower_m3": self.volume("lower"),
            "wear_depth_upper_m": float(self.wear_upper.max(initial=0.0)),
            "wear_depth_lower_m": float(self.wear_lower.max(initial=0.0)),
            "wear_depth_mean_scar_upper_m": _scar_mean(self.wear_upper),
            "wear_depth_mean_scar_lower_m": _scar_mean(self.wear_lower),
            "dissipated_energy_total_J": self.cumulative_energy,
            "grid": {"n": self.grid.n, "dx_m": self.grid.dx, "n_track": self.grid.n_track,
                     "ny": self.grid.ny, "dy_m": self.grid.dy},
            "criterion_last_cycle": self.criterion_info,
            **({"debris": self.debris_summary()} if self.debris is not None else {}),
        }

    def debris_summary(self) -> dict[str, Any]:
        """Debris totals: mass balance, particles, DE phases (servo error, steps, time)."""
        d = self.debris
        assert d is not None
        phases = [ph.summary() for ph in self.de_phases]
        return {"particles_in_contact": d.n, "particles_created": d.created,
                "particles_ejected": d.ejected, **d.mass_balance(),
                "volume_rel_error": (d.created_volume - d.settings.volume_correction
                                     * d.worn_volume) / max(d.worn_volume, 1e-300),
                "de_phases": phases}


def _scar_mean(w: NDArray[np.float64]) -> float:
    """Mean wear depth over the worn points (depth > 0), m (seed 6.3: "averaged wear depth
    over all nodes in the wear scar")."""
    worn = w > 0
    return float(w[worn].mean()) if worn.any() else 0.0


#: Default of ``FrettingLoop(geometry_tolerance=...)`` (docs/fretting.md, "Jumping").
GEOMETRY_TOLERANCE = 0.05
#: Default of ``FrettingLoop(update_tolerance=...)``: the largest depth increment of one
#: geometry update (a cycle, or a sub-cycle) over the contact's elastic approach.
UPDATE_TOLERANCE = 0.05
#: Most sub-cycles a cycle is split into (beyond it the summary says the tolerance was missed)
MAX_SUBCYCLES = 64
#: ``_geometry_limit`` without a limit (no tolerance, or nothing worn)
NO_LIMIT = 1 << 62


def _no_updates() -> dict[str, Any]:
    """``FrettingLoop.wear_updates`` before any cycle."""
    return {"cycles_split": 0, "most_subcycles": 1, "cycles_over_tolerance": 0,
            "largest_increment_over_approach": 0.0}


def _no_decisions() -> dict[str, Any]:
    return {"decisions": 0, "proposed": 0, "capped_by_geometry": 0, "cycles_proposed": 0,
            "cycles_jumped": 0, "first": None, "last": None}


class FrettingLoop:
    """Fretting wear loop on a first-body solver with worn-surface geometry update.

    The only driver of fretting cycles. It uses the solver through the first-body contract
    (:class:`tribodem.contact.FirstBodySolver`) alone: each cycle it gives the solver the
    worn surfaces (:class:`WornSurface`, via ``set_surfaces``). ``amplitude`` m,
    ``n_increments`` per cycle (multiple of 4). ``strategy``: a
    :class:`tribodem.cyclejump.JumpStrategy` or None (no jumping). A criterion or the debris
    third body that needs what the solver cannot give is refused here, before any work
    (``CriterionUnavailable``).
    """

    def __init__(
        self,
        solver: FirstBodySolver,
        criterion: Criterion,
        amplitude: float = 0.3e-3,
        n_increments: int = 48,
        strategy: JumpStrategy | None = None,
        debris: DebrisField | None = None,
        debris_every: int = 1,
        geometry_tolerance: float | None = GEOMETRY_TOLERANCE,
        update_tolerance: float | None = UPDATE_TOLERANCE,
    ) -> None:
        criterion.check_solver(solver)
        if debris is not None:
            try:
                require(solver, {"debris"}, "the debris third body")
            except ValueError as err:
                raise CriterionUnavailable(str(err)) from None
        self.solver = solver
        self.criterion = criterion
        self.offsets = cycle_offsets(amplitude, n_increments)
        self.amplitude = float(amplitude)
        self.strategy = strategy
        criterion.set_increments(n_increments)
        n, dx = solver.n, solver.dx
        self.grid = TrackGrid(n=n, dx=dx, pad=int(math.ceil(self.amplitude / dx)) + 1,
                              ny=solver.ny, dy=solver.dy)
        self.base_upper: Recession = solver.upper
        self.base_lower: Recession = solver.lower
        self.wear_upper = np.zeros(self.grid.upper_shape)
        self.wear_lower = np.zeros(self.grid.lower_shape)
        if int(debris_every) != debris_every or debris_every < 1:
            raise ValueError(f"debris_every = {debris_every!r}: must be an integer >= 1 cycle")
        self.debris = debris
        self.debris_every = int(debris_every)
        self.de_phases: list[DEPhaseResult] = []
        self._cycle = 0
        self._p_load = np.zeros(self.grid.upper_shape)  # pressure at the loading position, Pa
        self.history: FrettingHistory | None = None  #: set by the first loading
        #: what stopped this process's run early (``history.stopped`` is its text)
        self.stop_error: WindowTooSmallError | FESolverStopped | None = None
        self._done = 0  # cycles recorded (simulated + jumped)
        self._observe_pending = False  # last cycle of a finished run not shown to strategy
        self._last_per: dict[str, Any] = {}  # per-cycle values of the last simulated cycle
        self._wall = 0.0  # wall time of the earlier processes of a resumed run, s
        #: jumps keep the geometry the next cycle sees: the jumped depth increment stays
        #: below this fraction of the contact's elastic approach (None: strategy alone)
        self.geometry_tolerance: float | None = geometry_tolerance
        #: a cycle's largest depth increment over the elastic approach above which the
        #: cycle is split into sub-cycles (None: one update a cycle, whatever it wears)
        self.update_tolerance: float | None = update_tolerance or None
        self._updates = _no_updates()
        self._last_du = np.zeros(self.grid.upper_shape)
        self._last_dl = np.zeros(self.grid.lower_shape)
        #: every jump decision so far (``jump_decisions``), for the summary
        self._decisions = _no_decisions()
        self._keep: set[int] = set()  # cycles whose profiles stay recorded

    def _de_phase(self) -> dict[str, float]:
        """Lu (2018) figure 3.1 DE step: load the debris, map its forces back to the solver."""
        d, sol = self.debris, self.solver
        assert d is not None
        c = sol.coords
        target = debris_target(d, self._p_load, c, sol.dx, sol.load)
        if target <= 0.0:
            sol.set_debris_pressure(None)
            return {"de_phase": 0}
        xw, yw = np.meshgrid(c, c, indexing="ij")
        lower = np.asarray(sol.lower(xw, yw), dtype=float)
        p_without, gap = sol.loaded_solution(0.0)
        res = run_de_phase(d, lower, gap, c, target, cycle=self._cycle)
        sol.set_debris_pressure(res.pressure)
        res.pressure_without = p_without
        res.pressure_with = sol.loaded_solution(0.0, debris=True)[0]
        self.de_phases.append(res)
        return {"de_phase": 1}

    def _generate_debris(self, du: NDArray[np.float64], dl: NDArray[np.float64]) -> None:
        if self.debris is None:
            return
        g = self.grid
        self.debris.generate(self._cycle, [(du, g.x_upper, g.y), (dl, g.x_lower, g.y)],
                             g.cell_area)

    def _apply_geometry(self) -> None:
        g = self.grid
        up: Recession
        lo: Recession
        if g.ny == 1:  # one cross-section: the profiles along x
            up = WornProfile(self.wear_upper, g.dx, float(g.x_upper[0]))
            lo = WornProfile(self.wear_lower, g.dx, float(g.x_lower[0]))
        else:
            y0 = float(g.y[0])
            up = HeightMap(self.wear_upper, g.dx, g.dy, float(g.x_upper[0]), y0)
            lo = HeightMap(self.wear_lower, g.dx, g.dy, float(g.x_lower[0]), y0)
        self.solver.set_surfaces(WornSurface(self.base_upper, up),
                                 WornSurface(self.base_lower, lo))

    def _state(self) -> NDArray[np.float64]:
        return np.concatenate([self.wear_upper.ravel(), self.wear_lower.ravel()])

    def _set_state(self, s: NDArray[np.float64]) -> None:
        k = self.wear_upper.size
        self.wear_upper = s[:k].reshape(self.wear_upper.shape).copy()
        self.wear_lower = s[k:].reshape(self.wear_lower.shape).copy()

    def simulate_cycle(self) -> dict[str, float]:
        """One cycle on the current surfaces; adds its wear; returns per-cycle quantities.

        With debris: every ``debris_every`` cycles a DE phase first (target from the last
        loading-position pressure), its pressure kept by the solver for the cycle; the
        cycle's worn volume becomes new debris (eq 3.10).
        """
        self._cycle += 1
        self._apply_geometry()
        extra: dict[str, float] = {}
        if self.debris is not None:
            extra["de_phase"] = 0
            if self._cycle % self.debris_every == 0 and self.debris.n > 0:
                extra |= self._de_phase()
        du, dl, per = self._solve_pass()
        m = self._subcycles(du, dl, per["contact_area_m2"])
        # the cycle in m passes, each adding 1/m of its wear (m = 1: x / 1 is x, bitwise)
        start = (self.wear_upper, self.wear_lower)
        du, dl = du / m, dl / m
        self.wear_upper, self.wear_lower = start[0] + du, start[1] + dl
        passes = [per]
        try:
            for _ in range(m - 1):
                self._apply_geometry()
                du_k, dl_k, per_k = self._solve_pass()
                du, dl = du + du_k / m, dl + dl_k / m
                self.wear_upper = self.wear_upper + du_k / m
                self.wear_lower = self.wear_lower + dl_k / m
                passes.append(per_k)
        except Exception:  # a stop inside the cycle: its wear is not kept (atomic)
            self.wear_upper, self.wear_lower = start
            self._apply_geometry()
            raise
        if m > 1:
            per = {k: (max(p[k] for p in passes) if k.startswith("max_")
                       else sum(p[k] for p in passes) / m) for k in per}
        self._last_du, self._last_dl = du, dl
        self._generate_debris(du, dl)
        if self.debris is not None:
            extra |= {"debris_particles": self.debris.n,
                      "debris_load_fraction": float(self.solver.debris_load) / self.solver.load,
                      "max_pressure_with_debris_Pa": self._pmax_debris,
                      "load_balance_error": self._balance}
        return {**per, **self.solver.cycle_columns(), **extra,
                "criterion": self.criterion.info()}  # this cycle's diagnostics (criterion.csv)

    def _solve_pass(self) -> tuple[NDArray[np.float64], NDArray[np.float64], dict[str, float]]:
        """One pass of the stroke on the current surfaces: (the wear depth it gives the
        upper and the lower body, m; its dissipated energy J, largest pressure and traction
        Pa, mean contact area m^2)."""
        self.solver.begin_cycle()  # the solver's hook (ccx: the cycle's job)
        crit = self.criterion
        crit.begin_cycle(self.grid, self.solver)
        cell = self.grid.cell_area
        energy = pmax = qmax = area = pmax_d = balance = 0.0
        pd = self.solver.debris_pressure if self.debris is not None else None
        load = self.solver.load
        for i, s in enumerate(self.offsets):
            inc = self.solver.solve_increment(float(s))
            crit.add_increment(i, inc)
            energy += float(inc.energy_density.sum()) * cell
            pmax = max(pmax, inc.max_pressure)
            qmax = max(qmax, inc.max_traction)
            area += inc.contact_area
            if self.debris is not None and pd is not None:
                total = inc.pressure + pd
                pmax_d = max(pmax_d, float(total.max()))
                balance = max(balance, abs(float(total.sum()) * cell - load) / load)
                if s == 0.0:
                    self._p_load = total
        self._pmax_debris, self._balance = pmax_d, balance
        du, dl = crit.depths()
        if np.any(du < 0) or np.any(dl < 0):
            raise RuntimeError(f"criterion '{crit.name}' returned a negative wear depth")
        return du, dl, {"dissipated_energy_J": energy, "max_pressure_Pa": pmax,
                        "max_traction_Pa": qmax, "contact_area_m2": area / len(self.offsets)}

    def _subcycles(self, du: NDArray[np.float64], dl: NDArray[np.float64],
                   area: float) -> int:
        """Passes the cycle's wear (``du``, ``dl``, m; mean contact area ``area``, m^2) is
        split into: ceil(increment / (update_tolerance x approach)) up to
        :data:`MAX_SUBCYCLES` where the loop can repeat the cycle (module docstring), else
        1; every cycle over the tolerance is counted for the summary."""
        tol = self.update_tolerance
        ratio = max(float(du.max(initial=0.0)), float(dl.max(initial=0.0))) / self._approach(area)
        u = self._updates
        u["largest_increment_over_approach"] = max(u["largest_increment_over_approach"], ratio)
        if tol is None or ratio <= tol:
            return 1
        if not (isinstance(self.criterion, RateCriterion) and self.debris is None
                and self.solver.capabilities.repeatable):
            u["cycles_over_tolerance"] += 1
            return 1
        m = min(math.ceil(ratio / tol), MAX_SUBCYCLES)
        u["cycles_split"] += 1
        u["most_subcycles"] = max(u["most_subcycles"], m)
        u["cycles_over_tolerance"] += int(ratio / m > tol)
        return m

    def wear_updates(self) -> dict[str, Any]:
        """The run's geometry updates against ``update_tolerance``: the cycles split into
        sub-cycles, the most sub-cycles of one cycle, the cycles whose update stayed over
        the tolerance (not splittable, or beyond :data:`MAX_SUBCYCLES`) and the largest
        depth increment of one simulated cycle over the elastic approach."""
        return {"update_tolerance": self.update_tolerance, **self._updates}

    def _row(self, cycle: int, jumped: bool, per_cycle: dict[str, float]) -> dict[str, Any]:
        cell = self.grid.cell_area
        return {
            "cycle": cycle,
            "jumped": int(jumped),
            "wear_depth_upper_m": float(self.wear_upper.max()),
            "wear_depth_lower_m": float(self.wear_lower.max()),
            "wear_volume_upper_m3": float(self.wear_upper.sum() * cell),
            "wear_volume_lower_m3": float(self.wear_lower.sum() * cell),
            **per_cycle,
        }

    def _new_history(self) -> FrettingHistory:
        g = self.grid
        return FrettingHistory(
            rows=[], grid=g, wear_upper=self.wear_upper, wear_lower=self.wear_lower,
            profiles_upper=[], profiles_lower=[],
            base_upper=np.asarray(self.base_upper(g.x_upper, np.zeros(g.n)), dtype=float),
            base_lower=np.asarray(self.base_lower(g.x_lower, np.zeros(g.n_track)),
                                  dtype=float),
            debris=self.debris,
        )

    def _record(self, row: dict[str, Any],
                progress: Callable[[dict[str, Any]], None] | None) -> None:
        """Record a row and the central-section profiles of its cycle (the newest replaces
        the one before it unless that one is among :meth:`plot_cycles`: a run of tens of
        thousands of cycles keeps six profiles, not one per cycle)."""
        hist = self.history
        assert hist is not None
        j = self.grid.ny // 2
        hist.rows.append(row)
        if hist.profile_cycles and hist.profile_cycles[-1] not in self._keep:
            for kept in (hist.profile_cycles, hist.profiles_upper, hist.profiles_lower):
                kept.pop()
        hist.profile_cycles.append(int(row["cycle"]))
        hist.profiles_upper.append(self.wear_upper[:, j].copy())
        hist.profiles_lower.append(self.wear_lower[:, j].copy())
        if progress is not None:
            progress(row)

    @staticmethod
    def plot_cycles(cycles: int, k: int = 5) -> set[int]:
        """The cycles whose profiles a run keeps for ``profiles.png`` / ``profiles.csv``:
        the first and ``k - 1`` evenly spaced up to ``cycles`` (the last among them)."""
        return {1} | {max(1, round(cycles * j / (k - 1))) for j in range(1, k)}

    def _jump(self, c: int, cycles: int, per: dict[str, Any],
              progress: Callable[[dict[str, Any]], None] | None) -> int:
        """Show cycle ``c`` to the strategy and jump if it proposes so; returns the cycle
        reached."""
        assert self.strategy is not None and self.history is not None
        self.strategy.observe(c, self._state())
        wanted = min(int(self.strategy.propose_jump()), cycles - c)
        inc, approach = self._geometry_scale(per)
        limit = self._geometry_limit(inc, approach)
        n = min(wanted, limit)
        self._note_decision(c, wanted, limit, n, inc, approach)
        if n <= 0:
            return c
        old = self._state()
        new = np.asarray(self.strategy.extrapolate(old, n), dtype=float)
        new = np.maximum(new, old)  # wear never heals
        for k in range(1, n + 1):
            prev = self._state()
            self._set_state(old + (new - old) * (k / n))
            self._cycle += 1
            if self.debris is not None:
                dd = self._state() - prev
                ku = self.wear_upper.size
                self._generate_debris(dd[:ku].reshape(self.wear_upper.shape),
                                      dd[ku:].reshape(self.wear_lower.shape))
                per = per | {"debris_particles": self.debris.n, "de_phase": 0}
            self._record(self._row(c + k, True, per), progress)
        self.history.cycles_jumped += n
        return c + n

    def _geometry_scale(self, per: dict[str, Any]) -> tuple[float, float]:
        """(largest depth increment of the last simulated cycle on either body, the
        contact's elastic approach), m: the two lengths of ``_geometry_limit``.

        The approach of the last simulated cycle's contact, 3 P / (4 a E*) with a the radius
        of its mean contact area (Hertz: a^2 / R), is the scale on which a change of the
        gap changes the pressure by its own order. A line contact (no finite approach in a
        half-space) takes b^2 / R = 4 P' / (pi E*), P' the load per unit length of the
        periodic window."""
        inc = max(float(self._last_du.max(initial=0.0)), float(self._last_dl.max(initial=0.0)))
        return inc, self._approach(float(per.get("contact_area_m2", 0.0)))

    def _approach(self, area: float) -> float:
        """The contact's elastic approach (m) for a mean contact area ``area`` (m^2):
        ``_geometry_scale``."""
        sol = self.solver
        if sol.contact == "line":  # b^2 / R = 4 P' / (pi E*), P' the load per unit length
            return 4.0 * sol.load / (math.pi * sol.modulus * sol.window)
        a = math.sqrt(max(area, self.grid.cell_area) / math.pi)
        return 3.0 * sol.load / (4.0 * a * sol.modulus)

    def _geometry_limit(self, inc: float, approach: float) -> int:
        """Longest jump the geometry allows (``NO_LIMIT``: none): the jumped depth
        increment, anywhere on either body, at most ``geometry_tolerance`` x the contact's
        elastic approach (``inc``, ``approach``: ``_geometry_scale``, m), so the pressure
        the next cycle sees moves little over a jump."""
        tol = self.geometry_tolerance
        if tol is None or inc <= 0.0:
            return NO_LIMIT
        return int(tol * approach / inc)

    def _note_decision(self, cycle: int, wanted: int, limit: int, n: int, inc: float,
                       approach: float) -> None:
        """Count one jump decision after simulated cycle ``cycle``: the strategy's
        proposal (cut at the run's end) ``wanted``, the geometry's ``limit``, the jump
        taken ``n``, and the two lengths behind the limit (m)."""
        d = self._decisions
        d["decisions"] += 1
        d["proposed"] += int(wanted > 0)
        d["capped_by_geometry"] += int(limit < wanted)
        d["cycles_proposed"] += max(wanted, 0)
        d["cycles_jumped"] += max(n, 0)
        d["last"] = {"after_cycle": int(cycle), "proposed": int(wanted),
                     "geometry_limit": None if limit >= NO_LIMIT else int(limit),
                     "jumped": max(int(n), 0), "depth_increment_m": inc,
                     "elastic_approach_m": approach,
                     "increment_over_approach": inc / approach if approach > 0 else None}
        if d["first"] is None:
            d["first"] = d["last"]

    def jump_decisions(self) -> dict[str, Any]:
        """What the jumps were and what limited them, for the summary: decisions (one per
        simulated cycle shown to the strategy), how many proposed a jump, how many the
        geometry cut (``geometry_tolerance``), the cycles proposed and jumped, and the
        first and last decision (proposal, geometry limit, jump, the last cycle's largest
        depth increment and the contact's elastic approach, m). ``cycles_proposed`` sums
        every proposal (cut at the run's end), so a proposal the geometry cut and the
        strategy makes again counts again."""
        return {"geometry_tolerance": self.geometry_tolerance, **self._decisions}

    @property
    def cycles_done(self) -> int:
        """Cycles recorded so far (simulated + jumped; 0 before the first loading)."""
        return self._done

    def state_dict(self) -> dict[str, Any]:
        """The loop's full state between two cycles, for a checkpoint.

        Wear maps, cycle counters, the rows and central profiles recorded so far, the
        solver's load history (warm starts, plastic state: ``solver.state_dict()``), the
        criterion's state carried across cycles (Miner sums, DFDI), the jump strategy's and
        the debris field's state (particles, counters, random generator) and the DE phases,
        the loading-position pressure. Nested dicts of numpy arrays and picklable Python
        objects; :meth:`load_state_dict` on a loop built from the same config restores it
        so that the run continues bitwise as if it had not stopped.
        """
        hist = self.history
        if hist is None:
            raise RuntimeError("nothing to save before the first loading (run() first)")
        return {
            "cycle": self._cycle, "done": self._done,
            "observe_pending": self._observe_pending, "last_per": dict(self._last_per),
            "wall_time_s": hist.wall_time_s,
            "wear_upper": self.wear_upper.copy(), "wear_lower": self.wear_lower.copy(),
            "last_du": self._last_du.copy(), "last_dl": self._last_dl.copy(),
            "p_load": np.asarray(self._p_load, dtype=float).copy(),
            "solver": self.solver.state_dict(),
            "criterion": self.criterion.state(),
            "strategy": None if self.strategy is None else dict(vars(self.strategy)),
            "debris": None if self.debris is None else dict(vars(self.debris)),
            "de_phases": list(self.de_phases),
            "rows": list(hist.rows),
            "profiles_upper": list(hist.profiles_upper),
            "profiles_lower": list(hist.profiles_lower),
            "profile_cycles": list(hist.profile_cycles),
            "cycles_simulated": hist.cycles_simulated,
            "cycles_jumped": hist.cycles_jumped,
            "jump_decisions": dict(self._decisions),
            "wear_updates": dict(self._updates),
        }

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore :meth:`state_dict` (``ValueError`` if it does not fit this loop)."""
        if (self.strategy is None) != (state["strategy"] is None):
            raise ValueError("the saved state and this loop differ in cycle-jumping")
        if (self.debris is None) != (state["debris"] is None):
            raise ValueError("the saved state and this loop differ in debris")
        for name in ("wear_upper", "wear_lower"):
            have, got = getattr(self, name).shape, np.shape(state[name])
            if have != got:
                raise ValueError(f"saved {name} has shape {got}, this loop {have}")
        self.wear_upper = np.array(state["wear_upper"], dtype=float)
        self.wear_lower = np.array(state["wear_lower"], dtype=float)
        self._last_du = np.array(state["last_du"], dtype=float)
        self._last_dl = np.array(state["last_dl"], dtype=float)
        self._p_load = np.array(state["p_load"], dtype=float)
        self._cycle = int(state["cycle"])
        self._done = int(state["done"])
        self._observe_pending = bool(state["observe_pending"])
        self._last_per = dict(state["last_per"])
        self._wall = float(state["wall_time_s"])
        self._apply_geometry()
        self.solver.load_state_dict(state["solver"])
        self.criterion.set_state(state["criterion"])
        if self.strategy is not None:
            vars(self.strategy).update(state["strategy"])
        if self.debris is not None:
            vars(self.debris).update(state["debris"])
        self.de_phases = list(state["de_phases"])
        hist = self._new_history()
        hist.rows = list(state["rows"])
        hist.profiles_upper = list(state["profiles_upper"])
        hist.profiles_lower = list(state["profiles_lower"])
        # checkpoints that kept a profile for every row did not name their cycles
        hist.profile_cycles = list(state.get("profile_cycles")
                                   or [int(r["cycle"]) for r in hist.rows])
        self._keep = set(hist.profile_cycles)
        hist.cycles_simulated = int(state["cycles_simulated"])
        hist.cycles_jumped = int(state["cycles_jumped"])
        # checkpoints written before the decisions were counted have none
        self._decisions = dict(state.get("jump_decisions") or _no_decisions())
        self._updates = dict(state.get("wear_updates") or _no_updates())
        hist.wall_time_s = self._wall
        hist.de_phases = self.de_phases
        self.history = hist

    def run(
        self,
        cycles: int,
        progress: Callable[[dict[str, Any]], None] | None = None,
        checkpoint: Callable[[FrettingLoop], None] | None = None,
        checkpoint_every: int = 1,
        checkpoint_seconds: float = 0.0,
    ) -> FrettingHistory:
        """Run up to cycle ``cycles`` (simulated or jumped) and return the history.

        The first call loads the bodies (normal loading at offset 0); a loop restored by
        :meth:`load_state_dict` (or run before) continues from where it is. ``progress`` is
        called with each recorded row; ``checkpoint(self)`` after every ``checkpoint_every``
        simulated cycles (each with the jump that may follow it) once ``checkpoint_seconds``
        of wall time have passed since the last one (the first: after the first cycle),
        and at the end. A contact
        that outgrows the solver window stops the run early (``history.stopped`` says why;
        rows so far are kept; no checkpoint is written for the unfinished cycle).
        """
        if int(cycles) != cycles or cycles < 1:
            raise ValueError(f"cycles = {cycles!r} is not allowed: must be an integer >= 1")
        if cycles > 1:
            try:
                require(self.solver, self.criterion.requires_over_cycles,
                        f"criterion '{self.criterion.name}' over {cycles} cycles")
            except ValueError as err:
                raise CriterionUnavailable(str(err)) from None
        if int(checkpoint_every) != checkpoint_every or checkpoint_every < 1:
            raise ValueError(f"checkpoint_every = {checkpoint_every!r} is not allowed: must "
                             "be an integer >= 1")
        t0 = time.perf_counter()
        cycles = int(cycles)
        self._keep |= self.plot_cycles(cycles)
        if self.history is None:
            self.history = self._new_history()
            self.solver.reset()
            self._apply_geometry()
            try:
                first = self.solver.solve_increment(0.0)  # normal loading at offset 0
            except (WindowTooSmallError, FESolverStopped) as err:
                self.history.stopped = f"first loading: {err}"
                self.stop_error = err
                return self._finish(t0)
            self._p_load = first.pressure + self.solver.debris_pressure
            if self.strategy is not None:
                self.strategy.observe(0, self._state())
        hist = self.history
        if cycles < self._done:
            raise ValueError(f"cycles = {cycles}: this run is already at cycle {self._done}")
        hist.stopped = None
        self.stop_error = None
        c = self._done
        if self._observe_pending and c < cycles:  # a finished run extended
            self._observe_pending = False
            c = self._done = self._jump(c, cycles, self._last_per, progress)
        since = 0
        last_checkpoint = -math.inf
        while c < cycles:
            try:
                per = self.simulate_cycle()
            except (WindowTooSmallError, FESolverStopped) as err:
                hist.stopped = f"cycle {c + 1}: {err}"
                self.stop_error = err
                break
            c += 1
            hist.cycles_simulated += 1
            self._record(self._row(c, False, per), progress)
            self._last_per = per
            if self.strategy is not None:
                if c >= cycles:
                    self._observe_pending = True
                else:
                    c = self._jump(c, cycles, per, progress)
            self._done = c
            since += 1
            now = time.perf_counter()
            if checkpoint is not None and (c >= cycles or (
                    since >= checkpoint_every and now - last_checkpoint >= checkpoint_seconds)):
                hist.wall_time_s = self._wall + now - t0
                checkpoint(self)
                since = 0
                last_checkpoint = now
        return self._finish(t0)

    def _finish(self, t0: float) -> FrettingHistory:
        hist = self.history
        assert hist is not None
        self._apply_geometry()  # the solver holds the final worn surfaces
        hist.wear_upper, hist.wear_lower = self.wear_upper, self.wear_lower
        hist.criterion_info = self.criterion.info()
        hist.de_phases = self.de_phases
        hist.wall_time_s = self._wall + time.perf_counter() - t0
        self._wall = hist.wall_time_s
        return hist
