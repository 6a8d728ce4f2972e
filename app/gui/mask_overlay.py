"""A painted mask drawn over its image in a translucent colour of its own.

Each mask an image carries has its own colour (:data:`MASK_COLOURS`, in the order of the method's
studio description: the first, a hole, red; the second, a sampling area, green), so two masks on
one image read apart. A stroke redraws only the pixels around each dab (:meth:`MaskOverlay.update_box`).
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QPointF, QRectF
from PySide6.QtGui import QImage
from PySide6.QtWidgets import QGraphicsItem
from weft.core.geometry import Mask, MaskStroke

#: The colours (RGBA) of the masks of one image, in the order the method lists them.
MASK_COLOURS = ((255, 48, 96, 120), (40, 220, 120, 64), (64, 160, 255, 100), (255, 200, 40, 100))
MASK_RGBA = MASK_COLOURS[0]  # the first mask's colour


def colour_word(rgba) -> np.uint32:
    """The four bytes of ``rgba`` as one 32-bit word in memory order (any byte order)."""
    return np.array(rgba, dtype=np.uint8).view(np.uint32)[0]


class MaskOverlay(QGraphicsItem):
    """The mask drawn over its image: its colour where it is set, transparent elsewhere. A stroke
    updates only the pixels around each dab (:meth:`update_box`), so painting costs the dab's area,
    not the image's."""

    def __init__(self, rgba=MASK_RGBA):
        super().__init__()
        self.rgba = tuple(rgba)
        self._word = colour_word(rgba)
        self._rgba: np.ndarray | None = None  # (H, W, 4) uint8: the QImage's pixels (kept alive with it)
        self._image = QImage()
        # what is drawn: a mask (immutable: the same one is not redrawn), or the stroke being painted
        self._mask: Mask | MaskStroke | None = None

    def image(self) -> QImage:
        """What is drawn (a null image when the mask is empty or none)."""
        return self._image

    def set_mask(self, mask: Mask | MaskStroke | None) -> None:
        """Draw ``mask`` (None or empty: nothing; or a stroke's bits so far); nothing to do if that
        very mask is drawn already (every parameter change syncs the tools: no rebuild of a large
        overlay then)."""
        if mask is self._mask:
            return
        self._mask = mask
        if mask is None or (isinstance(mask, Mask) and not mask):
            self._show(None)
        else:
            h, w = mask.shape
            # one multiply of the bits by the colour as a 32-bit word, not a boolean-indexed assignment
            # (a GUI-thread stall at each undo, Clear, session open for a large mask)
            rgba = np.empty((h, w), dtype=np.uint32)
            np.multiply(mask.bits, self._word, out=rgba, casting="unsafe")
            self._show(rgba)

    def _show(self, words: np.ndarray | None) -> None:
        """Draw the (H, W) uint32 colour words ``words`` (None: nothing)."""
        self.prepareGeometryChange()
        if words is None:
            self._rgba, self._image = None, QImage()
        else:
            h, w = words.shape
            self._rgba = words.view(np.uint8).reshape(h, w, 4)
            self._image = QImage(self._rgba.data, w, h, 4 * w, QImage.Format.Format_RGBA8888)
        self.update()

    def begin(self, stroke: MaskStroke, start: Mask | None) -> None:
        """A stroke begins on ``start``, the document's mask (None: nothing painted): draw the stroke
        from now on. No redraw when ``start`` is what is drawn; a stroke on no mask starts from its
        own bits (blank, calloc'd: pages made as the stroke paints them; or all set)."""
        if start is not None and start is self._mask and self._rgba is not None:
            self._mask = stroke
        elif start is None and not stroke.bits.any():
            self._mask = stroke
            self._show(np.zeros(stroke.shape, dtype=np.uint32))
        else:
            self._mask = None
            self.set_mask(stroke)

    def adopt(self, mask: Mask | None) -> None:
        """``mask`` has the very bits drawn now (the stroke just ended became it): it is what is drawn,
        with no redraw (None: the overlay shows nothing painted, and is dropped)."""
        if mask is None:
            self.set_mask(None)
        else:
            self._mask = mask

    def update_box(self, mask: Mask | MaskStroke, box: tuple[int, int, int, int]) -> None:
        """Redraw ``box`` = (x0, y0, x1, y1) of ``mask`` (a mask, or the stroke being painted, of the
        same size as the one shown); ``mask`` is then what is drawn."""
        if self._rgba is None or self._rgba.shape[:2] != mask.shape:
            self.set_mask(mask)
            return
        self._mask = mask
        x0, y0, x1, y1 = box
        h, w = mask.shape
        x0, y0, x1, y1 = max(0, x0), max(0, y0), min(w, x1), min(h, y1)
        if x0 >= x1 or y0 >= y1:
            return
        words = self._rgba.view(np.uint32).reshape(h, w)
        np.multiply(mask.bits[y0:y1, x0:x1], self._word, out=words[y0:y1, x0:x1], casting="unsafe")
        self.update(QRectF(x0, y0, x1 - x0, y1 - y0))

    def boundingRect(self) -> QRectF:  # noqa: N802 (Qt naming)
        return QRectF(0, 0, self._image.width(), self._image.height())

    def paint(self, painter, option, widget=None) -> None:
        if not self._image.isNull():
            painter.drawImage(QPointF(0, 0), self._image)
