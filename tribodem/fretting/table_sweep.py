"""``tribodem fretting sweep``: a fretting parameter study over a table of configs on Dask,
:func:`sweep`.

The table is a CSV file: a header of config fields in dotted form (``cycles``, ``solver``,
``contact.load``, ``contact.amplitude``, ``wear.criterion``, ``jump.params.N``, ...) and an
optional ``name`` column (the member's folder; default ``member_001``, ...); each row is a
member, the base config (``--config``, or the defaults; ``--quick`` as in ``fretting run``)
with the row's non-empty cells merged over it. A cell is read as a TOML value (``100``,
``0.3e-3``, ``true``, ``[0.5, 0.3, 0.2]``, ``"text"``), else as text (``energy``). From
Python the table may also be a list of dict rows or a pandas DataFrame (their values
written as such cells; None and NaN: empty).

Every row is validated as a :class:`~tribodem.fretting.config.FrettingConfig` and checked as
``fretting run`` checks it before building the solver (criterion and solver compatible,
window, criterion, jumping, debris), all before any work: a bad table is refused with
``ConfigError`` naming the row, the field, the value and what is allowed (exit 2), and
nothing is written. The solver's own checks run in the member's task (a failed member).

Each member is one task of :mod:`tribodem.io.ensemble` running a fretting run in
``OUT/<name>/`` with one numba thread; the task is idempotent and retry-safe
(:func:`member_plan`): a finished run of the same config is returned as it is (skipped), a
run that stopped early with the same config is kept (its stop is reported again: a resume
would stop at the same cycle; ``fretting run --resume --out OUT/<name>`` retries it by hand),
a checkpoint the run may resume (:func:`~tribodem.fretting.config.check_resume`: the same
config, cycles raised or equal, ``[output]`` free) is resumed, anything else starts over.

At the end ``OUT/sweep.csv`` (a row per member: name, the table's cells, status, final
wear depths and volumes, cycles done, wall time, message) and ``OUT/sweep.json`` are written
atomically. A failed or stopped member is reported and the others go on; the command then
exits 3 (:class:`~tribodem.io.runs.RunStopped`).
"""

from __future__ import annotations

import csv
import json
import math
import os
import re
import time
import tomllib
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeAlias

import numba
from pydantic import BaseModel

from tribodem.fretting.case import preflight
from tribodem.fretting.config import (
    QUICK,
    FrettingConfig,
    check_resume,
    effective_config,
    read_config,
    recorded_config,
    resolve_config,
    resume_diffs,
)
from tribodem.fretting.output import CHECKPOINT, read_checkpoint
from tribodem.fretting.runner import Echo, run
from tribodem.io import runs
from tribodem.io.config import ConfigError, load_toml, merge, validate
from tribodem.io.ensemble import Member, check_cluster_options, run_members
from tribodem.io.record import ConfigSource, RunResult, as_out, flatten, nest
from tribodem.io.results import write_csv, write_json

if TYPE_CHECKING:
    import pandas as pd

#: What :func:`sweep` takes as its table: the path of a CSV file, dict rows (column ->
#: value) or a pandas DataFrame.
Table: TypeAlias = "str | os.PathLike[str] | Sequence[Mapping[str, Any]] | pd.DataFrame"

#: sweep.csv / sweep.json column <- summary.json entry, in this order
RESULT_FIELDS = {"wear_depth_upper_m": "wear_depth_upper_m",
                 "wear_depth_lower_m": "wear_depth_lower_m",
                 "wear_volume_upper_m3": "wear_volume_upper_m3",
                 "wear_volume_lower_m3": "wear_volume_lower_m3",
                 "cycles_done": "cycles", "wall_time_s": "wall_time_s"}
#: a member name: a plain folder name
NAME_RE = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.+=-]*")
#: what messages call a table given as rows (not a file)
ROWS_NAME = "<rows>"


# ---------------------------------------------------------------- the table

def config_fields(model: type[BaseModel], prefix: str = "") -> dict[str, bool]:
    """Dotted config fields of ``model`` -> whether it is a free-form table
    (``jump.params``)."""
    out: dict[str, bool] = {}
    for k, f in model.model_fields.items():
        sub = f.annotation
        if isinstance(sub, type) and issubclass(sub, BaseModel):
            out |= config_fields(sub, f"{prefix}{k}.")
        else:
            out[f"{prefix}{k}"] = sub is dict or str(sub).startswith("dict")
    return out


