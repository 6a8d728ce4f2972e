"""Indices and codes of the quilting kernel's parameter arrays, in a module without numba.

``core._kernels.quilting`` (numba) and the numpy engine of ``core.quilting.engine`` both read them
from here, so a small synthesis can run without importing numba and the two cannot disagree.
"""

# place_block integer parameters (one int64 array)
P_Y0, P_X0, P_B, P_TOP, P_LEFT, P_RIGHT, P_BOTTOM, P_WRAP = 0, 1, 2, 3, 4, 5, 6, 7
P_MODE, P_RULE, P_TOL, P_SEED, P_POISSON, P_BAND, P_FIX_Y, P_FIX_X = 8, 9, 10, 11, 12, 13, 14, 15
N_IPARAMS = 16
# place_block float parameters (one float64 array)
F_CONST, F_EPS, F_U = 0, 1, 2
N_FPARAMS = 3

MODE_RANDOM, MODE_OVERLAP, MODE_MINCUT = 0, 1, 2
RULE_TOL, RULE_EPSILON, RULE_SAMPLED = 0, 1, 2

SAMPLE_FRACTION = 0.1  # the Poisson write-up: a random 10% of the positions ...
TOP_FRACTION = 0.1  # ... of which the best 10% are candidates
