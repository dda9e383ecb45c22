"""The fretting run's configuration: the TOML tables as pydantic models, the ``--quick``
presets, the resolution of a config (defaults <- the config <- ``quick`` <- overrides), the
migration of configs recorded by older versions and the comparison a resume makes.

Every model is strict (:class:`~tribodem.io.model.StrictModel`: an unknown key is refused);
every field is in SI units unless its description says otherwise.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any, ClassVar, Literal

from pydantic import (
    Field,
    ValidationError,
    ValidationInfo,
    field_validator,
    model_validator,
)

from tribodem.contact import BACKENDS, FirstBodySolver
from tribodem.contact.fe.options import FEOptions
from tribodem.contact.geometry import CrossedCylinders, CylinderOnFlat, FlatPunch, SphereOnFlat
from tribodem.contact.options import STRENGTH_RANGE, ElasticOptions, PlasticOptions
from tribodem.fretting.criteria import ALPHA_SEED, ARCHARD_K, UTS_EN24T, YIELD_EN24T
from tribodem.fretting.loop import GEOMETRY_TOLERANCE, UPDATE_TOLERANCE
from tribodem.io.config import ConfigError, format_validation_error, merge
from tribodem.io.model import PhysicalConfig, StrictModel, physical
from tribodem.io.record import (
    ConfigSource,
    Source,
    flatten,
    is_free,
    may_change_text,
    read_source,
    resolve,
)
from tribodem.materials.en24t import EN24T

CriterionName = Literal["energy", "archard", "s22", "von_mises", "shear", "dfdi", "swt"]
JumpName = Literal["none", "constant", "cojocaru", "moving", "overlapping", "adaptive",
                   "polynomial"]


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

#: Physical ranges (real materials and rigs) of the fields that share them (SI units; the
#: strengths' STRENGTH_RANGE, Pa, is the [plastic] table's).
YOUNG_RANGE = (1e6, 2e12)  #: Young's moduli, Pa: soft elastomers to diamond x 2
RADIUS_RANGE = (1e-6, 10.0)  #: radii of curvature, m: an AFM tip to a large roller
DIAMETER_RANGE = (2e-6, 20.0)  #: diameters, m (2 x RADIUS_RANGE)
FRICTION_RANGE = (0.0, 5.0)  #: friction coefficients: lubricated to clean metals in vacuum
WEAR_COEFFICIENT_RANGE = (0.0, 1e-9)  #: Archard k, 1/Pa, and energy alpha, m^3/J (the
#: seed's alpha 1.6e-15: severe wear of the softest materials stays below 1e-11)

#: Default total normal load on the window, N (DESIGN.md default case).
DEFAULT_LOAD = 100.0

#: Window side when ``contact.window`` is left out, in contact radii (or half-widths).
WINDOW_RADII = 10.0


class ContactConfig(StrictModel):
    """First-body case (DESIGN.md default: crossed 8 mm cylinders, 100 N, +-0.3 mm, mu 0.6).

    ``geometry`` picks the case (docs/fretting.md, "Geometries"); its own fields left out
    take the defaults of :mod:`tribodem.contact.geometry` and are filled in on validation
    (the resolved config shows what ran). A field of another geometry is refused.
    """

    geometry: GeometryName = Field(
        "crossed_cylinders", description="the first-body case: crossed cylinders, sphere on "
        "flat, cylinder on flat (line contact), flat punch with a rounded edge, measured "
        "height maps (docs/fretting.md 'Geometries')")
    diameter: float | None = Field(
        None, gt=0, **physical(*DIAMETER_RANGE, "m", "crossed_cylinders: both cylinders' "
                               "diameter, m (shorthand for radius_upper = radius_lower = "
                               "diameter / 2; a radius given wins)"))
    radius_upper: float | None = Field(None, gt=0, **physical(
        *RADIUS_RANGE, "m", "crossed_cylinders: upper cylinder's radius (axis along y), m"))
    radius_lower: float | None = Field(None, gt=0, **physical(
        *RADIUS_RANGE, "m", "crossed_cylinders: lower cylinder's radius (axis along x), m"))
    radius: float | None = Field(None, gt=0, **physical(
        *RADIUS_RANGE, "m", "sphere_on_flat / cylinder_on_flat: radius of the upper body, m"))
    punch_radius: float | None = Field(None, gt=0, **physical(
        *RADIUS_RANGE, "m", "flat_punch: radius of the flat face, m"))
    edge_radius: float | None = Field(None, gt=0, **physical(
        *RADIUS_RANGE, "m", "flat_punch: edge radius, m"))
    upper_map: str | None = Field(None, description="height_map: upper body's surface "
                                  "heights (.csv, .npy with map_dx; .stl)")
    lower_map: str | None = Field(None, description="height_map: lower body's surface "
                                  "heights (must cover the window plus the stroke along x)")
    map_dx: float | None = Field(None, gt=0, **physical(
        1e-9, 1.0, "m", "height_map: grid spacing of CSV/NPY maps (STL: sampling step, "
        "default its vertex spacing), m"))
    load: float | None = Field(None, gt=0, **physical(
        1e-6, 1e6, "N", "total normal load on the window, N (default 100 N; line contact: "
        "or load_per_length)"))
    load_per_length: float | None = Field(None, gt=0, **physical(
        1e-3, 1e8, "N/m", "cylinder_on_flat: normal load per unit length of the cylinder, "
        "N/m (instead of the total load over the window)"))
    friction: float = Field(0.6, ge=0, **physical(*FRICTION_RANGE, "",
                                                  "friction coefficient"))
    amplitude: float = Field(0.3e-3, gt=0, **physical(
        1e-9, 0.1, "m", "displacement amplitude, m (the lower body's track grid spans the "
        "window plus twice the amplitude at the window's spacing, and must fit in memory)"))
    n_increments: int = Field(48, ge=4, le=100_000,
                              description="increments per cycle (multiple of 4)")
    regime: Literal["gross", "ciavarella-jaeger"] = Field(
        "gross", description="tangential problem: gross, q = mu p wherever in contact; "
        "ciavarella-jaeger, partial slip after the loading and each reversal (Mindlin's "
        "superposition)")
    n: int = Field(256, ge=16, le=2048, description="window points per side (even)")
    window: float | None = Field(None, gt=0, **physical(
        1e-8, 1.0, "m", "window side, m (None: 10 radii; it must hold 4 contact radii and "
        "resolve the contact: a spacing window / n of at most a contact radius)"))
    tolerance: float = Field(1e-6, gt=0, lt=1, description="normal solver (PKR) tolerance")
    young: float = Field(EN24T.young, gt=0, **physical(
        *YOUNG_RANGE, "Pa", "Young's modulus (both bodies unless young_upper / young_lower), "
        "Pa"))
    poisson: float = Field(EN24T.poisson, gt=-1, lt=0.5, description="Poisson's ratio (both "
                           "bodies unless poisson_upper / poisson_lower)")
    young_upper: float | None = Field(None, gt=0, **physical(
        *YOUNG_RANGE, "Pa", "upper body's Young's modulus, Pa"))
    poisson_upper: float | None = Field(None, gt=-1, lt=0.5, description="upper body's "
                                        "Poisson's ratio")
    young_lower: float | None = Field(None, gt=0, **physical(
        *YOUNG_RANGE, "Pa", "lower body's Young's modulus, Pa"))
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


class WearConfig(StrictModel):
    """Criterion and its parameters (SI)."""

    criterion: CriterionName = Field(
        "energy", description="material evolution criterion: energy (eq 2.7), archard "
        "(eq 2.6), s22, von_mises, shear (eq 6.9), dfdi (eqs 6.1-6.2), swt (eqs 6.3-6.8)")
    alpha: float = Field(ALPHA_SEED, ge=0, **physical(
        *WEAR_COEFFICIENT_RANGE, "m^3/J", "energy wear coefficient, m^3/J"))
    energy_share_upper: float = Field(
        0.5, ge=0, le=1, description="energy: upper body's share of eq 2.7's total volume")
    archard_k_upper: float = Field(ARCHARD_K, ge=0, **physical(
        *WEAR_COEFFICIENT_RANGE, "1/Pa", "Archard k, upper body, 1/Pa"))
    archard_k_lower: float = Field(ARCHARD_K, ge=0, **physical(
        *WEAR_COEFFICIENT_RANGE, "1/Pa", "Archard k, lower body, 1/Pa"))
    yield_strength: float = Field(YIELD_EN24T, gt=0, **physical(
        *STRENGTH_RANGE, "Pa", "yield strength, Pa (s22, von_mises)"))
    uts: float = Field(UTS_EN24T, gt=0, **physical(
        *STRENGTH_RANGE, "Pa", "ultimate tensile strength, Pa (shear: S_us = 0.8 UTS)"))
    stress_depth: float | None = Field(None, gt=0, **physical(
        1e-9, 1.0, "m", "subsurface grid depth, m"))
    stress_nz: int = Field(33, ge=2, le=257, description="subsurface grid levels")
    stress_samples: int = Field(8, ge=1, description="sampled increments per cycle")
    eps0: float = Field(EN24T.dfdi_eps0, gt=0, **physical(
        1e-4, 10.0, "", "dfdi: uniaxial failure strain eps0 (eq 6.2; default the seed's "
        "script's, appendix IV)"))
    dfdi_triaxiality: Literal["local", "seed-script"] = Field(
        "local", description="dfdi: eq 6.2's sigma_m / sigma_eq per point (local), or as the "
        "seed's script computes it (ranges over the cycle, sigma_eq summed over all nodes: "
        "the exponent ~0, eps_f = 1.65 eps0)")
    swt_nz: int = Field(17, ge=2, le=129, description="swt: subsurface levels")
    swt_plane_step: float = Field(5.0, gt=0, le=90, description="swt: candidate planes, deg")
    update_tolerance: float = Field(
        UPDATE_TOLERANCE, ge=0, description="largest depth increment of one geometry update "
        "/ the contact's elastic approach: a cycle that wears more is solved again in "
        "sub-cycles, each adding its share of the cycle's wear (archard, energy on the "
        "elastic backend; 0: one update a cycle)")


class JumpConfig(StrictModel):
    """Cycle-jumping: a strategy of Lu (2018) chapter 4 and its parameters, capped by the
    loop's geometry control (docs/fretting.md, "Jumping")."""

    strategy: JumpName = Field(
        "none", description="cycle-jumping strategy (none: every cycle is simulated); its "
        "parameters in jump.params")
    params: dict[str, Any] = Field(
        default_factory=dict, description="keyword parameters of the strategy (the table "
        "below); an unknown key is refused")
    geometry_tolerance: float = Field(
        GEOMETRY_TOLERANCE, ge=0, description="largest jumped depth increment / the "
        "contact's elastic approach (0: the strategy alone)")


