"""CalculiX input deck of the plane-strain pad-on-flat fretting model (Lu (2018) section 3.2.5).

Model (SI units; per unit length: the plane-strain thickness is 1 m, so forces are N/m):

* elements ``CPE4`` (ccx expands them to one layer of 8-node bricks);
* materials: ``*ELASTIC`` (E, nu) and optionally ``*PLASTIC`` with bilinear isotropic
  hardening (seed table 5.1): the true stress grows linearly from the yield stress at zero
  plastic strain through the UTS at the plastic strain ``uts_strain - UTS / E``, i.e. the
  tangent modulus E_t = (UTS - Y) / (uts_strain - Y / E) of :func:`bilinear_hardening`, and
  on along the same line (``beyond_uts = "line"``, the tamaas backend's law) or held at the
  UTS (``"hold"``, the law of config_version 2 and earlier);
* contact: ``*CONTACT PAIR, TYPE=SURFACE TO SURFACE``, slave the pad's arc, master the flat;
  ``*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR`` with the penalty stiffness
  ``penalty_factor * E / h_fine`` (Pa/m), ``*FRICTION`` mu with the stick slope
  ``stick_factor`` times that stiffness (Pa/m);
* boundary conditions: the flat's bottom fixed; every node of the pad's top edge tied to the
  reference node REF (x = 0) by ``*EQUATION`` in x and y (no rocking), so the normal load is
  one ``*CLOAD`` and the tangential displacement one ``*BOUNDARY`` on REF;
* steps: (1) seating: REF moved down by ``seat`` (m) under displacement control, x held;
  (2) loading: the y displacement released, P (N/m) applied on REF as a ramp, x held,
  automatic increments <= P / ``load_increments``;
  (3) tangential: REF x displacement 0 -> +delta -> 0 -> -delta -> 0 (``*AMPLITUDE`` over a
  step time of 4), automatic increments <= 4 / ``n_increments``; friction is mu_loading
  (0.001) in steps 1-2 and mu in step 3 (``*CHANGE FRICTION``). (Fixed ``DIRECT``
  increments diverged in the loading, and ccx refuses them together with ``*TIME POINTS``.)

The small-strain (``NLGEOM`` off) solution treats the table 5.1 strengths as true stresses.

Output to the ``.dat`` file at the ``*TIME POINTS`` (every P / ``load_increments`` and every
4 / ``n_increments`` of the cycle, i.e. at :func:`tribodem.contact.cycle_offsets`) and at the
end of each seating increment: total reaction force of the flat's bottom
(``*NODE PRINT, TOTALS=ONLY``), displacements of REF and of both contact faces, the
integration-point stresses of the elements along both contact faces (the contact tractions
are recovered from them, see :mod:`tribodem.contact.fe.results`) and optionally of the fine
zones (and PEEQ); optionally to the ``.frd``: displacements, stresses (and PEEQ).
"""

from __future__ import annotations

import io
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tribodem.contact.fe.mesh import Mesh

#: engineering strain at the UTS of EN24T used by the tamaas elasto-plastic backend
UTS_STRAIN_EN24T = 0.132
#: what the flow stress does past the UTS (:attr:`FEMaterial.beyond_uts`)
BEYOND_UTS = ("line", "hold")


