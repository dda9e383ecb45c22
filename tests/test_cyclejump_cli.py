"""``tribodem jump replay``: output, plot, and refusal of bad CSVs (exit 2)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from tribodem.cyclejump import synthetic_two_phase_series
from tribodem.cyclejump.cli import jump_app, parse_params
from tribodem.cyclejump.recorded import read_increments_csv
from tribodem.io.config import ConfigError

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "wear_increments_two_phase.csv"


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "tribodem.cli", "jump", "replay", *args],
                          cwd=ROOT, capture_output=True, text=True, timeout=120)


def write(tmp_path: Path, text: str, name: str = "in.csv") -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


def series_csv(tmp_path: Path, n: int = 300, **kw) -> Path:
    c, inc = synthetic_two_phase_series(n=n, **kw)
    lines = ["cycle,increment"]
    lines += [f"{int(a)},{float(b)!r}" for a, b in zip(c, inc, strict=True)]
    return write(tmp_path, "\n".join(lines) + "\n", f"s{n}.csv")


def test_example_csv_is_the_synthetic_series():
    c, inc = read_increments_csv(EXAMPLE)
    c0, inc0 = synthetic_two_phase_series(n=2000, seed=0)
    assert len(c) == 2000
    np.testing.assert_array_equal(c, c0)
    np.testing.assert_allclose(inc, inc0, rtol=1e-15)


def test_replay_json_adaptive_example(tmp_path):
    png = tmp_path / "fig" / "replay.png"
    p = run("--strategy", "adaptive", "--input", str(EXAMPLE), "--json", "--plot", str(png))
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    for key in ("strategy", "cycles_total", "cycles_simulated", "cycles_saved_fraction",
                "final_value", "reference_final_value", "relative_difference",
                "max_relative_difference"):
        assert key in out
    assert out["strategy"] == "adaptive" and out["cycles_total"] == 2000
    assert out["cycles_saved_fraction"] == pytest.approx(1 - out["cycles_simulated"] / 2000)
    assert out["cycles_saved_fraction"] >= 0.6
    ref = float(np.sum(read_increments_csv(EXAMPLE)[1]))
    assert out["reference_final_value"] == pytest.approx(ref)
    assert out["relative_difference"] == pytest.approx(
        abs(out["final_value"] - ref) / ref)
    assert out["relative_difference"] <= out["max_relative_difference"] <= 0.1
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not [f for f in png.parent.iterdir() if f.name.endswith(".tmp.png")]


@pytest.mark.parametrize("strategy", ["constant", "cojocaru", "moving", "overlapping"])
def test_replay_every_strategy_with_params(tmp_path, strategy):
    csv = series_csv(tmp_path, noise=0.0, ratio=1.0)
    extra = {"constant": ["--param", "jump_length=30"],
             "cojocaru": ["--param", "q_y=0.05", "--param", "max_jump=50"],
             "moving": ["--param", "group_size=10"],
             "overlapping": ["--param", "group_size=10", "--param", "q_e=0.002"]}[strategy]
    p = run("--strategy", strategy, "--input", str(csv), "--json", *extra)
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout)
    assert out["cycles_saved_fraction"] > 0.5
    assert out["relative_difference"] < 1e-9
    key, val = extra[1].split("=")
    assert str(out["params"][key]) == val


BAD = {
    "missing column": ("cycle,wear\n1,0.1\n2,0.1\n", "missing column(s) 'increment'"),
    "non-numeric": ("cycle,increment\n1,0.1\n2,abc\n3,0.1\n",
                    "line 3, column 'increment': value 'abc' is not a number"),
    "non-increasing": ("cycle,increment\n1,0.1\n2,0.1\n2,0.1\n",
                       "line 4, column 'cycle': value 2 is not greater than the previous"),
    "gap": ("cycle,increment\n1,0.1\n2,0.1\n5,0.1\n", "skips cycles after 2"),
    "nan": ("cycle,increment\n1,0.1\n2,nan\n", "is not finite"),
    "empty": ("", "is empty"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_csv_exit_2(tmp_path, case):
    text, msg = BAD[case]
    csv = write(tmp_path, text)
    p = run("--strategy", "constant", "--input", str(csv))
    assert p.returncode == 2, (p.stdout, p.stderr)
    assert msg in p.stderr
    assert str(csv) in p.stderr
    assert "Traceback" not in p.stderr
    with pytest.raises(ConfigError, match="input file"):
        read_increments_csv(csv)


def test_fewer_rows_than_foundation_exit_2(tmp_path):
    csv = series_csv(tmp_path, n=8)
    p = run("--strategy", "adaptive", "--input", str(csv))
    assert p.returncode == 2
    assert "has 8 data rows; the 'adaptive' strategy needs at least 9" in p.stderr
    assert run("--strategy", "moving", "--input", str(csv)).returncode == 2
    ok = run("--strategy", "cojocaru", "--input", str(csv))
    assert ok.returncode == 0, ok.stderr


@pytest.mark.parametrize("args, msg", [
    (["--strategy", "bogus"], "--strategy 'bogus' is unknown; allowed: constant"),
    (["--strategy", "adaptive", "--param", "nope=1"], "'nope' is not a parameter"),
])
def test_bad_options_exit_2(args, msg):
    p = run(*args, "--input", str(EXAMPLE))
    assert p.returncode == 2, (p.stdout, p.stderr)
    assert msg in p.stderr
    assert "Traceback" not in p.stderr


@pytest.mark.parametrize("args, msg", [
    (["--strategy", "polynomial", "--param", "q_y=abc"], "expected float"),
    (["--strategy", "polynomial", "--param", "degree=2.5"], "expected int"),
    (["--strategy", "polynomial", "--param", "taylor_order=3"], "taylor_order = 3: must be"),
    (["--strategy", "constant", "--param", "jump_length"], "expected key=value"),
    (["--strategy", "moving", "--param", "moving_window=1"], "not a parameter"),
])
def test_bad_params_raise_config_error_in_process(args, msg):
    res = CliRunner().invoke(jump_app, ["replay", *args, "--input", str(EXAMPLE)])
    assert isinstance(res.exception, ConfigError)
    assert msg in str(res.exception)


def test_missing_input_file_exit_2(tmp_path):
    p = run("--strategy", "adaptive", "--input", str(tmp_path / "none.csv"))
    assert p.returncode == 2
    assert "does not exist" in p.stderr


def test_parse_params_types():
    assert parse_params("polynomial", ["degree_late=none", "moving_window=false",
                                     "q_e=0.01", "max_jump_initial=15"]) == {
        "degree_late": None, "moving_window": False, "q_e": 0.01, "max_jump_initial": 15}
    with pytest.raises(ConfigError):
        parse_params("constant", ["q_y=1"])


def test_extra_columns_and_crlf_accepted(tmp_path):
    csv = write(tmp_path, "cycle,increment,note\r\n1,1.0,a\r\n2,1.0,b\r\n3,1.0,c\r\n")
    c, inc = read_increments_csv(csv)
    assert list(c) == [1, 2, 3] and list(inc) == [1.0, 1.0, 1.0]
