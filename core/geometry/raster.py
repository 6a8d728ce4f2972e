"""Raster painting: a round brush line painted into a bool array in place."""

from __future__ import annotations

import math

import numpy as np


def paint_line(bits: np.ndarray, p0, p1, radius: float, value: bool = True) -> tuple[int, int, int, int] | None:
    """Paint :meth:`Mask.painted_line`'s brush line into ``bits`` in place.

    Only the line's box is read and written, so a dab costs the dab, not a copy of the mask.

    Parameters
    ----------
    bits : ndarray, bool (H, W)
        The mask's bits, changed in place.
    p0, p1 : (float, float)
        The line's ends, image pixels.
    radius : float
        The brush's radius, pixels.
    value : bool, default True
        Paint (True) or erase (False).

    Returns
    -------
    (int, int, int, int) or None
        The box ``(x0, y0, x1, y1)`` (exclusive ends) whose pixels changed, None if none did.
    """
    h, w = bits.shape
    (x0, y0), (x1, y1) = (float(p0[0]), float(p0[1])), (float(p1[0]), float(p1[1]))
    r = max(0.0, float(radius)) + 0.5  # a pixel is hit when its centre is within radius (+ half a pixel)
    left, right = max(0, int(math.floor(min(x0, x1) - r))), min(w, int(math.ceil(max(x0, x1) + r)) + 1)
    top, bottom = max(0, int(math.floor(min(y0, y1) - r))), min(h, int(math.ceil(max(y0, y1) + r)) + 1)
    if left >= right or top >= bottom:
        return None  # the line misses the image
    yy, xx = np.mgrid[top:bottom, left:right].astype(np.float64)
    dx, dy = x1 - x0, y1 - y0
    length2 = dx * dx + dy * dy
    t = np.zeros_like(xx) if length2 == 0 else np.clip(((xx - x0) * dx + (yy - y0) * dy) / length2, 0.0, 1.0)
    hit = (xx - x0 - t * dx) ** 2 + (yy - y0 - t * dy) ** 2 < r * r
    part = bits[top:bottom, left:right]
    hit &= part != bool(value)  # the pixels this line changes
    rows, cols = np.flatnonzero(hit.any(axis=1)), np.flatnonzero(hit.any(axis=0))
    if not len(rows):
        return None
    part[hit] = bool(value)
    return left + int(cols[0]), top + int(rows[0]), left + int(cols[-1]) + 1, top + int(rows[-1]) + 1