@dataclass(frozen=True)
class FEMaterial:
    """Isotropic material of one body; ``yield_strength`` None = purely elastic.
    Defaults: EN24T, seed table 5.1 (E 240 GPa, nu 0.3, Y 680 MPa, UTS 1000 MPa)."""

    young: float = 240e9  #: Pa
    poisson: float = 0.3  #: -
    yield_strength: float | None = None  #: Pa
    uts: float = 1000e6  #: Pa
    uts_strain: float = UTS_STRAIN_EN24T  #: total strain at the UTS, -
    #: plastic modulus h = d sigma / d eps_p, Pa (None: the bilinear law through the UTS)
    hardening: float | None = None
    #: past the UTS: "line" (the hardening line goes on; the tamaas backend's law) or
    #: "hold" (the flow stress stays at the UTS: ccx holds a table's last row)
    beyond_uts: str = "line"

    def __post_init__(self) -> None:
        if self.beyond_uts not in BEYOND_UTS:
            raise ValueError(f"beyond_uts = {self.beyond_uts!r} is not allowed: allowed: "
                             f"{', '.join(repr(b) for b in BEYOND_UTS)}")

    def plastic_table(self) -> list[tuple[float, float]]:
        """``*PLASTIC`` rows (true stress Pa, equivalent plastic strain) of the linear
        hardening sigma = Y + h eps_p, h the ``hardening`` given or the bilinear law's
        through (Y, 0) and (UTS, uts_strain - UTS / E) (seed table 5.1, fig. 5.5): with
        ``beyond_uts`` "line" rows at eps_p = 0 and 1 (ccx holds Y + h past eps_p = 1),
        with "hold" at eps_p = 0 and where the line meets the UTS (held after it)."""
        if self.yield_strength is None:
            return []
        y, u = float(self.yield_strength), float(self.uts)
        if self.hardening is not None:
            h = float(self.hardening)
            if not (y > 0 and h >= 0 and math.isfinite(h)):
                raise ValueError(f"linear hardening needs Y > 0 and h >= 0; got Y={y!r}, "
                                 f"h={h!r}")
            p_uts = (u - y) / h if h > 0.0 else math.inf  # where the line meets the UTS
        else:
            if not (0 < y < u) or self.uts_strain <= u / self.young:
                raise ValueError(f"bilinear hardening needs 0 < yield < uts and uts_strain > "
                                 f"uts / E; got Y={y!r}, UTS={u!r}, "
                                 f"uts_strain={self.uts_strain!r}")
            p_uts = self.uts_strain - u / self.young
            h = (u - y) / p_uts
        if self.beyond_uts == "line":
            return [(y, 0.0), (y + h, 1.0)]
        if h == 0.0 and y <= u:  # perfectly plastic: the UTS is never reached
            return [(y, 0.0)]
        if not (0 < y < u):
            raise ValueError(f"beyond_uts = 'hold' needs 0 < yield < uts; got Y={y!r}, "
                             f"UTS={u!r}")
        return [(y, 0.0), (u, p_uts)]


@dataclass(frozen=True)
class ContactSettings:
    """Interface law: Coulomb friction ``mu``, linear penalty in normal and stick directions."""

    mu: float = 0.6  #: Coulomb friction coefficient (seed: 0.6)
    penalty_factor: float = 50.0  #: normal stiffness = factor * E_min / h_fine, Pa/m
    stick_factor: float = 0.1  #: stick slope = factor * normal stiffness, Pa/m
    formulation: str = "SURFACE TO SURFACE"  #: ccx contact pair type
    #: friction coefficient while seating and loading (> 0: ccx rejects 0; for elastically
    #: similar bodies, Dundurs beta = 0, the normal problem does not depend on friction)
    mu_loading: float = 1e-3
    stick_factor_loading: float = 0.1  #: stick slope factor while seating and loading
    #: ``*CONTACT PAIR`` once in the model data (else, as validated for the Hertz and
    #: Mindlin checks, written again with each ``*CHANGE FRICTION``)
    pair_in_model: bool = False
    #: node-to-surface only: the tension (Pa) ccx's linear law keeps at large clearances
    #: (None: ccx's default, measured 0.34 % of p0 on every free slave node; docs/fe.md)
    tension: float | None = None

    def normal_penalty(self, young_a: float, young_b: float, h: float) -> float:
        """Normal penalty stiffness k_n = ``penalty_factor`` x min(E_a, E_b) / h, Pa/m (E in
        Pa, h the fine element size in m): what every deck writes and every reading of
        stick and slip assumes."""
        return self.penalty_factor * min(young_a, young_b) / h

    def stick_slope(self, young_a: float, young_b: float, h: float,
                    loading: bool = False) -> float:
        """Stick slope k_t = stick factor x k_n, Pa/m (``stick_factor_loading`` while
        seating and loading): a slip increment up to mu p / k_t is the interface spring's,
        i.e. stick."""
        factor = self.stick_factor_loading if loading else self.stick_factor
        return factor * self.normal_penalty(young_a, young_b, h)


