"""What every fill engine shares: checking its arguments (the common signature of
``fill_patchmatch``, ``fill_quilt`` and ``fill_hybrid``), the fill-front order and the progress count."""

from __future__ import annotations

import cv2
import numpy as np

from ..errors import ImageError, InvalidParameter, WeftError


def as_channels(image: np.ndarray) -> np.ndarray:
    """An image as float32 (H, W, C), C-contiguous.

    Parameters
    ----------
    image : array_like, (H, W) or (H, W, C) with C = 1..4

    Returns
    -------
    ndarray, float32 (H, W, C)

    Raises
    ------
    ImageError
        Another shape.
    """
    img = np.asarray(image, dtype=np.float32)
    if img.ndim == 2:
        img = img[..., None]
    if img.ndim != 3 or not 1 <= img.shape[2] <= 4:
        raise ImageError(f"image must be (H, W) or (H, W, C) with C = 1..4, not shape {img.shape}")
    return np.ascontiguousarray(img)


def percentile(values: np.ndarray, q: float) -> float:
    """``np.percentile(values, q)`` (linear interpolation) of a non-empty vector, in float64.

    Computed by ``np.partition``: ``np.percentile`` imports ``numpy.ma`` on first use, a cost at every
    fill's process start. Equal to ``np.percentile`` on float64 input; on float32 within a float32
    rounding (numpy computes in the input's precision).

    Parameters
    ----------
    values : ndarray, (N,)
        N >= 1.
    q : float
        The percentile, 0..100.

    Returns
    -------
    float
    """
    a = np.asarray(values, dtype=np.float64).ravel()
    virtual = q / 100.0 * (len(a) - 1)
    lo = int(np.floor(virtual))
    hi = min(lo + 1, len(a) - 1)
    part = np.partition(a, [lo, hi]) if hi != lo else np.partition(a, lo)
    x0, x1 = float(part[lo]), float(part[hi])
    t = virtual - lo
    d = x1 - x0
    return x1 - d * (1.0 - t) if t >= 0.5 else x0 + d * t  # numpy's _lerp


def check_engine_args(image, hole, source, patch: int, name: str):
    """Validate an engine's inputs.

    Parameters
    ----------
    image : array_like, (H, W) or (H, W, C)
        The picture, float in [0, 1].
    hole : array_like, bool (H, W)
        The pixels to fill.
    source : array_like, bool (H, W) or None
        The pixels to copy from (default all outside the hole).
    patch : int
        The engine's patch or block side, at least 3.
    name : str
        The engine, for messages.

    Returns
    -------
    image : ndarray, float32 (H, W, C)
    hole, source : ndarray, bool (H, W)

    Raises
    ------
    ImageError
        The masks' sizes are not the image's.
    InvalidParameter
        A bad ``patch``.
    WeftError
        No whole patch of the source to copy from.
    """
    img = as_channels(image)
    h, w = img.shape[:2]
    hole = np.asarray(hole, dtype=bool)
    if hole.shape != (h, w):
        raise ImageError(f"the hole is {hole.shape[1]}x{hole.shape[0]} but the image is {w}x{h}")
    src = ~hole if source is None else (np.asarray(source, dtype=bool) & ~hole)
    if src.shape != (h, w):
        raise ImageError(f"the source is {src.shape[1]}x{src.shape[0]} but the image is {w}x{h}")
    if isinstance(patch, bool) or not isinstance(patch, (int, np.integer)) or patch < 3:
        raise InvalidParameter(f"parameter 'patch' = {patch!r} must be an integer of at least 3", name="patch")
    if patch > min(h, w):
        raise InvalidParameter(f"parameter 'patch' = {patch} is larger than the {w}x{h} image", name="patch")
    if not whole_patches(src, patch).any():
        raise WeftError(
            f"the {name} engine needs at least one whole {patch}x{patch} patch of known pixels to copy "
            f"from; the source has none"
        )
    return img, hole, src


#: A fill that copies from the known pixels works on the hole's bounding box grown by this many
#: pixels and two patches (:func:`neighbourhood`): the quilt engine's REACH (96) and the refines'
#: reach, with room to spare.
NEAR = 128


