"""Write the generated reference pages of the docs from the code, so they cannot drift.

- ``docs/reference/config.md``: every key of the config files (the pydantic models
  ``FrettingConfig``, ``BrakingConfig``, ``DemRunConfig``, walked recursively through
  ``model_fields``): dotted key, type, default, allowed range (the ``ge``/``gt``/``le``/``lt``
  of the field), unit (from the field's name or description) and description; the
  ``--quick`` presets; the parameters of each cycle-jumping strategy (``[jump] params``);
  the options of ``tribodem calibrate``, which has no config file.
- ``docs/reference/cli.md``: every command of ``tribodem`` with its options (type,
  default, range, help), read from the typer app.

Usage (from the repository root)::

    .venv/bin/python tools/config_reference.py           # rewrite the pages
    .venv/bin/python tools/config_reference.py --check   # exit 1 when a page differs

CI runs the check (``tests/test_docs.py``). Descriptions come from the code: to change one,
edit the model's ``Field(description=...)`` or the option's ``help=`` and run this script.
"""

from __future__ import annotations

import argparse
import difflib
import inspect
import re
import sys
import types
import typing
from pathlib import Path
from typing import Any, Literal

ROOT = Path(__file__).resolve().parent.parent
CONFIG_PAGE = ROOT / "docs" / "reference" / "config.md"
CLI_PAGE = ROOT / "docs" / "reference" / "cli.md"

#: The source works as the code's messages name them.
LEGEND = (
    "In the descriptions, which come from the code, *seed 000* is the braking study of "
    "Sha et al., Lubricants 10 (2022) 136, and *seed 003* is P. Lu's thesis, Numerical "
    "Modelling of Fretting Wear and Debris Particles (University of Exeter, 2018); "
    "\"the seed's\" means the source work's."
)

#: Units written as a suffix of a field's name (the braking tables), or as its name.
NAME_UNITS = (("_kg_m2", "kg/m^2"), ("_m_s", "m/s"), ("_kN", "kN"), ("_MPa", "MPa"),
              ("_Pa", "Pa"), ("_m", "m"), ("_s", "s"))
EXACT_UNITS = {"rpm": "r/min"}

#: Descriptions of the keys whose model field has none yet (dotted key, as in the page):
#: used only while the field's ``Field(description=...)`` is empty. Move them into the
#: models; an entry whose field has a description in the code is not used.
MISSING: dict[str, str] = {
    # braking
    "condition.load_kN": "brake load, kN (table 4; turned into the pad pressure by the "
    "pad area the table implies: 13 kN -> 0.33 MPa)",
    "condition.pressure_Pa": "pressure on the pad, Pa (instead of load_kN)",
    "condition.rpm": "disc speed, r/min (table 4; turned into the sliding speed at the "
    "friction radius the table implies: 1200 r/min -> 47.12 m/s)",
    "condition.speed_m_s": "sliding speed, m/s (instead of rpm)",
    "geometry.width_m": "cell width along the sliding (periodic), m",
    "geometry.disc_height_m": "disc (Q345B) height, m",
    "geometry.pad_height_m": "pad (Cu-based powder metallurgy) height, m",
    "geometry.roughness_amplitude_m": "largest height of the random sine profiles cut into "
    "both surfaces, m",
    "geometry.roughness_modes": "highest sine mode k of the surface profiles (wavelength "
    "width / k)",
    "geometry.clearance_m": "gap between the pad's lowest and the disc's highest point at "
    "the start, m",
    "geometry.seed": "packing and roughness seed (a sweep's packing k runs seed + k)",
    "run.duration_s": "simulated sliding time, s (mapped to braking time by the identity, "
    "stated in summary.json)",
    "run.samples": "measurement samples over the run (rows of timeseries.csv)",
    "run.vtk_snapshots": "VTK snapshots of the particles and force chains over the run "
    "(0: none)",
    "run.micro": "micro-parameters: calibrated, E_c and kratio of tribodem calibrate with "
    "table 3's strengths; table3, the source work's table 3 as printed",
    "run.wall_mass_ratio": "pressure plate mass / the cell's pad mass (when "
    "plate_areal_mass_kg_m2 is 0)",
    "run.backing": "the pad's back face: absorbing, non-reflecting dashpots standing for "
    "the omitted pad; support, its top layer held in x and free in y",
    "run.local_damping": "local (PFC) damping coefficient while sliding (0: none)",
    "run.dt_safety": "time step / the critical time step",
    "run.figures": "write the PNG figures",
    "run.steady_tolerance": "until_steady: the last third's wear rate within this "
    "fraction of the middle third's",
    "thermal.curve": "temperature boundary curve: the path of a CSV file of time in s and "
    "temperature in K, applied to every particle (left out: no thermal load)",
    "thermal.time_map": "simulated, the curve's time is the simulated time; stretched, the "
    "curve squeezed into the simulated window (an explicit distortion)",
    # dem demo
    "case.kind": "settle3d: Hertz-Mindlin spheres settling under gravity in an open box; "
    "compress2d: linear-contact disks compressed by two platens",
    "case.seed": "random seed of the particle placement",
    "run.steps": "time steps to run (a resume may raise it)",
    "output.scalars_every": "steps between rows of timeseries.csv",
    "output.vtk_every": "steps between VTK snapshots (0: none)",
    "output.checkpoint_every": "steps between checkpoints (0: none)",
}

