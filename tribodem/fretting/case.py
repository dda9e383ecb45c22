"""One fretting case, resolved once from a config: the geometry, the two bodies, E*, the
window, the total load and the unworn contact's size (:class:`FrettingCase`), the checks
made on it before any work, and the first-body solver and the fretting loop built on it
(:func:`build_solver`, :func:`build_loop`).

Every quantity is derived here once; the checks and the builders take the case.
"""

from __future__ import annotations

import inspect
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from tribodem.contact import (
    BACKENDS,
    CAPABILITY_TEXT,
    ElasticBody,
    FirstBodySolver,
    contact_modulus,
)
from tribodem.contact.base import ContactCase
from tribodem.contact.fe.ccx import CcxNotFoundError
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
from tribodem.cyclejump import STRATEGIES, JumpStrategy, make_strategy
from tribodem.dem.clumps import debris_template
from tribodem.dem.state import BYTES_PER_PARTICLE
from tribodem.fretting.config import (
    GEOMETRY_FIELDS,
    FrettingConfig,
    option_tables,
    runs_ccx,
)
from tribodem.fretting.criteria import CRITERIA, Criterion, CriterionUnavailable, make_criterion
from tribodem.fretting.debris import SHAPES, DebrisField, DebrisSettings, particle_count
from tribodem.fretting.loop import FrettingLoop
from tribodem.io import runs
from tribodem.io.config import ConfigError

#: Window side when ``contact.window`` is left out, in contact radii (or half-widths).
WINDOW_RADII = 10.0

#: Smallest ``contact.window`` allowed, in Hertz contact radii of the unworn bodies.
MIN_WINDOW_RADII = 4.0


@dataclass(frozen=True)
class FrettingCase:
    """The first-body case of a config, derived once (SI units).

    ``geometry``: the ``[contact]`` geometry (height maps read); ``upper_material`` /
    ``lower_material``: the two bodies (Pa, -); ``modulus``: their contact modulus E*, Pa;
    ``window``: the window side the solver gets, m (None: the solver's own estimate from
    the surfaces' curvature); ``load``: the total normal load on the window, N;
    ``half_size``: (description, the unworn analytic contact's largest half-size along a
    checked direction, m), None for height maps; ``contact``: "point" or "line" (None for
    height maps: the solver finds it from the maps); ``contact_case``: what the first-body
    backend is built from (:class:`~tribodem.contact.base.ContactCase`: the recessions,
    the bodies, the load, the stroke, the window).
    """

    config: FrettingConfig
    geometry: Geometry
    upper_material: ElasticBody
    lower_material: ElasticBody
    modulus: float
    window: float | None
    load: float
    half_size: tuple[str, float] | None
    contact: str | None
    contact_case: ContactCase
    #: how the window was chosen (summary.json's ``contact_case.window_reason``)
    window_reason: str = ""
    #: the cycles a window left out was sized for (:func:`scar_window`)
    sizing_cycles: int = 0

    @classmethod
    def of(cls, cfg: FrettingConfig, sizing_cycles: int | None = None) -> FrettingCase:
        """The case of a validated config: first its criterion and debris checked against
        the backend (:func:`check_compatible`), then derived (``ConfigError`` naming the
        field when the materials, the geometry or the height maps cannot be used).

        ``sizing_cycles``: the cycles the window left out is sized for (:func:`scar_window`;
        default ``cfg.cycles``; a resumed run passes the cycles its checkpoint was made
        for, so its grids keep their size)."""
        check_compatible(cfg)
        sizing_cycles = cfg.cycles if sizing_cycles is None else int(sizing_cycles)
        geo = case_geometry(cfg)
        up, lo = case_materials(cfg)
        es = contact_modulus(up, lo)
        window = case_window(cfg, geo, es)
        c = cfg.contact
        if c.load_per_length is not None and window is None:
            raise ConfigError("contact.load_per_length needs a window (m)")
        load = c.load_per_length * window if c.load_per_length is not None else c.load
        assert load is not None
        n, reason = c.n, ("contact.window" if c.window is not None else
                          f"{WINDOW_RADII:g} contact radii (half-widths) of the unworn contact")
        if c.window is None and not isinstance(geo, HeightMaps):
            sized = scar_window(cfg, geo, es, window, load, sizing_cycles)
            if sized is not None:
                new_window, n, reason = sized
                if window is not None and isinstance(geo, CylinderOnFlat):
                    load *= new_window / window  # the same load per unit length
                window = new_window
        contact = getattr(geo, "contact", None)
        upper, lower = geo.recessions()
        first_body = ContactCase(
            upper=upper, lower=lower, upper_material=up, lower_material=lo, load=load,
            friction=c.friction, amplitude=c.amplitude, n_increments=c.n_increments, n=n,
            window=window, regime=c.regime, tolerance=c.tolerance, contact=contact,
            stress_depth=cfg.wear.stress_depth)
        return cls(config=cfg, geometry=geo, upper_material=up, lower_material=lo,
                   modulus=es, window=window, load=load,
                   half_size=contact_half_size(cfg, geo, es, window, load),
                   contact=contact, contact_case=first_body, window_reason=reason,
                   sizing_cycles=sizing_cycles)

    @property
    def hertz_radius(self) -> float:
        """Contact radius (m) of the unworn analytic geometry (line contact: half-width; 0
        for height maps): for the default crossed cylinders a = (3 P R / (4 E*))^(1/3)."""
        return 0.0 if self.half_size is None else self.half_size[1]

    def summary(self, solver: FirstBodySolver) -> dict[str, Any]:
        """What ran (summary.json's ``contact_case``): geometry and its parameters, contact
        type, load (and which was given), window, the two bodies and E* (SI)."""
        c = self.config.contact
        up, lo = self.upper_material, self.lower_material
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
        out["window_points"] = solver.n
        out["window_reason"] = self.window_reason
        return out


