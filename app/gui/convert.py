"""numpy float images <-> QImage, without sharing memory with the array.

A QImage may be built on any thread (a QPixmap only on the GUI thread): the views draw
:func:`display_qimage`'s QImages directly, built on a worker thread when they are large
(:class:`weft.app.gui.views.ImageView`).
"""

from __future__ import annotations

import numpy as np
from PySide6.QtGui import QImage


def to_qimage(image: np.ndarray) -> QImage:
    """A float32 [0, 1] (H, W) or (H, W, 3) array (or uint8) as a QImage that owns its pixels; with
    alpha, (H, W, 4) RGBA or (H, W, 2) grey+alpha (a fill of a transparent image), transparent where it is."""
    q, _pixels = _wrapped(image)
    return q.copy()  # detach from the numpy buffer


def _wrapped(image: np.ndarray) -> tuple[QImage, np.ndarray]:
    """A QImage over a uint8 copy of ``image`` (see :func:`to_qimage`), and that copy: the QImage
    reads it, so keep it alive as long as the QImage."""
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
    return q, arr


def display_qimage(image: np.ndarray) -> QImage:
    """``image`` as the view draws it (any thread): :func:`to_qimage` in the format a QPixmap made
    from it would hold on a raster screen (RGB32, or premultiplied ARGB32 with alpha), converted by
    Qt as ``QPixmap.fromImage`` converts it, so the pixels shown are the same and drawing needs no
    conversion on the GUI thread."""
    q, _pixels = _wrapped(image)  # (RGB888, Grayscale8 or RGBA8888: converting makes new pixels)
    fmt = QImage.Format.Format_ARGB32_Premultiplied if q.hasAlphaChannel() else QImage.Format.Format_RGB32
    return q.convertToFormat(fmt)
