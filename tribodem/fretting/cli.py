"""``tribodem fretting run``: the fretting wear loop from a TOML config (issue 5).

Python API: :func:`run_fretting` (config -> files in ``out``, returns the summary).
"""

from __future__ import annotations

import inspect
import math
import time
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
import typer
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    ValidationInfo,
    field_serializer,
    field_validator,
    model_validator,
)

from tribodem import __version__
from tribodem.contact import (
    BACKENDS,
    CAPABILITY_TEXT,
    ElasticBody,
    FEContactSolver,
    FirstBodySolver,
    contact_modulus,
)
from tribodem.contact.fe.backend import PLASTIC_MIN_INCREMENTS
from tribodem.contact.fe.backend3d import CONVERGED_SLOPE
from tribodem.contact.fe.ccx import CcxNotFoundError, CcxTimeoutError, FESolverStopped
from tribodem.contact.geometry import (
    CrossedCylinders,
    CylinderOnFlat,
    FlatPunch,
    Geometry,
    HeightMap,
    HeightMaps,
    SphereOnFlat,
    line_window,
    load_height_map,
)
from tribodem.cyclejump import STRATEGIES, make_strategy
from tribodem.fretting.criteria import (
    ALPHA_SEED,
    ARCHARD_K,
    CRITERIA,
    UTS_EN24T,
    YIELD_EN24T,
    Criterion,
    CriterionUnavailable,
    make_criterion,
)
from tribodem.fretting.debris import DebrisField, DebrisSettings
from tribodem.fretting.loop import GEOMETRY_TOLERANCE, FrettingHistory, FrettingLoop
from tribodem.fretting.output import (
    CHECKPOINT,
    read_checkpoint,
    write_checkpoint,
    write_debris_outputs,
    write_figures,
    write_results,
    write_rows,
    write_vtk_surfaces,
)
from tribodem.io import runs
from tribodem.io.config import (
    ConfigError,
    dump_toml,
    load_toml,
    merge,
    parse_int_list,
    validate,
)
from tribodem.io.results import write_text
from tribodem.materials.en24t import EN24T

CriterionName = Literal["energy", "archard", "s22", "von_mises", "shear", "dfdi", "swt"]
JumpName = Literal["none", "constant", "cojocaru", "moving", "overlapping", "adaptive"]


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid")


GeometryName = Literal["crossed_cylinders", "sphere_on_flat", "cylinder_on_flat", "flat_punch",
                       "height_map"]

#: Each geometry's own ``[contact]`` fields (their defaults: the dataclasses of
#: :mod:`tribodem.contact.geometry`); any other geometry field given is refused.
GEOMETRY_FIELDS: dict[str, tuple[str, ...]] = {
    "crossed_cylinders": ("radius_upper", "radius_lower", "diameter"),
    "sphere_on_flat": ("radius",),
    "cylinder_on_flat": ("radius", "load_per_length"),
    "flat_punch": ("punch_radius", "edge_radius"),
    "height_map": ("upper_map", "lower_map", "map_dx"),
}
_ALL_GEOMETRY_FIELDS = tuple(dict.fromkeys(f for fs in GEOMETRY_FIELDS.values() for f in fs))

#: Default total normal load on the window, N (DESIGN.md default case).
DEFAULT_LOAD = 100.0

#: Window side when ``contact.window`` is left out, in contact radii (or half-widths).
WINDOW_RADII = 10.0


class ContactConfig(_Model):
    """First-body case (DESIGN.md default: crossed 8 mm cylinders, 100 N, +-0.3 mm, mu 0.6).

    ``geometry`` picks the case (docs/fretting.md, "Geometries"); its own fields left out
    take the defaults of :mod:`tribodem.contact.geometry` and are filled in on validation
    (the resolved config shows what ran). A field of another geometry is refused.
    """

    geometry: GeometryName = "crossed_cylinders"
    diameter: float | None = Field(
        None, gt=0, description="crossed_cylinders: both cylinders' diameter, m (shorthand for "
        "radius_upper = radius_lower = diameter / 2; a radius given wins)")
    radius_upper: float | None = Field(None, gt=0, description="crossed_cylinders: upper "
                                       "cylinder's radius (axis along y), m")
    radius_lower: float | None = Field(None, gt=0, description="crossed_cylinders: lower "
                                       "cylinder's radius (axis along x), m")
    radius: float | None = Field(None, gt=0, description="sphere_on_flat / cylinder_on_flat: "
                                 "radius of the upper body, m")
    punch_radius: float | None = Field(None, gt=0, description="flat_punch: radius of the "
                                       "flat face, m")
    edge_radius: float | None = Field(None, gt=0, description="flat_punch: edge radius, m")
    upper_map: str | None = Field(None, description="height_map: upper body's surface "
                                  "heights (.csv, .npy with map_dx; .stl)")
    lower_map: str | None = Field(None, description="height_map: lower body's surface "
                                  "heights (must cover the window plus the stroke along x)")
    map_dx: float | None = Field(None, gt=0, description="height_map: grid spacing of CSV/NPY "
                                 "maps (STL: sampling step, default its vertex spacing), m")
    load: float | None = Field(None, gt=0, description="total normal load on the window, N "
                               "(default 100 N; line contact: or load_per_length)")
    load_per_length: float | None = Field(
        None, gt=0, description="cylinder_on_flat: normal load per unit length of the "
        "cylinder, N/m (instead of the total load over the window)")
    friction: float = Field(0.6, ge=0, description="friction coefficient")
    amplitude: float = Field(0.3e-3, gt=0, description="displacement amplitude, m")
    n_increments: int = Field(48, ge=4, description="increments per cycle (multiple of 4)")
    regime: Literal["gross", "ciavarella-jaeger"] = "gross"
    n: int = Field(256, ge=16, le=2048, description="window points per side (even)")
    window: float | None = Field(None, gt=0, description="window side, m (None: 10 radii)")
    tolerance: float = Field(1e-6, gt=0, lt=1, description="normal solver (PKR) tolerance")
    young: float = Field(EN24T.young, gt=0, description="Young's modulus (both bodies unless "
                         "young_upper / young_lower), Pa")
    poisson: float = Field(EN24T.poisson, gt=-1, lt=0.5, description="Poisson's ratio (both "
                           "bodies unless poisson_upper / poisson_lower)")
    young_upper: float | None = Field(None, gt=0, description="upper body's Young's modulus, Pa")
    poisson_upper: float | None = Field(None, gt=-1, lt=0.5, description="upper body's "
                                        "Poisson's ratio")
    young_lower: float | None = Field(None, gt=0, description="lower body's Young's modulus, Pa")
    poisson_lower: float | None = Field(None, gt=-1, lt=0.5, description="lower body's "
                                        "Poisson's ratio")

    @field_validator(*_ALL_GEOMETRY_FIELDS)
    @classmethod
    def _of_geometry(cls, v: Any, info: ValidationInfo) -> Any:
        geo = info.data.get("geometry")
        name = info.field_name or ""
        if v is None or geo is None or name in GEOMETRY_FIELDS[geo]:
            return v
        owners = [g for g, fs in GEOMETRY_FIELDS.items() if name in fs]
        raise ValueError(
            f"Extra inputs are not permitted with geometry = {geo!r}: {name} belongs to "
            f"geometry = {' or '.join(repr(g) for g in owners)}; allowed for {geo!r}: "
            f"{', '.join(GEOMETRY_FIELDS[geo])}")

    @field_validator("load_per_length")
    @classmethod
    def _one_load(cls, v: float | None, info: ValidationInfo) -> float | None:
        if v is not None and info.data.get("load") is not None:
            raise ValueError(f"give load (total over the window, N; here "
                             f"{info.data['load']!r}) or load_per_length (N/m), not both")
        return v

    @field_validator("upper_map", "lower_map")
    @classmethod
    def _absolute(cls, v: str | None) -> str | None:
        return None if v is None else str(Path(v).expanduser().absolute())

    @model_validator(mode="after")
    def _fill_geometry(self) -> ContactConfig:
        """Fill the geometry's own fields with their defaults (one definition each, in
        :mod:`tribodem.contact.geometry`) and the load (100 N unless load_per_length)."""
        if self.load is None and self.load_per_length is None:
            self.load = DEFAULT_LOAD
        geo = self.geometry
        if geo == "crossed_cylinders":
            d = CrossedCylinders()
            half = None if self.diameter is None else self.diameter / 2
            if self.radius_upper is None:
                self.radius_upper = half if half is not None else d.radius_upper
            if self.radius_lower is None:
                self.radius_lower = half if half is not None else d.radius_lower
        elif geo in ("sphere_on_flat", "cylinder_on_flat") and self.radius is None:
            self.radius = (SphereOnFlat() if geo == "sphere_on_flat" else CylinderOnFlat()).radius
        elif geo == "flat_punch":
            fp = FlatPunch()
            if self.punch_radius is None:
                self.punch_radius = fp.punch_radius
            if self.edge_radius is None:
                self.edge_radius = fp.edge_radius
        elif geo == "height_map" and self.upper_map is None and self.lower_map is None:
            raise ValueError("geometry = 'height_map' needs upper_map or lower_map (a file "
                             "of surface heights, m), or both")
        return self

    @field_validator("n_increments")
    @classmethod
    def _mult4(cls, v: int) -> int:
        if v % 4:
            raise ValueError("must be a multiple of 4")
        return v

    @field_validator("n")
    @classmethod
    def _even(cls, v: int) -> int:
        if v % 2:
            raise ValueError("must be even")
        return v


