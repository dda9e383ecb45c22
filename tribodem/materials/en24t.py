"""EN24T, the first-body steel of Lu (2018) (crossed cylinders), defined once.

Sources, all Lu (2018): table 5.1 (E, nu, yield, UTS; bilinear hardening), section 5.2 (the
Fouvry energy wear coefficient of the fretting tests), table 6.2 (Smith-Watson-Topper
constants by Mitchell's method; its true UTS 1132 MPa = 1000 MPa x (1 + e) fixes the
engineering strain at the UTS), appendix IV (the DFDI script's eps0 = 0.118). SI units.
"""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class SolidMaterial:
    """A continuum first-body material (SI): elastic, bilinear plastic, wear and fatigue data."""

    name: str
    young: float  #: Young's modulus E, Pa
    poisson: float  #: Poisson's ratio nu
    yield_strength: float  #: initial yield sigma_y, Pa
    uts: float  #: ultimate tensile strength, Pa (engineering)
    uts_strain: float  #: engineering strain at the UTS
    energy_wear_coefficient: float  #: Fouvry alpha, m^3/J (eq 2.7)
    swt: dict[str, float] = field(default_factory=dict)  #: b, sigma_f (Pa), sigma_t, eps_f, c
    #: eps0 of the ductile failure damage indicator (eq 6.2), uniaxial failure strain
    dfdi_eps0: float = 0.0
    source: str = ""


EN24T = SolidMaterial(
    name="EN24T",
    young=240e9,
    poisson=0.3,
    yield_strength=680e6,
    uts=1000e6,
    uts_strain=0.132,
    energy_wear_coefficient=1.641e-6 * 1e-9,  # 1.641e-6 mm^3/J
    swt={"b": -0.103, "sigma_f": 2349e6, "sigma_t": 1132e6, "eps_f": 1.22, "c": -0.6},
    dfdi_eps0=0.118,  # the seed's DFDI script (appendix IV: FailE = 1.65*0.118*exp(...))
    source="Lu (2018) table 5.1 (elastic-plastic), section 5.2 (alpha), table 6.2 (SWT), "
    "appendix IV (DFDI eps0)",
)
