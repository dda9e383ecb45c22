"""3D crossed-cylinder model on CalculiX against Hertz (Johnson eqs 4.22-4.23).

A coarse quarter model (h = a/4, bodies 6 a): peak pressure and contact radius within 2 %,
the contact force equal to the load. The half model with friction (Mindlin, gross slip) is in
``tribodem validate --solver fe`` (minutes of ccx), not here.
"""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pytest

from tribodem.contact.fe.crossed import CrossedCase, crossed_mesh, run_crossed

pytestmark = pytest.mark.skipif(shutil.which("ccx") is None, reason="needs CalculiX ccx")


def test_mesh_columns_and_surfaces() -> None:
    """Straight vertical node columns under the contact (seed fig 3.4); the contact rows lie
    on the cylinders: upper z = R - sqrt(R^2 - x^2), lower z = -(R - sqrt(R^2 - y^2))."""
    case = CrossedCase(size_factor=6, growth=1.4)
    m = crossed_mesh(case)
    R = case.radius
    up = m.nodes[m.node_sets["UBOT"] - 1]
    lo = m.nodes[m.node_sets["LTOP"] - 1]
    assert np.allclose(up[:, 2], R - np.sqrt(R * R - up[:, 0] ** 2), atol=1e-15)
    assert np.allclose(lo[:, 2], -(R - np.sqrt(R * R - lo[:, 1] ** 2)), atol=1e-15)
    # every column of the upper body keeps its (x, y) from bottom to top
    n_layer = m.node_sets["UBOT"].size
    upper = m.nodes[m.node_sets["UBOT"][0] - 1:].reshape(-1, n_layer, 3)
    assert np.ptp(upper[:, :, :2], axis=0).max() == 0.0


def test_crossed_cylinders_hertz(tmp_path: Path) -> None:
    case = CrossedCase(size_factor=6, growth=1.4)
    p0, a = case.hertz
    case = CrossedCase(h_fine=a / 4, size_factor=6, growth=1.4)
    run = run_crossed(case, tmp_path / "crossed", threads=1, timeout=600)
    st = run.loaded
    p_fe, a_fe = st.hertz_fit()
    assert math.isclose(st.normal_force, case.load, rel_tol=1e-4)
    assert abs(p_fe / p0 - 1) < 0.02, (p_fe, p0)
    assert abs(a_fe / a - 1) < 0.02, (a_fe, a)
    # the recovered pressure integrates to the quarter's load (tributary areas)
    assert math.isclose(float((st.pressure * st.area).sum()), case.load / 4, rel_tol=1e-3)
    assert (tmp_path / "crossed" / "mesh.vtu").is_file()
