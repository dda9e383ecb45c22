"""The cycle-jumping strategies by name (``[jump] strategy``, ``tribodem jump replay
--strategy``): one registry, each strategy one class behind :class:`JumpStrategy`.

``adaptive`` (the default of the fretting runs' jumping) is :class:`SmoothJump`, the error-
controlled step on a local fit of the underlying wear curve; ``polynomial`` is the adaptive
polynomial strategy of P. Lu's thesis (Numerical Modelling of Fretting Wear and Debris
Particles, University of Exeter 2018), section 4.3 with the fixes of section 4.4
(:class:`AdaptiveJump`; it was ``adaptive`` in configs before ``config_version`` 5).
"""

from __future__ import annotations

from typing import Any

from tribodem.cyclejump.smooth import SmoothJump
from tribodem.cyclejump.strategies import (
    AdaptiveJump,
    CojocaruJump,
    ConstantJump,
    JumpStrategy,
    MovingGroupsJump,
    OverlappingGroupsJump,
)

STRATEGIES: dict[str, type[JumpStrategy]] = {
    "constant": ConstantJump,
    "cojocaru": CojocaruJump,
    "moving": MovingGroupsJump,
    "overlapping": OverlappingGroupsJump,
    "adaptive": SmoothJump,
    "polynomial": AdaptiveJump,
}


def make_strategy(name: str, **params: Any) -> JumpStrategy:
    """Build a strategy by name with keyword parameters (unknown keys raise TypeError)."""
    try:
        cls = STRATEGIES[name]
    except KeyError:
        raise ValueError(f"unknown strategy {name!r}; allowed: {', '.join(STRATEGIES)}") from None
    return cls(**params)
