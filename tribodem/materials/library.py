"""Micro-parameter sets of the braking materials (Sha et al. (2022) tables 1 and 3).

Macro targets (table 1) are what the uniaxial compression test must reproduce (eq 12);
micro-parameters (table 3) feed the linear contact law (PFC deformability,
``kn = A E_c / (r1 + r2)``, ``ks = kn / kratio``) and the linear parallel bond
(``kn_b = E_b / (r1 + r2)`` per area). All SI (Pa, m, kg/m^3, 1/K).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from tribodem.dem.contact import Material

#: default radius ratio r_max / r_min of the uniform size distribution around the seed's
#: 3.6 um (narrow, but polydisperse enough to avoid a 2D hexagonal crystal)
DEFAULT_RADIUS_RATIO = 1.2
#: default bond radius multiplier lambda (Rb = lambda min(r1, r2)); the seed gives none,
#: PFC's default is 1.0
DEFAULT_BOND_LAMBDA = 1.0


@dataclass(frozen=True)
class MaterialSpec:
    """One bonded-particle material: macro targets and DEM micro-parameters (SI).

    Targets (table 1): ``density`` (kg/m^3), ``young`` E (Pa), ``poisson`` nu.
    Micro (table 3): ``effective_modulus`` E_c (Pa), ``kratio`` kn/ks of the contacts,
    ``bond_modulus`` (Pa, ``None`` = E_c), ``bond_kratio`` (``None`` = kratio),
    ``tensile_strength`` and ``cohesion`` of the bonds (Pa), linear ``expansion``
    coefficient (1/K), normal critical damping ratio ``beta_n``, ``friction``, mean
    ``radius`` (m), ``radius_ratio`` r_max/r_min (uniform), ``bond_gap`` (m),
    ``bond_lambda`` (bond radius multiplier) and disk ``thickness`` (m, unit 2D).
    """

    name: str
    density: float
    young: float
    poisson: float
    effective_modulus: float
    kratio: float
    tensile_strength: float
    cohesion: float
    expansion: float
    beta_n: float = 0.5
    friction: float = 0.5
    radius: float = 3.6e-6
    radius_ratio: float = DEFAULT_RADIUS_RATIO
    bond_gap: float = 5.0e-9
    bond_lambda: float = DEFAULT_BOND_LAMBDA
    bond_modulus: float | None = None
    bond_kratio: float | None = None
    thickness: float = 1.0

    def __post_init__(self) -> None:
        checks = [
            ("density", self.density, self.density > 0, "> 0 kg/m^3"),
            ("young", self.young, self.young > 0, "> 0 Pa"),
            ("poisson", self.poisson, -1.0 < self.poisson < 0.5, "in (-1, 0.5)"),
            ("effective_modulus", self.effective_modulus, self.effective_modulus > 0, "> 0 Pa"),
            ("kratio", self.kratio, self.kratio > 0, "> 0"),
            ("tensile_strength", self.tensile_strength, self.tensile_strength > 0, "> 0 Pa"),
            ("cohesion", self.cohesion, self.cohesion > 0, "> 0 Pa"),
            ("expansion", self.expansion, self.expansion >= 0, ">= 0 1/K"),
            ("beta_n", self.beta_n, 0 <= self.beta_n < 1, "in [0, 1)"),
            ("friction", self.friction, self.friction >= 0, ">= 0"),
            ("radius", self.radius, self.radius > 0, "> 0 m"),
            ("radius_ratio", self.radius_ratio, 1.0 <= self.radius_ratio <= 3.0, "in [1, 3]"),
            ("bond_gap", self.bond_gap, self.bond_gap >= 0, ">= 0 m"),
            ("bond_lambda", self.bond_lambda, 0 < self.bond_lambda <= 2, "in (0, 2]"),
            ("thickness", self.thickness, self.thickness > 0, "> 0 m"),
        ]
        if self.bond_modulus is not None:
            checks.append(("bond_modulus", self.bond_modulus, self.bond_modulus > 0, "> 0 Pa"))
        if self.bond_kratio is not None:
            checks.append(("bond_kratio", self.bond_kratio, self.bond_kratio > 0, "> 0"))
        for field_name, value, ok, allowed in checks:
            if not ok:
                raise ValueError(f"material spec '{self.name}': {field_name} = {value!r}: "
                                 f"must be {allowed}")

    @property
    def bond_E(self) -> float:
        """Bond effective modulus (Pa): ``bond_modulus`` or E_c."""
        return self.effective_modulus if self.bond_modulus is None else self.bond_modulus

    @property
    def bond_kr(self) -> float:
        """Bond stiffness ratio kn/ks: ``bond_kratio`` or the contact kratio."""
        return self.kratio if self.bond_kratio is None else self.bond_kratio

    @property
    def radius_range(self) -> tuple[float, float]:
        """(r_min, r_max) (m) of the uniform distribution with mean ``radius``."""
        rmin = 2.0 * self.radius / (1.0 + self.radius_ratio)
        return rmin, rmin * self.radius_ratio

    def contact_material(self) -> Material:
        """The engine material of the particles (linear law, PFC deformability)."""
        return Material(name=self.name, young=self.young, poisson=self.poisson,
                        density=self.density, friction=self.friction,
                        effective_modulus=self.effective_modulus, kratio=self.kratio,
                        beta_n=self.beta_n, beta_s=0.0, law="linear")

    def with_micro(self, effective_modulus: float | None = None, kratio: float | None = None
                   ) -> MaterialSpec:
        """A copy with a new E_c and/or kratio (the bond follows unless set on its own)."""
        kw: dict[str, float] = {}
        if effective_modulus is not None:
            kw["effective_modulus"] = float(effective_modulus)
        if kratio is not None:
            kw["kratio"] = float(kratio)
        return dataclasses.replace(self, **kw)

    def micro_dict(self) -> dict[str, float]:
        """Micro-parameters by name (SI), for result files."""
        return {"effective_modulus_Pa": self.effective_modulus, "kratio": self.kratio,
                "bond_modulus_Pa": self.bond_E, "bond_kratio": self.bond_kr,
                "tensile_strength_Pa": self.tensile_strength, "cohesion_Pa": self.cohesion,
                "expansion_per_K": self.expansion, "beta_n": self.beta_n,
                "friction": self.friction, "radius_m": self.radius,
                "radius_ratio": self.radius_ratio, "bond_gap_m": self.bond_gap,
                "bond_lambda": self.bond_lambda, "thickness_m": self.thickness,
                "density_kg_m3": self.density}


#: brake disc, Q345B steel (Sha et al. (2022) tables 1 and 3)
Q345B = MaterialSpec(name="q345b", density=7850.0, young=201e9, poisson=0.302,
                     effective_modulus=9.35e10, kratio=1.75, tensile_strength=440e6,
                     cohesion=440e6, expansion=9.5e-6)
#: brake pad, copper-based powder metallurgy (Sha et al. (2022) tables 1 and 3)
CU_PM = MaterialSpec(name="cu-pm", density=5250.0, young=178e9, poisson=0.294,
                     effective_modulus=8.45e10, kratio=1.75, tensile_strength=245e6,
                     cohesion=245e6, expansion=1.11e-5)

LIBRARY: dict[str, MaterialSpec] = {Q345B.name: Q345B, CU_PM.name: CU_PM}


def get_material(name: str) -> MaterialSpec:
    """The library material ``name`` (``q345b`` or ``cu-pm``); ValueError names the choices."""
    key = name.strip().lower()
    if key not in LIBRARY:
        raise ValueError(f"material = {name!r}: must be one of {sorted(LIBRARY)}")
    return LIBRARY[key]