def neighbourhood(hole: np.ndarray, source: np.ndarray, patch: int) -> tuple[slice, slice] | None:
    """The part of the picture a fill of ``hole`` reads when it copies from the known pixels.

    The hole's bounding box grown by ``NEAR`` and two patches. The method fills that part alone (every
    engine): their steps over the whole picture (the refine's candidate search, the colour guide, the
    fill order's edge scale, the pyramid) would cost a small hole in a large photo time and memory,
    though the quilt's blocks come from nearby. Only a hole wider than twice ``NEAR`` has windows
    whose neighbourhood holds no whole block; they search the part, not the picture.

    Parameters
    ----------
    hole : ndarray, bool (H, W)
        The hole.
    source : ndarray, bool (H, W)
        The pixels to copy from.
    patch : int
        The engine's patch side.

    Returns
    -------
    (slice, slice) or None
        None when the part is more than a quarter of the picture, or the source is a smaller region (a
        source mask, a second texture), which may lie anywhere.
    """
    if source.sum() < 0.9 * (hole.size - hole.sum()):
        return None
    ys, xs = np.nonzero(hole)
    m = NEAR + 2 * patch
    h, w = hole.shape
    y0, y1, x0, x1 = max(0, ys.min() - m), min(h, ys.max() + 1 + m), max(0, xs.min() - m), min(w, xs.max() + 1 + m)
    if (y1 - y0) * (x1 - x0) * 4 > h * w:  # most of the picture: the picture (its pixels as before)
        return None
    return slice(y0, y1), slice(x0, x1)


def touches_border(hole: np.ndarray) -> bool:
    """Whether ``hole`` has a pixel in the picture's first or last row or column.

    Parameters
    ----------
    hole : ndarray, bool (H, W)

    Returns
    -------
    bool
        True for an uncrop's hole or a transparent border.
    """
    return bool(hole[0].any() or hole[-1].any() or hole[:, 0].any() or hole[:, -1].any())


def whole_patches(region: np.ndarray, patch: int) -> np.ndarray:
    """Where a patch lies wholly inside ``region``.

    Parameters
    ----------
    region : ndarray, bool (H, W)
    patch : int
        The patch side.

    Returns
    -------
    ndarray, bool (H - patch + 1, W - patch + 1)
        True where the patch with this top-left corner lies inside ``region``.
    """
    h, w = region.shape
    if patch > h or patch > w:
        return np.zeros((max(0, h - patch + 1), max(0, w - patch + 1)), dtype=bool)
    ii = cv2.integral(region.astype(np.uint8), sdepth=cv2.CV_32S)
    n = ii[patch:, patch:] - ii[:-patch, patch:] - ii[patch:, :-patch] + ii[:-patch, :-patch]
    return n == patch * patch


def onion_order(hole: np.ndarray) -> np.ndarray:
    """The hole's pixels from its edge inwards: by distance to the nearest known pixel, ties in scan order.

    Parameters
    ----------
    hole : ndarray, bool (H, W)

    Returns
    -------
    ndarray, int64 (N, 2)
        Rows of (y, x).
    """
    from scipy.ndimage import distance_transform_edt

    # exact and the same on every call (OpenCV's precise transform varies in its last bit between
    # calls, which reordered ties and broke determinism under a seed)
    # (the image's border is not a known pixel: an uncrop grows from the image inwards-out)
    dist = distance_transform_edt(hole) if hole.any() and not hole.all() else np.zeros(hole.shape)
    ys, xs = np.nonzero(hole)
    order = np.lexsort((xs, ys, dist[ys, xs]))
    return np.stack([ys[order], xs[order]], axis=1).astype(np.int64)


class Progress:
    """An engine's progress in units of work: ``report(done)`` checks ``cancel`` and sends
    :class:`weft.core.jobs.Progress` (stage ``"fill"``) to ``progress`` when the percentage changes."""

    def __init__(self, progress, cancel, total: int):
        from ..jobs import ProgressReporter

        self.cancel, self.total = cancel, max(1, int(total))
        self.reporter = ProgressReporter(progress, "fill", self.total)

    def __call__(self, done: int) -> None:
        if self.cancel is not None:
            self.cancel.raise_if_cancelled()
        self.reporter.update(min(int(done), self.total))