def check_column(col: str, table: str | Path) -> None:
    """Refuse a header name that is not a config field (naming it and what is allowed);
    ``table``: the table as messages name it."""
    fields = config_fields(FrettingConfig)
    if col in fields and not fields[col]:
        return
    for f, free in fields.items():
        if free and col.startswith(f + ".") and len(col) > len(f) + 1:
            return
    head, _, _ = col.partition(".")
    tables = sorted({f.split(".")[0] for f in fields if "." in f})
    if head in tables and "." in col:
        allowed = ", ".join(f + (".<name>" if free else "") for f, free in fields.items()
                            if f.startswith(head + "."))
    elif head in tables:
        allowed = f"a field of [{head}] such as {next(f for f in fields if f.startswith(head))}"
    else:
        top = [f for f in fields if "." not in f]
        allowed = (f"name, {', '.join(top)} or a dotted field of "
                   f"{', '.join(f'[{t}]' for t in tables)} (e.g. contact.load)")
    raise ConfigError(f"--table = '{table}': column '{col}' is not a config field; "
                      f"allowed: {allowed}")


def parse_cell(text: str) -> Any:
    """A cell as a TOML value (number, boolean, array, quoted string), else as text."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def cell_text(value: Any) -> str:
    """A Python value as the CSV cell :func:`parse_cell` reads back to it (None and NaN:
    empty; booleans ``true``/``false``; lists as arrays; text as it is)."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, list | tuple):
        return json.dumps(list(value))
    if isinstance(value, float):
        return repr(value)
    return str(value)


def table_lines(table: Table) -> tuple[str, list[tuple[int, list[str]]]]:
    """(what messages call the table, its non-empty lines as (line number, cells)): a CSV
    file read, dict rows or a DataFrame as the lines of the CSV file they make (a header
    of every column in order of appearance, then a line per row)."""
    if isinstance(table, str | os.PathLike):
        path = Path(table)
        field = f"--table = '{path}'"
        if path.is_dir():
            raise ConfigError(f"{field}: is a folder; allowed: a CSV file")
        if not path.is_file():
            raise ConfigError(f"{field}: file does not exist")
        try:
            text = path.read_text(encoding="utf-8-sig")
        except (OSError, UnicodeDecodeError) as err:
            raise ConfigError(f"{field}: cannot be read: {err}") from None
        try:
            return str(path), [(i, r) for i, r in
                               enumerate(csv.reader(text.splitlines()), start=1)
                               if any(c.strip() for c in r)]
        except csv.Error as err:
            raise ConfigError(f"{field}: not a CSV table: {err}") from None
    records = table.to_dict("records") if hasattr(table, "to_dict") else table
    if not isinstance(records, Sequence) or not all(isinstance(r, Mapping) for r in records):
        raise ConfigError(f"--table = {table!r}: allowed: the path of a CSV file, a list of "
                          "dict rows (column -> value) or a pandas DataFrame")
    header = list(dict.fromkeys(str(k) for r in records for k in r))
    lines = [(1, header)] if header else []
    lines += [(i, [cell_text(r.get(c)) for c in header])
              for i, r in enumerate(records, start=2)]
    return ROWS_NAME, lines