#: normal penalty of the sliding set-up, x E_min / h (docs/fe.md, "Penalty and speed": at
#: 10 E/h ccx slides a quarter cycle of +-0.1 mm in 9 increments where 50 E/h took 67, 3.2x
#: faster, p0 -1.0 % at h = a/4; every validate check passes at h = a/8)
SLIDING_PENALTY = 10.0


def sliding_contact(mu: float, p0: float, penalty_factor: float = SLIDING_PENALTY
                    ) -> ContactSettings:
    """The contact set-up of the fretting backend (docs/fe.md, "Reversals"): node-to-surface
    pair declared once in the model data, ccx's large-clearance tension of the linear law
    set to 1e-5 ``p0`` (Pa, the Hertz peak pressure), normal penalty ``penalty_factor``
    E/h; use with ``LoadCase(split_cycle=True)`` for full cycles (surface-to-surface
    friction is wrong on the return strokes)."""
    return ContactSettings(mu=mu, formulation="NODE TO SURFACE", pair_in_model=True,
                           tension=1e-5 * p0, penalty_factor=penalty_factor)


@dataclass(frozen=True)
class LoadCase:
    """Normal load (N/m), tangential amplitude (m) and increments of the tangential cycle."""

    load: float = 1e5  #: P per unit length, N/m
    delta: float = 0.0  #: tangential displacement amplitude of REF, m (0: no tangential step)
    n_increments: int = 16  #: increments of the cycle 0 -> +d -> 0 -> -d -> 0 (multiple of 4)
    half_cycle: bool = False  #: only 0 -> +delta (n_increments / 4 increments)
    load_increments: int = 5  #: increments of the loading step
    seat: float = 0.0  #: seating displacement, m (0: 5 % of a^2 / (2 R), set by the writer)
    #: ``*CONTROLS, PARAMETERS=FIELD``: residual and correction tolerances (ccx defaults
    #: 0.005, 0.01), e.g. (0.02, 0.05) for plastic cycles; None keeps the defaults
    field_controls: tuple[float, float] | None = None
    #: divide the largest automatic increment of the loading and the cycle by this factor,
    #: keeping the output times (the retry after a non-convergence)
    refine: int = 1
    #: divide the largest automatic increment of the cycle only (on top of ``refine``)
    cycle_refine: int = 1
    #: the cycle as one step per monotonic quarter (0 -> +d, +d -> 0, 0 -> -d, -d -> 0),
    #: ramped boundary values instead of the ``*AMPLITUDE``: ccx 2.20's surface-to-surface
    #: friction keeps a wrong tangential state through a reversal inside one step (docs/fe.md)
    split_cycle: bool = False
    #: with ``split_cycle``: cycles in the job, one after the other on the same bodies (the
    #: plastic strain and residual stress carry over; the first piece of ``chained`` mode);
    #: cycle k ends at total time 2 + 4 k
    cycles: int = 1
    #: with ``split_cycle``: after the last cycle, lift the pad off under displacement
    #: control (one more step of unit time: the residual, unloaded surfaces: pile-up, dent)
    unload: bool = False


def fmt(v: float) -> str:
    """A deck's number field: ``v`` with 10 significant digits (at most 16 characters)."""
    return f"{v:.9e}"


def write_ids(out: io.StringIO, ids: np.ndarray, per_line: int = 16) -> None:
    """Write the 1-based ``ids`` of a set's data lines, ``per_line`` to a line."""
    for k in range(0, ids.size, per_line):
        out.write(", ".join(str(int(i)) for i in ids[k:k + per_line]) + "\n")


def write_material(out: io.StringIO, name: str, mat: FEMaterial) -> None:
    """Write ``*MATERIAL`` ``name``: ``*ELASTIC`` E (Pa) and nu and, for a plastic one, its
    ``*PLASTIC`` rows (true stress Pa, equivalent plastic strain)."""
    out.write(f"*MATERIAL, NAME={name}\n*ELASTIC\n{fmt(mat.young)}, {mat.poisson}\n")
    table = mat.plastic_table()
    if table:
        out.write("*PLASTIC\n" + "".join(f"{fmt(s)}, {fmt(e)}\n" for s, e in table))