# ---------------------------------------------------------------- deriving the case

def case_materials(cfg: FrettingConfig) -> tuple[ElasticBody, ElasticBody]:
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


def map_limits(geo: HeightMaps, n: int, amplitude: float, window: float
               ) -> list[tuple[str, str, float, float]]:
    """(field, axis, needed half-extent, available half-extent) of each map (m) for a
    window ``window`` (m) of ``n`` points and a stroke of +-``amplitude`` (m): the upper
    map covers the window, the lower one the window plus the stroke along x (the track
    grid)."""
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
    w = min(2 * have for *_, have in map_limits(geo, c.n, c.amplitude, 1.0)) or 1.0
    for _ in range(200):
        if all(need <= have * (1 + 1e-9) for *_, need, have in
               map_limits(geo, c.n, c.amplitude, w)):
            return w
        w *= 0.99
    raise ConfigError(f"contact.lower_map = {c.lower_map!r}: the map is too short along x for "
                      f"the stroke (amplitude {c.amplitude:g} m) plus a window")


def case_window(cfg: FrettingConfig, geo: Geometry, modulus: float) -> float | None:
    """The window side (m) the solver gets: ``contact.window``, else ``WINDOW_RADII`` contact
    radii (line contact: half-widths; None = the solver's own estimate of the Hertz radius
    from the surfaces' curvature, for crossed cylinders of equal radii and the sphere; height
    maps: the largest window the maps cover). ``modulus``: E*, Pa."""
    c = cfg.contact
    if c.window is not None:
        return c.window
    if isinstance(geo, SphereOnFlat) or (isinstance(geo, CrossedCylinders)
                                         and geo.radius_upper == geo.radius_lower):
        return None
    if isinstance(geo, CylinderOnFlat):
        if c.load_per_length is not None:
            return WINDOW_RADII * geo.hertz(c.load_per_length, modulus).half_width
        assert c.load is not None
        return line_window(geo.radius, c.load, modulus, WINDOW_RADII)
    if isinstance(geo, HeightMaps):
        return map_window(cfg, geo)
    assert c.load is not None  # a point contact: load_per_length is cylinder_on_flat's
    return WINDOW_RADII * max(geo.contact_size(c.load, modulus))


