"""Compiled per-step forms of interactions, for the engine's compiled multi-step loop.

``Simulation.step`` runs many steps in one compiled call (``engine._run_steps``) when
every active piece has a compiled form; otherwise it keeps its Python loop. An
interaction declares its compiled form by two optional methods (see
``engine.Interaction``):

- ``compiled(sim)`` returns its state for the compiled loop -- an instance of a
  ``typing.NamedTuple`` class registered here with :func:`register` (arrays it owns,
  shared by reference, and constants) -- or ``None`` when it has no compiled form now
  (the engine then steps in Python);
- ``after_compiled(sim, state)`` runs each time the compiled loop hands back to Python
  (at a neighbour rebuild, an event, a stability check, a recorder sample, the end of
  the call): it copies back what is not shared by reference and handles events (a
  bond break is logged there).

The registered step function ``fn(state, ctx) -> int`` runs where ``compute`` would: each
step after the pair contacts, in the order of ``sim.interactions``, adding into
``ctx.ext_force`` / ``ctx.ext_torque`` (N, N m; zeroed before). ``ctx`` is the engine's
:class:`StepContext` (SI arrays of the particles, pairs and walls; the walls' drive in
``wall_par``, see ``W_*``). It returns 0, or a non-zero event code: the loop then ends
the step and returns to Python, where ``after_compiled`` sees the event. The engine
dispatches to the step function by the state's class (:func:`interaction_step`, a numba
overload), so the engine knows no application.

Numba's disk cache checks a compiled function against its own source file only, and the
loop links the registered steps (and every kernel's helpers) from other files: after
editing one of them, delete ``tribodem/**/__pycache__/*.nbi`` and ``*.nbc`` (else the old
code keeps running; a fresh clone has no cache). The first call compiles the loop once per
set of state classes (seconds); it is cached after that.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np
from numba import njit, types
from numba.extending import overload

#: columns of ``StepContext.wall_par`` (one row per wall): the wall's mode (``WALL_MODES``
#: index), its target force (N), servo mass (kg), servo damping (N s/m), PFC gain factor,
#: speed cap (m/s)
W_MODE, W_TARGET, W_MASS, W_DAMPING, W_ALPHA, W_MAXSPEED = range(6)
N_WPAR = 6

_STEPS: dict[type, Any] = {}


class StepContext(NamedTuple):
    """What a compiled step function sees (SI; arrays shared with the ``Simulation``)."""

    pos: np.ndarray  # (n, 3) m
    vel: np.ndarray  # (n, 3) m/s
    omega: np.ndarray  # (n, 3) 1/s
    radius: np.ndarray  # (n,) m
    mass: np.ndarray  # (n,) kg
    inertia: np.ndarray  # (n,) kg m^2
    mat: np.ndarray  # (n,) material index
    group: np.ndarray  # (n,) application label
    fixed: np.ndarray  # (n,) FIX_* bits
    force: np.ndarray  # (n, 3) N, pair sums (then the total without gravity)
    torque: np.ndarray  # (n, 3) N m
    ext_force: np.ndarray  # (n, 3) N, the interactions' forces of this step
    ext_torque: np.ndarray  # (n, 3) N m
    start: np.ndarray  # neighbour list (``neighbors.NeighborList``)
    pair_i: np.ndarray
    pair_j: np.ndarray
    rev_start: np.ndarray
    rev_pair: np.ndarray
    ref_pos: np.ndarray  # (n, 3) m, positions at the last build
    ref_radius: np.ndarray  # (n,) m
    hist: np.ndarray  # (m, 3) m, shear springs
    pinfo: np.ndarray  # (m, 4): overlap m, normal force N, energy J, kn N/m
    fpair: np.ndarray  # (m, 3) N, force on j
    tpair_i: np.ndarray
    tpair_j: np.ndarray
    pairtab: np.ndarray  # pair property table
    elin: np.ndarray  # (materials,) Pa
    wstart: np.ndarray  # near-wall list (``walls.near_walls``)
    wid: np.ndarray
    wpart: np.ndarray
    wbstart: np.ndarray
    wall_hist: np.ndarray  # (walls, n, 3) m
    wall_info: np.ndarray  # (walls, n, 4)
    wsum: np.ndarray  # (blocks, walls, 5)
    wforce: np.ndarray  # (n, 3) N
    wtorque: np.ndarray  # (n, 3) N m
    wall_tot: np.ndarray  # (walls, 5): force on the wall (3, N), contacts, sum of kn (N/m)
    wall_point: np.ndarray  # (walls, 3) m
    wall_normal: np.ndarray  # (walls, 3), unit, towards the particles
    wall_vel: np.ndarray  # (walls, 3) m/s
    wall_mat: np.ndarray  # (walls,) material index
    wall_par: np.ndarray  # (walls, N_WPAR): see W_*
    wall_nf: np.ndarray  # (walls,) N, normal force of the particles on the wall (+ pushes)
    wall_ref_point: np.ndarray  # (walls, 3) m, wall points at the last neighbour build
    wall_ref_normal: np.ndarray  # (walls, 3)
    drift: np.ndarray  # (blocks,) m, largest move since the build
    gravity: np.ndarray  # (3,) m/s^2
    lo: np.ndarray  # (3,) m, box origin
    length: np.ndarray  # (3,) m, box edges
    periodic: np.ndarray  # (3,) bool
    clock: np.ndarray  # (1,) s, the simulation time
    dim: int  # 2 disks, 3 spheres
    thickness: float  # m (disks)
    dt: float  # s
    viscous: float  # 1/s
    local: float  # PFC local damping alpha
    has_ext: bool  # interactions present: ext_force/ext_torque are used
    half_skin: float  # m, the neighbour list's rebuild trigger


def register(state_cls: type) -> Callable[[Any], Any]:
    """Decorator: ``fn`` (a ``numba.njit`` function ``fn(state, ctx) -> int``) is the
    compiled step of the interactions whose ``compiled(sim)`` returns a ``state_cls``
    (a module-level ``typing.NamedTuple`` class)."""

    def deco(fn: Any) -> Any:
        _STEPS[state_cls] = fn
        return fn

    return deco


def registered(state: object) -> bool:
    """Is ``state`` an instance of a registered compiled-step state class?"""
    return type(state) in _STEPS


def interaction_step(state: Any, ctx: Any) -> int:  # pragma: no cover - numba only
    """Run the compiled step registered for ``type(state)`` (in compiled code only)."""
    raise NotImplementedError("interaction_step is called from compiled code only")


@overload(interaction_step)
def _interaction_step(state: Any, ctx: Any) -> Any:
    if isinstance(state, types.BaseNamedTuple) and state.instance_class in _STEPS:
        fn = _STEPS[state.instance_class]

        def impl(state: Any, ctx: Any) -> Any:  # pragma: no cover - numba
            # (annotated as the overload: numba compares the two signatures)
            return fn(state, ctx)

        return impl
    return None


class NoStep(NamedTuple):
    """The state of nothing: closes the engine's tuple of states (never empty)."""

    unused: int = 0


