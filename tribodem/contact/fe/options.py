"""The ``[fe]`` table: the options of the CalculiX backends ``fe`` and ``fe3d``.

:class:`FEOptions` is what a config's ``[fe]`` table holds; each backend takes the fields
it declares (``FE_FIELDS`` of :class:`~tribodem.contact.fe.base.CcxBackend`) and refuses
another one set away from its default. SI units; every description names its unit.
"""

from __future__ import annotations

from typing import Any, Literal

from pydantic import Field, field_serializer, field_validator

from tribodem.contact.base import BACKEND_OWN as BACKEND_OWN
from tribodem.io.model import StrictModel

#: plastic runs: the smallest number of cycle increments ccx may take per cycle
#: (docs/fe.md, "Elastic-plastic cycles": >= 32 cycle increments converge where 16 stalled)
PLASTIC_MIN_INCREMENTS = 32

#: the steepest worn-depth step / column spacing on which the seed's elastic-plastic shear
#: run converged in 3D (docs/fe3d.md "Worn geometry": cycle 2 on 0.093 / 0.099 converged,
#: cycle 3 on 0.22 / 0.24 did not, h = a/3); a job that fails on steeper surfaces says so
CONVERGED_SLOPE = 0.1

#: the largest change of slope at a node (the angle by which the worn surface's facets turn
#: between neighbouring node columns, rad for small slopes) the fe3d morph leaves; the
#: unworn R 4 mm cylinder turns by h / R = 0.011 per 44 um element, the seed's shear scar
#: after 7 cycles, slope-limited, by up to 0.17 / 0.20 (upper / lower; docs/fe3d.md "Worn
#: geometry")
DEFAULT_KINK = 0.03


