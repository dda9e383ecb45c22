"""The volume-conserving slope limit on node-column worn depths (contact.fe.slope)."""
from __future__ import annotations

import numpy as np
import pytest

from tribodem.contact.fe.crossed import tributary_area
from tribodem.contact.fe.slope import TOLERANCE, limit_slope, steepest


def _graded(n: int, h: float, growth: float) -> np.ndarray:
    """A grid from 0: n cells of h, then cells growing by ``growth`` (as the fe3d mesh)."""
    steps = [h] * n + [h * growth ** k for k in range(1, 6)]
    return np.concatenate([[0.0], np.cumsum(steps)])


def _grid(nx: int = 24, ny: int = 12, h: float = 44e-6):
    xs, ys = _graded(nx, h, 1.4), _graded(ny, h, 1.4)
    return xs, ys, tributary_area(*np.meshgrid(xs, ys), xs, ys)


def _steepest(w: np.ndarray, xs: np.ndarray, ys: np.ndarray) -> float:
    return max(float((np.abs(np.diff(w, axis=1)) / np.diff(xs)).max()),
               float((np.abs(np.diff(w, axis=0)) / np.diff(ys)[:, None]).max()))


def test_two_columns_meet_the_closed_form() -> None:
    """Two columns, areas A1, A2, depths D and 0, spacing d: the limit leaves w1 - w2 = s d
    and w1 A1 + w2 A2 = D A1, so w2 = (D - s d) A1 / (A1 + A2); within the tolerance."""
    xs, ys = np.array([0.0, 40e-6]), np.array([0.0])
    area = np.array([[3e-9, 1e-9]])
    depth, s = 10e-6, 0.1
    w, lim = limit_slope(np.array([[depth, 0.0]]), xs, ys, area, s)
    d = xs[1]
    w2 = (depth - s * d) * area[0, 0] / area.sum()
    assert lim.converged
    assert w[0, 1] == pytest.approx(w2, abs=TOLERANCE * s * d)
    assert w[0, 0] - w[0, 1] == pytest.approx(s * d, rel=TOLERANCE)
    assert float((w * area).sum()) == pytest.approx(depth * area[0, 0], rel=1e-12)
    assert lim.steepest_before == pytest.approx(depth / d, rel=1e-12)
    # the volume carried: from the deep column to the shallow one
    assert lim.moved_volume == pytest.approx(w2 * area[0, 1], rel=1e-9)


def test_pits_keep_their_volume_and_the_limit_holds() -> None:
    """Random pits 0-20 um deep on a graded 44-um grid (the seed's shear scar steps up to 10
    um between columns): the worn volume to 1e-12, every x and y step <= s (1 + tol), the
    depths within their old range."""
    xs, ys, area = _grid()
    rng = np.random.default_rng(3)
    x, y = np.meshgrid(xs, ys)
    w0 = 20e-6 * rng.random(x.shape) * ((x - 0.5e-3) ** 2 + y ** 2 < 0.35e-3 ** 2)
    assert steepest(w0, xs, ys) == pytest.approx(_steepest(w0, xs, ys), rel=1e-12)
    for s in (0.2, 0.05):
        w, lim = limit_slope(w0, xs, ys, area, s)
        assert lim.converged and lim.steepest_before > 0.4
        assert float((w * area).sum()) == pytest.approx(float((w0 * area).sum()), rel=1e-12)
        assert _steepest(w, xs, ys) <= s * (1.0 + TOLERANCE)
        assert lim.steepest_after == pytest.approx(_steepest(w, xs, ys), rel=1e-12)
        assert w.min() >= 0.0 and w.max() <= w0.max()
        assert lim.moved_volume > 0.0


def test_a_surface_within_the_limit_is_left_alone() -> None:
    xs, ys, area = _grid()
    x, y = np.meshgrid(xs, ys)
    w0 = 5e-6 * np.exp(-((x - 0.4e-3) ** 2 + y ** 2) / (0.2e-3) ** 2)  # slope <= 0.02
    w, lim = limit_slope(w0, xs, ys, area, 0.05)
    np.testing.assert_array_equal(w, w0)
    assert lim.sweeps == 0 and lim.moved_volume == 0.0 and lim.converged


def test_a_symmetric_pit_stays_symmetric() -> None:
    """Jacobi updates: a pit symmetric about the grid's middle column stays so (to rounding)."""
    xs = np.arange(41) * 44e-6
    ys = np.arange(15) * 44e-6
    area = tributary_area(*np.meshgrid(xs, ys), xs, ys)
    x, y = np.meshgrid(xs, ys)
    w0 = 12e-6 * (np.abs(x - xs[20]) < 200e-6) * (y < 150e-6)
    w, _ = limit_slope(w0, xs, ys, area, 0.08)
    np.testing.assert_allclose(w, w[:, ::-1], rtol=0, atol=1e-9 * w0.max())


@pytest.mark.parametrize("slope", [0.0, -0.1, float("nan")])
def test_a_bad_slope_is_refused(slope: float) -> None:
    xs, ys, area = _grid(4, 3)
    with pytest.raises(ValueError, match="slope"):
        limit_slope(np.zeros(area.shape), xs, ys, area, slope)
