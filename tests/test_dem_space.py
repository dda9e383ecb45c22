"""``column_order``: a permutation that numbers particles column by column, so that
particles within a column width of each other get nearby indices."""

from __future__ import annotations

import numpy as np

from tribodem.dem.space import column_order


def test_column_order_is_a_permutation_that_keeps_neighbours_close() -> None:
    """A random strip 50 columns wide and 10 high (2,000 points): the order is a
    permutation; columns come in increasing x and y increases within a column; every
    pair closer than one column width is at most three columns' count apart in the new
    numbering (the invariant the pair and bond passes rely on), where a random numbering
    puts a typical pair ~n/3 apart."""
    rng = np.random.default_rng(3)
    n, cell = 2000, 1.0
    pos = np.c_[rng.uniform(0, 50 * cell, n), rng.uniform(0, 10 * cell, n), np.zeros(n)]
    order = column_order(pos, 0.0, cell)
    assert np.array_equal(np.sort(order), np.arange(n))
    p = pos[order]
    col = np.floor(p[:, 0] / cell)
    assert np.all(np.diff(col) >= 0)
    same = np.diff(col) == 0
    assert np.all(np.diff(p[:, 1])[same] >= 0)
    d = np.linalg.norm(p[:, None, :2] - p[None, :, :2], axis=2)
    i, j = np.nonzero(np.triu(d < cell, 1))
    per_col = n / 50
    assert i.size > 1000 and np.abs(i - j).max() <= 3 * per_col * 1.5
    d0 = np.linalg.norm(pos[:, None, :2] - pos[None, :, :2], axis=2)
    i0, j0 = np.nonzero(np.triu(d0 < cell, 1))
    assert np.median(np.abs(i0 - j0)) > 10 * np.median(np.abs(i - j))
