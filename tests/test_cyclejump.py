"""Cycle-jumping strategies (Lu (2018) chapter 4)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tribodem.cyclejump import (
    SMOOTH_SHAPES,
    STRATEGIES,
    AdaptiveJump,
    CojocaruJump,
    ConstantJump,
    MovingGroupsJump,
    OverlappingGroupsJump,
    error_controlled_jump,
    make_strategy,
    replay,
    synthetic_smooth_series,
    synthetic_two_phase_series,
    transition_end,
    two_phase_rate,
)

NOISE_SEEDS = range(5)


def linear_series(n: int = 2000, rate: float = 1.0):
    return synthetic_two_phase_series(n=n, ratio=1.0, noise=0.0, steady_rate=rate)


def noisy_two_phase(seed: int):
    return synthetic_two_phase_series(n=2000, ratio=10.0, noise=0.1, seed=seed)


# --- the synthetic series --------------------------------------------------------------


def test_two_phase_series_form():
    c, inc = synthetic_two_phase_series(n=2000, ratio=10, noise=0.0)
    assert c[0] == 1 and c[-1] == 2000 and len(inc) == 2000
    assert inc[0] == pytest.approx(10.0)
    assert inc[-1] == pytest.approx(1.0, rel=1e-9)
    te = transition_end()
    assert two_phase_rate(te) == pytest.approx(1.5)
    _, noisy = synthetic_two_phase_series(noise=0.1, seed=1)
    rel = noisy / two_phase_rate(c) - 1.0
    assert 0.09 < rel.std() < 0.11 and abs(rel.mean()) < 0.01


# --- acceptance: adaptive strategy -----------------------------------------------------


def test_adaptive_linear_noise_free_saves_80_percent_within_half_percent():
    c, inc = linear_series()
    r = replay(AdaptiveJump(), c, inc)
    assert r.cycles_saved_fraction >= 0.80
    assert r.relative_difference < 0.005
    assert r.max_relative_difference < 0.005


@pytest.mark.parametrize("seed", NOISE_SEEDS)
def test_adaptive_two_phase_noisy(seed):
    c, inc = noisy_two_phase(seed)
    r = replay(AdaptiveJump(), c, inc)
    assert r.cycles_saved_fraction >= 0.60, r.summary()
    assert r.relative_difference <= 0.10, r.summary()
    # running-in transition: cycles where the true rate exceeds 1.5x the steady rate
    te = transition_end(ratio=10.0, factor=1.5)
    assert r.jumps, "no jump at all"
    for start, n in r.jumps:
        # a jump from `start` skips cycles start+1 .. start+n: none may be in the transition
        assert start >= te, f"jump {start}->{start + n} inside the transition (< {te:.0f})"


def test_adaptive_no_jump_in_noise_free_transition():
    c, inc = synthetic_two_phase_series(noise=0.0)
    r = replay(AdaptiveJump(), c, inc)
    assert r.jumps and min(s for s, _ in r.jumps) >= transition_end()
    assert r.relative_difference < 0.05


def test_constant_has_larger_error_through_transition_than_adaptive():
    te = transition_end()
    for seed in NOISE_SEEDS:
        c, inc = noisy_two_phase(seed)
        ref = np.cumsum(inc)
        errs = {}
        for name in ("constant", "adaptive"):
            r = replay(make_strategy(name), c, inc)
            idx = np.searchsorted(c, r.cycles)
            m = r.cycles <= 2 * te  # through the transition
            errs[name] = np.max(np.abs(r.values[m] - ref[idx[m]]) / ref[idx[m]])
        # McColl's constant-rate jump over-predicts while the rate is falling (section 4.2.1)
        assert errs["constant"] > 0.05
        assert errs["constant"] > 5 * errs["adaptive"], errs


def test_constant_overpredicts_systematically_in_noise_free_transition():
    c, inc = synthetic_two_phase_series(noise=0.0)
    r = replay(ConstantJump(), c, inc)
    ref = np.cumsum(inc)
    idx = np.searchsorted(c, r.cycles)
    m = (r.cycles > 20) & (r.cycles < transition_end())
    assert np.all(r.values[m] > ref[idx[m]])  # rate of cycle N kept while it falls


def test_cojocaru_fails_on_noisy_series():
    """Section 4.2.2: on noisy wear the slope ratio is noise, so linearity is not detected."""
    te = transition_end()
    # noise-free: the ratio is tiny in the steady phase and the method jumps there
    c, inc = synthetic_two_phase_series(noise=0.0)
    s = CojocaruJump()
    r = replay(s, c, inc)
    h = np.array(s.history, dtype=float)
    steady = h[(h[:, 0] > 2 * te) & np.isfinite(h[:, 1])]
    assert np.median(steady[:, 1]) < 0.1 * s.q_y
    assert r.cycles_saved_fraction > 0.9
    for seed in NOISE_SEEDS:
        c, inc = noisy_two_phase(seed)
        s = CojocaruJump()
        replay(s, c, inc)
        h = np.array(s.history, dtype=float)
        h = h[np.isfinite(h[:, 1])]
        trans, steady = h[h[:, 0] < te], h[h[:, 0] > 2 * te]
        med_t, med_s = np.median(trans[:, 1]), np.median(steady[:, 1])
        # the ratio in the linear steady phase is ~5x q_y: linearity check fails there...
        assert med_s > 3 * s.q_y
        assert np.mean(steady[:, 1] <= s.q_y) < 0.2
        # ... and it cannot tell the linear phase from the non-linear transition
        assert 0.67 < med_t / med_s < 1.5


# --- the four other strategies on a linear series --------------------------------------


@pytest.mark.parametrize("name", ["constant", "cojocaru", "moving", "overlapping"])
def test_strategies_exact_on_noise_free_linear(name):
    c, inc = linear_series(n=500, rate=2.5e-9)
    r = replay(make_strategy(name), c, inc)
    assert r.cycles_saved_fraction > 0.9
    assert r.relative_difference < 1e-9


def test_constant_pattern_eq_2_20():
    c = np.arange(1, 101)
    inc = np.linspace(1.0, 2.0, 100)
    r = replay(ConstantJump(jump_length=20), c, inc)
    assert r.cycles_simulated == 5  # cycles 1, 21, 41, 61, 81 (the last jump ends at 100)
    assert [n for _, n in r.jumps] == [19, 19, 19, 19, 19]
    # H_total = N x H^N: cycles 1..20 worth 20 x increment of cycle 1
    assert r.values[1] == pytest.approx(20 * inc[0])


def test_cojocaru_jump_length_eq_4_2():
    s = CojocaruJump(q_y=0.02, q_e=0.05)
    s.observe(0, 0.0)
    s.observe(1, 1.0)
    s.observe(2, 2.01)  # slopes 1.0 and 1.01: r = 0.01 -> dx = 0.05 / 0.01 = 5
    assert s.propose_jump() == 5
    assert s.extrapolate(2.01, 5) == pytest.approx(2.01 + 5 * 1.01)
    s = CojocaruJump()
    s.observe(0, 0.0)
    s.observe(1, 1.0)
    s.observe(2, 2.03)  # r = 0.03 > q_y
    assert s.propose_jump() == 0


def test_group_ratios_eqs_4_3_and_4_5():
    # cumulative w = n^2: slope of group fit over a window = 2 * centre
    m = MovingGroupsJump(group_size=4, q_y=10.0, q_e=0.1)
    o = OverlappingGroupsJump(group_size=4, q_y=10.0, q_e=0.1)
    for n in range(0, 8):
        m.observe(n, float(n * n))
    for n in range(2, 8):
        o.observe(n, float(n * n))
    # moving: groups 0-3 (centre 1.5) and 4-7 (centre 5.5): r = (11 - 3) / 3
    assert m.ratio() == pytest.approx(8 / 3)
    assert m.propose_jump() == int(0.1 * 4 / (8 / 3))
    # overlapping: groups 2-5 (centre 3.5) and 4-7 (centre 5.5): r = (11 - 7) / 7
    assert o.ratio() == pytest.approx(4 / 7)
    assert o.propose_jump() == int(0.1 * 2 / (4 / 7))


def test_group_extrapolation_uses_latest_group_slope():
    m = MovingGroupsJump(group_size=3, q_y=1.0, q_e=1.0)
    for n in range(6):
        m.observe(n, 2.0 * n)
    assert m.propose_jump() > 0
    assert m.extrapolate(10.0, 7) == pytest.approx(24.0)


# --- adaptive internals ----------------------------------------------------------------


def test_adaptive_defaults_are_the_seeds():
    a = AdaptiveJump()
    assert (a.degree, a.foundation_cycles, a.q_coef, a.q_y, a.q_y_late, a.q_e) == (
        3, 8, 0.02, 0.005, 0.0002, 0.02)
    assert a.max_jump(100) == 200 and a.max_jump(1000) == 1000
    assert a.q_y_at(100) == 0.005 and a.q_y_at(1000) == 0.0002
    b = AdaptiveJump(max_jump_initial=15, max_jump_until=200)
    assert b.max_jump(150) == 15 and b.max_jump(400) == 30


def test_adaptive_jump_length_and_taylor_eq_4_13_4_15():
    # w(n) = n + 1e-4 n^2 exactly quadratic: f' = 1 + 2e-4 n, f'' = 2e-4
    a = AdaptiveJump(degree=2, degree_late=None, q_y=1.0, q_e=0.02, max_jump_initial=10**6,
                     curvature_over_window=False, window_fraction=None)
    for n in range(0, 40):
        a.observe(n, n + 1e-4 * n * n)
    d1, d2 = 1 + 2e-4 * 39, 2e-4
    assert a.propose_jump() == int(0.02 * d1 / d2)
    w39 = 39 + 1e-4 * 39**2
    assert a.extrapolate(w39, 50) == pytest.approx(w39 + 50 * d1)  # eq 4.15
    a2 = AdaptiveJump(degree=2, degree_late=None, taylor_order=2, window_fraction=None)
    for n in range(0, 40):
        a2.observe(n, n + 1e-4 * n * n)
    a2.propose_jump()
    assert a2.extrapolate(w39, 50) == pytest.approx(89 + 1e-4 * 89**2)  # exact for a quadratic


def test_adaptive_max_consecutive_jumps_and_moving_window():
    c, inc = linear_series(n=3000)
    a = AdaptiveJump(max_jump_initial=20, max_jump_until=10**6, max_consecutive_jumps=3,
                     refit_cycles=8)
    r = replay(a, c, inc)
    starts = [s for s, _ in r.jumps]
    ends = [s + n for s, n in r.jumps]
    run = 1
    for k in range(1, len(starts)):
        gap = starts[k] - ends[k - 1]  # simulated cycles between two jumps
        run = run + 1 if gap == 1 else 1
        assert run <= 3
        if k % 3 == 0:
            assert gap >= 8  # refit after the window restart
    assert r.relative_difference < 1e-9


def test_unconverged_fit_blocks_jumps():
    # strongly curved data: w = n^3 never looks linear, no jump
    a = AdaptiveJump()
    for n in range(0, 100):
        a.observe(n, float(n) ** 3)
        assert a.propose_jump() == 0


# --- arrays: a whole wear profile ------------------------------------------------------


def profile_rates(k: int = 41) -> np.ndarray:
    x = np.linspace(-1.5, 1.5, k)
    return 1e-9 * np.sqrt(np.clip(1.0 - x**2, 0.0, None))  # Hertz-like, zero outside


@pytest.mark.parametrize("name", sorted(STRATEGIES))
def test_profile_jump_reproduces_each_element_trend(name):
    rates = profile_rates()
    n = 1500
    c = np.arange(1, n + 1, dtype=float)
    inc = np.tile(rates, (n, 1))
    r = replay(make_strategy(name), c, inc)
    assert r.cycles_saved_fraction > 0.5
    final = np.asarray(r.final_value)
    assert final.shape == rates.shape
    ref = n * rates
    on = rates > 0
    assert np.all(np.abs(final[on] - ref[on]) <= 0.005 * ref[on])
    assert np.all(np.abs(final[~on]) <= 1e-20)


def test_profile_direct_extrapolation_uses_each_elements_rate():
    rates = profile_rates(9)
    base = np.linspace(0.0, 1e-6, 9)
    a = AdaptiveJump()
    for n in range(0, 60):
        a.observe(n, base + n * rates)
    assert a.propose_jump() > 0
    out = a.extrapolate(base + 59 * rates, 100)
    assert isinstance(out, np.ndarray) and out.shape == (9,)
    np.testing.assert_allclose(out, base + 159 * rates, rtol=0.005, atol=1e-18)


def test_profile_two_phase_each_element():
    """Profile whose elements all follow the running-in law with their own steady rate."""
    rates = profile_rates(11)[3:8]
    c, inc1 = synthetic_two_phase_series(noise=0.0)
    inc = inc1[:, None] * rates[None, :]
    r = replay(AdaptiveJump(), c, inc)
    scalar = replay(AdaptiveJump(), c, inc1)
    assert r.cycles_saved_fraction == scalar.cycles_saved_fraction > 0.6
    # the profile jumps exactly like the scalar series, element by element
    np.testing.assert_allclose(r.final_value, scalar.final_value * rates, rtol=1e-6)
    np.testing.assert_allclose(r.final_value, np.sum(inc, axis=0), rtol=0.05)


# --- misc ------------------------------------------------------------------------------


def test_replay_refuses_too_few_rows():
    with pytest.raises(ValueError, match="needs at least"):
        replay(AdaptiveJump(), np.arange(1, 5), np.ones(4))


def test_make_strategy_unknown():
    with pytest.raises(ValueError, match="allowed"):
        make_strategy("nope")
    with pytest.raises(TypeError):
        make_strategy("constant", q_y=1.0)


def test_reset_and_reuse_gives_same_result():
    c, inc = noisy_two_phase(0)
    s = AdaptiveJump()
    r1 = replay(s, c, inc)
    r2 = replay(s, c, inc)
    assert r1.cycles_simulated == r2.cycles_simulated
    assert math.isclose(r1.final_value, r2.final_value)


def test_adaptive_total_decides_on_the_sum_of_an_array_state() -> None:
    """A map whose points start wearing one after another (kinks) while the total grows
    linearly: deciding on every point never jumps, deciding on the total does."""
    from tribodem.cyclejump import AdaptiveJump

    def state(c: int) -> np.ndarray:
        # point k wears at rate 1 from cycle 3 k on; a last point absorbs the rest so the
        # total is exactly 10 c
        w = np.clip(c - 3.0 * np.arange(8), 0.0, None)
        return np.append(w, 10.0 * c - w.sum())

    jumps = {}
    for mode in ("worst", "total"):
        s = AdaptiveJump(decide_on=mode)
        s.observe(0, state(0))
        total = 0
        for c in range(1, 40):
            s.observe(c, state(c))
            total += s.propose_jump()
        jumps[mode] = total
    assert jumps["worst"] == 0
    assert jumps["total"] > 0
    with pytest.raises(ValueError, match="decide_on"):
        AdaptiveJump(decide_on="mean")


# --- step control follows the curve's smoothness ---------------------------------------

SMOOTH_N = 3000
SMOOTH_NOISE_SEEDS = range(3)


def smooth_cases():
    for shape in SMOOTH_SHAPES:
        yield shape, 0.0, 0
        for seed in SMOOTH_NOISE_SEEDS:
            yield shape, 0.02, seed


def test_smooth_series_forms():
    c, inc = synthetic_smooth_series("power", n=SMOOTH_N)
    assert c[0] == 1 and c[-1] == SMOOTH_N
    assert np.sum(inc) == pytest.approx(SMOOTH_N**0.5)  # h = N^0.5
    _, inc = synthetic_smooth_series("exponential", n=SMOOTH_N)
    assert inc[0] == pytest.approx(10.0)  # r_0 = 10 r_s
    assert inc[SMOOTH_N // 10] == pytest.approx(1 + 9 * math.exp(-1), rel=1e-3)  # N0 = n/10
    assert inc[-1] == pytest.approx(1.0, rel=1e-3)
    _, lin = synthetic_smooth_series("linear", n=100)
    np.testing.assert_array_equal(lin, np.ones(100))
    np.testing.assert_array_equal(synthetic_smooth_series("two_phase", n=2000, noise=0.02,
                                                          seed=3)[1],
                                  synthetic_two_phase_series(noise=0.02, seed=3)[1])
    _, noisy = synthetic_smooth_series("linear", n=SMOOTH_N, noise=0.02, seed=1)
    assert 0.018 < np.std(noisy) < 0.022
    with pytest.raises(ValueError, match="allowed"):
        synthetic_smooth_series("cubic")


def test_error_controlled_jump_formula():
    # relative error of the extrapolated increment = rate_error + kappa (lag + L / 2)
    assert error_controlled_jump(0.0, 0.01) == math.inf
    assert error_controlled_jump(0.01, 0.01) == pytest.approx(2.0)
    assert error_controlled_jump(1e-4, 0.01, lag=3.5) == pytest.approx(193.0)
    assert error_controlled_jump(1e-4, 0.01, rate_error=0.004) == pytest.approx(120.0)
    assert error_controlled_jump(1e-4, 0.01, rate_error=0.01) == 0.0
    assert error_controlled_jump(0.01, 0.01, lag=5.0) == 0.0
    assert error_controlled_jump(math.inf, 0.01) == 0.0


@pytest.mark.parametrize("shape, noise, seed", list(smooth_cases()))
def test_adaptive_default_saves_60_percent_on_smooth_shapes(shape, noise, seed):
    """Acceptance: >= 60 % saved at <= 5 % final error on every shape."""
    c, inc = synthetic_smooth_series(shape, n=SMOOTH_N, noise=noise, seed=seed)
    r = replay(AdaptiveJump(), c, inc)
    assert r.cycles_saved_fraction >= 0.60, r.summary()
    assert r.relative_difference <= 0.05, r.summary()
    if noise == 0.0:
        # the error control keeps every jump within tol = 1 % of what it adds
        assert r.relative_difference <= 0.01, r.summary()
    if shape == "linear" and noise == 0.0:
        assert r.relative_difference <= 1e-9


def test_seed_linearity_gate_is_blind_on_a_power_law():
    """The problem the step control fixes: kappa <= q_y refuses a smoothly bending curve."""
    c, inc = synthetic_smooth_series("power", n=1000)
    seed = replay(AdaptiveJump(step_control="seed"), c, inc)
    error = replay(AdaptiveJump(), c, inc)
    assert seed.cycles_saved_fraction < 0.1
    assert error.cycles_saved_fraction > 6 * seed.cycles_saved_fraction


@pytest.mark.parametrize("tol", [0.005, 0.02, 0.05])
def test_adaptive_tolerance_bounds_the_final_error(tol):
    """tol is the relative local error per jump, so it bounds the final relative error on
    noise-free smooth shapes; a looser tolerance saves more."""
    for shape in ("power", "exponential", "two_phase"):
        c, inc = synthetic_smooth_series(shape, n=SMOOTH_N)
        r = replay(AdaptiveJump(tol=tol), c, inc)
        assert r.relative_difference <= tol, (shape, r.summary())
        assert r.max_relative_difference <= tol, (shape, r.summary())
        if tol > 0.01:
            assert r.cycles_saved_fraction > replay(AdaptiveJump(), c, inc).cycles_saved_fraction


@pytest.mark.parametrize("name, params", [
    ("constant", {"step_control": "error"}),
    ("cojocaru", {}),
    ("moving", {}),
    ("overlapping", {}),
    ("cojocaru", {"q_e": 0.02}),
    ("moving", {"q_e": 0.02}),
    ("overlapping", {"q_e": 0.02}),
])
def test_error_controlled_strategies_stay_within_their_tolerance(name, params):
    s = make_strategy(name, **params)
    tol = s.tolerance
    for shape in ("power", "exponential", "two_phase"):
        c, inc = synthetic_smooth_series(shape, n=SMOOTH_N)
        r = replay(make_strategy(name, **params), c, inc)
        assert r.relative_difference <= tol, (shape, r.summary())


def test_constant_error_control_shortens_jumps_where_the_curve_bends():
    c, inc = synthetic_smooth_series("two_phase", n=2000)
    blind = replay(ConstantJump(), c, inc)
    ctrl = replay(ConstantJump(step_control="error"), c, inc)
    assert blind.relative_difference > 0.02  # McColl over-predicts during running-in
    assert ctrl.relative_difference < 0.01 * 0.1 and ctrl.cycles_saved_fraction > 0.8
    # short jumps while the rate still bends, N - 1 (the longest allowed) once it is steady
    assert all(n < 19 for s, n in ctrl.jumps if s < 2 * transition_end())
    assert all(n == 19 for s, n in ctrl.jumps[:-1] if s > 1000)  # the last one is clipped


def test_cojocaru_error_cap_stops_noise_driven_long_jumps():
    """A ratio that is small by chance gives dx = q_e / |r| without bound (section 4.2.2);
    the measured curvature caps it."""
    c, inc = synthetic_smooth_series("power", n=SMOOTH_N, noise=0.02, seed=0)
    seed = replay(CojocaruJump(step_control="seed"), c, inc)
    ctrl = replay(CojocaruJump(), c, inc)
    assert ctrl.max_relative_difference < seed.max_relative_difference / 3
    assert ctrl.relative_difference <= CojocaruJump().tolerance


def test_measured_curvature_ignores_jumped_points():
    # w = n + 1e-3 n^2: measured rates 1 + 1e-3 (2n - 1), kappa = 2e-3 / rate
    s = AdaptiveJump()
    for n in range(0, 41):
        s.observe(n, n + 1e-3 * n * n)
    k = s.measured_curvature(window_fraction=None, both_ends=False)
    assert k == pytest.approx(2e-3 / (1 + 1e-3 * 79))
    s.extrapolate(40 + 1.6, 30)  # a straight extrapolation must not straighten the curve
    assert s.measured_curvature(window_fraction=None, both_ends=False) == k
    assert ConstantJump().measured_curvature() != ConstantJump().measured_curvature()  # nan


def test_adaptive_total_on_a_profile_of_smooth_shapes():
    """decide_on="total" (the fretting loop's setting) on a profile whose elements follow
    different smooth laws."""
    cols = [synthetic_smooth_series(sh, n=SMOOTH_N, noise=0.02, seed=k)[1]
            for k, sh in enumerate(SMOOTH_SHAPES)]
    inc = np.column_stack(cols) * np.array([1.0, 20.0, 0.5, 1.0])
    c = np.arange(1, SMOOTH_N + 1, dtype=float)
    r = replay(AdaptiveJump(decide_on="total"), c, inc)
    assert r.cycles_saved_fraction >= 0.6, r.summary()
    assert r.relative_difference <= 0.05, r.summary()
    total = replay(AdaptiveJump(), c, inc.sum(axis=1))
    assert abs(np.sum(r.final_value) - total.reference_final_value) <= \
        0.05 * total.reference_final_value


def test_strategies_pickle_mid_run_and_continue_identically():
    """A strategy pickled mid-run (state save/restore) continues exactly like the original."""
    import pickle

    c, inc = synthetic_smooth_series("exponential", n=600, noise=0.02, seed=2)
    for name in STRATEGIES:
        a = make_strategy(name)
        a.observe(0, 0.0)
        copies: list = []
        h, i = 0.0, 0
        while i < len(c):
            h += inc[i]
            if i >= 300 and not copies:
                copies.append(pickle.loads(pickle.dumps(a)))
            props = []
            for s in [a, *copies]:
                s.observe(int(c[i]), h)
                props.append(min(s.propose_jump(), len(c) - 1 - i))
            assert len(set(props)) == 1, (name, i, props)
            if props[0]:
                new = [s.extrapolate(h, props[0]) for s in [a, *copies]]
                assert len(set(new)) == 1, (name, i, new)
                h, i = new[0], i + props[0]
            i += 1
        assert copies and copies[0].jumps == a.jumps


def test_step_control_parameters_are_checked():
    for cls in (AdaptiveJump, CojocaruJump, MovingGroupsJump, OverlappingGroupsJump,
                ConstantJump):
        with pytest.raises(ValueError, match="step_control"):
            cls(step_control="ode")
        with pytest.raises(ValueError, match="tol"):
            cls(tol=0.0)
    with pytest.raises(ValueError, match="min_jump"):
        AdaptiveJump(min_jump=0)
    assert AdaptiveJump().tolerance == 0.01 and AdaptiveJump(q_e=0.04).tolerance == 0.02
    assert AdaptiveJump(tol=0.003).tolerance == 0.003
    assert CojocaruJump().tolerance == 0.025 and MovingGroupsJump().tolerance == 0.0005
