"""The benchmark cases beside settle3d: a dense packing (coordination ~6) and a bonded block."""

from __future__ import annotations

import numpy as np

from tribodem.dem.bench import simulation_from_case
from tribodem.dem.bench_cases import bonded3d_case, dense3d_case


def test_dense3d_is_a_stable_coordination_six_packing() -> None:
    case = dense3d_case(n=1000, steps=100)  # 10 x 10 x 10
    assert case.n == 1000 and case.lid
    sim = simulation_from_case(case)
    assert len(sim.walls) == 6
    sim.step(case.steps)
    # interior spheres touch their six lattice neighbours; the surface has fewer
    assert 2.0 * sim.n_contacts() / case.n > 5.0
    assert sim.nl.builds == 1  # held in place: no particle drifts half a skin
    assert all(w.normal_force > 0 for w in sim.walls)  # every wall is pressed


def test_bonded3d_carries_the_platen_load_through_bonds() -> None:
    case = bonded3d_case(n=1000, steps=300)
    sim = simulation_from_case(case)
    bonds = sim.interactions[0]
    assert 2.8 < 2.0 * bonds.i.size / case.n <= 6.0  # lattice neighbours bonded
    z0 = sim.walls[-1].point[2]
    sim.step(case.steps)
    assert sim.walls[-1].point[2] < z0  # the lid moved down
    assert np.isfinite(sim.p.pos).all()
    assert sim.walls[0].normal_force > 0  # the floor feels the compression