class DebrisConfig(StrictModel):
    """The debris third body (Lu (2018) 3.2.6-3.2.7); off unless ``every`` is set."""

    every: int | None = Field(None, ge=1, description="DE phase every K cycles (None: off)")
    diameter: float = Field(0.6e-6, gt=0, **physical(
        1e-7, 1e-3, "m", "debris diameter d of eq 3.10, m (the particles a run makes, worn "
        "volume / (pi d^3 / 6), must fit in memory)"))
    shares: tuple[float, float, float] = Field(
        (1 / 3, 1 / 3, 1 / 3), description="spherical, chunk, rubbing fractions")
    volume_correction: float = Field(1.0, gt=0, le=2, description="seed's 0.77 (optional)")
    cor: float = Field(0.72, gt=0, le=1, description="coefficient of restitution of the "
                       "debris contacts (Hertz-Mindlin)")
    friction: float = Field(0.6, ge=0, **physical(
        *FRICTION_RANGE, "", "sliding friction coefficient of the debris contacts"))
    rolling_friction: float = Field(0.001, ge=0, **physical(
        0.0, 1.0, "", "rolling friction coefficient of the debris contacts (constant "
        "torque)"))
    density_scaling: float = Field(1.0, ge=1, description="DE-phase mass scaling")
    tolerance: float = Field(1e-4, gt=0, lt=0.1, description="servo relative load error")
    max_steps: int = Field(200_000, ge=100, description="DE steps per phase at most")
    ramp_steps: int = Field(10_000, ge=0, description="servo target ramp, steps")
    target_cap: float = Field(0.9, gt=0, lt=1, description="debris load <= cap x load")
    seed: int = Field(0, description="random seed of the debris placement")


