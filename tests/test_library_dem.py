"""tribodem as a library: ``tribodem.dem.run`` and ``tribodem.materials.calibrate`` from
Python (a dict config, a str folder), their ``RunResult``, and a resume that gives what the
command line gives, byte for byte."""

from __future__ import annotations

import inspect
from pathlib import Path

import pytest
from conftest import run_tribodem

import tribodem.dem
import tribodem.materials
from tribodem.dem import DemRunConfig
from tribodem.io.config import ConfigError, dump_toml
from tribodem.io.record import RunResult

#: A small settling run (a few seconds): 300 spheres, 400 steps on one thread.
SMALL = {"case": {"particles": 300, "seed": 3}, "run": {"steps": 400, "threads": 1},
         "output": {"scalars_every": 50, "vtk_every": 200, "checkpoint_every": 200}}

#: Outputs equal byte for byte between the command line and the library.
SAME = ["timeseries.csv", "checkpoint.npz", "config.toml", "vtk/particles.pvd",
        "vtk/chains.pvd"]


def _steps(n: int) -> dict:
    return {**SMALL, "run": {**SMALL["run"], "steps": n}}


def _same(a: Path, b: Path) -> None:
    for name in SAME:
        assert (a / name).read_bytes() == (b / name).read_bytes(), name
    va = sorted(p.name for p in (a / "vtk").glob("*.vtu"))
    assert va == sorted(p.name for p in (b / "vtk").glob("*.vtu")) and va
    for n in va:
        assert (a / "vtk" / n).read_bytes() == (b / "vtk" / n).read_bytes(), n


@pytest.fixture(scope="module")
def command_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The SMALL run made by the installed command."""
    tmp = tmp_path_factory.mktemp("cmd")
    cfg = tmp / "small.toml"
    cfg.write_text(dump_toml(SMALL))
    out = tmp / "out"
    r = run_tribodem("dem", "run", "--config", str(cfg), "--out", str(out), "--no-progress",
                     timeout=300)
    assert r.returncode == 0, r.stderr
    return out


def test_run_from_a_dict_and_a_str_path(tmp_path: Path, command_run: Path) -> None:
    out = str(tmp_path / "lib")
    res = tribodem.dem.run(SMALL, out)
    assert isinstance(res, RunResult) and res.out == Path(out) and res.table == "timeseries.csv"
    assert res.summary["steps"] == 400 and res["particles"] == 300
    assert res.summary["threads"] == 1 and res["case"] == "settle3d"
    df = res.to_dataframe()
    assert list(df["step"]) == list(range(0, 401, 50))
    assert {"time_s", "kinetic_energy_J", "contacts"} <= set(df.columns)
    assert all((res.out / f).is_file() for f in res.files)
    _same(command_run, res.out)  # the command is this function


def test_library_resume_equals_the_command_line_run(tmp_path: Path, command_run: Path) -> None:
    half = tmp_path / "half"
    first = tribodem.dem.run(_steps(200), half)
    assert first.summary["steps"] == 200
    res = tribodem.dem.run(SMALL, str(half), resume=True)
    assert res.summary["steps"] == 400
    _same(command_run, half)
    # and the other way round: started here, resumed by the command from its own record
    other = tmp_path / "other"
    tribodem.dem.run(DemRunConfig.model_validate(_steps(200)), other)
    cfg = tmp_path / "small.toml"
    cfg.write_text(dump_toml(SMALL))
    r = run_tribodem("dem", "run", "--config", str(cfg), "--out", str(other), "--resume",
                     "--no-progress", timeout=300)
    assert r.returncode == 0, r.stderr
    _same(command_run, other)


def test_refusals_before_any_work(tmp_path: Path) -> None:
    out = tmp_path / "o"
    with pytest.raises(ConfigError, match="run.stepz"):
        tribodem.dem.run({"run": {"stepz": 3}}, out)
    with pytest.raises(ConfigError, match="case.particles"):
        tribodem.dem.run({"case": {"particles": -5}}, out)
    with pytest.raises(ConfigError, match="--out"):
        tribodem.dem.run(SMALL, "")
    with pytest.raises(ConfigError, match="--out"):
        tribodem.dem.run(SMALL, out, resume=True)  # nothing to resume
    assert not out.exists()
    tribodem.dem.run(_steps(50), out)
    with pytest.raises(ConfigError, match="case.seed"):
        tribodem.dem.run({**SMALL, "case": {"particles": 300, "seed": 4}}, out, resume=True)


def test_quick_preset_and_echo(tmp_path: Path) -> None:
    from tribodem.dem.demo import resolve_config

    quick = DemRunConfig.quick()
    assert quick.case.particles == 1000 and quick.run.steps == 3000
    assert quick.output.vtk_every == 500 and quick.output.checkpoint_every == 500
    # the preset wins over the config; the config's other fields stay
    cfg = resolve_config({"case": {"particles": 50}, "output": {"scalars_every": 10}},
                         quick=True)
    assert cfg.case.particles == 1000 and cfg.output.scalars_every == 10
    said: list[str] = []
    res = tribodem.dem.run({**_steps(50), "output": {"vtk_every": 0, "checkpoint_every": 0}},
                           tmp_path / "q", echo=said.append)
    assert len(said) == 1 and '"steps": 50' in said[0] and res.summary["steps"] == 50
    assert not (tmp_path / "q" / "vtk").exists() and "checkpoint.npz" not in res.files


def test_calibrate_from_python(tmp_path: Path) -> None:
    sig = inspect.signature(tribodem.materials.calibrate)
    assert list(sig.parameters)[:2] == ["material", "out"]
    assert {"quick", "specimens", "workers", "scheduler", "progress", "echo"} <= set(
        sig.parameters)
    res = tribodem.materials.calibrate("Q345B", str(tmp_path / "cal"), quick=True)
    assert res.summary["ran_on"] == "this process" and res["converged"]
    df = res.to_dataframe()
    assert len(df) == res["iterations"] and "E_rel_error" in df.columns
    assert (res.out / "stress_strain.png").is_file()
    with pytest.raises(ConfigError, match="steel"):
        tribodem.materials.calibrate("steel", tmp_path / "x")
