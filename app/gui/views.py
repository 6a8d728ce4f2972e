"""Image views: zoom under the mouse, pan, fit, 1:1, pixel read-out, drop of files, mouse tools.

``ImageView`` shows one float image. Wheel zooms under the cursor; middle-drag, or left-drag with
Space held (or with no tool active), pans; ``fit()`` and ``actual_size()`` reset the zoom. A *tool*
(``weft.app.gui.tools``) may be attached: it receives the left-button events in image coordinates and
draws its overlay items in the view's scene. ``ResultView`` adds a before/after split.

The GUI thread never converts a large image: an image of more than ``ASYNC_PIXELS`` pixels is turned
into the QImage the view draws (:func:`~weft.app.gui.convert.display_qimage`, numpy only, so the
worker leaves Python's GIL to the GUI thread) on a worker thread, and the view keeps showing the
previous image until it is ready (``image_shown`` then; ``image`` is always the image on screen). A
view draws that QImage itself: no QPixmap (which only the GUI thread may make, slowly for a large
image) is made. Requests made while one is converted are coalesced: the newest is converted next,
and a conversion older than what is on screen is dropped. ``set_image(image, changed=box)`` redraws
only a part of the array on screen changed in place (a stroke's preview pasted into the result).
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np
from PySide6.QtCore import QObject, QPoint, QPointF, QRectF, Qt, Signal
from PySide6.QtGui import QColor, QImage, QPainter, QPen
from PySide6.QtWidgets import QGraphicsItem, QGraphicsLineItem, QGraphicsRectItem, QGraphicsScene, QGraphicsView, QLabel

from .convert import display_qimage
from .transparency import TransparencyItem

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp", ".webp")

#: Images of more pixels than this are converted for display on a worker thread (display_qimage's
#: time grows with the pixels; under this it is short enough for the GUI thread).
ASYNC_PIXELS = 512 * 512
#: A part of the image on screen changed in place of at most this many pixels is converted on the GUI
#: thread (``set_image(changed=)``: a stroke's preview), not the whole image on a worker. It is large
#: enough for the crop a large picture's stroke preview changes: a part that outgrows it sends the
#: whole picture to the worker, every later preview waits behind that conversion, and previews reach
#: the screen in bursts.
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
        Else every later preview of the stroke would wait behind a whole-picture conversion and they
        would reach the screen in bursts."""
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
        _q, part = display_qimage(image[y0:y1, x0:x1])
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


def is_image_path(path: str | Path) -> bool:
    return Path(path).suffix.lower() in IMAGE_SUFFIXES
