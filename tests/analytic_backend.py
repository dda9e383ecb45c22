"""A first-body backend in one file, written against the contract alone: the closed-form
Hertz sphere-on-flat contact in gross slip (q = mu p against the sliding direction).

It ignores wear (the surfaces it is given do not change its answer) and gives no subsurface
stress: it declares so in its capabilities, and the loop must refuse a criterion that needs
more. Its one option, the sphere's radius, is its own ``[analytic]`` table
(:class:`AnalyticOptions`, declared in :attr:`AnalyticHertzSolver.options`): a fretting
config takes it as it takes the built-in backends' tables. Registered by one line:
``BACKENDS["analytic-hertz"] = AnalyticHertzSolver``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np
from pydantic import BaseModel, Field

from tribodem.contact import (
    Capabilities,
    ElasticBody,
    FirstBodySolver,
    HertzSphere,
    IncrementResult,
    contact_modulus,
    crossed_cylinders,
)
from tribodem.contact.base import ContactCase
from tribodem.io.model import StrictModel


class AnalyticOptions(StrictModel):
    """``[analytic]``: the closed-form backend's own option."""

    radius: float = Field(4e-3, gt=0, description="radius of the Hertz sphere, m")


class AnalyticHertzSolver(FirstBodySolver):
    """Hertz pressure of a sphere of radius ``radius`` (m) under ``load`` (N) on an n x n
    window of ``window`` (m); gross slip with friction ``friction``."""

    capabilities = Capabilities(subsurface=False, contacts=("point",))
    options: ClassVar[dict[str, type[BaseModel]]] = {"analytic": AnalyticOptions}

    @classmethod
    def from_case(cls, case: ContactCase, options: Mapping[str, BaseModel] | None = None
                  ) -> AnalyticHertzSolver:
        """On ``case`` with the ``[analytic]`` table's radius (its default when left
        out)."""
        opts = (options or {}).get("analytic") or AnalyticOptions()
        assert isinstance(opts, AnalyticOptions)
        return cls(case.upper, case.lower, load=case.load, friction=case.friction,
                   upper_material=case.upper_material, lower_material=case.lower_material,
                   n=case.n, window=case.window, radius=opts.radius)

    def __init__(self, upper: Any = None, lower: Any = None, load: float = 100.0,
                 friction: float = 0.6, upper_material: ElasticBody | None = None,
                 lower_material: ElasticBody | None = None, n: int = 64,
                 window: float | None = None, radius: float = 4e-3, **_: Any) -> None:
        if upper is None or lower is None:
            upper, lower = crossed_cylinders()
        self.upper, self.lower = upper, lower
        self.load, self.friction, self.n = float(load), float(friction), int(n)
        e_star = contact_modulus(upper_material or ElasticBody(),
                                 lower_material or ElasticBody())
        self.modulus = e_star
        self.hertz = HertzSphere(radius, self.load, e_star)
        self.dx = (window or 10 * self.hertz.contact_radius) / self.n
        self.reset()

    def reset(self) -> None:
        self._offset = 0.0

    def solve_increment(self, offset: float) -> IncrementResult:
        step = offset - self._offset
        xw, yw = np.meshgrid(self.coords, self.coords, indexing="ij")
        p = self.hertz.pressure(np.hypot(xw, yw))
        inside = p > 0
        traction = np.zeros((self.n, self.n, 2))
        slip = np.zeros((self.n, self.n, 2))
        if step != 0.0:
            traction[..., 0] = -np.sign(step) * self.friction * p
            slip[inside, 0] = step
        inc = IncrementResult(offset=offset, start_offset=self._offset,
                              direction=float(np.sign(step)), pressure=p, traction=traction,
                              slip=slip, contact_area=float(inside.sum()) * self.dx**2,
                              normal_load=float(p.sum()) * self.dx**2)
        self._offset = offset
        return inc

    def state_dict(self) -> dict[str, Any]:
        return {"offset": self._offset}

    def load_state_dict(self, state: dict[str, Any]) -> None:
        self._offset = float(state["offset"])
