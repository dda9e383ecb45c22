"""The ``tribodem`` command: Ctrl-C gives exit 130 and a message from start to exit.

Python's own Ctrl-C handling leaves two windows in which the command dies of SIGINT (exit
-2, no message, sometimes a traceback): between the end of the work and the interpreter's
exit (Python puts the default action back, then tears down every module: 0.3 s with numba
loaded), and in the few instructions of the error handling itself. Here one handler is
installed before anything heavy is imported; it raises ``KeyboardInterrupt`` once, while
the command works (``tribodem.cli.main`` turns that into the message and exit 130), and
any later Ctrl-C prints the same message and ends the process with 130 at once. After the
work the other threads are waited for and the exit handlers run as in Python's own
shutdown, the streams are flushed, and the process ends without the module teardown.
Only the standard library is imported here.
"""

from __future__ import annotations

import atexit
import os
import signal
import sys
import threading

_working = True


def interrupted_message() -> str:
    """The Ctrl-C message: where the outputs and the last checkpoint are (``runs.where``)."""
    runs = sys.modules.get("tribodem.io.runs")
    where = runs.where() if runs is not None else ""
    return "\ninterrupted (Ctrl-C)" + (f": {where}" if where else "")


def _on_sigint(signum: int, frame: object) -> None:
    global _working
    if _working:  # the first one, while the command works: the normal path
        _working = False
        raise KeyboardInterrupt
    try:  # after it, or after the work: report and leave at once
        sys.stdout.flush()
        sys.stderr.write(interrupted_message() + "\n")
        sys.stderr.flush()
    finally:
        os._exit(130)


def entry() -> None:
    """Run :func:`tribodem.cli.main` under the handler, then end the process with its code.

    A Ctrl-C inherited as ignored (a background job of a shell without job control) stays
    ignored. An unexpected exception still prints Python's traceback and exits 1.
    """
    global _working
    if signal.getsignal(signal.SIGINT) is not signal.SIG_IGN:
        signal.signal(signal.SIGINT, _on_sigint)
    code: int | str | None = 0
    try:
        from tribodem.cli import main

        main()
    except SystemExit as e:
        code = e.code
    except KeyboardInterrupt:  # raised outside main's own handling (import, error paths)
        _working = False
        sys.stderr.write(interrupted_message() + "\n")
        code = 130
    finally:
        _working = False
    if isinstance(code, str):
        sys.stderr.write(code + "\n")
        code = 1
    # what Python's shutdown does first: wait for the threads that are not daemons
    for t in threading.enumerate():
        if t is not threading.main_thread() and not t.daemon:
            t.join()
    atexit._run_exitfuncs()
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code or 0)
