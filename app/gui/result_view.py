"""The result view: an image view with a before/after split, a notice over the picture (what to draw,
a first run's preparing) and a mark when the result shown is out of date."""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QRectF, Qt
from PySide6.QtGui import QColor, QPen
from PySide6.QtWidgets import QGraphicsLineItem, QGraphicsRectItem, QLabel

from .display import DisplayConverter, ImageItem
from .views import ImageView


class ResultView(ImageView):
    """The result, with an optional before/after split: left of the divider shows ``compare_image``.

    With compare on, dragging with the left button moves the divider.
    """

    def __init__(self, parent=None, *, title: str = "result"):
        super().__init__(parent, title=title)
        self._clip = QGraphicsRectItem()
        self._clip.setPen(QPen(Qt.PenStyle.NoPen))
        self._clip.setFlag(QGraphicsRectItem.GraphicsItemFlag.ItemClipsChildrenToShape, True)
        self._before = ImageItem(self._clip)
        self._before_converter = DisplayConverter(self._show_compare, self)
        self._divider = QGraphicsLineItem()
        pen = QPen(QColor(255, 255, 255, 220), 0)
        self._divider.setPen(pen)
        self.scene().addItem(self._clip)
        self.scene().addItem(self._divider)
        self._clip.setZValue(1)
        self._divider.setZValue(2)
        self.compare_image: np.ndarray | None = None
        self.split = 0.5
        self.comparing = False
        self._dragging_split = False
        self._update_compare()
        self.notice = QLabel(self.viewport())
        self.notice.setObjectName("result-notice")
        self.notice.setAlignment(Qt.AlignmentFlag.AlignCenter)
        self.notice.setWordWrap(True)
        self.notice.setStyleSheet(
            "QLabel { background: rgba(20, 20, 20, 200); color: white; padding: 12px 18px;"
            " border-radius: 6px; font-size: 15px; }"
        )
        self.notice.hide()
        # "stale": the result on screen does not match the panel (its render failed); shown along
        # the top so the pixels stay visible, until a render succeeds
        self.stale = QLabel(self.viewport())
        self.stale.setObjectName("result-stale")
        self.stale.setWordWrap(True)
        self.stale.setStyleSheet(
            "QLabel { background: rgba(150, 30, 30, 220); color: white; padding: 6px 10px; font-size: 13px; }"
        )
        self.stale.hide()

    def set_stale(self, text: str | None) -> None:
        """Mark the result as not matching the panel (``text`` says why); None removes the mark."""
        if not text:
            self.stale.hide()
            return
        self.stale.setText(text)
        self.stale.setToolTip(text)
        self._place_stale()
        self.stale.show()

    def _place_stale(self) -> None:
        width = self.viewport().width()
        self.stale.setFixedWidth(width)
        self.stale.adjustSize()
        self.stale.move(0, 0)

    def set_notice(self, text: str | None) -> None:
        """Words shown over the middle of the result (e.g. what a long first run is doing); None hides them."""
        if not text:
            self.notice.hide()
            return
        self.notice.setText(text)
        self._place_notice()
        self.notice.show()

    def _place_notice(self) -> None:
        vp = self.viewport().rect()
        text = self.notice.fontMetrics().horizontalAdvance(self.notice.text()) + 48  # + padding
        width = max(min(vp.width() - 40, text), 120)
        self.notice.setFixedWidth(width)
        self.notice.adjustSize()
        self.notice.move(vp.center().x() - width // 2, vp.center().y() - self.notice.height() // 2)

    def resizeEvent(self, event):  # noqa: N802
        super().resizeEvent(event)
        if self.notice.isVisible():
            self._place_notice()
        if self.stale.isVisible():
            self._place_stale()

    def set_compare(self, image: np.ndarray | None) -> None:
        """The "before" image (e.g. the target), shown left of the divider when comparing (a large
        one once converted, as :meth:`set_image`)."""
        if image is not self._before_converter.latest:  # (the same one again: converted once)
            self._before_converter.request(image)

    def _show_compare(self, image: np.ndarray | None, q: tuple | None, _extra=None) -> None:
        self.compare_image = image
        if image is not None:
            self._before.set_qimage(q)
        self._update_compare()

    def set_comparing(self, on: bool) -> None:
        self.comparing = bool(on)
        self._update_compare()

    def set_split(self, fraction: float) -> None:
        self.split = float(np.clip(fraction, 0.0, 1.0))
        self._update_compare()

    def _image_changed(self) -> None:
        self._update_compare()

    def _update_compare(self) -> None:
        show = self.comparing and self.compare_image is not None and self.image is not None
        self._clip.setVisible(show)
        self._divider.setVisible(show)
        if not show:
            return
        w, h = self.image_size()
        bw = self._before.qimage().width() or 1
        bh = self._before.qimage().height() or 1
        self._before.setTransform(self._before.transform().fromScale(w / bw, h / bh))
        x = self.split * w
        self._clip.setRect(QRectF(0, 0, x, h))
        self._divider.setLine(x, 0, x, h)

    def mousePressEvent(self, event):  # noqa: N802
        if self.comparing and event.button() == Qt.MouseButton.LeftButton and not self._space:
            self._dragging_split = True
            self._drag_split(event)
            event.accept()
            return
        super().mousePressEvent(event)

    def mouseMoveEvent(self, event):  # noqa: N802
        if self._dragging_split:
            self._drag_split(event)
            event.accept()
            return
        super().mouseMoveEvent(event)

    def mouseReleaseEvent(self, event):  # noqa: N802
        if self._dragging_split:
            self._dragging_split = False
            event.accept()
            return
        super().mouseReleaseEvent(event)

    def _drag_split(self, event) -> None:
        w, _ = self.image_size()
        if w:
            self.set_split(self.mapToScene(event.position().toPoint()).x() / w)
