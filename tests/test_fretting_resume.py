"""``tribodem fretting run`` is resumable and honest, through the installed command.

A run killed (SIGKILL) or interrupted (Ctrl-C) at a random point and continued with
``--resume`` writes the same results.csv and summary.json numbers as an uninterrupted run
(bitwise; only wall-clock timings differ); so do resumed runs with cycle-jumping and with
the debris third body. Bad inputs are refused before any output is written; a checkpoint
made with another config is refused without touching the outputs; an early stop exits 3
with everything so far written.
"""

from __future__ import annotations

import json
import random
import signal
import subprocess
import time
from pathlib import Path

import pytest
from conftest import before_config_v2 as _before_v2
from conftest import run_tribodem, tribodem_exe, without_timings

from tribodem.fretting.config import resolve_config
from tribodem.fretting.runner import run
from tribodem.io.config import merge
from tribodem.io.runs import RunStopped

SMALL = "[output]\nfigures = false\nvtk = false\n"
CYCLES = "30"


def _same_outputs(a: Path, b: Path) -> None:
    assert (a / "results.csv").read_bytes() == (b / "results.csv").read_bytes()
    sa = json.loads((a / "summary.json").read_text())
    sb = json.loads((b / "summary.json").read_text())
    assert without_timings(sa) == without_timings(sb)
    assert (a / "config.toml").read_bytes() == (b / "config.toml").read_bytes()


def _args(cfg: Path, out: Path, *extra: str) -> list[str]:
    return ["fretting", "run", "--quick", "--config", str(cfg), "--cycles", CYCLES,
            "--no-progress", "--out", str(out), *extra]


@pytest.fixture(scope="module")
def small_cfg(tmp_path_factory: pytest.TempPathFactory) -> Path:
    p = tmp_path_factory.mktemp("cfg") / "small.toml"
    p.write_text(SMALL)
    return p