class WearConfig(_Model):
    """Criterion and its parameters (SI)."""

    criterion: CriterionName = "energy"
    alpha: float = Field(ALPHA_SEED, ge=0, description="energy wear coefficient, m^3/J")
    energy_share_upper: float = Field(
        0.5, ge=0, le=1, description="energy: upper body's share of eq 2.7's total volume")
    archard_k_upper: float = Field(ARCHARD_K, ge=0, description="Archard k, upper body, 1/Pa")
    archard_k_lower: float = Field(ARCHARD_K, ge=0, description="Archard k, lower body, 1/Pa")
    yield_strength: float = Field(YIELD_EN24T, gt=0, description="Pa (s22, von_mises)")
    uts: float = Field(UTS_EN24T, gt=0, description="Pa (shear: S_us = 0.8 UTS)")
    stress_depth: float | None = Field(None, gt=0, description="subsurface grid depth, m")
    stress_nz: int = Field(33, ge=2, le=257, description="subsurface grid levels")
    stress_samples: int = Field(8, ge=1, description="sampled increments per cycle")
    eps0: float = Field(EN24T.dfdi_eps0, gt=0, description="dfdi: uniaxial failure strain "
                        "eps0 (eq 6.2; default the seed's script's, appendix IV)")
    dfdi_triaxiality: Literal["local", "seed-script"] = Field(
        "local", description="dfdi: eq 6.2's sigma_m / sigma_eq per point (local), or as the "
        "seed's script computes it (ranges over the cycle, sigma_eq summed over all nodes: "
        "the exponent ~0, eps_f = 1.65 eps0)")
    swt_nz: int = Field(17, ge=2, le=129, description="swt: subsurface levels")
    swt_plane_step: float = Field(5.0, gt=0, le=90, description="swt: candidate planes, deg")


class PlasticConfig(_Model):
    """The plastic law of ``solver = "elastic-plastic"`` (tamaas EPIC; its ``ep_*`` grid) and
    of the ccx backends' ``[fe] material = "elastic-plastic"``: bilinear EN24T (seed table
    5.1), one law for every backend."""

    yield_strength: float = Field(EN24T.yield_strength, gt=0, description="initial yield, Pa")
    uts: float = Field(EN24T.uts, gt=0, description="ultimate tensile strength, Pa")
    uts_strain: float = Field(EN24T.uts_strain, gt=0, lt=1,
                              description="engineering strain at UTS")
    hardening: float | None = Field(None, ge=0, description="h, Pa (None: bilinear)")
    beyond_uts: Literal["line", "hold"] = Field(
        "line", description="past the UTS: line, the hardening line goes on (seed fig. 5.5; "
        "tamaas's law, the only one it has); hold, the flow stress stays at the UTS (fe, "
        "fe3d; their law before config_version 3)")
    ep_n: int = Field(32, ge=8, le=256, description="EP grid points per side (even)")
    ep_nz: int = Field(12, ge=3, le=64, description="EP grid layers")
    ep_window_radii: float = Field(5.0, gt=0, description="EP window, Hertz radii")
    ep_depth_radii: float = Field(2.0, gt=0, description="EP depth, Hertz radii")
    load_steps: int = Field(4, ge=1, le=100, description="first-loading steps")
    ep_tolerance: float = Field(1e-6, gt=0, lt=0.1, description="EPIC tolerance")


class JumpConfig(_Model):
    """Cycle-jumping: a strategy of seed 003 chapter 4 and its parameters, capped by the
    loop's geometry control (docs/fretting.md, "Jumping")."""

    strategy: JumpName = "none"
    params: dict[str, Any] = Field(default_factory=dict)
    geometry_tolerance: float = Field(
        GEOMETRY_TOLERANCE, ge=0, description="largest jumped depth increment / the "
        "contact's elastic approach (0: the strategy alone)")


class DebrisConfig(_Model):
    """The debris third body (seed 003 3.2.6-3.2.7); off unless ``every`` is set."""

    every: int | None = Field(None, ge=1, description="DE phase every K cycles (None: off)")
    diameter: float = Field(0.6e-6, gt=0, description="debris diameter d of eq 3.10, m")
    shares: tuple[float, float, float] = Field(
        (1 / 3, 1 / 3, 1 / 3), description="spherical, chunk, rubbing fractions")
    volume_correction: float = Field(1.0, gt=0, le=2, description="seed's 0.77 (optional)")
    cor: float = Field(0.72, gt=0, le=1)
    friction: float = Field(0.6, ge=0)
    rolling_friction: float = Field(0.001, ge=0)
    density_scaling: float = Field(1.0, ge=1, description="DE-phase mass scaling")
    tolerance: float = Field(1e-4, gt=0, lt=0.1, description="servo relative load error")
    max_steps: int = Field(200_000, ge=100, description="DE steps per phase at most")
    ramp_steps: int = Field(10_000, ge=0, description="servo target ramp, steps")
    target_cap: float = Field(0.9, gt=0, lt=1, description="debris load <= cap x load")
    seed: int = 0


class OutputConfig(_Model):
    """What is written besides results.csv / summary.json / config.toml (which always are)."""

    figures: bool = True
    vtk: bool = True
    checkpoint_every: int = Field(
        1, ge=1, description="checkpoint.npz and results.csv rewritten every K simulated "
        "cycles (and at the end)")


