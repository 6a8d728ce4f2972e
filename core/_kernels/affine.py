"""numba kernels of the affine prototype model (``weft.core.affine``, Smith & Bhalerao).

Every kernel takes all its arrays as arguments, allocates at most small per-call buffers, and
releases the GIL (``nogil=True``), so two jobs use two cores. Coordinates are ``(y, x)`` row-major
throughout; a 2x2 matrix ``M`` maps an offset ``(dy, dx)`` in a target patch to an offset in the
prototype (the *sampling* matrix ``M = T^-1`` of the paper's eq. 1 and 22).

Layout
------
proto      (Sp, Sp) or (Sp, Sp, C) f32   the prototype patch (S x S) padded by mirroring
                                         (reflect-101) on every side (``weft.core.affine`` pads by S);
                                         sampled bilinearly, coordinates clamped to the padded
                                         array (so no branch in the inner loops)
cy, cx     float                         the prototype's centre in the padded array
mats       (n, 2, 2) float64             sampling matrices
shifts     (n, 2) int64                  translations ``t`` in target pixels: the patch shows the
                                         warped prototype moved by ``t`` (``p_t(y) = P(y - t)``)
window     (B, B) float32                the cos^2 window of §3.1 (sums to one at a B/2 step)
origins    (K, 2) int64                  top-left corner of every patch in the padded canvas
frames     (K, L, L) float32             warped prototypes on a frame of side L = B + 2R around each
                                         patch (R = B/4), so a shift ``|t| <= R`` is a slice:
                                         ``p_t[a, b] = frame[R + a - ty, R + b - tx]``
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .affine_refine import lk_systems  # noqa: F401 (re-exported: the analysis calls it through this module)


@njit(cache=True, nogil=True, inline="always", fastmath=True)
def _sample(img, y, x, hm, wm):
    """Bilinear sample of a padded 2-D array (see ``pad``): coordinates are clamped, no branches."""
    y = min(max(y, 0.0), hm)
    x = min(max(x, 0.0), wm)
    y0 = int(y)
    x0 = int(x)
    ay = y - y0
    ax = x - x0
    a = img[y0, x0]
    r0 = a + ax * (img[y0, x0 + 1] - a)
    c = img[y0 + 1, x0]
    r1 = c + ax * (img[y0 + 1, x0 + 1] - c)
    return r0 + ay * (r1 - r0)


@njit(cache=True, nogil=True, fastmath=True)
def warp_frames(pimg, cy, cx, mats, out):
    """``out[k]`` = the prototype sampled through ``mats[k]`` on an L x L frame centred on the
    prototype's centre (frame centre ``(L - 1) / 2``); unwindowed, no translation (§2.3).
    ``pimg`` is the padded prototype and (cy, cx) its centre in ``pimg``."""
    n, L = out.shape[0], out.shape[1]
    half = (L - 1) * 0.5
    hm = pimg.shape[0] - 1.0001
    wm = pimg.shape[1] - 1.0001
    for k in range(n):
        m00 = mats[k, 0, 0]
        m01 = mats[k, 0, 1]
        m10 = mats[k, 1, 0]
        m11 = mats[k, 1, 1]
        for u in range(L):
            dy = u - half
            by = cy + m00 * dy
            bx = cx + m10 * dy
            for v in range(L):
                dx = v - half
                out[k, u, v] = _sample(pimg, by + m01 * dx, bx + m11 * dx, hm, wm)


@njit(cache=True, nogil=True, inline="always")
def _target_energy(weights, target):
    """``||W t||²`` of one windowed target patch and how many of its pixels are inside the image."""
    et = 0.0
    count = 0
    B = target.shape[0]
    for a in range(B):
        for b in range(B):
            v = weights[a, b] * target[a, b]
            et += v * v
            if weights[a, b] > 0.0:
                count += 1
    return et, count


@njit(cache=True, nogil=True, inline="always")
def _normalised_error(et, ep, cross, count):
    """§3.2's intensity factor ``alpha = ||W t|| / ||W p'||`` and the RMS error of ``alpha p'`` against
    ``t`` over ``count`` pixels, from ``ep = ||W p'||²`` and ``cross = <W p', W t>``:
    ``sum (alpha p - t)² = alpha² ep - 2 alpha cross + et``."""
    al = math.sqrt(et / ep) if ep > 1e-20 else 0.0
    e2 = al * al * ep - 2.0 * al * cross + et
    return al, math.sqrt(max(e2, 0.0) / max(count, 1))


@njit(cache=True, nogil=True)
def score_frames(frames, index, flip, shifts, R, targets, weights, alpha, err):
    """§2.4 from warped frames (no resampling): candidate j of patch i is frame ``index[i, j]``
    (turned by 180° where ``flip[i, j]``) moved by ``shifts[i, j]``, windowed by ``weights[i]``,
    normalised by ``alpha = ||W t|| / ||W p'||`` (§3.2); ``err`` is its RMS error against the
    target over the patch's pixels inside the image."""
    n, J = index.shape[0], index.shape[1]
    L = frames.shape[1]
    B = targets.shape[1]
    for i in range(n):
        et, count = _target_energy(weights[i], targets[i])
        for j in range(J):
            ty = shifts[i, j, 0]
            tx = shifts[i, j, 1]
            f = index[i, j]
            ep = 0.0
            cross = 0.0
            for a in range(B):
                u = R + a - ty
                for b in range(B):
                    wgt = weights[i, a, b]
                    v = R + b - tx
                    if flip[i, j]:
                        p = frames[f, L - 1 - u, L - 1 - v]
                    else:
                        p = frames[f, u, v]
                    p *= wgt
                    ep += p * p
                    cross += p * wgt * targets[i, a, b]
            alpha[i, j], err[i, j] = _normalised_error(et, ep, cross, count)


