"""Columns of the pair property table ``pairtab[mat_a, mat_b, :]`` shared by every law."""

P_LAW, P_ESTAR, P_GSTAR, P_MU, P_MUR, P_GAMMA, P_KRATIO, P_BETAN, P_BETAS = range(9)
N_PROPS = 9
