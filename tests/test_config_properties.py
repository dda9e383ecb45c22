"""Property tests of every command's config: whatever a user writes, it is accepted or
refused with ``ConfigError`` naming a field, never another exception.

Each test draws dicts shaped like the command's TOML file (its fields with plausible values
and with anything else: huge, tiny, negative, infinite and NaN numbers, booleans, text,
lists, nested tables, unknown keys and tables) and puts them through the validation path
the command uses and the cheap checks it makes before any work (no solver is built here):
``fretting run`` (:func:`tribodem.fretting.config.resolve_config`, then
:func:`tribodem.fretting.case.preflight`), ``braking run``
(:func:`tribodem.braking.config.resolve_config`, then ``setup_from_config``), ``dem run``
(:func:`tribodem.dem.demo.resolve_config`, the memory and thread checks), ``calibrate``
(its options, up to the announcement of its output folder) and the cells of a ``fretting
sweep`` table (:func:`tribodem.fretting.table_sweep.members`). A sample of the refused
configs then goes through the installed command: exit 2, no traceback, no output folder.
"""

from __future__ import annotations

import math
import types
import typing
from collections.abc import Callable
from pathlib import Path
from typing import Any
from unittest import mock

import pytest
from conftest import run_tribodem
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from pydantic import BaseModel

from tribodem.braking.config import BrakingConfig
from tribodem.dem.config import DemRunConfig
from tribodem.fretting.config import FrettingConfig
from tribodem.io.config import ConfigError, dump_toml
from tribodem.io.model import physical_ranges
from tribodem.io.record import flatten, nest

EXAMPLES = settings(max_examples=200, deadline=None, database=None,
                    suppress_health_check=[HealthCheck.too_slow,
                                           HealthCheck.function_scoped_fixture])

# ---------------------------------------------------------------- values


def _awkward_numbers() -> st.SearchStrategy[Any]:
    return st.one_of(
        st.sampled_from([0, 0.0, -0.0, -1, -1.0, 1, 2, 3, 1e-300, 5e-324, 1e300, -1e300,
                         1.7976931348623157e308, math.inf, -math.inf, math.nan, 2**63,
                         -(2**63), 10**30]),
        st.floats(allow_nan=True, allow_infinity=True),
        st.integers(min_value=-(2**70), max_value=2**70))


SCALARS = st.one_of(_awkward_numbers(), st.booleans(),
                    st.text(max_size=10),
                    st.sampled_from(["", " ", "off", "none", "inf", "nan", "true", "1e3",
                                     "energy", "elastic", "fe", "fe3d", "q345b", "..", "/"]))
ANY_VALUE = st.recursive(
    SCALARS, lambda inner: st.lists(inner, max_size=3)
    | st.dictionaries(st.text(max_size=6), inner, max_size=3), max_leaves=5)


def _leaf_fields(model: type[BaseModel], prefix: str = "") -> dict[str, Any]:
    """Dotted name -> pydantic field of every leaf field of ``model`` (tables descended)."""
    out: dict[str, Any] = {}
    for name, f in model.model_fields.items():
        ann = f.annotation
        if isinstance(ann, type) and issubclass(ann, BaseModel):
            out |= _leaf_fields(ann, f"{prefix}{name}.")
        else:
            out[f"{prefix}{name}"] = f
    return out


def _literal_choices(ann: Any) -> list[Any]:
    if typing.get_origin(ann) is typing.Literal:
        return list(typing.get_args(ann))
    if typing.get_origin(ann) in (typing.Union, types.UnionType):
        return [c for a in typing.get_args(ann) for c in _literal_choices(a)]
    return []


def _bounds(field: Any) -> tuple[float | None, float | None]:
    """The (lower, upper) constraints a field declares (ge/gt, le/lt), None where none."""
    lo = hi = None
    for m in field.metadata:
        lo = getattr(m, "ge", getattr(m, "gt", lo))
        hi = getattr(m, "le", getattr(m, "lt", hi))
    return lo, hi


