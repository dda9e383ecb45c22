"""Linear contact law (PFC "deformability" style; Sha et al. (2022) table 3).

``kn = A / (r_i/E_i + r_j/E_j)`` -- for equal moduli ``A E / (r_i + r_j)`` -- with
``A = 2 r_min t`` (2D) or ``pi r_min^2`` (3D), computed by the caller as ``lin_k``;
``ks = kn / kratio``; normal and shear dashpots by critical damping ratios beta_n, beta_s.
Time step: stiffness estimate ``sqrt(m/k)``.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from tribodem.dem.laws.table import P_BETAN, P_BETAS, P_KRATIO

NAME = "linear"
TIME_STEP = "stiffness"  # sqrt(m / k) with k = kn, ks (integrate.critical_step)


@njit(cache=True, inline="always")
def normal(prop, delta, vn, rstar, mstar, lin_k):
    """Normal force (N, + = repulsive), tangential stiffness (N/m), tangential damping
    (N s/m), normal stiffness (N/m), stored normal energy (J) at overlap ``delta`` (m) and
    normal approach speed ``vn`` (m/s)."""
    kn = lin_k
    ks = kn / prop[P_KRATIO]
    fn = kn * delta - 2.0 * prop[P_BETAN] * np.sqrt(mstar * kn) * vn
    ct = 2.0 * prop[P_BETAS] * np.sqrt(mstar * ks)
    return fn, ks, ct, kn, 0.5 * kn * delta * delta
