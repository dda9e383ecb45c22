"""The life of a long run on the command line: output folder, stops, Ctrl-C, progress.

One vocabulary for every command (``tribodem.cli.main`` maps it to exit codes):

- :class:`~tribodem.io.config.ConfigError` -> exit 2 (bad input, refused before any work);
- :class:`RunStopped` -> exit 3 (an early stop or a numerical instability; outputs kept);
- ``KeyboardInterrupt`` (Ctrl-C, SIGINT) -> exit 130, after saying where the outputs and the
  last checkpoint are. A command announces its outputs with :func:`announce` as soon as it
  has checked them, and its checkpoint with :func:`checkpoint_written`.

:func:`check_out_dir` checks an output location before any work; :func:`progress` is the one
progress bar (tqdm on stderr, with an ETA; off when ``enabled`` is false).
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tribodem.io.config import ConfigError


class RunStopped(RuntimeError):
    """A run that stopped before its end (instability, contact outgrew the window, ...).

    The message says why; every output written so far is kept (exit code 3).
    """


@dataclass
class _Current:
    out: Path | None = None
    checkpoint: Path | None = None
    resume_hint: str | None = None


_current = _Current()


def announce(out: str | Path, checkpoint: str | Path | None = None,
             resume_hint: str | None = None) -> None:
    """Say which folder this command writes (and where its checkpoint will be).

    ``resume_hint``: how to continue (e.g. "add --resume to the same command").
    """
    _current.out = Path(out)
    _current.checkpoint = Path(checkpoint) if checkpoint is not None else None
    _current.resume_hint = resume_hint


def checkpoint_written(path: str | Path) -> None:
    """Record the latest complete checkpoint (reported on Ctrl-C or a stop)."""
    _current.checkpoint = Path(path)


def where() -> str:
    """One line: where the outputs and the last checkpoint are (empty if nothing announced)."""
    c = _current
    if c.out is None:
        return ""
    text = f"outputs so far are in '{c.out}'"
    if c.checkpoint is not None and c.checkpoint.exists():
        text += f"; last checkpoint '{c.checkpoint}'"
        if c.resume_hint:
            text += f" ({c.resume_hint})"
    elif c.checkpoint is not None:
        text += "; no checkpoint was written yet"
    return text


def check_out_dir(out: str | Path, field: str = "--out", resume: bool = False,
                  need: tuple[str, ...] = ()) -> Path:
    """Check an output folder before any work; ``ConfigError`` names ``field`` and the value.

    It must be a folder (or not exist yet) in a writable place. With ``resume``, it must
    exist and hold the files named in ``need``.
    """
    p = Path(out)
    if p.exists() and not p.is_dir():
        raise ConfigError(f"{field} = '{p}': is a file, not a folder; allowed: a folder "
                          "(existing or new)")
    if resume:
        if not p.is_dir():
            raise ConfigError(f"{field} = '{p}': --resume needs the folder of an earlier "
                              "run, and it does not exist")
        for name in need:
            if not (p / name).is_file():
                raise ConfigError(f"{field} = '{p}': --resume needs '{name}' there, and it "
                                  "is missing (was the run started with checkpoints?)")
    parent = p
    while not parent.exists():
        parent = parent.parent
    if not parent.is_dir():
        raise ConfigError(f"{field} = '{p}': '{parent}' is a file, so the folder cannot be "
                          "made; allowed: a folder path")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise ConfigError(f"{field} = '{p}': '{parent}' is not writable; allowed: a folder "
                          "in a writable place")
    try:
        p.mkdir(parents=True, exist_ok=True)
        fd, probe = tempfile.mkstemp(dir=p, prefix=".tribodem-write-test-")
        os.close(fd)
        os.unlink(probe)
    except OSError as err:
        raise ConfigError(f"{field} = '{p}': cannot write there ({err.strerror})") from None
    return p


def check_out_file(path: str | Path, field: str) -> Path:
    """Check a file to be written (e.g. ``--plot``): its folder exists and is writable."""
    p = Path(path)
    if p.is_dir():
        raise ConfigError(f"{field} = '{p}': is a folder; allowed: a file path")
    parent = p.parent if str(p.parent) else Path(".")
    if not parent.is_dir():
        raise ConfigError(f"{field} = '{p}': folder '{parent}' does not exist; allowed: a "
                          "file in an existing folder")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise ConfigError(f"{field} = '{p}': folder '{parent}' is not writable")
    return p


@contextmanager
def progress(total: float, unit: str, desc: str = "", enabled: bool = True,
             initial: float = 0) -> Iterator[Any]:
    """A progress bar with rate and ETA on stderr (tqdm); a no-op object when disabled.

    ``initial``: work already done (a resumed run), so the ETA counts only what is left.
    """
    if not enabled:
        yield _NoBar()
        return
    from tqdm import tqdm

    with tqdm(total=total, initial=initial, unit=unit, desc=desc, leave=True,
              dynamic_ncols=True, mininterval=0.5) as bar:
        yield bar


class _NoBar:
    def update(self, n: float = 1) -> None:
        """Nothing to show."""

    def set_postfix_str(self, s: str) -> None:
        """Nothing to show."""
