"""The environment variables tribodem and the engines it loads read, checked at start.

Only the standard library is imported here (it runs before numba is loaded: numba reads
``NUMBA_NUM_THREADS`` and ``NUMBA_THREADING_LAYER`` when it is imported and fails with a
traceback on a value it cannot use, or prints a warning and ignores it).
"""

from __future__ import annotations

import importlib.util
import os

#: numba's threading layers (``tbb`` only where the tbb package is installed)
THREADING_LAYERS = ("default", "safe", "forksafe", "threadsafe", "omp", "workqueue", "tbb")


def _whole(name: str, what: str) -> str | None:
    v = os.environ.get(name)
    if v is None:
        return None
    try:
        ok = int(v.strip()) >= 1
    except ValueError:
        ok = False
    if ok:
        return None
    return f"environment variable {name} = {v!r}: allowed: a whole number >= 1 ({what}), or " \
           f"leave it unset"


def problems() -> list[str]:
    """One message per variable whose value cannot be used (empty when all are usable)."""
    out = [m for m in (
        _whole("NUMBA_NUM_THREADS", "the threads numba may use; unset: all cores"),
        _whole("OMP_NUM_THREADS", "the threads of OpenMP and BLAS"),
    ) if m is not None]
    layer = os.environ.get("NUMBA_THREADING_LAYER")
    if layer is not None:
        allowed = [x for x in THREADING_LAYERS
                   if x != "tbb" or importlib.util.find_spec("tbb") is not None]
        if layer not in allowed:
            out.append(f"environment variable NUMBA_THREADING_LAYER = {layer!r}: allowed: "
                       f"{', '.join(allowed)}, or leave it unset")
    return out
