"""Disks (dim 2) run planar builds of the serial kernels (``pair_forces_sum_2d``,
``bond_forces_2d``): they must give the general kernels' values step after step."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from tribodem.dem import Box, Material, ParticleState, PlaneWall, Simulation, engine
from tribodem.dem import bonds as bonds_module
from tribodem.dem.bonds import bond_forces, install_bonds_by_gap
from tribodem.dem.contact import pair_forces_sum

R = 1.0e-3


class _General:
    """Stands in for ``bond_forces_2d``: runs the general ``bond_forces`` (dim 2)."""

    def pick(self, size: int, threads: int | None = None) -> Callable[..., int]:
        build = bond_forces.pick(size, threads)

        def run(*a: Any) -> int:
            nb = a[4].shape[0]
            # (the general kernel has no strength screen: the 2D kernel's last argument)
            return build(*a[:9], np.zeros(nb), *a[9:17], np.zeros(nb), *a[17:24], 2,
                         *a[24:30])
        return run


def packing(law: str, bonded: bool) -> Simulation:
    """A random, compressed bed of disks in a box periodic in x (friction, rolling
    friction, damping: every branch of the contact response), optionally bonded."""
    rng = np.random.default_rng(11)
    nx, ny = 16, 12
    x, y = np.meshgrid(np.arange(nx) * 1.98 * R, np.arange(ny) * 1.98 * R)
    pos = np.c_[x.ravel() + R, y.ravel() + R, np.zeros(nx * ny)]
    pos[:, :2] += rng.uniform(-0.05, 0.05, (nx * ny, 2)) * R
    radius = rng.uniform(0.99, 1.04, nx * ny) * R
    vel = np.c_[rng.normal(0, 0.05, (nx * ny, 2)), np.zeros(nx * ny)]
    omega = np.c_[np.zeros((nx * ny, 2)), rng.normal(0, 50.0, nx * ny)]
    p = ParticleState(dim=2, pos=pos, radius=radius, density=2500.0, thickness=2 * R,
                      vel=vel, omega=omega)
    mat = Material(law=law, young=1e9, poisson=0.3, density=2500.0, friction=0.3,
                   rolling_friction=0.05, cor=0.6, beta_n=0.2, beta_s=0.1)
    floor = PlaneWall([0, 0, 0], [0, 1, 0], name="floor")
    box = Box([0, -0.01, 0], [nx * 1.98 * R, 0.05, 0], [True, False, False])
    sim = Simulation(p, [mat], box, walls=[floor], gravity=(0, -9.81e3, 0))
    if bonded:
        install_bonds_by_gap(sim, 0.2 * R, 0.8, 1e9, 2.0, 2e6, 4e6)
    return sim


@pytest.mark.parametrize(("law", "bonded"), [("hertz", False), ("linear", True)])
def test_planar_kernels_give_the_general_values(law: str, bonded: bool,
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    planar = packing(law, bonded)
    planar.step(400)
    with monkeypatch.context() as m:  # the general pair kernel on the same disks
        m.setattr(engine, "pair_forces_sum_2d", pair_forces_sum)
        general = packing(law, bonded)
        general.compiled_loop = False  # the Python loop calls the patched kernels
        m.setattr(bonds_module, "bond_forces_2d", _General())
        general.step(400)
    assert planar.n_contacts() > 100
    for name in ("pos", "vel", "omega"):
        assert np.array_equal(getattr(planar.p, name), getattr(general.p, name)), name
    assert np.array_equal(planar.hist, general.hist)
    assert np.array_equal(planar.pinfo, general.pinfo)
    if bonded:
        a, b = planar.interactions[0], general.interactions[0]
        assert 0 < a.broken_count() == b.broken_count() < a.n_bonds
        for name in ("fn", "fs", "mb", "normal", "mode"):
            assert np.array_equal(getattr(a, name), getattr(b, name)), name


def test_cross_group_force_equals_the_contacts_sum() -> None:
    """``cross_group_force`` = the pushing contacts between groups, summed as numpy does."""
    sim = packing("hertz", False)
    sim.p.group[:] = (sim.p.pos[:, 0] > np.median(sim.p.pos[:, 0])).astype(np.int32)
    for steps in (0, 50):
        sim.step(steps)
        c = sim.contacts()
        g = sim.p.group
        f = c["normal_force"]
        want = float(f[(g[c["i"]] != g[c["j"]]) & (f > 0)].sum())
        assert want > 0.0 or steps == 0  # before the first step: no forces yet
        assert sim.cross_group_force() == want