#: a window sized for the scar holds this many predicted worn contact half-sizes
SCAR_WINDOW_HALF_SIZES = 5.0
#: the most window points along x a line contact on one cross-section is given
LINE_POINTS_MAX = 16384


def worn_areas(cfg: FrettingConfig, load: float, cycles: int) -> tuple[float, float] | None:
    """(upper, lower) worn volume after ``cycles`` gross-slip cycles that a rate criterion
    predicts for a total load ``load`` (N), m^3: Archard k_body P s and the energy law's
    alpha mu P s shared share_upper : 1 - share_upper, with the sliding distance
    s = 4 A cycles (gross slip: an upper bound); None for the threshold criteria, whose
    wear is not known before they run."""
    w = cfg.wear
    s = 4.0 * cfg.contact.amplitude * cycles
    if w.criterion == "archard":
        return w.archard_k_upper * load * s, w.archard_k_lower * load * s
    if w.criterion == "energy":
        total = w.alpha * cfg.contact.friction * load * s
        return w.energy_share_upper * total, (1.0 - w.energy_share_upper) * total
    return None


def scar_window(cfg: FrettingConfig, geo: Geometry, modulus: float, window: float | None,
                load: float, cycles: int) -> tuple[float, int, str] | None:
    """The window that holds the scar a rate criterion predicts over ``cycles``, with its
    points and the reason: (window m, points per side, text); None when the default
    window holds it (or the criterion's wear is not known in advance).

    The worn volume of both bodies (:func:`worn_areas`), taken off the curved upper body
    as a flat cap, gives the worn contact's half-size b: a cylinder of radius R worn by an
    area A' per unit length has b = (3 R A' / 2)^(1/3) (the cap's area 2 b^3 / (3 R)), a
    sphere worn by a volume V has b = (4 R V / pi)^(1/4) (pi b^4 / (4 R)). Putting the
    lower body's wear on the upper one overestimates b (the flat's wear is spread over the
    stroke): the window is conservative. It holds :data:`SCAR_WINDOW_HALF_SIZES` b. A line
    contact solved on one cross-section keeps the default window's spacing (more points,
    cheap there); every other solver keeps its points (a coarser spacing)."""
    areas = worn_areas(cfg, load, cycles)
    c = cfg.contact
    if areas is None:
        return None
    default = window
    if isinstance(geo, CylinderOnFlat):
        assert window is not None
        per_length = sum(areas) / window
        b = (1.5 * geo.radius * per_length) ** (1.0 / 3.0)
    elif isinstance(geo, SphereOnFlat | CrossedCylinders):
        r = geo.radius if isinstance(geo, SphereOnFlat) else min(geo.radius_upper,
                                                                 geo.radius_lower)
        b = (4.0 * r * sum(areas) / math.pi) ** 0.25
        if default is None:
            default = WINDOW_RADII * max(geo.contact_size(load, modulus))
    else:
        return None
    need = SCAR_WINDOW_HALF_SIZES * b
    if default is None or need <= default:
        return None
    n = c.n
    if one_section(cfg, geo):
        dx = default / c.n
        n = min(LINE_POINTS_MAX, 2 * math.ceil(need / dx / 2))
        need = n * dx
    law = {"archard": "Archard k_body P s", "energy": "alpha mu P s"}[cfg.wear.criterion]
    return need, n, (
        f"sized for the scar: after {cycles} cycles ({law}, s = 4 A per cycle) the worn "
        f"contact's half-size is at most {b:.4g} m, so the window holds "
        f"{SCAR_WINDOW_HALF_SIZES:g} of it ({need:.4g} m, {n} points; the default, "
        f"{WINDOW_RADII:g} contact radii, is {default:.4g} m"
        + (", and the load per unit length is kept)" if isinstance(geo, CylinderOnFlat)
           else ")"))


def one_section(cfg: FrettingConfig, geo: Geometry) -> bool:
    """Whether the solver solves the line contact on one cross-section (grids [n, 1])."""
    return (isinstance(geo, CylinderOnFlat) and cfg.solver == "elastic"
            and cfg.elastic.line_model == "plane-strain")


