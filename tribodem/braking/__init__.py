"""Braking interface wear model (Sha et al. (2022) sections 3.2-5): pad over disc, rough surfaces,
periodic in x, pressure plate on the pad, sliding disc; table 4 conditions; wear depth,
broken bonds, debris, force chains, transfer layer.

As a library: :func:`run` (one run, what ``tribodem braking run`` does) and :func:`sweep`
(conditions x packings on Dask, what ``tribodem braking sweep`` does), each returning a
:class:`~tribodem.io.record.RunResult` (``.summary``, ``.to_dataframe()``); the config as
a :class:`BrakingConfig`, a dict shaped like the TOML file or a TOML file's path. Lower
down: :func:`run_braking` on a :class:`RunSetup`, and :class:`BrakingLoop`;
:func:`projected_wall_s` projects a sweep's wall time on a cluster of a given size.
"""

from tribodem.braking.api import run, sweep
from tribodem.braking.conditions import (
    CONDITIONS,
    Condition,
    get_condition,
    load_to_pressure,
    pressure_to_load,
    rpm_to_speed,
    speed_to_rpm,
)
from tribodem.braking.config import BrakingConfig, resolve_config, setup_from_config
from tribodem.braking.ensemble import projected_wall_s
from tribodem.braking.loop import BrakingLoop
from tribodem.braking.model import Geometry, Interface, build_interface, start_sliding
from tribodem.braking.setup import RunSetup
from tribodem.braking.simulate import run_braking

__all__ = [
    "CONDITIONS",
    "BrakingConfig",
    "BrakingLoop",
    "Condition",
    "Geometry",
    "Interface",
    "RunSetup",
    "build_interface",
    "get_condition",
    "load_to_pressure",
    "projected_wall_s",
    "pressure_to_load",
    "resolve_config",
    "rpm_to_speed",
    "run",
    "run_braking",
    "setup_from_config",
    "speed_to_rpm",
    "start_sliding",
    "sweep",
]
