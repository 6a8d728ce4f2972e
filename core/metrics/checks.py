"""Checking the arguments of the quality figures: images large enough for a patch, whole numbers."""

from __future__ import annotations

import numpy as np

from ..errors import ImageError, InvalidParameter
from ..image import validate_image

MIN_SIDE = 7


def _check_image(image, what: str, min_side: int = MIN_SIDE) -> np.ndarray:
    """``image`` as float32 in [0, 1] (uint8/uint16 are rescaled) after checking its shape and size."""
    arr = validate_image(image, what)
    h, w = arr.shape[:2]
    if h < min_side or w < min_side:
        raise ImageError(f"{what} is {w}x{h}; it must be at least {min_side}x{min_side} pixels")
    return arr


def _check_int(name: str, value, lo: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise InvalidParameter(f"parameter '{name}' = {value!r} must be an integer", name=name, value=value)
    if value < lo:
        raise InvalidParameter(f"parameter '{name}' = {value} is outside {lo}..inf", name=name, value=value)
    return int(value)
