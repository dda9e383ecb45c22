"""Hertz-Mindlin (no slip) contact law, as EDEM and LIGGGHTS (Lu (2018) section 2.3).

``Fn = 4/3 E* sqrt(R*) d^1.5``, ``Sn = 2 E* sqrt(R* d)``, ``St = 8 G* sqrt(R* d)``, dashpots
``gamma sqrt(S m*)`` with gamma from the coefficient of restitution
(``contact.hertz_damping_from_cor``). Time step: the Rayleigh step (Lu (2018) eq 2.17).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from tribodem.dem.laws.table import P_ESTAR, P_GAMMA, P_GSTAR, P_SQ2E, P_SQ8G

NAME = "hertz"
TIME_STEP = "rayleigh"  # eq 2.17 of the smaller particle (integrate.critical_step)


@njit(cache=True, inline="always")
def normal(prop, delta, vn, rstar, mstar, lin_k):
    """Normal force (N, + = repulsive), tangential stiffness (N/m), tangential damping
    (N s/m), normal stiffness (N/m), stored normal energy (J) at overlap ``delta`` (m) and
    normal approach speed ``vn`` (m/s)."""
    estar = prop[P_ESTAR]
    sq = np.sqrt(rstar * delta)  # contact radius a = sqrt(R* d)
    sn = 2.0 * estar * sq
    st = 8.0 * prop[P_GSTAR] * sq
    fe = (4.0 / 3.0) * estar * delta * sq
    gm = prop[P_GAMMA] * np.sqrt(sq * mstar)  # gamma sqrt(S m*) = gm sqrt(S / a)
    fn = fe - gm * prop[P_SQ2E] * vn  # sqrt(2 E*), sqrt(8 G*): from the table
    ct = gm * prop[P_SQ8G]
    return fn, st, ct, sn, 0.4 * fe * delta
