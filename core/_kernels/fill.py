"""numba kernels of the patch-search hole filler (``weft.core.fill.patchmatch``): Wexler, Shechtman &
Irani's multi-scale EM completion with Barnes et al.'s PatchMatch as the nearest-neighbour search.

* :func:`onion_fill` -- the coarsest level's first guess: hole pixels in order of their distance to
  the known region, each the mean of its already filled 8-neighbours.
* :func:`refresh` -- the distance of every target patch to its current match (after a vote changed
  the hole, the stored distances are stale).
* :func:`patchmatch_pass` -- one PatchMatch sweep over the target patches (propagation from the two
  previous neighbours in scan order, then random search around the best match at halving radii);
  even sweeps run forward, odd ones backward.
* :func:`vote` -- each hole pixel becomes the weighted mean of the pixels the overlapping target
  patches' matches put there (Wexler's M step; used to start a finer level from the coarser one's
  matches).
* :func:`vote_offset` -- each hole pixel is copied through the offset most of the overlapping
  target patches' matches agree on (no averaging: keeps the source's grain).

Patches are addressed by their top-left corner; a patch is ``p`` x ``p`` pixels. The distance of a
target patch to a source patch is the sum over its pixels of ``conf * squared colour difference``
(all channels), ``conf`` being 1 on known pixels and decaying into the hole. Random numbers come from
a 64-bit LCG whose state (a 1-element int64 array) the caller seeds, so a seed gives the same pixels
on any thread. Everything releases the GIL (``nogil=True``).
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def _rand(state):
    """The next 31-bit random integer of the LCG whose state is ``state[0]``."""
    s = state[0] * 6364136223846793005 + 1442695040888963407
    state[0] = s
    return (s >> 33) & 0x7FFFFFFF


@njit(cache=True, nogil=True)
def _dist(img, conf, ty, tx, sy, sx, p, limit):
    """Confidence-weighted SSD of the target patch at (ty, tx) to the source patch at (sy, sx); stops
    early (returning a value above ``limit``) once a row pushed the partial sum past ``limit``."""
    nc = img.shape[2]
    d = 0.0
    for i in range(p):
        for j in range(p):
            s = 0.0
            for c in range(nc):
                e = img[ty + i, tx + j, c] - img[sy + i, sx + j, c]
                s += e * e
            d += conf[ty + i, tx + j] * s
        if d > limit:
            return d
    return d


@njit(cache=True, nogil=True)
def onion_fill(img, hole, order_y, order_x):
    """Fill the hole pixels listed in ``order_y``/``order_x`` (nearest to the known region first):
    each becomes the mean of its known or already filled 8-neighbours (left as is when it has
    none). Writes ``img`` in place."""
    h, w, nc = img.shape
    done = np.empty((h, w), np.bool_)
    for y in range(h):
        for x in range(w):
            done[y, x] = not hole[y, x]
    acc = np.empty(nc)
    for k in range(order_y.shape[0]):
        y = order_y[k]
        x = order_x[k]
        n = 0
        for c in range(nc):
            acc[c] = 0.0
        for dy in range(-1, 2):
            for dx in range(-1, 2):
                yy = y + dy
                xx = x + dx
                if 0 <= yy < h and 0 <= xx < w and done[yy, xx]:
                    n += 1
                    for c in range(nc):
                        acc[c] += img[yy, xx, c]
        if n > 0:
            for c in range(nc):
                img[y, x, c] = acc[c] / n
            done[y, x] = True


@njit(cache=True, nogil=True)
def refresh(img, conf, tpos, nnf, dist, p):
    """Recompute ``dist[k]``, the distance of target patch k to its match ``nnf[k]``."""
    for k in range(tpos.shape[0]):
        dist[k] = _dist(img, conf, tpos[k, 0], tpos[k, 1], nnf[k, 0], nnf[k, 1], p, np.inf)


@njit(cache=True, nogil=True)
def patchmatch_pass(img, conf, valid, tpos, tmap, nnf, dist, p, reverse, state, bias):
    """One PatchMatch sweep (Barnes et al. 2009) improving ``nnf``/``dist`` in place.

    ``valid`` (H-p+1, W-p+1) says which top-left corners are allowed sources (the patch lies wholly
    in the source region); ``tmap`` gives the index of the target patch at a corner, or -1. A
    forward sweep propagates from the left and upper neighbours, a backward one (``reverse``) from
    the right and lower ones; then random search samples one candidate in windows of radius
    max(H, W) halving down to 1 around the best match. ``bias`` >= 0 favours coherence: a
    propagated candidate (the neighbour's offset) replaces the current match when its distance is
    below ``(1 + bias)`` times the current one's (0 = plain PatchMatch)."""
    n = tpos.shape[0]
    hv, wv = valid.shape
    step = -1 if reverse else 1
    for q in range(n):
        k = n - 1 - q if reverse else q
        ty = tpos[k, 0]
        tx = tpos[k, 1]
        by = nnf[k, 0]
        bx = nnf[k, 1]
        bd = dist[k]
        # propagation: the neighbour's match, shifted by one
        nx = tx - step
        if 0 <= nx < wv:
            m = tmap[ty, nx]
            if m >= 0:
                cy = nnf[m, 0]
                cx = nnf[m, 1] + step
                if 0 <= cx < wv and valid[cy, cx] and (cy != by or cx != bx):
                    lim = bd * (1.0 + bias)
                    d = _dist(img, conf, ty, tx, cy, cx, p, lim)
                    if d < lim:
                        by = cy
                        bx = cx
                        bd = d
        ny = ty - step
        if 0 <= ny < hv:
            m = tmap[ny, tx]
            if m >= 0:
                cy = nnf[m, 0] + step
                cx = nnf[m, 1]
                if 0 <= cy < hv and valid[cy, cx] and (cy != by or cx != bx):
                    lim = bd * (1.0 + bias)
                    d = _dist(img, conf, ty, tx, cy, cx, p, lim)
                    if d < lim:
                        by = cy
                        bx = cx
                        bd = d
        # random search around the best match, at halving radii
        r = max(hv, wv)
        while r >= 1:
            y0 = max(by - r, 0)
            y1 = min(by + r, hv - 1)
            x0 = max(bx - r, 0)
            x1 = min(bx + r, wv - 1)
            cy = y0 + _rand(state) % (y1 - y0 + 1)
            cx = x0 + _rand(state) % (x1 - x0 + 1)
            if valid[cy, cx] and (cy != by or cx != bx):
                d = _dist(img, conf, ty, tx, cy, cx, p, bd)
                if d < bd:
                    by = cy
                    bx = cx
                    bd = d
            r //= 2
        nnf[k, 0] = by
        nnf[k, 1] = bx
        dist[k] = bd


@njit(cache=True, nogil=True)
def vote(img, hole, tpos, nnf, weight, p):
    """Wexler's M step: every hole pixel of ``img`` becomes the ``weight``-weighted mean of the
    pixels that the matches of the target patches covering it put there."""
    h, w, nc = img.shape
    acc = np.zeros((h, w, nc))
    wacc = np.zeros((h, w))
    for k in range(tpos.shape[0]):
        wk = weight[k]
        ty = tpos[k, 0]
        tx = tpos[k, 1]
        sy = nnf[k, 0]
        sx = nnf[k, 1]
        for i in range(p):
            for j in range(p):
                if hole[ty + i, tx + j]:
                    wacc[ty + i, tx + j] += wk
                    for c in range(nc):
                        acc[ty + i, tx + j, c] += wk * img[sy + i, sx + j, c]
    for y in range(h):
        for x in range(w):
            if hole[y, x] and wacc[y, x] > 0.0:
                for c in range(nc):
                    img[y, x, c] = acc[y, x, c] / wacc[y, x]


@njit(cache=True, nogil=True)
def vote_offset(img, hole, tmap, nnf, weight, p):
    """Every hole pixel of ``img`` is copied through the offset (match minus target corner) that the
    covering target patches agree on most, each counted with its ``weight``: where the matches are
    coherent, whole regions are copied verbatim and the only seams lie between regions."""
    h, w, nc = img.shape
    ht, wt = tmap.shape
    n = p * p
    oy = np.empty(n, np.int64)
    ox = np.empty(n, np.int64)
    ow = np.empty(n)
    for y in range(h):
        for x in range(w):
            if not hole[y, x]:
                continue
            u = 0
            for i in range(p):
                ty = y - i
                if ty < 0 or ty >= ht:
                    continue
                for j in range(p):
                    tx = x - j
                    if tx < 0 or tx >= wt:
                        continue
                    k = tmap[ty, tx]
                    if k < 0:
                        continue
                    dy = nnf[k, 0] - ty
                    dx = nnf[k, 1] - tx
                    found = False
                    for q in range(u):
                        if oy[q] == dy and ox[q] == dx:
                            ow[q] += weight[k]
                            found = True
                            break
                    if not found:
                        oy[u] = dy
                        ox[u] = dx
                        ow[u] = weight[k]
                        u += 1
            if u == 0:
                continue
            b = 0
            for q in range(1, u):
                if ow[q] > ow[b]:
                    b = q
            for c in range(nc):
                img[y, x, c] = img[y + oy[b], x + ox[b], c]
