"""Finite-element first-body backend on CalculiX (groundwork; docs/fe.md).

Plane-strain cylindrical pad on a flat (line contact): graded quadrilateral mesh
(:mod:`.mesh`), ccx deck with seating, normal load and a tangential displacement cycle
(:mod:`.deck`), ccx runner with a wall-clock limit and clear errors (:mod:`.ccx`), ``.dat`` /
``.frd`` readers with contact tractions recovered from element nodal forces (:mod:`.results`),
one-call runs (:mod:`.model`) and closed-form checks (:mod:`.validate`, also
``python -m tribodem.contact.fe.validate``).
"""

from tribodem.contact.fe.ccx import (
    CCX_PATCHES,
    INSTALL_COMMAND,
    CcxConvergenceError,
    CcxError,
    CcxNotFoundError,
    CcxRun,
    CcxTimeoutError,
    ccx_build,
    ccx_patches,
    ccx_solvers,
    find_ccx,
    resolve_ccx,
    run_ccx,
)
from tribodem.contact.fe.deck import ContactSettings, FEMaterial, LoadCase, write_deck
from tribodem.contact.fe.mesh import Mesh, PadOnFlat, cylinder_on_flat, hertz_line
from tribodem.contact.fe.model import LineCase, LineRun, build, run_line_case
from tribodem.contact.fe.results import (
    ContactState,
    FEResults,
    read_dat,
    read_frd,
    read_results,
)

__all__ = [
    "CCX_PATCHES",
    "INSTALL_COMMAND",
    "CcxConvergenceError",
    "CcxError",
    "CcxNotFoundError",
    "CcxRun",
    "CcxTimeoutError",
    "ContactSettings",
    "ContactState",
    "FEMaterial",
    "FEResults",
    "LineCase",
    "LineRun",
    "LoadCase",
    "Mesh",
    "PadOnFlat",
    "build",
    "ccx_build",
    "ccx_patches",
    "ccx_solvers",
    "cylinder_on_flat",
    "find_ccx",
    "hertz_line",
    "read_dat",
    "read_frd",
    "read_results",
    "resolve_ccx",
    "run_ccx",
    "run_line_case",
    "write_deck",
]
