"""The costs the quilting filler adds to a block's masked SSD (:mod:`weft.core.fill.quilt`, steps 4
and 5): correlations channel by channel, the coarse colour guide (a diffusion fill of the hole, its
chroma), and the thin-gap cost of a continued copy.
"""

from __future__ import annotations

import cv2
import numpy as np

#: A window's unknown pixels form a thin gap when none is farther than this (px) from a valued one.
GAP_WIDTH = 5.0
#: The source blocks are blurred by this sigma (px) to meet the gap's diffusion fill.
GAP_SIGMA = 1.5


def _chroma(img: np.ndarray) -> np.ndarray:
    """(H, W, 3) float32: the colour of ``img``'s first three channels less their mean (grey = 0)."""
    rgb = img[..., :3]
    return np.ascontiguousarray(rgb - rgb.mean(axis=2, keepdims=True), dtype=np.float32)


def _planes(img: np.ndarray) -> list[np.ndarray]:
    """The channels of (H, W, C) ``img`` as C contiguous (H, W) float32 arrays."""
    return [np.ascontiguousarray(img[..., k], dtype=np.float32) for k in range(img.shape[2])]


def _ccorr(planes: list[np.ndarray], crop: tuple[slice, slice], template: np.ndarray) -> np.ndarray:
    """``cv2.matchTemplate(image[crop], template, TM_CCORR)`` of the multi-channel image whose channels
    are ``planes``, as the sum of one single-channel correlation per channel, which is quicker than OpenCV's
    multi-channel correlation on a fill's crops and blocks (equal to float32 rounding)."""
    out: np.ndarray = cv2.matchTemplate(planes[0][crop], np.ascontiguousarray(template[..., 0]), cv2.TM_CCORR)
    for k in range(1, len(planes)):
        out += cv2.matchTemplate(planes[k][crop], np.ascontiguousarray(template[..., k]), cv2.TM_CCORR)
    return out


def _coarse_guide(canvas: np.ndarray, hole: np.ndarray, scale: int) -> np.ndarray:
    """(H, W, C) float32: the hole filled by diffusion (cv2.inpaint, Telea) at 1/scale, brought back
    to full size; the known pixels' own values elsewhere (only the hole's are read)."""
    h, w, c = canvas.shape
    sh, sw = max(1, h // scale), max(1, w // scale)
    small = cv2.resize(canvas, (sw, sh), interpolation=cv2.INTER_AREA).reshape(sh, sw, c)
    cover = cv2.resize(hole.astype(np.float32), (sw, sh), interpolation=cv2.INTER_AREA)
    known_share = np.maximum(1.0 - cover, 1e-6)[..., None]
    small = small / known_share  # the mean of the known pixels alone (the hole is 0 in the canvas)
    up = cv2.resize(_telea(small, cover > 0.5), (w, h), interpolation=cv2.INTER_LINEAR).reshape(h, w, c)
    return np.ascontiguousarray(up, dtype=np.float32)


def _telea(img: np.ndarray, unknown: np.ndarray) -> np.ndarray:
    """(H, W, C) float32: ``img`` in 8-bit levels, its ``unknown`` pixels (bool (H, W)) filled by
    diffusion from the others (``cv2.inpaint``, Telea, radius 3, channel by channel)."""
    mask = unknown.astype(np.uint8)
    out = np.empty(img.shape, dtype=np.float32)
    for k in range(img.shape[2]):
        ch8 = np.clip(np.rint(img[..., k] * 255), 0, 255).astype(np.uint8)
        out[..., k] = (cv2.inpaint(ch8, mask, 3, cv2.INPAINT_TELEA) if mask.any() else ch8).astype(np.float32) / 255.0
    return out


def _gap_cost(
    template: np.ndarray, unknown: np.ndarray, search: np.ndarray, crop: tuple[slice, slice], blurred: list[np.ndarray]
) -> np.ndarray | None:
    """Step 5's thin-gap cost of every block position of ``search[crop]``, or None when the window's
    ``unknown`` pixels (float32 0/1) are no thin gap (one lies more than :data:`GAP_WIDTH` px from a
    valued pixel): the SSD, over those pixels, between the window's diffusion fill (``cv2.inpaint``,
    Telea, radius 3, from its valued pixels) and the source block blurred by :data:`GAP_SIGMA`.
    ``blurred`` caches the blurred source (its channel planes, then their summed squares)."""
    gap = unknown > 0
    if float(cv2.distanceTransform(gap.astype(np.uint8), cv2.DIST_L2, 3).max()) > GAP_WIDTH:
        return None
    if not blurred:
        soft = cv2.GaussianBlur(search, (0, 0), GAP_SIGMA).reshape(search.shape)
        blurred.extend(_planes(soft))
        blurred.append(np.ascontiguousarray((soft * soft).sum(axis=2)))
    est = _telea(template, gap)
    g = np.ascontiguousarray(est * unknown[..., None])
    out = cv2.matchTemplate(blurred[-1][crop], unknown, cv2.TM_CCORR) - 2.0 * _ccorr(blurred[:-1], crop, g)
    out += float((g * est).sum())
    return np.maximum(out, 0.0)
