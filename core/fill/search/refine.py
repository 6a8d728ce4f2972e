"""Full-resolution EM / PatchMatch from a given fill (no pyramid): what the ``hybrid`` engine and the
final step of the ``quilt`` (colour) and ``patchmatch`` engines run over the hole and the blend band.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ...errors import ImageError, InvalidParameter
from ...jobs import CancelToken, Progress, ProgressReporter
from ...params import as_rng
from ..common import whole_patches
from .em import _SEARCH_SHRINK, STEPS_FIRST, _try, em
from .patches import Flat, check_inputs

__all__ = ["REFINE_ITERATIONS", "refine_band", "refine_patchmatch"]

REFINE_ITERATIONS = 3
_REFINE_CANDIDATES = 2  # source patches tried per target along the principal axis at the start


def _principal_candidates(fl: Flat, img: np.ndarray, gen: np.random.Generator, k: int):
    """For every target patch, the ``k`` source patches nearest to it along the source patches'
    principal axis (a one-dimensional nearest-neighbour guess that finds an exact copy, as a quilted
    block holds, exactly): ``(cy, cx)`` arrays of shape (k, N)."""
    import cv2

    vy, vx = np.nonzero(fl.valid)
    pick = gen.choice(len(vy), size=min(len(vy), 2000), replace=False)
    sample = fl.gather(vy[pick], vx[pick]).astype(np.float64)
    sample -= sample.mean(axis=0)
    v = np.ones(sample.shape[1]) / np.sqrt(sample.shape[1])  # the principal axis by power iteration
    for _ in range(12):  # (not numpy's SVD, whose BLAS threads cost more than this)
        v = np.dot(np.dot(sample, v), sample)
        v /= max(float(np.sqrt(np.dot(v, v))), 1e-30)
    axis = v.reshape(fl.p, fl.p, fl.c).astype(np.float32)
    proj = np.zeros(img.shape[:2], np.float32)
    for ch in range(fl.c):  # the projection of every window, by its top-left corner
        proj += cv2.filter2D(
            np.ascontiguousarray(img[..., ch]),
            cv2.CV_32F,
            np.ascontiguousarray(axis[..., ch]),
            anchor=(0, 0),
            borderType=cv2.BORDER_CONSTANT,
        )
    src = proj[vy, vx]
    order = _stable_argsort(src)
    pos = np.searchsorted(src[order], proj[fl.ty, fl.tx])
    lo = -(k // 2)
    out_y = np.empty((k, len(pos)), np.int64)
    out_x = np.empty((k, len(pos)), np.int64)
    for c in range(k):
        j = order[np.clip(pos + lo + c, 0, len(order) - 1)]
        out_y[c], out_x[c] = vy[j], vx[j]
    return out_y, out_x


def _stable_argsort(values: np.ndarray) -> np.ndarray:
    """``np.argsort(values, kind="stable")`` of a float32 vector without NaN, faster: each value's
    bits as an order-preserving int32 in the high half of an int64 key, its index in the low half,
    so the keys are unique and a plain (unstable) sort orders them as the stable argsort does."""
    bits = (np.asarray(values, dtype=np.float32) + np.float32(0.0)).view(np.int32)  # (-0.0 becomes 0.0)
    ordered = np.where(bits < 0, bits ^ np.int32(0x7FFFFFFF), bits).astype(np.int64)
    keys = (ordered << 32) | np.arange(len(bits), dtype=np.int64)
    keys.sort()
    return keys & np.int64(0xFFFFFFFF)


def refine_band(
    filled: np.ndarray,
    hole: np.ndarray,
    region: np.ndarray,
    source: np.ndarray,
    *,
    patch: int,
    iterations: int,
    rng=0,
    progress=None,
    cancel=None,
    worst: float = 0.0,
    last_vote_stride: int | None = None,
) -> np.ndarray:
    """:func:`refine_patchmatch` of a finished fill over ``region``, copying from ``source`` outside it.

    The band becomes a continuation of the copies. Over the hole alone, from the whole source, when
    the band took the last whole source patch; ``filled`` as it is when there is none either. What the
    ``quilt`` (colour), ``hybrid`` and ``patchmatch`` engines end with.

    Parameters
    ----------
    filled : ndarray, float32 (H, W, C)
        The finished fill.
    hole : ndarray, bool (H, W)
        The hole.
    region : ndarray, bool (H, W)
        The hole and the blend band's known pixels that may change.
    source : ndarray, bool (H, W)
        The pixels to copy from.
    patch, iterations, rng, progress, cancel, worst, last_vote_stride
        As in :func:`refine_patchmatch`.

    Returns
    -------
    ndarray, float32 (H, W, C)
    """
    sources = source & ~region
    if not whole_patches(sources, patch).any():
        region, sources = hole, source
        if not whole_patches(sources, patch).any():
            return filled
    return refine_patchmatch(
        filled,
        region,
        sources,
        filled,
        patch=patch,
        iterations=iterations,
        rng=rng,
        progress=progress,
        cancel=cancel,
        worst=worst,
        last_vote_stride=last_vote_stride,
    )


def refine_patchmatch(
    image: np.ndarray,
    hole: np.ndarray,
    source: np.ndarray | None = None,
    init: np.ndarray | None = None,
    *,
    patch: int = 7,
    iterations: int = REFINE_ITERATIONS,
    rng: None | int | np.random.Generator = 0,
    progress: Callable[[Progress], None] | None = None,
    cancel: CancelToken | None = None,
    worst: float = 0.0,
    last_vote_stride: int | None = None,
) -> np.ndarray:
    """EM / PatchMatch iterations at full resolution, started from a given fill ``init`` (no pyramid).

    1. Every ``patch`` x ``patch`` patch touching the hole gets a match among the patches lying wholly
       in ``source``: first the source patches nearest to it along their principal axis (an exact
       copy, as a quilted block holds, is found exactly), then, on every iteration, PatchMatch
       propagation (the offset of the neighbours 8, 4, 2 and 1 px away on the first iteration --
       jump flooding, vectorised --, 1 px on later ones) and random search around the match at radii
       from half the image down to 1 px; plain SSD over all channels.
    2. Every hole pixel is copied through the offset (match minus patch) the covering patches agree
       on most, each counted with ``exp(-d / 2 sigma^2)`` (sigma^2: the 75th percentile of the
       distances): no averaging, the fill keeps its grain; where two copies meet, the seam moves to
       where the covering patches agree.

    A patch that is an exact copy of its match is not searched again, and a pixel only such patches
    cover keeps its value (any of their offsets gives it). In numpy and OpenCV: a fill that uses only
    this loads no numba.

    Parameters
    ----------
    image : ndarray, float (H, W) or (H, W, C) in [0, 1]
        The picture.
    hole : ndarray, bool (H, W)
        The pixels to fill.
    source : ndarray, bool (H, W), optional
        The pixels to copy from (default all outside the hole).
    init : ndarray, optional
        An array of the image's shape whose hole pixels are the starting fill (default: the image).
    patch : int, default 7
        The patch side.
    iterations : int, default REFINE_ITERATIONS
        EM iterations, 1..64.
    rng : None, int or numpy.random.Generator, default 0
        Seed.
    progress : callable, optional
        Receives :class:`weft.core.jobs.Progress`, one unit per iteration.
    cancel : CancelToken, optional
        Checked every iteration.
    worst : float, default 0
        A percentage 0..100: every iteration searches only the patches that are not exact copies and
        whose distance is at least this percentile of theirs (the hybrid engine searches the worse
        half, where most of the gain is).
    last_vote_stride : int, optional
        The last iteration's vote counts the covering patches at every this-th corner row and column
        (default: every ``VOTE_STRIDE``-th, as the others; the ``patchmatch`` engine's final refine
        counts every one).

    Returns
    -------
    ndarray, float32
        Every pixel outside the hole equal to ``image``'s bit for bit.

    Raises
    ------
    ImageError
        Bad shapes (see :func:`check_inputs`), or an ``init`` of another shape.
    InvalidParameter
        A bad ``patch``, ``iterations`` or ``worst``.

    References
    ----------
    Barnes et al., "PatchMatch" (2009); Wexler, Shechtman & Irani, "Space-time completion of video" (2007).
    """
    if isinstance(worst, bool) or not isinstance(worst, (int, float, np.integer, np.floating)) or not 0 <= worst < 100:
        raise InvalidParameter(
            f"parameter 'worst' = {worst!r} must be a percentage 0..100 (below 100)", name="worst", value=worst
        )
    arr, hole, source, p = check_inputs(image, hole, source, patch, None, iterations)
    out = np.array(arr, dtype=np.float32, copy=True)
    if not hole.any():
        return out
    start = arr if init is None else np.asarray(init)
    if start.shape != arr.shape:
        raise ImageError(f"the starting fill has shape {start.shape} but the image {arr.shape}")
    gen = as_rng(rng)
    img = np.array(out if out.ndim == 3 else out[..., None], dtype=np.float32, order="C")
    img[hole] = (start if start.ndim == 3 else start[..., None])[hole]
    fl = Flat(img, hole, source, p)
    if not fl.valid.any():
        raise ImageError(
            f"the source region holds no whole {p}x{p} patch: leave at least a {p}x{p} square "
            f"of known pixels to copy from (or use a smaller patch)"
        )
    n = len(fl.ty)
    report = ProgressReporter(progress, "fill", iterations)
    cy, cx = _principal_candidates(fl, img, gen, _REFINE_CANDIDATES)
    targets = fl.gather(fl.ty, fl.tx)
    sy, sx = cy[0].copy(), cx[0].copy()
    everyone = np.arange(n)
    dist = fl.dist(targets, everyone, sy, sx)
    for c in range(1, len(cy)):
        _try(fl, targets, everyone, sy, sx, dist, cy[c], cx[c], np.ones(n, bool))
    em(
        fl,
        img,
        hole,
        sy,
        sx,
        dist,
        iterations=iterations,
        gen=gen,
        steps_first=STEPS_FIRST,
        shrink=_SEARCH_SHRINK,
        bias=0.0,
        worst=worst,
        cancel=cancel,
        on_iteration=lambda it: report.update(it + 1),
        last_stride=last_vote_stride,
    )
    if out.ndim == 2:
        out[hole] = img[..., 0][hole]
    else:
        out[hole] = img[hole]
    return out
