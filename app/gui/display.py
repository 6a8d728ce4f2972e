"""Showing a float image in a view without blocking the GUI thread.

The GUI thread never converts a large image: an image of more than ``ASYNC_PIXELS`` pixels is turned
into the QImage the view draws (:func:`~weft.app.gui.convert.display_qimage`, numpy only, so the
worker leaves Python's GIL to the GUI thread) on a worker thread, and the view keeps showing the
previous image until it is ready (``image_shown`` then; ``image`` is always the image on screen). A
view draws that QImage itself: no QPixmap (which only the GUI thread may make, 35 ms for a 4096²
image) is made. Requests made while one is converted are coalesced: the newest is converted next,
and a conversion older than what is on screen is dropped. ``set_image(image, changed=box)`` redraws
only a part of the array on screen changed in place (a stroke's preview pasted into the result).
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np
from PySide6.QtCore import QObject, QPointF, QRectF, Signal
from PySide6.QtGui import QImage, QPainter
from PySide6.QtWidgets import QGraphicsItem

from .convert import display_qimage

#: Images of more pixels than this are converted for display on a worker thread (display_qimage:
#: 0.4 ms for 512², 10 ms for 1024², 39 ms for 2048², 145 ms for 4096², median of 7, loaded machine).
ASYNC_PIXELS = 512 * 512
#: A part of the image on screen changed in place of at most this many pixels is converted on the GUI
#: thread (``set_image(changed=)``: a stroke's preview), not the whole image on a worker: 2048² in 9 ms
#: grey, 14 ms RGB (1024² in 3 and 2.4 ms; medians of 5, a quiet machine). At 1024², the part a 4096²
#: picture's preview changes (its crop, up to ~1100x1200 px once dabs coalesced) outgrew it; the whole
#: picture then went to the worker (~150 ms), every later preview waited behind that conversion, and
#: previews reached the screen in bursts: medians 86-130 ms instead of ~31 ms in such runs.
PART_PIXELS = 2048 * 2048

_converters = ThreadPoolExecutor(max_workers=2, thread_name_prefix="weft-display")


class ImageItem(QGraphicsItem):
    """Draws a QImage (made on any thread) at the scene's origin, one scene unit per pixel, as a
    ``QGraphicsPixmapItem`` with fast transformation draws its pixmap."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self._image = QImage()
        self._pixels: np.ndarray | None = None  # the buffer the QImage reads (kept alive with it)

    def qimage(self) -> QImage:
        return self._image

    def pixels(self) -> np.ndarray | None:
        """The (H, W, 4) buffer the QImage reads (a part written there shows at the next paint), or None."""
        return self._pixels

    def set_qimage(self, shown: tuple[QImage, np.ndarray] | None) -> None:
        """Draw ``shown`` = :func:`~weft.app.gui.convert.display_qimage`'s (QImage, pixels); None: nothing."""
        self.prepareGeometryChange()
        self._image, self._pixels = (QImage(), None) if shown is None else shown
        self.update()

    def boundingRect(self) -> QRectF:  # noqa: N802 (Qt naming)
        return QRectF(0, 0, self._image.width(), self._image.height())

    def paint(self, painter, option, widget=None) -> None:
        if not self._image.isNull():
            painter.setRenderHint(QPainter.RenderHint.SmoothPixmapTransform, False)
            painter.drawImage(QPointF(0, 0), self._image)


class DisplayConverter(QObject):
    """Turns images into what a view draws and hands it to ``show(image, (qimage, pixels), extra)``
    on the GUI thread: at once when small, else from a worker thread (module docstring). One
    conversion at a time per converter; :meth:`request` while one runs replaces the waiting request."""

    _converted = Signal(int, object, object, object)  # generation, image, (QImage, pixels) or the error, extra

    def __init__(self, show: Callable[[np.ndarray | None, tuple | None, Any], None], parent=None):
        super().__init__(parent)
        self._show = show
        self._generation = 0  # of the latest request
        self._shown = 0  # of what is on screen
        self._waiting: tuple[int, np.ndarray, Any] | None = None
        self._running = False
        self.latest: np.ndarray | None = None  # the image of the latest request
        self._converted.connect(self._on_converted)

    @property
    def pending(self) -> bool:
        """A requested image is not on screen yet."""
        return self._shown != self._generation

    def shown_now(self) -> None:
        """What is on screen was changed by its owner (a part redrawn): newer than any conversion running."""
        self._generation += 1
        self._shown = self._generation
        self._waiting = None

    def request(self, image: np.ndarray | None, extra: Any = None) -> None:
        self._generation += 1
        self.latest = image
        if image is None or image.shape[0] * image.shape[1] <= ASYNC_PIXELS:
            self._waiting = None
            self._shown = self._generation
            self._show(image, None if image is None else display_qimage(image), extra)
            return
        self._waiting = (self._generation, image, extra)
        if not self._running:
            self._start()

    def _start(self) -> None:
        generation, image, extra = self._waiting
        self._waiting = None
        self._running = True
        done = self._converted

        def work() -> None:
            try:
                q: Any = display_qimage(image)
            except Exception as e:  # raised on the GUI thread
                q = e
            try:
                done.emit(generation, image, q, extra)
            except RuntimeError:  # the view is gone
                pass

        _converters.submit(work)

    def _on_converted(self, generation: int, image, q, extra) -> None:
        self._running = False
        if self._waiting is not None:
            self._start()
        if isinstance(q, Exception):
            raise q
        if generation > self._shown:  # (older than what is on screen: dropped)
            self._shown = generation
            self._show(image, q, extra)