#: Units recognised in a description, longest first: after ", " or "(" or at the start,
#: followed by the end, a space, ",", ";" or ")".
DESCRIPTION_UNITS = ("m^3/J", "kg/m^2", "1/Pa", "N/m", "m/s", "1/K", "GPa", "MPa", "Pa",
                     "Hertz radii", "deg", "steps", "N", "m", "s", "K", "J")
_UNIT_RE = re.compile(
    r"(?:^|, |\()(" + "|".join(re.escape(u) for u in DESCRIPTION_UNITS) + r")(?=$|[ ,;)])")


def clean(text: str | None) -> str:
    """A docstring or description as one markdown line: reST literals and roles as code,
    pipes escaped."""
    if not text:
        return ""
    text = " ".join(text.split())
    text = re.sub(r":[a-z]+:`~?([^`]+)`", lambda m: f"`{m.group(1).split('.')[-1]}`", text)
    text = text.replace("``", "`")
    return text.replace("|", "\\|")


def first_paragraph(text: str | None) -> str:
    """The first paragraph of a docstring, cleaned."""
    return clean((text or "").strip().split("\n\n")[0])


def unit_of(name: str, description: str | None) -> str:
    """The field's unit: from its name's suffix, else from its description, else "-"."""
    if name in EXACT_UNITS:
        return EXACT_UNITS[name]
    for suffix, unit in NAME_UNITS:
        if name.endswith(suffix):
            return unit
    m = _UNIT_RE.search(description or "")
    return m.group(1) if m else "-"


def fmt_value(v: Any) -> str:
    """A default as it would be written in TOML (None: left out)."""
    if v is None:
        return "left out"
    if isinstance(v, bool):
        return f"`{str(v).lower()}`"
    if isinstance(v, float):
        return f"`{fmt_number(v)}`"
    if isinstance(v, int):
        return f"`{v}`"
    if isinstance(v, str):
        return f'`"{v}"`'
    if isinstance(v, tuple | list):
        return "`[" + ", ".join(fmt_value(x).strip("`") for x in v) + "]`"
    if isinstance(v, dict):
        return "`{}`" if not v else f"`{v}`"
    return f"`{v}`"


def fmt_number(v: float) -> str:
    """A float in 10 significant digits, large values with an exponent (6.8e+08)."""
    text = f"{v:.10g}"
    if "e" not in text and abs(v) >= 1e5:
        mantissa, exp = f"{v:.10e}".split("e")
        text = mantissa.rstrip("0").rstrip(".") + "e" + exp
    return text


