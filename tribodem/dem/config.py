"""The config of the engine's demo run (``tribodem dem run``, :func:`tribodem.dem.run`).

TOML tables ``[case]`` (which scenario, how many particles), ``[run]`` (steps, threads) and
``[output]`` (sampling intervals). Every model refuses keys it does not declare.
"""

from __future__ import annotations

from typing import Any, ClassVar, Literal

from pydantic import Field

from tribodem.io.model import PhysicalConfig, StrictModel
from tribodem.io.record import resolve


class CaseCfg(StrictModel):
    """Which scenario and how big."""

    kind: Literal["settle3d", "compress2d"] = "settle3d"
    particles: int = Field(2000, ge=10, le=5_000_000, description="number of particles")
    seed: int = Field(0, ge=0)


class RunCfg(StrictModel):
    """Length of the run and threads."""

    steps: int = Field(4000, ge=1, le=100_000_000)
    threads: int = Field(0, ge=0, le=256, description="0 = all cores")


class OutputCfg(StrictModel):
    """Sampling intervals (steps); 0 switches an output off."""

    scalars_every: int = Field(50, ge=1)
    vtk_every: int = Field(1000, ge=0)
    checkpoint_every: int = Field(2000, ge=0)


class DemRunConfig(PhysicalConfig):
    """``tribodem dem run`` configuration (TOML tables [case], [run], [output]).

    Its scenarios fix their materials and sizes, so it has no physically bounded field of
    its own (``allow_unphysical`` is there as in every command's config); the particle
    count is bounded by the memory this machine has (:func:`tribodem.io.runs.check_memory`,
    before any work)."""

    #: The ``--quick`` preset, laid over the config (it wins over a config file): 1,000
    #: spheres for 3,000 steps, a snapshot and a checkpoint every 500.
    QUICK: ClassVar[dict[str, Any]] = {
        "case": {"particles": 1000}, "run": {"steps": 3000},
        "output": {"vtk_every": 500, "checkpoint_every": 500}}

    #: What a resume may change (dotted fields, :func:`tribodem.io.record.config_diffs`):
    #: how far the run goes and on how many threads; everything else makes another run.
    MAY_CHANGE: ClassVar[tuple[str, ...]] = ("run.steps", "run.threads")

    case: CaseCfg = CaseCfg()
    run: RunCfg = RunCfg()
    output: OutputCfg = OutputCfg()

    @classmethod
    def quick(cls) -> DemRunConfig:
        """The ``--quick`` preset over the defaults (the README's demo run)."""
        return resolve(cls, {}, source="quick", quick=cls.QUICK)