def contact_half_size(cfg: FrettingConfig, geo: Geometry, modulus: float,
                      window: float | None, load: float) -> tuple[str, float] | None:
    """(description, largest contact half-size along a checked direction, m) of the unworn
    analytic geometry (None for height maps) under E* ``modulus`` (Pa) and the total load
    ``load`` (N) on a window of side ``window`` (m): Hertz radius (the larger semi-axis for
    crossed cylinders of unequal radii), the line contact's half-width along x (P' = load /
    window or load_per_length), the rounded punch's contact radius."""
    c = cfg.contact
    es = modulus
    if isinstance(geo, HeightMaps):
        return None
    if isinstance(geo, CylinderOnFlat):
        pl = c.load_per_length
        if pl is None:
            assert c.load is not None and window is not None
            pl = c.load / window
        return (f"the Hertz line contact of the cylinder (R {geo.radius:g} m, P' {pl:.4g} N/m, "
                f"E* {es:.4g} Pa) has half-width a", geo.hertz(pl, es).half_width)
    what = {"crossed_cylinders": "the Hertz contact of the crossed cylinders (R "
                                 f"{getattr(geo, 'radius_upper', 0):g} and "
                                 f"{getattr(geo, 'radius_lower', 0):g} m",
            "sphere_on_flat": f"the Hertz contact of the sphere (R {getattr(geo, 'radius', 0):g} m",
            "flat_punch": "the contact of the rounded flat punch (punch radius "
                          f"{getattr(geo, 'punch_radius', 0):g} m, edge radius "
                          f"{getattr(geo, 'edge_radius', 0):g} m"}[geo.name]
    return f"{what}, load {load:g} N, E* {es:.4g} Pa) has radius a", max(
        geo.contact_size(load, es))


# ---------------------------------------------------------------- checks before any work

def check_window(case: FrettingCase) -> None:
    """Refuse (``ConfigError``) a ``contact.window`` that cannot hold the contact.

    The window travels with the upper body and the contact stays at its centre through the
    stroke (the lower track grid covers the stroke separately), so the window must hold the
    contact, width 2 a, with a margin of a on each side for the periodic images and the
    contact's growth with wear: window >= 4 a, along every direction in which the contact
    can reach an edge (a line contact, periodic along y by design: x only); and its spacing
    window / n must resolve the contact: at most a (a contact of a node or two is no
    solution; also for a window sized for the scar). The memory the run's arrays need is
    checked first (:func:`check_allocations`). Height maps: the maps must cover the window
    (and the lower one the stroke); the contact itself is checked by a solve
    (:func:`check_solved_window`).
    """
    check_allocations(case)
    c = case.config.contact
    geo = case.geometry
    if isinstance(geo, HeightMaps):
        w = case.window
        assert w is not None
        for field, axis, need, have in map_limits(geo, c.n, c.amplitude, w):
            if need > have * (1 + 1e-9):
                raise ConfigError(
                    f"contact.{field} = {getattr(c, field)!r}: the map spans +-{have:.4g} m "
                    f"along {axis} about its centre but the window ({w:.4g} m"
                    f"{'' if c.window is not None else ', contact.window left out'}"
                    f"{', plus the stroke' if field == 'lower_map' and axis == 'x' else ''}"
                    f") needs +-{need:.4g} m; allowed: a larger map or a smaller "
                    "contact.window")
        return
    assert case.half_size is not None
    what, a = case.half_size
    low = MIN_WINDOW_RADII * a
    if c.window is not None and c.window < low:
        along = " along x (a line contact is periodic along y)" if geo.contact == "line" else ""
        raise ConfigError(
            f"contact.window = {c.window!r} m cannot hold the contact: {what} = {a:.4g} m; "
            f"allowed: >= {low:.4g} m ({MIN_WINDOW_RADII:g} a{along}; the window travels with "
            f"the upper body, so the stroke does not enter), or leave it out for "
            f"{WINDOW_RADII:g} a")
    n = case.contact_case.n
    window = case.window if case.window is not None else WINDOW_RADII * a
    if window / n > a:  # a contact of a node or two: the normal solve cannot resolve it
        given = (f"contact.window = {c.window!r} m" if c.window is not None else
                 f"the window ({window:.4g} m, {case.window_reason}; contact.window left out)")
        raise ConfigError(
            f"{given} does not resolve the contact: its spacing window / n = "
            f"{window / n:.4g} m (n = {n} points) is larger than the contact's radius: "
            f"{what} = {a:.4g} m; allowed: a spacing of at most a (contact.window <= "
            f"{a * n:.4g} m, or a larger contact.n)")


