"""tribodem.cyclejump: cycle-jumping (Lu (2018) chapter 4 and appendix III; eq 2.20).

``strategies`` (the strategies of the thesis behind :class:`JumpStrategy`, error-controlled
steps, :func:`replay` and the synthetic series), ``smooth`` (:class:`SmoothJump`, the default
``adaptive``: steps judged on a local fit of the underlying curve), ``registry``
(:data:`STRATEGIES` by name, :func:`make_strategy`), ``recorded`` (a recorded
``cycle,increment`` CSV:
:func:`read_increments_csv`, :func:`replay_csv` as ``tribodem jump replay`` does it,
:func:`plot_replay`), ``cli`` (``tribodem jump replay``).
"""

from tribodem.cyclejump.recorded import plot_replay, read_increments_csv, replay_csv
from tribodem.cyclejump.registry import STRATEGIES, make_strategy
from tribodem.cyclejump.smooth import SmoothJump
from tribodem.cyclejump.strategies import (
    SMOOTH_SHAPES,
    AdaptiveDiagnostics,
    AdaptiveJump,
    CojocaruJump,
    ConstantJump,
    JumpStrategy,
    MovingGroupsJump,
    OverlappingGroupsJump,
    ReplayResult,
    error_controlled_jump,
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
    "SmoothJump",
    "error_controlled_jump",
    "make_strategy",
    "plot_replay",
    "read_increments_csv",
    "replay",
    "replay_csv",
    "synthetic_smooth_series",
    "synthetic_two_phase_series",
    "transition_end",
    "two_phase_rate",
]
