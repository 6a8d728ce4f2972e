"""numba kernels of image quilting (``weft.core.quilting``).

* :func:`choose_best`, :func:`choose_tol`, :func:`choose_epsilon`, :func:`choose_sampled` -- the
  source position of one block from the SSD map of every position, one kernel per selection rule.
* :func:`best_k`, :func:`seam_error` -- the seam rule of synthesis: the tol rule's candidates, and
  the error along the cut of each.
* :func:`block_error` -- the error surface of one block's overlap, which the engine cuts with
  ``weft.core._kernels.seams.cut_mask``; :func:`place_block` -- paste the block where the cut says.
* :func:`poisson_band` -- Poisson-blend a band around the seam of the block just placed
  (``weft.core._kernels.poisson.poisson_cg``).
* :func:`make_template` -- writes the correlation templates of one block (the overlap, the previous
  iteration and the correspondence terms) into the zero-padded FFT buffers.

Everything is float32 in, float64 inside sums. Random numbers come from the caller (a uniform
``u`` and a 64-bit seed for the sampled rule, hashed with splitmix64), so a seed gives the same
pixels on any thread.

Integer parameters of :func:`place_block` travel in one int64 array (fewer arguments to dispatch
per block; see the ``P_*`` indices in ``weft.core.quilting.codes``).

Compile cost (numba compiles a kernel and everything it calls on first use, when the cache is
cold): the selection rules and the Poisson band are separate kernels so that a run compiles only
what it uses; no ``np.partition``/``np.argsort`` (slow to compile; a hand-written selection
instead); work buffers come from the caller instead of ``np.full``.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..quilting.codes import (  # noqa: F401 (re-exported: the codes of place_block's array)
    MODE_MINCUT,
    MODE_OVERLAP,
    MODE_RANDOM,
    N_IPARAMS,
    P_B,
    P_BAND,
    P_BOTTOM,
    P_LEFT,
    P_MODE,
    P_POISSON,
    P_RIGHT,
    P_SX,
    P_SY,
    P_TOP,
    P_WRAP,
    P_X0,
    P_Y0,
    SAMPLE_FRACTION,
    TOP_FRACTION,
)
from .poisson import poisson_cg

_DY = (1, -1, 0, 0)
_DX = (0, 0, 1, -1)


# --------------------------------------------------------------------------------------------
# one block of quilting


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


@njit(cache=True, nogil=True)
def make_template(
    canvas,
    prev,
    corr_t,
    y0,
    x0,
    bsz,
    top,
    left,
    right,
    bottom,
    wrap,
    w_overlap,
    w_prev,
    w_corr,
    mean,
    mean_c,
    tbuf,
    tcorr,
):
    """Write the correlation templates of the block at (y0, x0) and return the constant term.

    ``tbuf`` (C, N, N) gets ``w_overlap * M * (O - mean) + w_prev * (P - mean)`` in its top-left
    ``bsz x bsz`` corner (M: the overlap strips, O: the canvas, P: ``prev``); ``tcorr`` (N, N) gets
    ``w_corr * (T - mean_c)`` (T: ``corr_t``). The rest of the buffers is left as it is (zero).
    The constant is ``sum w_overlap M |O - mean|^2 + w_prev |P - mean|^2 + w_corr (T - mean_c)^2``,
    so that SSD = sq - 2 cross + const.
    """
    hc, wc, nc = canvas.shape
    const = 0.0
    for by in range(bsz):
        cy = y0 + by
        if wrap:
            cy %= hc
        in_top = by < top or by >= bsz - bottom
        for bx in range(bsz):
            cx = x0 + bx
            if wrap:
                cx %= wc
            m = in_top or bx < left or bx >= bsz - right
            for c in range(nc):
                v = 0.0
                if m and w_overlap != 0.0:
                    o = canvas[cy, cx, c] - mean
                    v += w_overlap * o
                    const += w_overlap * o * o
                if w_prev != 0.0:
                    pv = prev[cy, cx, c] - mean
                    v += w_prev * pv
                    const += w_prev * pv * pv
                tbuf[c, by, bx] = v
            if w_corr != 0.0:
                t = corr_t[cy, cx] - mean_c
                tcorr[by, bx] = w_corr * t
                const += w_corr * t * t
    return const


@njit(cache=True, nogil=True)
def block_error(canvas, filled, tex, iparams, err):
    """The input of the minimum-error cut (``weft.core._kernels.seams.cut_mask``) of one block:
    ``err[by, bx]`` = the squared difference, summed over channels, between the canvas and the
    source block at (P_SY, P_SX) on the block's overlap strips where the canvas is filled, else 0.

    The engine calls ``cut_mask`` itself between this and :func:`place_block`: linked into
    place_block, the cut's code would be optimised and compiled a second time.
    """
    hc, wc, nc = canvas.shape
    y0 = iparams[P_Y0]
    x0 = iparams[P_X0]
    bsz = iparams[P_B]
    top = iparams[P_TOP]
    left = iparams[P_LEFT]
    right = iparams[P_RIGHT]
    bottom = iparams[P_BOTTOM]
    wrap = iparams[P_WRAP] != 0
    sy = iparams[P_SY]
    sx = iparams[P_SX]
    for by in range(bsz):
        for bx in range(bsz):
            err[by, bx] = 0.0
    for by in range(bsz):
        cy = (y0 + by) % hc if wrap else y0 + by
        for bx in range(bsz):
            if by < top or bx < left or bx >= bsz - right or by >= bsz - bottom:
                cx = (x0 + bx) % wc if wrap else x0 + bx
                if filled[cy, cx]:
                    e = 0.0
                    for c in range(nc):
                        d = canvas[cy, cx, c] - tex[sy + by, sx + bx, c]
                        e += d * d
                    err[by, bx] = e


@njit(cache=True, nogil=True)
def place_block(canvas, filled, tex, iparams, mask, win, label, old):
    """Paste one block: the source block at (P_SY, P_SX) onto the canvas at (P_Y0, P_X0).

    ``canvas`` (Hc, Wc, C) float32 and ``filled`` (Hc, Wc) uint8 are updated in place;
    ``iparams``: see ``P_*``. In ``mincut`` mode a block with overlaps pastes only where ``mask``
    (B, B) uint8 is 1 (the cut of :func:`block_error`'s error, made by the caller), any other block
    pastes whole. Work buffers, allocated once per pass: ``win`` (2, S) int64, ``label`` (S, S)
    int8 and ``old`` (S, S, C) float32 get the window of the canvas around the block (S = B + 2
    margin, the margin ``P_BAND + 2`` with ``P_POISSON``, else 0): its rows and columns (-1
    outside), the labels (-1 outside or empty, 0 old pixel, 1 new pixel) and the old pixels (NaN
    where empty), which :func:`poisson_band` reads next when the pass blends its seams.
    """
    hc, wc, nc = canvas.shape
    y0 = iparams[P_Y0]
    x0 = iparams[P_X0]
    bsz = iparams[P_B]
    top = iparams[P_TOP]
    left = iparams[P_LEFT]
    right = iparams[P_RIGHT]
    bottom = iparams[P_BOTTOM]
    wrap = iparams[P_WRAP] != 0
    mode = iparams[P_MODE]
    sy = iparams[P_SY]
    sx = iparams[P_SX]
    cut = mode == MODE_MINCUT and (top > 0 or left > 0 or right > 0 or bottom > 0)

    # paste (keeping a window of the old pixels for the Poisson band)
    poisson = iparams[P_POISSON] != 0 and mode != MODE_RANDOM
    band = iparams[P_BAND]
    margin = band + 2 if poisson else 0
    ws = bsz + 2 * margin
    win_y = win[0]
    win_x = win[1]
    for i in range(ws):
        cy = y0 - margin + i
        cx = x0 - margin + i
        if wrap:
            cy %= hc
            cx %= wc
        win_y[i] = cy if 0 <= cy < hc else -1
        win_x[i] = cx if 0 <= cx < wc else -1
    if poisson:
        # label: -1 outside canvas or empty, 0 old pixel, 1 new pixel (after the paste)
        for wy in range(ws):
            for wx in range(ws):
                label[wy, wx] = -1
                for c in range(nc):
                    old[wy, wx, c] = np.nan
        for wy in range(ws):
            cy = win_y[wy]
            if cy < 0:
                continue
            for wx in range(ws):
                cx = win_x[wx]
                if cx < 0:
                    continue
                if filled[cy, cx]:
                    label[wy, wx] = 0
                    for c in range(nc):
                        old[wy, wx, c] = canvas[cy, cx, c]
    for by in range(bsz):
        cy = win_y[by + margin]
        for bx in range(bsz):
            if not cut or mask[by, bx]:
                cx = win_x[bx + margin]
                for c in range(nc):
                    canvas[cy, cx, c] = tex[sy + by, sx + bx, c]
                filled[cy, cx] = 1
                if poisson:
                    label[by + margin, bx + margin] = 1


@njit(cache=True, nogil=True)
def poisson_band(canvas, old, label, win, band):
    """Blend the seam of the block just placed (``place_block`` with ``P_POISSON``) by a Poisson
    solve over a band: ceil(band/2) pixels on the old side of the seam, floor(band/2) on the new
    side; ``old``, ``label`` and ``win`` as ``place_block`` left them. A separate kernel, so that a
    pass without Poisson blending never compiles it."""
    win_y = win[0]
    win_x = win[1]
    ws = label.shape[0]
    nc = canvas.shape[2]
    big = 1 << 20
    # np.empty and loops rather than np.full/np.zeros (each of those is one more numba compile)
    dist = np.empty((ws, ws), dtype=np.int64)
    index = np.empty((ws, ws), dtype=np.int64)
    for wy in range(ws):
        for wx in range(ws):
            dist[wy, wx] = big
            index[wy, wx] = -1
    # Chebyshev distance of each labelled pixel to the nearest pixel of the other label (<= band)
    for wy in range(ws):
        for wx in range(ws):
            lab = label[wy, wx]
            if lab < 0:
                continue
            for dy in (-1, 0, 1):
                for dx in (-1, 0, 1):
                    qy = wy + dy
                    qx = wx + dx
                    if 0 <= qy < ws and 0 <= qx < ws:
                        ql = label[qy, qx]
                        if ql >= 0 and ql != lab:
                            dist[wy, wx] = 1
    for step in range(2, band + 1):
        for wy in range(ws):
            for wx in range(ws):
                if label[wy, wx] < 0 or dist[wy, wx] <= band:
                    continue
                found = False
                for dy in (-1, 0, 1):
                    for dx in (-1, 0, 1):
                        qy = wy + dy
                        qx = wx + dx
                        if (
                            0 <= qy < ws
                            and 0 <= qx < ws
                            and dist[qy, qx] == step - 1
                            and label[qy, qx] == label[wy, wx]
                        ):
                            found = True
                if found:
                    dist[wy, wx] = step
    old_side = (band + 1) // 2
    new_side = band // 2
    # the unknowns: the band, except next to empty canvas pixels (nothing to meet there yet)
    n = 0
    for wy in range(1, ws - 1):
        for wx in range(1, ws - 1):
            lab = label[wy, wx]
            if lab < 0:
                continue
            d = dist[wy, wx]
            if lab == 0 and d > old_side:
                continue
            if lab == 1 and d > new_side:
                continue
            ok = True
            for k in range(4):
                qy = wy + _DY[k]
                qx = wx + _DX[k]
                if label[qy, qx] < 0 and win_y[qy] >= 0 and win_x[qx] >= 0:
                    ok = False
            if ok:
                index[wy, wx] = n
                n += 1
    if n == 0:
        return
    nbr = np.empty((n, 4), dtype=np.int64)
    ndeg = np.empty(n)
    rhs = np.empty((n, nc))
    x = np.empty((n, nc))
    for i in range(n):
        ndeg[i] = 0.0
        for k in range(4):
            nbr[i, k] = -1
        for c in range(nc):
            rhs[i, c] = 0.0
    for wy in range(1, ws - 1):
        for wx in range(1, ws - 1):
            i = index[wy, wx]
            if i < 0:
                continue
            cy = win_y[wy]
            cx = win_x[wx]
            for c in range(nc):
                x[i, c] = canvas[cy, cx, c]
            for k in range(4):
                qy = wy + _DY[k]
                qx = wx + _DX[k]
                if label[qy, qx] < 0:
                    continue  # outside the canvas: Neumann
                ndeg[i] += 1.0
                j = index[qy, qx]
                qcy = win_y[qy]
                qcx = win_x[qx]
                if label[qy, qx] == label[wy, wx]:
                    # same side of the seam: the gradient of the quilt as pasted
                    for c in range(nc):
                        rhs[i, c] += canvas[cy, cx, c] - canvas[qcy, qcx, c]
                elif _had_old(old, wy, wx) and _had_old(old, qy, qx):
                    # across the seam: the existing pixels' gradient (the write-up's source)
                    for c in range(nc):
                        rhs[i, c] += old[wy, wx, c] - old[qy, qx, c]
                if j >= 0:
                    nbr[i, k] = j
                else:
                    for c in range(nc):
                        rhs[i, c] += canvas[qcy, qcx, c]
    poisson_cg(nbr, ndeg, rhs, x, 1e-6, 500)
    for wy in range(1, ws - 1):
        for wx in range(1, ws - 1):
            i = index[wy, wx]
            if i < 0:
                continue
            for c in range(nc):
                v = x[i, c]
                canvas[win_y[wy], win_x[wx], c] = 0.0 if v < 0.0 else (1.0 if v > 1.0 else v)


@njit(cache=True, nogil=True, inline="always")
def _had_old(old, wy, wx):
    # ``old`` holds NaN in its first channel where the canvas was empty before the paste
    return not np.isnan(old[wy, wx, 0])
