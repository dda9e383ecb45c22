"""Atomic writes after an interruption, and Ctrl-C that surfaces as another exception."""

from __future__ import annotations

from pathlib import Path

from tribodem.cli import _interrupt_in_chain
from tribodem.io import runs
from tribodem.io.results import atomic_write, remove_temporaries


def test_resume_removes_only_the_temporaries(tmp_path: Path) -> None:
    """A kill -9 between write and rename leaves ``.NAME.XXXXXXXX.tmp.suffix``; a resume's
    folder check deletes it and nothing else."""
    out = tmp_path / "run"
    (out / "vtk").mkdir(parents=True)
    stray = out / "vtk" / ".chains_000001000.vtu.rn8jm3o6.tmp.vtu"
    stray.write_text("half")
    keep = [out / "vtk" / "chains_000000000.vtu", out / ".hidden", out / "notes.tmp.txt",
            out / ".a.b.tmp"]
    for k in keep:
        k.write_text("x")
    (out / "checkpoint.npz").write_text("x")

    def interrupted(p: Path) -> None:
        p.write_text("partial")
        raise KeyboardInterrupt

    try:
        atomic_write(out / "x.csv", interrupted)
    except KeyboardInterrupt:
        pass
    assert not list(out.glob(".x.csv.*"))  # the writer's own cleanup
    runs.check_out_dir(out, "--out", resume=True, need=("checkpoint.npz",))
    assert not stray.exists() and all(k.exists() for k in keep)
    assert remove_temporaries(out) == []


def test_interrupt_found_in_the_exception_chain() -> None:
    """numba's dispatcher turns a Ctrl-C during kernel loading into a SystemError whose
    context is the KeyboardInterrupt (seen in CI): that is still a Ctrl-C."""
    try:
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt:
            raise SystemError("returned a result with an exception set")  # noqa: B904
    except SystemError as err:
        assert _interrupt_in_chain(err)
    assert not _interrupt_in_chain(ValueError("plain"))


def test_interrupted_message_says_where_the_outputs_are(tmp_path: Path) -> None:
    """The Ctrl-C message is ``runs``' (the entry only looks it up once loaded)."""
    import tribodem._entry as entry

    out = tmp_path / "run"
    out.mkdir()
    (out / "checkpoint.npz").write_text("x")
    runs.announce(out, out / "checkpoint.npz", resume_hint="add --resume")
    try:
        text = runs.interrupted_message()
        assert text.startswith("\ninterrupted (Ctrl-C): ") and str(out) in text
        assert "checkpoint" in text and "--resume" in text
        assert entry.interrupted_message() == text
    finally:
        runs._current.out = None  # nothing announced, as at the start
