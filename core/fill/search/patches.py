"""The patches the shared search works on: window sums, the inputs' checks, and :class:`Flat`, an
image seen as its target patches (those touching the hole) and the source patches they may copy.
"""

from __future__ import annotations

import numpy as np

from ...errors import ImageError, InvalidParameter
from ..common import whole_patches

__all__ = ["MIN_PATCH", "MAX_PATCH", "Flat", "box_sum", "check_inputs"]

MIN_PATCH = 3
MAX_PATCH = 63


def box_sum(a: np.ndarray, p: int) -> np.ndarray:
    """Sums of ``a`` over every p x p window, indexed by the window's top-left corner.

    Parameters
    ----------
    a : ndarray, (H, W)
        Values; a bool ``a`` gives exact int32 counts from OpenCV's integral image.
    p : int
        The window side.

    Returns
    -------
    ndarray, (H - p + 1, W - p + 1)
    """
    if a.dtype == bool:
        import cv2

        c = cv2.integral(np.ascontiguousarray(a).view(np.uint8), sdepth=cv2.CV_32S)
        return c[p:, p:] - c[:-p, p:] - c[p:, :-p] + c[:-p, :-p]
    c = np.zeros((a.shape[0] + 1, a.shape[1] + 1), np.float64)
    np.cumsum(np.cumsum(a, axis=0, dtype=np.float64), axis=1, out=c[1:, 1:])
    return c[p:, p:] - c[:-p, p:] - c[p:, :-p] + c[:-p, :-p]


def check_inputs(image, hole, source, patch, levels, iterations):
    """Validate the inputs of a patch-search fill.

    Parameters
    ----------
    image : array_like, (H, W) or (H, W, C) with C = 1..4
        Float in [0, 1].
    hole : array_like, bool (H, W)
        The pixels to fill.
    source : array_like, bool (H, W) or None
        The pixels to copy from (default all outside the hole).
    patch : int
        The patch side, MIN_PATCH..MAX_PATCH, at most the image's shorter side.
    levels, iterations : int or None
        1..64, or None.

    Returns
    -------
    image : ndarray
    hole, source : ndarray, bool (H, W)
        ``source`` never includes the hole.
    patch : int

    Raises
    ------
    ImageError
        A bad shape or type, or masks of another size than the image.
    InvalidParameter
        A bad ``patch``, ``levels`` or ``iterations``.
    """
    arr = np.asarray(image)
    if arr.ndim not in (2, 3) or (arr.ndim == 3 and not 1 <= arr.shape[2] <= 4):
        raise ImageError(f"image must be (H, W) or (H, W, C) with C = 1..4 channels, got shape {arr.shape}")
    if not np.issubdtype(arr.dtype, np.floating):
        raise ImageError(f"image must be float in [0, 1], got {arr.dtype}")
    h, w = arr.shape[:2]
    if isinstance(patch, bool) or not isinstance(patch, (int, np.integer)) or not MIN_PATCH <= patch <= MAX_PATCH:
        raise InvalidParameter(
            f"parameter 'patch' = {patch!r} must be an integer {MIN_PATCH}..{MAX_PATCH}", name="patch", value=patch
        )
    patch = int(patch)
    if min(h, w) < patch:
        raise ImageError(f"image is {w}x{h}: smaller than the {patch}x{patch} patch")
    for name, value in (("levels", levels), ("iterations", iterations)):
        if value is not None and (
            isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not 1 <= value <= 64
        ):
            raise InvalidParameter(
                f"parameter '{name}' = {value!r} must be an integer 1..64 or None", name=name, value=value
            )

    def mask(m, what):
        m = np.asarray(m)
        if m.shape != (h, w):
            got = f"{m.shape[1]}x{m.shape[0]}" if m.ndim == 2 else f"of shape {m.shape}"
            raise ImageError(f"{what} is {got} but the image is {w}x{h}")
        return m.astype(bool)

    hole = mask(hole, "hole mask")
    source = ~hole if source is None else mask(source, "source mask") & ~hole
    return arr, hole, source, patch


class Flat:
    """An image as the patch search sees it: target patches (those touching the hole), the allowed
    source corners, gathering of p x p patches by their top-left corner, and the distance of target
    patches to candidates: the plain SSD, or with ``conf`` (H, W) each target pixel's squared
    difference weighted by its confidence (the pyramid's levels), except on the ``fixed`` channels
    (the guide, known in the hole), weighted 1."""

    def __init__(
        self,
        img: np.ndarray,
        hole: np.ndarray,
        source: np.ndarray,
        p: int,
        conf: np.ndarray | None = None,
        fixed: slice | None = None,
    ):
        from numpy.lib.stride_tricks import as_strided

        h, w, c = img.shape
        self.h, self.w, self.c, self.p = h, w, c, p
        # every p x p patch by its top-left corner, as p rows of p * c contiguous values: a view of
        # ``img`` (C-contiguous), so the vote's writes are seen by the next gathers; indexing it
        # copies a patch row by row, with no index array to build for every gather
        s0, s1, s2 = img.strides
        assert img.flags.c_contiguous and s1 == c * s2
        self.windows = as_strided(
            img, shape=(h - p + 1, w - p + 1, p, p * c), strides=(s0, s1, s0, s2), writeable=False
        )
        self.valid = whole_patches(source, p)
        touches = box_sum(hole, p) > 0.5
        ty, tx = np.nonzero(touches)
        self.ty, self.tx = ty.astype(np.int64), tx.astype(np.int64)
        self.tmap: np.ndarray = np.full(touches.shape, -1, np.int64)
        self.tmap[ty, tx] = np.arange(len(ty))
        self.weights = None  # (N, P * C) float32: the target patches' confidences, a pixel's repeated per channel
        self.mean_conf = None  # (N,) float64: their means over the patch
        if conf is not None:
            cw = as_strided(conf, shape=(h - p + 1, w - p + 1, p, p), strides=conf.strides * 2, writeable=False)
            c_ = cw[self.ty, self.tx].reshape(len(ty), p * p)
            self.weights = np.ascontiguousarray(np.repeat(c_, c, axis=1), dtype=np.float32)
            if fixed is not None:  # channels known in the hole (the guide) count in full there
                self.weights.reshape(len(ty), p * p, c)[:, :, fixed] = 1.0
            self.mean_conf = c_.mean(axis=1, dtype=np.float64)

    def gather(self, ys: np.ndarray, xs: np.ndarray) -> np.ndarray:
        """(N, P * C) float32: the patches whose top-left corners are (``ys``, ``xs``), each its rows
        one after the other, a pixel's channels together."""
        return self.windows[ys, xs].reshape(len(ys), self.p * self.p * self.c)

    def dist(self, targets: np.ndarray, k: np.ndarray, sy: np.ndarray, sx: np.ndarray) -> np.ndarray:
        """The distances of the target patches ``k`` (whose pixels are ``targets``) to the patches at
        (``sy``, ``sx``)."""
        d = self.gather(sy, sx)  # a fresh copy (fancy indexing): worked on in place
        np.subtract(targets, d, out=d)
        if self.weights is None:
            return np.einsum("nk,nk->n", d, d)
        np.multiply(d, d, out=d)  # (squaring first, then a two-operand einsum: the faster order)
        return np.einsum("nk,nk->n", self.weights[k], d)

    def normalized(self, dist: np.ndarray) -> np.ndarray:
        """Distances per patch pixel (and per unit of confidence), for the vote's weights."""
        p2 = self.p * self.p
        return dist / p2 if self.mean_conf is None else dist / (self.mean_conf * p2)
