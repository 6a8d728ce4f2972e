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


def display_qimage(image: np.ndarray) -> tuple[QImage, np.ndarray]:
    """``image`` as the view draws it, on any thread: ``(qimage, pixels)``, a QImage over ``pixels``
    (keep them together) in the format a QPixmap made from :func:`to_qimage` holds on a raster screen
    -- RGB32, or premultiplied ARGB32 with alpha, premultiplied as Qt's ``qPremultiply`` does -- so
    the pixels shown are the same and drawing converts nothing on the GUI thread. Built in numpy
    only, which leaves Python's GIL to the GUI thread: Qt's ``QImage.copy`` and ``convertToFormat``
    hold it for the whole conversion."""
    arr = np.asarray(image)
    h, w = arr.shape[:2]
    if arr.dtype == np.uint8:
        scaled = arr
    else:  # as to_qimage: clip(x, 0, 1) * 255 + 0.5, truncated
        scaled = np.multiply(arr, np.float32(255.0), dtype=np.float32)
        scaled += np.float32(0.5)
        np.clip(scaled, np.float32(0.0), np.float32(255.5), out=scaled)
    if scaled.ndim == 3 and scaled.shape[2] == 1:
        scaled = scaled[..., 0]
    grey = scaled.ndim == 2 or scaled.shape[2] == 2
    has_alpha = scaled.ndim == 3 and scaled.shape[2] in (2, 4)
    pixels = np.empty((h, w, 4), dtype=np.uint8)  # B, G, R, A in memory: a 32-bit ARGB word on little-endian
    for i, c in enumerate((2, 1, 0)):
        pixels[..., i] = scaled if scaled.ndim == 2 else scaled[..., 0 if grey else c]
    if has_alpha:
        pixels[..., 3] = scaled[..., -1]
        a = pixels[..., 3:4].astype(np.uint16)
        t = pixels[..., :3] * a  # qPremultiply: (t + (t >> 8) + 0x80) >> 8
        t += (t >> 8) + 0x80
        pixels[..., :3] = t >> 8
        fmt = QImage.Format.Format_ARGB32_Premultiplied
    else:
        pixels[..., 3] = 255
        fmt = QImage.Format.Format_RGB32
    if not np.little_endian:  # (a big-endian word is A, R, G, B in memory)
        pixels = np.ascontiguousarray(pixels[..., ::-1])
    return QImage(pixels.data, w, h, pixels.strides[0], fmt), pixels
