"""Coherence and completeness: the two halves of Simakov et al.'s bidirectional similarity, on
luminance patches with exact nearest neighbours (a chunked float32 BLAS product that picks the
neighbour, then the chosen neighbour's distance recomputed exactly in float64).
"""

from __future__ import annotations

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from ..image import luminance
from .checks import MIN_SIDE, _check_image, _check_int

# Upper bound on the float32 distance block held at once by the nearest-neighbour search (small
# enough that the add/argmin passes stay close to the cache).
_BLOCK_BYTES = 16 * 1024 * 1024


def _patches(lum: np.ndarray, patch: int, stride: int) -> np.ndarray:
    """All ``patch`` x ``patch`` windows of ``lum`` on a ``stride`` grid, as float32 rows (N, patch²)."""
    windows = sliding_window_view(lum, (patch, patch))[::stride, ::stride]
    return np.ascontiguousarray(windows, dtype=np.float32).reshape(-1, patch * patch)


def _nearest_distances(queries: np.ndarray, database: np.ndarray, *, block_bytes: int = _BLOCK_BYTES) -> np.ndarray:
    """Euclidean distance from every query row to its nearest database row.

    Parameters
    ----------
    queries : ndarray, shape (N, D)
    database : ndarray, shape (M, D), M >= 1
    block_bytes : int
        Memory bound for the float32 distance block computed at once.

    Returns
    -------
    ndarray of float64, shape (N,)
        ``min_j ||queries[i] - database[j]||``. The neighbour is chosen with float32 BLAS
        (``|b|^2 - 2 a.b``, on data centred on the database mean to limit cancellation); its
        distance is then recomputed exactly in float64, so identical rows give exactly 0.
    """
    queries = np.asarray(queries)
    database = np.asarray(database)
    n, m = len(queries), len(database)
    if n == 0:
        return np.zeros(0, dtype=np.float64)
    centre = database.mean(axis=0, dtype=np.float64).astype(np.float32)
    q32 = np.subtract(queries, centre, dtype=np.float32)
    d32 = np.subtract(database, centre, dtype=np.float32)
    dnorm = np.einsum("ij,ij->i", d32, d32, dtype=np.float32)

    elems = max(1, block_bytes // 4)
    rows = int(min(n, max(64, elems // m)))
    cols = int(min(m, max(1, elems // rows)))
    buffer = np.empty(rows * cols, dtype=np.float32)
    best = np.empty(n, dtype=np.intp)

    for r0 in range(0, n, rows):
        qc = q32[r0 : r0 + rows]
        r = len(qc)
        best_val = np.full(r, np.inf, dtype=np.float32)
        best_idx = np.zeros(r, dtype=np.intp)
        for c0 in range(0, m, cols):
            dc = d32[c0 : c0 + cols]
            c = len(dc)
            block = buffer[: r * c].reshape(r, c)
            np.matmul(qc, dc.T, out=block)
            block *= -2.0
            block += dnorm[c0 : c0 + c]
            idx = np.argmin(block, axis=1)
            val = block[np.arange(r), idx]
            better = val < best_val
            best_val[better] = val[better]
            best_idx[better] = idx[better] + c0
        best[r0 : r0 + r] = best_idx

    out = np.empty(n, dtype=np.float64)
    step = 65536
    for r0 in range(0, n, step):
        diff = queries[r0 : r0 + step].astype(np.float64) - database[best[r0 : r0 + step]].astype(np.float64)
        out[r0 : r0 + step] = np.sqrt(np.einsum("ij,ij->i", diff, diff))
    return out


def _patch_score(queries_img, database_img, patch, stride, q_what, d_what) -> float:
    patch = _check_int("patch", patch, 1)
    stride = _check_int("stride", stride, 1)
    min_side = max(MIN_SIDE, patch)
    q = luminance(_check_image(queries_img, q_what, min_side).astype(np.float32, copy=False))
    d = luminance(_check_image(database_img, d_what, min_side).astype(np.float32, copy=False))
    dist = _nearest_distances(_patches(q, patch, stride), _patches(d, patch, 1))
    return float(dist.mean())


def coherence(out, source, *, patch: int = 7, stride: int = 2) -> float:
    """Mean distance from the output's patches to their nearest source patch (lower is better).

    Every ``patch`` x ``patch`` luminance window of ``out`` on a ``stride`` grid (all valid
    positions) is matched to its exact nearest window of ``source`` among all positions
    (stride 1). The distance is Euclidean over the window's pixels, intensities in [0, 1]: the
    square root of the sum of squared differences (for 7x7 windows it lies in 0..7). This is the
    "coherence" half of Simakov et al.'s bidirectional similarity: an output assembled only from
    verbatim source patches scores ~0; blur, seams and invented structure raise it.

    Parameters
    ----------
    out : ndarray, float32 in [0, 1], shape (H, W) or (H, W, 3)
        The synthesized image; colour is reduced to Rec. 601 luminance.
    source : ndarray, float32 in [0, 1], shape (H', W') or (H', W', 3)
        The example texture.
    patch : int, default 7
        Window side in pixels, >= 1.
    stride : int, default 2
        Step between the windows of ``out``, >= 1.

    Returns
    -------
    float
        Mean nearest-neighbour distance, >= 0.

    Raises
    ------
    ImageError
        If an image is not (H, W) or (H, W, 3), or is smaller than max(7, patch) on a side.
    InvalidParameter
        If ``patch`` or ``stride`` is not an integer >= 1.
    """
    return _patch_score(out, source, patch, stride, "output image", "source image")


def completeness(out, source, *, patch: int = 7, stride: int = 2) -> float:
    """Mean distance from the source's patches to their nearest output patch (lower is better).

    The roles of :func:`coherence` swapped: every ``patch`` x ``patch`` luminance window of
    ``source`` on a ``stride`` grid is matched to its exact nearest window of ``out`` among all
    positions. An output that omits part of the source's appearance (e.g. a small crop of it)
    scores high even when it is perfectly coherent.

    Parameters
    ----------
    out : ndarray, float32 in [0, 1], shape (H, W) or (H, W, 3)
        The synthesized image; colour is reduced to Rec. 601 luminance.
    source : ndarray, float32 in [0, 1], shape (H', W') or (H', W', 3)
        The example texture.
    patch : int, default 7
        Window side in pixels, >= 1.
    stride : int, default 2
        Step between the windows of ``source``, >= 1.

    Returns
    -------
    float
        Mean nearest-neighbour distance, >= 0 (0..7 for 7x7 windows).

    Raises
    ------
    ImageError
        If an image is not (H, W) or (H, W, 3), or is smaller than max(7, patch) on a side.
    InvalidParameter
        If ``patch`` or ``stride`` is not an integer >= 1.
    """
    return _patch_score(source, out, patch, stride, "source image", "output image")
