"""Shared helpers of the gallery scripts: captioned panels laid out in a grid (float RGB in [0, 1])."""

from __future__ import annotations

import cv2
import numpy as np


def rgb(img: np.ndarray) -> np.ndarray:
    """A grey image as three equal channels; colour passes through."""
    return np.repeat(img[..., None], 3, axis=2) if img.ndim == 2 else img


def label(img: np.ndarray, text: str) -> np.ndarray:
    """The panel with a caption strip underneath (one line per ``|``-separated part of ``text``)."""
    img = rgb(img)
    lines = text.split("|")
    strip = np.full((8 + 17 * len(lines), img.shape[1], 3), 255, np.uint8)
    for i, line in enumerate(lines):
        cv2.putText(strip, line.strip(), (6, 17 + 17 * i), cv2.FONT_HERSHEY_SIMPLEX, 0.42, (20, 20, 20), 1, cv2.LINE_AA)
    return np.concatenate([img, strip.astype(np.float32) / 255.0], axis=0)


def grid(panels: list[np.ndarray], cols: int, gap: int = 6) -> np.ndarray:
    """Panels left to right, top to bottom, ``cols`` a row, on white."""
    h = max(p.shape[0] for p in panels)
    w = max(p.shape[1] for p in panels)
    rows = -(-len(panels) // cols)
    out = np.ones((rows * h + (rows - 1) * gap, cols * w + (cols - 1) * gap, 3), np.float32)
    for i, p in enumerate(panels):
        r, c = divmod(i, cols)
        out[r * (h + gap) : r * (h + gap) + p.shape[0], c * (w + gap) : c * (w + gap) + p.shape[1]] = p
    return out
