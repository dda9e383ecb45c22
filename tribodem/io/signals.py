"""Which signal interrupted the command: Ctrl-C (SIGINT) or a scheduler's SIGTERM.

Only the standard library is imported here: the entry point sets :data:`received` before
anything heavy is loaded, and the command layer reads it to word its message and to pick
the exit code (128 + the signal's number: 130 for SIGINT, 143 for SIGTERM).
"""

from __future__ import annotations

import signal

#: the signal that interrupted the command (``signal.SIGINT`` or ``signal.SIGTERM``), None
#: while none did
received: int | None = None

_WORDS = {signal.SIGINT: "interrupted (Ctrl-C)", signal.SIGTERM: "terminated (SIGTERM)"}


def words() -> str:
    """How the interruption is named in messages ("interrupted (Ctrl-C)" by default)."""
    return _WORDS.get(received or signal.SIGINT, "interrupted (Ctrl-C)")


def exit_code() -> int:
    """The exit code of an interrupted command: 128 + the signal's number."""
    return 128 + int(received or signal.SIGINT)
