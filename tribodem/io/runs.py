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
    if not c.out.exists():  # stopped before its first file (e.g. calibrate writes at the end)
        return f"no outputs were written yet (they go to '{c.out}')"
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

    It must be a folder (or not exist yet) in a writable place; nothing is created here.
    With ``resume``, it must exist and hold the files named in ``need``; the temporaries an
    interrupted atomic write left there (``.NAME.XXXXXXXX.tmp*``, never results) are
    removed.
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
        from tribodem.io.results import remove_temporaries

        remove_temporaries(p)
    parent = p
    while not parent.exists():
        parent = parent.parent
    if not parent.is_dir():
        raise ConfigError(f"{field} = '{p}': '{parent}' is a file, so the folder cannot be "
                          "made; allowed: a folder path")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise ConfigError(f"{field} = '{p}': '{parent}' is not writable; allowed: a folder "
                          "in a writable place")
    if p.is_dir():  # an existing folder: try a write (permissions, read-only mounts)
        try:
            fd, probe = tempfile.mkstemp(dir=p, prefix=".tribodem-write-test-")
            os.close(fd)
            os.unlink(probe)
        except OSError as err:
            raise ConfigError(f"{field} = '{p}': cannot write there ({err.strerror})"
                              ) from None
    return p


def check_out_file(path: str | Path, field: str) -> Path:
    """Check a file to be written (e.g. ``--plot``) before any work: not a folder, and its
    folder exists or can be made in a writable place (``ConfigError`` otherwise)."""
    p = Path(path)
    if p.is_dir():
        raise ConfigError(f"{field} = '{p}': is a folder; allowed: a file path")
    check_out_dir(p.parent if str(p.parent) else Path("."), field)
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


def available_memory() -> int:
    """Memory this machine can give a new run, bytes (MemAvailable; total RAM as fallback)."""
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return int(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))


def check_memory(count: int, bytes_each: float, field: str, fraction: float = 0.8) -> None:
    """Refuse (``ConfigError``) ``count`` items of ``bytes_each`` when that is above
    ``fraction`` of the memory available, naming the field, the value and the largest count
    that fits."""
    have = available_memory()
    need = count * bytes_each
    if need > fraction * have:
        fits = int(fraction * have / bytes_each)
        raise ConfigError(
            f"{field} = {count!r}: needs about {need / 2**30:.3g} GiB (~{bytes_each:.0f} B "
            f"each), but this machine has {have / 2**30:.1f} GiB available; allowed: at most "
            f"about {fits:,}")


def check_threads(threads: int, field: str, zero_means_all: bool = True) -> int:
    """Check a thread count against the cores numba may use; returns the count to set
    (0 -> all when ``zero_means_all``). ``ConfigError`` names the field and the range."""
    import numba

    most = int(numba.config.NUMBA_NUM_THREADS)
    low = 0 if zero_means_all else 1
    if not low <= threads <= most:
        extra = " (0 = all)" if zero_means_all else ""
        raise ConfigError(f"{field} = {threads!r}: allowed: {low}..{most}{extra} "
                          f"(this machine has {most} core(s) for numba)")
    return threads or most
