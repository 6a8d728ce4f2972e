"""numba kernels of the NFPT method (``weft.core.nfpt``); its field morph is ``weft.core._kernels.warps``
and its seams ``weft.core._kernels.seams``.

* :func:`l_template` -- the feature-weighted template of one patch's L-shaped neighbourhood (eqs.
  1-3 of Yan, Lee & Lin): writes the weights and weighted pixels into zero-padded FFT buffers.
* :func:`select` -- the cost of every candidate position from the correlation map, and a pick among
  the ``tol`` best valid ones.
* :func:`repair` -- pixel-by-pixel re-synthesis of the mismatched pixels around the seams by
  neighbourhood matching (steps 6 of the paper).

Everything allocates little, releases the GIL (``nogil=True``) and takes its random numbers from the
caller, so a seed gives the same pixels on any thread.
"""

from __future__ import annotations

import numpy as np
from numba import njit

# --------------------------------------------------------------------------------------------
# feature-weighted L-shape template (eqs. 1-3)

_SQRT_2PI = 2.5066282746310002


@njit(cache=True, nogil=True)
def l_template(canvas_y, canvas, y0, x0, bsz, wd, sigma_s, levels, mean, w_buf, tw_buf):
    """Write the weights and weighted pixels of one patch's L-shape; return the constant term.

    ``wd`` (bsz, bsz) float64 holds W_d (eq. 1) on the L-shape and 0 elsewhere, so it also says
    which pixels are in the L. The dominant colour M (eq. 2) is the mean colour of the L pixels in
    the most populated cell of a ``levels``-per-channel colour histogram; the feature strength of a
    pixel is the RMS over channels of P - M (intensities in [0, 1], so the paper's 255 is 1) and
    ``W_s = exp(-(|P - M| - 1)^2 / (2 sigma_s^2)) / (sqrt(2 pi) sigma_s)``. The weight of an L pixel
    is ``w = W_d + W_s`` (eq. 3). ``w_buf`` gets w, ``tw_buf`` gets ``w (Y - mean)`` (Y: the
    canvas luminance), both in their top-left bsz x bsz corner (the rest is left at zero); the
    return value is ``sum w (Y - mean)^2``, so that the weighted SSD of a candidate is
    ``corr(S^2, w) - 2 corr(S, w (Y - mean)) + const`` with S the centred source luminance.
    """
    nc = canvas.shape[2]
    nbins = 1
    for _ in range(nc):
        nbins *= levels
    # np.empty and loops rather than np.zeros/np.full: each of those is one more numba compile
    counts = np.empty(nbins, np.int64)
    sums = np.empty((nbins, nc))
    for k in range(nbins):
        counts[k] = 0
        for c in range(nc):
            sums[k, c] = 0.0
    for by in range(bsz):
        for bx in range(bsz):
            if wd[by, bx] > 0.0:
                k = 0
                for c in range(nc):
                    q = int(canvas[y0 + by, x0 + bx, c] * levels)
                    if q >= levels:
                        q = levels - 1
                    if q < 0:
                        q = 0
                    k = k * levels + q
                counts[k] += 1
                for c in range(nc):
                    sums[k, c] += canvas[y0 + by, x0 + bx, c]
    mode = 0
    for k in range(nbins):
        if counts[k] > counts[mode]:
            mode = k
    m = np.empty(nc)
    for c in range(nc):
        m[c] = sums[mode, c] / counts[mode] if counts[mode] > 0 else 0.0
    norm = 1.0 / (_SQRT_2PI * sigma_s)
    inv2s2 = 1.0 / (2.0 * sigma_s * sigma_s)
    const = 0.0
    for by in range(bsz):
        for bx in range(bsz):
            wv = 0.0
            tv = 0.0
            if wd[by, bx] > 0.0:
                f = 0.0
                for c in range(nc):
                    d = canvas[y0 + by, x0 + bx, c] - m[c]
                    f += d * d
                f = np.sqrt(f / nc)
                ws = norm * np.exp(-(f - 1.0) * (f - 1.0) * inv2s2)
                wv = wd[by, bx] + ws
                yv = canvas_y[y0 + by, x0 + bx] - mean
                tv = wv * yv
                const += wv * yv * yv
            w_buf[by, bx] = wv
            tw_buf[by, bx] = tv
    return const


