"""Fretting wear loop (issue 5): criteria plug-ins, column search, geometry update, jumping.

See ``docs/fretting.md`` section "The wear loop".
"""

from tribodem.fretting.criteria import (
    ALPHA_SEED,
    CRITERIA,
    Criterion,
    CriterionUnavailable,
    DFDICriterion,
    SWTCriterion,
    ThresholdCriterion,
    TrackGrid,
    column_search,
    make_criterion,
    swt_life,
)
from tribodem.fretting.loop import RESULT_COLUMNS, FrettingHistory, FrettingLoop, WornSurface

__all__ = [
    "ALPHA_SEED",
    "CRITERIA",
    "RESULT_COLUMNS",
    "Criterion",
    "CriterionUnavailable",
    "DFDICriterion",
    "FrettingHistory",
    "FrettingLoop",
    "SWTCriterion",
    "ThresholdCriterion",
    "TrackGrid",
    "WornSurface",
    "column_search",
    "make_criterion",
    "swt_life",
]