@njit(cache=True, nogil=True)
def score_candidates(proto, cy, cx, mats, shifts, targets, weights, alpha, err):
    """§2.4 for every patch i and candidate j: the prototype warped by ``mats[i, j]`` and moved by
    ``shifts[i, j]``, windowed by ``weights[i]`` (the cos² window, zero outside the image),
    intensity-normalised by ``alpha = ||W t|| / ||W p'||`` (§3.2), and its RMS error against the
    windowed target patch ``targets[i]`` (over the patch's pixels inside the image)."""
    n, J = mats.shape[0], mats.shape[1]
    B = targets.shape[1]
    half = (B - 1) * 0.5
    hm = proto.shape[0] - 1.0001
    wm = proto.shape[1] - 1.0001
    for i in range(n):
        et, count = _target_energy(weights[i], targets[i])
        for j in range(J):
            m00 = mats[i, j, 0, 0]
            m01 = mats[i, j, 0, 1]
            m10 = mats[i, j, 1, 0]
            m11 = mats[i, j, 1, 1]
            ty = shifts[i, j, 0]
            tx = shifts[i, j, 1]
            ep = 0.0
            cross = 0.0
            for a in range(B):
                dy = a - half - ty
                by = cy + m00 * dy
                bx = cx + m10 * dy
                for b in range(B):
                    dx = b - half - tx
                    wgt = weights[i, a, b]
                    if wgt == 0.0:
                        continue
                    p = wgt * _sample(proto, by + m01 * dx, bx + m11 * dx, hm, wm)
                    ep += p * p
                    cross += p * wgt * targets[i, a, b]
            alpha[i, j], err[i, j] = _normalised_error(et, ep, cross, count)


@njit(cache=True, nogil=True)
def render(proto, cy, cx, mats, shifts, alpha, origins, window, index, out):
    """Add ``alpha_k * W * p_k`` of the patches ``index`` into ``out`` (Hp, Wp, C) (§3);
    ``proto`` is the padded prototype (Sp, Sp, C) and (cy, cx) its centre there."""
    B = window.shape[0]
    C = proto.shape[2]
    half = (B - 1) * 0.5
    hm = proto.shape[0] - 1.0001
    wm = proto.shape[1] - 1.0001
    for ii in range(index.shape[0]):
        k = index[ii]
        m00 = mats[k, 0, 0]
        m01 = mats[k, 0, 1]
        m10 = mats[k, 1, 0]
        m11 = mats[k, 1, 1]
        ty = shifts[k, 0]
        tx = shifts[k, 1]
        al = alpha[k]
        oy = origins[k, 0]
        ox = origins[k, 1]
        for a in range(B):
            dy = a - half - ty
            by = cy + m00 * dy
            bx = cx + m10 * dy
            for b in range(B):
                wgt = al * window[a, b]
                dx = b - half - tx
                y = min(max(by + m01 * dx, 0.0), hm)
                x = min(max(bx + m11 * dx, 0.0), wm)
                y0 = int(y)
                x0 = int(x)
                ay = y - y0
                ax = x - x0
                w00 = wgt * (1.0 - ay) * (1.0 - ax)
                w01 = wgt * (1.0 - ay) * ax
                w10 = wgt * ay * (1.0 - ax)
                w11 = wgt * ay * ax
                for c in range(C):
                    out[oy + a, ox + b, c] += (
                        w00 * proto[y0, x0, c]
                        + w01 * proto[y0, x0 + 1, c]
                        + w10 * proto[y0 + 1, x0, c]
                        + w11 * proto[y0 + 1, x0 + 1, c]
                    )


@njit(cache=True, nogil=True)
def accumulate(frames, window, origins, shifts, R, acc, acc2, wacc):
    """Fill the boundary-matching canvases from scratch: ``acc = sum W p``, ``acc2 = sum W p^2``,
    ``wacc = sum W`` over all patches (float64, (Hp, Wp))."""
    K = frames.shape[0]
    B = window.shape[0]
    acc[:, :] = 0.0
    acc2[:, :] = 0.0
    wacc[:, :] = 0.0
    for k in range(K):
        oy = origins[k, 0]
        ox = origins[k, 1]
        fy = R - shifts[k, 0]
        fx = R - shifts[k, 1]
        for a in range(B):
            for b in range(B):
                w = window[a, b]
                p = frames[k, fy + a, fx + b]
                acc[oy + a, ox + b] += w * p
                acc2[oy + a, ox + b] += w * p * p
                wacc[oy + a, ox + b] += w