@pytest.fixture(scope="module")
def reference(small_cfg: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """An uninterrupted run."""
    out = tmp_path_factory.mktemp("ref") / "run"
    r = run_tribodem(*_args(small_cfg, out), timeout=120)
    assert r.returncode == 0, r.stderr
    assert len((out / "results.csv").read_text().splitlines()) == int(CYCLES) + 1
    return out


def _start_and_signal(args: list[str], out: Path, sig: int) -> subprocess.CompletedProcess:
    """Start a run, wait for its first checkpoint, wait a random short time, send ``sig``."""
    # SIGINT as from a terminal: a shell starting background jobs may leave it ignored (and
    # Python then keeps it ignored), so the child gets the default disposition back
    proc = subprocess.Popen([tribodem_exe(), *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    ck = out / "checkpoint.npz"
    t_end = time.monotonic() + 90
    while not ck.exists() and proc.poll() is None and time.monotonic() < t_end:
        time.sleep(0.02)
    assert ck.exists(), "no checkpoint was written"
    time.sleep(random.uniform(0.0, 0.5))
    proc.send_signal(sig)
    stdout, stderr = proc.communicate(timeout=60)
    return subprocess.CompletedProcess(proc.args, proc.returncode, stdout, stderr)


def test_kill_9_then_resume_equals_uninterrupted(small_cfg: Path, reference: Path,
                                                 tmp_path: Path) -> None:
    out = tmp_path / "run"
    r = _start_and_signal(_args(small_cfg, out), out, signal.SIGKILL)
    assert r.returncode in (-signal.SIGKILL, 0)  # 0: it finished before the kill
    done = len((out / "results.csv").read_text().splitlines()) - 1
    assert 1 <= done <= int(CYCLES)
    r = run_tribodem(*_args(small_cfg, out, "--resume"), timeout=120)
    assert r.returncode == 0, r.stderr
    _same_outputs(reference, out)


def test_ctrl_c_exits_130_naming_outputs_then_resume_equals(small_cfg: Path, reference: Path,
                                                            tmp_path: Path) -> None:
    out = tmp_path / "run"
    r = _start_and_signal(_args(small_cfg, out), out, signal.SIGINT)
    if r.returncode == 0:  # finished before the signal arrived: nothing to check there
        pytest.skip("the run finished before Ctrl-C")
    assert r.returncode == 130, r.stderr
    assert "Traceback" not in r.stderr, r.stderr
    assert str(out) in r.stderr and "checkpoint" in r.stderr and "--resume" in r.stderr
    r = run_tribodem(*_args(small_cfg, out, "--resume"), timeout=120)
    assert r.returncode == 0, r.stderr
    _same_outputs(reference, out)


def test_a_run_carried_to_another_folder_resumes_to_the_same_result(
        small_cfg: Path, reference: Path, tmp_path: Path) -> None:
    """``tools/carry_run pack`` takes what ``--resume`` needs of a killed run, and nothing
    else the run depends on: unpacked into another folder (as on another machine), the run
    goes on there to the uninterrupted run's results, bitwise."""
    root = Path(__file__).resolve().parents[1]
    out = tmp_path / "here" / "run"
    r = _start_and_signal(_args(small_cfg, out), out, signal.SIGKILL)
    assert r.returncode in (-signal.SIGKILL, 0)
    archive = tmp_path / "run.tar.gz"
    carry = ["bash", str(root / "tools" / "carry_run")]
    r = subprocess.run([*carry, "pack", str(out), str(archive)], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    r = subprocess.run([*carry, "unpack", str(archive), str(tmp_path / "there")],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    moved = tmp_path / "there" / "run"
    assert {p.name for p in moved.iterdir()} <= {
        "checkpoint.npz", "config.toml", "results.csv", "criterion.csv", "summary.json"}
    r = run_tribodem(*_args(small_cfg, moved, "--resume"), timeout=120)
    assert r.returncode == 0, r.stderr
    _same_outputs(reference, moved)
    r = subprocess.run([*carry, "pack", str(tmp_path / "nowhere"), str(archive)],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and "nowhere" in r.stderr, r.stderr


def _in_process(tmp: Path, monkeypatch: pytest.MonkeyPatch, name: str, cycles: int,
                extra: dict, stop_after: int) -> None:
    """Uninterrupted vs interrupted (Ctrl-C raised right after the ``stop_after``-th
    checkpoint, so the rest of that cycle's work is lost) and resumed (Python API)."""
    import tribodem.fretting.runner as fcli

    ov = merge({"output": {"figures": False, "vtk": True, "checkpoint_seconds": 0}}, extra)
    cfg = resolve_config(None, quick=True, overrides=merge(ov, {"cycles": cycles}))
    run(cfg, tmp / f"{name}_a")
    real, calls = fcli.write_checkpoint, []

    def interrupted(*args, **kw):  # noqa: ANN002, ANN003, ANN202
        real(*args, **kw)
        calls.append(1)
        if len(calls) == stop_after:
            raise KeyboardInterrupt

    monkeypatch.setattr(fcli, "write_checkpoint", interrupted)
    with pytest.raises(KeyboardInterrupt):
        run(cfg, tmp / f"{name}_b")
    monkeypatch.undo()
    run(cfg, tmp / f"{name}_b", resume=True)
    _same_outputs(tmp / f"{name}_a", tmp / f"{name}_b")
    for f in ("surface_upper.vtu", "surface_lower.vtu"):  # the wear maps
        assert (tmp / f"{name}_a" / f).read_bytes() == (tmp / f"{name}_b" / f).read_bytes()


@pytest.mark.parametrize(("jump", "cycles", "stop_after"), [
    ({"strategy": "constant", "params": {"jump_length": 3}}, 12, 2),
    ({"strategy": "polynomial", "params": {"foundation_cycles": 4, "max_jump_initial": 4}},
     20, 5),
    ({"strategy": "adaptive", "params": {"foundation_cycles": 6, "max_jump_initial": 4}},
     20, 5),
])
def test_resume_with_jumping_equals_uninterrupted(tmp_path: Path,
                                                  monkeypatch: pytest.MonkeyPatch,
                                                  jump: dict, cycles: int,
                                                  stop_after: int) -> None:
    _in_process(tmp_path, monkeypatch, "jump", cycles, {"jump": jump}, stop_after)
    rows = (tmp_path / "jump_a" / "results.csv").read_text().splitlines()[1:]
    assert any(r.split(",")[1] == "1" for r in rows), "no cycle was jumped"
    # the summary's decisions (compared whole above, so carried through the checkpoint)
    d = json.loads((tmp_path / "jump_b" / "summary.json").read_text())["jump"]
    assert d["decisions"]["cycles_jumped"] == sum(r.split(",")[1] == "1" for r in rows)
    assert "cycles were jumped" in d["reading"] or "proposed no jump" in d["reading"]


def test_resume_with_debris_equals_uninterrupted(tmp_path: Path,
                                                 monkeypatch: pytest.MonkeyPatch) -> None:
    # 2.5 um particles (about 150, not 10,000) and short DE phases keep it to seconds; a DE
    # phase before the stop (cycle 2) and one after it (cycle 4)
    debris = {"every": 2, "diameter": 2.5e-6, "max_steps": 3000, "ramp_steps": 1000}
    _in_process(tmp_path, monkeypatch, "debris", 5, {"debris": debris}, 3)
    s = json.loads((tmp_path / "debris_a" / "summary.json").read_text())
    assert len(s["debris"]["de_phases"]) == 2


def test_config_round_trip_and_finished_resume(small_cfg: Path, tmp_path: Path) -> None:
    a, b = tmp_path / "a", tmp_path / "b"
    r = run_tribodem("fretting", "run", "--quick", "--config", str(small_cfg), "--cycles", "2",
                     "--jump", "constant", "--no-progress", "--out", str(a), timeout=120)
    assert r.returncode == 0, r.stderr
    text = (a / "config.toml").read_text()
    assert "none" not in text.replace('strategy = "none"', "")  # None fields left out
    r = run_tribodem("fretting", "run", "--config", str(a / "config.toml"), "--no-progress",
                     "--out", str(b), timeout=120)
    assert r.returncode == 0, r.stderr
    assert (a / "config.toml").read_bytes() == (b / "config.toml").read_bytes()
    _same_outputs(a, b)
    before = (a / "results.csv").read_bytes()
    r = run_tribodem("fretting", "run", "--out", str(a), "--resume", "--no-progress",
                     timeout=120)  # a finished run: outputs rewritten, same numbers
    assert r.returncode == 0, r.stderr
    assert (a / "results.csv").read_bytes() == before


#: a window just above the minimum (4 Hertz radii) and a wear rate 100x the seed's: the
#: worn contact reaches the window edge in cycle 5
OUTGROWS = {"contact": {"window": 5.4e-4}, "wear": {"alpha": 1e-11}}


def test_early_stop_exits_3_with_outputs(tmp_path: Path) -> None:
    cfg = tmp_path / "stop.toml"
    cfg.write_text("[contact]\nwindow = 5.4e-4\n[wear]\nalpha = 1e-11\n[output]\nvtk = false\n")
    out = tmp_path / "run"
    r = run_tribodem("fretting", "run", "--quick", "--config", str(cfg), "--cycles", "8",
                     "--no-progress", "--out", str(out), timeout=180)
    assert r.returncode == 3, r.stderr
    assert "run stopped" in r.stderr and "window" in r.stderr and str(out) in r.stderr
    assert "Traceback" not in r.stderr
    s = json.loads((out / "summary.json").read_text())
    assert s["stopped"] and s["cycles"] < 8
    rows = (out / "results.csv").read_text().splitlines()
    assert len(rows) == s["cycles"] + 1
    assert (out / "wear_scar.png").stat().st_size > 0


def test_window_smaller_than_contact_refused_before_output(tmp_path: Path) -> None:
    cfg = tmp_path / "w.toml"
    cfg.write_text("[contact]\nwindow = 2e-4\n")
    out = tmp_path / "new"
    r = run_tribodem("fretting", "run", "--config", str(cfg), "--out", str(out), timeout=120)
    assert r.returncode == 2, r.stderr
    assert "contact.window" in r.stderr and "0.0002" in r.stderr and "allowed: >=" in r.stderr
    assert "Traceback" not in r.stderr
    assert not out.exists()


def test_unknown_jump_param_refused(tmp_path: Path) -> None:
    cfg = tmp_path / "j.toml"
    cfg.write_text("[jump]\nstrategy = 'adaptive'\n[jump.params]\nq_why = 3\n")
    out = tmp_path / "new"
    r = run_tribodem("fretting", "run", "--config", str(cfg), "--out", str(out), timeout=120)
    assert r.returncode == 2, r.stderr
    assert "q_why" in r.stderr and "tol" in r.stderr and "foundation_cycles" in r.stderr
    assert not out.exists()


def test_mismatched_or_corrupt_checkpoint_refused_outputs_untouched(small_cfg: Path,
                                                                    tmp_path: Path) -> None:
    out = tmp_path / "run"
    r = run_tribodem("fretting", "run", "--quick", "--config", str(small_cfg), "--cycles", "2",
                     "--no-progress", "--out", str(out), timeout=120)
    assert r.returncode == 0, r.stderr

    def snapshot() -> dict[str, tuple[bytes, int]]:
        return {p.name: (p.read_bytes(), p.stat().st_mtime_ns) for p in out.iterdir()}

    before = snapshot()
    r = run_tribodem("fretting", "run", "--quick", "--config", str(small_cfg), "--cycles", "4",
                     "--criterion", "archard", "--no-progress", "--out", str(out), "--resume",
                     timeout=120)
    assert r.returncode == 2, r.stderr
    assert "wear.criterion = 'archard'" in r.stderr and "'energy'" in r.stderr
    assert snapshot() == before
    r = run_tribodem("fretting", "run", "--quick", "--config", str(small_cfg), "--cycles", "1",
                     "--no-progress", "--out", str(out), "--resume", timeout=120)
    assert r.returncode == 2 and "cycles = 1" in r.stderr, r.stderr
    assert snapshot() == before
    ck = out / "checkpoint.npz"
    ck.write_bytes(ck.read_bytes()[: ck.stat().st_size // 2])
    before = snapshot()
    r = run_tribodem("fretting", "run", "--out", str(out), "--resume", timeout=120)
    assert r.returncode == 2, r.stderr
    assert f"checkpoint '{ck}' cannot be read" in r.stderr and "Traceback" not in r.stderr
    assert snapshot() == before


def test_python_api_early_stop_raises_run_stopped(tmp_path: Path) -> None:
    cfg = resolve_config(None, quick=True, overrides=merge(OUTGROWS, {
        "cycles": 8, "output": {"figures": False, "vtk": False}}))
    with pytest.raises(RunStopped, match="window"):
        run(cfg, tmp_path / "run")
    assert json.loads((tmp_path / "run" / "summary.json").read_text())["stopped"]


def test_resume_accepts_a_field_added_since_the_checkpoint_at_its_default_only() -> None:
    """A checkpoint made before a config field existed lacks it: resuming is allowed while
    the field keeps its default (the behaviour the checkpoint ran with), refused otherwise."""
    from tribodem.fretting.config import FrettingConfig, check_resume
    from tribodem.io.config import ConfigError

    cfg = FrettingConfig()
    old = json.loads(json.dumps(cfg.model_dump()))
    del old["fe"]["plastic_increments"]
    meta = {"config": old, "cycles_done": 0}
    check_resume(cfg, meta, Path("ck.npz"))  # the default: same behaviour
    changed = FrettingConfig(fe={"plastic_increments": 16})
    absent = r"fe\.plastic_increments = 16 \(checkpoint: '<absent>'\)"
    with pytest.raises(ConfigError, match=absent):
        check_resume(changed, meta, Path("ck.npz"))


def test_a_recorded_config_from_before_config_version_2_reads_the_old_defaults_as_left_out(
) -> None:
    """An unmarked recorded config's [fe] 0.25 / 40 (recorded for every run) are read as left
    out: an old default fe3d checkpoint resumes with the fields left out (as a/3, 8 a) and
    refuses 0.25 (a/4 is another run), naming the values fe3d gets; old fe and elastic
    checkpoints resume with the fields left out or at 0.25 / 40. A marked config (this
    version's) is read as it is: its fe3d 0.25 stays a/4."""
    from tribodem.fretting.config import (
        CONFIG_VERSION,
        FrettingConfig,
        check_resume,
        recorded_config,
    )
    from tribodem.io.config import ConfigError

    ck = Path("checkpoint.npz")
    fe3d = FrettingConfig(solver="fe3d")
    old = _before_v2(fe3d)
    read = recorded_config(old)
    assert read["config_version"] == CONFIG_VERSION
    assert (read["fe"]["h_over_a"], read["fe"]["size_factor"]) == (None, None)
    low = fe3d.model_copy(update={"fe": fe3d.fe.model_copy(update={"loading_friction": "low"})})
    assert resolve_config(None, base=read) == low  # the resume without --config (v4: low)
    check_resume(fe3d, {"config": old}, ck)
    a4 = FrettingConfig(solver="fe3d", fe={"h_over_a": 0.25})
    with pytest.raises(ConfigError, match=r"fe\.h_over_a = 0\.25 \(checkpoint: 0\.333"):
        check_resume(a4, {"config": old}, ck)
    marked = json.loads(json.dumps(a4.model_dump()))
    assert recorded_config(marked) == marked
    check_resume(a4, {"config": marked}, ck)
    with pytest.raises(ConfigError, match=r"fe\.h_over_a = 0\.333.* \(checkpoint: 0\.25\)"):
        check_resume(fe3d, {"config": marked}, ck)
    line = {"contact": {"geometry": "cylinder_on_flat", "radius": 4e-3}}
    for solver, extra in (("fe", line), ("elastic", {})):
        left_out = FrettingConfig.model_validate({"solver": solver, **extra})
        stated = FrettingConfig.model_validate(
            {"solver": solver, **extra, "fe": {"h_over_a": 0.25, "size_factor": 40.0}})
        for cfg in (left_out, stated):
            check_resume(cfg, {"config": _before_v2(left_out)}, ck)


def test_a_version_2_record_keeps_the_flow_stress_its_ccx_bodies_ran_with(
        tmp_path: Path) -> None:
    """Before config_version 3 the ccx backends held the flow stress at the UTS (their
    *PLASTIC table's last row) unless [plastic] hardening was given; tamaas's line went on.
    A version-2 record reads as what ran: fe3d elastic-plastic -> beyond_uts 'hold', with a
    hardening given, elastic bodies or tamaas -> 'line'. Its resume from a config that
    leaves beyond_uts out (now 'line') is refused naming the field; a run's version-2
    config.toml given back with --config runs 'hold' as it did."""
    from tribodem.fretting.config import (
        CONFIG_VERSION,
        FrettingConfig,
        check_resume,
        recorded_config,
    )
    from tribodem.io.config import ConfigError, dump_toml

    def v2(cfg: FrettingConfig) -> dict:
        old = json.loads(json.dumps(cfg.model_dump()))
        del old["plastic"]["beyond_uts"], old["fe"]["loading_friction"]
        return old | {"config_version": 2}

    ep = FrettingConfig(solver="fe3d", fe={"material": "elastic-plastic"})
    read = recorded_config(v2(ep))
    assert read["config_version"] == CONFIG_VERSION
    assert read["plastic"]["beyond_uts"] == "hold"
    for cfg in (FrettingConfig(solver="fe3d", fe={"material": "elastic-plastic"},
                               plastic={"hardening": 2.5e9}),
                FrettingConfig(solver="fe3d"), FrettingConfig(solver="elastic-plastic")):
        assert recorded_config(v2(cfg))["plastic"]["beyond_uts"] == "line"
        check_resume(cfg, {"config": v2(cfg)}, Path("ck.npz"))
    with pytest.raises(ConfigError, match=r"plastic\.beyond_uts = 'line' \(checkpoint: "
                                          r"'hold'\)"):
        check_resume(ep, {"config": v2(ep)}, Path("ck.npz"))
    held = ep.model_copy(update={"plastic": ep.plastic.model_copy(
        update={"beyond_uts": "hold"})})
    check_resume(held, {"config": v2(ep)}, Path("ck.npz"))
    given_back = tmp_path / "config.toml"
    given_back.write_text(dump_toml(v2(ep)))
    assert resolve_config(given_back) == held.model_copy(update={"fe": held.fe.model_copy(
        update={"loading_friction": "low"})})


def test_a_version_3_record_keeps_the_low_friction_its_ccx_bodies_were_loaded_with(
        tmp_path: Path) -> None:
    """Before config_version 4 the ccx backends seated and loaded the bodies with friction
    0.001: a version-3 record of fe or fe3d without ``[fe] loading_friction`` reads as
    'low' (one that names it keeps it); other solvers' records get the default (the field
    does nothing there, and the record compares equal to this version's). A resume may
    change it (the cycles after are another run's: each cycle's ``loading_mu`` says which
    ran); a run's version-3 config.toml given back with --config loads the bodies as it
    did."""
    from tribodem.fretting.config import (
        CONFIG_VERSION,
        FrettingConfig,
        check_resume,
        recorded_config,
    )
    from tribodem.io.config import dump_toml

    def v3(cfg: FrettingConfig, drop: bool = True) -> dict:
        old = json.loads(json.dumps(cfg.model_dump()))
        if drop:
            del old["fe"]["loading_friction"]
        return old | {"config_version": 3}

    line = {"contact": {"geometry": "cylinder_on_flat", "radius": 4e-3}}
    for cfg in (FrettingConfig(solver="fe3d"), FrettingConfig.model_validate(
            {"solver": "fe", **line, "fe": {"material": "elastic-plastic"}})):
        assert cfg.fe.loading_friction == "auto"  # the default since version 4
        read = recorded_config(v3(cfg))
        assert read["config_version"] == CONFIG_VERSION
        assert read["fe"]["loading_friction"] == "low"
        check_resume(cfg, {"config": v3(cfg)}, Path("ck.npz"))  # may change on resume
        assert recorded_config(v3(cfg, drop=False))["fe"]["loading_friction"] == "auto"
        given_back = tmp_path / "config.toml"
        given_back.write_text(dump_toml(v3(cfg)))
        assert resolve_config(given_back).fe.loading_friction == "low"
    elastic = FrettingConfig(solver="elastic")
    other = recorded_config(v3(elastic))  # the field does nothing there: the default
    assert other["fe"]["loading_friction"] == "auto"
    assert other["config_version"] == CONFIG_VERSION
    assert resolve_config(None, base=other) == elastic


def test_a_new_config_round_trips_with_its_marker(tmp_path: Path) -> None:
    """What tribodem writes carries config_version: config.toml (the [fe] fields left out
    stay out and reload as left out) and a checkpoint (read back unchanged, None stays
    None, so a resume makes the same run)."""
    from tribodem.fretting.config import (
        CONFIG_VERSION,
        FrettingConfig,
        check_resume,
        recorded_config,
    )
    from tribodem.fretting.output import read_checkpoint, write_checkpoint
    from tribodem.io.config import dump_toml

    cfg = FrettingConfig(solver="fe3d")
    text = dump_toml(cfg.model_dump())
    assert f"config_version = {CONFIG_VERSION}" in text and "h_over_a" not in text
    path = tmp_path / "config.toml"
    path.write_text(text)
    assert resolve_config(path) == cfg
    write_checkpoint(tmp_path / "checkpoint.npz", {"config": json.loads(json.dumps(
        cfg.model_dump())), "cycles_done": 1}, {})
    meta, _ = read_checkpoint(tmp_path / "checkpoint.npz")
    assert meta["config"]["config_version"] == CONFIG_VERSION
    assert meta["config"]["fe"]["h_over_a"] is None
    assert resolve_config(None, base=recorded_config(meta["config"])) == cfg
    check_resume(cfg, meta, tmp_path / "checkpoint.npz")


def test_a_checkpoint_from_before_config_version_2_resumes(tmp_path: Path) -> None:
    """A real run's checkpoint rewritten as before config_version 2 (no marker, [fe] 0.25 /
    40) resumes: from its own config (``--resume`` alone) and from a config file that leaves
    [fe] out; the resumed run records the marker and the fields left out. Old study.toml
    files and a sweep member's old summary.json are read the same way."""
    from tribodem.fretting.config import recorded_config
    from tribodem.fretting.output import CHECKPOINT, read_checkpoint, write_checkpoint
    from tribodem.fretting.record import study_diffs
    from tribodem.fretting.table_sweep import member_plan
    from tribodem.io.config import dump_toml

    cfg = resolve_config(None, quick=True, overrides={
        "cycles": 2, "output": {"figures": False, "vtk": False}})
    out = tmp_path / "run"
    run(cfg, out)
    meta, state = read_checkpoint(out / CHECKPOINT)
    old = _before_v2(cfg)
    write_checkpoint(out / CHECKPOINT, {**meta, "config": old}, state)
    more = resolve_config(None, overrides={"cycles": 3}, base=recorded_config(old))
    assert more == cfg.model_copy(update={"cycles": 3})
    run(more, out, resume=True)
    meta, state = read_checkpoint(out / CHECKPOINT)
    assert meta["cycles_done"] == 3 and meta["config"] == more.record()
    write_checkpoint(out / CHECKPOINT, {**meta, "config": _before_v2(more)}, state)
    run(more.model_copy(update={"cycles": 4}), out, resume=True)  # --config FILE
    assert read_checkpoint(out / CHECKPOINT)[0]["cycles_done"] == 4
    # a study's study.toml and a sweep member's summary.json of before
    (tmp_path / "study.toml").write_text(dump_toml({"config": old, "quick": True}))
    assert study_diffs(tmp_path, {"config": cfg.record(), "quick": True}) == []
    member = tmp_path / "member"
    member.mkdir()
    (member / "summary.json").write_text(json.dumps({"config": old, "cycles": 2}))
    assert member_plan(cfg.record(), member)[0] == "done"


def test_a_study_resumes_with_other_threads_or_retries_and_names_what_may_not_change(
        tmp_path: Path) -> None:
    """A study (``fretting study``, ``debris-study``) resumes under the rule of a run's
    resume: how ccx runs (``fe.threads`` / ``retries`` / ``timeout``) may change (a long
    fe3d study goes on on another machine, or with more retries after a non-convergence);
    a field that makes another run is refused by name with both values, and so is
    ``--quick``."""
    from tribodem.fretting.record import study_diffs
    from tribodem.io.config import dump_toml

    cfg = resolve_config(None, overrides={"solver": "fe3d", "fe": {"threads": 2}})
    (tmp_path / "study.toml").write_text(dump_toml({"config": cfg.record(), "quick": False}))
    other = cfg.model_copy(update={"fe": cfg.fe.model_copy(
        update={"threads": 1, "retries": 4, "timeout": 7200.0})})
    assert study_diffs(tmp_path, {"config": other.record(), "quick": False}) == []
    rougher = cfg.model_copy(update={"contact": cfg.contact.model_copy(
        update={"friction": 0.7})})
    assert study_diffs(tmp_path, {"config": rougher.record(), "quick": True}) == [
        f"contact.friction = 0.7 (study: {cfg.contact.friction!r})", "quick = True (study: False)"]
    # a debris study's cycle is its phases' cycle: there, cycles may not change
    later = cfg.model_copy(update={"cycles": 40}).record()
    assert study_diffs(tmp_path, {"config": later, "quick": False}) == []
    assert study_diffs(tmp_path, {"config": later, "quick": False}, may_change=("fe.",)) == [
        f"cycles = 40 (study: {cfg.cycles!r})"]


def test_a_recorded_config_reloads_to_the_same_config(tmp_path: Path) -> None:
    """What tribodem records of a config (``config.toml``, study.toml: TOML, which has no
    null) reloads to the same config, field for field: a field left out (None) whose
    default is not None, such as ``[fe] max_wear_slope = "off"`` (default 0.1), is recorded
    in a form that reloads as itself."""
    from tribodem.fretting.config import FrettingConfig, recorded_config
    from tribodem.io.config import dump_toml, load_toml

    cfg = resolve_config(None, overrides={"solver": "fe3d", "fe": {
        "max_wear_slope": "off", "h_over_a": 0.25, "timeout": 60.0}})
    assert cfg.fe.max_wear_slope is None and cfg.fe.size_factor is None
    path = tmp_path / "config.toml"
    path.write_text(dump_toml(cfg.record()))
    assert FrettingConfig.model_validate(recorded_config(load_toml(path))) == cfg
    assert resolve_config(None, base=recorded_config(load_toml(path))) == cfg
    # and the run's own config.toml, given back with --config
    out = tmp_path / "run"
    run(resolve_config(None, quick=True, overrides={
        "cycles": 1, "fe": {"max_wear_slope": "off"}, "output": {"figures": False,
                                                                 "vtk": False}}), out)
    assert resolve_config(out / "config.toml").fe.max_wear_slope is None
