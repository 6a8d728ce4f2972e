"""Minimum-error boundary cuts between overlapping blocks (Efros & Freeman 2001, §2.1).

When a new block overlaps pixels that are already there, the seam between the two should run where
they agree. Given the per-pixel error ``e = (existing - new)²`` over the overlap, the cut is the
8-connected path of least accumulated error, found by dynamic programming: for a vertical strip
``E[y, x] = e[y, x] + min(E[y+1, x-1], E[y+1, x], E[y+1, x+1])`` and a backtrace (the Poisson
write-up's "accumulated cost matrix", neighbours beyond the strip's edges simply not used).

Used by ``weft.core.quilting`` (modes ``mincut``) and meant for any other method that stitches patches
(the NFPT synthesis): :func:`min_cut_mask` for a block with overlaps on any of its four sides,
:func:`min_error_path` for one strip, :func:`overlap_error` for the error surface.
"""

from __future__ import annotations

import numpy as np

from .errors import ImageError, InvalidParameter
from .params import out_of_range

__all__ = ["min_cut_mask", "min_error_path", "overlap_error", "accumulated_costs"]


def _check_error(error, name: str = "error") -> np.ndarray:
    err = np.asarray(error)
    if err.ndim != 2 or err.shape[0] < 1 or err.shape[1] < 1:
        raise ImageError(f"{name} must be a 2-D array (rows, columns), not shape {err.shape}")
    if not np.issubdtype(err.dtype, np.number) or np.issubdtype(err.dtype, np.complexfloating):
        raise ImageError(f"{name} must be real numbers, not {err.dtype}")
    err = np.ascontiguousarray(err, dtype=np.float64)
    if not np.isfinite(err).all():
        raise ImageError(f"{name} contains NaN or infinite values")
    return err


def _check_width(name: str, value, limit: int, side: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise InvalidParameter(f"parameter '{name}' = {value!r} must be an integer", name=name, value=value)
    value = int(value)
    if not 0 <= value <= limit:
        raise out_of_range(name, value, 0, limit, f"the block is {limit} pixels {side}")
    return value


def overlap_error(existing: np.ndarray, new: np.ndarray) -> np.ndarray:
    """Per-pixel squared difference of two overlapping images, summed over channels.

    Parameters
    ----------
    existing, new : ndarray, (H, W) or (H, W, C), same shape
        The pixels already in place and the new block's pixels over the same area.

    Returns
    -------
    ndarray of float64, shape (H, W)
        ``sum_c (existing - new)²``, the error surface of Efros & Freeman §2.1.
    """
    a = np.asarray(existing, dtype=np.float64)
    b = np.asarray(new, dtype=np.float64)
    if a.shape != b.shape:
        raise ImageError(f"existing pixels have shape {a.shape} but the new block has {b.shape}")
    d = (a - b) ** 2
    return d if d.ndim == 2 else d.sum(axis=2)


def min_cut_mask(error: np.ndarray, *, left: int = 0, top: int = 0, right: int = 0, bottom: int = 0) -> np.ndarray:
    """Where the new block shows after the minimum-error boundary cut (True = new pixel).

    Parameters
    ----------
    error : ndarray (h, w)
        Per-pixel error between the existing pixels and the new block over the block's footprint
        (:func:`overlap_error`); only the overlap strips are read, non-negative values expected.
    left, top : int, default 0
        Widths of the overlap with the block on the left (columns ``[0, left)``) and above (rows
        ``[0, top)``), 0..w and 0..h.
    right, bottom : int, default 0
        Overlaps on the right (columns ``[w - right, w)``) and below (rows ``[h - bottom, h)``),
        which a tileable output has where its last blocks wrap onto the first ones.

    Returns
    -------
    ndarray of bool, shape (h, w)
        False where the existing pixels stay, True where the new block is pasted.

    Notes
    -----
    Efros & Freeman §2.1: a vertical cut through the left overlap, a horizontal one through the top
    overlap, by dynamic programming over 8-connected paths (each step moves one row down, or one
    column right for a horizontal cut, and at most one pixel sideways). The paper says only that the
    two cuts are "combined at the corner"; here they are *joined*: the vertical accumulated cost is
    computed from the bottom up, the horizontal one from the right leftwards, and the corner pixel
    ``(r, c)`` of the top-left ``top x left`` square minimising ``E_v + E_h - e`` starts both
    backtraces, so the seam is one least-error path through the L-shaped overlap. Above ``r`` and
    left of ``c`` the existing pixels stay. Right and bottom cuts are separate paths and the new
    region is the intersection of all sides. Pixels on a path belong to the new block. A side of
    width 0 has no cut; with all four 0 the whole block is new.
    """
    err = _check_error(error)
    h, w = err.shape
    left = _check_width("left", left, w, "wide")
    right = _check_width("right", right, w, "wide")
    top = _check_width("top", top, h, "high")
    bottom = _check_width("bottom", bottom, h, "high")
    mask = np.ones((h, w), dtype=np.uint8)
    from ._kernels import seams as _k  # numba loads on first use

    _k.cut_mask(err, top, left, right, bottom, mask)
    return mask.astype(bool)


def min_error_path(error: np.ndarray) -> np.ndarray:
    """The 8-connected top-to-bottom path of least total error through a strip.

    Parameters
    ----------
    error : ndarray (h, w)
        Error surface of a vertical strip (transpose it for a horizontal one).

    Returns
    -------
    ndarray of int64, shape (h,)
        The path's column in every row; consecutive columns differ by at most 1.

    Notes
    -----
    The dynamic program of the Poisson write-up, run from the bottom row up (accumulated cost =
    error + minimum of the three neighbours below); the path starts at the least accumulated cost
    of the top row and follows the minima down. Ties go to the straight-down, then left neighbour.
    """
    err = _check_error(error)
    h, w = err.shape
    mask = np.ones((h, w), dtype=np.uint8)
    from ._kernels import seams as _k

    _k.cut_mask(err, 0, w, 0, 0, mask)
    return np.argmax(mask, axis=1).astype(np.int64)


def accumulated_costs(error: np.ndarray) -> np.ndarray:
    """The dynamic program's accumulated costs of a stack of vertical strips, in numpy (no numba).

    ``E[y, x] = e[y, x] + min(E[y+1, x-1], E[y+1, x], E[y+1, x+1])`` (the bottom row its error;
    neighbours beyond the strip's edges not used), the values of the numba kernel's (the same
    additions; min is exact). A backtrace from any row follows it down; the numpy quilting engine
    (its kernel's tie rule) and the fill's cut (lowest column) trace their own.

    The rows are accumulated into a buffer padded with +inf columns, three ufunc calls a row written
    in place, for the whole stack at once (the run is ``h`` steps of calls on tiny arrays, so the
    number of calls is the cost).

    Parameters
    ----------
    error : ndarray, (K, h, w)
        The error surfaces of K strips.

    Returns
    -------
    ndarray, float64 (K, h, w)
        The accumulated costs ``E``.

    References
    ----------
    Efros & Freeman (2001), §2.1: the minimum error boundary cut by dynamic programming.
    """
    k, h, w = error.shape
    accp = np.full((k, h, w + 2), np.inf)
    accp[:, h - 1, 1:-1] = error[:, h - 1]
    tmp = np.empty((k, w))
    for y in range(h - 2, -1, -1):
        below = accp[:, y + 1]
        np.minimum(below[:, :-2], below[:, 2:], out=tmp)
        np.minimum(tmp, below[:, 1:-1], out=tmp)
        np.add(error[:, y], tmp, out=accp[:, y, 1:-1])
    return accp[:, :, 1:-1]