def fmt_type(annotation: Any) -> str:
    """A field's type in words."""
    origin = typing.get_origin(annotation)
    if origin is Literal:
        return "one of " + ", ".join(f'`"{a}"`' if isinstance(a, str) else f"`{a}`"
                                     for a in typing.get_args(annotation))
    if origin in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(annotation) if a is not type(None)]
        inner = " or ".join(fmt_type(a) for a in args)
        return inner + " (may be left out)" if len(args) < len(typing.get_args(annotation)) \
            else inner
    if origin is tuple:
        args = typing.get_args(annotation)
        return f"{len(args)} numbers" if all(a is float for a in args) else "list"
    if origin is dict or annotation is dict:
        return "table"
    return {int: "integer", float: "number", bool: "true / false", str: "string"}.get(
        annotation, getattr(annotation, "__name__", str(annotation)))


def fmt_range(metadata: list[Any]) -> str:
    """The bounds of a field (annotated_types Ge / Gt / Le / Lt) as text."""
    out = []
    for m in metadata:
        for attr, sym in (("ge", ">="), ("gt", ">"), ("le", "<="), ("lt", "<")):
            v = getattr(m, attr, None)
            if v is not None:
                out.append(f"{sym} {fmt_number(v)}" if isinstance(v, float) else f"{sym} {v}")
    return ", ".join(out) if out else "-"


def is_model(annotation: Any) -> bool:
    from pydantic import BaseModel

    return isinstance(annotation, type) and issubclass(annotation, BaseModel)


def field_default(field: Any) -> Any:
    if field.default_factory is not None:
        return field.default_factory()
    return field.default


def filled_in(model: Any) -> dict[str, str]:
    """Defaults a model fills in on validation, per field: the value in the default model,
    else the values it takes for the values of the model's Literal fields ("`0.004` with
    `geometry = "sphere_on_flat"` or ..."). A choice the model refuses on its own (a height
    map without maps) is skipped."""
    from pydantic import ValidationError

    choices: list[tuple[str, Any]] = [("", None)]
    for name, f in model.model_fields.items():
        if typing.get_origin(f.annotation) is Literal:
            choices += [(name, v) for v in typing.get_args(f.annotation)]
    found: dict[str, dict[str, list[str]]] = {}
    for name, value in choices:
        try:
            inst = model() if not name else model.model_validate({name: value})
        except ValidationError:
            continue
        for fname, f in model.model_fields.items():
            v = getattr(inst, fname)
            if fname == name or is_model(f.annotation) or v == field_default(f):
                continue
            how = f"`{name} = {fmt_value(value).strip('`')}`" if name else ""
            found.setdefault(fname, {}).setdefault(fmt_value(v), []).append(how)
    out: dict[str, str] = {}
    for fname, values in found.items():
        out[fname] = "; ".join(v if "" in hows else f"{v} with " + " or ".join(hows)
                               for v, hows in values.items())
    return out


def physical_of(field: Any) -> tuple[str, str]:
    """(the field's physical range as text, its unit) when it declares one
    (``tribodem.io.model.physical``: the range of real materials and rigs, refused outside
    unless ``allow_unphysical = true``), else ("-", "")."""
    from tribodem.io import model as m

    if not hasattr(m, "physical_range"):
        return "-", ""
    rng = m.physical_range(field)
    if rng is None:
        return "-", ""
    unit = m.physical_unit(field) if hasattr(m, "physical_unit") else ""
    return m.range_text(rng[0], rng[1]), unit


#: the sentence :func:`tribodem.io.model.physical` appends to a description (shown in the
#: table's own column instead)
_PHYSICAL_TEXT = re.compile(r"(?:^|;\s*)physical range [^()]*\([^)]*allow_unphysical[^)]*\)\s*$")


