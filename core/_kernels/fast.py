"""numba kernel of Ashikhmin's coherent synthesis / fast texture transfer (``weft.core.fast``).

One call synthesizes a band of rows ``[y0, y1)`` of the result in scan-line order, so the Python
side can report progress and honour cancellation between bands. Everything the kernel needs is an
array argument; it allocates nothing, releases the GIL (``nogil=True``), and its random numbers come
from a xorshift64* state passed in, so a seed gives the same pixels on any thread.

Layout
------
src        (Hs, Ws) float32   source luminance
src_mean   (Hs, Ws) float32   n x n box mean of the source (artistic metric; else any 2-D array)
tgt        (H+2h, W+2h) f32   target luminance padded by h (edge-replicated); unused without target
tgt_mean   (H, W) float32     n x n box mean of the target (artistic metric)
res        (H, W) float32     result luminance (in/out)
pos        (H, W) int32       source position of every result pixel, as y * Ws + x (in/out)
allowed    (K, 2) int32       source positions a random candidate may come from
mask       (Hs, Ws) uint8     1 where a candidate may come from (valid interior & user mask); it
                              must be 0 within h of every border (the kernel relies on it)
res_offs   (k, 2) int32       offsets of the result part: the causal L (first pass) or the whole
                              square without its centre (later passes); also the candidate sources
tgt_offs   (j, 2) int32       offsets of the target part: the complementary half with the centre
"""

from __future__ import annotations

import numpy as np
from numba import njit

METRIC_FULL = 0  # the codes of weft.core.fast.METRICS
METRIC_TARGET = 1
METRIC_ARTISTIC = 2


@njit(cache=True, nogil=True, inline="always")
def _next(state):
    x = state[0]
    x ^= x >> np.uint64(12)
    x ^= x << np.uint64(25)
    x ^= x >> np.uint64(27)
    state[0] = x
    return x * np.uint64(2685821657736338717)


@njit(cache=True, nogil=True, inline="always")
def _uniform(state):
    return (_next(state) >> np.uint64(11)) * (1.0 / 9007199254740992.0)


@njit(cache=True, nogil=True, inline="always")
def _add(cand, nc, c):
    for j in range(nc):
        if cand[j] == c:
            return nc
    cand[nc] = c
    return nc + 1