class OutputConfig(StrictModel):
    """What is written besides results.csv / summary.json / config.toml (which always are)."""

    figures: bool = Field(True, description="write the PNG figures (profiles, wear scar, "
                          "wear per cycle)")
    vtk: bool = Field(True, description="write the worn surfaces for ParaView "
                      "(surface_upper.vtu, surface_lower.vtu)")
    checkpoint_every: int = Field(
        1, ge=1, description="checkpoint.npz and results.csv rewritten every K simulated "
        "cycles at the most (and at the end)")
    checkpoint_seconds: float = Field(
        10.0, ge=0, le=86400, description="and at least this many seconds of wall time "
        "apart, s (the first after the first cycle; 0: every checkpoint_every cycles): a "
        "run of tens of thousands of short cycles does not spend its time rewriting its "
        "checkpoint")


#: Layout version of the fretting config, recorded as ``config_version`` in every config
#: tribodem writes (config.toml, summary.json, checkpoint.npz, study.toml). 2: ``[fe]
#: h_over_a`` / ``size_factor`` left out are the backend's own (``BACKEND_OWN`` of
#: :mod:`tribodem.contact.fe.options`); a recorded config without it is older. 3:
#: ``[plastic] beyond_uts`` (default "line": the ccx backends held the flow stress at the
#: UTS before). :func:`recorded_config` migrates an older record, and a config file that
#: names an older version (a run's config.toml given back with --config) is read the same
#: way (:func:`resolve_config`). 4: ``[fe] loading_friction`` (default "auto":
#: elastic-plastic bodies seated and loaded with the interface's mu; the ccx backends
#: seated and loaded with 0.001 before). 5: ``[jump] strategy = "adaptive"`` is the step
#: control on a fitted curve (:class:`~tribodem.cyclejump.SmoothJump`); the polynomial
#: strategy that had the name is "polynomial"; ``[elastic] line_model`` (default
#: "plane-strain": a line contact on one cross-section; the n x n periodic window before).
#: 6: ``[wear] update_tolerance`` (default 0.05: a cycle that wears more than that share of
#: the elastic approach is split into sub-cycles; one geometry update a cycle before).
#: 7: ``[fe] morph`` (default "tributary": fe3d's surface nodes take their exact tributary
#: share of the wear maps) and ``[fe] max_wear_kink`` (default 0.03); fe3d morphed by the
#: lumped projection without a kink limit before.
CONFIG_VERSION = 7


