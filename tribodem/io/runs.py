"""The life of a long run on the command line: output folder, stops, Ctrl-C, progress.

One vocabulary for every command (``tribodem.cli.main`` maps it to exit codes):

- :class:`~tribodem.io.config.ConfigError` -> exit 2 (bad input, refused before any work);
- :class:`RunStopped` -> exit 3 (an early stop or a numerical instability; outputs kept);
- ``KeyboardInterrupt`` (Ctrl-C, SIGINT) -> exit 130, after saying where the outputs and the
  last checkpoint are (:func:`interrupted_message`). A command announces its outputs with
  :func:`announce` as soon as it has checked them, and its checkpoint with
  :func:`checkpoint_written`.

:func:`check_out_dir` checks an output location before any work; :func:`progress` is the one
progress bar (tqdm on stderr, with an ETA; off when ``enabled`` is false).
"""

from __future__ import annotations

import functools
import math
import os
import tempfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypeVar

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


#: the lock file in a run folder while a run writes there
LOCK_NAME = ".tribodem.lock"
#: run folders this process holds locked: resolved path -> open lock file descriptor
_locks: dict[Path, int] = {}


def announce(out: str | Path, checkpoint: str | Path | None = None,
             resume_hint: str | None = None, lock: bool = True) -> None:
    """Say which folder this command writes (and where its checkpoint will be), once every
    input has been checked, and take the folder's lock (:func:`lock_folder`: ``ConfigError``
    naming the process that holds it).

    ``resume_hint``: how to continue (e.g. "add --resume to the same command").
    """
    if lock:
        lock_folder(out)
    _current.out = Path(out)
    _current.checkpoint = Path(checkpoint) if checkpoint is not None else None
    _current.resume_hint = resume_hint


def started() -> bool:
    """Whether this command has announced its outputs (its checks passed, its work began)."""
    return _current.out is not None


