"""The fe3d test files' shared case: the seed's crossed R 4 mm cylinders at 100 N on one
ccx thread (``tests/test_fe_backend3d*.py``; not a test module)."""
from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

from tribodem.contact import ElasticBody, HertzSphere, contact_modulus
from tribodem.contact.base import ContactCase
from tribodem.contact.fe.backend3d import FE3DContactSolver
from tribodem.contact.fe.options import FEOptions
from tribodem.contact.geometry import crossed_cylinders
from tribodem.contact.options import PlasticOptions

R = 4e-3
LOAD = 100.0
E_STAR = contact_modulus(ElasticBody(), ElasticBody())
HZ = HertzSphere(R, LOAD, E_STAR)
P0, A = HZ.peak_pressure, HZ.contact_radius
AMPLITUDE = 10e-6  # m: gross slip from about 3.2 um (Mindlin, docs/fe3d.md)
#: Compact bodies for the tests that compare with half-space closed forms at a point or a
#: ring: bodies 4 a deep and wide (the default 8 a, ``fe3d_solver`` 6 a) and a 6 a window
#: (10 a), half the nodes of 6 a at h = a/3 and ccx ~2x faster on SPOOLES (measured,
#: BENCHMARKS.md). The finite bodies' own compliance grows as they shrink: the
#: Cattaneo-Mindlin energy of the fresh cycle measured -1.6 / -2.4 / -3.7 % at 6 / 4 / 3 a
#: (h = a/3), Hertz p0 -1.4 / -0.6 / +0.04 %; so the energy tests keep 6 a where their
#: tolerance is 2 %.
COMPACT: dict[str, float] = dict(size_factor=4.0, window_radii=6.0)

#: the fields of a :class:`ContactCase`
CASE_FIELDS = frozenset(f.name for f in dataclasses.fields(ContactCase))


def fe3d_case(**changes: Any) -> ContactCase:
    """The seed's crossed cylinders (EN24T, mu 0.6, 100 N, the window the backend's) with
    ``changes`` (:class:`ContactCase` fields)."""
    upper, lower = crossed_cylinders()
    case = ContactCase(upper=upper, lower=lower, upper_material=ElasticBody(),
                       lower_material=ElasticBody(), load=LOAD, friction=0.6,
                       amplitude=AMPLITUDE, n_increments=4, n=64, window=None)
    return dataclasses.replace(case, **changes)


def fe3d_solver(workdir: Path | None, **kw: Any) -> FE3DContactSolver:
    """The fe3d backend on :func:`fe3d_case` (h = a/3, bodies 6 a, 1 ccx thread, 600 s) in
    ``workdir``. ``kw``: :class:`ContactCase` fields, ``[fe]`` and ``[plastic]`` fields (the
    option models are built unvalidated, so that the backend's own checks answer a bad
    value) and the constructor's keywords (``window_radii``, ``growth``)."""
    opts: dict[str, Any] = dict(h_over_a=1.0 / 3.0, size_factor=6.0, threads=1, timeout=600)
    opts.update(kw)

    def take(names: Any) -> dict[str, Any]:
        return {k: opts.pop(k) for k in list(opts) if k in names}

    case = fe3d_case(**take(CASE_FIELDS))
    fe = FEOptions.model_construct(**take(FEOptions.model_fields))
    plastic = PlasticOptions.model_construct(**take(PlasticOptions.model_fields))
    return FE3DContactSolver(case, fe, plastic, workdir=workdir, **opts)
