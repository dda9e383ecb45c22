"""Sampling of the stroke: the worn profile of a gross-slip Archard contact has no
saw-tooth, whatever the step of the stroke is against the grid, and its depth converges as
the stroke is sampled more finely; for a line and a point contact.

The cases, steel on steel, 16 increments a cycle, a step of 1.49 grid spacings (the ratio
at which depositing each increment's wear half a step away from where it was solved grew a
two-point ripple of 27 % (the line on the periodic window) and 17 % (the sphere) of the
scar's depth in 60 cycles, measured): a 6 mm cylinder on a flat at 20 N/mm (Hertz
half-width 36 um, amplitude 34 um, step 8.5 um on a 5.7 um grid), on one plane-strain
cross-section (the default) and on the n x n window periodic along its axis; a 10 mm
sphere on a flat at 20 N (contact radius 109 um, amplitude 102 um, step 25.5 um on a 17 um
grid). Wear coefficients are large (k 2e-13 and 6e-13 1/Pa) so that 60 cycles wear many
elastic approaches deep: the feedback of the worn surface on the pressure is what a
saw-tooth would feed on.
"""

from __future__ import annotations

import numpy as np
import pytest

from tribodem.fretting import FrettingConfig, build_loop

CONTACTS = {
    "line": {"geometry": "cylinder_on_flat", "radius": 6e-3, "load_per_length": 2.0e4,
             "amplitude": 34e-6},
    "line-periodic-2d": {"geometry": "cylinder_on_flat", "radius": 6e-3,
                         "load_per_length": 2.0e4, "amplitude": 34e-6},
    "sphere": {"geometry": "sphere_on_flat", "radius": 10e-3, "load": 20.0,
               "amplitude": 102e-6},
}
CASE = {
    "cycles": 60,
    "contact": {"friction": 0.6, "n_increments": 16, "n": 64},
    "wear": {"criterion": "archard", "archard_k_upper": 2e-13, "archard_k_lower": 6e-13},
    "output": {"vtk": False, "figures": False},
}


def alternating(profile: np.ndarray) -> float:
    """The amplitude of the two-grid-point ripple of ``profile`` (m): the (-1)^i-weighted
    second difference, averaged over 8 points (a pure ripple c (-1)^i gives c; a smooth
    profile ~0), at its largest along the profile."""
    d2 = profile[:-2] - 2 * profile[1:-1] + profile[2:]
    signed = (-1.0) ** np.arange(d2.size) * d2
    return float(np.abs(np.convolve(signed, np.ones(8) / 8, "valid")).max() / 4)


def worn(contact: str, n_increments: int, n: int = 64) -> tuple[np.ndarray, np.ndarray]:
    """(upper, lower) worn profiles along the stroke through the contact's centre, m."""
    data = {**CASE, "contact": {**CASE["contact"], **CONTACTS[contact],
                                "n_increments": n_increments, "n": n}}
    if contact == "line-periodic-2d":  # the n x n window periodic along the axis
        data["elastic"] = {"line_model": "periodic-2d"}
    cfg = FrettingConfig.model_validate(data)
    loop = build_loop(cfg)
    hist = loop.run(cfg.cycles)
    j = hist.grid.ny // 2  # the central section (the only one of a line on one section)
    return hist.wear_upper[:, j], hist.wear_lower[:, j]


@pytest.fixture(scope="module", params=sorted(CONTACTS))
def coarse(request: pytest.FixtureRequest) -> tuple[str, tuple[np.ndarray, np.ndarray]]:
    return request.param, worn(request.param, 16)


def test_no_saw_tooth_on_either_body(coarse: tuple[str, tuple[np.ndarray, np.ndarray]]
                                     ) -> None:
    for profile in coarse[1]:
        depth = profile.max()
        assert depth > 0
        assert alternating(profile) < 0.01 * depth


def test_depth_converges_with_the_stroke_sampling(
        coarse: tuple[str, tuple[np.ndarray, np.ndarray]]) -> None:
    """Twice the increments (a step of 0.74 grid spacings) change the maximum depth of
    each body by < 2 % (measured, upper / lower: line 0.06 / 0.17 %, line on the periodic
    window 0.01 / 0.11 %, sphere 0.15 / 0.08 %; the two-point ripple 0.17-0.40 % of the
    depth; the first cycles, up to 0.16 elastic approaches each, split in sub-cycles)."""
    contact, profiles = coarse
    fine = worn(contact, 32)
    for a, b in zip(profiles, fine, strict=True):
        assert abs(a.max() / b.max() - 1) < 0.02
        assert alternating(b) < 0.01 * b.max()
