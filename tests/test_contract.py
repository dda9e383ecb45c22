"""The first-body contract: a backend written in one file (``analytic_backend.py``) and
registered by one line runs the fretting loop; capabilities refuse mismatches before work."""

from __future__ import annotations

import pytest
from analytic_backend import AnalyticHertzSolver

from tribodem.contact import BACKENDS
from tribodem.fretting import ALPHA_SEED, CriterionUnavailable, FrettingLoop, make_criterion
from tribodem.fretting.case import build_loop
from tribodem.fretting.config import resolve_config
from tribodem.io.config import ConfigError

LOAD, MU, AMP = 100.0, 0.6, 0.3e-3


@pytest.fixture
def registered():
    BACKENDS["analytic-hertz"] = AnalyticHertzSolver  # the one line of registration
    yield "analytic-hertz"
    del BACKENDS["analytic-hertz"]


def test_new_backend_runs_the_loop_from_a_config(registered) -> None:
    cfg = resolve_config(None, overrides={"solver": registered, "cycles": 3,
                                          "contact": {"n": 64}})
    loop = build_loop(cfg)
    assert isinstance(loop.solver, AnalyticHertzSolver)
    hist = loop.run(3)
    # gross slip: mu P 4A per cycle (closed form), wear volume = alpha x energy (eq 2.7)
    for row in hist.rows:
        assert row["dissipated_energy_J"] == pytest.approx(MU * LOAD * 4 * AMP, rel=0.02)
    total = hist.volume("upper") + hist.volume("lower")
    assert total == pytest.approx(ALPHA_SEED * hist.cumulative_energy, rel=1e-9)


def test_new_backend_takes_its_own_options_table(registered) -> None:
    """The plug-in backend's ``[analytic]`` table (its own options model) through the
    config: validated by its model (a bad value refused naming ``analytic.radius``),
    handed to the backend, recorded as a table of its own and read back."""
    cfg = resolve_config(None, overrides={"solver": registered, "cycles": 1,
                                          "contact": {"n": 64}, "analytic": {"radius": 6e-3}})
    loop = build_loop(cfg)
    assert loop.solver.hertz.radius == 6e-3
    rec = cfg.record()
    assert rec["analytic"] == {"radius": 6e-3}
    assert resolve_config(None, base=rec) == cfg
    with pytest.raises(ConfigError, match=r"analytic\.radius = -1"):
        resolve_config(None, overrides={"solver": registered, "analytic": {"radius": -1}})


def test_capabilities_refuse_a_criterion_before_any_work(registered) -> None:
    with pytest.raises(CriterionUnavailable, match="subsurface.*AnalyticHertzSolver"):
        FrettingLoop(AnalyticHertzSolver(), make_criterion("s22"))
    with pytest.raises(CriterionUnavailable, match="plastic.*HalfSpaceSolver"):
        from tribodem.contact import HalfSpaceSolver

        FrettingLoop(HalfSpaceSolver(n=32), make_criterion("dfdi"))
    cfg = resolve_config(None, overrides={"solver": registered, "wear": {"criterion": "shear"}})
    with pytest.raises(ConfigError, match="wear.criterion = 'shear' needs subsurface.*"
                                          "solver = 'analytic-hertz'.*allowed: solver = "
                                          "'elastic' or solver = 'elastic-plastic'"):
        build_loop(cfg)
    cfg = resolve_config(None, overrides={"solver": registered, "debris": {"every": 2}})
    with pytest.raises(ConfigError, match="debris.*needs debris"):
        build_loop(cfg)


def test_unknown_backend_is_refused_naming_the_registered_ones() -> None:
    with pytest.raises(ConfigError, match="solver.*fe2.*allowed: elastic, elastic-plastic"):
        resolve_config(None, overrides={"solver": "fe2"})