def _model_data(out: io.StringIO, mesh: Mesh, lower: FEMaterial, upper: FEMaterial,
                contact: ContactSettings) -> None:
    out.write("*HEADING\ntribodem fe: plane-strain cylindrical pad on flat\n")
    out.write("*NODE, NSET=NALL\n")
    for k, (x, y) in enumerate(mesh.nodes, start=1):
        out.write(f"{k}, {fmt(x)}, {fmt(y)}\n")
    n_low = mesh.element_sets["LOWER"].size
    for name, rows, first in (("LOWER", mesh.elements[:n_low], 1),
                              ("UPPER", mesh.elements[n_low:], n_low + 1)):
        out.write(f"*ELEMENT, TYPE=CPE4, ELSET={name}\n")
        for k, conn in enumerate(rows + 1, start=first):
            out.write(f"{k}, {conn[0]}, {conn[1]}, {conn[2]}, {conn[3]}\n")
    for name, ids in mesh.node_sets.items():
        out.write(f"*NSET, NSET={name}\n")
        write_ids(out, ids)
    for name, ids in mesh.element_sets.items():
        if name not in ("LOWER", "UPPER"):
            out.write(f"*ELSET, ELSET={name}\n")
            write_ids(out, ids)
    out.write("*ELSET, ELSET=FINE\nLFINE, UFINE\n")
    for name, (ids, face) in mesh.surfaces.items():
        out.write(f"*SURFACE, NAME={name}, TYPE=ELEMENT\n")
        for e in ids:
            out.write(f"{int(e)}, S{face + 1}\n")
    for name, mat in (("MLOWER", lower), ("MUPPER", upper)):
        write_material(out, name, mat)
    out.write("*SOLID SECTION, ELSET=LOWER, MATERIAL=MLOWER\n1.\n")
    out.write("*SOLID SECTION, ELSET=UPPER, MATERIAL=MUPPER\n1.\n")
    ref = int(mesh.node_sets["REF"][0])
    out.write("*EQUATION\n")
    for n in mesh.node_sets["UTOP"]:
        if int(n) != ref:
            for dof in (1, 2):
                out.write(f"2\n{int(n)}, {dof}, 1., {ref}, {dof}, -1.\n")
    k_n = contact.normal_penalty(lower.young, upper.young, mesh.h_fine)
    out.write("*SURFACE INTERACTION, NAME=SI\n")
    tension = "" if contact.tension is None else f", {fmt(contact.tension)}"
    out.write(f"*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR\n{fmt(k_n)}{tension}\n")
    if contact.mu > 0:
        k_t = contact.stick_slope(lower.young, upper.young, mesh.h_fine)
        out.write(f"*FRICTION\n{contact.mu}, {fmt(k_t)}\n")
    if contact.pair_in_model:
        out.write(f"*CONTACT PAIR, INTERACTION=SI, TYPE={contact.formulation}\nSPAD, SFLAT\n")


def _change_friction(out: io.StringIO, mesh: Mesh, lower: FEMaterial, upper: FEMaterial,
                     contact: ContactSettings, loading: bool) -> None:
    if contact.mu > 0:
        mu = contact.mu_loading if loading else contact.mu
        k_t = contact.stick_slope(lower.young, upper.young, mesh.h_fine, loading)
        out.write("*CHANGE FRICTION, INTERACTION=SI\n")
        out.write(f"*FRICTION\n{mu}, {fmt(k_t)}\n")
    if not contact.pair_in_model:
        out.write(f"*CONTACT PAIR, INTERACTION=SI, TYPE={contact.formulation}\nSPAD, SFLAT\n")


def static_step(initial: float, period: float, minimum: float, maximum: float) -> str:
    """A ``*STATIC`` keyword with its data line: initial increment, step period, minimum and
    maximum increment (step time). ccx reads each field as at most 20 characters: a
    ``repr`` such as ``8.333333333333334e-06`` (21) loses its exponent's last digit and
    became a minimum increment of 8.3 (ccx: "a time point precedes the minimum time tmin"),
    so 12 significant digits, as the time points are written."""
    return "*STATIC\n" + ", ".join(f"{v:.12g}" for v in (initial, period, minimum, maximum)) + "\n"