def read_table(table: Table) -> tuple[list[str], list[tuple[int, int, str, dict[str, str]]]]:
    """(config columns, rows as (row number, line, name, cells)) of ``table`` (a CSV file,
    dict rows or a DataFrame: :func:`table_lines`); ``ConfigError`` for anything that is
    not a usable table."""
    name_, lines = table_lines(table)
    field = f"--table = '{name_}'"
    if not lines:
        raise ConfigError(f"{field}: is empty; allowed: a header of config fields (e.g. "
                          "name,contact.load,wear.criterion) and one row per member")
    header = [c.strip() for c in lines[0][1]]
    for i, col in enumerate(header):
        if not col:
            raise ConfigError(f"{field}: column {i + 1} of the header has no name; allowed: "
                              "a config field in dotted form (e.g. contact.load) or name")
        if header.count(col) > 1:
            raise ConfigError(f"{field}: column '{col}' appears {header.count(col)} times; "
                              "allowed: each field once")
        if col != "name":
            check_column(col, name_)
    if len(lines) == 1:
        raise ConfigError(f"{field}: has a header but no rows; allowed: one row per member")
    rows = []
    names: dict[str, int] = {}
    for n, (line, r) in enumerate(lines[1:], start=1):
        if len(r) != len(header):
            raise ConfigError(f"{field}: row {n} (line {line}) has {len(r)} cells but the "
                              f"header {len(header)}; allowed: one cell per column (empty: "
                              "the base config's value)")
        cells = {c: v.strip() for c, v in zip(header, r, strict=True)}
        name = cells.pop("name", "") or f"member_{n:03d}"
        if not NAME_RE.fullmatch(name):
            raise ConfigError(f"{field}: row {n} (line {line}): name = {name!r}: not a "
                              "folder name; allowed: letters, digits, _ . + = - (not "
                              "starting with . or -)")
        if name in ("sweep.csv", "sweep.json"):
            raise ConfigError(f"{field}: row {n} (line {line}): name = {name!r} is the "
                              "sweep's own output file; allowed: another name")
        if name in names:
            raise ConfigError(f"{field}: row {n} (line {line}): name = {name!r} is also "
                              f"row {names[name]}'s; allowed: a distinct name per row")
        names[name] = n
        rows.append((n, line, name, cells))
    return [c for c in header if c != "name"], rows


def base_data(config: ConfigSource, quick: bool) -> dict[str, Any]:
    """The unresolved base config of every row, as ``fretting run`` builds it: defaults <-
    ``config`` (height maps relative to its file) <- ``quick`` (:data:`QUICK`); checked on
    its own."""
    resolve_config(config, quick=quick)  # a bad base is named as the config file's
    data = read_config(config).data
    if quick:
        data = merge(data, QUICK) if config is not None else merge(QUICK, data)
    return data


def members(table: Table, out: Path, config: ConfigSource, quick: bool
            ) -> tuple[list[str], list[Member]]:
    """The table's columns and members, every row checked before anything is made."""
    columns, rows = read_table(table)
    name_ = str(table) if isinstance(table, str | os.PathLike) else ROWS_NAME
    maps_dir = Path(table).parent if isinstance(table, str | os.PathLike) else Path(".")
    base = base_data(config, quick)
    result = []
    for n, line, name, cells in rows:
        where = f"--table '{name_}' row {n} (line {line}, name '{name}')"
        values = {}
        for col, text in cells.items():
            if text == "":
                continue
            v = parse_cell(text)
            if col.endswith(("upper_map", "lower_map")) and isinstance(v, str) and \
                    not Path(v).expanduser().is_absolute():
                v = str(maps_dir / v)  # relative to the table, as maps to a config
            values[col] = v
        cfg = validate(FrettingConfig, merge(base, nest(values)), source=where)
        try:
            preflight(cfg)
        except ConfigError as err:
            raise ConfigError(f"{where}: {err}") from None
        result.append(Member(key=name, label=f"member '{name}' (row {n})",
                             task_name=f"fretting-{name}", task=run_member,
                             data=cfg.record(), folder=out / name,
                             info={"row": n, "cells": cells}))
    return columns, result


# ---------------------------------------------------------------- a member's task

def read_summary(folder: Path) -> dict[str, Any] | None:
    """``folder/summary.json`` as a dict (None when missing or unreadable)."""
    try:
        s = json.loads((folder / "summary.json").read_text())
    except (OSError, ValueError):
        return None
    return s if isinstance(s, dict) else None


def status_of(summary: dict[str, Any]) -> str:
    """done (finished) or stopped (an early stop: ``stopped`` says why)."""
    return "stopped" if summary.get("stopped") else "done"


