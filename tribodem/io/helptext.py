"""The help texts of the commands as typer shows them.

typer's help keeps every single line break of a command's docstring after its first
paragraph, and then wraps each line to the terminal: a docstring wrapped at 90 columns
shows, on an 80-column terminal, as "... task with its" / "own" / "folder and ...".
:func:`reflowed` joins the lines of each paragraph, so the terminal's width alone wraps
them. Lines that start a list item (``- ``) keep their break.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from typing import TypeVar

F = TypeVar("F", bound=Callable[..., object])


def reflow(text: str) -> str:
    """``text`` (a docstring) with the lines of each paragraph joined by spaces; paragraphs
    stay apart (a blank line), a line starting with ``- `` starts a new line, and a
    paragraph starting with ``\\b`` (click's "do not rewrap") is kept as it is."""
    out = []
    for para in inspect.cleandoc(text).split("\n\n"):
        if para.startswith("\b"):
            out.append(para)
            continue
        lines: list[str] = []
        for ln in para.splitlines():
            s = ln.strip()
            if lines and not s.startswith("- "):
                lines[-1] += " " + s
            else:
                lines.append(s)
        out.append("\n".join(lines))
    return "\n\n".join(out)


def reflowed(fn: F) -> F:
    """Decorator (under typer's ``@app.command``): ``fn``'s docstring :func:`reflow`-ed, as
    the command's help."""
    if fn.__doc__:
        fn.__doc__ = reflow(fn.__doc__)
    return fn
