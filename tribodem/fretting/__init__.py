"""Fretting wear: the wear loop (criteria plug-ins, column search, geometry update, jumping,
the debris third body) and its runs as library functions.

From Python::

    from tribodem.fretting import FrettingConfig, run

    result = run({"cycles": 3, "contact": {"n": 32}}, "runs/a", quick=True)
    result.to_dataframe()          # results.csv: one row per cycle
    result.summary["wear_volume_lower_m3"]

:func:`run` (one fretting run), :func:`study` (Lu (2018) chapter 6),
:func:`debris_study` (Lu (2018) section 5.4) and :func:`sweep` (a table of runs on Dask)
take a config as a :class:`FrettingConfig`, a dict shaped like the TOML file, a TOML path
or None, and return a :class:`~tribodem.io.record.RunResult`. See ``docs/fretting.md``
section "The wear loop".
"""

from tribodem.contact.fe.options import FEOptions
from tribodem.contact.options import PlasticOptions
from tribodem.fretting.case import FrettingCase, build_loop, build_solver
from tribodem.fretting.chapter6 import study
from tribodem.fretting.config import (
    CONFIG_VERSION,
    ContactConfig,
    DebrisConfig,
    FrettingConfig,
    JumpConfig,
    OutputConfig,
    WearConfig,
    check_resume,
    recorded_config,
    resolve_config,
)
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
from tribodem.fretting.debris_counts import debris_study
from tribodem.fretting.loop import RESULT_COLUMNS, FrettingHistory, FrettingLoop, WornSurface
from tribodem.fretting.runner import run
from tribodem.fretting.table_sweep import sweep

__all__ = [
    "ALPHA_SEED",
    "CONFIG_VERSION",
    "CRITERIA",
    "RESULT_COLUMNS",
    "ContactConfig",
    "Criterion",
    "CriterionUnavailable",
    "DFDICriterion",
    "DebrisConfig",
    "FEOptions",
    "FrettingCase",
    "FrettingConfig",
    "FrettingHistory",
    "FrettingLoop",
    "JumpConfig",
    "OutputConfig",
    "PlasticOptions",
    "SWTCriterion",
    "ThresholdCriterion",
    "TrackGrid",
    "WearConfig",
    "WornSurface",
    "build_loop",
    "build_solver",
    "check_resume",
    "column_search",
    "debris_study",
    "make_criterion",
    "recorded_config",
    "resolve_config",
    "run",
    "study",
    "swt_life",
    "sweep",
]