#: ``--quick``: a 64^2 window, 10 cycles, a coarser subsurface grid and a shorter debris
#: servo ramp (a few seconds a run on the elastic half-space).
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


class FrettingConfig(PhysicalConfig):
    """``tribodem fretting run`` configuration (TOML tables contact, wear, jump, plastic, fe,
    debris, output)."""

    cycles: int = Field(160, ge=1, le=10**7, description="cycles to run, simulated and "
                        "jumped (a resume may raise it)")
    solver: str = Field("elastic", description="first-body backend (tribodem.contact.BACKENDS)")
    config_version: int = Field(
        CONFIG_VERSION, ge=CONFIG_VERSION, le=CONFIG_VERSION, description="the config "
        "layout, written by tribodem into the configs it records; leave it out of your own "
        "files (they are read as this version)")
    contact: ContactConfig = Field(default_factory=ContactConfig)
    wear: WearConfig = Field(default_factory=WearConfig)
    jump: JumpConfig = Field(default_factory=JumpConfig)
    elastic: ElasticOptions = Field(default_factory=ElasticOptions)
    plastic: PlasticOptions = Field(default_factory=PlasticOptions)
    fe: FEOptions = Field(default_factory=FEOptions)
    debris: DebrisConfig = Field(default_factory=DebrisConfig)
    output: OutputConfig = Field(default_factory=OutputConfig)
    #: the option tables of backends registered beside the built-in ones (a plug-in
    #: backend's own ``[name]`` table, from its ``FirstBodySolver.options``), each checked
    #: by the backend's model and written back as a table of its own
    plugin_options: dict[str, dict[str, Any]] = Field(default_factory=dict, exclude=True)

    #: the ``--quick`` presets (:data:`QUICK`, per backend :data:`QUICK_SOLVER`)
    QUICK: ClassVar[dict[str, Any]] = QUICK
    QUICK_SOLVER: ClassVar[dict[str, dict[str, Any]]] = QUICK_SOLVER

    @model_validator(mode="before")
    @classmethod
    def _plugin_tables(cls, data: Any) -> Any:
        """Move the top-level tables that a registered backend reads but this model does
        not declare into :attr:`plugin_options`, each validated by the backend's model
        (``ValueError`` naming ``table.field``)."""
        if not isinstance(data, dict):
            return data
        models = {t: m for b in BACKENDS.values() for t, m in b.options.items()
                  if t not in cls.model_fields}
        found = [k for k in data if k in models]
        if not found:
            return data
        plugin = dict(data.get("plugin_options") or {})
        for k in found:
            try:
                plugin[k] = models[k].model_validate(data[k]).model_dump(mode="json")
            except ValidationError as err:
                raise ValueError(format_validation_error(err, k).replace(
                    f"{k}: field '", f"{k}.").replace("' = ", " = ")) from None
        return {**{k: v for k, v in data.items() if k not in found}, "plugin_options": plugin}

    @field_validator("solver")
    @classmethod
    def _known_backend(cls, v: str) -> str:
        if v not in BACKENDS:
            raise ValueError(f"not a first-body backend; allowed: {', '.join(BACKENDS)}")
        return v

    @classmethod
    def quick_preset(cls, solver: str | None = None) -> dict[str, Any]:
        """The ``--quick`` preset (a dict shaped like the TOML file) for first-body backend
        ``solver``: :data:`QUICK` and, over it, the backend's own (:data:`QUICK_SOLVER`)."""
        return merge(QUICK, QUICK_SOLVER.get(str(solver), {}))

    @classmethod
    def quick(cls, solver: str = "elastic") -> FrettingConfig:
        """The quick config of backend ``solver``: the defaults under
        :meth:`quick_preset` (what ``tribodem fretting run --quick --solver NAME`` runs)."""
        return resolve_config(None, quick=True, overrides={"solver": solver})

    def record(self) -> dict[str, Any]:
        """This config as JSON-able nested dicts, as it is recorded (config.toml,
        summary.json, the checkpoint, study.toml): every field, in its JSON form ('off' for
        no slope limit), a plug-in backend's table among the others."""
        return {**self.model_dump(mode="json"), **self.plugin_options}


