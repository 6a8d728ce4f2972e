"""The M step of the shared search: every hole pixel copied through the offset its covering patches
agree on most (a weighted mode, not Wexler's weighted mean, so copies keep their grain).
"""

from __future__ import annotations

import numpy as np

from .patches import Flat

__all__ = ["VOTE_STRIDE", "vote_mode"]

# the vote counts the covering patches at every 3rd row and column (and the last): as good as all of
# them at a fifth of the cost, except in the last vote of a fill (see refine_patchmatch)
VOTE_STRIDE = 3


def vote_mode(
    img: np.ndarray, hole: np.ndarray, fl: Flat, sy, sx, weight, stride: int = VOTE_STRIDE, fixed: slice | None = None
) -> np.ndarray:
    """Copy every pixel of ``hole`` through the offset its covering target patches agree on most.

    The covering patches are those at every ``stride``-th row and column of corners, and the last,
    each counted with its ``weight``. Each covering patch is one int64 key: its offset's code in the
    high bits, its weight as an integer (``weight * 2**(bits - 6)``, at least 1: a pixel whose votes all
    weigh nearly nothing takes its most frequent offset) in the low ones; a plain sort of each pixel's
    keys groups equal offsets, and exact integer sums weigh them (the result of a stable argsort of
    the codes and float sums, for less).

    Parameters
    ----------
    img : ndarray, float32 (H, W, C)
        Written in place, but for its ``fixed`` channels.
    hole : ndarray, bool (H, W)
    fl : Flat
        The target patches and their geometry.
    sy, sx : ndarray
        Each target patch's match (top-left corner).
    weight : ndarray
        Each target patch's weight, 0..1.
    stride : int, default VOTE_STRIDE
        Which corners vote.
    fixed : slice, optional
        Channels left as they are (the guide's, the last ones).

    Returns
    -------
    ndarray, bool (H, W)
        The pixels whose value changed.

    References
    ----------
    Wexler, Shechtman & Irani, "Space-time completion of video" (2007), §3 (the vote), with the mode
    of the offsets in place of their mean.
    """
    h, w, p = fl.h, fl.w, fl.p
    hy, hx = np.nonzero(hole)
    changed = np.zeros(hole.shape, bool)
    if len(hy) == 0:
        return changed
    hv, wv = fl.tmap.shape
    span = 2 * w + 1
    none = (2 * h + 1) * span  # the codes are 0 .. none - 1; ``none``: no covering patch
    wbits = 62 - int(none).bit_length()
    shifts = np.array(sorted(set(range(0, p, stride)) | {p - 1}), np.int64)
    # a padded map of each target corner's key: pixel (y, x) is covered by the patch at corner
    # (y - i, x - j), at (y - i + p, x - j + p) in it
    kmap = np.full((hv + p, wv + p), np.int64(none) << wbits, np.int64)
    q = np.maximum(np.rint(np.asarray(weight, np.float64) * float(1 << (wbits - 6))), 1).astype(np.int64)
    kmap[p + fl.ty, p + fl.tx] = (((sy - fl.ty + h) * span + (sx - fl.tx + w)) << wbits) | q
    yy = np.minimum(p + hy[:, None] - shifts[None, :], hv + p - 1)  # (a row beyond the corners: none)
    xx = np.minimum(p + hx[:, None] - shifts[None, :], wv + p - 1)
    idx = (yy[:, :, None] * (wv + p) + xx[:, None, :]).reshape(len(hy), -1)
    inside = (
        (hy[:, None] - shifts[None, :] < hv)[:, :, None] & (hx[:, None] - shifts[None, :] < wv)[:, None, :]
    ).reshape(len(hy), -1)
    keys = np.where(inside, np.take(kmap.ravel(), idx), np.int64(none) << wbits)
    keys.sort(axis=1)
    cs = keys >> wbits
    ws = keys & ((np.int64(1) << wbits) - 1)
    cw = np.cumsum(ws, axis=1)
    start = np.ones(cs.shape, bool)
    start[:, 1:] = cs[:, 1:] != cs[:, :-1]
    end = np.ones(cs.shape, bool)
    end[:, :-1] = start[:, 1:]
    before = np.maximum.accumulate(np.where(start, cw - ws, -1), axis=1)  # weight before each run
    total = np.where(end & (cs != none), cw - before, -1)  # each run's weight, at its last entry
    bc = cs[np.arange(len(hy)), np.argmax(total, axis=1)]
    has = bc != none
    py, px = hy[has], hx[has]
    cols = slice(None) if fixed is None else slice(0, fixed.start)
    new = img[py + bc[has] // span - h, px + bc[has] % span - w, cols]
    changed[py, px] = (new != img[py, px, cols]).any(axis=1)
    img[py, px, cols] = new
    return changed