def member_plan(cfg_data: dict[str, Any], d: Path) -> tuple[str, Any]:
    """What a member needs: ("done", summary) when ``d`` holds its finished run with the
    same config, ("stopped", summary) when it holds its run stopped early with the same
    config, ("resume", None) when it holds a checkpoint this config may resume, else
    ("new", why-not-reused or None). The folder's configs are read as
    :func:`~tribodem.fretting.config.recorded_config` reads them and compared as
    :func:`~tribodem.fretting.config.effective_config` gives them."""
    cfg = validate(FrettingConfig, cfg_data, source=f"member '{d}'")
    new = effective_config(cfg.record())
    s = read_summary(d)
    recorded = (s or {}).get("config")
    old = effective_config(recorded_config(recorded)) if isinstance(recorded, dict) else None
    # the same run: every field equal, a field added to tribodem since the record was made
    # left at its default (resume_diffs, nothing free)
    if s is not None and isinstance(recorded, dict) and not resume_diffs(
            recorded, cfg.record(), may_change=()):
        if s.get("stopped"):
            return "stopped", s
        if s.get("cycles") == cfg.cycles:
            return "done", s
    ck = d / CHECKPOINT
    if ck.is_file():
        try:
            meta, _ = read_checkpoint(ck)
            check_resume(cfg, meta, ck)
            return "resume", None
        except ConfigError:
            pass
    if old is None and (d / "config.toml").is_file():
        try:
            old = effective_config(recorded_config(load_toml(d / "config.toml")))
        except ConfigError:
            return "new", "its config.toml cannot be read"
    if old is None:
        return "new", None
    a, b = flatten(old), flatten(new)
    default = flatten(FrettingConfig().record())  # a field newer than the record: default
    diff = [k for k in sorted(set(a) | set(b)) if a.get(k) != b.get(k)
            and not (k not in a and k in default and b.get(k) == default[k])]
    if not diff:
        return "new", "its run did not finish and left no usable checkpoint"
    k = diff[0]
    more = f" (and {len(diff) - 1} more)" if len(diff) > 1 else ""
    return "new", f"{k} changed from {a.get(k)!r} to {b.get(k)!r}{more}"


@runs.releases_folders
def run_member(cfg_data: dict[str, Any], out: str, stop_event: str | None = None
               ) -> dict[str, Any]:
    """The task of one member (idempotent, retry-safe): decide from the folder's state
    (:func:`member_plan`), then run the fretting run with one numba thread. Returns the
    summary (an early stop's too: its ``stopped`` says why).

    ``stop_event`` is accepted for :func:`tribodem.io.ensemble.run_members`, but the run
    has no stop hook: on an external cluster a member already running when the sweep is
    stopped runs to its end (local workers are killed at once)."""
    numba.set_num_threads(1)
    d = Path(out)
    cfg = validate(FrettingConfig, cfg_data, source=f"member '{d}'")
    what, info = member_plan(cfg_data, d)
    if what in ("done", "stopped"):
        return info
    if what == "new":  # never leave an older run's results as this one's
        for name in ("summary.json", "results.csv", "criterion.csv"):
            (d / name).unlink(missing_ok=True)
    try:
        return run(cfg, d, resume=what == "resume").summary
    except runs.RunStopped:
        s = read_summary(d)
        if s is None or not s.get("stopped"):
            raise
        return s


# ---------------------------------------------------------------- the sweep

@runs.releases_folders
def sweep(table: Table, out: str | os.PathLike[str], *, config: ConfigSource = None,
          quick: bool = False, workers: int = 0, scheduler: str | None = None,
          progress: bool = False, echo: Echo | None = None, err_echo: Echo | None = None
          ) -> RunResult:
    """Every row of ``table`` (the path of a CSV file, dict rows or a DataFrame: config
    fields in dotted form, an optional ``name``) a fretting run in ``out/<name>/``, each an
    idempotent task on Dask; writes ``sweep.csv`` (one row per member) and ``sweep.json``.

    ``config``: the base config of every row (a model, a dict shaped like the TOML file, a
    TOML path or None); ``quick``: the quick preset under the rows' cells; ``workers``:
    processes of the local cluster (0: all cores; not with ``scheduler``); ``scheduler``:
    an existing cluster (``tcp://HOST:PORT`` or a scheduler file). Running it again on the
    same ``out`` skips the finished members and resumes the others. ``echo``: progress
    lines; ``err_echo``: a failed member's (default ``echo``). A failed or stopped member
    raises :class:`~tribodem.io.runs.RunStopped` at the end, after ``sweep.csv``.
    """
    folder = as_out(out)
    report = run_sweep(table, folder, config, quick, workers, scheduler, progress,
                       echo=echo, err_echo=err_echo)
    return RunResult(folder, report, "sweep.csv", ["sweep.csv", "sweep.json"])


