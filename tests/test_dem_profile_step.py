"""benchmarks/profile_step.py steps the same physics as the compiled loop.

The profiler calls the compiled loop's kernels one by one from Python to time them; its
figures are only worth something if those calls are the loop: the same kernels in the same
order on the same arrays. Checked bitwise against ``Simulation.step`` on the bonded block
(bonds, walls with a moving lid, neighbour rebuilds) and the settling case.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numba
import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

from profile_step import new_timers, step_by_kernel  # noqa: E402

from tribodem.dem.bench import CASES, simulation_from_case  # noqa: E402


@pytest.mark.parametrize(("case", "n", "steps"), [("bonded3d", 1000, 120),
                                                 ("settle3d", 1000, 300)])
def test_kernel_by_kernel_is_the_compiled_loop(case: str, n: int, steps: int) -> None:
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        a = simulation_from_case(CASES[case](n=n))
        b = simulation_from_case(CASES[case](n=n))
        a.step(10)
        b.step(10)
        builds = a.nl.builds
        a.step(steps)
        tim = new_timers()
        step_by_kernel(b, steps, tim)
    finally:
        numba.set_num_threads(threads)
    assert b.step_count == a.step_count
    assert np.array_equal(a.p.pos, b.p.pos) and np.array_equal(a.p.omega, b.p.omega)
    assert b.time == a.time and b.nl.builds == a.nl.builds
    for wa, wb in zip(a.walls, b.walls, strict=True):
        assert np.array_equal(wa.point, wb.point) and wa.normal_force == wb.normal_force
    for ia, ib in zip(a.interactions, b.interactions, strict=True):  # the bonds' state
        assert np.array_equal(ia.fn, ib.fn) and np.array_equal(ia.mb, ib.mb)
    if case == "settle3d":
        assert a.nl.builds > builds  # the steps crossed neighbour rebuilds
    assert all(v >= 0.0 for v in tim.values()) and tim["pair contacts"] > 0.0
