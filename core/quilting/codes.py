"""Indices and codes of the quilting kernel's parameter array, in a module without numba.

``weft.core._kernels.quilting`` (numba) and the numpy engine of ``weft.core.quilting.engine`` both read them
from here, so a small synthesis can run without importing numba and the two cannot disagree.
(``weft.core._kernels``'s ``__init__`` imports numba for its cache set-up, so the codes do not live
there.)
"""

# place_block integer parameters (one int64 array): the block, its overlaps, the pass's options and
# the chosen source position (P_SY, P_SX)
P_Y0, P_X0, P_B, P_TOP, P_LEFT, P_RIGHT, P_BOTTOM, P_WRAP = 0, 1, 2, 3, 4, 5, 6, 7
P_MODE, P_POISSON, P_BAND, P_SY, P_SX = 8, 9, 10, 11, 12
N_IPARAMS = 13

MODE_RANDOM, MODE_OVERLAP, MODE_MINCUT = 0, 1, 2

SAMPLE_FRACTION = 0.1  # the Poisson write-up: a random 10% of the positions ...
TOP_FRACTION = 0.1  # ... of which the best 10% are candidates
