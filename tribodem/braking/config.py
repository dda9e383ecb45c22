"""The braking run's configuration: the TOML tables as pydantic models (:class:`BrakingConfig`),
the ``--quick`` preset (:meth:`BrakingConfig.quick`), the resolution (defaults <- the config
<- the quick preset <- the condition, :func:`resolve_config` on
:func:`tribodem.io.record.resolve`), the :class:`~tribodem.braking.setup.RunSetup` a config
means (:func:`setup_from_config`) and the fields a resumed run may change
(:data:`RESUME_FREE`).

The resolved config is written to ``<out>/config.toml`` and reloads to the same config; a
resume compares the config it is given with the checkpoint's field by field
(:func:`check_same_config`).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, Field, model_validator

from tribodem.braking.conditions import get_condition, load_to_pressure, rpm_to_speed
from tribodem.braking.model import PHI_TARGET, Geometry, materials
from tribodem.braking.setup import RunSetup
from tribodem.dem.state import BYTES_PER_PARTICLE
from tribodem.dem.thermal import read_curve
from tribodem.io import runs
from tribodem.io.config import ConfigError, validate
from tribodem.io.model import PhysicalConfig, StrictModel, physical
from tribodem.io.record import ConfigSource, Source, config_diffs, may_change_text, read_source
from tribodem.io.record import resolve as resolve_model


class ConditionCfg(StrictModel):
    """Table 4 ``index`` or an explicit load (kN or Pa) and speed (r/min or m/s)."""

    index: int | None = Field(None, ge=1, le=5, description="table 4 condition 1..5")
    load_kN: float | None = Field(None, gt=0, **physical(
        1e-3, 1e4, "kN", "brake load, kN (table 4; turned into the pad pressure by the pad "
        "area the table implies: 13 kN -> 0.33 MPa)"))
    pressure_Pa: float | None = Field(None, gt=0, **physical(
        1e3, 1e9, "Pa", "pressure on the pad, Pa (instead of load_kN)"))
    rpm: float | None = Field(None, gt=0, **physical(
        1e-2, 25_000.0, "r/min", "disc speed, r/min (table 4; turned into the sliding speed "
        "at the friction radius the table implies: 1200 r/min -> 47.12 m/s)"))
    speed_m_s: float | None = Field(None, gt=0, **physical(
        1e-3, 1000.0, "m/s", "sliding speed, m/s (instead of rpm)"))

    @model_validator(mode="after")
    def _one_form(self) -> ConditionCfg:
        if self.load_kN is not None and self.pressure_Pa is not None:
            raise ValueError("give load_kN or pressure_Pa, not both")
        if self.rpm is not None and self.speed_m_s is not None:
            raise ValueError("give rpm or speed_m_s, not both")
        return self


#: the one-junction cell's width (m): ``--quick`` is narrower still, and
#: ``examples/braking_one_junction.toml`` is this cell (the default before the trend-study
#: cell); the default cell is ``WIDE_FACTOR`` times as wide with the same asperities
JUNCTION_WIDTH_M = 216e-6
#: the default (trend-study) cell is this many one-junction cells wide: in contact 90-97 %
#: of 2-4 mm slides (87 % of a 40 us run at condition 5, all of it after the run-in) where
#: the one-junction cell is in contact 12-56 % (docs/braking.md "Wider cells and more
#: packings")
WIDE_FACTOR = 16
#: sine modes of the one-junction cell (wavelengths W/1 .. W/4)
JUNCTION_MODES = 4


class GeometryCfg(StrictModel):
    """Interface cell sizes (m). The default is the trend-study cell: 16 one-junction cells
    wide (3,456 um, ~12,600 disks), the one-junction cell's wavelengths (54-216 um) kept by
    sine modes 16..64; ``--quick`` is a narrow cell (one junction, 144 um)."""

    width_m: float = Field(WIDE_FACTOR * JUNCTION_WIDTH_M, gt=0, **physical(
        1e-6, 0.5, "m", "cell width along the sliding (periodic), m (the cell's particles "
        "must fit in memory); the default, 16 x 216 um, holds about 16 asperity junctions: "
        "at condition 5 the pad carried load 87 % of a 40 us run and at every sample after "
        "the run-in, where a one-junction cell does 12-56 % of the time"))
    disc_height_m: float = Field(72e-6, gt=0, **physical(
        1e-6, 0.1, "m", "disc (Q345B) height, m"))
    pad_height_m: float = Field(108e-6, gt=0, **physical(
        1e-6, 0.1, "m", "pad (Cu-based powder metallurgy) height, m"))
    roughness_amplitude_m: float = Field(8e-6, ge=0, **physical(
        0.0, 1e-2, "m", "largest height of the random sine profiles cut into both surfaces, "
        "m"))
    roughness_modes: int = Field(
        WIDE_FACTOR * JUNCTION_MODES, ge=1, le=64,
        description="highest sine mode k of the random profiles (wavelength width/k)")
    roughness_first_mode: int = Field(
        0, ge=0, le=64, description="lowest sine mode k (wavelength width/k); 0 = "
        "ceil(roughness_modes / 4): wavelengths from width/modes to 4 width/modes, the "
        "band of the one-junction cell (modes 1..4), so a cell n times as wide with n "
        "times the modes has the same asperities")
    clearance_m: float = Field(5e-8, ge=0, **physical(
        0.0, 1e-2, "m", "gap between the pad's lowest and the disc's highest point at the "
        "start, m"))
    seed: int = Field(0, ge=0)

    @model_validator(mode="after")
    def _first_mode(self) -> GeometryCfg:
        if self.roughness_first_mode == 0:  # resolved here: recorded configs hold the k
            self.roughness_first_mode = max(1, math.ceil(self.roughness_modes / 4))
        return self


class RunCfg(StrictModel):
    """Simulated sliding time (s), sampling, numerics."""

    duration_s: float = Field(40e-6, gt=0, le=1e-2)
    distance_m: float = Field(
        0.0, ge=0, le=0.1,
        description="slide this distance (m) instead of duration_s: duration = distance / "
                    "sliding speed, so the conditions of a sweep are compared at the same "
                    "distance (the closed cell's saturated wear depth, docs/braking.md); 0 = "
                    "off; not with duration_s in the same file")
    samples: int = Field(150, ge=2, le=100_000)
    vtk_snapshots: int = Field(6, ge=0, le=10_000)
    micro: Literal["calibrated", "table3"] = "calibrated"
    plate_areal_mass_kg_m2: float = Field(
        0.0, ge=0, le=1e4,
        description="pressure plate mass per area (kg/m^2), e.g. 126 for the omitted pad "
                    "and back plate; 0 = wall_mass_ratio x the cell's pad mass")
    wall_mass_ratio: float = Field(0.05, gt=0, le=1000)
    backing: Literal["absorbing", "support"] = "absorbing"
    local_damping: float = Field(0.0, ge=0, lt=1)
    dt_safety: float = Field(0.3, gt=0, le=1)
    threads: int = Field(0, ge=0, le=256, description="0 = all cores")
    figures: bool = True
    until_steady: bool = Field(
        False, description="slide past duration_s until the wear rate per sliding distance "
                           "is steady (last third within steady_tolerance of the middle "
                           "third), in blocks of 20% of duration_s, at most max_distance_m")
    max_distance_m: float = Field(0.0, ge=0, le=1.0,
                                  description="cap on the sliding distance (m) with "
                                              "until_steady; 0 = 5 x speed x duration_s")
    steady_tolerance: float = Field(0.15, gt=0, le=1)
    ramp_s: float = Field(0.0, ge=0, le=1e-2,
                          description="load ramped linearly from 0 over this sliding time "
                                      "(s); 0 = the full load at once")
    speed_ramp_s: float = Field(0.0, ge=0, le=1e-2,
                                description="the disc starts at rest under the loaded pad "
                                            "and reaches the speed linearly over this "
                                            "time (s); 0 = at speed from the start")
    outlet_length_m: float = Field(
        0.0, ge=0, le=0.1,
        description="debris outlet: a debris component leaves the cell once carried this "
                    "far (m) along the sliding relative to the pad (residence length, e.g. "
                    "a pad plateau, 50-500 um); 0 = closed cell, as in Sha et al. (2022)")
    worn_through_diameters: float = Field(
        2.0, ge=0, le=1000,
        description="stop the run (exit 3, outputs kept) when a body's remaining intact "
                    "thickness outside its anchored layer falls below this many of its "
                    "mean particle diameters (worn through: the boundary layer meets the "
                    "interface); 0 = never stop")
    feed: bool = Field(
        False, description="add a slab of fresh body behind a body's anchored layer "
                           "whenever one slab's thickness has been worn (3 mean particle "
                           "diameters), so slides can be longer than the bodies are thick "
                           "(with outlet_length_m); the bodies are then cut from a block "
                           "periodic in y (docs/braking.md 'Feed')")
    checkpoint_every: int = Field(
        0, ge=0, le=100_000,
        description="samples between checkpoints (checkpoint.npz in the output folder); "
                    "0 = ceil(samples / 10), about every 10% of the run")


class ThermalCfg(StrictModel):
    """Optional temperature boundary curve (CSV: time s, temperature K)."""

    curve: str | None = None
    time_map: Literal["simulated", "stretched"] = "simulated"


class BrakingConfig(PhysicalConfig):
    """``tribodem braking run`` configuration (TOML tables)."""

    condition: ConditionCfg = ConditionCfg()
    geometry: GeometryCfg = GeometryCfg()
    run: RunCfg = RunCfg()
    thermal: ThermalCfg = ThermalCfg()

    @classmethod
    def quick(cls) -> dict[str, Any]:
        """The ``--quick`` preset (a dict shaped like the TOML file, laid over the config):
        a cell one asperity junction wide (144 um, 3 modes of wavelengths 48-144 um) instead
        of the default 16 junctions, a thinner disc (50 um), 20 us of sliding: the pad is
        then in contact only part of the time (docs/braking.md "Wider cells and more
        packings"). Its pad has the default height: a 50-um pad shattered under the first
        impacts at conditions 1-4 (worn through within 0.06-0.55 mm, docs/braking.md
        "Bodies worn through")."""
        return {
            "geometry": {"width_m": 144e-6, "disc_height_m": 50e-6, "pad_height_m": 108e-6,
                         "roughness_amplitude_m": 6e-6, "roughness_modes": 3,
                         "roughness_first_mode": 0},
            "run": {"duration_s": 20e-6, "distance_m": 0.0, "samples": 100,
                    "vtk_snapshots": 4},
        }


#: config fields a resumed run may change (they do not change the results)
RESUME_FREE = ("run.threads", "run.checkpoint_every", "run.figures")


def _check_one_length(src: Source) -> None:
    """``ConfigError`` when the config gives both run lengths, ``run.duration_s`` and a
    non-zero ``run.distance_m``."""
    run = src.data.get("run", {}) if isinstance(src.data.get("run"), dict) else {}
    if "duration_s" in run and run.get("distance_m"):
        raise ConfigError(f"{src.name}: field 'run.duration_s' = {run['duration_s']!r} and "
                          f"'run.distance_m' = {run['distance_m']!r}: give one run length "
                          "(distance_m replaces duration_s)")


def resolve_config(config: ConfigSource | Source = None, *, condition: int | None = None,
                   quick: bool = False) -> BrakingConfig:
    """The run's config: defaults <- ``config`` (a :class:`BrakingConfig`, a dict shaped
    like the TOML file, the path of a TOML file, or None) <- the quick preset (``quick``)
    <- ``condition`` (table 4 index). A :class:`~tribodem.io.record.Source` is a run's
    recorded config (its ``config.toml`` or its checkpoint's), taken as it is. A file or
    a dict may give one run length only (``duration_s`` or ``distance_m``). ``ConfigError``
    names every bad field."""
    if isinstance(config, Source):
        src = config
    else:
        src = read_source(config)
        if not isinstance(config, BaseModel):
            _check_one_length(src)
        if config is None:
            src = Source({}, "braking")
    return resolve_model(BrakingConfig, src.data, source=src.name,
                         quick=BrakingConfig.quick() if quick else None,
                         overrides=None if condition is None else
                         {"condition": {"index": condition}})


def _pressure_speed(c: ConditionCfg) -> tuple[float, float]:
    """(pressure Pa, sliding speed m/s) of the [condition] table; ``ConfigError`` when the
    load or the speed is missing."""
    base = get_condition(c.index) if c.index is not None else None
    if c.pressure_Pa is not None:
        p = c.pressure_Pa
    elif c.load_kN is not None:
        p = load_to_pressure(c.load_kN)
    elif base is not None:
        p = base.pressure_Pa
    else:
        raise ConfigError("braking: no load: give --condition 1..5 or condition.index, "
                          "condition.load_kN or condition.pressure_Pa")
    if c.speed_m_s is not None:
        v = c.speed_m_s
    elif c.rpm is not None:
        v = rpm_to_speed(c.rpm)
    elif base is not None:
        v = base.speed_m_s
    else:
        raise ConfigError("braking: no speed: give --condition 1..5 or condition.index, "
                          "condition.rpm or condition.speed_m_s")
    return p, v


def _geometry(cfg: BrakingConfig) -> Geometry:
    """The cell's :class:`Geometry` (m); ``ConfigError`` when it cannot hold the bodies'
    grains."""
    g = cfg.geometry
    geo = Geometry(width=g.width_m, disc_height=g.disc_height_m, pad_height=g.pad_height_m,
                   amplitude=g.roughness_amplitude_m, modes=g.roughness_modes,
                   first_mode=g.roughness_first_mode, clearance=g.clearance_m, seed=g.seed)
    specs = materials(cfg.run.micro)
    rmax = max(m.radius_range[1] for m in specs)
    try:
        geo.check(rmax)
    except ValueError as err:
        raise ConfigError(f"braking: {err}") from None
    check_cell_memory(cfg)
    return geo


def cell_particles(cfg: BrakingConfig) -> float:
    """About how many grains the cell's two bodies hold (a float: an estimate, infinite for
    a cell too large to count): each body's area (width x height) at the packing's area
    fraction over its grains' mean area, as :func:`tribodem.braking.model.compact_once`
    counts them."""
    g = cfg.geometry
    disc, pad = materials(cfg.run.micro)
    total = 0.0
    for spec, height in ((disc, g.disc_height_m), (pad, g.pad_height_m)):
        rmin, rmax = spec.radius_range
        mean_area = math.pi * (rmin * rmin + rmin * rmax + rmax * rmax) / 3.0
        total += PHI_TARGET * g.width_m * height / mean_area
    return total


def check_cell_memory(cfg: BrakingConfig) -> None:
    """Refuse (``ConfigError`` naming ``geometry.width_m`` and the heights) a cell whose
    grains would not fit in the memory this machine has (:func:`cell_particles`; before
    any output)."""
    g = cfg.geometry
    runs.check_memory(
        cell_particles(cfg), BYTES_PER_PARTICLE, "geometry.width_m",
        given=f"{g.width_m!r} m (disc_height_m {g.disc_height_m!r} m, pad_height_m "
              f"{g.pad_height_m!r} m)", what="the cell's particles",
        allowed="a smaller cell (geometry.width_m x the heights)")


def setup_from_config(cfg: BrakingConfig) -> RunSetup:
    """A ``RunSetup`` from a validated config; ``ConfigError`` when the load or speed is
    missing, the cell too small, the thermal curve missing, or the feed asked for with a
    thermal curve."""
    c = cfg.condition
    p, v = _pressure_speed(c)
    explicit = any(x is not None for x in (c.load_kN, c.pressure_Pa, c.rpm, c.speed_m_s))
    geo = _geometry(cfg)
    curve = None
    if cfg.thermal.curve is not None:
        curve = Path(cfg.thermal.curve)
        if not curve.is_file():
            raise ConfigError(f"braking: thermal.curve = '{curve}': file does not exist")
        try:  # read here, before any output is touched: a bad file changes nothing
            read_curve(curve)
        except ValueError as err:
            raise ConfigError(f"braking: thermal.curve = '{curve}': {err}") from None
    r = cfg.run
    if r.feed and curve is not None:
        raise ConfigError(f"braking: run.feed = true with thermal.curve = '{curve}': the "
                          "feed does not carry temperatures; allowed: one of the two")
    duration = r.distance_m / v if r.distance_m else r.duration_s
    return RunSetup(pressure_Pa=p, speed_m_s=v, duration_s=duration, geometry=geo,
                    condition=None if explicit else c.index, micro=r.micro, samples=r.samples,
                    vtk_snapshots=r.vtk_snapshots, wall_mass_ratio=r.wall_mass_ratio,
                    plate_areal_mass=r.plate_areal_mass_kg_m2 or None, backing=r.backing,
                    local_damping=r.local_damping, dt_safety=r.dt_safety,
                    thermal_curve=curve, thermal_time_map=cfg.thermal.time_map,
                    figures=r.figures, checkpoint_every=r.checkpoint_every,
                    until_steady=r.until_steady, max_distance_m=r.max_distance_m,
                    steady_tolerance=r.steady_tolerance, ramp_s=r.ramp_s,
                    speed_ramp_s=r.speed_ramp_s, outlet_length_m=r.outlet_length_m,
                    worn_through_diameters=r.worn_through_diameters, feed=r.feed)


def config_differences(old: dict[str, Any], new: dict[str, Any]) -> list[tuple[str, Any, Any]]:
    """(field, old, new) of the resolved configs that differ, ``RESUME_FREE`` left out."""
    return config_diffs(old, new, RESUME_FREE)


def checkpoint_config(rec: dict[str, Any], path: Path) -> dict[str, Any] | None:
    """The resolved config a checkpoint's run was made with (``rec``: its braking-loop
    record; None when it has none)."""
    if rec.get("config") is None:
        return None
    return validate(BrakingConfig, rec["config"], source=f"checkpoint '{path}'").model_dump()


def check_same_config(cfg: BrakingConfig, old: dict[str, Any] | None, path: Path) -> None:
    """``ConfigError`` naming the first field (and how many more) in which ``cfg`` differs
    from the checkpoint's config ``old`` (``path``: the checkpoint), ``RESUME_FREE``
    aside; nothing when the checkpoint has no config."""
    if old is None:
        return
    diff = config_differences(old, cfg.model_dump())
    if diff:
        name, a, b = diff[0]
        more = f" (and {len(diff) - 1} more)" if len(diff) > 1 else ""
        raise ConfigError(
            f"--resume: {name} = {b!r} differs from the checkpointed run's {a!r}{more} "
            f"('{path}'); allowed: the same value ({may_change_text(RESUME_FREE)})")
