"""Thermal room (Sha et al. (2022) section 2.4, eq 13; PFC thermal): temperature, expansion,
conduction.

Per particle: temperature T (K), heat capacity c (J/(kg K)), linear expansion alpha (1/K).
Each step (an engine ``Interaction``; it adds no force itself):

1. conduction through **intact bonds only** (thermal pipes): ``Q = (T_j - T_i) / eta`` (W)
   per bond with resistance eta (K/W), ``dT_i = dt sum Q / (m_i c_i)`` (explicit; a step
   above ``min m c / sum(1/eta)`` is refused);
2. boundary temperatures: particles of a group follow a curve (time s, T K), linearly
   interpolated at the end of the step;
3. the temperature change since the last update expands the particles freely,
   ``dR = alpha R dT`` (mass kept: the density is scaled), and loads the intact bonds with
   the constrained part, ``dFn = kn A alpha L dT`` (+ = compression; Sha et al. (2022) eq 13
   ``dsigma = E alpha dT`` on the bond section), alpha and dT the means of the two ends.

Heat reaching a particle changes its temperature only; there is no heat of friction here.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numba import prange

from tribodem.dem.bonds import INTACT, ParallelBonds
from tribodem.dem.jit import kernel
from tribodem.dem.state import checked_per_item

if TYPE_CHECKING:
    from tribodem.dem.engine import Simulation


@kernel
def conduct(temp, cstart, cbond, bi, bj, mode, resistance, mass, heat_cap, dt, out):
    """New temperatures after one explicit conduction step over intact bonds (prange over
    particles, fixed order: independent of the thread count)."""
    n = temp.shape[0]
    for p in prange(n):
        q = 0.0
        for k in range(cstart[p], cstart[p + 1]):
            b = cbond[k]
            if mode[b] != INTACT:
                continue
            other = bj[b] if bi[b] == p else bi[b]
            q += (temp[other] - temp[p]) / resistance[b]
        out[p] = temp[p] + dt * q / (mass[p] * heat_cap[p])


def read_curve(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """Read a temperature curve CSV with two columns, time (s) and T (K); a header row and
    ``#`` comments are skipped. Returns (times, temperatures). ``ValueError`` naming the
    file and the row for anything else: a file that cannot be read or is not text, a row
    that is not two finite numbers, times that do not increase, a temperature <= 0 K."""
    rows = []
    try:
        with open(path, newline="", encoding="utf-8") as fh:
            for n, row in enumerate(csv.reader(fh), start=1):
                if not row or not "".join(row).strip() or row[0].strip().startswith("#"):
                    continue
                try:
                    t, temp = float(row[0]), float(row[1])
                except (ValueError, IndexError):
                    if rows or n > 1:
                        raise ValueError(f"curve '{path}': row {n} {row!r} is not two numbers "
                                         "(time s, temperature K)") from None
                    continue  # a header
                if not (math.isfinite(t) and math.isfinite(temp)) or temp <= 0.0:
                    raise ValueError(f"curve '{path}': row {n} {row!r}: allowed: a finite "
                                     "time (s) and a temperature > 0 K")
                rows.append((t, temp))
    except (OSError, UnicodeDecodeError, csv.Error) as err:
        raise ValueError(f"curve '{path}': cannot be read as a CSV text file: {err}") from None
    if not rows:
        raise ValueError(f"curve '{path}': no (time s, temperature K) rows")
    a = np.array(rows)
    if np.any(np.diff(a[:, 0]) <= 0):
        raise ValueError(f"curve '{path}': the times do not increase from row to row")
    return a[:, 0], a[:, 1]


def _per_particle(x: object, n: int, name: str, allowed: str, ok: object) -> np.ndarray:
    return checked_per_item(x, n, "thermal", name, allowed, ok)


class Thermal:
    """Particle temperatures, free expansion and conduction through intact bonds.

    ``heat_capacity`` c (J/(kg K)) and ``expansion`` alpha (1/K): scalars or per particle;
    ``temperature``: initial T (K); ``bonds``/``resistance``: thermal pipes along the bonds
    with resistance eta (K/W, scalar or per bond; ``None``: no conduction). Add it to the
    simulation with ``sim.add_interaction``.
    """

    def __init__(self, sim: Simulation, heat_capacity: float | np.ndarray,
                 expansion: float | np.ndarray = 0.0, temperature: float | np.ndarray = 293.15,
                 bonds: ParallelBonds | None = None,
                 resistance: float | np.ndarray | None = None) -> None:
        n = sim.p.n
        self.heat_capacity = _per_particle(heat_capacity, n, "heat_capacity", "> 0 J/(kg K)",
                                           lambda a: a > 0)
        self.expansion = _per_particle(expansion, n, "expansion", ">= 0 1/K",
                                       lambda a: a >= 0)
        self.temperature = _per_particle(temperature, n, "temperature", "> 0 K",
                                         lambda a: a > 0)
        self.applied = self.temperature.copy()  # T the radii and bond forces correspond to
        self.bonds = bonds
        self.resistance: np.ndarray | None = None
        if resistance is not None:
            if bonds is None:
                raise ValueError("thermal: resistance given but bonds = None: conduction runs "
                                 "through bonds")
            nb = bonds.n_bonds
            r = np.asarray(resistance, dtype=np.float64)
            r = np.full(nb, float(r)) if r.ndim == 0 else r.reshape(-1).copy()
            if r.shape != (nb,):
                raise ValueError(f"thermal: resistance has shape {r.shape}, expected a scalar "
                                 f"or ({nb},)")
            if np.any(~(r > 0)):
                k = int(np.flatnonzero(~(r > 0))[0])
                raise ValueError(f"thermal: resistance = {float(r[k])!r}: must be > 0 K/W")
            self.resistance = r
        self.boundaries: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
        self._out = np.zeros(n)
        self.dt_limit = self.conduction_step(sim)
        self._check_step(sim)

    def conduction_step(self, sim: Simulation) -> float:
        """Largest stable explicit conduction step (s): ``min m c / sum(1/eta)``."""
        if self.bonds is None or self.resistance is None or self.bonds.n_bonds == 0:
            return np.inf
        g = np.zeros(sim.p.n)
        for ends in (self.bonds.i, self.bonds.j):
            np.add.at(g, ends, 1.0 / self.resistance)
        sel = g > 0
        return float((sim.p.mass[sel] * self.heat_capacity[sel] / g[sel]).min())

    def _check_step(self, sim: Simulation) -> None:
        if sim.dt > self.dt_limit:
            raise ValueError(f"thermal: dt = {sim.dt:.6g} s is above the conduction limit "
                             f"{self.dt_limit:.6g} s (m c / sum 1/eta); raise the resistance "
                             "or the heat capacity, or lower dt")

    def add_boundary(self, sim: Simulation, group: int, times: np.ndarray,
                     temperatures: np.ndarray) -> None:
        """Hold the particles of ``group`` at the curve T(t) (s, K; linear interpolation,
        constant beyond the ends)."""
        t = np.asarray(times, dtype=np.float64).reshape(-1)
        temp = np.asarray(temperatures, dtype=np.float64).reshape(-1)
        if t.size == 0 or t.shape != temp.shape:
            raise ValueError(f"thermal: boundary curve has {t.size} times and {temp.size} "
                             "temperatures: need the same number, at least one")
        if np.any(np.diff(t) <= 0):
            raise ValueError("thermal: boundary curve times must increase strictly")
        if np.any(~(temp > 0)):
            k = int(np.flatnonzero(~(temp > 0))[0])
            raise ValueError(f"thermal: boundary temperature = {float(temp[k])!r}: must be "
                             "> 0 K")
        mask = sim.p.group == group
        if not mask.any():
            raise ValueError(f"thermal: group = {group!r}: no particle has this group")
        self.boundaries.append((np.flatnonzero(mask), t, temp))

    def set_temperature(self, value: float | np.ndarray, index: np.ndarray | None = None
                        ) -> None:
        """Set temperatures (K; all particles or ``index``); the expansion follows at the
        next step."""
        v = np.asarray(value, dtype=np.float64)
        if np.any(~(v > 0)):
            raise ValueError(f"thermal: temperature = {v!r}: must be > 0 K")
        if index is None:
            self.temperature[:] = v
        else:
            self.temperature[index] = v

    def compute(self, sim: Simulation) -> None:
        """Conduct, apply the boundary curves, expand particles and load bonds."""
        p = sim.p
        if self.resistance is not None and self.bonds is not None and self.bonds.n_bonds:
            self._check_step(sim)
            b = self.bonds
            conduct.pick(p.n)(self.temperature, b.cstart, b.cbond, b.i, b.j, b.mode,
                              self.resistance, p.mass, self.heat_capacity, sim.dt, self._out)
            self.temperature[:] = self._out
        t_end = sim.time + sim.dt
        for idx, times, temps in self.boundaries:
            self.temperature[idx] = np.interp(t_end, times, temps)
        dT = self.temperature - self.applied
        if not dT.any():
            return
        grow = 1.0 + self.expansion * dT
        if np.any(grow != 1.0):
            p.radius *= grow
            p.density /= grow ** (2 if p.dim == 2 else 3)  # keep the mass
            p.update_mass()
            if self.bonds is not None:
                self.bonds.thermal_load(dT, self.expansion)
        self.applied[:] = self.temperature

    def state(self) -> dict[str, np.ndarray]:
        """Temperatures, for checkpoints (radii and densities are particle arrays)."""
        return {"temperature": self.temperature, "applied": self.applied}

    def set_state(self, state: dict[str, np.ndarray]) -> None:
        """Restore what ``state`` returned."""
        self.temperature = np.array(state["temperature"])
        self.applied = np.array(state["applied"])
