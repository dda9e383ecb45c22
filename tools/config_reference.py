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

#: Units written as a suffix of a field's name (the braking tables).
NAME_UNITS = (("_kg_m2", "kg/m^2"), ("_m_s", "m/s"), ("_kN", "kN"), ("_MPa", "MPa"),
              ("_Pa", "Pa"), ("_m", "m"), ("_s", "s"))

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
        return f"`{v:.10g}`"
    if isinstance(v, int):
        return f"`{v}`"
    if isinstance(v, str):
        return f'`"{v}"`'
    if isinstance(v, tuple | list):
        return "`[" + ", ".join(fmt_value(x).strip("`") for x in v) + "]`"
    if isinstance(v, dict):
        return "`{}`" if not v else f"`{v}`"
    return f"`{v}`"


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
                out.append(f"{sym} {v:.10g}" if isinstance(v, float) else f"{sym} {v}")
    return ", ".join(out) if out else "-"


def is_model(annotation: Any) -> bool:
    from pydantic import BaseModel

    return isinstance(annotation, type) and issubclass(annotation, BaseModel)


def field_default(field: Any) -> Any:
    if field.default_factory is not None:
        return field.default_factory()
    return field.default


def table_rows(model: Any, prefix: str) -> tuple[list[str], list[tuple[str, Any]]]:
    """The rows of ``model``'s own (non-table) fields, and its sub-tables (dotted name,
    model class)."""
    rows: list[str] = []
    tables: list[tuple[str, Any]] = []
    for name, f in model.model_fields.items():
        key = f"{prefix}{name}"
        if is_model(f.annotation):
            tables.append((key, f.annotation))
            continue
        default = field_default(f)
        desc = clean(f.description)
        rows.append(f"| `{key}` | {fmt_type(f.annotation)} | {fmt_value(default)} | "
                    f"{fmt_range(f.metadata)} | {unit_of(name, f.description)} | {desc} |")
    return rows, tables


HEADER = "| key | type | default | range | unit | description |\n|---|---|---|---|---|---|"


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
        text = ", ".join(f"`{p.name} = {fmt_value(p.default).strip('`')}`" for p in params)
        out.append(f"| `{name}` | `{cls.__name__}` | {text} |")
    return out + [""]


def option_rows(command: Any) -> list[str]:
    """The options of a typer (click) command as table rows."""
    rows = []
    for p in command.params:
        if getattr(p, "hidden", False) or p.name == "help":
            continue
        names = " / ".join(f"`{o}`" for o in [*p.opts, *p.secondary_opts])
        kind = "flag" if p.is_flag else p.bare_type().replace("Path", "path").replace(
            "str", "text").replace("int", "integer").replace("float", "number")
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
        "description. A dotted key `contact.load` is the key `load` of the table "
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
        "from its default is refused.")
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
              "`tribodem calibrate` has no config file; its options (and the keyword "
              "arguments of `tribodem.materials.calibrate(material, out, ...)`, same "
              "names without the dashes):", "", OPTION_HEADER, *option_rows(cal), ""]
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


PAGES = {CONFIG_PAGE: config_page, CLI_PAGE: cli_page}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--check", action="store_true",
                    help="exit 1 (and show the difference) when a page is not current")
    args = ap.parse_args(argv)
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
