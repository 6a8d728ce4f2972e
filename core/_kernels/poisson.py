"""numba kernel of the Poisson solve shared by ``weft.core.blending.poisson_blend`` and quilting's
Poisson seam band (``weft.core._kernels.quilting``).

* :func:`poisson_cg` -- a conjugate-gradient solve of the discrete Poisson equation on an arbitrary
  set of pixels (matrix-free, 4-neighbours, Dirichlet values from the image, Neumann at invalid
  neighbours).
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def poisson_cg(nbr, ndeg, rhs, x, tol, max_iter):
    """Solve ``A x = rhs`` for the discrete Poisson system of a pixel set, by conjugate gradient.

    ``nbr`` (n, 4) int64 lists each unknown's neighbours that are unknowns too (-1: none);
    ``ndeg`` (n,) the number of valid neighbours (unknown or Dirichlet), so
    ``(A x)_p = ndeg_p x_p - sum_{q in nbr_p} x_q``. ``rhs`` (n, C) holds, per channel, the guidance
    divergence plus the Dirichlet neighbours' values; ``x`` (n, C) is the initial guess and is
    overwritten with the solution. Stops when ``||r|| <= tol * ||rhs||`` or after ``max_iter``
    iterations. Returns the largest iteration count over the channels.
    """
    n, nc = rhs.shape
    r = np.empty(n)
    p = np.empty(n)
    ap = np.empty(n)
    most = 0
    for c in range(nc):
        bnorm = 0.0
        for i in range(n):
            bnorm += rhs[i, c] * rhs[i, c]
        bnorm = np.sqrt(bnorm)
        if bnorm == 0.0:
            bnorm = 1.0
        rr = 0.0
        for i in range(n):
            s = ndeg[i] * x[i, c]
            for k in range(4):
                q = nbr[i, k]
                if q >= 0:
                    s -= x[q, c]
            r[i] = rhs[i, c] - s
            p[i] = r[i]
            rr += r[i] * r[i]
        it = 0
        while it < max_iter and np.sqrt(rr) > tol * bnorm:
            pap = 0.0
            for i in range(n):
                s = ndeg[i] * p[i]
                for k in range(4):
                    q = nbr[i, k]
                    if q >= 0:
                        s -= p[q]
                ap[i] = s
                pap += p[i] * s
            if pap <= 0.0:
                break
            a = rr / pap
            rr_new = 0.0
            for i in range(n):
                x[i, c] += a * p[i]
                r[i] -= a * ap[i]
                rr_new += r[i] * r[i]
            beta = rr_new / rr
            rr = rr_new
            for i in range(n):
                p[i] = r[i] + beta * p[i]
            it += 1
        if it > most:
            most = it
    return most
