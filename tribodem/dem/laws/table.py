"""Columns of the pair property table ``pairtab[mat_a, mat_b, :]`` shared by every law.

``P_SQ2E`` = sqrt(2 E*) and ``P_SQ8G`` = sqrt(8 G*) (sqrt(Pa)) are derived once per pair of
materials so the Hertz law takes no square root of a constant per contact.
"""

(P_LAW, P_ESTAR, P_GSTAR, P_MU, P_MUR, P_GAMMA, P_KRATIO, P_BETAN, P_BETAS, P_SQ2E,
 P_SQ8G) = range(11)
N_PROPS = 11
