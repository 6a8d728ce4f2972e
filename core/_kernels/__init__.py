"""numba kernels (njit, cache=True, nogil=True), one module per method."""
