"""``tribodem fretting run``: the fretting wear loop from a TOML config (issue 5).

Python API: :func:`run_fretting` (config -> files in ``out``, returns the summary).
"""

from __future__ import annotations

import inspect
import json
import time
from pathlib import Path
from typing import Annotated, Any, Literal

import typer
from pydantic import BaseModel, ConfigDict, Field, field_validator

from tribodem import __version__
from tribodem.contact import (
    BACKENDS,
    CAPABILITY_TEXT,
    ElasticBody,
    FirstBodySolver,
    HertzSphere,
    contact_modulus,
    crossed_cylinders,
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
from tribodem.io.config import ConfigError, dump_toml, load_toml, merge, validate
from tribodem.io.results import write_text
from tribodem.materials.en24t import EN24T

CriterionName = Literal["energy", "archard", "s22", "von_mises", "shear", "dfdi", "swt"]
JumpName = Literal["none", "constant", "cojocaru", "moving", "overlapping", "adaptive"]


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid")


class ContactConfig(_Model):
    """First-body case (DESIGN.md default: crossed 8 mm cylinders, 100 N, +-0.3 mm, mu 0.6)."""

    diameter: float = Field(8e-3, gt=0, description="cylinder diameter, m")
    load: float = Field(100.0, gt=0, description="normal load, N")
    friction: float = Field(0.6, ge=0, description="friction coefficient")
    amplitude: float = Field(0.3e-3, gt=0, description="displacement amplitude, m")
    n_increments: int = Field(48, ge=4, description="increments per cycle (multiple of 4)")
    regime: Literal["gross", "ciavarella-jaeger"] = "gross"
    n: int = Field(256, ge=16, le=2048, description="window points per side (even)")
    window: float | None = Field(None, gt=0, description="window side, m (None: 10 radii)")
    tolerance: float = Field(1e-6, gt=0, lt=1, description="normal solver (PKR) tolerance")
    young: float = Field(EN24T.young, gt=0, description="Young's modulus (both bodies), Pa")
    poisson: float = Field(EN24T.poisson, gt=-1, lt=0.5, description="Poisson's ratio")

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
    eps0: float = Field(0.132, gt=0, description="dfdi: uniaxial failure strain eps0 (eq 6.2)")
    swt_nz: int = Field(17, ge=2, le=129, description="swt: subsurface levels")
    swt_plane_step: float = Field(5.0, gt=0, le=90, description="swt: candidate planes, deg")


class PlasticConfig(_Model):
    """``solver = "elastic-plastic"``: tamaas EPIC, bilinear EN24T (seed table 5.1)."""

    yield_strength: float = Field(EN24T.yield_strength, gt=0, description="initial yield, Pa")
    uts: float = Field(EN24T.uts, gt=0, description="ultimate tensile strength, Pa")
    uts_strain: float = Field(EN24T.uts_strain, gt=0, lt=1,
                              description="engineering strain at UTS")
    hardening: float | None = Field(None, ge=0, description="h, Pa (None: bilinear)")
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


class FrettingConfig(_Model):
    """``tribodem fretting run`` configuration (TOML tables contact, wear, jump, output)."""

    cycles: int = Field(160, ge=1, le=10**7)
    solver: str = Field("elastic", description="first-body backend (tribodem.contact.BACKENDS)")
    contact: ContactConfig = Field(default_factory=ContactConfig)
    wear: WearConfig = Field(default_factory=WearConfig)
    jump: JumpConfig = Field(default_factory=JumpConfig)
    plastic: PlasticConfig = Field(default_factory=PlasticConfig)
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


def build_criterion(cfg: FrettingConfig) -> Criterion:
    """The configured criterion; ``ConfigError`` when it cannot run."""
    w = cfg.wear
    name = w.criterion
    stress = {"depth": w.stress_depth, "nz": w.stress_nz, "samples": w.stress_samples}
    params: dict[str, Any] = {
        "energy": {"alpha": w.alpha, "share_upper": w.energy_share_upper},
        "archard": {"k_upper": w.archard_k_upper, "k_lower": w.archard_k_lower},
        "s22": {"yield_strength": w.yield_strength, **stress},
        "von_mises": {"yield_strength": w.yield_strength, **stress},
        "shear": {"uts": w.uts, **stress},
        "dfdi": {"eps0": w.eps0, "depth": w.stress_depth},
        "swt": {"nz": w.swt_nz, "depth": w.stress_depth, "samples": w.stress_samples,
                "plane_step": w.swt_plane_step, "young": cfg.contact.young,
                "poisson": cfg.contact.poisson},
    }.get(name, {})
    try:
        return make_criterion(name, **params)
    except CriterionUnavailable as err:
        raise ConfigError(f"wear.criterion = {name!r}: {err}") from None
    except ValueError as err:
        raise ConfigError(f"wear: {err}") from None


#: Smallest ``contact.window`` allowed, in Hertz contact radii of the unworn bodies.
MIN_WINDOW_RADII = 4.0


def hertz_radius(cfg: FrettingConfig) -> float:
    """Hertz contact radius of the unworn crossed cylinders, m: a = (3 P R / (4 E*))^(1/3),
    R the cylinders' radius (equal crossed cylinders act as a sphere of that radius)."""
    c = cfg.contact
    mat = ElasticBody(young=c.young, poisson=c.poisson)
    return HertzSphere(c.diameter / 2, c.load, contact_modulus(mat, mat)).contact_radius


def check_window(cfg: FrettingConfig) -> None:
    """Refuse (``ConfigError``) a ``contact.window`` that cannot hold the contact.

    The window travels with the upper body and the crossed-cylinder contact stays at its
    centre through the stroke (the lower track grid covers the stroke separately), so the
    window must hold the contact, diameter 2 a, with a margin of a on each side for the
    periodic images and the contact's growth with wear: window >= 4 a.
    """
    c = cfg.contact
    if c.window is None:
        return
    a = hertz_radius(cfg)
    low = MIN_WINDOW_RADII * a
    if c.window < low:
        mat = ElasticBody(young=c.young, poisson=c.poisson)
        raise ConfigError(
            f"contact.window = {c.window!r} m cannot hold the contact: the Hertz contact of "
            f"the crossed cylinders (load {c.load:g} N, E* {contact_modulus(mat, mat):.4g} Pa,"
            f" R {c.diameter / 2:g} m) has radius a = {a:.4g} m; allowed: >= {low:.4g} m "
            f"({MIN_WINDOW_RADII:g} a; the window travels with the upper body, so the stroke "
            "does not enter), or leave it out for 10 a")


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
    have = backend.capabilities.names()
    crit = CRITERIA[cfg.wear.criterion]
    needs = [(f"wear.criterion = {cfg.wear.criterion!r}", crit.requires)]
    if cfg.cycles > 1 and crit.requires_over_cycles:
        needs.append((f"wear.criterion = {cfg.wear.criterion!r} over cycles = {cfg.cycles} "
                      "(allowed with this solver: cycles = 1)", crit.requires_over_cycles))
    if cfg.debris.every is not None:
        needs.append(("debris.every (the debris third body)", frozenset({"debris"})))
    for who, req in needs:
        missing = set(req) - have
        if missing:
            ok = [k for k, b in BACKENDS.items() if set(req) <= b.capabilities.names()]
            raise ConfigError(
                f"{who} needs {', '.join(CAPABILITY_TEXT.get(m, m) for m in sorted(missing))}, "
                f"which solver = {cfg.solver!r} "
                f"({backend.__name__}) does not give; allowed: solver = "
                f"{' or '.join(repr(k) for k in ok) or '(none registered)'}")


def build_solver(cfg: FrettingConfig) -> FirstBodySolver:
    """The configured first-body backend (:data:`tribodem.contact.BACKENDS`) on the case."""
    c = cfg.contact
    mat = ElasticBody(young=c.young, poisson=c.poisson)
    backend = BACKENDS[cfg.solver]
    upper, lower = crossed_cylinders(c.diameter)
    kw: dict[str, Any] = dict(
        load=c.load, friction=c.friction, upper_material=mat, lower_material=mat,
        n=c.n, window=c.window, regime=c.regime, tolerance=c.tolerance)
    if backend.capabilities.plastic:
        kw |= cfg.plastic.model_dump()
    try:
        return backend(upper, lower, **kw)
    except ValueError as err:
        raise ConfigError(f"contact: {err}") from None


def build_loop(cfg: FrettingConfig) -> FrettingLoop:
    """Solver + criterion + strategy from a validated config (``ConfigError`` if unusable)."""
    check_compatible(cfg)
    check_window(cfg)
    crit = build_criterion(cfg)
    c = cfg.contact
    solver = build_solver(cfg)
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
    debris = None
    if cfg.debris.every is not None:
        dc = cfg.debris.model_dump(exclude={"every"})
        try:
            debris = DebrisField(DebrisSettings(young=c.young, poisson=c.poisson, **dc))
        except ValueError as err:
            raise ConfigError(str(err)) from None
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
    else:
        data, source = dict(base or {}), "command line"
    if quick:
        data = merge(QUICK, data) if config is None and base is None else merge(data, QUICK)
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
    return json.loads(json.dumps(cfg.model_dump()))


#: Config fields a resumed run may change: ``cycles`` (raised, to extend a run) and the
#: ``[output]`` table (what is written, not the numbers).
RESUME_MAY_CHANGE = ("cycles", "output.")


def check_resume(cfg: FrettingConfig, meta: dict[str, Any], path: Path) -> None:
    """Refuse (``ConfigError``) resuming checkpoint ``path`` with a different config (every
    differing field named with both values) or fewer cycles than it already has."""
    old = _flat(meta.get("config") or {})
    new = _flat(_jsonable(cfg))
    absent = "<absent>"
    diffs = [f"{k} = {new.get(k, absent)!r} (checkpoint: {old.get(k, absent)!r})"
             for k in sorted(set(old) | set(new))
             if not k.startswith(RESUME_MAY_CHANGE) and old.get(k, absent) != new.get(k, absent)]
    if diffs:
        raise ConfigError(
            f"--resume: the config differs from the one checkpoint '{path}' was made with: "
            + "; ".join(diffs) + "; allowed: the checkpoint's values (only cycles, to extend "
            "the run, and the [output] table may change)")
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
    resolved = cfg.model_dump()
    write_text(out / "config.toml", dump_toml(resolved))
    t0 = time.perf_counter()
    every = max(1, cfg.cycles // 10)
    meta_cfg = _jsonable(cfg)

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
                 **({"params": loop.strategy.params()} if loop.strategy else {})},
        "window_m": loop.solver.window,
        "wall_time_total_s": time.perf_counter() - t0,
        "files": files,
        "config": resolved,
    }
    summary = write_results(hist, out, extra)
    if hist.stopped:
        runs.announce(out, ck, resume_hint="a resume would stop at the same cycle: to go on, "
                      "start a new run with a larger contact.window")
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
    if debris_every is not None and no_debris:
        raise ConfigError("--debris-every and --no-debris: give one of them, not both")
    if debris_every is not None:
        ov.setdefault("debris", {})["every"] = debris_every
    if no_debris:
        ov.setdefault("debris", {})["every"] = None
    runs.check_out_dir(out, "--out", resume=resume, need=(CHECKPOINT,) if resume else ())
    ck = read_checkpoint(out / CHECKPOINT) if resume else None
    cfg = resolve_config(config, quick=quick, overrides=ov,
                         base=ck[0].get("config") if ck is not None else None)
    summary = run_fretting(cfg, out, echo=typer.echo, resume=resume, progress=progress,
                           checkpoint=ck)
    typer.echo(
        f"done: {summary['cycles']} cycles ({summary['cycles_simulated']} simulated, "
        f"{summary['cycles_jumped']} jumped) in {summary['wall_time_s']:.1f} s; worn volume "
        f"upper {summary['wear_volume_upper_m3']:.4g} m^3, lower "
        f"{summary['wear_volume_lower_m3']:.4g} m^3 -> {out}"
    )
