"""Image views: zoom under the mouse, pan, fit, 1:1, pixel read-out, drop of files, mouse tools.

``ImageView`` shows one float image. Wheel zooms under the cursor; middle-drag, or left-drag with
Space held (or with no tool active), pans; ``fit()`` and ``actual_size()`` reset the zoom. A *tool*
(``weft.app.gui.tools``) may be attached: it receives the left-button events in image coordinates and
draws its overlay items in the view's scene. ``ResultView`` (``result_view.py``) adds a before/after split.

Large images are converted for display off the GUI thread (``display.py``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PySide6.QtCore import QPoint, QRectF, Qt, Signal
from PySide6.QtGui import QColor, QPainter
from PySide6.QtWidgets import QGraphicsScene, QGraphicsView

from . import display
from .display import PART_PIXELS, DisplayConverter, ImageItem
from .transparency import TransparencyItem

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp", ".webp")


class ImageView(QGraphicsView):
    """A zoomable, pannable view of one image.

    Signals: ``hovered(x, y)`` in image pixels (-1, -1 outside), ``zoomed(scale)``,
    ``file_dropped(path)`` when an image file is dropped on it.
    """

    hovered = Signal(int, int)
    zoomed = Signal(float)
    file_dropped = Signal(str)
    image_shown = Signal()  # the image on screen changed (``image``): at once, or once converted

    def __init__(self, parent=None, *, title: str = ""):
        super().__init__(parent)
        self.title = title
        self.setScene(QGraphicsScene(self))
        self._item = ImageItem()
        self.scene().addItem(self._item)
        self.transparency = TransparencyItem()  # where an input with alpha is transparent
        self.transparency.setVisible(False)
        self.scene().addItem(self.transparency)
        self.image: np.ndarray | None = None  # the image on screen
        self._converter = DisplayConverter(self._show_image, self)
        # parts of the array on its way to the screen changed in place since its conversion was asked
        # for: redrawn from it once it is shown (:meth:`_defer_part`)
        self._late_parts: list[tuple[int, int, int, int]] = []
        self._late_of: np.ndarray | None = None
        self._fit_wanted = False
        self.tool = None
        self.auto_fit = True  # keep fitting the image to the window until the user zooms
        self._frame: QRectF | None = None  # a tool's frame around the image (an uncrop's grown canvas)
        self._pan_from = None
        self._space = False
        self._tool_drag = False  # a tool's left-button drag is in progress: the view must not move under it
        self._refit_after_drag = False
        self._scroll_unlocked = False  # (during a drag whose view was moved: see _unlock_scroll)
        self.setTransformationAnchor(QGraphicsView.ViewportAnchor.NoAnchor)
        self.setResizeAnchor(QGraphicsView.ViewportAnchor.AnchorViewCenter)
        self.setDragMode(QGraphicsView.DragMode.NoDrag)
        self.setRenderHint(QPainter.RenderHint.SmoothPixmapTransform, False)
        self.setMouseTracking(True)
        self.setAcceptDrops(True)
        self.setBackgroundBrush(QColor(60, 60, 60))
        self.setFocusPolicy(Qt.FocusPolicy.StrongFocus)

    # --- image ---------------------------------------------------------------------------------
    def set_image(self, image: np.ndarray | None, *, fit: bool = False, changed=None, over=None) -> None:
        """Show ``image`` (float32 [0, 1]); ``fit`` also fits it to the window, as does an image of
        another size while the view is fitting (the user has not zoomed). A large image is shown
        once converted on a worker thread (module docstring); the previous one stays until then.

        ``changed`` = ``(x0, y0, x1, y1)``: ``image`` differs from ``over`` (default: ``image`` itself,
        changed in place) only there; when ``over`` is the array on screen (a stroke's preview pasted
        into the result, or into a copy of it), only that part is converted and redrawn, at once
        (a part of at most ``PART_PIXELS``)."""
        if changed is not None:
            over = image if over is None else over
            if self._defer_part(image, changed, over) or self._redraw_part(image, changed, over):
                return
        self._fit_wanted = self._fit_wanted or fit
        self._converter.request(image)

    def set_transparency(self, alpha: np.ndarray | None) -> None:
        """Show where the picture is transparent (``alpha`` (H, W) in [0, 1], None: nowhere): a
        checkerboard over it and its outline."""
        self.transparency.set_alpha(alpha)

    def _redraw_part(self, image: np.ndarray | None, box, over) -> bool:
        """Show ``image``, which is the array on screen ``over`` but for ``box``, by redrawing ``box``
        (see :meth:`set_image`); False when that does not apply (not what is on screen, one being
        converted, or a part too large to convert here)."""
        pixels = self._item.pixels()
        if image is None or over is not self.image or self.converting or pixels is None:
            return False
        h, w = image.shape[:2]
        if over.shape != image.shape or pixels.shape[:2] != (h, w):
            return False
        x0, y0, x1, y1 = (int(v) for v in box)
        if (min(w, x1) - max(0, x0)) * (min(h, y1) - max(0, y0)) > PART_PIXELS:
            return False
        self.image = image  # (the same pixels as ``over`` outside ``box``)
        self._converter.shown_now()  # (a conversion still running is older: dropped)
        self._paint_part(image, box)
        return True

    def _defer_part(self, image: np.ndarray | None, box, over) -> bool:
        """``image``, changed in place only in ``box`` (``over`` is ``image``), is the array whose
        conversion for the screen is on its way (the whole picture went to the worker: the first
        preview of a stroke came before the picture itself was on screen, or its part was too large):
        ``box`` is redrawn from it once that conversion is shown, instead of converting it all again.
        Else every later preview of the stroke waited behind a whole-picture conversion (~150 ms at
        4096²) and they reached the screen in bursts."""
        if image is None or over is not image or not self.converting or self._converter.latest is not image:
            return False
        if self._late_of is not image:
            self._late_of, self._late_parts = image, []
        self._late_parts.append(tuple(int(v) for v in box))
        return True

    def _paint_part(self, image: np.ndarray, box) -> None:
        """Convert ``box`` of ``image`` (the array on screen) and redraw it."""
        pixels = self._item.pixels()
        h, w = image.shape[:2]
        x0, y0, x1, y1 = box
        x0, y0, x1, y1 = max(0, x0), max(0, y0), min(w, x1), min(h, y1)
        if x0 >= x1 or y0 >= y1 or pixels is None:
            return  # nothing on screen changed
        _q, part = display.display_qimage(image[y0:y1, x0:x1])  # (display's: one function to replace in tests)
        pixels[y0:y1, x0:x1] = part
        self._item.update(QRectF(x0, y0, x1 - x0, y1 - y0))
        self.image_shown.emit()

    @property
    def converting(self) -> bool:
        """An image given to :meth:`set_image` is not on screen yet (it is being converted)."""
        return self._converter.pending

    def _show_image(self, image: np.ndarray | None, q: tuple | None, _extra=None) -> None:
        first = self.image is None
        resized = not first and image is not None and self.image.shape[:2] != image.shape[:2]
        self.image = image
        if image is None:
            self._item.set_qimage(None)
            self._image_changed()
            self.image_shown.emit()
            return
        fit, self._fit_wanted = self._fit_wanted, False
        self._item.set_qimage(q)
        self._set_scene_rect()
        if fit or first or (resized and self.auto_fit):
            if self._tool_drag and not first:
                self._refit_after_drag = True  # (fitted when the drag ends: nothing moves under the mouse)
            else:
                self.fit()
        self._image_changed()
        self.viewport().update()
        self.image_shown.emit()
        late, self._late_parts = self._late_parts, []
        if image is self._late_of and not self.converting:
            for box in late:  # changed in place since this conversion was asked for
                self._paint_part(image, box)
        self._late_of = None

    def _image_changed(self) -> None:
        """(For subclasses: what follows the image on screen.)"""

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
        if self._scroll_unlocked:
            return  # (mid-drag: the view holds still; set when the drag ends)
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
        if self._tool_drag:
            # the layout changed mid-drag (a hint above the view shrank): keep the image where it is
            # on the screen under the mouse; it is fitted again when the drag ends
            self._hold_under_drag(lambda: super(ImageView, self).resizeEvent(event))
            self._refit_after_drag = self._refit_after_drag or self.auto_fit
            return
        super().resizeEvent(event)
        if self.auto_fit and self.image is not None:
            self.fitInView(self._fitted(), Qt.AspectRatioMode.KeepAspectRatio)
            self.zoomed.emit(self.scale_factor())  # the % label follows a refit on resize

    def moveEvent(self, event):  # noqa: N802
        if self._tool_drag:
            self._hold_under_drag(lambda: super(ImageView, self).moveEvent(event), moved=event.pos() - event.oldPos())
            return
        super().moveEvent(event)

    def _hold_under_drag(self, handle, moved=None) -> None:
        """Let Qt handle a resize or move of the view (``handle``), then scroll so that the image
        point under a fixed place on the screen stays there (a drag's line ends where the mouse went)."""
        self._unlock_scroll()
        origin = self.viewport().mapToGlobal(QPoint(0, 0))
        anchor = self.mapToScene(QPoint(0, 0))
        handle()
        shift = (self.viewport().mapToGlobal(QPoint(0, 0)) - origin) if moved is None else moved
        self._scroll_to(anchor, -shift)

    def _scroll_to(self, scene_point, at: QPoint) -> None:
        """Scroll so that ``scene_point`` is at view position ``at``."""
        off = self.mapFromScene(scene_point) - at
        self.horizontalScrollBar().setValue(self.horizontalScrollBar().value() + off.x())
        self.verticalScrollBar().setValue(self.verticalScrollBar().value() + off.y())

    def _unlock_scroll(self) -> None:
        """Give the scene room around the image so that the view can be scrolled anywhere (an image
        smaller than the view is otherwise held centred), keeping what is on screen where it is;
        undone when the drag ends."""
        if self._scroll_unlocked:
            return
        anchor = self.mapToScene(QPoint(0, 0))
        rect = self.sceneRect() if self._frame is not None else self._item.sceneBoundingRect()
        room = 2 * max(self.viewport().width(), self.viewport().height()) / max(self.scale_factor(), 1e-6)
        self.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        self.setVerticalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        self.scene().setSceneRect(rect.adjusted(-room, -room, room, room))
        self._scroll_unlocked = True
        self._scroll_to(anchor, QPoint(0, 0))

    def _end_tool_drag(self) -> None:
        """The drag ended: the scene's own rect again, and the fit the layout asked for meanwhile."""
        self._tool_drag = False
        if self._scroll_unlocked:
            self._scroll_unlocked = False
            self.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAsNeeded)
            self.setVerticalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAsNeeded)
            self._set_scene_rect()
        if self._refit_after_drag:
            self._refit_after_drag = False
            if self.auto_fit and self.image is not None:
                self.fit()

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
            self.zoom_by(1.25**steps, at=event.position().toPoint())
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
            event.button() == Qt.MouseButton.LeftButton and (self._space or self.tool is None)
        )

    def mousePressEvent(self, event):  # noqa: N802
        if self._panning(event):
            self._pan_from = event.position()
            self.viewport().setCursor(Qt.CursorShape.ClosedHandCursor)
            event.accept()
            return
        if (
            self.tool is not None
            and event.button() == Qt.MouseButton.LeftButton
            and self.image is not None
            and not self.converting
        ):  # (not on the image being replaced: its geometry is the new one's)
            self.setFocus()
            self._tool_drag = True
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
            try:
                self.tool.release(self, self.mapToScene(event.position().toPoint()), event)
            finally:
                self._end_tool_drag()
            event.accept()
            return
        self._end_tool_drag()
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


def is_image_path(path: str | Path) -> bool:
    return Path(path).suffix.lower() in IMAGE_SUFFIXES
