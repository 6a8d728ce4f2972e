"""numba kernels of image quilting (``weft.core.quilting``).

* :func:`choose_best`, :func:`choose_tol`, :func:`choose_epsilon`, :func:`choose_sampled` -- the
  source position of one block from the SSD map of every position, one kernel per selection rule;
  :func:`best_k`, :func:`seam_error` -- the seam rule (in ``weft.core._kernels.quilting_rules``,
  re-exported here).
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
from .quilting_rules import (  # noqa: F401 (re-exported: the engine and tests read the rules here)
    _argmin,
    _cost_map,
    _kth_smallest,
    _ranked,
    _splitmix,
    best_k,
    choose_best,
    choose_epsilon,
    choose_sampled,
    choose_tol,
    seam_error,
)

_DY = (1, -1, 0, 0)
_DX = (0, 0, 1, -1)


# --------------------------------------------------------------------------------------------
# one block of quilting


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