class FEConfig(_Model):
    """``solver = "fe"``: the CalculiX plane-strain backend (docs/fe.md)."""

    mode: Literal["fresh", "chained", "primed"] = Field(
        "fresh", description="fresh: one ccx job per cycle on the worn geometry, virgin "
        "material (seed 003 section 3.3); chained (fe): cycles continue in one job while the "
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


#: Layout version of the fretting config, recorded as ``config_version`` in every config
#: tribodem writes (config.toml, summary.json, checkpoint.npz, study.toml). 2: ``[fe]
#: h_over_a`` / ``size_factor`` left out are the backend's own (:data:`FE_BACKEND_OWN`); a
#: recorded config without it is older. 3: ``[plastic] beyond_uts`` (default "line": the
#: ccx backends held the flow stress at the UTS before). :func:`recorded_config` migrates an
#: older record, and a config file that names an older version (a run's config.toml given
#: back with --config) is read the same way (:func:`resolve_config`). 4: ``[fe]
#: loading_friction`` (default "auto": elastic-plastic bodies seated and loaded with the
#: interface's mu; the ccx backends seated and loaded with 0.001 before).
CONFIG_VERSION = 4


class FrettingConfig(_Model):
    """``tribodem fretting run`` configuration (TOML tables contact, wear, jump, output)."""

    cycles: int = Field(160, ge=1, le=10**7)
    solver: str = Field("elastic", description="first-body backend (tribodem.contact.BACKENDS)")
    config_version: int = Field(
        CONFIG_VERSION, ge=CONFIG_VERSION, le=CONFIG_VERSION, description="the config "
        "layout, written by tribodem into the configs it records; leave it out of your own "
        "files (they are read as this version)")
    contact: ContactConfig = Field(default_factory=ContactConfig)
    wear: WearConfig = Field(default_factory=WearConfig)
    jump: JumpConfig = Field(default_factory=JumpConfig)
    plastic: PlasticConfig = Field(default_factory=PlasticConfig)
    fe: FEConfig = Field(default_factory=FEConfig)
    debris: DebrisConfig = Field(default_factory=DebrisConfig)
    output: OutputConfig = Field(default_factory=OutputConfig)

    @field_validator("solver")
    @classmethod
    def _known_backend(cls, v: str) -> str:
        if v not in BACKENDS:
            raise ValueError(f"not a first-body backend; allowed: {', '.join(BACKENDS)}")
        return v


QUICK: dict[str, Any] = {"cycles": 10, "contact": {"n": 64}, "wear": {"stress_nz": 17},
                         "debris": {"ramp_steps": 4000}}
#: ``--quick`` on top of :data:`QUICK` per backend: fe3d's seed-size job is minutes a cycle,
#: so a plumbing-grade mesh (h = a, bodies 10 a: 800 elements), 8 increments a cycle and 2
#: cycles (the second on the morphed surfaces): ~30 s (docs/fe3d.md); ccx takes at most 1/16
#: of a quarter per increment (``cycle_increments`` 64: 0.14 h of slide; at 1/2, nodes crossed
#: elements and 140 of 443 Newton iterations a cycle were in failed attempts, now 16 of 299)
QUICK_SOLVER: dict[str, dict[str, Any]] = {
    "fe3d": {"cycles": 2, "contact": {"n_increments": 8},
             "fe": {"h_over_a": 1.0, "size_factor": 10.0, "cycle_increments": 64}}}


def build_criterion(cfg: FrettingConfig) -> Criterion:
    """The configured criterion; ``ConfigError`` when it cannot run."""
    w = cfg.wear
    name = w.criterion
    up, lo = materials(cfg)
    if name == "swt" and up != lo:
        raise ConfigError(
            f"wear.criterion = 'swt' takes one material for both bodies, but the upper body is "
            f"(young {up.young:g} Pa, poisson {up.poisson:g}) and the lower one (young "
            f"{lo.young:g} Pa, poisson {lo.poisson:g}); allowed: equal materials (young/"
            "poisson only) or another criterion")
    stress = {"depth": w.stress_depth, "nz": w.stress_nz, "samples": w.stress_samples}
    params: dict[str, Any] = {
        "energy": {"alpha": w.alpha, "share_upper": w.energy_share_upper},
        "archard": {"k_upper": w.archard_k_upper, "k_lower": w.archard_k_lower},
        "s22": {"yield_strength": w.yield_strength, **stress},
        "von_mises": {"yield_strength": w.yield_strength, **stress},
        "shear": {"uts": w.uts, **stress},
        "dfdi": {"eps0": w.eps0, "depth": w.stress_depth, "triaxiality": w.dfdi_triaxiality},
        "swt": {"nz": w.swt_nz, "depth": w.stress_depth, "samples": w.stress_samples,
                "plane_step": w.swt_plane_step, "young": lo.young, "poisson": lo.poisson},
    }.get(name, {})
    try:
        return make_criterion(name, **params)
    except CriterionUnavailable as err:
        raise ConfigError(f"wear.criterion = {name!r}: {err}") from None
    except ValueError as err:
        raise ConfigError(f"wear: {err}") from None


#: Smallest ``contact.window`` allowed, in Hertz contact radii of the unworn bodies.
MIN_WINDOW_RADII = 4.0


def materials(cfg: FrettingConfig) -> tuple[ElasticBody, ElasticBody]:
    """(upper, lower) bodies: ``young_upper``/``poisson_upper`` etc., else ``young``/
    ``poisson`` for both (Pa, -)."""
    c = cfg.contact

    def pick(v: float | None, both: float) -> float:
        return both if v is None else v

    try:
        return (ElasticBody(pick(c.young_upper, c.young), pick(c.poisson_upper, c.poisson)),
                ElasticBody(pick(c.young_lower, c.young), pick(c.poisson_lower, c.poisson)))
    except ValueError as err:
        raise ConfigError(f"contact: {err}") from None


def case_modulus(cfg: FrettingConfig) -> float:
    """Contact modulus E* of the two bodies, Pa."""
    return contact_modulus(*materials(cfg))


def case_geometry(cfg: FrettingConfig) -> Geometry:
    """The ``[contact]`` geometry as a :mod:`tribodem.contact.geometry` dataclass; height
    maps are read here (``ConfigError`` naming the field and the file when unusable)."""
    c = cfg.contact
    try:
        if c.geometry == "crossed_cylinders":
            assert c.radius_upper is not None and c.radius_lower is not None
            return CrossedCylinders(c.radius_upper, c.radius_lower)
        if c.geometry == "sphere_on_flat":
            assert c.radius is not None
            return SphereOnFlat(c.radius)
        if c.geometry == "cylinder_on_flat":
            assert c.radius is not None
            return CylinderOnFlat(c.radius)
        if c.geometry == "flat_punch":
            assert c.punch_radius is not None and c.edge_radius is not None
            return FlatPunch(c.punch_radius, c.edge_radius)
    except ValueError as err:
        raise ConfigError(f"contact: {err}") from None
    maps: dict[str, HeightMap | None] = {"upper": None, "lower": None}
    for body in maps:
        path = getattr(c, f"{body}_map")
        if path is None:
            continue
        try:
            maps[body] = load_height_map(path, body, c.map_dx)
        except ValueError as err:
            raise ConfigError(f"contact.{body}_map = {path!r}: {err}") from None
    return HeightMaps(maps["upper"], maps["lower"])


def _map_limits(geo: HeightMaps, n: int, amplitude: float, window: float
                ) -> list[tuple[str, str, float, float]]:
    """(field, axis, needed half-extent, available half-extent) of each map (m) for a
    window ``window``: the upper map covers the window, the lower one the window plus the
    stroke along x (the track grid)."""
    dx = window / n
    pad = math.ceil(amplitude / dx) + 1
    out = []
    for name, hm, px in (("upper_map", geo.upper, 0), ("lower_map", geo.lower, pad)):
        if hm is None:
            continue
        x0, x1, y0, y1 = hm.extent
        out.append((name, "x", (n // 2 + px) * dx, min(-x0, x1)))
        out.append((name, "y", (n // 2) * dx, min(-y0, y1)))
    return out


def map_window(cfg: FrettingConfig, geo: HeightMaps) -> float:
    """The largest window (m) the height maps cover (upper: the window; lower: the window
    plus the stroke), for ``geometry = "height_map"`` without ``contact.window``."""
    c = cfg.contact
    w = min(2 * have for *_, have in _map_limits(geo, c.n, c.amplitude, 1.0)) or 1.0
    for _ in range(200):
        if all(need <= have * (1 + 1e-9) for *_, need, have in
               _map_limits(geo, c.n, c.amplitude, w)):
            return w
        w *= 0.99
    raise ConfigError(f"contact.lower_map = {c.lower_map!r}: the map is too short along x for "
                      f"the stroke (amplitude {c.amplitude:g} m) plus a window")


def case_window(cfg: FrettingConfig, geo: Geometry | None = None) -> float | None:
    """The window side (m) the solver gets: ``contact.window``, else ``WINDOW_RADII`` contact
    radii (line contact: half-widths; None = the solver's own estimate of the Hertz radius
    from the surfaces' curvature, for crossed cylinders of equal radii and the sphere; height
    maps: the largest window the maps cover)."""
    c = cfg.contact
    if c.window is not None:
        return c.window
    geo = case_geometry(cfg) if geo is None else geo
    es = case_modulus(cfg)
    if isinstance(geo, SphereOnFlat) or (isinstance(geo, CrossedCylinders)
                                         and geo.radius_upper == geo.radius_lower):
        return None
    if isinstance(geo, CylinderOnFlat):
        if c.load_per_length is not None:
            return WINDOW_RADII * geo.hertz(c.load_per_length, es).half_width
        assert c.load is not None
        return line_window(geo.radius, c.load, es, WINDOW_RADII)
    if isinstance(geo, HeightMaps):
        return map_window(cfg, geo)
    return WINDOW_RADII * max(geo.contact_size(total_load(cfg, None), es))


def total_load(cfg: FrettingConfig, window: float | None) -> float:
    """Total normal load on the window, N: ``load``, or ``load_per_length`` x window."""
    c = cfg.contact
    if c.load_per_length is not None:
        assert window is not None
        return c.load_per_length * window
    assert c.load is not None
    return c.load


def contact_half_size(cfg: FrettingConfig, geo: Geometry | None = None,
                      window: float | None = None) -> tuple[str, float] | None:
    """(description, largest contact half-size along a checked direction, m) of the unworn
    analytic geometry (None for height maps): Hertz radius (the larger semi-axis for
    crossed cylinders of unequal radii), the line contact's half-width along x (P' =
    load / window or load_per_length), the rounded punch's contact radius."""
    c = cfg.contact
    geo = case_geometry(cfg) if geo is None else geo
    es = case_modulus(cfg)
    if isinstance(geo, HeightMaps):
        return None
    if isinstance(geo, CylinderOnFlat):
        pl = c.load_per_length
        if pl is None:
            assert c.load is not None and window is not None
            pl = c.load / window
        return (f"the Hertz line contact of the cylinder (R {geo.radius:g} m, P' {pl:.4g} N/m, "
                f"E* {es:.4g} Pa) has half-width a", geo.hertz(pl, es).half_width)
    load = total_load(cfg, window)
    what = {"crossed_cylinders": "the Hertz contact of the crossed cylinders (R "
                                 f"{getattr(geo, 'radius_upper', 0):g} and "
                                 f"{getattr(geo, 'radius_lower', 0):g} m",
            "sphere_on_flat": f"the Hertz contact of the sphere (R {getattr(geo, 'radius', 0):g} m",
            "flat_punch": "the contact of the rounded flat punch (punch radius "
                          f"{getattr(geo, 'punch_radius', 0):g} m, edge radius "
                          f"{getattr(geo, 'edge_radius', 0):g} m"}[geo.name]
    return f"{what}, load {load:g} N, E* {es:.4g} Pa) has radius a", max(
        geo.contact_size(load, es))


def hertz_radius(cfg: FrettingConfig) -> float:
    """Contact radius (m) of the unworn analytic geometry (line contact: half-width; 0 for
    height maps): for the default crossed cylinders a = (3 P R / (4 E*))^(1/3)."""
    hs = contact_half_size(cfg, window=case_window(cfg))
    return 0.0 if hs is None else hs[1]


def check_window(cfg: FrettingConfig, geo: Geometry | None = None) -> None:
    """Refuse (``ConfigError``) a ``contact.window`` that cannot hold the contact.

    The window travels with the upper body and the contact stays at its centre through the
    stroke (the lower track grid covers the stroke separately), so the window must hold the
    contact, width 2 a, with a margin of a on each side for the periodic images and the
    contact's growth with wear: window >= 4 a, along every direction in which the contact
    can reach an edge (a line contact, periodic along y by design: x only). Height maps:
    the maps must cover the window (and the lower one the stroke); the contact itself is
    checked by a solve (:func:`check_solved_window`).
    """
    c = cfg.contact
    geo = case_geometry(cfg) if geo is None else geo
    if isinstance(geo, HeightMaps):
        w = case_window(cfg, geo)
        assert w is not None
        for field, axis, need, have in _map_limits(geo, c.n, c.amplitude, w):
            if need > have * (1 + 1e-9):
                raise ConfigError(
                    f"contact.{field} = {getattr(c, field)!r}: the map spans +-{have:.4g} m "
                    f"along {axis} about its centre but the window ({w:.4g} m"
                    f"{'' if c.window is not None else ', contact.window left out'}"
                    f"{', plus the stroke' if field == 'lower_map' and axis == 'x' else ''}"
                    f") needs +-{need:.4g} m; allowed: a larger map or a smaller "
                    "contact.window")
        return
    if c.window is None:
        return
    hs = contact_half_size(cfg, geo, c.window)
    assert hs is not None
    what, a = hs
    low = MIN_WINDOW_RADII * a
    if c.window < low:
        along = " along x (a line contact is periodic along y)" if geo.contact == "line" else ""
        raise ConfigError(
            f"contact.window = {c.window!r} m cannot hold the contact: {what} = {a:.4g} m; "
            f"allowed: >= {low:.4g} m ({MIN_WINDOW_RADII:g} a{along}; the window travels with "
            f"the upper body, so the stroke does not enter), or leave it out for "
            f"{WINDOW_RADII:g} a")


def check_solved_window(cfg: FrettingConfig, solver: FirstBodySolver) -> None:
    """For height maps (no analytic contact size): solve the loaded contact at offset 0 and
    refuse (``ConfigError`` naming ``contact.window``) a contact on the window's edge along
    a checked direction (solvers without a separate loaded solution: skipped)."""
    c = cfg.contact
    xw, yw = np.meshgrid(solver.coords, solver.coords, indexing="ij")
    gap = np.asarray(solver.upper(xw, yw) + solver.lower(xw, yw), dtype=float)
    if float(np.ptp(gap)) <= 0.0:
        given = ", ".join(f"contact.{k} = {getattr(c, k)!r}" for k in ("upper_map", "lower_map")
                          if getattr(c, k) is not None)
        raise ConfigError(
            f"{given}: the surfaces are flat on the window ({solver.window:.4g} m): the "
            "contact would fill the window (contact.window cannot hold it); allowed: maps "
            "with a contact spot (curved or rough surfaces)")
    try:
        p, _ = solver.loaded_solution(0.0)
    except NotImplementedError:
        return
    contact = solver.contact
    edge = max(p[0].max(), p[-1].max())
    if contact == "point":
        edge = max(edge, p[:, 0].max(), p[:, -1].max())
    if edge > 0.0:
        raise ConfigError(
            f"contact.window = {c.window!r} (window {solver.window:.4g} m) cannot hold the "
            f"contact of the height maps: the loaded contact ({int((p > 0).sum())} of "
            f"{p.size} points) reaches the window edge{' along x' if contact == 'line' else ''};"
            " allowed: a larger contact.window (and maps covering it) or a smaller load")


def jump_reading(loop: FrettingLoop) -> dict[str, Any]:
    """The run's jump decisions (``FrettingLoop.jump_decisions``) and one sentence on what
    limited the jumps, for summary.json's ``jump``."""
    d = loop.jump_decisions()
    tol, last = d["geometry_tolerance"], d["last"]
    if not d["decisions"]:
        text = "no jump decision yet (no simulated cycle was shown to the strategy)"
    elif tol is None:
        text = ("geometry control off (jump.geometry_tolerance = 0): every jump as the "
                f"strategy proposed it; {d['cycles_jumped']} cycles jumped")
    else:
        text = (f"the strategy proposed no jump in {d['decisions']} decisions"
                if not d["proposed"] else
                f"the strategy proposed a jump in {d['proposed']} of {d['decisions']} "
                f"decisions; the geometry (jump.geometry_tolerance = {tol:g}: a jump adds "
                f"at most {tol:.0%} of the contact's elastic approach to the depth anywhere)"
                f" cut {d['capped_by_geometry']} of them; {d['cycles_jumped']} cycles were "
                "jumped")
        if last["geometry_limit"] is not None and last["increment_over_approach"]:
            text += (f"; at the last decision the last cycle's largest depth increment, "
                     f"{last['depth_increment_m'] * 1e6:.3g} um, was "
                     f"{last['increment_over_approach']:.3g} elastic approaches "
                     f"({last['elastic_approach_m'] * 1e6:.3g} um), so the geometry allowed "
                     f"{last['geometry_limit']} cycles")
    return {"decisions": d, "reading": text}


def case_summary(cfg: FrettingConfig, solver: FirstBodySolver) -> dict[str, Any]:
    """What ran: geometry and its parameters, contact type, load (and which was given),
    window, the two bodies and E* (SI)."""
    c = cfg.contact
    up, lo = materials(cfg)
    contact = solver.contact
    out: dict[str, Any] = {
        "geometry": c.geometry, "contact": contact,
        "parameters": {k: getattr(c, k) for k in GEOMETRY_FIELDS[c.geometry]
                       if getattr(c, k) is not None},
        "load_given": "load_per_length" if c.load_per_length is not None else "load",
        "load_total_N": solver.load, "window_m": solver.window,
        "upper": {"young_Pa": up.young, "poisson": up.poisson},
        "lower": {"young_Pa": lo.young, "poisson": lo.poisson},
        "modulus_Pa": solver.modulus,
    }
    if contact == "line":
        out["load_per_length_N_per_m"] = solver.load / solver.window
    return out


def check_jump_params(strategy: str, params: dict[str, Any]) -> None:
    """Refuse (``ConfigError``) ``jump.params`` keys the strategy does not take, naming the
    key and the strategy's parameters."""
    if strategy == "none" or strategy not in STRATEGIES:
        return
    sig = inspect.signature(STRATEGIES[strategy])
    allowed = [k for k, p in sig.parameters.items()
               if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)]
    for key, value in params.items():
        if key not in allowed:
            raise ConfigError(
                f"jump.params.{key} = {value!r}: not a parameter of strategy '{strategy}'; "
                f"allowed: {', '.join(allowed)}")


def check_compatible(cfg: FrettingConfig) -> None:
    """Refuse, before any work, a criterion (or the debris third body) that needs what the
    chosen first-body backend cannot give, naming both and the backends that would do."""
    backend = BACKENDS[cfg.solver]
    have = backend.capabilities_for(cfg.fe.model_dump()).names()
    crit = CRITERIA[cfg.wear.criterion]
    needs = [(f"wear.criterion = {cfg.wear.criterion!r}", crit.requires)]
    if cfg.contact.geometry == "cylinder_on_flat":
        needs.append(("contact.geometry = 'cylinder_on_flat' (a line contact)",
                      frozenset({"line_contact"})))
        if cfg.debris.every is not None:
            raise ConfigError(
                f"debris.every = {cfg.debris.every!r}: the debris third body is not available "
                "for contact.geometry = 'cylinder_on_flat' (a line contact); allowed: leave "
                "debris.every out (or --no-debris)")
    elif cfg.contact.geometry != "height_map":
        needs.append((f"contact.geometry = {cfg.contact.geometry!r} (a point contact)",
                      frozenset({"point_contact"})))
    if cfg.cycles > 1 and crit.requires_over_cycles:
        needs.append((f"wear.criterion = {cfg.wear.criterion!r} over cycles = {cfg.cycles} "
                      "(allowed with this solver: cycles = 1)", crit.requires_over_cycles))
    if cfg.debris.every is not None:
        needs.append(("debris.every (the debris third body)", frozenset({"debris"})))
    for who, req in needs:
        missing = set(req) - have
        if missing:
            ok = [k for k, b in BACKENDS.items() if set(req) <= b.capabilities.names()
                  and k != cfg.solver]
            opts = backend.options_for(set(missing))
            allowed = [f"solver = {k!r}" for k in ok]
            if opts and set(req) <= backend.capabilities.names():
                allowed.insert(0, f"solver = {cfg.solver!r} with {opts}")
            raise ConfigError(
                f"{who} needs {', '.join(CAPABILITY_TEXT.get(m, m) for m in sorted(missing))}, "
                f"which solver = {cfg.solver!r} "
                f"({backend.__name__}) does not give as configured; allowed: "
                f"{' or '.join(allowed) or '(no solver registered)'}")


#: ``[fe]`` fields whose None (left out) is the backend's own default, which differs
#: between fe and fe3d: not passed on
FE_BACKEND_OWN = ("h_over_a", "size_factor", "timeout")


def ccx_backends() -> tuple[type, ...]:
    """The first-body backends that run CalculiX and take the ``[fe]`` table."""
    return (FEContactSolver, BACKENDS["fe3d"])


def build_solver(cfg: FrettingConfig) -> FirstBodySolver:
    """The configured first-body backend (:data:`tribodem.contact.BACKENDS`) on the case."""
    c = cfg.contact
    up, lo = materials(cfg)
    backend = BACKENDS[cfg.solver]
    geo = case_geometry(cfg)
    upper, lower = geo.recessions()
    window = case_window(cfg, geo)
    if c.load_per_length is not None and window is None:
        raise ConfigError("contact.load_per_length needs a window (m)")
    kw: dict[str, Any] = dict(
        load=total_load(cfg, window), friction=c.friction, upper_material=up,
        lower_material=lo, n=c.n, window=window, regime=c.regime, tolerance=c.tolerance)
    if backend.capabilities.plastic:
        kw |= cfg.plastic.model_dump()
        if cfg.plastic.beyond_uts != "line" and backend not in ccx_backends():
            raise ConfigError(
                f"plastic.beyond_uts = {cfg.plastic.beyond_uts!r}: solver = {cfg.solver!r} "
                "has linear hardening only (it goes on past the UTS); allowed: 'line', or "
                "solver = 'fe' or 'fe3d' with [fe] material = 'elastic-plastic'")
    if "line" in backend.capabilities.contacts and not isinstance(geo, HeightMaps):
        kw["contact"] = geo.contact
    if backend in ccx_backends():
        fe = {k: v for k, v in cfg.fe.model_dump().items()
              if v is not None or k not in FE_BACKEND_OWN}
        fe["threads"] = runs.check_threads(fe["threads"], "fe.threads (--threads)")
        takes = inspect.signature(backend).parameters
        for k in [k for k in fe if k not in takes]:  # an [fe] field this backend lacks
            if fe[k] != type(cfg.fe).model_fields[k].default:
                has = [name for name in ("fe", "fe3d")
                       if k in inspect.signature(BACKENDS[name]).parameters]
                raise ConfigError(f"fe.{k} = {fe[k]!r}: solver = {cfg.solver!r} does not "
                                  f"take it; allowed: leave fe.{k} out (solver = "
                                  f"{' or '.join(repr(n) for n in has)} has it)")
            del fe[k]
        kw |= fe | {"amplitude": c.amplitude, "n_increments": c.n_increments,
                    "stress_depth": cfg.wear.stress_depth}
    try:
        return backend(upper, lower, **kw)
    except CcxNotFoundError as err:
        raise ConfigError(f"solver = {cfg.solver!r}: {err}; allowed: another solver "
                          f"({', '.join(k for k in BACKENDS if k != cfg.solver)})") from None
    except ValueError as err:
        raise ConfigError(f"contact: {err}") from None


def debris_settings(cfg: FrettingConfig) -> DebrisSettings:
    """The debris particles of the ``[debris]`` table (``ConfigError`` if unusable); they take
    the lower body's (the track's) material."""
    lo = materials(cfg)[1]
    try:
        return DebrisSettings(young=lo.young, poisson=lo.poisson,
                              **cfg.debris.model_dump(exclude={"every"}))
    except ValueError as err:
        raise ConfigError(str(err)) from None


def build_loop(cfg: FrettingConfig) -> FrettingLoop:
    """Solver + criterion + strategy from a validated config (``ConfigError`` if unusable)."""
    check_compatible(cfg)
    check_window(cfg)
    crit = build_criterion(cfg)
    c = cfg.contact
    solver = build_solver(cfg)
    if c.geometry == "height_map":
        check_solved_window(cfg, solver)
    strategy = None
    if cfg.jump.strategy != "none":
        check_jump_params(cfg.jump.strategy, cfg.jump.params)
        try:
            params = dict(cfg.jump.params)
            if cfg.jump.strategy == "adaptive":  # decide on the worn volume (docs/fretting.md)
                params.setdefault("decide_on", "total")
            strategy = make_strategy(cfg.jump.strategy, **params)
        except (TypeError, ValueError) as err:
            raise ConfigError(f"jump.params for '{cfg.jump.strategy}': {err}") from None
    debris = DebrisField(debris_settings(cfg)) if cfg.debris.every is not None else None
    try:
        return FrettingLoop(solver, crit, amplitude=c.amplitude, n_increments=c.n_increments,
                            strategy=strategy, debris=debris,
                            debris_every=cfg.debris.every or 1,
                            geometry_tolerance=cfg.jump.geometry_tolerance or None)
    except ValueError as err:  # CriterionUnavailable included
        raise ConfigError(f"wear: {err}") from None


def resolve_config(config: Path | None, quick: bool = False,
                   overrides: dict[str, Any] | None = None,
                   base: dict[str, Any] | None = None) -> FrettingConfig:
    """Defaults <- config file <- ``--quick`` preset <- command-line overrides.

    ``base``: the resolved config of a checkpoint, used in place of a config file (a resumed
    run without ``--config``).
    """
    if config is not None:
        data: dict[str, Any] = load_toml(config)
        source = str(config)
        contact = data.get("contact")
        if isinstance(contact, dict):  # height maps: relative to the config file
            for key in ("upper_map", "lower_map"):
                v = contact.get(key)
                if isinstance(v, str) and not Path(v).expanduser().is_absolute():
                    contact[key] = str(Path(config).parent / v)
        if data.get("config_version", CONFIG_VERSION) != CONFIG_VERSION:
            data = recorded_config(data)  # a run's record given back: what it ran
    else:
        data, source = dict(base or {}), "command line"
    if quick:
        solver = (overrides or {}).get("solver", data.get("solver"))
        preset = merge(QUICK, QUICK_SOLVER.get(str(solver), {}))
        data = merge(preset, data) if config is None and base is None else merge(data, preset)
    data = merge(data, overrides or {})
    return validate(FrettingConfig, data, source=source)


def _flat(d: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    out: dict[str, Any] = {}
    for k, v in d.items():
        if isinstance(v, dict):
            out |= _flat(v, f"{prefix}{k}.")
        else:
            out[f"{prefix}{k}"] = v
    return out


def _jsonable(cfg: FrettingConfig) -> dict[str, Any]:
    """``cfg`` as JSON-able nested dicts, as it is recorded (config.toml, summary.json, the
    checkpoint, study.toml): every field, the fields' JSON forms ('off' for no slope
    limit)."""
    return cfg.model_dump(mode="json")


#: ``[fe]`` defaults that tribodem recorded in every config before ``config_version`` 2 (it
#: dumped every field): there they meant "left out", and fe3d ran its own mesh on them
FE_DEFAULTS_BEFORE_V2: dict[str, float] = {"h_over_a": 0.25, "size_factor": 40.0}


def recorded_config(data: dict[str, Any]) -> dict[str, Any]:
    """A config that tribodem recorded (a checkpoint's, study.toml's, a run folder's
    summary.json or config.toml) as this version reads it; a user's config file goes
    through this only when it names an older ``config_version`` (:func:`resolve_config`):
    else it means what it says. A version this one does not know is returned as it is
    (validation refuses it).

    Without ``config_version`` it was written before version 2, when every config held
    ``[fe] h_over_a = 0.25`` and ``size_factor = 40.0`` unless they were set otherwise and
    fe3d read these values as "its own" (h = a/3, bodies 8 a): they become None, left out,
    the backend's own (for fe the same 0.25 and 40). Before version 3 the ccx backends (fe,
    fe3d) held the flow stress of elastic-plastic bodies at the UTS unless ``[plastic]
    hardening`` was given (then the line went on, as in tamaas): ``beyond_uts`` is set to
    what ran ("hold" there, else "line"). Before version 4 the ccx backends seated and
    loaded the bodies with friction 0.001: ``[fe] loading_friction`` is set to "low" in the
    records of fe and fe3d runs that leave it out (to the default in the others').
    """
    version = data.get("config_version", 1)
    if version == CONFIG_VERSION or version not in (1, 2, 3):
        return data
    if version == 1 and isinstance(data.get("fe"), dict):
        old = FE_DEFAULTS_BEFORE_V2
        data = {**data, "fe": {k: None if k in old and v == old[k] else v
                               for k, v in data["fe"].items()}}
    fe = dict(data["fe"]) if isinstance(data.get("fe"), dict) else {}
    ccx = BACKENDS.get(str(data.get("solver", "elastic"))) in ccx_backends()
    if version in (1, 2):
        plastic = data.get("plastic")
        plastic = dict(plastic) if isinstance(plastic, dict) else {}
        held = (ccx and fe.get("material") == "elastic-plastic"
                and plastic.get("hardening") is None)
        plastic["beyond_uts"] = "hold" if held else "line"
        data = {**data, "plastic": plastic}
    # a record that names it (none before version 4 did) keeps it; for other solvers it
    # does nothing: the default, so that the record compares equal to this version's
    low = "low" if ccx else FEConfig.model_fields["loading_friction"].default
    data = {**data, "fe": fe | {"loading_friction": fe.get("loading_friction", low)}}
    return {**data, "config_version": CONFIG_VERSION}


def effective_config(data: dict[str, Any]) -> dict[str, Any]:
    """``data`` (a config as a dict) with its ``[fe]`` fields of :data:`FE_BACKEND_OWN` as
    its solver's backend takes them: left out (None or absent), the backend's own default
    (fe3d: h_over_a 1/3, size_factor 8); for a solver without ccx, none (they do nothing
    there). For telling whether two configs make the same run."""
    fe = data.get("fe")
    if not isinstance(fe, dict):
        return data
    backend = BACKENDS.get(str(data.get("solver")))
    out = {k: v for k, v in fe.items() if k not in FE_BACKEND_OWN}
    if backend in ccx_backends():
        takes = inspect.signature(backend).parameters
        out |= {k: takes[k].default if fe.get(k) is None else fe[k] for k in FE_BACKEND_OWN}
    return {**data, "fe": out}


#: Config fields a resumed run may change: ``cycles`` (raised, to extend a run), the
#: ``[output]`` table (what is written, not the numbers), how ccx runs (threads, time limit,
#: job cache) and, to go on from a stopped finite-element cycle, its retries, the worn
#: surface's slope limit and the friction while loading (the cycles after the resume are
#: then another run's: each cycle's ``wear_slope_limit`` and ``loading_mu`` in summary.json
#: say what it ran with).
RESUME_MAY_CHANGE = ("cycles", "output.", "fe.threads", "fe.timeout", "fe.cache",
                     "fe.retries", "fe.retry_from", "fe.max_wear_slope",
                     "fe.loading_friction")


def resume_diffs(old_cfg: dict[str, Any], new_cfg: dict[str, Any], what: str = "checkpoint",
                 may_change: tuple[str, ...] = RESUME_MAY_CHANGE) -> list[str]:
    """The fields in which config ``new_cfg`` would make another run than the recorded
    config ``old_cfg`` (read as :func:`recorded_config` reads it), each as "field = new
    (``what``: old)": both compared as :func:`effective_config` gives them, without the
    fields a resume may change (``may_change``, prefixes) and without a field added to
    tribodem after the record was made that ``new_cfg`` leaves at its default (it keeps the
    behaviour the record ran with)."""
    old = _flat(effective_config(recorded_config(old_cfg)))
    new = _flat(effective_config(new_cfg))
    absent = "<absent>"
    default = _flat(_jsonable(FrettingConfig()))
    return [f"{k} = {new.get(k, absent)!r} ({what}: {old.get(k, absent)!r})"
            for k in sorted(set(old) | set(new))
            if not k.startswith(may_change) and old.get(k, absent) != new.get(k, absent)
            and not (k not in old and k in default and new.get(k) == default[k])]


def resume_allowed(may_change: tuple[str, ...] = RESUME_MAY_CHANGE) -> str:
    """What a refused resume says may change (``may_change``: field names and prefixes)."""
    return "only " + ", ".join(f"[{k[:-1]}]" if k.endswith(".") else k
                               for k in may_change) + " may change"


def check_resume(cfg: FrettingConfig, meta: dict[str, Any], path: Path) -> None:
    """Refuse (``ConfigError``) resuming checkpoint ``path`` with a different config (every
    differing field named with both values, :func:`resume_diffs`) or fewer cycles than it
    already has."""
    diffs = resume_diffs(meta.get("config") or {}, _jsonable(cfg))
    if diffs:
        raise ConfigError(
            f"--resume: the config differs from the one checkpoint '{path}' was made with: "
            + "; ".join(diffs) + f"; allowed: the checkpoint's values ({resume_allowed()}; "
            "cycles to extend the run)")
    done = int(meta.get("cycles_done", 0))
    if cfg.cycles < done:
        raise ConfigError(f"cycles = {cfg.cycles}: checkpoint '{path}' is already at cycle "
                          f"{done}; allowed: >= {done}")


def run_fretting(cfg: FrettingConfig, out: Path, echo: Any = None, resume: bool = False,
                 progress: bool = False,
                 checkpoint: tuple[dict[str, Any], dict[str, Any]] | None = None
                 ) -> dict[str, Any]:
    """Run the loop and write results.csv, summary.json, config.toml, figures, VTK to ``out``.

    Checks ``out`` (and, with ``resume``, its checkpoint against ``cfg``) before any work;
    ``checkpoint``: the (meta, state) already read from it. While running, ``out/results.csv``
    and ``out/checkpoint.npz`` are rewritten (atomically) every ``output.checkpoint_every``
    simulated cycles; ``resume`` continues from that checkpoint, bitwise as if the run had
    not stopped. An early stop (contact outgrew the window) writes every output so far,
    then raises :class:`tribodem.io.runs.RunStopped`.
    """
    out = Path(out)
    ck = out / CHECKPOINT
    runs.check_out_dir(out, "--out", resume=resume, need=(CHECKPOINT,) if resume else ())
    state: dict[str, Any] | None = None
    if resume:
        meta, state = checkpoint if checkpoint is not None else read_checkpoint(ck)
        check_resume(cfg, meta, ck)
    loop = build_loop(cfg)
    if isinstance(loop.solver, ccx_backends()):  # ccx decks, logs, results
        loop.solver.workdir = out / "fe"
    if state is not None:
        try:
            loop.load_state_dict(state)
        except (KeyError, TypeError, ValueError) as err:
            raise ConfigError(f"checkpoint '{ck}' cannot be read: it does not fit this run: "
                              f"{type(err).__name__}: {err}") from None
    runs.announce(out, ck, resume_hint="add --resume to the same command")
    if resume:
        runs.checkpoint_written(ck)
    out.mkdir(parents=True, exist_ok=True)
    if not resume:  # a new run: an older run's checkpoint must not pass for this one's
        ck.unlink(missing_ok=True)
    resolved = _jsonable(cfg)
    write_text(out / "config.toml", dump_toml(resolved))
    t0 = time.perf_counter()
    every = max(1, cfg.cycles // 10)
    meta_cfg = resolved  # the checkpoint records the config as config.toml does

    def save(lp: FrettingLoop) -> None:
        assert lp.history is not None
        write_checkpoint(ck, {"config": meta_cfg, "cycles_done": lp.cycles_done,
                              "tribodem": __version__}, lp.state_dict())
        runs.checkpoint_written(ck)
        write_rows(lp.history, out)  # never ahead of the checkpoint

    with runs.progress(cfg.cycles, "cycle", "fretting run", enabled=progress,
                       initial=loop.cycles_done) as bar:
        def report(row: dict[str, Any]) -> None:
            bar.update(1)
            bar.set_postfix_str(f"wear depth lower {row['wear_depth_lower_m']:.3g} m")
            if echo is not None and not progress and (
                    row["cycle"] % every == 0 or row["cycle"] == cfg.cycles):
                echo(f"cycle {row['cycle']}/{cfg.cycles}"
                     f"{' (jumped)' if row['jumped'] else ''}: wear depth upper "
                     f"{row['wear_depth_upper_m']:.4g} m, lower "
                     f"{row['wear_depth_lower_m']:.4g} m")

        hist: FrettingHistory = loop.run(cfg.cycles, progress=report, checkpoint=save,
                                         checkpoint_every=cfg.output.checkpoint_every)
    files: list[str] = ["results.csv", "summary.json", "config.toml", CHECKPOINT]
    if (out / "criterion.csv").exists():
        files.append("criterion.csv")
    if cfg.output.figures:
        files += [p.name for p in write_figures(hist, out)]
    if cfg.output.vtk:
        files += [p.name for p in write_vtk_surfaces(hist, out)]
    if hist.de_phases:
        files += [p.name for p in write_debris_outputs(hist, out, figures=cfg.output.figures,
                                                       vtk=cfg.output.vtk)]
    extra = {
        "criterion": {"name": loop.criterion.name, "kind": loop.criterion.kind,
                      **loop.criterion.params()},
        "jump": {"strategy": cfg.jump.strategy,
                 **({"params": loop.strategy.params(), **jump_reading(loop)}
                    if loop.strategy else {})},
        "window_m": loop.solver.window,
        "contact_case": case_summary(cfg, loop.solver),
        "first_body_report": loop.solver.report(),
        "wall_time_total_s": time.perf_counter() - t0,
        "files": files,
        "config": resolved,
    }
    summary = write_results(hist, out, extra)
    if hist.stopped:
        fe_stop = isinstance(loop.stop_error, FESolverStopped)
        timed_out = isinstance(loop.stop_error, CcxTimeoutError)
        runs.announce(out, ck, resume_hint=(
                      f"raise fe.timeout (now {loop.solver.timeout:g} s) and add --resume to "
                      "the same command" if timed_out else
                      "see the deck and its .log, then add --resume to "
                      "retry the cycle (a deck that did not converge is not run again: raise "
                      "fe.retries, or delete its .failed file)") if fe_stop else
                      "a resume would stop at the same cycle: to go on, start a new run with a "
                      "larger contact.window")
        raise runs.RunStopped(f"{hist.stopped} (results.csv, summary.json and figures up "
                              f"to cycle {loop.cycles_done} are written)")
    return summary


fretting_app = typer.Typer(help="Fretting wear loop (seed 003 chapters 5-6).",
                           no_args_is_help=True, add_completion=False)


@fretting_app.callback()
def _fretting() -> None:
    """Fretting wear loop (seed 003 chapters 5-6)."""


@fretting_app.command("run")
def run_cmd(
    out: Annotated[Path, typer.Option("--out", help="Output directory.")],
    config: Annotated[Path | None, typer.Option("--config", help="TOML config file.")] = None,
    criterion: Annotated[str | None, typer.Option(
        "--criterion", help=f"One of: {', '.join(CRITERIA)}.")] = None,
    cycles: Annotated[int | None, typer.Option("--cycles", help="Number of cycles.")] = None,
    jump: Annotated[str | None, typer.Option(
        "--jump", help=f"none or one of: {', '.join(STRATEGIES)}.")] = None,
    solver: Annotated[str | None, typer.Option(
        "--solver", help=f"First-body backend: {', '.join(BACKENDS)}.")] = None,
    threads: Annotated[int | None, typer.Option(
        "--threads", help="ccx threads of solver = 'fe' (0 = all cores).")] = None,
    debris_every: Annotated[int | None, typer.Option(
        "--debris-every", help="Debris third body: a DE phase every K cycles.")] = None,
    no_debris: Annotated[bool, typer.Option(
        "--no-debris", help="Switch the debris third body off (overrides the config).")
    ] = False,
    quick: Annotated[bool, typer.Option("--quick", help="64^2 grid, 10 cycles.")] = False,
    resume: Annotated[bool, typer.Option(
        "--resume", help=f"Continue from OUT/{CHECKPOINT} (same config; --cycles may be "
        "raised).")] = False,
    progress: Annotated[bool, typer.Option(
        "--progress/--no-progress", help="Progress bar with ETA on stderr.")] = True,
) -> None:
    """Run the fretting wear loop; writes results.csv, summary.json, figures, VTK to --out."""
    for opt, value, allowed in (("--criterion", criterion, tuple(CRITERIA)),
                                ("--jump", jump, ("none", *STRATEGIES)),
                                ("--solver", solver, tuple(BACKENDS))):
        if value is not None and value not in allowed:
            raise ConfigError(f"{opt} = {value!r}: allowed: {', '.join(allowed)}")
    ov: dict[str, Any] = {}
    if criterion is not None:
        ov.setdefault("wear", {})["criterion"] = criterion
    if cycles is not None:
        ov["cycles"] = cycles
    if jump is not None:
        ov.setdefault("jump", {})["strategy"] = jump
    if solver is not None:
        ov["solver"] = solver
    if threads is not None:
        runs.check_threads(threads, "--threads")
        ov.setdefault("fe", {})["threads"] = threads
    if debris_every is not None and no_debris:
        raise ConfigError("--debris-every and --no-debris: give one of them, not both")
    if debris_every is not None:
        ov.setdefault("debris", {})["every"] = debris_every
    if no_debris:
        ov.setdefault("debris", {})["every"] = None
    runs.check_out_dir(out, "--out", resume=resume, need=(CHECKPOINT,) if resume else ())
    ck = read_checkpoint(out / CHECKPOINT) if resume else None
    cfg = resolve_config(config, quick=quick, overrides=ov,
                         base=recorded_config(ck[0].get("config") or {})
                         if ck is not None else None)
    summary = run_fretting(cfg, out, echo=typer.echo, resume=resume, progress=progress,
                           checkpoint=ck)
    typer.echo(
        f"done: {summary['cycles']} cycles ({summary['cycles_simulated']} simulated, "
        f"{summary['cycles_jumped']} jumped) in {summary['wall_time_s']:.1f} s; worn volume "
        f"upper {summary['wear_volume_upper_m3']:.4g} m^3, lower "
        f"{summary['wear_volume_lower_m3']:.4g} m^3 -> {out}"
    )


#: ``debris-study --quick``: the seed's counts / 20 on the quick preset (64^2, 10 cycles).
QUICK_STUDY_COUNTS = "1100,4050,5100"


def parse_counts(text: str, field: str = "--counts") -> tuple[int, ...]:
    """Comma-separated particle counts (each 1..10^7, distinct, in any order)."""
    return parse_int_list(text, field, lambda c: 1 <= c <= 10**7,
                          "comma-separated distinct particle counts, each 1..10000000 "
                          "(e.g. 22000,81000,102000)")


@fretting_app.command("study")
def study_cmd(
    out: Annotated[Path, typer.Option("--out", help="Output directory.")],
    config: Annotated[Path | None, typer.Option(
        "--config", help="TOML config of the case (default: the seed's crossed cylinders; "
        "its criterion, cycles and jumping are the study's).")] = None,
    solver: Annotated[str | None, typer.Option(
        "--solver", help=f"First-body backend: {', '.join(BACKENDS)}.")] = None,
    quick: Annotated[bool, typer.Option(
        "--quick", help="64^2 grid, 5 and 15 cycles instead of 30 and 110.")] = False,
    stages: Annotated[str | None, typer.Option(
        "--stages", help="Comma-separated stages to run (default all: von_mises,s22,dfdi,"
        "swt,shear,energy,shear_jump).")] = None,
    threads: Annotated[int | None, typer.Option(
        "--threads", help="ccx threads of solver = 'fe' (0 = all cores).")] = None,
    resume: Annotated[bool, typer.Option(
        "--resume", help="Keep the finished stages of an earlier study in --out, resume the "
        "unfinished one (its config unless given).")] = False,
    progress: Annotated[bool, typer.Option(
        "--progress/--no-progress", help="Progress bars of the runs on stderr.")] = True,
) -> None:
    """Seed 003 chapter 6: every material evolution criterion on one case (one cycle for
    von Mises, S22, DFDI, SWT; 30 for shear and energy; shear with jumping to 110), the
    seed's numbers beside ours and the criteria ordered (study.md, study.json)."""
    from tribodem.fretting.record import read_study
    from tribodem.fretting.study import run_study

    runs.check_out_dir(out, "--out", resume=resume, need=("study.toml",) if resume else ())
    ov: dict[str, Any] = {}
    if solver is not None:
        ov["solver"] = solver
    if threads is not None:
        ov.setdefault("fe", {})["threads"] = threads
    base = read_study(out)["config"] if resume and config is None else None
    cfg = resolve_config(config, quick=quick, overrides=ov, base=base)
    only = None if stages is None else tuple(x.strip() for x in stages.split(","))
    summary = run_study(cfg, out, quick=quick, resume=resume, progress=progress,
                        echo=typer.echo, only=only)
    typer.echo(f"done: criteria study ({summary['solver']}), ours largest first: "
               f"{', '.join(summary['ranking_ours'])} -> {out}")


@fretting_app.command("debris-study")
def debris_study_cmd(
    out: Annotated[Path, typer.Option("--out", help="Output directory.")],
    config: Annotated[Path | None, typer.Option(
        "--config", help="TOML config of the case (default: the energy case).")] = None,
    counts: Annotated[str | None, typer.Option(
        "--counts", help="Debris particle counts (default: the seed's 22000,81000,102000; "
        f"--quick: {QUICK_STUDY_COUNTS}).")] = None,
    cycle: Annotated[int | None, typer.Option(
        "--cycle", help="Cycle of the study (default: config cycles, 160).")] = None,
    threads: Annotated[int, typer.Option("--threads", help="DEM threads (0 = all).")] = 0,
    quick: Annotated[bool, typer.Option("--quick", help="64^2 grid, cycle 10, counts / 20.")
                     ] = False,
    resume: Annotated[bool, typer.Option(
        "--resume", help="Skip the finished stages of an earlier study in --out (its config "
        "and counts unless given).")] = False,
    progress: Annotated[bool, typer.Option(
        "--progress/--no-progress", help="Progress bar of the wear run on stderr.")] = True,
) -> None:
    """Seed 003 section 5.4: contact force on the lower body at a cycle, without and with N
    debris particles (figs 5.22-5.27); writes debris_study.{csv,json}, plots, per-count data."""
    import numba

    from tribodem.fretting.debris_study import SEED_COUNTS, run_debris_study
    from tribodem.fretting.record import read_study

    n_threads = runs.check_threads(threads, "--threads")
    runs.check_out_dir(out, "--out", resume=resume, need=("study.toml",) if resume else ())
    # a resume takes the study's own config and counts unless they are given again
    study = read_study(out) if resume else {}
    default = ",".join(str(c) for c in study.get("counts") or ()) if resume else \
        QUICK_STUDY_COUNTS if quick else ",".join(str(c) for c in SEED_COUNTS)
    wanted = parse_counts(counts if counts is not None else default)
    ov: dict[str, Any] = {}
    if cycle is not None:
        ov["cycles"] = cycle
    base = study["config"] if resume and config is None else None
    cfg = resolve_config(config, quick=quick, overrides=ov, base=base)
    numba.set_num_threads(n_threads)
    summary = run_debris_study(cfg, out, wanted, resume=resume, progress=progress,
                               echo=typer.echo)
    typer.echo(f"done: debris study at cycle {summary['cycle']} "
               f"({', '.join(f'{c:,}' for c in wanted)} particles) -> {out}")


@fretting_app.command("sweep")
def sweep_cmd(
    table: Annotated[Path, typer.Option(
        "--table", help="CSV table: a header of config fields in dotted form (contact.load, "
        "wear.criterion, cycles, ...) and an optional name column; one row per member.")],
    out: Annotated[Path, typer.Option(
        "--out", help="Output directory (a folder per member, sweep.csv, sweep.json); "
        "re-running the same sweep there skips finished members and resumes the others.")],
    config: Annotated[Path | None, typer.Option(
        "--config", help="TOML base config of every row (default: the defaults).")] = None,
    quick: Annotated[bool, typer.Option(
        "--quick", help="64^2 grid, 10 cycles (as fretting run --quick); the table's cells "
        "override it.")] = False,
    workers: Annotated[int, typer.Option(
        "--workers", min=0, max=1024, help="Worker processes of the local Dask cluster "
        "(1 thread each); 0 = all local cores. Not with --scheduler.")] = 0,
    scheduler: Annotated[str | None, typer.Option(
        "--scheduler", help="Use an existing Dask cluster: tcp://HOST:PORT of its scheduler "
        "or its scheduler JSON file; --out must be on a file system the workers share.")
    ] = None,
    progress: Annotated[bool, typer.Option(
        "--progress/--no-progress", help="Progress bar (members done / running / failed) on "
        "stderr.")] = True,
) -> None:
    """A parameter study: every row of --table is a fretting run, an independent,
    idempotent task on Dask in OUT/<name>/; writes sweep.csv and sweep.json. A failed (or
    early-stopped) member is reported and the others go on (exit 3 at the end)."""
    from tribodem.fretting.sweep import run_sweep

    run_sweep(table, out, config, quick, workers, scheduler, progress, echo=typer.echo,
              err_echo=lambda s: typer.echo(s, err=True))
