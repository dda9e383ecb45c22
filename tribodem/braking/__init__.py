"""Braking interface wear model (seed 000 sections 3.2-5): pad over disc, rough surfaces,
periodic in x, pressure plate on the pad, sliding disc; table 4 conditions; wear depth,
broken bonds, debris, force chains, transfer layer; ``tribodem braking run|sweep``."""

from tribodem.braking.conditions import (
                                         CONDITIONS,
                                         Condition,
                                         get_condition,
                                         load_to_pressure,
                                         pressure_to_load,
                                         rpm_to_speed,
                                         speed_to_rpm,
)
from tribodem.braking.model import Geometry, Interface, build_interface, start_sliding
from tribodem.braking.run import RunSetup, run_braking

__all__ = [
    "CONDITIONS",
    "Condition",
    "Geometry",
    "Interface",
    "RunSetup",
    "build_interface",
    "get_condition",
    "load_to_pressure",
    "pressure_to_load",
    "rpm_to_speed",
    "run_braking",
    "speed_to_rpm",
    "start_sliding",
]