def table_rows(model: Any, prefix: str) -> tuple[list[str], list[tuple[str, Any]]]:
    """The rows of ``model``'s own (non-table) fields, and its sub-tables (dotted name,
    model class)."""
    rows: list[str] = []
    tables: list[tuple[str, Any]] = []
    filled = filled_in(model)
    for name, f in model.model_fields.items():
        key = f"{prefix}{name}"
        if f.exclude:  # internal: not written in a config file (e.g. plug-in tables)
            continue
        if is_model(f.annotation):
            tables.append((key, f.annotation))
            continue
        default = fmt_value(field_default(f))
        if name in filled:
            default += f"; filled in: {filled[name]}"
        physical, physical_unit = physical_of(f)
        description = f.description or ""
        if physical != "-":
            description = _PHYSICAL_TEXT.sub("", description).strip()
        description = description or MISSING.get(key, "")
        unit = physical_unit or unit_of(name, description)
        rows.append(f"| `{key}` | {fmt_type(f.annotation)} | {default} | "
                    f"{fmt_range(f.metadata)} | {physical} | {unit} | {clean(description)} |")
    return rows, tables


def undescribed() -> list[str]:
    """The dotted keys of every config model whose field has no description in the code."""
    from tribodem.braking import BrakingConfig
    from tribodem.dem import DemRunConfig
    from tribodem.fretting import FrettingConfig

    out: list[str] = []

    def walk(model: Any, prefix: str) -> None:
        for name, f in model.model_fields.items():
            if f.exclude:
                continue
            if is_model(f.annotation):
                walk(f.annotation, f"{prefix}{name}.")
            elif not f.description:
                out.append(f"{prefix}{name}")

    for m in (FrettingConfig, BrakingConfig, DemRunConfig):
        walk(m, "")
    return out


HEADER = ("| key | type | default | allowed | physical range | unit | description |\n"
          "|---|---|---|---|---|---|---|")


def model_section(title: str, model: Any, intro: str, level: int = 2) -> list[str]:
    """The section of one config model: its top-level keys, then one table per TOML
    table (recursively)."""
    out = [f"{'#' * level} {title}", "", intro, ""]
    rows, tables = table_rows(model, "")
    if rows:
        out += ["Top-level keys (before any `[table]`):", "", HEADER, *rows, ""]
    out += _tables(tables, level + 1)
    return out


def _tables(tables: list[tuple[str, Any]], level: int) -> list[str]:
    out: list[str] = []
    for key, sub in tables:
        rows, inner = table_rows(sub, key + ".")
        out += [f"{'#' * level} `[{key}]`", "", first_paragraph(sub.__doc__), ""]
        if rows:
            out += [HEADER, *rows, ""]
        out += _tables(inner, level + 1)
    return out


def flat_preset(preset: dict[str, Any], prefix: str = "") -> list[str]:
    """A preset (nested dicts) as ``key = value`` items."""
    out = []
    for k, v in preset.items():
        if isinstance(v, dict):
            out += flat_preset(v, f"{prefix}{k}.")
        else:
            out.append(f"`{prefix}{k} = {fmt_value(v).strip('`')}`")
    return out


def strategy_section() -> list[str]:
    from tribodem.cyclejump import STRATEGIES

    out = ["### `[jump] params` by strategy", "",
           "`[jump] params` is a table of keyword arguments of the strategy named by "
           "`[jump] strategy` (an unknown key is refused; the same names work with "
           "`tribodem jump replay --param key=value`). The strategies and their "
           "parameters are described in [Cycle-jumping](../cyclejump.md).", "",
           "| strategy | class | parameters (defaults) |", "|---|---|---|"]
    for name, cls in STRATEGIES.items():
        params = [p for p in inspect.signature(cls.__init__).parameters.values()
                  if p.name != "self"]
        text = ", ".join(f"`{p.name}` (unset)" if p.default is None else
                         f"`{p.name} = {fmt_value(p.default).strip('`')}`" for p in params)
        out.append(f"| `{name}` | `{cls.__name__}` | {text} |")
    return out + [""]


