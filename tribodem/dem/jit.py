"""Kernels compiled twice: serial for small systems, threaded (``prange``) for large ones.

A threaded region costs tens of microseconds to launch, more than the whole work of a
few hundred particles, so the engine picks the serial build below ``PARALLEL_MIN``
items. Both builds come from the same plain function and are cached on disk.

Threading layer: OpenMP first (``THREADING_LAYER_PRIORITY``), unless the user names one
with ``NUMBA_THREADING_LAYER``. numba's own order puts TBB first, and with the TBB that
Debian installs beside Yade a threaded region took ~100 us to launch against ~2 us for
OpenMP (measured here, idle, 2 cores), which cost a 2-thread step of 20,000 spheres
about 15 % (BENCHMARKS.md, the threading-layer measurements).
"""

from __future__ import annotations

import os
import types
from collections.abc import Callable
from typing import Any

import numba
from numba import njit

PARALLEL_MIN = 4000

if os.environ.get("NUMBA_THREADING_LAYER", "default") == "default":
    numba.config.THREADING_LAYER_PRIORITY = ["omp", "tbb", "workqueue"]


class Kernel:
    """A plain function with a serial and a threaded compiled build (compiled lazily).

    ``chunk`` is the number of loop iterations a thread takes at a time (0 = equal static
    shares); small chunks balance loops whose work is uneven, like contacts that crowd
    at the bottom of a settling bed.
    """

    def __init__(self, fn: Callable[..., Any], chunk: int = 0, cache: bool = True) -> None:
        self.py_func = fn
        self.chunk = int(chunk)
        self.__doc__ = fn.__doc__
        self.__name__ = fn.__name__
        serial_fn = types.FunctionType(fn.__code__, fn.__globals__, fn.__name__ + "_serial",
                                       fn.__defaults__, fn.__closure__)
        serial_fn.__qualname__ = fn.__qualname__ + "_serial"
        self.serial = njit(cache=cache)(serial_fn)
        self.parallel = njit(cache=cache, parallel=True)(fn)

    def pick(self, size: int, threads: int | None = None) -> Callable[..., Any]:
        """The build to use for ``size`` items (particles or pairs): the serial one below
        ``PARALLEL_MIN`` items or on one thread (a threaded region with one thread only
        adds its launch cost). ``threads``: ``numba.get_num_threads()`` if known (it
        costs about 2 us a call)."""
        if serial_run(size, threads):
            return self.serial
        return self._chunked if self.chunk else self.parallel

    def _chunked(self, *args: Any) -> Any:
        with numba.parallel_chunksize(self.chunk):
            return self.parallel(*args)

    def __call__(self, *args: Any) -> Any:
        return self.parallel(*args)


def kernel(fn: Callable[..., Any] | None = None, *, chunk: int = 0) -> Any:
    """Decorator: make ``fn`` a ``Kernel`` (serial + threaded builds); ``@kernel(chunk=k)``."""
    if fn is None:
        return lambda f: Kernel(f, chunk)
    return Kernel(fn, chunk)


def serial_run(size: int, threads: int | None = None) -> bool:
    """True when a kernel over ``size`` items runs its serial build (see ``Kernel.pick``)."""
    if size < PARALLEL_MIN:
        return True
    return (numba.get_num_threads() if threads is None else threads) == 1
