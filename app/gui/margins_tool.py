"""Dragging an uncrop's canvas edges outward: the margins geometry (``Geometry(MARGINS, param=...)``).

``MarginsTool``: a press outside the image drags the canvas edges on that side outward (the grown
frame drawn as a dashed outline); one undo command on release; Esc cancels. ``ExtendDialog``:
"Extend canvas…", the four margins typed.
"""

from __future__ import annotations

from collections.abc import Callable

from PySide6.QtCore import QRectF, Qt
from PySide6.QtGui import QColor
from PySide6.QtWidgets import QDialog, QDialogButtonBox, QFormLayout, QGraphicsRectItem, QLabel, QSpinBox
from weft.core.geometry import MAX_SIDE, Margins

from .tools import Tool, _cosmetic


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
        return Margins(
            *(max(0, min(MAX_SIDE, int(round(v + d)))) if s else v for v, d, s in zip(m, moves, sides, strict=True))
        )

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


class ExtendDialog(QDialog):
    """ "Extend canvas…": the four margins typed, in pixels."""

    def __init__(self, margins: Margins, size: tuple[int, int], parent=None):
        super().__init__(parent)
        self.setWindowTitle("Extend canvas")
        self.size_ = size
        form = QFormLayout(self)
        self.boxes = {}
        for side, value in zip(("left", "top", "right", "bottom"), margins, strict=True):
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
