"""Atomic result files: write to a temporary sibling, then rename over the target.

Every result and checkpoint goes through these helpers, so a crash never leaves a
half-written file: a reader sees the previous complete version or the new one.
"""

from __future__ import annotations

import csv
import io
import json
import os
import tempfile
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
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp" + path.suffix,
                               dir=path.parent)
    os.close(fd)
    tmp_path = Path(tmp)
    try:
        writer(tmp_path)
        os.chmod(tmp_path, _MODE)
        os.replace(tmp_path, path)
    finally:
        if tmp_path.exists():
            tmp_path.unlink()
    return path


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