@njit(cache=True, nogil=True)
def select(cmap, const, valid, tol, u):
    """Flat index (into ``valid``'s (ph, pw)) of the chosen position: uniformly one of the ``tol``
    lowest costs ``cmap[py, px] + const`` among positions with ``valid[py, px] != 0``; -1 if none."""
    ph, pw = valid.shape
    k = max(1, tol)
    best_c = np.empty(k)
    best_i = np.empty(k, np.int64)
    for j in range(k):
        best_c[j] = np.inf
        best_i[j] = -1
    for py in range(ph):
        for px in range(pw):
            if valid[py, px] == 0:
                continue
            c = cmap[py, px] + const
            if c < best_c[k - 1]:
                j = k - 1
                while j > 0 and best_c[j - 1] > c:
                    best_c[j] = best_c[j - 1]
                    best_i[j] = best_i[j - 1]
                    j -= 1
                best_c[j] = c
                best_i[j] = py * pw + px
    n = 0
    for j in range(k):
        if best_i[j] >= 0:
            n += 1
    if n == 0:
        return -1
    pick = int(u * n)
    if pick >= n:
        pick = n - 1
    return best_i[pick]


# --------------------------------------------------------------------------------------------
# repair: pixel-based re-synthesis of the mismatched pixels


@njit(cache=True, nogil=True)
def repair(canvas, pos, todo, tex, allowed, half, shift, order):
    """Re-synthesize the pixels with ``todo == 1`` listed in ``order`` (flat indices), in that order.

    For each, every known neighbour q (``todo != 1``) in the (2 half + 1)^2 window proposes the
    source pixel next to the one q was copied from (``pos[q]`` shifted back by q's offset), the
    pixel's own source too, and every source pixel within ``shift`` pixels (Chebyshev) of those;
    the candidate whose window matches the known pixels best (mean squared colour difference over
    the window pixels that are known and inside the source) is copied and the pixel becomes known
    (``todo = 2``). ``pos`` holds flat source indices ``y * Ws + x`` (-1:
    none); ``allowed`` (Hs, Ws) uint8 says which source pixels may be copied. Returns how many
    pixels were repaired.
    """
    hc, wc, nc = canvas.shape
    hs, ws = tex.shape[0], tex.shape[1]
    side = 2 * half + 1
    cand = np.empty(side * side + 1, np.int64)
    count = 0
    for t in range(order.shape[0]):
        y = order[t] // wc
        x = order[t] % wc
        if todo[y, x] != 1:
            continue
        nc_ = 0
        for dy in range(-half, half + 1):
            qy = y + dy
            if qy < 0 or qy >= hc:
                continue
            for dx in range(-half, half + 1):
                qx = x + dx
                if qx < 0 or qx >= wc:
                    continue
                if (dy != 0 or dx != 0) and todo[qy, qx] == 1:
                    continue
                p = pos[qy, qx]
                if p < 0:
                    continue
                cy = p // ws - dy
                cx = p % ws - dx
                if cy < 0 or cy >= hs or cx < 0 or cx >= ws or allowed[cy, cx] == 0:
                    continue
                c = cy * ws + cx
                dup = False
                for j in range(nc_):
                    if cand[j] == c:
                        dup = True
                        break
                if not dup:
                    cand[nc_] = c
                    nc_ += 1
        best = -1
        best_cost = np.inf
        for jj in range(nc_ * (2 * shift + 1) * (2 * shift + 1)):
            j = jj // ((2 * shift + 1) * (2 * shift + 1))
            r = jj % ((2 * shift + 1) * (2 * shift + 1))
            cy = cand[j] // ws + r // (2 * shift + 1) - shift
            cx = cand[j] % ws + r % (2 * shift + 1) - shift
            if cy < 0 or cy >= hs or cx < 0 or cx >= ws or allowed[cy, cx] == 0:
                continue
            cost = 0.0
            n = 0
            for dy in range(-half, half + 1):
                qy = y + dy
                sy = cy + dy
                if qy < 0 or qy >= hc or sy < 0 or sy >= hs:
                    continue
                for dx in range(-half, half + 1):
                    qx = x + dx
                    sx = cx + dx
                    if qx < 0 or qx >= wc or sx < 0 or sx >= ws:
                        continue
                    if todo[qy, qx] == 1 or (dy == 0 and dx == 0):
                        continue
                    for ch in range(nc):
                        d = canvas[qy, qx, ch] - tex[sy, sx, ch]
                        cost += d * d
                    n += 1
            if n == 0:
                continue
            cost /= n
            if cost < best_cost:
                best_cost = cost
                best = cy * ws + cx
        if best >= 0:
            by = best // ws
            bx = best % ws
            for ch in range(nc):
                canvas[y, x, ch] = tex[by, bx, ch]
            pos[y, x] = best
        todo[y, x] = 2
        count += 1
    return count