#: The option tables beside ``[contact]`` that backends read (each backend its own,
#: ``FirstBodySolver.options``): ``[plastic]`` and ``[fe]``.
OPTION_TABLES = ("elastic", "plastic", "fe")

#: ``[fe]`` defaults that tribodem recorded in every config before ``config_version`` 2 (it
#: dumped every field): there they meant "left out", and fe3d ran its own mesh on them
FE_DEFAULTS_BEFORE_V2: dict[str, float] = {"h_over_a": 0.25, "size_factor": 40.0}


def runs_ccx(solver: str | None) -> bool:
    """Whether first-body backend ``solver`` (a name of ``BACKENDS``) runs CalculiX and
    reads the ``[fe]`` table (False for a name not registered)."""
    backend = BACKENDS.get(str(solver))
    return backend is not None and backend.runs_ccx


def option_tables(cfg: FrettingConfig) -> dict[str, Any]:
    """The option tables the configured backend reads (``FirstBodySolver.options``), by
    TOML name, as :meth:`~tribodem.contact.FirstBodySolver.from_case` takes them (a
    plug-in backend's own table from :attr:`FrettingConfig.plugin_options`)."""
    return {t: getattr(cfg, t) if t in FrettingConfig.model_fields
            else model.model_validate(cfg.plugin_options.get(t, {}))
            for t, model in BACKENDS[cfg.solver].options.items()}