def write_time_points(out: io.StringIO, name: str, times: np.ndarray) -> None:
    """Write a ``*TIME POINTS`` card ``name`` with ``times`` (step time), 8 to a line."""
    out.write(f"*TIME POINTS, NAME={name}\n")
    for k in range(0, times.size, 8):
        out.write(", ".join(f"{t:.12g}" for t in times[k:k + 8]) + "\n")


def _outputs(out: io.StringIO, plastic: bool, fine_stress: bool, frd: bool,
             time_points: str, stress_sets: tuple[str, ...] = ()) -> None:
    tp = f", TIME POINTS={time_points}" if time_points else ""
    for name in stress_sets:
        out.write(f"*EL PRINT, ELSET={name}{tp}\nS\n")
        if plastic:
            out.write(f"*EL PRINT, ELSET={name}{tp}\nPEEQ\n")
    out.write(f"*NODE PRINT, NSET=LBOT, TOTALS=ONLY{tp}\nRF\n")
    out.write(f"*NODE PRINT, NSET=REF{tp}\nU\n")
    out.write(f"*NODE PRINT, NSET=UBOT{tp}\nU\n*NODE PRINT, NSET=LTOP{tp}\nU\n")
    out.write(f"*EL PRINT, ELSET=UCONT{tp}\nS\n*EL PRINT, ELSET=LCONT{tp}\nS\n")
    if fine_stress:
        out.write(f"*EL PRINT, ELSET=FINE{tp}\nS\n")
        if plastic:
            out.write(f"*EL PRINT, ELSET=FINE{tp}\nPEEQ\n")
    if frd:
        out.write(f"*NODE FILE{tp}\nU\n*EL FILE{tp}\nS" + (", PEEQ" if plastic else "") + "\n")


