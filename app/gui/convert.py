"""numpy float images <-> QImage, without sharing memory with the array."""

from __future__ import annotations

import numpy as np
from PySide6.QtGui import QImage


def to_qimage(image: np.ndarray) -> QImage:
    """A float32 [0, 1] (H, W) or (H, W, 3) array (or uint8) as a QImage that owns its pixels; with
    alpha, (H, W, 4) RGBA or (H, W, 2) grey+alpha (a fill of a transparent image), transparent where it is."""
    arr = np.asarray(image)
    if arr.dtype != np.uint8:
        arr = (np.clip(arr, 0.0, 1.0) * 255.0 + 0.5).astype(np.uint8)
    arr = np.ascontiguousarray(arr)
    h, w = arr.shape[:2]
    if arr.ndim == 3 and arr.shape[2] == 2:
        arr = np.ascontiguousarray(arr[..., [0, 0, 0, 1]])
    if arr.ndim == 3 and arr.shape[2] == 4:
        q = QImage(arr.data, w, h, arr.strides[0], QImage.Format.Format_RGBA8888)
    elif arr.ndim == 2:
        q = QImage(arr.data, w, h, arr.strides[0], QImage.Format.Format_Grayscale8)
    else:
        q = QImage(arr.data, w, h, arr.strides[0], QImage.Format.Format_RGB888)
    return q.copy()  # detach from the numpy buffer