def option_rows(command: Any) -> list[str]:
    """The options of a typer (click) command as table rows."""
    rows = []
    for p in command.params:
        if getattr(p, "hidden", False) or p.name == "help":
            continue
        names = " / ".join(f"`{o}`" for o in [*p.opts, *p.secondary_opts])
        base = p.bare_type()
        if base.startswith("list[") and base.endswith("]"):
            base = base[5:-1]
        kind = "flag" if p.is_flag else {"Path": "path", "str": "text", "int": "integer",
                                         "float": "number"}.get(base, base)
        if getattr(p, "multiple", False):
            kind += ", repeatable"
        if p.required:
            default = "required"
        elif p.is_flag and p.secondary_opts:
            default = p.opts[0] if p.default else p.secondary_opts[0]
            default = f"`{default}`"
        elif p.is_flag:
            default = "off" if not p.default else "on"
        else:
            default = "-" if p.default is None else fmt_value(p.default)
        bounds = []
        if getattr(p, "min", None) is not None:
            bounds.append(f">= {p.min}")
        if getattr(p, "max", None) is not None:
            bounds.append(f"<= {p.max}")
        rows.append(f"| {names} | {kind} | {default} | {', '.join(bounds) or '-'} | "
                    f"{clean(p.help)} |")
    return rows


OPTION_HEADER = "| option | type | default | range | what |\n|---|---|---|---|---|"


def commands() -> list[tuple[str, Any]]:
    """Every leaf command of ``tribodem`` as (full name, click command), in the app's
    order."""
    import typer

    from tribodem.cli import full_app

    root = typer.main.get_command(full_app())
    out: list[tuple[str, Any]] = []

    def walk(group: Any, path: str) -> None:
        for name, sub in group.commands.items():
            if getattr(sub, "hidden", False):
                continue
            full = f"{path} {name}"
            if hasattr(sub, "commands"):
                walk(sub, full)
            else:
                out.append((full, sub))

    walk(root, "tribodem")
    return out


def config_page() -> str:
    from tribodem.braking import BrakingConfig
    from tribodem.dem import DemRunConfig
    from tribodem.fretting import FrettingConfig

    lines = [
        "# Configuration reference",
        "",
        "<!-- Generated by tools/config_reference.py from the pydantic models: do not edit; "
        "run `.venv/bin/python tools/config_reference.py` after changing a model. -->",
        "",
        "Every key of the TOML config files, with its type, default, allowed range, unit and "
        "description. *Allowed* is what the model accepts at all; *physical range* is the "
        "range of real materials and rigs, outside which a value is refused unless the "
        "config sets `allow_unphysical = true` (at its top level). A dotted key "
        "`contact.load` is the key `load` of the table "
        "`[contact]`; from Python the same keys go in nested dicts "
        "(`{\"contact\": {\"load\": 50.0}}`), and in a sweep table they are column names. "
        "Units are SI unless the key's name says otherwise (`load_kN`, `rpm`). A key the "
        "model does not declare is refused, and so are `inf`, `nan` and `true` / `false` "
        "where a number is expected: the command exits 2 naming the key, the value and "
        "what is allowed, before any work.",
        "",
        "Resolution order, everywhere: the defaults below <- the config file (or dict) <- "
        "the `--quick` preset <- the command-line options. A run records what it resolved "
        "in `OUT/config.toml`, which reloads unchanged with `--config OUT/config.toml`.",
        "",
        LEGEND,
        "",
        "Contents: [fretting](#fretting-config) · [braking](#braking-config) · "
        "[DEM demo](#dem-demo-config) · [calibration](#calibration-options)",
        "",
    ]
    lines += model_section(
        "Fretting config", FrettingConfig,
        "`tribodem fretting run | study | debris-study | sweep --config FILE`, "
        "`tribodem.fretting.run(config, out)` and the other functions of "
        "`tribodem.fretting`. Each first-body backend reads its own option table "
        "(`[elastic]`, `[plastic]`, `[fe]`); a key of another backend's table set away "
        "from its default is refused. A backend registered from Python may declare a "
        "table of its own (`FirstBodySolver.options`), which the config then accepts "
        "beside these.")
    quick = FrettingConfig.QUICK
    lines += ["### `--quick` (fretting)", "",
              "`--quick` (and `quick=True`) lays these over the config: "
              + ", ".join(flat_preset(quick)) + "."]
    for solver, extra in FrettingConfig.QUICK_SOLVER.items():
        lines += ["", f"With `solver = \"{solver}\"` also: " + ", ".join(flat_preset(extra))
                  + "."]
    lines += ["", *strategy_section()]
    lines += model_section(
        "Braking config", BrakingConfig,
        "`tribodem braking run | sweep --config FILE`, `tribodem.braking.run(config, out)`. "
        "`--condition K` sets `condition.index`. The load is given as `load_kN` (table 4 "
        "of Sha et al., converted by the pad area that table implies: 13 kN = 0.33 MPa) or "
        "as `pressure_Pa`; the speed as `rpm` (converted by the friction radius implied: "
        "1200 r/min = 47.12 m/s) or `speed_m_s`.")
    lines += ["### `--quick` (braking)", "",
              "`--quick` lays these over the config: "
              + ", ".join(flat_preset(BrakingConfig.quick())) + ".", ""]
    lines += model_section(
        "DEM demo config", DemRunConfig,
        "`tribodem dem run --config FILE`, `tribodem.dem.run(config, out)`: the engine's "
        "demonstration scenarios.")
    lines += ["### `--quick` (DEM demo)", "",
              "`--quick` lays these over the config: "
              + ", ".join(flat_preset(DemRunConfig.QUICK)) + ".", ""]
    cal = dict(commands())["tribodem calibrate"]
    lines += ["## Calibration options", "",
              "`tribodem calibrate` has no config file; its options are below. "
              "`tribodem.materials.calibrate(material, out, ...)` takes the same names as "
              "keyword arguments (without the dashes; `progress=True` for the bar); from "
              "Python `workers` left out runs in the calling process.", "", OPTION_HEADER,
              *option_rows(cal), ""]
    return "\n".join(lines).rstrip() + "\n"