def read_config(config: ConfigSource) -> Source:
    """``config`` as plain data (:func:`~tribodem.io.record.read_source`: a file is read,
    ``ConfigError`` naming ``--config``), the height-map paths of a file made relative to
    its folder."""
    src = read_source(config)
    contact = src.data.get("contact")
    if src.path is not None and isinstance(contact, dict):
        for key in ("upper_map", "lower_map"):
            v = contact.get(key)
            if isinstance(v, str) and not Path(v).expanduser().is_absolute():
                contact[key] = str(src.path.parent / v)
    return src


def resolve_config(config: ConfigSource = None, quick: bool = False,
                   overrides: Mapping[str, Any] | None = None,
                   base: Mapping[str, Any] | None = None) -> FrettingConfig:
    """Defaults <- ``config`` <- the ``quick`` preset <- ``overrides`` (command-line options),
    validated (``ConfigError`` naming each bad field).

    ``config``: a :class:`FrettingConfig`, a dict shaped like the TOML file, the path of a
    TOML file (its height-map paths are relative to it) or None. A config that names an
    older ``config_version`` (a run's record given back) is read as
    :func:`recorded_config` reads it. ``base``: the resolved config of a checkpoint or a
    study, used in place of ``config`` when that is None (a resume without a config).
    """
    if config is not None:
        src = read_config(config)
        data, source = src.data, src.name
        if data.get("config_version", CONFIG_VERSION) != CONFIG_VERSION:
            data = recorded_config(data)  # a run's record given back: what it ran
    else:
        data, source = dict(base or {}), "command line"
    preset = None
    if quick:
        preset = FrettingConfig.quick_preset((overrides or {}).get("solver", data.get("solver")))
    return resolve(FrettingConfig, data, source=source, quick=preset, overrides=overrides)


