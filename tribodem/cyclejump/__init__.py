"""tribodem.cyclejump: cycle-jumping (seed 003 chapter 4 and appendix III; eq 2.20).

``strategies`` (the five strategies behind :class:`JumpStrategy`, error-controlled steps,
:func:`replay` and the synthetic series), ``cli`` (``tribodem jump replay``).
"""

from tribodem.cyclejump.strategies import (
    SMOOTH_SHAPES,
    STRATEGIES,
    AdaptiveDiagnostics,
    AdaptiveJump,
    CojocaruJump,
    ConstantJump,
    JumpStrategy,
    MovingGroupsJump,
    OverlappingGroupsJump,
    ReplayResult,
    error_controlled_jump,
    make_strategy,
    replay,
    synthetic_smooth_series,
    synthetic_two_phase_series,
    transition_end,
    two_phase_rate,
)

__all__ = [
    "SMOOTH_SHAPES",
    "STRATEGIES",
    "AdaptiveDiagnostics",
    "AdaptiveJump",
    "CojocaruJump",
    "ConstantJump",
    "JumpStrategy",
    "MovingGroupsJump",
    "OverlappingGroupsJump",
    "ReplayResult",
    "error_controlled_jump",
    "make_strategy",
    "replay",
    "synthetic_smooth_series",
    "synthetic_two_phase_series",
    "transition_end",
    "two_phase_rate",
]