def cli_page() -> str:
    lines = [
        "# Command reference",
        "",
        "<!-- Generated by tools/config_reference.py from the typer app: do not edit. -->",
        "",
        "Every `tribodem` command and its options, as `tribodem COMMAND --help` prints "
        "them. Exit codes, the files each command writes and the environment variables "
        "it reads: [Runs, outputs and exit codes](outputs.md). Config keys: "
        "[Configuration reference](config.md).",
        "",
        LEGEND,
        "",
    ]
    for name, cmd in commands():
        lines += [f"## `{name}`", "", first_paragraph(cmd.help), "",
                  OPTION_HEADER, *option_rows(cmd), ""]
    return "\n".join(lines).rstrip() + "\n"


def without_unused_legend(text: str) -> str:
    """The page without :data:`LEGEND` when no description names a seed any more."""
    body = text.replace(LEGEND, "")
    if "seed 00" in body.lower() or "the seed" in body.lower():
        return text
    return text.replace(LEGEND + "\n\n", "")


PAGES = {CONFIG_PAGE: lambda: without_unused_legend(config_page()),
         CLI_PAGE: lambda: without_unused_legend(cli_page())}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--check", action="store_true",
                    help="exit 1 (and show the difference) when a page is not current")
    ap.add_argument("--undescribed", action="store_true",
                    help="list the config keys whose model field has no description")
    args = ap.parse_args(argv)
    if args.undescribed:
        keys = undescribed()
        print("\n".join(f"{k}{'' if k in MISSING else '  (no description at all)'}"
                        for k in keys))
        return 0
    stale = 0
    for path, make in PAGES.items():
        text = make()
        old = path.read_text() if path.is_file() else ""
        if args.check:
            if old != text:
                stale += 1
                rel = path.relative_to(ROOT)
                sys.stdout.writelines(difflib.unified_diff(
                    old.splitlines(keepends=True), text.splitlines(keepends=True),
                    f"{rel} (in the tree)", f"{rel} (from the code)", n=1))
                print(f"{rel} is not current: run .venv/bin/python tools/config_reference.py")
        elif old != text:
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(text)
            print(f"wrote {path.relative_to(ROOT)}")
    return 1 if stale else 0


if __name__ == "__main__":
    sys.exit(main())
