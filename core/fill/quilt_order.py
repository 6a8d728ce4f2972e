"""The quilting filler's fill-front order (:mod:`weft.core.fill.quilt`, step 1): each front pixel's
score, the count of valued pixels in its window (times the structure term on colour pictures), and
the first maximum of the scores, kept by strips.
"""

from __future__ import annotations

import cv2
import numpy as np

#: Weight of the structure term in the fill order (step 1; colour images only); 0 = the count alone.
DATA = 3.0


def _edges(canvas: np.ndarray, known: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The structure term's inputs (step 1): float32 (H, W) gradient magnitude of the known pixels
    whose 3x3 neighbourhood is known (0 elsewhere, ~normalised by its mean there) and that mask."""
    grey = canvas.mean(axis=2).astype(np.float32)
    gx = cv2.Sobel(grey, cv2.CV_32F, 1, 0, ksize=3)
    gy = cv2.Sobel(grey, cv2.CV_32F, 0, 1, ksize=3)
    inner = (
        cv2.erode(known.astype(np.uint8), np.ones((3, 3), np.uint8), borderType=cv2.BORDER_CONSTANT, borderValue=1) > 0
    )
    mag = np.where(inner, np.sqrt(gx * gx + gy * gy), 0.0).astype(np.float32)
    mean = float(mag[inner].mean()) if inner.any() else 0.0
    return (mag / mean if mean > 0 else mag), inner.astype(np.float32)


def _score(
    have: np.ndarray,
    score: np.ndarray,
    b: int,
    y0: int,
    y1: int,
    x0: int,
    x1: int,
    edges: tuple[np.ndarray, np.ndarray] | None = None,
) -> None:
    """Recompute ``score`` (see :func:`fill_quilt`) on rows ``[y0, y1)`` and columns ``[x0, x1)``."""
    h, w = have.shape
    m = b // 2 + 2  # context the box filter and the front's dilation read around the region
    ya, yb, xa, xb = max(0, y0 - m), min(h, y1 + m), max(0, x0 - m), min(w, x1 + m)
    sub = have[ya:yb, xa:xb]
    # the window of a centre pixel: rows [y - b//2, y - b//2 + b) (cv2's anchor for even sizes too)
    count = cv2.boxFilter(sub.astype(np.float32), -1, (b, b), normalize=False, borderType=cv2.BORDER_CONSTANT)
    near = (
        cv2.dilate(sub.astype(np.uint8), np.ones((3, 3), np.uint8), borderType=cv2.BORDER_CONSTANT, borderValue=0) > 0
    )
    front = ~sub & near
    if edges is not None:  # step 1's structure term: count x (1 + DATA g / G)
        mag, inner = edges[0][ya:yb, xa:xb], edges[1][ya:yb, xa:xb]
        g = cv2.boxFilter(mag, -1, (b, b), normalize=False, borderType=cv2.BORDER_CONSTANT)
        n = cv2.boxFilter(inner, -1, (b, b), normalize=False, borderType=cv2.BORDER_CONSTANT)
        count = count * (1.0 + DATA * g / np.maximum(n, 1.0))
    part = np.where(front, count, -1.0)
    score[y0:y1, x0:x1] = part[y0 - ya : y1 - ya, x0 - xa : x1 - xa]


#: Rows per strip of :class:`_Front`.
_STRIP = 32


class _Front:
    """The first maximum of ``score`` in scan order (``np.argmax``'s answer), found through the
    maxima of its strips of :data:`_STRIP` rows: ``update(y0, y1)`` after rows ``[y0, y1)`` of it
    changed, so that a block does not search the whole score of a large picture."""

    def __init__(self, score: np.ndarray):
        self.score = score
        self.maxima = np.empty(-(-score.shape[0] // _STRIP), dtype=score.dtype)
        self.update(0, score.shape[0])

    def update(self, y0: int, y1: int) -> None:
        for k in range(y0 // _STRIP, -(-y1 // _STRIP)):
            self.maxima[k] = self.score[k * _STRIP : (k + 1) * _STRIP].max()

    def first_max(self) -> tuple[int, int]:
        k = int(np.argmax(self.maxima))  # the first strip holding the maximum, then its first in scan order
        y, x = divmod(int(np.argmax(self.score[k * _STRIP : (k + 1) * _STRIP])), self.score.shape[1])
        return k * _STRIP + y, x
