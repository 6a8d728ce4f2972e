"""Image views: zoom under the mouse, pan, fit, 1:1, pixel read-out, drop of files, mouse tools.

``ImageView`` shows one float image. Wheel zooms under the cursor; middle-drag, or left-drag with
Space held (or with no tool active), pans; ``fit()`` and ``actual_size()`` reset the zoom. A *tool*
(``weft.app.gui.tools``) may be attached: it receives the left-button events in image coordinates and
draws its overlay items in the view's scene. ``ResultView`` adds a before/after split.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PySide6.QtCore import QRectF, Qt, Signal
from PySide6.QtGui import QColor, QPainter, QPen, QPixmap
from PySide6.QtWidgets import (QGraphicsLineItem, QGraphicsPixmapItem, QGraphicsRectItem, QGraphicsScene, QGraphicsView,
                               QLabel)

from .convert import to_qimage

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp", ".webp")


class ImageView(QGraphicsView):
    """A zoomable, pannable view of one image.

    Signals: ``hovered(x, y)`` in image pixels (-1, -1 outside), ``zoomed(scale)``,
    ``file_dropped(path)`` when an image file is dropped on it.
    """

    hovered = Signal(int, int)
    zoomed = Signal(float)
    file_dropped = Signal(str)

    def __init__(self, parent=None, *, title: str = ""):
        super().__init__(parent)
        self.title = title
        self.setScene(QGraphicsScene(self))
        self._item = QGraphicsPixmapItem()
        self._item.setTransformationMode(Qt.TransformationMode.FastTransformation)
        self.scene().addItem(self._item)
        self.image: np.ndarray | None = None
        self.tool = None
        self.auto_fit = True  # keep fitting the image to the window until the user zooms
        self._frame: QRectF | None = None  # a tool's frame around the image (an uncrop's grown canvas)
        self._pan_from = None
        self._space = False
        self.setTransformationAnchor(QGraphicsView.ViewportAnchor.NoAnchor)
        self.setResizeAnchor(QGraphicsView.ViewportAnchor.AnchorViewCenter)
        self.setDragMode(QGraphicsView.DragMode.NoDrag)
        self.setRenderHint(QPainter.RenderHint.SmoothPixmapTransform, False)
        self.setMouseTracking(True)
        self.setAcceptDrops(True)
        self.setBackgroundBrush(QColor(60, 60, 60))
        self.setFocusPolicy(Qt.FocusPolicy.StrongFocus)

    # --- image ---------------------------------------------------------------------------------
    def set_image(self, image: np.ndarray | None, *, fit: bool = False) -> None:
        """Show ``image`` (float32 [0, 1]); ``fit`` also fits it to the window, as does an image of
        another size while the view is fitting (the user has not zoomed)."""
        first = self.image is None
        resized = not first and image is not None and self.image.shape[:2] != image.shape[:2]
        self.image = image
        if image is None:
            self._item.setPixmap(QPixmap())
            return
        self._item.setPixmap(QPixmap.fromImage(to_qimage(image)))
        self._set_scene_rect()
        if fit or first or (resized and self.auto_fit):
            self.fit()
        self.viewport().update()

    def set_frame(self, rect: QRectF | None, *, fit: bool = True) -> None:
        """A tool draws a frame around the image (the grown canvas of an uncrop): the scene keeps
        room around the image and the frame, to drag its edges in; None: just the image."""
        if rect == self._frame:
            return
        self._frame = rect
        self._set_scene_rect()
        if fit and self.auto_fit and self.image is not None:
            self.fit()

    def _set_scene_rect(self) -> None:
        rect = self._item.boundingRect()
        if self._frame is not None and not rect.isEmpty():
            room = 0.12 * max(rect.width(), rect.height())
            rect = rect.united(self._frame).adjusted(-room, -room, room, room)
        self.scene().setSceneRect(rect)

    def _fitted(self) -> QRectF:
        return self.sceneRect() if self._frame is not None else self._item.sceneBoundingRect()

    def image_size(self) -> tuple[int, int]:
        return (0, 0) if self.image is None else (self.image.shape[1], self.image.shape[0])

    # --- zoom ----------------------------------------------------------------------------------
    def scale_factor(self) -> float:
        return self.transform().m11()

    def fit(self) -> None:
        self.auto_fit = True
        if self.image is not None:
            self.fitInView(self._fitted(), Qt.AspectRatioMode.KeepAspectRatio)
            self.zoomed.emit(self.scale_factor())

    def actual_size(self) -> None:
        self.auto_fit = False
        self.resetTransform()
        self.zoomed.emit(1.0)

    def resizeEvent(self, event):  # noqa: N802
        super().resizeEvent(event)
        if self.auto_fit and self.image is not None:
            self.fitInView(self._fitted(), Qt.AspectRatioMode.KeepAspectRatio)
            self.zoomed.emit(self.scale_factor())  # the % label follows a refit on resize

    def zoom_by(self, factor: float, at=None) -> None:
        """Zoom by ``factor`` keeping the image point under view position ``at`` (default: centre) fixed."""
        new = self.scale_factor() * factor
        if not 1 / 64 <= new <= 64:
            return
        self.auto_fit = False
        if at is None:
            at = self.viewport().rect().center()
        anchor = self.mapToScene(at)
        self.scale(factor, factor)
        moved = self.mapFromScene(anchor) - at
        self.horizontalScrollBar().setValue(self.horizontalScrollBar().value() + moved.x())
        self.verticalScrollBar().setValue(self.verticalScrollBar().value() + moved.y())
        self.zoomed.emit(self.scale_factor())

    def wheelEvent(self, event):  # noqa: N802 (Qt naming)
        steps = event.angleDelta().y() / 120.0
        if steps:
            self.zoom_by(1.25 ** steps, at=event.position().toPoint())
        event.accept()

    # --- coordinates ---------------------------------------------------------------------------
    def image_pos(self, view_pos) -> tuple[int, int]:
        p = self.mapToScene(view_pos)
        x, y = int(np.floor(p.x())), int(np.floor(p.y()))
        if self.image is None or not (0 <= x < self.image.shape[1] and 0 <= y < self.image.shape[0]):
            return -1, -1
        return x, y

    def screen_to_image_distance(self, pixels: float) -> float:
        """How many image pixels ``pixels`` screen pixels span at the current zoom."""
        return pixels / max(self.scale_factor(), 1e-6)

    # --- mouse: tools and panning --------------------------------------------------------------
    def _panning(self, event) -> bool:
        return event.button() == Qt.MouseButton.MiddleButton or (
            event.button() == Qt.MouseButton.LeftButton and (self._space or self.tool is None))

    def mousePressEvent(self, event):  # noqa: N802
        if self._panning(event):
            self._pan_from = event.position()
            self.viewport().setCursor(Qt.CursorShape.ClosedHandCursor)
            event.accept()
            return
        if self.tool is not None and event.button() == Qt.MouseButton.LeftButton and self.image is not None:
            self.setFocus()
            self.tool.press(self, self.mapToScene(event.position().toPoint()), event)
            event.accept()
            return
        super().mousePressEvent(event)

    def mouseMoveEvent(self, event):  # noqa: N802
        pos = event.position().toPoint()
        self.hovered.emit(*self.image_pos(pos))
        if self._pan_from is not None:
            delta = event.position() - self._pan_from
            self._pan_from = event.position()
            self.horizontalScrollBar().setValue(self.horizontalScrollBar().value() - int(delta.x()))
            self.verticalScrollBar().setValue(self.verticalScrollBar().value() - int(delta.y()))
            event.accept()
            return
        if self.tool is not None and self.image is not None:
            self.tool.move(self, self.mapToScene(pos), event)
        super().mouseMoveEvent(event)

    def mouseReleaseEvent(self, event):  # noqa: N802
        if self._pan_from is not None:
            self._pan_from = None
            self.viewport().unsetCursor()
            event.accept()
            return
        if self.tool is not None and event.button() == Qt.MouseButton.LeftButton and self.image is not None:
            self.tool.release(self, self.mapToScene(event.position().toPoint()), event)
            event.accept()
            return
        super().mouseReleaseEvent(event)

    def leaveEvent(self, event):  # noqa: N802
        leave = getattr(self.tool, "leave", None)  # (a brush's circle goes with the mouse)
        if leave is not None:
            leave()
        super().leaveEvent(event)

    def keyPressEvent(self, event):  # noqa: N802
        if event.key() == Qt.Key.Key_Space and not event.isAutoRepeat():
            self._space = True
        if self.tool is not None and self.tool.key(self, event):
            event.accept()
            return
        super().keyPressEvent(event)

    def keyReleaseEvent(self, event):  # noqa: N802
        if event.key() == Qt.Key.Key_Space and not event.isAutoRepeat():
            self._space = False
        super().keyReleaseEvent(event)

    # --- drag and drop -------------------------------------------------------------------------
    def _dropped_path(self, event) -> str | None:
        urls = event.mimeData().urls() if event.mimeData().hasUrls() else []
        for url in urls:
            if url.isLocalFile():
                return url.toLocalFile()
        return None

    def dragEnterEvent(self, event):  # noqa: N802
        if self._dropped_path(event):
            event.acceptProposedAction()
        else:
            event.ignore()

    dragMoveEvent = dragEnterEvent

    def dropEvent(self, event):  # noqa: N802
        path = self._dropped_path(event)
        if path:
            event.acceptProposedAction()
            self.file_dropped.emit(path)


class ResultView(ImageView):
    """The result, with an optional before/after split: left of the divider shows ``compare_image``.

    With compare on, dragging with the left button moves the divider.
    """

    def __init__(self, parent=None, *, title: str = "result"):
        super().__init__(parent, title=title)
        self._clip = QGraphicsRectItem()
        self._clip.setPen(QPen(Qt.PenStyle.NoPen))
        self._clip.setFlag(QGraphicsRectItem.GraphicsItemFlag.ItemClipsChildrenToShape, True)
        self._before = QGraphicsPixmapItem(self._clip)
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
        self.notice.setStyleSheet("QLabel { background: rgba(20, 20, 20, 200); color: white; padding: 12px 18px;"
                                  " border-radius: 6px; font-size: 15px; }")
        self.notice.hide()
        # "stale": the result on screen does not match the panel (its render failed); shown along
        # the top so the pixels stay visible, until a render succeeds
        self.stale = QLabel(self.viewport())
        self.stale.setObjectName("result-stale")
        self.stale.setWordWrap(True)
        self.stale.setStyleSheet("QLabel { background: rgba(150, 30, 30, 220); color: white; padding: 6px 10px;"
                                 " font-size: 13px; }")
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
        """The "before" image (e.g. the target), shown left of the divider when comparing."""
        self.compare_image = image
        if image is not None:
            self._before.setPixmap(QPixmap.fromImage(to_qimage(image)))
        self._update_compare()

    def set_comparing(self, on: bool) -> None:
        self.comparing = bool(on)
        self._update_compare()

    def set_split(self, fraction: float) -> None:
        self.split = float(np.clip(fraction, 0.0, 1.0))
        self._update_compare()

    def set_image(self, image, *, fit: bool = False) -> None:
        super().set_image(image, fit=fit)
        self._update_compare()

    def _update_compare(self) -> None:
        show = self.comparing and self.compare_image is not None and self.image is not None
        self._clip.setVisible(show)
        self._divider.setVisible(show)
        if not show:
            return
        w, h = self.image_size()
        bw = self._before.pixmap().width() or 1
        bh = self._before.pixmap().height() or 1
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


def is_image_path(path: str | Path) -> bool:
    return Path(path).suffix.lower() in IMAGE_SUFFIXES
