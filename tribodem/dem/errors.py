"""Errors the engine raises; each message says what happened and why."""

from tribodem.io.config import ConfigError
from tribodem.io.runs import RunStopped


class SimulationUnstable(RunStopped):
    """The run went numerically unstable (NaN, runaway overlap); outputs so far are kept."""


class TimeStepError(ConfigError):
    """A user time step above the critical step (names the limiting pair and the value)."""
