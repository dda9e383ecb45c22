"""Contact laws as styles (LAMMPS's ``pair_style``): one module per law, one signature.

A law module defines

- ``NAME`` (str): what ``Material(law=...)`` names;
- ``TIME_STEP``: ``"stiffness"`` (critical step ``sqrt(m/k)`` from the normal and shear
  stiffness, PFC) or ``"rayleigh"`` (Lu (2018) eq 2.17);
- ``normal(prop, delta, vn, rstar, mstar, lin_k) -> (fn, kt, ct, kn, energy)``, a
  ``numba.njit(inline="always")`` function: normal force (N, + = repulsive), tangential
  stiffness (N/m) and damping (N s/m), normal stiffness (N/m), stored normal energy (J) at
  overlap ``delta`` (m), normal approach speed ``vn`` (m/s), effective radius ``rstar`` (m)
  and mass ``mstar`` (kg); ``prop`` is the pair's row of the property table
  (:mod:`tribodem.dem.laws.table`), ``lin_k`` the PFC deformability stiffness (N/m).

Everything else of a contact (shear spring, Coulomb limit, rolling resistance) is common
(``contact.contact_response``). Built in: ``linear`` (id 0) and ``hertz`` (id 1), compiled
and cached. :func:`register` adds a law without touching any kernel: the kernels that
evaluate contacts are then re-bound to a dispatcher over all registered laws (compiled
once per registry, not cached on disk), through :func:`active`.
"""

from __future__ import annotations

import types
from types import ModuleType
from typing import Any

from numba import njit
from numba.core.registry import CPUDispatcher

from tribodem.dem.jit import Kernel
from tribodem.dem.laws import hertz, linear

BUILTIN: tuple[ModuleType, ...] = (linear, hertz)
_registry: list[ModuleType] = list(BUILTIN)
_memo: dict[Any, Any] = {}


@njit(cache=True, inline="always")
def law_normal(law, prop, delta, vn, rstar, mstar, lin_k):
    """The normal response of law ``law`` (an id of the registry); see the module doc."""
    if law == 1:
        return hertz.normal(prop, delta, vn, rstar, mstar, lin_k)
    return linear.normal(prop, delta, vn, rstar, mstar, lin_k)


def ids() -> dict[str, int]:
    """Registered law names -> ids (the value stored in the property table)."""
    return {m.NAME: k for k, m in enumerate(_registry)}


def modules() -> tuple[ModuleType, ...]:
    """The registered law modules, by id."""
    return tuple(_registry)


def register(module: ModuleType) -> int:
    """Add a contact law (a module as described above); returns its id."""
    name = getattr(module, "NAME", None)
    if not isinstance(name, str) or not name:
        raise ValueError(f"law module {module.__name__}: NAME must be a non-empty string")
    if name in ids():
        raise ValueError(f"law '{name}' is registered already")
    if getattr(module, "TIME_STEP", None) not in ("stiffness", "rayleigh"):
        raise ValueError(f"law '{name}': TIME_STEP must be 'stiffness' or 'rayleigh'")
    if not isinstance(getattr(module, "normal", None), CPUDispatcher):
        raise ValueError(f"law '{name}': normal must be a numba.njit function")
    _registry.append(module)
    _memo.clear()
    return len(_registry) - 1


def unregister(name: str) -> None:
    """Remove a registered (not built-in) law."""
    for m in _registry[len(BUILTIN):]:
        if m.NAME == name:
            _registry.remove(m)
            _memo.clear()
            return
    raise ValueError(f"law '{name}' is not a registered extra law")


def active(kernel: Kernel) -> Kernel:
    """``kernel`` as compiled for the registered laws: itself while only the built-in laws
    are registered, else a copy whose contact calls dispatch over every registered law."""
    if len(_registry) == len(BUILTIN):
        return kernel
    key = (id(kernel), tuple(m.NAME for m in _registry))
    if key not in _memo:
        dispatch = _dispatcher(_registry)
        deps: dict[Any, Any] = {}
        _memo[key] = Kernel(_rebind(kernel.py_func, dispatch, deps), kernel.chunk, cache=False)
    return _memo[key]


def _dispatcher(mods: list[ModuleType]) -> Any:
    """An njit ``law_normal`` with one branch per registered law."""
    src = ["def law_normal(law, prop, delta, vn, rstar, mstar, lin_k):"]
    for k in range(1, len(mods)):
        src += [f"    if law == {k}:", f"        return f{k}(prop, delta, vn, rstar, mstar, lin_k)"]
    src += ["    return f0(prop, delta, vn, rstar, mstar, lin_k)"]
    ns: dict[str, Any] = {f"f{k}": m.normal for k, m in enumerate(mods)}
    exec("\n".join(src), ns)  # noqa: S102 - generated from the registry, no user text
    return njit(inline="always")(ns["law_normal"])


def _uses_law(fn: types.FunctionType, seen: set[int]) -> bool:
    """Does ``fn`` call ``law_normal``, directly or through other njit functions?"""
    if id(fn) in seen:
        return False
    seen.add(id(fn))
    for name in fn.__code__.co_names:
        obj = fn.__globals__.get(name)
        if obj is law_normal:
            return True
        if isinstance(obj, CPUDispatcher) and _uses_law(obj.py_func, seen):
            return True
    return False


def _rebind(fn: types.FunctionType, dispatch: Any, deps: dict[Any, Any]
            ) -> types.FunctionType:
    """A copy of ``fn`` whose globals use ``dispatch`` for ``law_normal`` and re-bound copies
    of the njit functions that reach it."""
    g = dict(fn.__globals__)
    for name in fn.__code__.co_names:
        obj = fn.__globals__.get(name)
        if obj is law_normal:
            g[name] = dispatch
        elif isinstance(obj, CPUDispatcher) and _uses_law(obj.py_func, set()):
            if obj not in deps:
                inline = obj.targetoptions.get("inline", "never")
                deps[obj] = njit(inline=inline)(_rebind(obj.py_func, dispatch, deps))
            g[name] = deps[obj]
    new = types.FunctionType(fn.__code__, g, fn.__name__, fn.__defaults__, fn.__closure__)
    new.__qualname__ = fn.__qualname__
    new.__doc__ = fn.__doc__
    return new