@njit(cache=True, nogil=True)
def coherent_rows(
    src,
    src_mean,
    tgt,
    tgt_mean,
    res,
    pos,
    allowed,
    mask,
    res_offs,
    tgt_offs,
    y0,
    y1,
    h,
    metric,
    has_target,
    target_weight,
    w,
    p,
    p_l,
    m,
    state,
):
    """Synthesize rows ``y0..y1-1`` (see the module docstring for the arrays)."""
    H, W = res.shape
    Hs, Ws = src.shape
    Wp = tgt.shape[1]
    n_res = res_offs.shape[0]
    n_tgt = tgt_offs.shape[0]
    n_allowed = allowed.shape[0]
    srcf = src.ravel()
    maskf = mask.ravel()
    meanf = src_mean.ravel()
    resf = res.ravel()
    tgtf = tgt.ravel()
    # Flat offsets: neighbour k of pixel i is i + off[k] in each image's own row stride. (Loops, not
    # array expressions: those compile numba's ufunc machinery, a third of this kernel's compile.)
    r_dy = np.empty(n_res, np.int64)
    r_dx = np.empty(n_res, np.int64)
    r_src = np.empty(n_res, np.int64)
    r_res = np.empty(n_res, np.int64)
    for k in range(n_res):
        r_dy[k] = res_offs[k, 0]
        r_dx[k] = res_offs[k, 1]
        r_src[k] = r_dy[k] * Ws + r_dx[k]
        r_res[k] = r_dy[k] * W + r_dx[k]
    t_src = np.empty(n_tgt, np.int64)
    t_tgt = np.empty(n_tgt, np.int64)
    for k in range(n_tgt):
        t_src[k] = tgt_offs[k, 0] * Ws + tgt_offs[k, 1]
        t_tgt[k] = tgt_offs[k, 0] * Wp + tgt_offs[k, 1]
    use_res = metric != METRIC_TARGET
    use_tgt = has_target and metric != METRIC_ARTISTIC and (metric == METRIC_TARGET or target_weight > 0.0)
    t_w = 1.0 if metric == METRIC_TARGET else target_weight
    # one candidate per causal neighbour, plus the random and the location-specific one
    cand = np.empty(n_res + 2, np.int64)
    lo_y, hi_y, lo_x, hi_x = h, Hs - h - 1, h, Ws - h - 1
    for y in range(y0, y1):
        for x in range(W):
            inside = y >= h and y < H - h and x >= h and x < W - h
            # ---- candidates: each neighbour's source position shifted forward by its offset
            nc = 0
            for k in range(n_res):
                qy = y + r_dy[k]
                qx = x + r_dx[k]
                if not inside and (qy < 0 or qy >= H or qx < 0 or qx >= W):
                    continue
                # The neighbour's source position lies in the interior (h from every border), so
                # shifting it by an offset of at most h stays inside the source: no row wrap-around.
                c = pos[qy, qx] - r_src[k]
                if maskf[c] == 0:
                    # Its neighbourhood would leave the source (or the mask): dropped, and a
                    # random position stands in for it (as in Ashikhmin 2001).
                    r = min(int(_uniform(state) * n_allowed), n_allowed - 1)
                    nc = _add(cand, nc, allowed[r, 0] * Ws + allowed[r, 1])
                else:
                    nc = _add(cand, nc, c)
            # ---- extra candidates: random with probability p, location-specific with p_l
            if nc == 0 or (p > 0.0 and _uniform(state) < p):
                r = min(int(_uniform(state) * n_allowed), n_allowed - 1)
                nc = _add(cand, nc, allowed[r, 0] * Ws + allowed[r, 1])
            if p_l > 0.0 and _uniform(state) < p_l:
                cy = min(max(y // m, lo_y), hi_y)
                cx = min(max(x // m, lo_x), hi_x)
                if mask[cy, cx] != 0:
                    nc = _add(cand, nc, cy * Ws + cx)
            # ---- pick the candidate whose neighbourhood matches best
            best_c = cand[0]
            if nc > 1:
                best = np.inf
                i_res = y * W + x
                i_tgt = (y + h) * Wp + (x + h)
                for j in range(nc):
                    c = cand[j]
                    dist = 0.0
                    d_res = 0.0
                    s_res = 0.0
                    cnt = 0
                    if use_res:
                        if inside:
                            for k in range(n_res):
                                d = resf[i_res + r_res[k]] - srcf[c + r_src[k]]
                                d_res += d * d
                                s_res += d
                            cnt = n_res
                        else:
                            for k in range(n_res):
                                qy = y + r_dy[k]
                                qx = x + r_dx[k]
                                if qy < 0 or qy >= H or qx < 0 or qx >= W:
                                    continue
                                d = resf[i_res + r_res[k]] - srcf[c + r_src[k]]
                                d_res += d * d
                                s_res += d
                                cnt += 1
                    if metric == METRIC_ARTISTIC:
                        dm = meanf[c] - tgt_mean[y, x]
                        dist = w * dm * dm
                        if cnt > 0:
                            # high-pass L2: sum((r - mean r) - (s - mean s))^2 = sum d^2 - (sum d)^2 / n
                            dist += (d_res - s_res * s_res / cnt) / (cnt * cnt)
                    else:
                        dist = d_res
                        if use_tgt and dist < best:
                            for k in range(n_tgt):
                                d = tgtf[i_tgt + t_tgt[k]] - srcf[c + t_src[k]]
                                dist += t_w * (d * d)
                                if dist >= best:
                                    break  # cannot win any more
                    if dist < best:
                        best = dist
                        best_c = c
            pos[y, x] = best_c
            res[y, x] = srcf[best_c]