@register(NoStep)
@njit(cache=True)
def _no_step(state, ctx):  # pragma: no cover - numba
    """Does nothing, returns no event."""
    return 0


@njit(cache=True, inline="always")
def _block_sum(a, lo, n):  # pragma: no cover - numba
    """numpy's ``pairwise_sum`` of ``a[lo:lo + n]`` for ``n <= 128`` (loops_utils: one
    accumulator below 8 items, else 8 accumulators combined as a tree, then the rest)."""
    if n < 8:
        res = 0.0
        for i in range(n):
            res += a[lo + i]
        return res
    r0 = a[lo]
    r1 = a[lo + 1]
    r2 = a[lo + 2]
    r3 = a[lo + 3]
    r4 = a[lo + 4]
    r5 = a[lo + 5]
    r6 = a[lo + 6]
    r7 = a[lo + 7]
    i = 8
    end = n - n % 8
    while i < end:
        r0 += a[lo + i]
        r1 += a[lo + i + 1]
        r2 += a[lo + i + 2]
        r3 += a[lo + i + 3]
        r4 += a[lo + i + 4]
        r5 += a[lo + i + 5]
        r6 += a[lo + i + 6]
        r7 += a[lo + i + 7]
        i += 8
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < n:
        res += a[lo + i]
        i += 1
    return res


@njit(cache=True)
def np_sum(a, n):  # pragma: no cover - numba
    """``float(np.sum(a[:n]))`` for a contiguous float64 ``a``, bitwise: numpy's
    ``add.reduce`` adds to its identity 0.0 the pairwise sum (blocks of up to 128 items,
    larger ranges halved at a multiple of 8, the halves summed), here walked with an
    explicit stack (numba's cache cannot link a recursive function into a caller)."""
    if n <= 128:
        return 0.0 + _block_sum(a, 0, n)
    # tasks (lo, count, combine?) and partial sums, post-order
    t_lo = np.empty(192, dtype=np.int64)
    t_n = np.empty(192, dtype=np.int64)
    t_c = np.empty(192, dtype=np.bool_)
    vals = np.empty(96)
    nt = 1
    nv = 0
    t_lo[0] = 0
    t_n[0] = n
    t_c[0] = False
    while nt:
        nt -= 1
        lo = t_lo[nt]
        m = t_n[nt]
        if t_c[nt]:
            nv -= 1
            vals[nv - 1] = vals[nv - 1] + vals[nv]
        elif m <= 128:
            vals[nv] = _block_sum(a, lo, m)
            nv += 1
        else:
            m2 = m // 2
            m2 -= m2 % 8
            t_c[nt] = True  # combine after both halves
            t_lo[nt + 1] = lo + m2
            t_n[nt + 1] = m - m2
            t_c[nt + 1] = False
            t_lo[nt + 2] = lo
            t_n[nt + 2] = m2
            t_c[nt + 2] = False
            nt += 3
    return 0.0 + vals[0]
