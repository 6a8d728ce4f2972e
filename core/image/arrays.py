"""Validating and resizing image arrays: float32 in [0, 1], (H, W) or (H, W, 3)."""

from __future__ import annotations

import numbers

import cv2
import numpy as np

from ..errors import ImageError, InvalidParameter
from .colour import _check_float_image


def validate_image(image: np.ndarray, what: str = "image") -> np.ndarray:
    """Check an image and return it as C-contiguous float32 in [0, 1] (the input itself if it is one).

    Parameters
    ----------
    image : ndarray
        (H, W) or (H, W, 3); float in [0, 1] without NaN/inf, or uint8 (/255) or uint16 (/65535).
    what : str, default "image"
        Name used in error messages ("texture", "target", ...).

    Raises
    ------
    ImageError
        Wrong shape, empty, unsupported dtype, non-finite or out-of-range values.
    """
    image = _check_float_image(image, what)
    if image.dtype in (np.uint8, np.uint16):
        return np.ascontiguousarray(image, dtype=np.float32) / np.float32(np.iinfo(image.dtype).max)
    if not np.issubdtype(image.dtype, np.floating):
        raise ImageError(f"{what} has unsupported dtype {image.dtype} (use float in [0, 1], uint8 or uint16)")
    image = np.ascontiguousarray(image, dtype=np.float32)
    if not np.isfinite(image).all():
        raise ImageError(f"{what} contains NaN or infinite values")
    low, high = float(image.min()), float(image.max())
    if low < 0.0 or high > 1.0:
        raise ImageError(f"{what} has values outside [0, 1] (min {low:.4g}, max {high:.4g})")
    return image


_INTERPOLATIONS = {
    "cubic": cv2.INTER_CUBIC,
    "linear": cv2.INTER_LINEAR,
    "area": cv2.INTER_AREA,
    "nearest": cv2.INTER_NEAREST_EXACT,
}


def resize(image: np.ndarray, size: tuple[int, int], interpolation: str = "cubic") -> np.ndarray:
    """Resize to ``size = (width, height)`` (each >= 1); float32, same channel count as the input.

    Parameters
    ----------
    image : ndarray
        Anything :func:`validate_image` accepts.
    size : (int, int)
        Output width and height.
    interpolation : {"cubic", "linear", "area", "nearest"}, default "cubic"
        OpenCV bicubic (result clipped to [0, 1]), bilinear, pixel-area (best for shrinking) or
        nearest neighbour (``INTER_NEAREST_EXACT``: pixel centres, as Pillow and scikit-image).
    """
    image = validate_image(image)
    if not (
        isinstance(size, (tuple, list))
        and len(size) == 2
        and all(isinstance(s, numbers.Integral) and not isinstance(s, bool) and s >= 1 for s in size)
    ):
        raise InvalidParameter(
            f"parameter 'size' = {size!r} must be (width, height), both >= 1", name="size", value=size
        )
    if interpolation not in _INTERPOLATIONS:
        raise InvalidParameter(
            f"parameter 'interpolation' = {interpolation!r} is not one of {', '.join(_INTERPOLATIONS)}",
            name="interpolation",
            value=interpolation,
        )
    out = cv2.resize(image, (int(size[0]), int(size[1])), interpolation=_INTERPOLATIONS[interpolation])
    return np.clip(out, 0.0, 1.0, out=out) if interpolation == "cubic" else out