def lock_folder(out: str | Path, field: str = "--out") -> None:
    """Hold ``out`` (made if missing) for this process: an exclusive ``flock`` on
    ``out/.tribodem.lock``, which holds the holder's pid. A second run or resume on the
    folder, from another process, is refused (``ConfigError`` naming the pid); the kernel
    drops the lock when its process ends, so a lock left by a killed run is free again.
    Taking a folder this process holds already does nothing."""
    import fcntl

    p = Path(out)
    key = p.resolve()
    if key in _locks:
        return
    p.mkdir(parents=True, exist_ok=True)
    fd = os.open(p / LOCK_NAME, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        holder = os.read(fd, 64).decode(errors="replace").strip() or "unknown"
        os.close(fd)
        raise ConfigError(f"{field} = '{p}': the folder is in use by another tribodem run "
                          f"(pid {holder}); allowed: another folder, or the same one once "
                          "that run has ended") from None
    os.ftruncate(fd, 0)
    os.write(fd, f"{os.getpid()}\n".encode())
    _locks[key] = fd


def release_folders(keep: frozenset[Path] = frozenset()) -> None:
    """Give up the run folders this process holds, but those in ``keep`` (the end of a run
    called from Python, or of a sweep member's task on a worker that lives on)."""
    for key, fd in list(_locks.items()):
        if key in keep:
            continue
        try:
            os.close(fd)
        finally:
            del _locks[key]


F = TypeVar("F", bound=Callable[..., Any])


def releases_folders(fn: F) -> F:
    """Decorate a public run function: the folders it locked (:func:`announce`) are given
    up when it returns or raises, so a notebook can run in a folder again, or another
    process resume there; folders locked before the call stay locked."""

    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        before = frozenset(_locks)
        try:
            return fn(*args, **kwargs)
        finally:
            release_folders(keep=before)

    return wrapper  # type: ignore[return-value]


def checkpoint_written(path: str | Path) -> None:
    """Record the latest complete checkpoint (reported on Ctrl-C or a stop)."""
    _current.checkpoint = Path(path)


def where() -> str:
    """One line: where the outputs and the last checkpoint are (empty if nothing announced)."""
    c = _current
    if c.out is None:
        return ""
    if not c.out.exists() or not any(  # stopped before its first file (calibrate writes at
            f.name != LOCK_NAME for f in c.out.iterdir()):  # the end)
        return f"no outputs were written yet (they go to '{c.out}')"
    text = f"outputs so far are in '{c.out}'"
    if c.checkpoint is not None and c.checkpoint.exists():
        text += f"; last checkpoint '{c.checkpoint}'"
        if c.resume_hint:
            text += f" ({c.resume_hint})"
    elif c.checkpoint is not None:
        text += "; no checkpoint was written yet"
    return text


def interrupted_message() -> str:
    """The Ctrl-C (or SIGTERM) message: where the outputs and the last checkpoint are
    (:func:`where`)."""
    from tribodem.io import signals

    text = where()
    return "\n" + signals.words() + (f": {text}" if text else "")


def check_out_dir(out: str | Path, field: str = "--out", resume: bool = False,
                  need: tuple[str, ...] = ()) -> Path:
    """Check an output folder before any work; ``ConfigError`` names ``field`` and the value.

    It must be a folder (or not exist yet) in a writable place; nothing is created here.
    With ``resume``, it must exist and hold the files named in ``need``; the temporaries an
    interrupted atomic write left there (``.NAME.XXXXXXXX.tmp*``, never results) are
    removed.
    """
    p = Path(out)
    if not str(out).strip():
        raise ConfigError(f"{field} = {str(out)!r}: allowed: a folder path (not empty)")
    check_path_length(p, field)
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


def check_path_length(p: Path, field: str) -> None:
    """Refuse (``ConfigError``) a path the file system cannot hold: a name over its
    ``NAME_MAX`` bytes or a whole path over ``PATH_MAX`` (255 and 4,096 on Linux)."""
    absolute = os.path.abspath(p)
    name_max, path_max = 255, 4096
    try:
        probe = next(q for q in (p, *p.parents) if q.exists())
        name_max = os.pathconf(probe, "PC_NAME_MAX")
        path_max = os.pathconf(probe, "PC_PATH_MAX")
    except (StopIteration, OSError, ValueError):
        pass
    long = next((part for part in p.parts if len(os.fsencode(part)) > name_max), None)
    if long is not None:
        raise ConfigError(f"{field} = '{p}': the name '{long[:40]}...' has "
                          f"{len(os.fsencode(long))} bytes; allowed: names of at most "
                          f"{name_max} bytes")
    if len(os.fsencode(absolute)) >= path_max:
        raise ConfigError(f"{field} = '{str(p)[:60]}...': the path has "
                          f"{len(os.fsencode(absolute))} bytes; allowed: less than {path_max}")


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


def check_memory(count: float, bytes_each: float, field: str, fraction: float = 0.8, *,
                 given: str | None = None, what: str = "", allowed: str | None = None
                 ) -> None:
    """Refuse (``ConfigError``) ``count`` items of ``bytes_each`` when that is above
    ``fraction`` of the memory available, naming the field, the value and the largest count
    that fits.

    ``count`` may be a float (an estimate; infinite: more than any machine has). When the
    count is not the field's value but follows from it (the cells of a grid, the particles
    of a cell), ``given`` is the field's value as the message writes it, ``what`` names the
    items ("the track grid's cells") and ``allowed`` says what would do."""
    have = available_memory()
    try:
        need = float(count) * bytes_each
    except OverflowError:  # an integer beyond any float
        need = math.inf
    if need <= fraction * have:
        return
    fits = int(fraction * have / bytes_each)
    size = (f"about {need / 2**30:.3g} GiB" if math.isfinite(need) else
            "more memory than any machine has")
    machine = (f"(~{bytes_each:.0f} B each), but this machine has {have / 2**30:.1f} GiB "
               "available")
    if given is None:
        raise ConfigError(f"{field} = {count!r}: needs {size} {machine}; allowed: at most "
                          f"about {fits:,}")
    shown = f"{count:.3g}" if isinstance(count, float) else f"{count:,}"
    raise ConfigError(f"{field} = {given}: {what or 'the items'} ({shown}) need {size} "
                      f"{machine}; allowed: {allowed or f'at most about {fits:,} of them'}")


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
