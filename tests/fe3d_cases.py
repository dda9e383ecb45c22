"""The fe3d test files' shared case: the seed's crossed R 4 mm cylinders at 100 N on one
ccx thread (``tests/test_fe_backend3d*.py``; not a test module)."""
from __future__ import annotations

from pathlib import Path

from tribodem.contact import ElasticBody, HertzSphere, contact_modulus
from tribodem.contact.fe.backend3d import FE3DContactSolver

R = 4e-3
LOAD = 100.0
E_STAR = contact_modulus(ElasticBody(), ElasticBody())
HZ = HertzSphere(R, LOAD, E_STAR)
P0, A = HZ.peak_pressure, HZ.contact_radius
AMPLITUDE = 10e-6  # m: gross slip from about 3.2 um (Mindlin, docs/fe3d.md)


def _solver(workdir: Path, **kw: float) -> FE3DContactSolver:
    opts: dict = dict(load=LOAD, n=64, amplitude=AMPLITUDE, n_increments=4,
                      h_over_a=1.0 / 3.0, size_factor=6.0, threads=1, timeout=600,
                      workdir=workdir)
    opts.update(kw)
    return FE3DContactSolver(**opts)
