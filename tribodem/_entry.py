"""The ``tribodem`` command: Ctrl-C gives exit 130 (SIGTERM 143) and a message from start to
exit.

Python's own Ctrl-C handling leaves two windows in which the command dies of SIGINT (exit
-2, no message, sometimes a traceback): between the end of the work and the interpreter's
exit (Python puts the default action back, then tears down every module: 0.3 s with numba
loaded), and in the few instructions of the error handling itself. Here one handler is
installed before anything heavy is imported; it raises ``KeyboardInterrupt`` once, while
the command works (``tribodem.cli.main`` turns that into the message and exit 130), and
any later Ctrl-C prints the same message and ends the process with 130 at once. SIGTERM
(what ``timeout`` and batch schedulers send before a kill) is handled the same way, with
exit 143. After the
work the other threads are waited for and the exit handlers run as in Python's own
shutdown, the streams are flushed, and the process ends without the module teardown.
Only the standard library (and tribodem's own stdlib-only ``io.signals`` and
``io.environment``) is imported here; the environment variables the engines read are
checked first (exit 2 naming the variable).
"""

from __future__ import annotations

import atexit
import os
import signal
import sys
import threading

from tribodem.io import environment, signals

_working = True


def interrupted_message() -> str:
    """The Ctrl-C / SIGTERM message, :func:`tribodem.io.runs.interrupted_message` once the
    command has loaded that module (looked up, not imported: nothing heavy is imported here,
    and the command layer imports the rest, never the reverse); before, the bare words."""
    runs = sys.modules.get("tribodem.io.runs")
    if runs is not None:
        return str(runs.interrupted_message())
    return "\n" + signals.words()


def _on_signal(signum: int, frame: object) -> None:
    """SIGINT (Ctrl-C) and SIGTERM (``timeout``, batch schedulers): the first one while the
    command works raises ``KeyboardInterrupt`` (outputs and checkpoint kept, the message
    says where); a later one, or one after the work, reports and leaves at once."""
    global _working
    if signals.received is None:
        signals.received = signum
    if _working:  # the first one, while the command works: the normal path
        _working = False
        raise KeyboardInterrupt
    try:  # after it, or after the work: report and leave at once
        sys.stdout.flush()
        sys.stderr.write(interrupted_message() + "\n")
        sys.stderr.flush()
    finally:
        os._exit(signals.exit_code())


def entry() -> None:
    """Run :func:`tribodem.cli.main` under the handler, then end the process with its code.

    A Ctrl-C inherited as ignored (a background job of a shell without job control) stays
    ignored. An unexpected exception still prints Python's traceback and exits 1.
    """
    global _working
    for sig in (signal.SIGINT, signal.SIGTERM):
        if signal.getsignal(sig) is not signal.SIG_IGN:
            signal.signal(sig, _on_signal)
    code: int | str | None = 0
    bad = environment.problems()
    if bad:  # before numba is imported: it would fail with a traceback or warn and ignore
        sys.stderr.write("".join(f"error: {m}\n" for m in bad))
        sys.stderr.flush()
        os._exit(2)
    try:
        from tribodem.cli import main

        main()
    except SystemExit as e:
        code = e.code
    except KeyboardInterrupt:  # raised outside main's own handling (import, error paths)
        _working = False
        sys.stderr.write(interrupted_message() + "\n")
        code = signals.exit_code()
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
