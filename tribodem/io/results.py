"""Atomic result files: write to a temporary sibling, then rename over the target.

Every result and checkpoint goes through these helpers, so a crash never leaves a
half-written file: a reader sees the previous complete version or the new one.
"""

from __future__ import annotations

import csv
import io
import json
import os
import re
import signal
import tempfile
import threading
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path
from typing import Any

import numpy as np


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


_MODE = 0o666 & ~_umask()  # what open() would give a new file


def atomic_write(path: str | Path, writer: Callable[[Path], None]) -> Path:
    """Call ``writer(tmp_path)`` then rename ``tmp_path`` to ``path`` (same directory).

    The file gets the mode a plainly created file would (0666 less the umask), not the
    owner-only mode of the temporary file.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    # Ctrl-C held off from the temporary's creation until the cleanup below is armed
    # (a Python signal handler only runs between bytecodes; the pending signal fires after
    # the unblock, inside the try)
    held = _block_sigint()
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp" + path.suffix,
                                   dir=path.parent)
        tmp_path = Path(tmp)
    finally:
        _unblock_sigint(held)
    try:
        os.close(fd)
        writer(tmp_path)
        os.chmod(tmp_path, _MODE)
        os.replace(tmp_path, path)
    finally:
        if tmp_path.exists():
            tmp_path.unlink()
    return path


def _block_sigint() -> bool:
    if threading.current_thread() is not threading.main_thread():
        return False
    signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    return True


def _unblock_sigint(held: bool) -> None:
    if held:
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})


#: the temporaries of :func:`atomic_write`: ``.NAME.XXXXXXXX.tmp[.suffix]``
_TEMPORARY = re.compile(r"^\..+\.[A-Za-z0-9_]{8}\.tmp(\.[^/]*)?$")


def remove_temporaries(folder: str | Path) -> list[Path]:
    """Delete the temporaries an interrupted :func:`atomic_write` left below ``folder``
    (a kill -9 between the write and the rename); returns them. Called before a resume."""
    gone = []
    root = Path(folder)
    if root.is_dir():
        for p in root.rglob(".*.tmp*"):
            if p.is_file() and _TEMPORARY.match(p.name):
                p.unlink()
                gone.append(p)
    return gone


def write_text(path: str | Path, text: str) -> Path:
    """Atomically write a text file."""
    return atomic_write(path, lambda p: p.write_text(text))


def _default(o: Any) -> Any:
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, Path):
        return str(o)
    raise TypeError(f"cannot serialise {type(o).__name__}")


def write_json(path: str | Path, data: Any) -> Path:
    """Atomically write JSON (numpy scalars/arrays converted)."""
    return write_text(path, json.dumps(data, indent=2, default=_default) + "\n")


def write_csv(path: str | Path, header: Sequence[str], rows: Iterable[Sequence[Any]]) -> Path:
    """Atomically write a CSV with a header row."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(header)
    for r in rows:
        w.writerow([repr(float(x)) if isinstance(x, (float, np.floating)) else x for x in r])
    return write_text(path, buf.getvalue())


def write_npz(path: str | Path, **arrays: Any) -> Path:
    """Atomically write a compressed-free ``.npz`` (exact float bits are kept)."""
    def w(p: Path) -> None:
        with p.open("wb") as fh:
            np.savez(fh, **arrays)
    return atomic_write(path, w)


def write_figure(path: str | Path, fig: Any, dpi: int = 120) -> Path:
    """Atomically save a matplotlib figure as PNG, then close it."""
    import matplotlib.pyplot as plt

    try:
        return atomic_write(path, lambda p: fig.savefig(p, format="png", dpi=dpi))
    finally:
        plt.close(fig)
