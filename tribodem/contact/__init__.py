"""First-body contact solvers (DESIGN.md "The fretting FE-DE model"; seed 003 ch. 3, 5, 6).

One interface, :class:`FirstBodySolver`, driven through fretting cycles by
:class:`FrettingCycle`; backends :class:`HalfSpaceSolver` (elastic half-space BEM on tamaas)
and :class:`ElastoPlasticSolver` (tamaas EPIC, bilinear EN24T).
"""

from tribodem.contact.base import (
    VOIGT_ORDER,
    CycleResult,
    ElasticBody,
    FirstBodySolver,
    FrettingCycle,
    IncrementResult,
    SubsurfaceStress,
    contact_modulus,
    cycle_offsets,
    dundurs_beta,
)
from tribodem.contact.elastoplastic import (
    ElastoPlasticSolver,
    PlasticStep,
    PlasticSubsurfaceStress,
    bilinear_hardening,
)
from tribodem.contact.geometry import (
    HeightMap,
    HertzSphere,
    crossed_cylinders,
    cylinder,
    extruded_profile,
)
from tribodem.contact.halfspace import (
    HalfSpaceSolver,
    WindowTooSmallError,
    max_shear,
    von_mises,
)

__all__ = [
    "VOIGT_ORDER",
    "CycleResult",
    "ElasticBody",
    "ElastoPlasticSolver",
    "FirstBodySolver",
    "FrettingCycle",
    "HalfSpaceSolver",
    "HeightMap",
    "HertzSphere",
    "IncrementResult",
    "PlasticStep",
    "PlasticSubsurfaceStress",
    "SubsurfaceStress",
    "WindowTooSmallError",
    "bilinear_hardening",
    "contact_modulus",
    "crossed_cylinders",
    "cycle_offsets",
    "cylinder",
    "dundurs_beta",
    "extruded_profile",
    "max_shear",
    "von_mises",
]
