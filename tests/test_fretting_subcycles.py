"""Sub-cycles: a cycle that wears more than ``wear.update_tolerance`` elastic approaches is
solved again in passes that each add their share of its wear, so the worn profile follows
the wear equation whatever the wear per cycle is.

The case: a 6 mm cylinder on a flat at 20 N/mm (Hertz half-width 36 um, elastic approach
b^2/R = 0.22 um), steel on steel, mu 0.6, gross slip at an amplitude of 25 um, local
Archard with k 2.75e-12 / 5.5e-12 1/Pa (upper / lower): one cycle wears 0.96 elastic
approaches deep on the upper body. With one geometry update a cycle the edge points of the
scar take the load that the worn centre sheds and overshoot into pits one cell wide (at
n 512 a pit 1.03 um deep in a 0.6 um scar by cycle 3, measured), and the depth moves with
the grid (20 cycles: 0.64 / 0.66 / 1.03 um upper at n 128 / 256 / 512). The reference is
the wear equation resolved in the cycle count: 40 x the cycles at k / 40 (0.024 approaches
a cycle, no split), on the same grid.
"""

from __future__ import annotations

import numpy as np
import pytest

from tribodem.fretting import FrettingConfig, build_loop
from tribodem.fretting.loop import FrettingHistory

CASE = {
    "contact": {"geometry": "cylinder_on_flat", "radius": 6e-3, "load_per_length": 2.0e4,
                "friction": 0.6, "amplitude": 25e-6, "n": 128, "n_increments": 24,
                "window": 3.64e-4},
    "output": {"vtk": False, "figures": False},
}
K_UPPER, K_LOWER = 2.75e-12, 5.5e-12


def worn(cycles: int, scale: float, tolerance: float | None = None
         ) -> tuple[FrettingHistory, dict]:
    """The history of ``cycles`` cycles at ``scale`` x the wear coefficients, and the
    loop's ``wear_updates``."""
    wear = {"criterion": "archard", "archard_k_upper": K_UPPER * scale,
            "archard_k_lower": K_LOWER * scale}
    if tolerance is not None:
        wear["update_tolerance"] = tolerance
    cfg = FrettingConfig.model_validate({**CASE, "cycles": cycles, "wear": wear})
    loop = build_loop(cfg)
    hist = loop.run(cfg.cycles)
    return hist, loop.wear_updates()


@pytest.fixture(scope="module")
def reference() -> FrettingHistory:
    return worn(800, 1 / 40)[0]


def profiles(hist: FrettingHistory) -> tuple[np.ndarray, np.ndarray]:
    return hist.wear_upper[:, 0], hist.wear_lower[:, 0]


def test_a_split_cycle_follows_the_wear_equation(reference: FrettingHistory) -> None:
    """Default tolerance 0.05: every cycle split (at most 20 passes); maximum depth 0.33 /
    0.09 % off the reference (upper / lower; asserted 1 %), the profiles within 0.38 / 0.13 %
    of the depth at every point (asserted 1.5 %), the worn volumes k P' 4 A N of gross slip
    to 1e-9."""
    hist, u = worn(20, 1.0)
    assert u["cycles_split"] == 20 and 2 <= u["most_subcycles"] <= 64
    assert u["cycles_over_tolerance"] == 0
    assert u["largest_increment_over_approach"] == pytest.approx(0.96, abs=0.02)
    slide = 4 * CASE["contact"]["amplitude"] * 20  # m of sliding
    load = CASE["contact"]["load_per_length"] * hist.grid.dy  # N on the section's width
    for got, ref, k, vol in zip(profiles(hist), profiles(reference), (K_UPPER, K_LOWER),
                                (hist.volume("upper"), hist.volume("lower")), strict=True):
        assert got.max() == pytest.approx(ref.max(), rel=1e-2)
        assert np.abs(got - ref).max() < 0.015 * ref.max()
        assert vol == pytest.approx(k * load * slide, rel=1e-9)


def test_the_split_converges_with_the_tolerance() -> None:
    """Halving the tolerance (0.1 -> 0.05 -> 0.025: at most 10, 20, 39 passes) moves the
    maximum depth by 0.08 / 0.01 % then 0.32 / 0.09 % (upper / lower; asserted 0.6 %)."""
    d = [np.array([w.max() for w in profiles(worn(20, 1.0, t)[0])]) for t in (0.1, 0.05, 0.025)]
    assert np.all(np.abs(d[1] / d[0] - 1) < 6e-3) and np.all(np.abs(d[2] / d[1] - 1) < 6e-3)


def test_one_update_a_cycle_is_what_the_split_removes(reference: FrettingHistory) -> None:
    """``update_tolerance = 0``: one update a cycle, as before the split: the upper depth
    2.2 % and the lower 5.3 % deeper than the reference, a point of the lower profile 7.7 %
    of the depth off it (asserted > 3 %), and the largest cycle 1.58 approaches."""
    hist, u = worn(20, 1.0, 0.0)
    assert u["update_tolerance"] is None and u["cycles_split"] == 0
    assert u["largest_increment_over_approach"] > 1.0
    lower, ref = profiles(hist)[1], profiles(reference)[1]
    assert np.abs(lower - ref).max() > 0.03 * ref.max()


def test_a_record_of_config_version_5_reads_one_update_a_cycle() -> None:
    """Records written before the split (config_version 5) ran one update a cycle: they are
    read with ``update_tolerance = 0``; a record that names it keeps it."""
    from tribodem.fretting.config import CONFIG_VERSION, recorded_config

    old = {**CASE, "config_version": 5, "wear": {"criterion": "archard"}}
    read = recorded_config(old)
    assert read["config_version"] == CONFIG_VERSION == 7
    assert read["wear"] == {"criterion": "archard", "update_tolerance": 0.0}
    assert FrettingConfig.model_validate(read).wear.update_tolerance == 0.0
    named = recorded_config({**old, "wear": {"update_tolerance": 0.1}})
    assert named["wear"]["update_tolerance"] == 0.1
    assert recorded_config({**CASE, "config_version": 7}) == {**CASE, "config_version": 7}


def test_a_record_of_config_version_6_keeps_the_fe3d_morph_it_ran() -> None:
    """fe3d records before config_version 7 morphed by the lumped projection without a
    kink limit: read so (a record that names them keeps them; other solvers unchanged)."""
    from tribodem.fretting.config import recorded_config

    old = {"solver": "fe3d", "config_version": 6, "fe": {"threads": 2}}
    read = recorded_config(old)
    assert read["fe"] == {"morph": "projection", "max_wear_kink": "off", "threads": 2}
    cfg = FrettingConfig.model_validate(read)
    assert cfg.fe.morph == "projection" and cfg.fe.max_wear_kink is None
    named = recorded_config({**old, "fe": {"morph": "tributary"}})
    assert named["fe"]["morph"] == "tributary"
    assert "fe" not in recorded_config({"solver": "elastic", "config_version": 6})
