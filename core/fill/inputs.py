"""A fill's inputs as the engines take them: the image's colour and alpha, the masks' bits (a photo
given as a mask refused), the margins an uncrop adds, and the hole's interior regions.
"""

from __future__ import annotations

import cv2
import numpy as np

from ..errors import ImageError, InvalidParameter
from ..geometry import Margins, Mask
from ..image import validate_image
from .params import FillParams


def _error(cls, message: str, input: str | None = None, **kw):
    """A ``cls`` error with ``message`` that names the ``input`` it is about."""
    e = cls(message, **kw)
    e.input = input  # the CLI puts that input's file name in front
    return e


def _split_alpha(image: np.ndarray, what: str) -> tuple[np.ndarray, np.ndarray | None]:
    """``(colour (H, W) or (H, W, 3) float32, alpha (H, W) or None)`` of a validated image."""
    arr = np.asarray(image)
    if arr.ndim == 3 and arr.shape[2] in (2, 4):
        alpha = validate_image(np.ascontiguousarray(arr[..., -1]), f"{what}'s alpha")
        colour = validate_image(np.ascontiguousarray(arr[..., 0] if arr.shape[2] == 2 else arr[..., :3]), what)
        return colour, alpha
    if arr.ndim == 3 and arr.shape[2] == 1:
        arr = arr[..., 0]
    return validate_image(arr, what), None


def _mask_bits(mask, shape: tuple[int, int], what: str, against: str) -> np.ndarray:
    m = np.asarray(mask)
    if m.dtype != bool and not (m.ndim == 3 and m.shape[2] in (2, 4)):  # (with alpha: Mask.from_image reads it)
        m = np.asarray(validate_image(m, what))
    if m.shape[:2] != tuple(shape):
        raise _error(
            ImageError,
            f"the {what.replace('_', ' ')} is {m.shape[1]}x{m.shape[0]} but the {against} is "
            f"{shape[1]}x{shape[0]}; they must be the same size",
            what,
        )
    if m.dtype == bool:
        return m
    _black_and_white(m, what)
    return Mask.from_image(m.astype(np.float32), what).bits


#: A mask is refused when more than this share of its pixels is neither nearly black nor nearly white
#: (or is coloured): a photo given as the mask, not a painted mask with soft edges.
MAX_GREY_SHARE = 0.25


def _black_and_white(m: np.ndarray, what: str) -> None:
    """Refuse a mask that is not nearly black and white (a photo passed by mistake)."""
    arr = np.asarray(m, dtype=np.float32)
    if arr.ndim == 3 and arr.shape[2] in (2, 4):  # a transparent pixel reads as black
        arr = arr[..., :-1] * arr[..., -1:]
    grey = arr if arr.ndim == 2 else arr.mean(axis=2)
    odd = (grey > 0.1) & (grey < 0.9)
    if arr.ndim == 3 and arr.shape[2] >= 3:
        odd |= (arr.max(axis=2) - arr.min(axis=2)) > 0.1
    share = float(odd.mean())
    if share > MAX_GREY_SHARE:
        raise _error(
            ImageError,
            f"the {what.replace('_', ' ')} is not black and white: {share:.0%} of its pixels are "
            "grey or coloured (white = fill, black = keep; was a photo given as the mask?)",
            what,
        )


def _margins(params: FillParams, w: int, h: int) -> Margins | None:
    """The margins to add, or None when nothing grows the canvas (no --extend/--size, or a --size
    equal to the image's)."""
    if params.extend:
        return params.extend
    if params.size is None:
        return None
    sw, sh = params.size
    if sw < w or sh < h:
        raise _error(
            InvalidParameter,
            f"parameter 'size' = {sw}x{sh} is smaller than the {w}x{h} image (an uncrop only grows the canvas)",
            None,
            name="size",
            value=params.size,
        )
    dx, dy = sw - w, sh - h
    col = {"left": 0, "right": 2}.get(params.anchor.split("-")[-1], 1)
    row = {"top": 0, "bottom": 2}.get(params.anchor.split("-")[0], 1)
    left = (0, dx // 2, dx)[col]
    top = (0, dy // 2, dy)[row]
    return Margins(left, top, dx - left, dy - top) if dx or dy else None


def _as_like(image: np.ndarray, colour: bool) -> np.ndarray:
    if colour and image.ndim == 2:
        return np.repeat(image[..., None], 3, axis=2)
    if not colour and image.ndim == 3:
        from ..image import luminance

        return luminance(image)
    return image


def _interior(hole: np.ndarray) -> np.ndarray:
    """The connected regions of ``hole`` (8-connected) that do not touch the picture's border."""
    n, labels = cv2.connectedComponents(hole.astype(np.uint8), connectivity=8)
    touches = np.zeros(n, bool)
    touches[np.concatenate([labels[0], labels[-1], labels[:, 0], labels[:, -1]])] = True
    return hole & ~touches[labels]