def _plausible(name: str, field: Any, ranges: dict[str, tuple[float, float]]
               ) -> st.SearchStrategy[Any]:
    """Values a user would write for the field: its literals, its default scaled, a
    value inside (or just outside) its physical range or its constraints, a boolean for a
    boolean."""
    options: list[st.SearchStrategy[Any]] = []
    choices = _literal_choices(field.annotation)
    if choices:
        options.append(st.sampled_from(choices))
    default = field.get_default(call_default_factory=True)
    ann = str(field.annotation)
    lo, hi = _bounds(field)
    if isinstance(default, bool):
        options.append(st.booleans())
    elif isinstance(default, int):
        options.append(st.sampled_from([default, default + 1, max(default - 1, 0),
                                        default * 2, default * 4]))
    elif isinstance(default, float):
        options.append(st.sampled_from([default, default * 0.5, default * 2, default * 10,
                                        default * 1e-3]))
    elif default is None and "int" in ann:
        first = int(lo if lo is not None else 0)
        options.append(st.integers(first, int(hi) if hi is not None else first + 8))
    elif default is None and "float" in ann and name not in ranges:
        options.append(st.sampled_from([1e-3, 0.1, 1.0, 10.0]))
    if name in ranges:
        lo, hi = ranges[name]
        mid = math.sqrt(max(lo, 1e-30) * hi)
        options.append(st.sampled_from([mid, mid, lo, hi, hi * 10, -lo - 1, mid * 0.3]))
    return st.one_of(options) if options else SCALARS


