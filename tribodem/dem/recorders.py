"""Recorders: CSV scalar time series, VTK particle snapshots and force chains.

Every file is (re)written atomically, so whatever was recorded before a crash or an
instability stop is on disk and readable.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from tribodem.io.results import write_csv
from tribodem.io.vtk import write_lines, write_points, write_pvd

if TYPE_CHECKING:
    from tribodem.dem.engine import Simulation

Probe = Callable[["Simulation"], float]


def default_probes(sim: Simulation) -> dict[str, Probe]:
    """Step, time, energies, contact count and each wall's position and normal force."""
    probes: dict[str, Probe] = {
        "step": lambda s: s.step_count,
        "time_s": lambda s: s.time,
        "kinetic_energy_J": lambda s: s.kinetic_energy(),
        "elastic_energy_J": lambda s: s.elastic_energy(),
        "contacts": lambda s: s.n_contacts(),
    }
    for w_id, w in enumerate(sim.walls):
        probes[f"{w.name}_normal_force_N"] = lambda s, k=w_id: s.walls[k].normal_force
        probes[f"{w.name}_position_m"] = lambda s, k=w_id: float(s.walls[k].point
                                                                  @ s.walls[k].normal)
    return probes


class ScalarRecorder:
    """Scalar time series to CSV; the file is rewritten atomically every ``flush_every`` rows."""

    def __init__(self, path: str | Path, probes: dict[str, Probe], flush_every: int = 50
                 ) -> None:
        self.path = Path(path)
        self.probes = dict(probes)
        self.rows: list[list[float]] = []
        self.flush_every = int(flush_every)

    def sample(self, sim: Simulation) -> None:
        """Append one row of probe values."""
        self.rows.append([f(sim) for f in self.probes.values()])
        if len(self.rows) % self.flush_every == 0:
            self.flush()

    def flush(self) -> None:
        """Write all rows so far (atomic)."""
        write_csv(self.path, list(self.probes), self.rows)

    def column(self, name: str) -> np.ndarray:
        """One recorded column as an array."""
        k = list(self.probes).index(name)
        return np.array([r[k] for r in self.rows], dtype=float)

    def close(self) -> None:
        """Final flush."""
        self.flush()

    def resume(self, step: int) -> None:
        """Take back the rows of an earlier run up to ``step`` (from the CSV on disk), with
        their exact values and types, so the rewritten file is byte-identical."""
        import csv

        if not self.path.is_file():
            return
        with self.path.open(newline="") as fh:
            rows = list(csv.reader(fh))
        if not rows:
            return
        if rows[0] != list(self.probes):
            raise ValueError(f"'{self.path}': its columns are not this run's probes")
        k = rows[0].index("step")
        self.rows = [[_number(x) for x in r] for r in rows[1:] if int(r[k]) <= step]


def _number(text: str) -> float:
    try:
        return int(text)
    except ValueError:
        return float(text)


class VTKRecorder:
    """Particle snapshots (``particles_<step>.vtu``) and force chains (``chains_<step>.vtu``).

    Force chains are the active contacts as lines between particle centres with the
    normal force (N; + compression, - tension) and its magnitude; ``particles.pvd`` and
    ``chains.pvd`` index the snapshots for ParaView.
    """

    def __init__(self, directory: str | Path, chains: bool = True) -> None:
        self.dir = Path(directory)
        self.chains = chains
        self.entries: list[tuple[float, str]] = []
        self.chain_entries: list[tuple[float, str]] = []

    def sample(self, sim: Simulation) -> None:
        """Write one snapshot."""
        p = sim.p
        name = f"particles_{sim.step_count:09d}.vtu"
        write_points(self.dir / name, p.pos, {
            "radius": p.radius, "velocity": p.vel, "angular_velocity": p.omega,
            "force": sim.force, "group": p.group, "material": p.mat,
        })
        self.entries.append((sim.time, name))
        write_pvd(self.dir / "particles.pvd", self.entries)
        if self.chains:
            c = sim.contacts()
            cname = f"chains_{sim.step_count:09d}.vtu"
            write_lines(self.dir / cname, p.pos, np.stack([c["i"], c["j"]], axis=1), {
                "normal_force": c["normal_force"],
                "force_magnitude": np.linalg.norm(c["force"], axis=1),
            })
            self.chain_entries.append((sim.time, cname))
            write_pvd(self.dir / "chains.pvd", self.chain_entries)

    def close(self) -> None:
        """Nothing buffered: every snapshot is complete on disk when written."""

    def resume(self, step: int) -> None:
        """Take back the snapshots of an earlier run up to ``step`` (from the ``.pvd``
        indexes on disk), so the indexes keep every snapshot across a resume."""
        self.entries = _pvd_entries(self.dir / "particles.pvd", step)
        if self.chains:
            self.chain_entries = _pvd_entries(self.dir / "chains.pvd", step)


def _pvd_entries(path: Path, step: int) -> list[tuple[float, str]]:
    """(time, file) rows of a ``.pvd`` written by ``write_pvd`` whose file's step <= ``step``."""
    import re

    if not path.is_file():
        return []
    out = []
    for t, f in re.findall(r'timestep="([^"]+)"[^>]*file="([^"]+)"', path.read_text()):
        m = re.search(r"_(\d+)\.vtu$", f)
        if m and int(m.group(1)) <= step and (path.parent / f).is_file():
            out.append((float(t), f))
    return out
