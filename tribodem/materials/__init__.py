"""tribodem.materials: micro-parameter sets and their calibration (seed 000 section 3.1).

``library`` (tables 1 and 3: ``MaterialSpec``, ``Q345B``, ``CU_PM``), ``specimen``
(bonded specimen generation), ``compression`` (uniaxial compression test, eq 12),
``calibrate`` (automatic E_c / kratio calibration), ``cli`` (``tribodem calibrate``).
"""

from tribodem.materials.calibrate import CalibrationResult, calibrate
from tribodem.materials.compression import CompressionResult, fit_moduli, run_compression
from tribodem.materials.library import CU_PM, LIBRARY, Q345B, MaterialSpec, get_material
from tribodem.materials.specimen import Specimen, make_specimen

__all__ = [
    "CU_PM",
    "LIBRARY",
    "Q345B",
    "CalibrationResult",
    "CompressionResult",
    "MaterialSpec",
    "Specimen",
    "calibrate",
    "fit_moduli",
    "get_material",
    "make_specimen",
    "run_compression",
]