def _rarely(one_in: int) -> st.SearchStrategy[bool]:
    """True about once in ``one_in`` draws (not at hypothesis's favourite end of a range,
    which it draws far more often than the rest)."""
    return st.integers(0, one_in - 1).map(lambda i: i == one_in // 2)


def config_dicts(model: type[BaseModel], extra_keys: tuple[str, ...] = ()
                 ) -> st.SearchStrategy[dict[str, Any]]:
    """Dicts shaped like ``model``'s TOML file: some of its fields with plausible or any
    values, unknown keys and tables now and then, a table given as a scalar now and
    then."""
    fields = _leaf_fields(model)
    ranges = physical_ranges(model)
    names = sorted(fields)
    tables = sorted({n.split(".")[0] for n in names if "." in n})

    @st.composite
    def build(draw: Callable[..., Any]) -> dict[str, Any]:
        chosen = draw(st.lists(st.sampled_from(names), max_size=6, unique=True))
        dotted: dict[str, Any] = {}
        for n in chosen:
            plausible = _plausible(n, fields[n], ranges)
            dotted[n] = draw(ANY_VALUE if draw(_rarely(5)) else plausible)
        if draw(_rarely(10)):  # an unknown key, at the top or in a table
            table = draw(st.sampled_from(["", *tables]))
            dotted[f"{table}.{draw(st.sampled_from(['bogus', 'Young', 'lod']))}".lstrip(".")] = (
                draw(ANY_VALUE))
        for k in extra_keys:
            if not draw(_rarely(5)):
                dotted[k] = draw(_plausible(k, fields[k], ranges)) if k in fields else True
        data = nest(dotted)
        if tables and draw(_rarely(15)):  # a table given as a scalar or a list
            data[draw(st.sampled_from(tables))] = draw(SCALARS | st.lists(SCALARS, max_size=2))
        return data

    return build()


# ---------------------------------------------------------------- the checks


def _named(message: str, data: dict[str, Any], model: type[BaseModel]) -> bool:
    """Whether ``message`` names a field: one the data set (dotted, or its table), or one
    of the model's (a check that names the field it compares against, e.g. the window)."""
    given = set(flatten(data)) | {k for k in data}
    known = set(_leaf_fields(model)) | set(model.model_fields)
    return any(k and k in message for k in given | {n for n in known if "." in n}) or any(
        f"'{k}'" in message or f"{k} =" in message for k in known)


def _check(fn: Callable[[], Any], data: dict[str, Any], model: type[BaseModel],
           refused: list[dict[str, Any]] | None = None) -> bool:
    """Run ``fn``: accepted (True), or refused with ``ConfigError`` naming a field (False);
    any other exception fails the test."""
    try:
        fn()
    except ConfigError as err:
        assert str(err).strip(), data
        assert _named(str(err), data, model), (str(err), data)
        assert "Traceback" not in str(err)
        if refused is not None:
            refused.append(data)
        return False
    return True


def fretting_checks(data: dict[str, Any]) -> None:
    """What ``fretting run`` checks before any work (the solver not built)."""
    from tribodem.fretting.case import preflight
    from tribodem.fretting.config import resolve_config

    preflight(resolve_config(data))


def braking_checks(data: dict[str, Any]) -> None:
    """What ``braking run`` checks before any work."""
    from tribodem.braking.config import resolve_config, setup_from_config

    setup_from_config(resolve_config(data))


def dem_checks(data: dict[str, Any]) -> None:
    """What ``dem run`` checks before any work."""
    from tribodem.dem.demo import resolve_config
    from tribodem.dem.state import BYTES_PER_PARTICLE
    from tribodem.io import runs

    cfg = resolve_config(data)
    runs.check_memory(cfg.case.particles, BYTES_PER_PARTICLE, "case.particles")
    runs.check_threads(cfg.run.threads, "run.threads")


@given(config_dicts(FrettingConfig))
@EXAMPLES
def test_fretting_config_accepted_or_refused_naming_the_field(data: dict[str, Any]) -> None:
    _check(lambda: fretting_checks(data), data, FrettingConfig)


@given(config_dicts(BrakingConfig, extra_keys=("condition.index",)))
@EXAMPLES
def test_braking_config_accepted_or_refused_naming_the_field(data: dict[str, Any]) -> None:
    _check(lambda: braking_checks(data), data, BrakingConfig)


@given(config_dicts(DemRunConfig))
@EXAMPLES
def test_dem_config_accepted_or_refused_naming_the_field(data: dict[str, Any]) -> None:
    _check(lambda: dem_checks(data), data, DemRunConfig)


class _Accepted(Exception):
    """Raised in place of the announcement of a run's outputs: every check passed."""


CALIBRATE_OPTIONS = st.fixed_dictionaries({
    "material": st.one_of(st.sampled_from(["q345b", "cu-pm", "Q345B", " cu-pm ", "steel"]),
                          st.sampled_from(["q345b", "cu-pm"]), st.text(max_size=6)),
    "seed": st.one_of(st.integers(0, 10**6), st.integers(-5, 10**6),
                      st.sampled_from([-(2**63), 2**63])),
    "specimens": st.one_of(st.none(), st.integers(-3, 20_000)),
    "workers": st.one_of(st.none(), st.integers(-3, 2000)),
    "scheduler": st.one_of(st.none(), st.sampled_from(
        ["tcp://127.0.0.1:8786", "tls://h:1", "tcp://:1", "udp://h:1", "tcp://h:x", "h:1",
         "", "no-such-scheduler.json"]), st.text(max_size=8)),
})


def calibrate_checks(opts: dict[str, Any], out: Path) -> None:
    """``calibrate`` up to the announcement of its folder (``_Accepted`` there)."""
    from tribodem.materials.calibration import calibrate

    def accepted(*args: Any, **kwargs: Any) -> None:
        raise _Accepted

    with mock.patch("tribodem.io.runs.announce", accepted):
        try:
            calibrate(out=out, **opts)
        except _Accepted:
            pass


CALIBRATE_NAMES = ("--material", "--seed", "--specimens", "--workers", "--scheduler",
                   "--out")


@given(CALIBRATE_OPTIONS)
@EXAMPLES
def test_calibrate_options_accepted_or_refused_naming_the_option(
        tmp_path: Path, opts: dict[str, Any]) -> None:
    out = tmp_path / "calibrate"
    try:
        calibrate_checks(opts, out)
    except ConfigError as err:
        assert any(n in str(err) for n in CALIBRATE_NAMES), (str(err), opts)
    assert not out.exists()


def sweep_rows() -> st.SearchStrategy[list[dict[str, Any]]]:
    """Tables of a ``fretting sweep`` as dict rows: config columns (or not) with cells of
    any kind."""
    fields = _leaf_fields(FrettingConfig)
    ranges = physical_ranges(FrettingConfig)
    names = sorted(fields)
    odd = st.sampled_from(["name", "contact.bogus", "bogus", "jump.params.jump_length",
                           "contact", ""])
    columns = st.lists(st.one_of(st.sampled_from(names), st.sampled_from(names),
                                 st.sampled_from(names), odd),
                       min_size=1, max_size=3, unique=True)

    @st.composite
    def build(draw: Callable[..., Any]) -> list[dict[str, Any]]:
        cols = draw(columns)
        rows = []
        for _ in range(draw(st.integers(1, 3))):
            row: dict[str, Any] = {}
            for c in cols:
                plausible = _plausible(c, fields[c], ranges) if c in fields else SCALARS
                row[c] = draw(st.one_of(SCALARS, st.lists(SCALARS, max_size=2))
                              if draw(_rarely(4)) else plausible)
            rows.append(row)
        return rows

    return build()


def sweep_checks(rows: list[dict[str, Any]], out: Path) -> None:
    """What ``fretting sweep`` checks of its table before any work (quick, as the tests
    of the sweep run it)."""
    from tribodem.fretting.table_sweep import members

    members(rows, out, None, True)


@given(sweep_rows())
@EXAMPLES
def test_sweep_table_cells_accepted_or_refused_naming_the_field(
        tmp_path: Path, rows: list[dict[str, Any]]) -> None:
    out = tmp_path / "sweep"
    try:
        sweep_checks(rows, out)
    except ConfigError as err:
        text = str(err)
        assert "--table" in text and ("row" in text or "column" in text or "header" in text
                                      or "empty" in text), (text, rows)
    assert not out.exists()


# ---------------------------------------------------------------- through the command

#: how many refused configs of each command go through the installed command
SAMPLE = 5


def _refused(strategy: st.SearchStrategy[Any], check: Callable[[Any], None],
             ok: Callable[[Any], bool] = lambda d: True) -> list[Any]:
    """The first refused examples (at most :data:`SAMPLE`) that ``strategy`` draws in a
    fixed order (derandomized) and ``check`` refuses with ``ConfigError``."""
    found: list[Any] = []

    @given(strategy)
    @settings(max_examples=80, deadline=None, database=None, derandomize=True,
              suppress_health_check=list(HealthCheck))
    def draw(data: Any) -> None:
        if len(found) >= SAMPLE or not ok(data):
            return
        try:
            check(data)
        except ConfigError:
            found.append(data)

    draw()
    assert found, "no refused example drawn"
    return found


def _toml_safe(data: Any) -> bool:
    """Whether ``data`` can be written as a TOML file (no empty table key, no integer
    beyond TOML's 64 bits)."""
    if isinstance(data, dict):
        return all(isinstance(k, str) and _toml_safe(v) for k, v in data.items())
    if isinstance(data, list):
        return all(_toml_safe(v) for v in data)
    if isinstance(data, int) and not isinstance(data, bool):
        return -(2**63) <= data < 2**63
    if isinstance(data, str):
        return "\x00" not in data and all(ord(c) >= 32 or c in "\t\n" for c in data)
    return True


def _assert_refused(r: Any, out: Path, what: Any) -> None:
    text = r.stdout + r.stderr
    assert r.returncode == 2, (r.returncode, text, what)
    assert "Traceback" not in text, text
    assert "error" in text.lower()
    assert not out.exists(), (what, text)


@pytest.mark.parametrize("command", ["fretting", "braking", "dem"])
def test_a_sample_of_refused_configs_through_the_command(tmp_path: Path, command: str
                                                         ) -> None:
    model, check, args = {
        "fretting": (FrettingConfig, fretting_checks, ["fretting", "run"]),
        "braking": (BrakingConfig, braking_checks, ["braking", "run"]),
        "dem": (DemRunConfig, dem_checks, ["dem", "run"]),
    }[command]
    for k, data in enumerate(_refused(config_dicts(model), check, _toml_safe)):
        cfg = tmp_path / f"refused_{k}.toml"
        cfg.write_text(dump_toml(data))
        out = tmp_path / f"out_{k}"
        r = run_tribodem(*args, "--config", str(cfg), "--out", str(out), "--no-progress",
                         timeout=120)
        _assert_refused(r, out, data)


def test_a_sample_of_refused_calibrate_options_through_the_command(tmp_path: Path) -> None:
    out = tmp_path / "calibrate"
    safe = CALIBRATE_OPTIONS.filter(
        lambda o: all(isinstance(v, int) or v is None or ("\x00" not in v and not v.startswith("-"))
                      for v in o.values()))
    for opts in _refused(safe, lambda o: calibrate_checks(o, out)):
        args = ["calibrate", "--out", str(out), "--material", opts["material"],
                "--seed", str(opts["seed"]), "--no-progress"]
        for k in ("specimens", "workers", "scheduler"):
            if opts[k] is not None:
                args += [f"--{k}", str(opts[k])]
        r = run_tribodem(*args, timeout=120)
        _assert_refused(r, out, opts)


def test_a_sample_of_refused_sweep_tables_through_the_command(tmp_path: Path) -> None:
    from tribodem.fretting.table_sweep import cell_text

    out = tmp_path / "sweep"

    def writable(rows: list[dict[str, Any]]) -> bool:
        return all(all(c.isprintable() and "," not in c and '"' not in c and c.strip() == c
                       for c in (*r, *map(cell_text, r.values()))) for r in rows)

    for k, rows in enumerate(_refused(sweep_rows(), lambda rs: sweep_checks(rs, out),
                                      writable)):
        header = list(rows[0])
        table = tmp_path / f"table_{k}.csv"
        table.write_text("\n".join([",".join(header), *(
            ",".join(cell_text(r.get(c)) for c in header) for r in rows)]) + "\n")
        r = run_tribodem("fretting", "sweep", "--table", str(table), "--out", str(out),
                         "--quick", "--workers", "1", "--no-progress", timeout=120)
        _assert_refused(r, out, rows)