class FEOptions(StrictModel):
    """``[fe]``: the CalculiX backends ``fe`` (plane strain, docs/fe.md) and ``fe3d`` (3D
    crossed cylinders, docs/fe3d.md)."""

    mode: Literal["fresh", "chained", "primed"] = Field(
        "fresh", description="fresh: one ccx job per cycle on the worn geometry, virgin "
        "material (Lu (2018) section 3.3); chained (fe): cycles continue in one job while the "
        "geometry is unchanged, so plastic strain and residual stress carry over; primed "
        "(fe3d): each job from cycle 2 first runs the previous cycle's second half, so the "
        "served cycle is a continuous test's (the steady loop of elastic bodies)")
    material: Literal["elastic", "elastic-plastic"] = Field(
        "elastic", description="elastic-plastic: bilinear isotropic hardening of the "
        "[plastic] table (seed table 5.1) in both bodies")
    chain_cycles: int = Field(5, ge=1, le=1000, description="chained mode: cycles per ccx "
                              "job (a used-up chain is run again with this many more)")
    plastic_increments: int = Field(
        PLASTIC_MIN_INCREMENTS, ge=4, le=10000, description="elastic-plastic: the fewest ccx "
        "increments per cycle (32 converged where 16 stalled, docs/fe.md)")
    cycle_increments: int | None = Field(
        None, ge=4, le=100000, description="fe3d: the fewest ccx increments per cycle, the "
        "output times staying n_increments (left out: n_increments, plastic_increments for "
        "elastic-plastic bodies; --quick: 64, docs/fe3d.md)")
    h_over_a: float | None = Field(
        None, gt=0, le=1, description="element size at the contact / Hertz half-width or "
        "radius (left out: the backend's own, fe 0.25, fe3d 1/3; docs/fe.md: a/4 is 4x "
        "faster than a/8 at large strokes)")
    size_factor: float | None = Field(
        None, ge=2, le=200, description="bodies' size / contact half-width or radius (left "
        "out: the backend's own, fe 40, fe3d 8; fe: >= 10; fe3d: at most R / (2 a))")
    threads: int = Field(1, ge=0, description="ccx threads (0 = all cores; --threads)")
    timeout: float | None = Field(
        None, gt=0, description="wall-clock limit of one ccx job, s (left out: the "
        "backend's, fe 1800 s, fe3d 14400 s: the seed's 3D cycle takes ~1 h with Debian's "
        "ccx on 2 threads, ~40 min at h = a/4 with ccx_pardiso)")
    retries: int = Field(1, ge=0, le=6, description="retries after a non-convergence: "
                         "halved increments, then also a contact half as stiff, alternately "
                         "(jobs.attempt_settings; 1: halved increments only; 5: (8, 1/4), "
                         "the finest increments at a quarter of the penalty)")
    retry_from: Literal["first", "last"] = Field(
        "first", description="where a cycle's ccx attempts start: first, the job as "
        "configured (every cycle); last, the attempt on which the previous cycle converged "
        "(the attempts before it are not run; a worn geometry that needed a finer or softer "
        "attempt mostly needs it again: docs/fe.md)")
    loading_friction: Literal["auto", "low", "full"] = Field(
        "auto", description="friction while seating and loading: low, 0.001 (the "
        "frictionless normal problem the Hertz and first-yield checks validate; for "
        "elastically similar bodies friction does not change it); full, the interface's "
        "[contact] friction from the first touch, as on a rig; auto: full for "
        "elastic-plastic bodies (worn plastic fe3d geometries got through only with it), "
        "low for elastic ones (docs/fe3d.md 'Friction while loading')")
    cache: str | None = Field(None, description="folder of finished ccx jobs keyed by the "
                              "deck's bytes and the ccx build: a deck found there is not run "
                              "again (the chapter 6 study shares one across its stages)")
    max_wear_slope: float | None = Field(
        CONVERGED_SLOPE, description="fe3d: the steepest step of the worn depth between "
        "neighbouring node columns / their spacing that the morphed mesh carries; steeper "
        "steps are relaxed volume for volume (contact.fe.slope; the default is the steepest "
        "on which ccx's contact converged, measured; 'off': the criterion's surface as "
        "projected, docs/fe3d.md 'Worn geometry')")

    morph: Literal["tributary", "projection"] = Field(
        "tributary", description="fe3d: how the wear maps become the depths the surface "
        "node columns move by (eqs 3.7-3.8). tributary: each node takes its share of every "
        "wear-map cell's volume (the exact integral of its bilinear shape function over the "
        "cell) over its tributary area, so the mesh loses the maps' volume exactly; "
        "projection: the lumped projection of the interpolated worn surface sampled at dx / 2 "
        "(within ~0.05 %, the morph before it; docs/fe3d.md 'Worn geometry')")
    max_wear_kink: float | None = Field(
        DEFAULT_KINK, description="fe3d: the largest change of slope of the morphed worn "
        "surface at a node column between its neighbours along x or y (dimensionless, the "
        "facets' turn in rad); beyond it the depths are smoothed volume for volume, after "
        "max_wear_slope (contact.fe.slope.limit_kink; 'off': none; the unworn cylinder turns "
        "by h / R = 0.011 per element at h = a/3; docs/fe3d.md 'Worn geometry')")

    @field_validator("max_wear_kink", mode="before")
    @classmethod
    def _kink_or_off(cls, v: Any) -> float | None:
        if v == "off" or v is None:
            return None
        if isinstance(v, bool) or not isinstance(v, int | float) or not 0 < v <= 10:
            raise ValueError("allowed: a number > 0 and <= 10 (a change of slope), or 'off'")
        return float(v)

    @field_serializer("max_wear_kink", when_used="json")
    def _kink_off(self, v: float | None) -> float | str:
        """Recorded as 'off', not None (as ``max_wear_slope``)."""
        return "off" if v is None else v

    @field_validator("max_wear_slope", mode="before")
    @classmethod
    def _slope_or_off(cls, v: Any) -> float | None:
        if v == "off" or v is None:
            return None
        if isinstance(v, bool) or not isinstance(v, int | float) or not 0 < v <= 10:
            raise ValueError("allowed: a number > 0 and <= 10 (a slope), or 'off'")
        return float(v)

    @field_serializer("max_wear_slope", when_used="json")
    def _off(self, v: float | None) -> float | str:
        """Recorded as 'off', not None: a TOML file has no null, and a field left out there
        reloads as the default slope, not as off."""
        return "off" if v is None else v
