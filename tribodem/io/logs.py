"""What the commands say while they work: the standard :mod:`logging` module, on stderr.

Every module that has something to say while a command is silent for long takes its own
logger, ``logging.getLogger(__name__)`` (all under ``"tribodem"``). The command's root
options ``-v`` / ``-q`` set how much of it is shown, through :func:`configure`:

- ``-q`` (verbosity -1): warnings and errors only;
- default (0): also the notes of a command that works silently for more than a few
  seconds (the first numba compile of a process with a cold cache, ``validate``'s ccx
  checks, a long DE phase), one line each, as bare text;
- ``-v`` (1): tribodem's debug messages too, with the time, the level and the logger;
- ``-vv`` (2): every library's (numba, distributed, matplotlib, ...) as well.

Messages go to stderr (a progress bar there is redrawn below them); the results a command
prints on stdout are untouched. Without :func:`configure` (tribodem used as a library)
nothing is set up here: the caller's logging configuration decides, as for any library.
"""

from __future__ import annotations

import logging
import sys
from typing import Any

#: the logger above every module's
ROOT = "tribodem"
#: the note before the first kernel compile of a process (:func:`watch_numba_compiles`)
COMPILE_NOTE = ("compiling the numba kernels (first run only: they are cached on disk for the "
                "next runs, ~1 min)...")

log = logging.getLogger(__name__)

_handler: logging.Handler | None = None
_watching = False


class _Stderr(logging.Handler):
    """Writes each record on the current ``sys.stderr`` (looked up at each record, so a
    redirected stream is honoured) through ``tqdm.write``: a progress bar on stderr is
    cleared, the line written, the bar redrawn."""

    def emit(self, record: logging.LogRecord) -> None:
        try:
            msg = self.format(record)
            try:
                from tqdm import tqdm

                tqdm.write(msg, file=sys.stderr)
            except ImportError:  # pragma: no cover - tqdm is a dependency
                sys.stderr.write(msg + "\n")
            sys.stderr.flush()
        except Exception:  # noqa: BLE001 - logging must never end the command
            self.handleError(record)


def level_of(verbosity: int) -> int:
    """The level of tribodem's loggers at ``verbosity`` (-1 quiet, 0 default, >= 1 verbose)."""
    if verbosity < 0:
        return logging.WARNING
    return logging.INFO if verbosity == 0 else logging.DEBUG


def configure(verbosity: int = 0) -> None:
    """Show tribodem's messages on stderr at ``verbosity`` (see the module's docstring:
    -1 ``-q``, 0 default, 1 ``-v``, 2 ``-vv``); a second call replaces the first one's
    handler. Also :func:`watch_numba_compiles` when numba is loaded."""
    global _handler
    verbosity = int(verbosity)
    handler = _Stderr()
    handler.setFormatter(logging.Formatter(
        "%(message)s" if verbosity <= 0 else
        "%(asctime)s %(levelname)s %(name)s: %(message)s", "%H:%M:%S"))
    top = logging.getLogger(ROOT)
    root = logging.getLogger()
    if _handler is not None:
        top.removeHandler(_handler)
        root.removeHandler(_handler)
    _handler = handler
    top.addHandler(handler)
    top.setLevel(level_of(verbosity))
    top.propagate = False  # shown once, by this handler
    if verbosity >= 2:  # the libraries' messages too
        root.addHandler(handler)
        root.setLevel(logging.DEBUG)
    watch_numba_compiles()


def watch_numba_compiles() -> bool:
    """Once per process, when numba is loaded: log :data:`COMPILE_NOTE` (INFO) before the
    first function numba compiles (not before one it loads from its disk cache: a warm
    cache says nothing). Returns whether the watch is on. Numba's ``numba:compile`` event
    fires only on a cache miss, so the check costs nothing; when numba is not loaded yet
    (a command without kernels) nothing is imported."""
    global _watching
    if _watching:
        return True
    if "numba" not in sys.modules:
        return False
    from numba.core import event

    class FirstCompile(event.Listener):
        """Says :data:`COMPILE_NOTE` at the start of the first compile, then nothing."""

        said = False

        def on_start(self, ev: Any) -> None:
            if not self.said:
                self.said = True
                log.info(COMPILE_NOTE)

        def on_end(self, ev: Any) -> None:
            pass

    event.register("numba:compile", FirstCompile())
    _watching = True
    return True
