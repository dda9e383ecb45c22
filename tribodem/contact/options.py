"""Option tables the backends read, and how a backend picks its table from a mapping.

:class:`ElasticOptions` is the ``[elastic]`` table (how the elastic half-space solves a
line contact). :class:`PlasticOptions` is the ``[plastic]`` table: the one plastic law of
every backend that models plastic bodies (``elastic-plastic`` on tamaas EPIC with its
``ep_*`` grid, and the ccx backends ``fe`` / ``fe3d`` with ``[fe] material =
"elastic-plastic"``). SI units; every description names its unit.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Literal, TypeVar

from pydantic import BaseModel, Field

from tribodem.io.model import StrictModel, physical
from tribodem.materials.en24t import EN24T

M = TypeVar("M", bound=BaseModel)

#: Physical range of yield and tensile strengths, Pa (soft polymers to ceramics).
STRENGTH_RANGE = (1e5, 2e10)


class ElasticOptions(StrictModel):
    """``[elastic]``: how ``solver = "elastic"`` solves a line contact (a cylinder on a flat,
    ``contact.geometry = "cylinder_on_flat"``)."""

    line_model: Literal["plane-strain", "periodic-2d"] = Field(
        "plane-strain", description="plane-strain: one cross-section along the stroke with "
        "the plane-strain influence function (tribodem.contact.line, n points, fast); "
        "periodic-2d: the n x n window periodic along the cylinder's axis on tamaas (the "
        "same contact, for comparison; n^2 points)")


class PlasticOptions(StrictModel):
    """The plastic law of ``solver = "elastic-plastic"`` (its ``ep_*`` plastic grid) and
    of the ccx backends' ``[fe] material = "elastic-plastic"``: bilinear EN24T (seed table
    5.1), one law for every backend."""

    yield_strength: float = Field(EN24T.yield_strength, gt=0, **physical(
        *STRENGTH_RANGE, "Pa", "initial yield, Pa"))
    uts: float = Field(EN24T.uts, gt=0, **physical(
        *STRENGTH_RANGE, "Pa", "ultimate tensile strength, Pa"))
    uts_strain: float = Field(EN24T.uts_strain, gt=0, lt=1,
                              description="engineering strain at UTS")
    hardening: float | None = Field(None, ge=0, **physical(
        0.0, 2e12, "Pa", "hardening modulus h, Pa (None: bilinear)"))
    beyond_uts: Literal["line", "hold"] = Field(
        "line", description="past the UTS: line, the hardening line goes on (seed fig. 5.5; "
        "tamaas's law, the only one it has); hold, the flow stress stays at the UTS (fe, "
        "fe3d; their law before config_version 3)")
    ep_n: int = Field(32, ge=8, le=256, description="EP grid points per side (even)")
    ep_nz: int = Field(12, ge=3, le=64, description="EP grid layers")
    ep_window_radii: float = Field(5.0, gt=0, description="EP window, Hertz radii")
    ep_depth_radii: float = Field(2.0, gt=0, description="EP depth, Hertz radii")
    load_steps: int = Field(4, ge=1, le=100, description="first-loading steps")
    ep_tolerance: float = Field(1e-6, gt=0, lt=0.1,
                                description="plastic solve tolerance (elastic-plastic)")
    shakedown_tolerance: float = Field(
        1e-4, gt=0, lt=1, description="shakedown: a cycle's largest increase of the "
        "equivalent plastic strain below this (elastic-plastic)")


def option_table(options: Mapping[str, BaseModel | Mapping[str, Any]] | None, table: str,
                 model: type[M]) -> M:
    """The option table ``table`` of ``options`` (config tables by TOML name) as ``model``:
    the model's defaults when it is missing; a model of another class with the same fields,
    or a plain mapping, is validated into ``model``."""
    given = None if options is None else options.get(table)
    if given is None:
        return model()
    if isinstance(given, model):
        return given
    return model.model_validate(given.model_dump() if isinstance(given, BaseModel) else given)
