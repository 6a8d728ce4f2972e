"""The tools of a painted mask and of an uncrop's margins (DESIGN.md, Studio and Geometry).

* ``MaskTool`` paints a mask geometry (``Geometry(MASK, input=...)``) of the document's current
  method over its image: brush and eraser (round, size with ``[`` / ``]``, shown as a circle of the
  brush's size on screen), lasso (add or subtract a polygon). The mask is drawn over the image in a
  semi-transparent colour. A brush or eraser stroke is painted into a Qt-free ``MaskStroke`` (a
  copy of the mask made at the press, changed in place dab by dab: a dab costs its own pixels, in the
  mask and in the overlay, not a copy of a 4096² mask), a lasso with ``Mask.painted_polygon``; a
  stroke is one undo command, pushed on release (the stroke's bits become the mask, not copied); Esc
  cancels a stroke in progress. While a brush or eraser stroke is drawn, ``on_stroke(stroke, box)``
  hears the ``MaskStroke`` so far and the box around the latest dab (the window renders a preview
  around it, cutting from the stroke only the part that preview reads); ``on_stroke(None, None)``:
  the stroke ended without an edit (Esc, or a release that left the mask as it was).
* ``MarginsTool`` edits a margins geometry (``Geometry(MARGINS, param=...)``): a press outside the
  image drags the canvas edges on that side outward (the grown frame drawn as a dashed outline);
  one undo command on release; Esc cancels.
* ``ToolSet`` puts several tools on one view: a press goes to the tool that claims it (the mask tool
  claims a press whose brush would paint), else to the first that wants it (the margins tool wants
  presses outside the image), hover moves to all (the pointer shows which: the brush's circle, or a
  resize arrow over what drags the canvas edges).
  **The rule with a mask and margins on one view:** outside the image, a brush or eraser press paints
  while the brush's circle covers a pixel of the image (an artist painting along the border gets
  paint); a press farther out, any press outside the image in a lasso mode, or a Shift+press outside
  the image drags the canvas edges.
* ``GeometryBar`` is the row of buttons over a view with such tools: brush, eraser, lasso +/-, brush
  size, Clear mask, Invert, Fill transparent, Extend canvas…; and the actions "Smaller brush" ``[``
  and "Larger brush" ``]``, shortcuts of the whole window while the mask tool is shown (after a click
  on a button or a slider too; a text field with the focus keeps them as text).
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np
from PySide6.QtCore import QPointF, QRectF, QSize, Qt, Signal
from PySide6.QtGui import QAction, QActionGroup, QBrush, QColor, QImage, QKeySequence, QPainterPath
from PySide6.QtWidgets import (
    QDialog,
    QDialogButtonBox,
    QFormLayout,
    QGraphicsEllipseItem,
    QGraphicsItem,
    QGraphicsPathItem,
    QGraphicsRectItem,
    QLabel,
    QSpinBox,
    QToolBar,
)

from weft.core.geometry import MAX_SIDE, Margins, Mask, MaskStroke

from .tools import Tool, _cosmetic

MASK_RGBA = (255, 48, 96, 120)  # the mask's colour over the image
_MASK_WORD = np.array(MASK_RGBA, dtype=np.uint8).view(np.uint32)[0]  # its four bytes as one word (any byte order)
BRUSH_MIN, BRUSH_MAX, BRUSH_DEFAULT = 1, 512, 24
BRUSH, ERASER, LASSO_ADD, LASSO_SUBTRACT = "brush", "eraser", "lasso add", "lasso subtract"
MODES = (BRUSH, ERASER, LASSO_ADD, LASSO_SUBTRACT)


class MaskOverlay(QGraphicsItem):
    """The mask drawn over its image: its colour where it is set, transparent elsewhere. A stroke
    updates only the pixels around each dab (:meth:`update_box`), so painting costs the dab's area,
    not the image's."""

    def __init__(self):
        super().__init__()
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
            # one multiply of the bits by the colour as a 32-bit word, not a boolean-indexed assignment:
            # 11.8 against 169.7 ms for a 4096² mask (a GUI-thread stall at each undo, Clear, session open)
            rgba = np.empty((h, w), dtype=np.uint32)
            np.multiply(mask.bits, _MASK_WORD, out=rgba, casting="unsafe")
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
        from now on. No redraw when ``start`` is what is drawn; with nothing painted, a blank overlay
        (calloc'd: its pages are made as the stroke paints them, no 64 MB written at 4096²)."""
        if start is not None and start is self._mask and self._rgba is not None:
            self._mask = stroke
        elif start is None:  # (a stroke on no mask starts blank)
            self._mask = stroke
            self._show(np.zeros(stroke.shape, dtype=np.uint32))
        else:
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
        np.multiply(mask.bits[y0:y1, x0:x1], _MASK_WORD, out=words[y0:y1, x0:x1], casting="unsafe")
        self.update(QRectF(x0, y0, x1 - x0, y1 - y0))

    def boundingRect(self) -> QRectF:  # noqa: N802 (Qt naming)
        return QRectF(0, 0, self._image.width(), self._image.height())

    def paint(self, painter, option, widget=None) -> None:
        if not self._image.isNull():
            painter.drawImage(QPointF(0, 0), self._image)


class MaskTool(Tool):
    """Paints the mask geometry ``geometry`` of the current method on ``view`` (module docstring)."""

    def __init__(self, view, doc, geometry, on_stroke: Callable[[Mask | None, tuple | None], None] | None = None,
                 on_size: Callable[[int], None] | None = None):
        self.view, self.doc, self.geometry, self.on_stroke, self.on_size = view, doc, geometry, on_stroke, on_size
        self.geometry_key = geometry.key
        self.mode = BRUSH
        self.size = BRUSH_DEFAULT  # brush diameter in image pixels
        scene = view.scene()
        self.overlay = MaskOverlay()
        self.overlay.setZValue(5)
        scene.addItem(self.overlay)
        self.cursor = QGraphicsEllipseItem()
        self.cursor.setPen(_cosmetic(QColor(255, 255, 255, 230), 1.5))
        self.cursor.setZValue(30)
        self.cursor.hide()
        scene.addItem(self.cursor)
        self.lasso_item = QGraphicsPathItem()
        self.lasso_item.setPen(_cosmetic(QColor("#ffd740"), 1.5, Qt.PenStyle.DashLine))
        self.lasso_item.setBrush(QBrush(QColor(255, 215, 64, 50)))
        self.lasso_item.setZValue(25)
        scene.addItem(self.lasso_item)
        # the stroke so far: a brush's or eraser's MaskStroke (painted in place), a lasso's starting mask
        self.live: MaskStroke | Mask | None = None
        self.start: Mask | None = None  # the document's mask when the stroke began
        self.touched: tuple[int, int, int, int] | None = None  # the box of the pixels the stroke changed
        self.last: tuple[float, float] | None = None
        self.points: list[tuple[float, float]] = []
        self.active = False
        self.refresh()

    # --- state ---------------------------------------------------------------------------------
    @property
    def stroking(self) -> bool:
        return self.active

    def mask(self) -> Mask | None:
        """The document's mask if it fits the image shown (else None)."""
        value = self.doc.value(self.geometry_key)
        w, h = self.view.image_size()
        return value if value is not None and value.shape == (h, w) else None

    def base(self) -> Mask:
        mask = self.mask()
        w, h = self.view.image_size()
        return mask if mask is not None else Mask.empty(max(w, 1), max(h, 1))

    @property
    def radius(self) -> float:
        """The brush's radius for ``Mask.painted_line``: a diameter of ``size`` pixels."""
        return (self.size - 1) / 2.0

    def claims(self, pos, modifiers=Qt.KeyboardModifier.NoModifier) -> bool:
        """A press at scene point ``pos`` outside the image is a brush stroke, not an edge drag: a
        brush or eraser whose circle covers the centre of an image pixel there (Shift: never; the
        module docstring has the rule)."""
        w, h = self.view.image_size()
        if 0 <= pos.x() <= w and 0 <= pos.y() <= h:
            return False  # inside: not a question (nothing else wants it)
        if self.mode not in (BRUSH, ERASER) or modifiers & Qt.KeyboardModifier.ShiftModifier or not w or not h:
            return False
        # the nearest pixel centre (centres at i + 0.5 in scene coordinates)
        dx = max(0.5 - pos.x(), 0.0, pos.x() - (w - 0.5))
        dy = max(0.5 - pos.y(), 0.0, pos.y() - (h - 0.5))
        return math.hypot(dx, dy) <= self.size / 2.0

    def reaches(self, pos, modifiers=Qt.KeyboardModifier.NoModifier) -> bool:
        """A press at ``pos`` paints (inside the image, or :meth:`claims` outside it)."""
        w, h = self.view.image_size()
        return (0 <= pos.x() <= w and 0 <= pos.y() <= h) or self.claims(pos, modifiers)

    def set_mode(self, mode: str) -> None:
        if mode in MODES:
            self.mode = mode
            self._show_cursor(None)

    def set_size(self, size: int) -> None:
        size = int(min(max(size, BRUSH_MIN), BRUSH_MAX))
        if size != self.size:
            self.size = size
            if self.cursor.isVisible():
                self._show_cursor(self.cursor.rect().center())
            if self.on_size is not None:
                self.on_size(size)

    def grow(self, steps: int) -> None:
        """``]`` (+1) and ``[`` (-1): the brush size by a quarter (at least a pixel) per step."""
        size = self.size
        for _ in range(abs(steps)):
            change = max(1, round(size * 0.25))
            size = size + change if steps > 0 else max(BRUSH_MIN, size - max(1, round(size * 0.2)))
        self.set_size(size)

    # --- drawing -------------------------------------------------------------------------------
    def refresh(self) -> None:
        """Draw the document's mask (the stroke so far while painting). A stroke whose mask the
        document changed under it (Ctrl+Z, another image opened) is cancelled: its release must not
        put the undone mask back."""
        if self.active and self.mask() is not self.start:
            self.cancel()
            return
        self._draw(self.live if self.active and self.live is not None else self.mask())

    def hide(self) -> None:
        self.active = False
        self.live = None
        self.points = []
        self.lasso_item.setPath(QPainterPath())
        self.overlay.set_mask(None)
        self._show_cursor(None)

    def _draw(self, mask: Mask | None) -> None:
        self.overlay.set_mask(mask)

    def _show_cursor(self, pos) -> None:
        """The brush's circle at ``pos`` (the mouse pointer a small cross inside it); None hides it."""
        if pos is None or self.mode not in (BRUSH, ERASER):
            if self.cursor.isVisible():
                self.cursor.hide()
                self.view.viewport().unsetCursor()
            return
        r = self.size / 2.0
        self.cursor.setRect(QRectF(pos.x() - r, pos.y() - r, 2 * r, 2 * r))
        if not self.cursor.isVisible():
            self.cursor.show()
            self.view.viewport().setCursor(Qt.CursorShape.CrossCursor)

    @staticmethod
    def _pixel(pos) -> tuple[float, float]:
        """Scene point -> the mask's pixel coordinates (pixel centres at whole numbers)."""
        return pos.x() - 0.5, pos.y() - 0.5

    def _dab(self, p0, p1) -> None:
        value = self.mode == BRUSH
        changed = self.live.line(p0, p1, self.radius, value)  # (in place: only the dab's pixels)
        self.last = p1
        r = self.radius + 1
        box = (min(p0[0], p1[0]) - r, min(p0[1], p1[1]) - r, max(p0[0], p1[0]) + r, max(p0[1], p1[1]) + r)
        if changed is not None:
            self.overlay.update_box(self.live, changed)
            t = self.touched
            self.touched = changed if t is None else (min(t[0], changed[0]), min(t[1], changed[1]),
                                                      max(t[2], changed[2]), max(t[3], changed[3]))
        if self.on_stroke is not None:  # the eraser's strokes too: erased pixels are previewed unfilled
            self.on_stroke(self.live, box)

    def press(self, view, pos, event):
        self.active = True
        self.start = self.mask()
        self.touched = None
        p = self._pixel(pos)
        if self.mode in (BRUSH, ERASER):
            w, h = self.view.image_size()
            self.live = MaskStroke(self.start, max(w, 1), max(h, 1))
            self.overlay.begin(self.live, self.start)
            self._dab(p, p)
        else:
            self.live = self.base()
            self.points = [p]
            self._draw_lasso()

    def move(self, view, pos, event):
        self._show_cursor(pos if self.active or self.reaches(pos, event.modifiers()) else None)
        if not self.active or not (event.buttons() & Qt.MouseButton.LeftButton):
            return
        p = self._pixel(pos)
        if self.mode in (BRUSH, ERASER):
            self._dab(self.last, p)
        else:
            self.points.append(p)
            self._draw_lasso()

    def leave(self) -> None:
        """The mouse left the view: no circle (a stroke in progress keeps it)."""
        if not self.active:
            self._show_cursor(None)

    def _draw_lasso(self) -> None:
        path = QPainterPath()
        if self.points:
            path.moveTo(QPointF(self.points[0][0] + 0.5, self.points[0][1] + 0.5))
            for x, y in self.points[1:]:
                path.lineTo(QPointF(x + 0.5, y + 0.5))
            path.closeSubpath()
        self.lasso_item.setPath(path)

    def release(self, view, pos, event):
        if not self.active:
            return
        if self.mode in (BRUSH, ERASER):
            if self.last is not None and self._pixel(pos) != self.last:
                self._dab(self.last, self._pixel(pos))
            stroke, text = self.live, "Brush stroke" if self.mode == BRUSH else "Erase"
            # (a stroke of one mode only paints or only erases: it changed a pixel iff its mask differs)
            changed, mask = stroke.changed, stroke.mask()  # (its bits, not a copy)
            if changed:
                self.overlay.adopt(mask)  # (drawn dab by dab already)
        else:
            self.points.append(self._pixel(pos))
            mask = self.live.painted_polygon(self.points, self.mode == LASSO_ADD)
            text = "Lasso" if self.mode == LASSO_ADD else "Lasso subtract"
            changed = mask != self.base()
        self._end()
        if changed:
            self.doc.set_mask(self.geometry_key, mask, text)  # (the document's live stroke ends with it)
            self.refresh()
        else:  # nothing changed: no undo step, and the stroke's previews go as with Esc
            self._cancelled()

    def _end(self) -> None:
        self.active = False
        self.live = None
        self.last = None
        self.points = []
        self.lasso_item.setPath(QPainterPath())

    def cancel(self) -> bool:
        """Esc: drop the stroke in progress (the mask stays as it was); False if there is none."""
        if not self.active:
            return False
        self._end()
        self._cancelled()
        return True

    def _cancelled(self) -> None:
        start, touched = self.start, self.touched
        if start is not None and start is self.mask() and self.overlay.image().size() == QSize(*start.size):
            # the overlay differs from the mask the stroke began on only where the stroke changed pixels
            if touched is not None:
                self.overlay.update_box(start, touched)
            self.overlay.adopt(start)
        self.touched = None
        self.refresh()
        if self.on_stroke is not None:
            self.on_stroke(None, None)

    def key(self, view, event) -> bool:
        if event.key() == Qt.Key.Key_Escape:
            return self.cancel()
        if event.key() == Qt.Key.Key_BracketRight:
            self.grow(+1)
            return True
        if event.key() == Qt.Key.Key_BracketLeft:
            self.grow(-1)
            return True
        return False


class MarginsTool(Tool):
    """Drags the canvas's edges outward: the margins geometry ``geometry`` (module docstring)."""

    def __init__(self, view, doc, geometry, on_drag: Callable[[Margins], None] | None = None):
        self.view, self.doc, self.geometry, self.on_drag = view, doc, geometry, on_drag
        self.geometry_key = geometry.key
        self.frame = QGraphicsRectItem()
        self.frame.setPen(_cosmetic(QColor("#40c4ff"), 2, Qt.PenStyle.DashLine))
        self.frame.setZValue(15)
        view.scene().addItem(self.frame)
        self.drag = None  # (sides, start point, start margins)
        self.live: Margins | None = None
        self.hover_cursor = True  # shows the resize arrow itself (a ToolSet does it for its tools)
        self._arrow = False
        self.refresh()

    def arrow(self, pos):
        """The resize arrow for a press at ``pos`` (which edges it drags)."""
        w, h = self.view.image_size()
        left, top, right, bottom = pos.x() < 0, pos.y() < 0, pos.x() > w, pos.y() > h
        if (left or right) and (top or bottom):
            return Qt.CursorShape.SizeFDiagCursor if left == top else Qt.CursorShape.SizeBDiagCursor
        return Qt.CursorShape.SizeHorCursor if left or right else Qt.CursorShape.SizeVerCursor

    def show_arrow(self, pos) -> None:
        """The resize arrow at ``pos`` (None: the view's own pointer again, if the arrow was shown)."""
        if pos is not None:
            self.view.viewport().setCursor(self.arrow(pos))
            self._arrow = True
        elif self._arrow:
            self.view.viewport().unsetCursor()
            self._arrow = False

    def margins(self) -> Margins:
        value = self.doc.value(self.geometry_key)
        return value if value is not None else Margins(0, 0, 0, 0)

    def wants(self, pos) -> bool:
        """A press outside the image is an edge drag."""
        w, h = self.view.image_size()
        return pos.x() < 0 or pos.y() < 0 or pos.x() > w or pos.y() > h

    def refresh(self) -> None:
        self._show(self.live if self.live is not None else self.margins())

    def hide(self) -> None:
        self.drag = None
        self.live = None
        self.frame.hide()
        self.show_arrow(None)
        self.view.set_frame(None)

    def _show(self, m: Margins) -> None:
        w, h = self.view.image_size()
        rect = QRectF(-m.left, -m.top, w + m.left + m.right, h + m.top + m.bottom)
        self.frame.setRect(rect)
        self.frame.setVisible(bool(m))
        self.view.set_frame(rect, fit=self.drag is None)  # no refit under the mouse mid-drag

    def press(self, view, pos, event):
        w, h = view.image_size()
        sides = (pos.x() < 0, pos.y() < 0, pos.x() > w, pos.y() > h)  # left, top, right, bottom
        # the drag is measured on screen: the scene grows with the frame, and a view centres a scene
        # smaller than itself, so a scene point under the mouse moves while the frame grows
        at = event.position()
        self.drag = (sides, (at.x(), at.y()), self.margins())
        self.live = self.margins()

    def _dragged(self, event) -> Margins:
        sides, (x0, y0), m = self.drag
        k = self.view.screen_to_image_distance(1.0)
        at = event.position()
        dx, dy = (at.x() - x0) * k, (at.y() - y0) * k
        moves = (-dx, -dy, dx, dy)
        return Margins(*(max(0, min(MAX_SIDE, int(round(v + d)))) if s else v
                         for v, d, s in zip(m, moves, sides)))

    def move(self, view, pos, event):
        if self.drag is None and self.hover_cursor:
            self.show_arrow(pos if self.wants(pos) else None)
        if self.drag is None or not (event.buttons() & Qt.MouseButton.LeftButton):
            return
        self.live = self._dragged(event)
        self._show(self.live)
        if self.on_drag is not None:
            self.on_drag(self.live)

    def release(self, view, pos, event):
        if self.drag is None:
            return
        margins = self._dragged(event)
        self.drag = None
        self.live = None
        if margins != self.margins():
            self.doc.set_margins(self.geometry_key, margins, f"Extend canvas {margins.to_text()}")
        self.refresh()

    def key(self, view, event) -> bool:
        if event.key() == Qt.Key.Key_Escape and self.drag is not None:
            self.drag = None
            self.live = None
            self.refresh()
            return True
        return False


class ToolSet(Tool):
    """Several tools on one view: a press goes to the first that ``claims`` it, else to the first
    that ``wants`` it (else the last), the rest of that drag to it; hover moves to every tool, the
    one a press would go to last (its pointer is the one shown: the brush's circle, or the margins
    tool's resize arrow); keys to the dragging tool first. See the module docstring for the rule."""

    def __init__(self, tools):
        self.tools = list(tools)
        self.view = self.tools[0].view
        self.grabbed: Tool | None = None
        for tool in self.tools:
            if isinstance(tool, MarginsTool):
                tool.hover_cursor = False  # shown here, when the press would be its

    def _pick(self, pos, modifiers=Qt.KeyboardModifier.NoModifier) -> Tool:
        for tool in self.tools:
            claims = getattr(tool, "claims", None)
            if claims is not None and claims(pos, modifiers):
                return tool
        for tool in self.tools:
            wants = getattr(tool, "wants", None)
            if wants is not None and wants(pos):
                return tool
        return next((t for t in self.tools if getattr(t, "wants", None) is None), self.tools[-1])

    def press(self, view, pos, event):
        self.grabbed = self._pick(pos, event.modifiers())
        self.grabbed.press(view, pos, event)

    def move(self, view, pos, event):
        if self.grabbed is not None and event.buttons() & Qt.MouseButton.LeftButton:
            self.grabbed.move(view, pos, event)
            return
        picked = self._pick(pos, event.modifiers())
        for tool in self.tools:
            if isinstance(tool, MarginsTool):
                tool.show_arrow(None)
        for tool in [t for t in self.tools if t is not picked] + [picked]:
            tool.move(view, pos, event)
        if isinstance(picked, MarginsTool):
            picked.show_arrow(pos)

    def release(self, view, pos, event):
        tool, self.grabbed = self.grabbed, None
        if tool is not None:
            tool.release(view, pos, event)

    def leave(self) -> None:
        for tool in self.tools:
            leave = getattr(tool, "leave", None)
            if leave is not None:
                leave()
            if isinstance(tool, MarginsTool) and tool.drag is None:
                tool.show_arrow(None)

    def key(self, view, event) -> bool:
        order = ([self.grabbed] if self.grabbed is not None else []) + [t for t in self.tools if t is not self.grabbed]
        return any(t.key(view, event) for t in order)

    def refresh(self) -> None:
        for tool in self.tools:
            tool.refresh()

    def hide(self) -> None:
        for tool in self.tools:
            tool.hide()


class ExtendDialog(QDialog):
    """"Extend canvas…": the four margins typed, in pixels."""

    def __init__(self, margins: Margins, size: tuple[int, int], parent=None):
        super().__init__(parent)
        self.setWindowTitle("Extend canvas")
        self.size_ = size
        form = QFormLayout(self)
        self.boxes = {}
        for side, value in zip(("left", "top", "right", "bottom"), margins):
            box = QSpinBox()
            box.setRange(0, MAX_SIDE)
            box.setSuffix(" px")
            box.setValue(int(value))
            box.setAccessibleName(f"{side} margin")
            box.valueChanged.connect(self._say)
            form.addRow(f"{side.capitalize()}:", box)
            self.boxes[side] = box
        self.result_label = QLabel()
        form.addRow(self.result_label)
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Ok | QDialogButtonBox.StandardButton.Cancel)
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        form.addRow(buttons)
        self._say()

    def margins(self) -> Margins:
        return Margins(*(self.boxes[s].value() for s in ("left", "top", "right", "bottom")))

    def _say(self) -> None:
        w, h = self.size_
        gw, gh = self.margins().grown(w, h)
        self.result_label.setText(f"canvas {w}x{h} → {gw}x{gh}")