def run_sweep(table: Table, out: Path, config: ConfigSource, quick: bool, workers: int,
              scheduler: str | None, progress: bool, echo: Echo | None = None,
              err_echo: Echo | None = None) -> dict[str, Any]:
    """The whole sweep: check everything, run the members not finished, write sweep.csv /
    sweep.json (returned); raise ``RunStopped`` when a member failed or stopped."""
    say: Echo = echo or (lambda s: None)
    warn: Echo = err_echo or say
    check_cluster_options("fretting sweep", workers, scheduler)
    t0 = time.perf_counter()
    columns, todo_all = members(table, out, config, quick)
    runs.check_out_dir(out, "--out")  # every member checked first: no folder for a bad one
    for m in todo_all:
        runs.check_out_dir(m.folder, f"--out member '{m.key}'")
    runs.announce(out)
    results, todo = plan_members(todo_all, say)
    failed: dict[str, str] = {}
    where = "nothing to run"
    if todo:
        try:
            done, failed_k, where = run_members(
                todo, len(todo_all), len(results), scheduler=scheduler, workers=workers,
                progress=progress, echo=warn, desc="fretting sweep")
        except BaseException:
            warn("\nsweep stopped: finished members are kept; run the same command "
                 "again to skip them and resume the others from their checkpoints")
            raise
        results.update({str(k): v for k, v in done.items()})
        failed = {str(k): v for k, v in failed_k.items()}
    wall = time.perf_counter() - t0
    records = member_records(todo_all, results, failed)
    header = ["name", *columns, "status", *RESULT_FIELDS, "message"]
    write_csv(out / "sweep.csv", header,
              [[r["name"], *(r["cells"][c] for c in columns), r["status"],
                *("" if r[k] is None else r[k] for k in RESULT_FIELDS), r["message"]]
               for r in records])
    counts = {k: sum(r["status"] == k for r in records) for k in ("done", "stopped", "failed")}
    report = {"table": str(table) if isinstance(table, str | os.PathLike) else ROWS_NAME,
              "config": str(config) if isinstance(config, str | os.PathLike) else
              None if config is None else type(config).__name__,
              "quick": quick, "cluster": where, "wall_time_s": wall,
              "members": len(records), "run": len(todo),
              "skipped": len(todo_all) - len(todo), **counts, "results": records}
    write_json(out / "sweep.json", report)
    say(f"sweep: {len(records)} member(s) in {wall:.1f} s on {where} ({len(todo)} run, "
        f"{report['skipped']} skipped as finished or stopped, {counts['failed']} failed, "
        f"{counts['stopped']} stopped) -> {out / 'sweep.csv'}")
    if counts["failed"] or counts["stopped"]:
        bad = next(r for r in records if r["status"] != "done")
        raise runs.RunStopped(
            f"{counts['failed']} of {len(records)} sweep members failed and "
            f"{counts['stopped']} stopped early (first: {bad['name']}: {bad['status']}: "
            f"{bad['message']}); sweep.csv covers every member")
    return report


def plan_members(todo_all: list[Member], say: Echo
                 ) -> tuple[dict[str, dict[str, Any]], list[Member]]:
    """(summaries of the members finished or stopped before, the members to run), each
    member's plan said (:func:`member_plan`)."""
    results: dict[str, dict[str, Any]] = {}
    todo = []
    for m in todo_all:
        what, info = member_plan(m.data, m.folder)
        if what == "done":
            results[str(m.key)] = info
            say(f"  {m.key}: finished earlier, skipped")
        elif what == "stopped":
            results[str(m.key)] = info
            say(f"  {m.key}: stopped earlier ({info['stopped']}), kept (a resume would "
                f"stop again; to retry: tribodem fretting run --resume --out "
                f"{m.folder})")
        else:
            if what == "resume":
                say(f"  {m.key}: resuming from its checkpoint")
            elif info:
                say(f"  {m.key}: starting over ({info})")
            todo.append(m)
    return results, todo


def member_records(todo_all: list[Member], results: dict[str, dict[str, Any]],
                   failed: dict[str, str]) -> list[dict[str, Any]]:
    """sweep.json's ``results``: per member its name, row, cells, status, the numbers of
    :data:`RESULT_FIELDS`, a message (why it failed or stopped) and its folder."""
    records = []
    for m in todo_all:
        name = str(m.key)
        s = results.get(name)
        status = "failed" if s is None else status_of(s)
        msg = failed.get(name, "") if s is None else (s.get("stopped") or "")
        records.append({"name": name, "row": m.info["row"], "cells": m.info["cells"],
                        "status": status,
                        **{k: (s or {}).get(v) for k, v in RESULT_FIELDS.items()},
                        "message": msg, "folder": str(m.folder)})
    return records
