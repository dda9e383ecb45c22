"""``tribodem fretting run``: the fretting wear loop from a TOML config (issue 5).

Python API: :func:`run_fretting` (config -> files in ``out``, returns the summary).
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated, Any, Literal

import typer
from pydantic import BaseModel, ConfigDict, Field, field_validator

from tribodem.contact import ElasticBody, HalfSpaceSolver, crossed_cylinders
from tribodem.cyclejump import STRATEGIES, make_strategy
from tribodem.fretting.criteria import (
    ALPHA_SEED,
    CRITERIA,
    UTS_EN24T,
    YIELD_EN24T,
    Criterion,
    CriterionUnavailable,
    make_criterion,
)
from tribodem.fretting.loop import FrettingHistory, FrettingLoop
from tribodem.fretting.output import write_figures, write_results, write_vtk_surfaces
from tribodem.io.config import ConfigError, dump_toml, load_toml, merge, validate
from tribodem.io.results import write_text

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
    young: float = Field(240e9, gt=0, description="Young's modulus (both bodies), Pa")
    poisson: float = Field(0.3, gt=-1, lt=0.5, description="Poisson's ratio")

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
    archard_k: float = Field(ALPHA_SEED * 0.6, ge=0, description="local Archard k, 1/Pa")
    yield_strength: float = Field(YIELD_EN24T, gt=0, description="Pa (s22, von_mises)")
    uts: float = Field(UTS_EN24T, gt=0, description="Pa (shear: S_us = 0.8 UTS)")
    stress_depth: float | None = Field(None, gt=0, description="subsurface grid depth, m")
    stress_nz: int = Field(33, ge=2, le=257, description="subsurface grid levels")
    stress_samples: int = Field(8, ge=1, description="sampled increments per cycle")


class JumpConfig(_Model):
    strategy: JumpName = "none"
    params: dict[str, Any] = Field(default_factory=dict)


class OutputConfig(_Model):
    figures: bool = True
    vtk: bool = True


class FrettingConfig(_Model):
    """``tribodem fretting run`` configuration (TOML tables contact, wear, jump, output)."""

    cycles: int = Field(160, ge=1, le=10**7)
    solver: Literal["elastic", "elastic-plastic"] = "elastic"
    contact: ContactConfig = Field(default_factory=ContactConfig)
    wear: WearConfig = Field(default_factory=WearConfig)
    jump: JumpConfig = Field(default_factory=JumpConfig)
    output: OutputConfig = Field(default_factory=OutputConfig)


QUICK: dict[str, Any] = {"cycles": 10, "contact": {"n": 64}, "wear": {"stress_nz": 17}}


def build_criterion(cfg: FrettingConfig) -> Criterion:
    """The configured criterion; ``ConfigError`` when it cannot run."""
    w = cfg.wear
    name = w.criterion
    stress = {"depth": w.stress_depth, "nz": w.stress_nz, "samples": w.stress_samples}
    params: dict[str, Any] = {
        "energy": {"alpha": w.alpha},
        "archard": {"k": w.archard_k},
        "s22": {"yield_strength": w.yield_strength, **stress},
        "von_mises": {"yield_strength": w.yield_strength, **stress},
        "shear": {"uts": w.uts, **stress},
    }.get(name, {})
    try:
        return make_criterion(name, **params)
    except CriterionUnavailable as err:
        raise ConfigError(f"wear.criterion = {name!r}: {err}") from None
    except ValueError as err:
        raise ConfigError(f"wear: {err}") from None


def build_loop(cfg: FrettingConfig) -> FrettingLoop:
    """Solver + criterion + strategy from a validated config (``ConfigError`` if unusable)."""
    if cfg.solver == "elastic-plastic":
        raise ConfigError(
            "solver = 'elastic-plastic' is not implemented yet (needs tamaas EPICSolver with "
            "bilinear EN24T hardening); use solver = 'elastic'"
        )
    crit = build_criterion(cfg)
    c = cfg.contact
    mat = ElasticBody(young=c.young, poisson=c.poisson)
    try:
        upper, lower = crossed_cylinders(c.diameter)
        solver = HalfSpaceSolver(upper, lower, load=c.load, friction=c.friction,
                                 upper_material=mat, lower_material=mat, n=c.n,
                                 window=c.window, regime=c.regime, tolerance=c.tolerance)
    except ValueError as err:
        raise ConfigError(f"contact: {err}") from None
    strategy = None
    if cfg.jump.strategy != "none":
        try:
            strategy = make_strategy(cfg.jump.strategy, **cfg.jump.params)
        except (TypeError, ValueError) as err:
            raise ConfigError(f"jump.params for '{cfg.jump.strategy}': {err}") from None
    try:
        return FrettingLoop(solver, crit, amplitude=c.amplitude, n_increments=c.n_increments,
                            strategy=strategy)
    except ValueError as err:
        raise ConfigError(f"wear: {err}") from None


def resolve_config(config: Path | None, quick: bool = False,
                   overrides: dict[str, Any] | None = None) -> FrettingConfig:
    """Defaults <- config file <- ``--quick`` preset <- command-line overrides."""
    data: dict[str, Any] = load_toml(config) if config is not None else {}
    source = str(config) if config is not None else "command line"
    if quick:
        data = merge(QUICK, data) if config is None else merge(data, QUICK)
    data = merge(data, overrides or {})
    return validate(FrettingConfig, data, source=source)


def run_fretting(cfg: FrettingConfig, out: Path, echo: Any = None) -> dict[str, Any]:
    """Run the loop and write results.csv, summary.json, config.toml, figures, VTK to ``out``."""
    loop = build_loop(cfg)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    every = max(1, cfg.cycles // 10)

    def progress(row: dict[str, Any]) -> None:
        if echo is not None and (row["cycle"] % every == 0 or row["cycle"] == cfg.cycles):
            echo(f"cycle {row['cycle']}/{cfg.cycles}{' (jumped)' if row['jumped'] else ''}: "
                 f"wear depth upper {row['wear_depth_upper_m']:.4g} m, lower "
                 f"{row['wear_depth_lower_m']:.4g} m")

    hist: FrettingHistory = loop.run(cfg.cycles, progress=progress)
    resolved = cfg.model_dump()
    write_text(out / "config.toml", dump_toml(_tomlable(resolved)))
    files: list[str] = ["results.csv", "summary.json", "config.toml"]
    if cfg.output.figures:
        files += [p.name for p in write_figures(hist, out)]
    if cfg.output.vtk:
        files += [p.name for p in write_vtk_surfaces(hist, out)]
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
    return write_results(hist, out, extra)


def _tomlable(d: dict[str, Any]) -> dict[str, Any]:
    return {k: _tomlable(v) if isinstance(v, dict) else ("none" if v is None else v)
            for k, v in d.items()}


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
        "--solver", help="elastic or elastic-plastic.")] = None,
    quick: Annotated[bool, typer.Option("--quick", help="64^2 grid, 10 cycles.")] = False,
) -> None:
    """Run the fretting wear loop; writes results.csv, summary.json, figures, VTK to --out."""
    ov: dict[str, Any] = {}
    if criterion is not None:
        ov.setdefault("wear", {})["criterion"] = criterion
    if cycles is not None:
        ov["cycles"] = cycles
    if jump is not None:
        ov.setdefault("jump", {})["strategy"] = jump
    if solver is not None:
        ov["solver"] = solver
    cfg = resolve_config(config, quick=quick, overrides=ov)
    summary = run_fretting(cfg, out, echo=typer.echo)
    typer.echo(
        f"done: {summary['cycles']} cycles ({summary['cycles_simulated']} simulated, "
        f"{summary['cycles_jumped']} jumped) in {summary['wall_time_s']:.1f} s; worn volume "
        f"upper {summary['wear_volume_upper_m3']:.4g} m^3, lower "
        f"{summary['wear_volume_lower_m3']:.4g} m^3 -> {out}"
    )
    if summary["stopped"]:
        typer.echo(f"run stopped: {summary['stopped']}", err=True)
        raise typer.Exit(3)
