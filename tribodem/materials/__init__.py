"""tribodem.materials: every material once, with sources, and the calibration of Sha et al. (2022).

``en24t`` (Lu (2018)'s first-body steel: tables 5.1, 6.2, section 5.2), ``library`` (Sha et
al. (2022)
tables 1 and 3: ``MaterialSpec``, ``Q345B``, ``CU_PM``), ``specimen`` (bonded specimen
generation), ``compression`` (uniaxial compression test, eq 12), ``calibration`` (automatic
E_c / kratio calibration: :func:`calibrate_spec` on a spec, :func:`calibrate` the run of
``tribodem calibrate`` from Python, returning a :class:`~tribodem.io.record.RunResult`),
``cli`` (``tribodem calibrate``).

Names are imported on first use (PEP 562), so reading a material constant does not load the
particle engine.
"""

from __future__ import annotations

import importlib
from typing import Any

_WHERE = {
    "EN24T": "en24t", "SolidMaterial": "en24t",
    "CalibrationResult": "calibration", "calibrate": "calibration",
    "calibrate_spec": "calibration",
    "CompressionResult": "compression", "fit_moduli": "compression",
    "run_compression": "compression",
    "CU_PM": "library", "LIBRARY": "library", "Q345B": "library", "MaterialSpec": "library",
    "get_material": "library",
    "Specimen": "specimen", "make_specimen": "specimen",
}

__all__ = sorted(_WHERE)


def __getattr__(name: str) -> Any:
    if name not in _WHERE:
        raise AttributeError(f"module 'tribodem.materials' has no attribute {name!r}")
    return getattr(importlib.import_module(f"tribodem.materials.{_WHERE[name]}"), name)
