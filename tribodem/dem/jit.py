"""Kernels compiled twice: serial for small systems, threaded (``prange``) for large ones.

A threaded region costs tens of microseconds to launch, more than the whole work of a
few hundred particles, so the engine picks the serial build below ``PARALLEL_MIN``
items. Both builds come from the same plain function and are cached on disk.
"""

from __future__ import annotations

import types
from collections.abc import Callable
from typing import Any

from numba import njit

PARALLEL_MIN = 4000


class Kernel:
    """A plain function with a serial and a threaded compiled build (compiled lazily)."""

    def __init__(self, fn: Callable[..., Any]) -> None:
        self.py_func = fn
        self.__doc__ = fn.__doc__
        self.__name__ = fn.__name__
        serial_fn = types.FunctionType(fn.__code__, fn.__globals__, fn.__name__ + "_serial",
                                       fn.__defaults__, fn.__closure__)
        serial_fn.__qualname__ = fn.__qualname__ + "_serial"
        self.serial = njit(cache=True)(serial_fn)
        self.parallel = njit(cache=True, parallel=True)(fn)

    def pick(self, size: int) -> Callable[..., Any]:
        """The build to use for ``size`` items (particles or pairs)."""
        return self.parallel if size >= PARALLEL_MIN else self.serial

    def __call__(self, *args: Any) -> Any:
        return self.parallel(*args)


def kernel(fn: Callable[..., Any]) -> Kernel:
    """Decorator: make ``fn`` a ``Kernel`` (serial + threaded builds)."""
    return Kernel(fn)