#: bytes per cell of the lower body's track grid: the loop's maps (cumulative wear, the
#: last cycle's increment, the pressure at the loading position), the criterion's depth
#: maps and the states a jump strategy keeps
TRACK_CELL_BYTES = 16 * 8
#: bytes per recorded cycle (its row of results.csv and its jump record, held in memory)
ROW_BYTES = 1024.0


def check_allocations(case: FrettingCase) -> None:
    """Refuse (``ConfigError`` naming the field) a run whose arrays would not fit in the
    memory this machine has (:func:`tribodem.io.runs.check_memory`), before any work: the
    lower body's track grid (the window plus twice ``contact.amplitude`` at the window's
    spacing; a window left out: 10 contact radii, as the solver sizes it), the cycles'
    rows and, for a rate criterion with the debris third body, the particles its
    predicted worn volume makes (:func:`worn_areas`, gross slip: an upper bound)."""
    cfg = case.config
    c = cfg.contact
    n = case.contact_case.n
    window = case.window if case.window is not None else WINDOW_RADII * case.hertz_radius
    if window > 0:
        dx = window / n
        ny = 1 if one_section(cfg, case.geometry) else n
        cells = (n + 2.0 * (c.amplitude / dx + 2.0)) * ny
        fits = runs.available_memory() * 0.8 / TRACK_CELL_BYTES / ny  # cells along x
        runs.check_memory(
            cells, TRACK_CELL_BYTES, "contact.amplitude", given=f"{c.amplitude!r} m",
            what=f"the lower body's track grid cells (the window, {window:.4g} m, plus "
                 f"twice the amplitude at the window's spacing {dx:.4g} m, x {ny} points)",
            allowed=f"an amplitude of at most about {max(0.0, fits - n) * dx / 2:.4g} m on "
                    "this window")
    runs.check_memory(cfg.cycles, ROW_BYTES, "cycles")
    areas = worn_areas(cfg, case.load, cfg.cycles) if cfg.debris.every is not None else None
    if areas is not None:
        d = cfg.debris
        spheres = sum(share * debris_template(shape, d.diameter).radii.size
                      for share, shape in zip(d.shares, SHAPES, strict=True))
        count = particle_count(sum(areas), d.diameter, d.volume_correction)
        runs.check_memory(
            count, spheres * BYTES_PER_PARTICLE, "debris.diameter", given=f"{d.diameter!r} m",
            what=f"the debris particles the predicted worn volume makes over {cfg.cycles} "
                 f"cycles ({sum(areas):.3g} m^3, gross slip)",
            allowed="a larger debris.diameter, fewer cycles, or a smaller wear coefficient")


