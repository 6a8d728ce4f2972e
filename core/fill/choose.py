"""What ``--engine auto`` measures of a hole's surroundings to pick the engine for it."""

from __future__ import annotations

import cv2
import numpy as np

RING = 24  # px of known picture around the hole that are measured


def surroundings(image: np.ndarray, hole: np.ndarray, known: np.ndarray) -> dict[str, float]:
    """Statistics of the known pixels within :data:`RING` px of ``hole`` in ``image`` (H, W[, C]):

    * ``chroma``: the mean distance of a pixel's channels from their mean (0 on a grey picture);
    * ``energy``: the mean luminance gradient magnitude (8-bit levels per px);
    * ``flat``: the share of pixels whose gradient is below 2 levels per px (sky, skin, a wall);
    * ``regular``: the height of the strongest off-centre peak of the ring's normalised
      autocorrelation (0..1): near 1 for a repeating pattern (bricks, a weave), low for a
      stochastic texture or a photo;
    * ``border``: 1 when the hole touches the picture's border (an uncrop), else 0.
    """
    img = np.asarray(image, dtype=np.float32)
    lum = img if img.ndim == 2 else img[..., :3].mean(axis=2)
    d = cv2.distanceTransform((~hole).astype(np.uint8), cv2.DIST_L2, 3)
    ring = known & (d <= RING)
    if not ring.any():
        ring = known
    ys, xs = np.nonzero(ring)
    crop = (slice(ys.min(), ys.max() + 1), slice(xs.min(), xs.max() + 1))
    gx = cv2.Sobel(lum, cv2.CV_32F, 1, 0, ksize=3) / 8.0
    gy = cv2.Sobel(lum, cv2.CV_32F, 0, 1, ksize=3) / 8.0
    inner = cv2.erode(known.astype(np.uint8), np.ones((3, 3), np.uint8)).astype(bool) & ring
    g = np.hypot(gx, gy)[inner if inner.any() else ring] * 255.0
    stats = {"chroma": 0.0, "energy": float(g.mean()), "flat": float((g < 2.0).mean()),
             "regular": _regularity(lum[crop], ring[crop]),
             "border": float(hole[0].any() or hole[-1].any() or hole[:, 0].any() or hole[:, -1].any())}
    if img.ndim == 3 and img.shape[2] >= 3:
        rgb = img[..., :3][ring]
        stats["chroma"] = float(np.abs(rgb - rgb.mean(axis=1, keepdims=True)).mean() * 255.0)
    return stats


def _regularity(lum: np.ndarray, mask: np.ndarray) -> float:
    """The strongest off-centre peak (beyond 4 px) of the masked, mean-removed luminance's
    autocorrelation, normalised by its value at the centre."""
    h, w = lum.shape
    if mask.sum() < 64 or min(h, w) < 16:
        return 0.0
    v = np.where(mask, lum - lum[mask].mean(), 0.0).astype(np.float32)
    fh, fw = cv2.getOptimalDFTSize(2 * h), cv2.getOptimalDFTSize(2 * w)
    f = np.fft.rfft2(v, s=(fh, fw))
    m = np.fft.rfft2(mask.astype(np.float32), s=(fh, fw))
    ac = np.fft.irfft2(f * np.conj(f), s=(fh, fw))
    overlap = np.fft.irfft2(m * np.conj(m), s=(fh, fw))
    ac = np.fft.fftshift(ac)
    overlap = np.fft.fftshift(overlap)
    cy, cx = fh // 2, fw // 2
    zero = ac[cy, cx] / max(overlap[cy, cx], 1.0)
    if zero <= 1e-12:
        return 0.0
    norm = np.where(overlap > 0.25 * overlap[cy, cx], ac / np.maximum(overlap, 1.0), 0.0) / zero
    yy, xx = np.ogrid[:fh, :fw]
    norm[(yy - cy) ** 2 + (xx - cx) ** 2 <= 16] = 0.0
    return float(np.clip(norm.max(), 0.0, 1.0))
