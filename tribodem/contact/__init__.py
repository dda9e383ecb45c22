"""First-body contact solvers (DESIGN.md "The fretting FE-DE model"; Lu (2018) ch. 3, 5, 6).

One contract, :class:`FirstBodySolver` with its :class:`Capabilities`, driven through
fretting cycles by :class:`tribodem.fretting.FrettingLoop`. Backends, registered by name in
:data:`BACKENDS` (a new backend is one module here plus one line there):
``elastic`` :class:`HalfSpaceSolver` (elastic half-space BEM on tamaas) and
``elastic-plastic`` :class:`ElastoPlasticSolver` (semi-analytical elastic-plastic
half-space with friction on tamaas's volume operators, bilinear EN24T), ``fe``
:class:`FEContactSolver` (CalculiX, plane strain) and ``fe3d`` :class:`FE3DContactSolver`
(CalculiX, 3D crossed cylinders). Each backend is built from a resolved case
(:class:`ContactCase`) and the config tables it reads (:attr:`FirstBodySolver.options`:
``[plastic]`` :class:`~tribodem.contact.options.PlasticOptions`, ``[fe]``
:class:`~tribodem.contact.fe.options.FEOptions`) by :meth:`FirstBodySolver.from_case`.
"""

from tribodem.contact.base import (
    CAPABILITY_TEXT,
    VOIGT_ORDER,
    Capabilities,
    ContactCase,
    ElasticBody,
    FirstBodySolver,
    IncrementResult,
    Recession,
    SubsurfaceStress,
    Unsupported,
    WindowTooSmallError,
    contact_modulus,
    cycle_offsets,
    dundurs_beta,
    require,
)
from tribodem.contact.elastoplastic import (
    ElastoPlasticSolver,
    PlasticStep,
    PlasticSubsurfaceStress,
    bilinear_hardening,
)
from tribodem.contact.fe.backend import FEContactSolver
from tribodem.contact.fe.backend3d import FE3DContactSolver
from tribodem.contact.geometry import (
    HeightMap,
    HertzSphere,
    crossed_cylinders,
    cylinder,
    extruded_profile,
)
from tribodem.contact.halfspace import HalfSpaceSolver, max_shear, von_mises

#: First-body backends by name (``solver = "..."`` in a fretting config).
BACKENDS: dict[str, type[FirstBodySolver]] = {
    "elastic": HalfSpaceSolver,
    "elastic-plastic": ElastoPlasticSolver,
    "fe": FEContactSolver,
    "fe3d": FE3DContactSolver,
}

__all__ = [
    "BACKENDS",
    "CAPABILITY_TEXT",
    "VOIGT_ORDER",
    "Capabilities",
    "ContactCase",
    "ElasticBody",
    "ElastoPlasticSolver",
    "FE3DContactSolver",
    "FEContactSolver",
    "FirstBodySolver",
    "HalfSpaceSolver",
    "HeightMap",
    "HertzSphere",
    "IncrementResult",
    "PlasticStep",
    "PlasticSubsurfaceStress",
    "Recession",
    "SubsurfaceStress",
    "Unsupported",
    "WindowTooSmallError",
    "bilinear_hardening",
    "contact_modulus",
    "crossed_cylinders",
    "cycle_offsets",
    "cylinder",
    "dundurs_beta",
    "extruded_profile",
    "max_shear",
    "require",
    "von_mises",
]
