"""Braking conditions of Sha et al. (2022) table 4 and the load/speed conversions behind them.

Table 4 gives each condition twice: initial braking load (kN) next to a simulation pressure
(MPa), and initial braking speed (r/min) next to a relative sliding speed (m/s). The pairs
imply one pad area and one friction radius:

- pressure ``p = F / A_pad`` with ``A_pad = 13 kN / 0.33 MPa = 0.03939 m^2``
  (17 kN -> 0.4315 MPa, 21 kN -> 0.5330 MPa: the table's 0.43 and 0.53 after rounding);
- speed ``v = 2 pi n / 60 R`` with ``R = 47.12 m/s / (1200 r/min x 2 pi / 60) = 0.375 m``
  (800 r/min -> 31.416 m/s, table 31.41; 1000 r/min -> 39.270 m/s, table 39.27).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

#: pad area implied by table 4 (m^2): 13 kN <-> 0.33 MPa
PAD_AREA_M2 = 13.0e3 / 0.33e6
#: friction radius implied by table 4 (m): 1200 r/min <-> 47.12 m/s (= 0.37497 m; 0.375 m)
FRICTION_RADIUS_M = 0.375
#: the seed's braking time of every condition (s, section 3.2)
SEED_BRAKING_TIME_S = 8.0


def load_to_pressure(load_kN: float) -> float:
    """Initial braking load (kN) -> interface pressure (Pa) over the table 4 pad area."""
    if not load_kN > 0:
        raise ValueError(f"load_kN = {load_kN!r}: must be > 0 kN")
    return load_kN * 1e3 / PAD_AREA_M2


def pressure_to_load(pressure_Pa: float) -> float:
    """Interface pressure (Pa) -> initial braking load (kN)."""
    if not pressure_Pa > 0:
        raise ValueError(f"pressure_Pa = {pressure_Pa!r}: must be > 0 Pa")
    return pressure_Pa * PAD_AREA_M2 / 1e3


def rpm_to_speed(rpm: float) -> float:
    """Initial braking speed (r/min) -> sliding speed at the friction radius (m/s)."""
    if not rpm > 0:
        raise ValueError(f"rpm = {rpm!r}: must be > 0 r/min")
    return rpm * 2.0 * math.pi / 60.0 * FRICTION_RADIUS_M


def speed_to_rpm(speed_m_s: float) -> float:
    """Sliding speed (m/s) -> disc speed (r/min) at the friction radius."""
    if not speed_m_s > 0:
        raise ValueError(f"speed_m_s = {speed_m_s!r}: must be > 0 m/s")
    return speed_m_s * 60.0 / (2.0 * math.pi * FRICTION_RADIUS_M)


@dataclass(frozen=True)
class Condition:
    """One braking condition: load (kN) and disc speed (r/min) with their SI forms."""

    index: int
    load_kN: float
    rpm: float
    table_pressure_MPa: float | None = None
    table_speed_m_s: float | None = None

    @property
    def pressure_Pa(self) -> float:
        """Interface pressure (Pa)."""
        return load_to_pressure(self.load_kN)

    @property
    def speed_m_s(self) -> float:
        """Sliding speed (m/s)."""
        return rpm_to_speed(self.rpm)


#: Sha et al. (2022) table 4
CONDITIONS: dict[int, Condition] = {
    1: Condition(1, 13.0, 1200.0, 0.33, 47.12),
    2: Condition(2, 17.0, 1200.0, 0.43, 47.12),
    3: Condition(3, 21.0, 800.0, 0.53, 31.41),
    4: Condition(4, 21.0, 1000.0, 0.53, 39.27),
    5: Condition(5, 21.0, 1200.0, 0.53, 47.12),
}


def get_condition(index: int) -> Condition:
    """Table 4 condition ``index`` (1..5); a clear ValueError otherwise."""
    if index not in CONDITIONS:
        raise ValueError(f"condition = {index!r}: must be one of {sorted(CONDITIONS)} "
                         "(Sha et al. (2022) table 4)")
    return CONDITIONS[index]
