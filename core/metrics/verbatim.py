"""How much of an output is a verbatim copy of its sample: the largest region sharing one source offset."""

from __future__ import annotations

import numpy as np

from ..errors import ImageError


def verbatim_region(sources) -> int:
    """Pixels of the largest region of an output copied verbatim from its sample.

    A verbatim region is a 4-connected set of copied pixels sharing one offset ``(sy - y, sx - x)``:
    a piece of the sample pasted as it is, whatever the blocks it was pasted in.

    Parameters
    ----------
    sources : ndarray, integer (H, W, 2)
        For every output pixel (y, x), the sample pixel (sy, sx) it was copied from, or a negative
        value where the pixel is not a copy (not made yet, blended).

    Returns
    -------
    int
        The region's pixel count (0 when nothing is a copy).

    Raises
    ------
    ImageError
        If ``sources`` is not an (H, W, 2) integer array.
    """
    import cv2

    src = np.asarray(sources)
    if src.ndim != 3 or src.shape[2] != 2 or not np.issubdtype(src.dtype, np.integer):
        raise ImageError(f"source map has shape {src.shape} and type {src.dtype}; it must be (H, W, 2) integers")
    h, w = src.shape[:2]
    if h == 0 or w == 0:
        return 0
    valid = (src[..., 0] >= 0) & (src[..., 1] >= 0)
    if not valid.any():
        return 0
    yy, xx = np.mgrid[0:h, 0:w]
    dy = src[..., 0].astype(np.int64) - yy
    dx = src[..., 1].astype(np.int64) - xx
    # The graph drawn at twice the resolution: pixel (y, x) at (2y, 2x), the edge to its right
    # neighbour at (2y, 2x + 1), to the one below at (2y + 1, 2x); an edge pixel is set where both
    # neighbours are copies with the same offset. The 4-connected components of that image are the
    # graph's (a node meets another only through an edge pixel), found by cv2 (importing
    # scipy.sparse's csgraph would slow every quilting process's start).
    grid = np.zeros((2 * h - 1, 2 * w - 1), dtype=np.uint8)
    grid[::2, ::2] = valid
    grid[::2, 1::2] = valid[:, :-1] & valid[:, 1:] & (dy[:, :-1] == dy[:, 1:]) & (dx[:, :-1] == dx[:, 1:])
    grid[1::2, ::2] = valid[:-1] & valid[1:] & (dy[:-1] == dy[1:]) & (dx[:-1] == dx[1:])
    _, labels = cv2.connectedComponents(grid, connectivity=4, ltype=cv2.CV_32S)
    counts = np.bincount(labels[::2, ::2][valid])
    return int(counts.max())


def verbatim_fraction(sources, sample_shape) -> float:
    """The largest verbatim region of an output (:func:`verbatim_region`) as a fraction of the sample.

    Quilting copies blocks, so every output has verbatim regions of about a block; a fraction near
    the block's share of the sample is the floor. When a method keeps choosing the continuation of
    its neighbour's source position, one region grows across blocks into a strip of the sample
    (1.0: as large as the whole sample). Lower is better.

    Parameters
    ----------
    sources : ndarray, integer (H, W, 2)
        As in :func:`verbatim_region`.
    sample_shape : tuple of int
        The sample's shape (H, W[, C]).

    Returns
    -------
    float
        The region's pixels over ``sample_shape[0] * sample_shape[1]``.

    Raises
    ------
    ImageError
        If ``sources`` is not an (H, W, 2) integer array or ``sample_shape`` has no area.
    """
    sh, sw = int(sample_shape[0]), int(sample_shape[1])
    if sh <= 0 or sw <= 0:
        raise ImageError(f"sample shape {tuple(sample_shape)} has no area")
    return verbatim_region(sources) / float(sh * sw)
