"""numba kernels of quilting's selection rules (``weft.core.quilting``): the source position of one
block from the SSD map of every position, one kernel per rule so that a run compiles only the one it
uses, and the seam rule's candidates and the error along a cut.

* :func:`choose_best`, :func:`choose_tol`, :func:`choose_epsilon`, :func:`choose_sampled` -- one
  kernel per selection rule.
* :func:`best_k`, :func:`seam_error` -- the seam rule of synthesis: the tol rule's candidates, and
  the error along the cut of each.

No ``np.partition``/``np.argsort`` (seconds each to compile): a hand-written selection instead
(:func:`_kth_smallest`, :func:`_ranked`). Random numbers come from the caller (a uniform ``u`` and a
64-bit seed for the sampled rule, hashed with splitmix64), so a seed gives the same pixels on any
thread. ``weft.core._kernels.quilting`` re-exports every kernel here.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..quilting.codes import SAMPLE_FRACTION, TOP_FRACTION


@njit(cache=True, nogil=True, inline="always")
def _splitmix(state):
    z = state + np.uint64(0x9E3779B97F4A7C15)
    state = z
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    z = z ^ (z >> np.uint64(31))
    return state, z


@njit(cache=True, nogil=True)
def _kth_smallest(cost, k):
    """The k-th smallest value of ``cost`` (1-based), as ``np.partition(cost, k - 1)[k - 1]``.

    For the small k of the tol rule, one pass keeping the k smallest in order, without a copy of
    the whole array. Larger k (tol > 32, rare) select on a copy by three-way quickselect
    (``np.partition`` is slow to compile in numba).
    """
    n = cost.size
    if k <= 32:
        best = np.empty(k)
        for j in range(k):
            best[j] = np.inf
        for i in range(n):
            v = cost[i]
            if v < best[k - 1]:
                j = k - 1
                while j > 0 and best[j - 1] > v:
                    best[j] = best[j - 1]
                    j -= 1
                best[j] = v
        return best[k - 1]
    work = np.empty(n)
    for i in range(n):
        work[i] = cost[i]
    t = k - 1
    lo = 0
    hi = n - 1
    while lo < hi:
        # median of three as the pivot, then [lo, lt) < pivot, [lt, gt] == pivot, (gt, hi] > pivot
        a = work[lo]
        b = work[(lo + hi) // 2]
        c = work[hi]
        pivot = max(min(a, b), min(max(a, b), c))
        lt = lo
        i = lo
        gt = hi
        while i <= gt:
            v = work[i]
            if v < pivot:
                work[i] = work[lt]
                work[lt] = v
                lt += 1
                i += 1
            elif v > pivot:
                work[i] = work[gt]
                work[gt] = v
                gt -= 1
            else:
                i += 1
        if t < lt:
            hi = lt - 1
        elif t > gt:
            lo = gt + 1
        else:
            return pivot
    return work[t]


@njit(cache=True, nogil=True)
def _argmin(cost):
    """The first index of the smallest value (``np.argmin`` without NaN; ``cost`` has none)."""
    best = 0
    for i in range(1, cost.size):
        if cost[i] < cost[best]:
            best = i
    return best


@njit(cache=True, nogil=True)
def _ranked(cost, k, pick):
    """Index of candidate ``pick`` (0-based) in this order: the values below the k-th smallest, in
    index order, then the ties with it, in index order.

    With ``pick == k - 1`` that is the element at ``pick`` of a stable sort (the k-th smallest
    value, the ties with it in index order), so the sampled rule uses it instead of a stable
    ``np.argsort`` (a merge sort, slow to compile).
    """
    n = cost.size
    kth = _kth_smallest(cost, k)
    seen = 0
    below = 0
    for i in range(n):
        if cost[i] < kth:
            below += 1
    if pick < below:
        for i in range(n):
            if cost[i] < kth:
                if seen == pick:
                    return i
                seen += 1
    pick -= below
    seen = 0
    for i in range(n):
        if cost[i] == kth:
            if seen == pick:
                return i
            seen += 1
    return _argmin(cost)


@njit(cache=True, nogil=True)
def _cost_map(cross, sq, const, cost):
    """``cost[py * pw + px] = max(sq - 2 cross + const, 0)`` for the (ph, pw) positions of ``sq``;
    returns the filled prefix of the work buffer ``cost``."""
    ph, pw = sq.shape
    cost = cost[: ph * pw]
    for py in range(ph):
        for px in range(pw):
            v = sq[py, px] - 2.0 * cross[py, px] + const
            cost[py * pw + px] = v if v > 0.0 else 0.0
    return cost


# One kernel per rule, called from Python: a run compiles only the rule it uses (a transfer, tol 1,
# needs none of the selection machinery). Each returns the flat index ``py * pw + px`` of the chosen
# source position; ``cross`` (N, N) is the cross-correlation of the centred source with the block's
# template and ``sq`` (Ph, Pw) the weighted sum of squares of the source under the template's
# weights, so that the SSD of candidate (py, px) is ``sq - 2 cross + const``. ``cost`` is a float64
# work buffer of at least Ph * Pw elements (reused across blocks: a fresh one per block made the heap
# trim and re-fault).


@njit(cache=True, nogil=True)
def choose_best(cross, sq, const, cost):
    """The tol rule with tol 1: the best position (the first one on ties)."""
    return _argmin(_cost_map(cross, sq, const, cost))


@njit(cache=True, nogil=True)
def choose_tol(cross, sq, const, cost, tol, u):
    """The tol rule: one of the ``tol`` best at random (``u`` uniform in [0, 1)): the candidates
    strictly better than the tol-th, then the ties with it, in index order."""
    cost = _cost_map(cross, sq, const, cost)
    k = min(tol, cost.size)
    return _ranked(cost, k, min(int(u * k), k - 1))


@njit(cache=True, nogil=True)
def best_k(cross, sq, const, cost, k, out):
    """The ``k`` best positions (the tol rule's candidates, in its order: those strictly better
    than the k-th, then the ties with it, each in index order) written into ``out``; returns how
    many (``min(k, positions)``). The seam rule of synthesis cuts each of them."""
    cost = _cost_map(cross, sq, const, cost)
    k = min(k, cost.size)
    kth = _kth_smallest(cost, k)
    m = 0
    for i in range(cost.size):
        if cost[i] < kth:
            out[m] = i
            m += 1
    for i in range(cost.size):
        if m >= k:
            break
        if cost[i] == kth:
            out[m] = i
            m += 1
    return m


@njit(cache=True, nogil=True)
def seam_error(err, mask):
    """The error along a block's cut: the sum of ``err`` over the pixels of the new block
    (``mask`` 1) with a 4-neighbour inside the block that keeps the old pixel (``mask`` 0), in
    row-major order."""
    h, w = err.shape
    total = 0.0
    for y in range(h):
        for x in range(w):
            if mask[y, x] and (
                (y > 0 and not mask[y - 1, x])
                or (y < h - 1 and not mask[y + 1, x])
                or (x > 0 and not mask[y, x - 1])
                or (x < w - 1 and not mask[y, x + 1])
            ):
                total += err[y, x]
    return total


@njit(cache=True, nogil=True)
def choose_epsilon(cross, sq, const, cost, eps, u):
    """The epsilon rule: one at random of the positions within ``(1 + eps)`` times the best."""
    cost = _cost_map(cross, sq, const, cost)
    n = cost.size
    m = max(cost[_argmin(cost)], 0.0)
    thr = (1.0 + eps) * m
    count = 0
    for i in range(n):
        if cost[i] <= thr:
            count += 1
    pick = min(int(u * count), count - 1)
    seen = 0
    for i in range(n):
        if cost[i] <= thr:
            if seen == pick:
                return i
            seen += 1
    return _argmin(cost)


@njit(cache=True, nogil=True)
def choose_sampled(cross, sq, const, cost, u, seed):
    """The sampled rule: a random SAMPLE_FRACTION of the positions (splitmix64 of ``seed``), a random
    one (``u``) of their best TOP_FRACTION."""
    cost = _cost_map(cross, sq, const, cost)
    n = cost.size
    state = np.uint64(seed)
    limit = np.uint64(int(SAMPLE_FRACTION * 18446744073709551615.0))
    idx = np.empty(n, dtype=np.int64)
    m = 0
    for i in range(n):
        state, z = _splitmix(state)
        if z < limit:
            idx[m] = i
            m += 1
    if m == 0:
        state, z = _splitmix(state)
        idx[0] = np.int64(z % np.uint64(n))
        m = 1
    vals = np.empty(m)
    for i in range(m):
        vals[i] = cost[idx[i]]
    k = max(1, int(np.ceil(TOP_FRACTION * m)))
    pick = min(int(u * k), k - 1)
    # the element at ``pick`` of a stable sort of vals (as the numpy engine's argsort, kind="stable")
    return idx[_ranked(vals, pick + 1, pick)]
