"""What one braking run needs (:class:`RunSetup`, SI units) and the rules read off it: the
checkpoint interval, the sliding-distance cap of a run that slides until steady, the
setup as the JSON record a checkpoint keeps."""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from tribodem.braking.model import Geometry

#: a body is worn through when its remaining thickness (``measure``: intact matrix and
#: delaminated slab outside the anchored layer, solid area over ``phi W``) falls below this
#: many of its mean particle diameters (the default of ``RunSetup.worn_through_diameters``):
#: the anchored boundary layer, not the body, then meets the sliding interface, so the cell
#: no longer models the surface zone of a thick pad or disc. The run stops there (exit 3,
#: every output written). With the debris outlet the bodies are consumed at the wear rate
#: (the 72-um disc of the default cell was worn through within 5-12 mm in 9 of 22 runs)
WORN_THROUGH = 2.0
#: ``RunSetup`` fields a resumed run may change: they do not change the results
FREE_SETUP_FIELDS = ("checkpoint_every", "figures")


@dataclass
class RunSetup:
    """Everything a run needs (SI). ``condition`` is the table 4 index or ``None``."""

    pressure_Pa: float
    speed_m_s: float
    duration_s: float
    geometry: Geometry = field(default_factory=Geometry)
    condition: int | None = None
    micro: str = "calibrated"
    samples: int = 100
    vtk_snapshots: int = 6
    wall_mass_ratio: float = 0.05
    backing: str = "absorbing"
    plate_areal_mass: float | None = None
    local_damping: float = 0.0
    dt_safety: float = 0.3
    thermal_curve: Path | None = None
    thermal_time_map: str = "simulated"
    figures: bool = True
    checkpoint_every: int = 0  # samples between checkpoints; 0: ceil(samples / 10)
    #: slide past ``duration_s`` until the wear rate per sliding distance is steady
    #: (``steady_state``), in blocks of 20% of ``duration_s``, at most ``max_distance_m``
    until_steady: bool = False
    max_distance_m: float = 0.0  # 0: 5 x the distance of duration_s
    steady_tolerance: float = 0.15
    #: applying the load: the full target at once (``0``) or ramped linearly from 0 over
    #: ``ramp_s`` seconds of sliding (the pad applied as a hydraulic pressure builds up)
    ramp_s: float = 0.0
    #: sliding ramped up: the disc starts at rest under the pad (full load) and its speed
    #: rises linearly to ``speed_m_s`` over ``speed_ramp_s`` seconds (0: at speed at once)
    speed_ramp_s: float = 0.0
    #: debris outlet (``outlet``): a debris component leaves the cell once carried this
    #: far (m) along the sliding relative to the pad; 0 = closed cell (Sha et al. (2022))
    outlet_length_m: float = 0.0
    #: stop when a body's remaining thickness falls below this many of its mean particle
    #: diameters (``WORN_THROUGH``); 0 = never stop
    worn_through_diameters: float = WORN_THROUGH
    #: feed fresh body behind a worn one (``braking.feed``; the bodies are then cut from a
    #: block periodic in y)
    feed: bool = False


def check_setup(setup: RunSetup) -> None:
    """``ValueError`` naming the first value a run cannot use: a load (Pa), speed (m/s)
    or duration (s) that is not positive, an unknown thermal time map, the feed with a
    thermal curve."""
    for name, v in (("pressure_Pa", setup.pressure_Pa), ("speed_m_s", setup.speed_m_s),
                    ("duration_s", setup.duration_s)):
        if not v > 0:
            raise ValueError(f"{name} = {v!r}: must be > 0")
    if setup.thermal_time_map not in ("simulated", "stretched"):
        raise ValueError(f"thermal_time_map = {setup.thermal_time_map!r}: must be "
                         "'simulated' or 'stretched'")
    if setup.feed and setup.thermal_curve is not None:
        raise ValueError("feed with a thermal_curve: the feed does not carry temperatures")


def setup_record(setup: RunSetup) -> dict[str, Any]:
    """The setup as JSON data, without the fields a resumed run may change."""
    d = asdict(setup)
    for k in FREE_SETUP_FIELDS:
        d.pop(k)
    d["thermal_curve"] = None if setup.thermal_curve is None else str(setup.thermal_curve)
    return json.loads(json.dumps(d))


def checkpoint_interval(setup: RunSetup) -> int:
    """Samples between checkpoints: ``checkpoint_every``, or (0) ceil(samples / 10), i.e.
    about every 10% of the run."""
    return setup.checkpoint_every or max(1, math.ceil(setup.samples / 10))


def max_distance(setup: RunSetup) -> float:
    """The cap on the sliding distance (m) of a run that slides until steady."""
    return setup.max_distance_m or 5.0 * setup.speed_m_s * setup.duration_s