@njit(cache=True, nogil=True)
def boundary_pass(
    frames, window, origins, mask, acc, acc2, wacc, placed, shifts, order, radius, R, cols, clock, moved_at, seen_at
):
    """One pass of boundary matching (§4): visit the patches in ``order``; for each, choose the
    translation within ``radius`` of its current one (and within ``|t| <= R``) that minimises its
    boundary error against the patches already on the canvas, then put it (back) on the canvas.

    The boundary error of patch k at translation t is the window-weighted squared difference to
    every overlapping placed patch b, ``sum_y mask W_k W_b (p_k,t - p_b)^2``, which expands to
    ``sum_y mask W_k (wother p_t^2 - 2 other p_t) + const`` with ``other = sum_b W_b p_b`` and
    ``wother = sum_b W_b`` (the canvases without patch k). Ties keep the current translation, so a
    pass never increases the total boundary error. ``placed[k]`` says whether patch k is on the
    canvases already (raster partial matching starts with none; the shaker box with all).

    Skipping (exact): ``clock[0]`` counts moves; ``moved_at[k]`` is the clock of patch k's last
    move and ``seen_at[k]`` of its last evaluation. A placed patch which neither moved itself nor
    had any of its eight grid neighbours (``cols`` per row) move since it was last evaluated is
    still at its optimum -- the canvases it sees are unchanged and the search window, centred on
    it, only shrinks -- so it is not evaluated again. (A patch that moved is evaluated again: its
    window is centred on the new translation.) Pass ``seen_at`` filled with -1 to evaluate everything.

    Returns the number of patches whose translation changed.
    """
    B = window.shape[0]
    K = frames.shape[0]
    rows = K // cols
    changed = 0
    f1 = np.empty((B, B), np.float64)
    f2 = np.empty((B, B), np.float64)
    for ii in range(order.shape[0]):
        k = order[ii]
        if placed[k] and seen_at[k] >= 0:
            r0 = k // cols
            c0 = k - r0 * cols
            fresh = True
            for dr in range(-1, 2):
                for dc in range(-1, 2):
                    rr = r0 + dr
                    cc = c0 + dc
                    if rr >= 0 and rr < rows and cc >= 0 and cc < cols:
                        if moved_at[rr * cols + cc] > seen_at[k]:
                            fresh = False
            if fresh:
                continue
        seen_at[k] = clock[0]
        oy = origins[k, 0]
        ox = origins[k, 1]
        cy = shifts[k, 0]
        cx = shifts[k, 1]
        was = placed[k]
        any_other = False
        for a in range(B):
            for b in range(B):
                w = window[a, b]
                wo = wacc[oy + a, ox + b]
                ot = acc[oy + a, ox + b]
                if was:
                    p = frames[k, R + a - cy, R + b - cx]
                    wo -= w
                    ot -= w * p
                g = mask[oy + a, ox + b] * w
                f1[a, b] = g * wo
                f2[a, b] = g * ot
                if g * wo > 1e-9:
                    any_other = True
        by, bx = cy, cx
        if any_other:
            ylo = max(cy - radius, -R)
            yhi = min(cy + radius, R)
            xlo = max(cx - radius, -R)
            xhi = min(cx + radius, R)
            best = np.inf
            cur = np.inf
            for ty in range(ylo, yhi + 1):
                for tx in range(xlo, xhi + 1):
                    e = 0.0
                    for a in range(B):
                        fr = R + a - ty
                        for b in range(B):
                            p = frames[k, fr, R + b - tx]
                            e += p * (f1[a, b] * p - 2.0 * f2[a, b])
                    if ty == cy and tx == cx:
                        cur = e
                    if e < best:
                        best = e
                        by = ty
                        bx = tx
            if not best < cur - 1e-12 * (abs(cur) + 1e-30):
                by, bx = cy, cx
        if by != cy or bx != cx:
            changed += 1
            clock[0] += 1
            moved_at[k] = clock[0]  # > seen_at[k]: re-centred on the new translation, evaluate again
        # take the old contribution off (if any) and put the new one on
        for a in range(B):
            for b in range(B):
                w = window[a, b]
                p = frames[k, R + a - by, R + b - bx]
                d = w * p
                d2 = w * p * p
                if was:
                    q = frames[k, R + a - cy, R + b - cx]
                    d -= w * q
                    d2 -= w * q * q
                else:
                    wacc[oy + a, ox + b] += w
                acc[oy + a, ox + b] += d
                acc2[oy + a, ox + b] += d2
        shifts[k, 0] = by
        shifts[k, 1] = bx
        placed[k] = True
    return changed