def recorded_config(data: Mapping[str, Any]) -> dict[str, Any]:
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
    records of fe and fe3d runs that leave it out (to the default in the others'). Before
    version 5 ``[jump] strategy = "adaptive"`` was the polynomial strategy of the thesis'
    section 4.3 (:class:`~tribodem.cyclejump.AdaptiveJump`): it becomes "polynomial"; and
    the elastic backend solved a line contact on the n x n periodic window: ``[elastic]
    line_model`` is set to "periodic-2d" in the records of line-contact runs. Before
    version 6 the geometry was updated once a cycle: ``[wear] update_tolerance`` is set to
    0 where the record leaves it out. Before version 7 fe3d morphed its meshes by the lumped
    projection without a kink limit: in fe3d records that leave them out ``[fe] morph`` is
    set to "projection" and ``max_wear_kink`` to "off".
    """
    data = dict(data)
    version = data.get("config_version", 1)
    if version == CONFIG_VERSION or version not in (1, 2, 3, 4, 5, 6):
        return data
    if data.get("solver") == "fe3d":
        fe_old = dict(data["fe"]) if isinstance(data.get("fe"), dict) else {}
        data["fe"] = {"morph": "projection", "max_wear_kink": "off", **fe_old}
    if version == 6:
        return {**data, "config_version": CONFIG_VERSION}
    wear = dict(data["wear"]) if isinstance(data.get("wear"), dict) else {}
    data["wear"] = {"update_tolerance": 0.0, **wear}
    if version == 5:
        return {**data, "config_version": CONFIG_VERSION}
    jump = data.get("jump")
    if isinstance(jump, dict) and jump.get("strategy") == "adaptive":
        data["jump"] = {**jump, "strategy": "polynomial"}
    contact = data.get("contact")
    line = isinstance(contact, dict) and contact.get("geometry") == "cylinder_on_flat"
    if line and data.get("solver", "elastic") == "elastic":
        data["elastic"] = {"line_model": "periodic-2d"}
    if version == 4:
        return {**data, "config_version": CONFIG_VERSION}
    if version == 1 and isinstance(data.get("fe"), dict):
        old = FE_DEFAULTS_BEFORE_V2
        data = {**data, "fe": {k: None if k in old and v == old[k] else v
                               for k, v in data["fe"].items()}}
    fe = dict(data["fe"]) if isinstance(data.get("fe"), dict) else {}
    ccx = runs_ccx(str(data.get("solver", "elastic")))
    if version in (1, 2):
        plastic = data.get("plastic")
        plastic = dict(plastic) if isinstance(plastic, dict) else {}
        held = (ccx and fe.get("material") == "elastic-plastic"
                and plastic.get("hardening") is None)
        plastic["beyond_uts"] = "hold" if held else "line"
        data = {**data, "plastic": plastic}
    # a record that names it (none before version 4 did) keeps it; for other solvers it
    # does nothing: the default, so that the record compares equal to this version's
    low = "low" if ccx else FEOptions.model_fields["loading_friction"].default
    data = {**data, "fe": fe | {"loading_friction": fe.get("loading_friction", low)}}
    return {**data, "config_version": CONFIG_VERSION}


def effective_config(data: Mapping[str, Any]) -> dict[str, Any]:
    """``data`` (a config as a dict) with its option tables (:data:`OPTION_TABLES`) as its
    solver's backend takes them (``FirstBodySolver.effective_options``): ``[fe]``'s
    fields whose None means the backend's own default (h_over_a, size_factor, timeout) are
    that default for a ccx backend (fe3d: h_over_a 1/3, size_factor 8) and left out for
    the others (they do nothing there). For telling whether two configs make the same
    run."""
    data = dict(data)
    tables = {t: data[t] for t in OPTION_TABLES if isinstance(data.get(t), Mapping)}
    backend = BACKENDS.get(str(data.get("solver")), FirstBodySolver)
    return {**data, **backend.effective_options(tables)}


#: Config fields a resumed run may change: ``cycles`` (raised, to extend a run), the
#: ``[output]`` table (what is written, not the numbers), how ccx runs (threads, time limit,
#: job cache) and, to go on from a stopped finite-element cycle, its retries, the worn
#: surface's morph, slope and kink limits and the friction while loading (the cycles after
#: the resume are then another run's: each cycle's ``wear_slope_limit``,
#: ``wear_kink_limit``, ``morph`` and ``loading_mu`` in summary.json say what it ran with).
RESUME_MAY_CHANGE = ("cycles", "output.", "fe.threads", "fe.timeout", "fe.cache",
                     "fe.retries", "fe.retry_from", "fe.max_wear_slope", "fe.morph",
                     "fe.max_wear_kink", "fe.loading_friction")


def resume_diffs(old_cfg: Mapping[str, Any], new_cfg: Mapping[str, Any],
                 what: str = "checkpoint",
                 may_change: tuple[str, ...] = RESUME_MAY_CHANGE) -> list[str]:
    """The fields in which config ``new_cfg`` would make another run than the recorded
    config ``old_cfg`` (read as :func:`recorded_config` reads it), each as "field = new
    (``what``: old)": both compared as :func:`effective_config` gives them, without the
    fields a resume may change (``may_change``, :func:`~tribodem.io.record.is_free`) and
    without a field added to tribodem after the record was made that ``new_cfg`` leaves at
    its default (it keeps the behaviour the record ran with)."""
    old = flatten(effective_config(recorded_config(old_cfg)))
    new = flatten(effective_config(new_cfg))
    absent = "<absent>"
    default = flatten(FrettingConfig().record())
    return [f"{k} = {new.get(k, absent)!r} ({what}: {old.get(k, absent)!r})"
            for k in sorted(set(old) | set(new))
            if not is_free(k, may_change) and old.get(k, absent) != new.get(k, absent)
            and not (k not in old and k in default and new.get(k) == default[k])]


def check_resume(cfg: FrettingConfig, meta: Mapping[str, Any], path: Path) -> None:
    """Refuse (``ConfigError``) resuming checkpoint ``path`` with a different config (every
    differing field named with both values, :func:`resume_diffs`) or fewer cycles than it
    already has."""
    diffs = resume_diffs(meta.get("config") or {}, cfg.record())
    if diffs:
        raise ConfigError(
            f"--resume: the config differs from the one checkpoint '{path}' was made with: "
            + "; ".join(diffs) + f"; allowed: the checkpoint's values "
            f"({may_change_text(RESUME_MAY_CHANGE)}; cycles to extend the run)")
    done = int(meta.get("cycles_done", 0))
    if cfg.cycles < done:
        raise ConfigError(f"cycles = {cfg.cycles}: checkpoint '{path}' is already at cycle "
                          f"{done}; allowed: >= {done}")