class GeometryBar(QToolBar):
    """The buttons of a view's mask and margins tools (module docstring); what does not fit the
    pane's width goes to the bar's » menu. ``message(text)``: a one-line note (why an action did nothing)."""

    message = Signal(str)

    def __init__(self, doc, parent=None):
        super().__init__(parent)
        self.doc = doc
        self.mask_tool: MaskTool | None = None
        self.margins_tool: MarginsTool | None = None
        self.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextOnly)
        self.setIconSize(QSize(12, 12))
        self.setStyleSheet("QToolBar { spacing: 1px; padding: 0px; }")
        self.mode_group = QActionGroup(self)
        self.mode_actions: dict[str, QAction] = {}
        edges = ("; outside the image a press paints while the brush's circle covers the image, and drags the "
                 "canvas edges farther out or with Shift")
        tips = {BRUSH: "paint the mask ([ and ] size the brush; Esc cancels a stroke)" + edges,
                ERASER: "erase the mask ([ and ] size the brush)" + edges,
                LASSO_ADD: "draw a closed outline to add to the mask (start it inside the image: a press "
                           "outside drags the canvas edges)",
                LASSO_SUBTRACT: "draw a closed outline to take from the mask (start it inside the image: a "
                                "press outside drags the canvas edges)"}
        labels = {BRUSH: "Brush", ERASER: "Eraser", LASSO_ADD: "Lasso +", LASSO_SUBTRACT: "Lasso −"}
        for mode in MODES:
            action = QAction(labels[mode], self)  # owned by the bar (the window's menu shows them too)
            self.addAction(action)
            action.setCheckable(True)
            action.setToolTip(tips[mode])
            self.mode_group.addAction(action)
            self.mode_actions[mode] = action
            action.toggled.connect(lambda on, m=mode: on and self.mask_tool is not None and self.mask_tool.set_mode(m))
        self.mode_buttons = {mode: self.widgetForAction(a) for mode, a in self.mode_actions.items()}
        self.size_box = QSpinBox()
        self.size_box.setRange(BRUSH_MIN, BRUSH_MAX)
        self.size_box.setSuffix(" px")
        self.size_box.setToolTip("brush size in image pixels ([ smaller, ] larger)")
        self.size_box.valueChanged.connect(lambda v: self.mask_tool is not None and self.mask_tool.set_size(v))
        self.size_action = self.addWidget(self.size_box)
        # [ and ]: shortcuts of the window while the size box is shown (the mask tool is), whatever has
        # the focus -- a button or slider just clicked too; a text field keeps them (Qt gives a key a
        # focused text field types to the field, not to a shortcut). Actions of the size box, not
        # buttons of the bar; the window's Edit > Mask and Canvas menu lists them.
        self.smaller_action = self._brush_action("Smaller brush", "[", -1)
        self.larger_action = self._brush_action("Larger brush", "]", +1)
        self.clear_action = self._action("Clear mask", "remove the whole mask", self.clear_mask)
        self.invert_action = self._action("Invert", "swap what the mask covers and what it does not", self.invert_mask)
        self.transparent_action = self._action("Fill transparent", "", self.fill_transparent)
        self.extend_action = self._action("Extend canvas…", "type the pixels to add on each side (or drag outward "
                                          "from outside the image: beyond the brush's circle, or with Shift)",
                                          self.extend_dialog)
        self.clear_button, self.invert_button, self.transparent_button, self.extend_button = (
            self.widgetForAction(a) for a in (self.clear_action, self.invert_action, self.transparent_action,
                                              self.extend_action))

    def _brush_action(self, text: str, key: str, steps: int) -> QAction:
        action = QAction(text, self.size_box)
        action.setShortcut(QKeySequence(key))
        action.setShortcutContext(Qt.ShortcutContext.WindowShortcut)
        action.setToolTip(f"{text.lower()} ({key})")
        action.triggered.connect(lambda _=False: self.mask_tool is not None and self.mask_tool.grow(steps))
        self.size_box.addAction(action)
        return action

    def _action(self, text, tip, slot) -> QAction:
        action = QAction(text, self)
        self.addAction(action)
        action.setToolTip(tip)
        action.triggered.connect(lambda _=False: slot())
        return action

    def menu_actions(self) -> list[QAction]:
        """Its actions that apply now (for the window's Edit menu)."""
        return [a for a in (*self.mode_actions.values(), self.smaller_action, self.larger_action, self.clear_action,
                            self.invert_action, self.transparent_action, self.extend_action) if a.isVisible()]

    def attach(self, mask_tool: MaskTool | None, margins_tool: MarginsTool | None) -> None:
        """Show the buttons of these tools (a view with neither hides the bar)."""
        self.mask_tool, self.margins_tool = mask_tool, margins_tool
        has_mask = mask_tool is not None
        for a in [*self.mode_actions.values(), self.size_action, self.smaller_action, self.larger_action,
                  self.clear_action, self.invert_action, self.transparent_action]:
            a.setVisible(has_mask)
        self.extend_action.setVisible(margins_tool is not None)
        if has_mask:
            mask_tool.on_size = self._show_size
            self.mode_actions[mask_tool.mode].setChecked(True)
            self._show_size(mask_tool.size)
        self.setVisible(has_mask or margins_tool is not None)
        self.refresh()

    def _show_size(self, size: int) -> None:
        if self.size_box.value() != size:
            self.size_box.blockSignals(True)
            self.size_box.setValue(size)
            self.size_box.blockSignals(False)

    def _on_image(self) -> tuple[str, object | None]:
        on = self.mask_tool.geometry.input_for(self.doc.inputs)
        return on, self.doc.item(on)

    def refresh(self) -> None:
        """Enable the actions that can do something now (a disabled one says why in its tooltip)."""
        if self.mask_tool is None:
            return
        on, item = self._on_image()
        pretty = on.replace("_", " ")
        mask = self.mask_tool.mask()
        self.clear_action.setEnabled(mask is not None and bool(mask))
        self.invert_action.setEnabled(item is not None)
        alpha = None if item is None else item.alpha
        if item is None:
            why = f"no {pretty} is open"
        elif alpha is None:
            why = f"the {pretty} has no alpha channel: nothing is transparent"
        elif not (alpha < 0.5).any():
            why = f"the {pretty} has an alpha channel but no transparent pixel"
        else:
            why = ""
        self.transparent_action.setEnabled(not why)
        self.transparent_action.setToolTip(why or f"make the mask the transparent pixels of the {pretty}")

    def _size(self) -> tuple[int, int]:
        return self.mask_tool.view.image_size()

    def clear_mask(self) -> None:
        if self.mask_tool is not None and self.mask_tool.mask() is not None:
            self.doc.set_mask(self.mask_tool.geometry_key, None, "Clear mask")

    def invert_mask(self) -> None:
        if self.mask_tool is None or self._on_image()[1] is None:
            return
        base = self.mask_tool.base()
        self.doc.set_mask(self.mask_tool.geometry_key, Mask(~base.bits), "Invert mask")

    def fill_transparent(self) -> None:
        if self.mask_tool is None:
            return
        on, item = self._on_image()
        if item is None or item.alpha is None:
            self.message.emit(f"the {on.replace('_', ' ')} has no alpha channel: nothing is transparent")
            return
        self.doc.set_mask(self.mask_tool.geometry_key, Mask.from_alpha(item.alpha), "Fill transparent")

    def extend_dialog(self) -> ExtendDialog | None:
        """Open the "Extend canvas" dialog (window-modal); OK sets the margins (one undo step)."""
        tool = self.margins_tool
        if tool is None:
            return None
        dialog = ExtendDialog(tool.margins(), tool.view.image_size(), self.window())
        dialog.setAttribute(Qt.WidgetAttribute.WA_DeleteOnClose)

        def apply() -> None:
            margins = dialog.margins()
            if margins != tool.margins():
                self.doc.set_margins(tool.geometry_key, margins, f"Extend canvas {margins.to_text()}")

        dialog.accepted.connect(apply)
        self.dialog = dialog  # (the open one: tests reach it)
        dialog.open()
        return dialog
