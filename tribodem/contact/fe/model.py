"""One plane-strain pad-on-flat ccx run: mesh, deck, solve, read (SI units, per unit length)."""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

from tribodem.contact.fe.ccx import CcxRun, run_ccx
from tribodem.contact.fe.deck import ContactSettings, FEMaterial, LoadCase, write_deck
from tribodem.contact.fe.mesh import Mesh, PadOnFlat, cylinder_on_flat, hertz_line
from tribodem.contact.fe.results import FEResults, read_results

#: default element size at the contact in units of the Hertz half-width a (docs/fe.md)
DEFAULT_H_OVER_A = 0.125


def contact_modulus_fe(lower: FEMaterial, upper: FEMaterial) -> float:
    """Plane-strain contact modulus E* = 1 / ((1 - nu1^2)/E1 + (1 - nu2^2)/E2), Pa."""
    return 1.0 / ((1 - lower.poisson**2) / lower.young + (1 - upper.poisson**2) / upper.young)


@dataclass(frozen=True)
class LineCase:
    """A 2D fretting case: the pad (radius ``radius``) pressed by ``load`` (N/m) then moved
    tangentially by ``delta`` (m). ``h_over_a`` sets the element size at the contact."""

    load: float = 1e5  #: N/m (p0 = 1.02 GPa, a = 62 um for EN24T, R 4 mm)
    radius: float = 4e-3  #: m
    delta: float = 0.0  #: tangential amplitude of the pad's top edge, m
    n_increments: int = 16  #: increments of a full cycle (multiple of 4)
    half_cycle: bool = False  #: only 0 -> +delta
    h_over_a: float = DEFAULT_H_OVER_A  #: element size at the contact / Hertz half-width
    size_factor: float = 40.0  #: body half-width and height / a (pad half-width <= 0.4 R)
    growth: float = 1.2  #: element size ratio outside the fine zone
    lower: FEMaterial = field(default_factory=FEMaterial)
    upper: FEMaterial = field(default_factory=FEMaterial)
    contact: ContactSettings = field(default_factory=ContactSettings)
    load_increments: int = 5
    field_controls: tuple[float, float] | None = None  #: see :class:`LoadCase`

    @property
    def e_star(self) -> float:
        return contact_modulus_fe(self.lower, self.upper)

    @property
    def hertz(self) -> tuple[float, float]:
        """Hertz (p0, a) in (Pa, m) of the line contact (Johnson eq. 4.45)."""
        return hertz_line(self.load, self.radius, self.e_star)


@dataclass
class LineRun:
    """Mesh, ccx run and parsed results of one :class:`LineCase`."""

    case: LineCase
    mesh: Mesh
    run: CcxRun
    results: FEResults
    seconds_mesh: float  #: meshing and deck writing, s
    seconds_read: float  #: reading the results, s


def build(case: LineCase, folder: str | Path, name: str = "job", fine_stress: bool = True,
          frd: bool = False) -> tuple[Mesh, Path]:
    """Mesh ``case`` and write ``<folder>/<name>.inp``; returns (mesh, deck path)."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    _, a = case.hertz
    mesh = cylinder_on_flat(PadOnFlat(radius=case.radius, a=a, h_fine=case.h_over_a * a,
                                      stroke=case.delta, size_factor=case.size_factor,
                                      growth=case.growth))
    load = LoadCase(load=case.load, delta=case.delta, n_increments=case.n_increments,
                    half_cycle=case.half_cycle, load_increments=case.load_increments,
                    field_controls=case.field_controls)
    deck = write_deck(folder / f"{name}.inp", mesh, load, case.lower, case.upper, case.contact,
                      fine_stress=fine_stress, frd=frd)
    return mesh, deck


def run_line_case(case: LineCase, folder: str | Path, threads: int = 1,
                  timeout: float = 600.0, fine_stress: bool = True, frd: bool = False,
                  executable: str | None = None) -> LineRun:
    """Build, solve with ccx (wall-clock ``timeout`` s) and read one case."""
    t0 = time.perf_counter()
    mesh, deck = build(case, folder, fine_stress=fine_stress, frd=frd)
    t1 = time.perf_counter()
    run = run_ccx(deck, threads=threads, timeout=timeout, executable=executable)
    t2 = time.perf_counter()
    results = read_results(run.job, mesh)
    t3 = time.perf_counter()
    return LineRun(case, mesh, run, results, t1 - t0, t3 - t2)