def check_solved_window(case: FrettingCase, solver: FirstBodySolver) -> None:
    """For height maps (no analytic contact size): solve the loaded contact at offset 0 and
    refuse (``ConfigError`` naming ``contact.window``) a contact on the window's edge along
    a checked direction (solvers without a separate loaded solution: skipped)."""
    c = case.config.contact
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
    chosen first-body backend cannot give, naming both and the backends that would do.

    Takes the config, not the case: it compares names only (solver, criterion, geometry,
    debris), so a study can skip a stage on it without reading height maps."""
    backend = BACKENDS[cfg.solver]
    have = backend.capabilities_for(option_tables(cfg)).names()
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


# ---------------------------------------------------------------- the parts of the loop

def build_criterion(case: FrettingCase) -> Criterion:
    """The configured criterion; ``ConfigError`` when it cannot run."""
    w = case.config.wear
    name = w.criterion
    up, lo = case.upper_material, case.lower_material
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


def build_strategy(cfg: FrettingConfig) -> JumpStrategy | None:
    """The configured cycle-jumping strategy (None for ``jump.strategy = "none"``;
    ``ConfigError`` naming ``jump.params`` when its parameters cannot be used). The
    adaptive and polynomial strategies decide on the worn volume unless ``decide_on`` is
    given (docs/fretting.md)."""
    if cfg.jump.strategy == "none":
        return None
    check_jump_params(cfg.jump.strategy, cfg.jump.params)
    try:
        params = dict(cfg.jump.params)
        if cfg.jump.strategy in ("adaptive", "polynomial"):
            params.setdefault("decide_on", "total")
        return make_strategy(cfg.jump.strategy, **params)
    except (TypeError, ValueError) as err:
        raise ConfigError(f"jump.params for '{cfg.jump.strategy}': {err}") from None


def debris_settings(case: FrettingCase) -> DebrisSettings:
    """The debris particles of the ``[debris]`` table (``ConfigError`` if unusable); they take
    the lower body's (the track's) material."""
    lo = case.lower_material
    try:
        return DebrisSettings(young=lo.young, poisson=lo.poisson,
                              **case.config.debris.model_dump(exclude={"every"}))
    except ValueError as err:
        raise ConfigError(str(err)) from None


def build_solver(case: FrettingCase | FrettingConfig) -> FirstBodySolver:
    """The configured first-body backend (:data:`tribodem.contact.BACKENDS`) on the case
    (a config: on its case, :meth:`FrettingCase.of`), built by the backend from the
    first-body case and the option tables it reads
    (:meth:`~tribodem.contact.FirstBodySolver.from_case`); ``ConfigError`` when it cannot
    be built (an option it refuses, no ccx, a case it cannot solve: ``contact: ...``)."""
    if isinstance(case, FrettingConfig):
        case = FrettingCase.of(case)
    cfg = case.config
    backend = BACKENDS[cfg.solver]
    try:
        return backend.from_case(case.contact_case, option_tables(cfg))
    except ConfigError:
        raise
    except CcxNotFoundError as err:
        raise ConfigError(f"solver = {cfg.solver!r}: {err}; allowed: another solver "
                          f"({', '.join(k for k in BACKENDS if k != cfg.solver)})") from None
    except ValueError as err:
        raise ConfigError(f"contact: {err}") from None


def preflight(cfg: FrettingConfig) -> FrettingCase:
    """The checks :func:`build_loop` makes before the solver is built (``ConfigError``):
    the case (criterion and backend compatible; materials, geometry, height maps), the
    window, the criterion, the jumping, the debris settings and ccx's threads. Returns the
    case."""
    case = FrettingCase.of(cfg)
    check_window(case)
    build_criterion(case)
    build_strategy(cfg)
    if cfg.debris.every is not None:
        debris_settings(case)
    if runs_ccx(cfg.solver):
        runs.check_threads(cfg.fe.threads, "fe.threads")
    return case


def build_loop(cfg: FrettingConfig, case: FrettingCase | None = None) -> FrettingLoop:
    """Solver + criterion + strategy from a validated config (``ConfigError`` if unusable).
    ``case``: the config's case (:meth:`FrettingCase.of`) when it is already derived."""
    case = FrettingCase.of(cfg) if case is None else case
    check_window(case)
    crit = build_criterion(case)
    c = cfg.contact
    solver = build_solver(case)
    if c.geometry == "height_map":
        check_solved_window(case, solver)
    strategy = build_strategy(cfg)
    debris = DebrisField(debris_settings(case)) if cfg.debris.every is not None else None
    try:
        return FrettingLoop(solver, crit, amplitude=c.amplitude, n_increments=c.n_increments,
                            strategy=strategy, debris=debris,
                            debris_every=cfg.debris.every or 1,
                            geometry_tolerance=cfg.jump.geometry_tolerance or None,
                            update_tolerance=cfg.wear.update_tolerance or None)
    except ValueError as err:  # CriterionUnavailable included
        raise ConfigError(f"wear: {err}") from None