def write_deck(path: str | Path, mesh: Mesh, case: LoadCase,
               lower: FEMaterial | None = None, upper: FEMaterial | None = None,
               contact: ContactSettings | None = None, fine_stress: bool = True,
               frd: bool = False, stress_sets: tuple[str, ...] = ()) -> Path:
    """Write the ccx deck for ``mesh`` and ``case`` to ``path`` (``.inp``); returns the path.

    ``fine_stress``: print the integration-point stresses (and PEEQ) of the fine zones to the
    ``.dat`` every increment; ``frd``: also write displacements and stresses to the ``.frd``
    (for ParaView via ccx2paraview); ``stress_sets``: element sets of ``mesh`` whose
    integration-point stresses (and PEEQ when a body is plastic) are printed too."""
    lower = lower or FEMaterial()
    upper = upper or FEMaterial()
    contact = contact or ContactSettings()
    if case.load <= 0 or not math.isfinite(case.load):
        raise ValueError(f"load = {case.load!r} is not allowed: must be finite and > 0 N/m")
    n = int(case.n_increments)
    if case.delta > 0 and (n < 4 or n % 4):
        raise ValueError(f"n_increments = {n!r} is not allowed: a multiple of 4, >= 4")
    plastic = lower.yield_strength is not None or upper.yield_strength is not None
    radius, a = mesh.info["radius"], mesh.info["a"]
    seat = case.seat if case.seat > 0 else 0.05 * a * a / (2.0 * radius)
    ref = int(mesh.node_sets["REF"][0])
    out = io.StringIO()
    _model_data(out, mesh, lower, upper, contact)
    out.write("*AMPLITUDE, NAME=STROKE\n0., 0., 1., 1., 2., 0., 3., -1.\n4., 0.\n")
    n_load = max(int(case.load_increments), 1)
    n_tan = n // 4 if case.half_cycle else n
    write_time_points(out, "TLOAD", np.arange(1, n_load + 1) / n_load)
    if case.delta > 0 and case.split_cycle:
        write_time_points(out, "TQUARTER", np.arange(1, n // 4 + 1) / (n // 4))
    elif case.delta > 0:
        write_time_points(out, "TCYCLE", np.arange(1, n_tan + 1) * (4.0 / n))
    out.write("*BOUNDARY\nLBOT, 1, 2\n")
    controls = ""
    if case.field_controls is not None:
        r_n, c_n = case.field_controls
        controls = f"*CONTROLS, PARAMETERS=FIELD\n{r_n}, {c_n}\n"
    def outputs(time_points: str) -> None:
        _outputs(out, plastic, fine_stress, frd, time_points, stress_sets)

    def sliding_friction() -> None:
        _change_friction(out, mesh, lower, upper, contact, loading=False)

    # step 1: seating under displacement control
    out.write("*STEP, INC=200\n" + static_step(0.5, 1.0, 1e-4, 0.5))
    _change_friction(out, mesh, lower, upper, contact, loading=True)
    out.write(f"*BOUNDARY\n{ref}, 1, 1, 0.\n{ref}, 2, 2, {fmt(-seat)}\n")
    outputs("")
    out.write("*END STEP\n")
    # step 2: normal load P on REF (automatic increments <= 1 / n_load, output at 1 / n_load)
    refine = max(int(case.refine), 1)
    dt = 1.0 / (n_load * refine)
    out.write("*STEP, INC=1000\n" + static_step(dt, 1.0, dt * 1e-4, dt))
    out.write(f"*BOUNDARY, OP=NEW\nLBOT, 1, 2\n{ref}, 1, 1, 0.\n")
    out.write(f"*CLOAD\n{ref}, 2, {fmt(-case.load)}\n" + controls)
    outputs("TLOAD")
    out.write("*END STEP\n")
    if case.delta > 0:
        _cycle_steps(out, case, ref, controls, 2.0 * a * a / radius, outputs, sliding_friction)
    path = Path(path)
    path.write_text(out.getvalue())
    return path


def _cycle_steps(out: io.StringIO, case: LoadCase, ref: int, controls: str, lift: float,
                 outputs: Callable[[str], None], sliding_friction: Callable[[], None]) -> None:
    """The deck's tangential steps (step 3 on): REF's x displacement cycle, increments <=
    4 / n (refined), outputs every 4 / n; with ``case.split_cycle`` one step per quarter of
    each of ``case.cycles`` cycles and, with ``case.unload``, REF lifted by ``lift`` (m, where
    the surfaces have separated) and the load removed; else one ``STROKE`` step."""
    n = int(case.n_increments)
    n_load = max(int(case.load_increments), 1)
    refine = max(int(case.refine), 1)
    if case.split_cycle:
        if int(case.cycles) != case.cycles or case.cycles < 1:
            raise ValueError(f"cycles = {case.cycles!r} is not allowed: an integer >= 1")
        targets = ([case.delta, 0.0, -case.delta, 0.0] * int(case.cycles))[
            :1 if case.half_cycle else None]
        dt = 4.0 / (n * refine * max(int(case.cycle_refine), 1))
        for k, target in enumerate(targets):
            out.write("*STEP, INC=10000\n" + static_step(dt, 1.0, dt * 1e-4, dt))
            if k == 0:
                sliding_friction()
            out.write(f"*BOUNDARY\n{ref}, 1, 1, {fmt(target)}\n" + controls)
            outputs("TQUARTER")
            out.write("*END STEP\n")
        if case.unload:  # REF to a height where the surfaces have separated, load removed
            dt = 1.0 / (n_load * refine)
            out.write("*STEP, INC=1000\n" + static_step(dt, 1.0, dt * 1e-4, dt))
            out.write(f"*BOUNDARY, OP=NEW\nLBOT, 1, 2\n{ref}, 1, 1, 0.\n"
                      f"{ref}, 2, 2, {fmt(lift)}\n*CLOAD, OP=NEW\n{ref}, 2, 0.\n")
            outputs("TLOAD")
            out.write("*END STEP\n")
        return
    dt = 4.0 / (n * refine)
    total = 1.0 if case.half_cycle else 4.0
    out.write("*STEP, INC=10000\n" + static_step(dt, total, dt * 1e-4, dt))
    sliding_friction()
    out.write(f"*BOUNDARY, AMPLITUDE=STROKE\n{ref}, 1, 1, {fmt(case.delta)}\n" + controls)
    outputs("TCYCLE")
    out.write("*END STEP\n")
