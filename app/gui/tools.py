"""Mouse tools: one object per mouse mode, attached to an ``ImageView`` (DESIGN.md, GUI).

A tool gets the left-button press/move/release in scene (= image pixel) coordinates, draws its
overlay in the view's scene, and pushes one undo command on release. Esc cancels what is in progress.

* ``PatchTool``: a square rubber band (a square geometry of the current method: a source region or
  a square parameter); the side snaps to even pixels; drag inside to move it, drag a corner handle to
  resize it.
* ``LineTool``: feature lines on the photo or on the frontal frame; click-drag draws a line, dragging an
  end point edits it (and the ends of other lines at the same point, such as Quad…'s corners; Alt
  moves it alone), a click on a line selects it and Delete removes the pair. Lines are numbered
  and coloured alike in both views (line i of the photo goes with line i of the frontal frame).
* ``QuadTool``: four clicks on the corners of the textured plane, clockwise from its top-left corner,
  give four photo lines and the
  matching edges of the frontal rectangle.
"""

from __future__ import annotations

from collections.abc import Callable

from PySide6.QtCore import QPointF, QRectF, Qt
from PySide6.QtGui import QBrush, QColor, QFont, QPen
from PySide6.QtWidgets import QGraphicsEllipseItem, QGraphicsLineItem, QGraphicsRectItem, QGraphicsSimpleTextItem
from weft.core.geometry import Square

HANDLE_PX = 8  # grab distance of handles and end points, in screen pixels
LINKED = 0.5  # end points of feature lines this close (image pixels) are one point: they move together


def _screen_sized(item, x: float, y: float):
    """``item`` (drawn around its origin in screen pixels) placed at image point (x, y), keeping its
    size on screen at any zoom (a handle must not cover a corner when zoomed out, nor vanish when
    zoomed in)."""
    item.setFlag(item.GraphicsItemFlag.ItemIgnoresTransformations, True)
    item.setPos(x, y)
    return item


_HALF = HANDLE_PX / 2
PALETTE = [QColor(c) for c in ("#ff5252", "#40c4ff", "#ffd740", "#69f0ae", "#e040fb", "#ff9100", "#b2ff59", "#f8bbd0")]


def line_colour(i: int) -> QColor:
    return PALETTE[i % len(PALETTE)]


def _cosmetic(colour: QColor, width: float = 2.0, style=Qt.PenStyle.SolidLine) -> QPen:
    pen = QPen(colour, width, style)
    pen.setCosmetic(True)  # constant on-screen width at any zoom
    return pen


class Tool:
    """Base: a tool does nothing until it overrides the handlers."""

    def press(self, view, pos: QPointF, event) -> None: ...

    def move(self, view, pos: QPointF, event) -> None: ...

    def release(self, view, pos: QPointF, event) -> None: ...

    def key(self, view, event) -> bool:
        return False

    def refresh(self) -> None: ...

    def hide(self) -> None:
        """Remove the overlay (the tool is detached from its view)."""


class PatchTool(Tool):
    """A square ``(x, y, side)`` with an even side, inside the image: the geometry ``key`` of the
    document's current method."""

    def __init__(self, view, doc, key: str, on_drag: Callable[[Square], None] | None = None):
        self.view, self.doc, self.geometry_key, self.on_drag = view, doc, key, on_drag
        self.rect_item = QGraphicsRectItem()
        self.rect_item.setPen(_cosmetic(QColor("#ffd740"), 2, Qt.PenStyle.DashLine))
        self.rect_item.setZValue(10)
        view.scene().addItem(self.rect_item)
        self.handles = []
        for _ in range(4):
            h = QGraphicsRectItem()
            h.setPen(_cosmetic(QColor("#ffd740"), 1))
            h.setBrush(QBrush(QColor(255, 215, 64, 160)))
            h.setZValue(11)
            view.scene().addItem(h)
            self.handles.append(h)
        self.mode = None
        self.anchor = None
        self.offset = None
        self.live: Square | None = None
        self.refresh()

    @property
    def square(self) -> Square | None:
        return self.doc.value(self.geometry_key)

    def hide(self) -> None:
        self.mode = None
        self._show(None)

    def _corners(self, rect):
        x, y, s = rect
        return [(x, y), (x + s, y), (x, y + s), (x + s, y + s)]

    def _show(self, rect) -> None:
        visible = rect is not None
        self.rect_item.setVisible(visible)
        for h in self.handles:
            h.setVisible(visible)
        if not visible:
            return
        x, y, s = rect
        self.rect_item.setRect(QRectF(x, y, s, s))
        for h, (cx, cy) in zip(self.handles, self._corners(rect), strict=True):
            h.setRect(QRectF(-_HALF, -_HALF, HANDLE_PX, HANDLE_PX))
            _screen_sized(h, cx, cy)

    def refresh(self) -> None:
        self._show(self.square)

    def _clamp(self, x: float, y: float, s: int) -> Square:
        w, h = self.view.image_size()
        s = int(max(2, min(s, min(w, h) - min(w, h) % 2)))
        s -= s % 2
        x = int(round(min(max(x, 0), w - s)))
        y = int(round(min(max(y, 0), h - s)))
        return Square(x, y, s)

    def press(self, view, pos, event):
        rect = self.square
        grab = view.screen_to_image_distance(HANDLE_PX)
        self.mode = "new"
        self.anchor = (pos.x(), pos.y())
        if rect is not None:
            corners = self._corners(rect)
            for i, (cx, cy) in enumerate(corners):
                if abs(pos.x() - cx) <= grab and abs(pos.y() - cy) <= grab:
                    self.mode = "resize"
                    self.anchor = corners[3 - i]  # the opposite corner stays put
                    break
            else:
                x, y, s = rect
                if x <= pos.x() <= x + s and y <= pos.y() <= y + s:
                    self.mode = "move"
                    self.offset = (pos.x() - x, pos.y() - y)
        self.live = rect if self.mode == "move" else None

    def _rect_from(self, pos) -> Square:
        if self.mode == "move":
            s = self.square[2]
            return self._clamp(pos.x() - self.offset[0], pos.y() - self.offset[1], s)
        ax, ay = self.anchor
        dx, dy = pos.x() - ax, pos.y() - ay
        s = int(max(abs(dx), abs(dy)))
        s -= s % 2
        w, h = self.view.image_size()
        # Keep the anchor corner fixed: the square grows towards the mouse, within the image.
        room_x = ax if dx < 0 else w - ax
        room_y = ay if dy < 0 else h - ay
        s = int(min(s, room_x, room_y))
        s -= s % 2
        s = max(s, 2)
        x = ax - s if dx < 0 else ax
        y = ay - s if dy < 0 else ay
        return self._clamp(x, y, s)

    def move(self, view, pos, event):
        if self.mode is None or not (event.buttons() & Qt.MouseButton.LeftButton):
            return
        self.live = self._rect_from(pos)
        self._show(self.live)
        if self.on_drag is not None:
            self.on_drag(self.live)

    def release(self, view, pos, event):
        if self.mode is None:
            return
        rect = self._rect_from(pos) if self.mode != "move" or self.live is not None else None
        if self.mode == "new" and max(abs(pos.x() - self.anchor[0]), abs(pos.y() - self.anchor[1])) < 2:
            rect = None  # a click, not a drag: keep the rectangle there is
        self.mode = None
        self.live = None
        if rect is not None:
            self.doc.set_geometry(self.geometry_key, rect, "Square")
        self.refresh()

    def key(self, view, event) -> bool:
        if event.key() == Qt.Key.Key_Escape and self.mode is not None:
            self.mode = None
            self.live = None
            self.refresh()
            if self.on_drag is not None and self.square is not None:
                self.on_drag(self.square)
            return True
        return False


class LineTool(Tool):
    """Feature lines of one view: ``which`` is ``"image"`` (the photo) or ``"frontal"``."""

    def __init__(self, view, doc, which: str, on_drag: Callable[[list, list], None] | None = None):
        self.view, self.doc, self.which, self.on_drag = view, doc, which, on_drag
        self.items: list = []
        self._dragged: list | None = None  # the lines as the drag in progress has them
        self.drag = None  # ("new", start) or ("end", index, 0|1, [(index, 0|1), ...] the ends moved together)
        self.selected: int | None = None
        self.refresh()

    def lines(self) -> list[list[float]]:
        return self.doc.image_lines if self.which == "image" else self.doc.frontal_lines

    def hide(self) -> None:
        self.drag = None
        self.refresh([])

    def _lists_with(self, mine: list[list[float]]) -> tuple[list, list]:
        if self.which == "image":
            return mine, [list(x) for x in self.doc.frontal_lines]
        return [list(x) for x in self.doc.image_lines], mine

    def refresh(self, lines: list[list[float]] | None = None) -> None:
        scene = self.view.scene()
        for it in self.items:
            scene.removeItem(it)
        self.items = []
        if lines is None and self.drag is not None and self._dragged is not None:
            lines = self._dragged  # (a redraw mid-drag, e.g. a new rectification: the line being drawn stays)
        lines = self.lines() if lines is None else lines
        font = QFont()
        font.setPointSize(9)
        font.setBold(True)
        for i, (x1, y1, x2, y2) in enumerate(lines):
            colour = line_colour(i)
            width = 3.5 if i == self.selected else 2.0
            seg = QGraphicsLineItem(x1, y1, x2, y2)
            seg.setPen(_cosmetic(colour, width))
            items = [seg]
            for x, y in ((x1, y1), (x2, y2)):
                dot = _screen_sized(QGraphicsEllipseItem(-_HALF, -_HALF, HANDLE_PX, HANDLE_PX), x, y)
                dot.setPen(_cosmetic(QColor("black"), 1))
                dot.setBrush(QBrush(colour))
                items.append(dot)
            label = QGraphicsSimpleTextItem(str(i + 1))
            label.setFont(font)
            label.setBrush(QBrush(colour))
            label.setFlag(QGraphicsSimpleTextItem.GraphicsItemFlag.ItemIgnoresTransformations, True)
            label.setPos((x1 + x2) / 2, (y1 + y2) / 2)
            items.append(label)
            for it in items:
                it.setZValue(20)
                scene.addItem(it)
            self.items.extend(items)

    def _near_end(self, pos) -> tuple[int, int] | None:
        grab = self.view.screen_to_image_distance(HANDLE_PX)
        best = None
        for i, (x1, y1, x2, y2) in enumerate(self.lines()):
            for end, (x, y) in enumerate(((x1, y1), (x2, y2))):
                d = ((pos.x() - x) ** 2 + (pos.y() - y) ** 2) ** 0.5
                if d <= grab and (best is None or d < best[0]):
                    best = (d, i, end)
        return None if best is None else best[1:]

    def _near_line(self, pos) -> int | None:
        grab = self.view.screen_to_image_distance(HANDLE_PX / 2)
        for i, (x1, y1, x2, y2) in enumerate(self.lines()):
            dx, dy = x2 - x1, y2 - y1
            length2 = dx * dx + dy * dy
            if length2 == 0:
                continue
            t = max(0.0, min(1.0, ((pos.x() - x1) * dx + (pos.y() - y1) * dy) / length2))
            px, py = x1 + t * dx, y1 + t * dy
            if ((pos.x() - px) ** 2 + (pos.y() - py) ** 2) ** 0.5 <= grab:
                return i
        return None

    def _clamp(self, pos) -> tuple[float, float]:
        w, h = self.view.image_size()
        return min(max(pos.x(), 0.0), float(w)), min(max(pos.y(), 0.0), float(h))

    def press(self, view, pos, event):
        self._dragged = None
        end = self._near_end(pos)
        if end is not None:
            # ends at the same point move together (Quad…'s corners: two lines meet at each), unless
            # Alt is held (then only the end grabbed moves)
            i, k = end
            ends = [(i, k)]
            if not event.modifiers() & Qt.KeyboardModifier.AltModifier:
                x, y = self.lines()[i][2 * k : 2 * k + 2]
                ends += [
                    (j, e)
                    for j, line in enumerate(self.lines())
                    for e in (0, 1)
                    if (j, e) != (i, k) and abs(line[2 * e] - x) < LINKED and abs(line[2 * e + 1] - y) < LINKED
                ]
            self.drag = ("end", i, k, ends)
            self.selected = i
        else:
            hit = self._near_line(pos)
            if hit is not None:
                self.selected = hit
                self.drag = None
                self.refresh()
                return
            self.drag = ("new", self._clamp(pos))

    def _edited(self, pos) -> list[list[float]]:
        lines = [list(x) for x in self.lines()]
        x, y = self._clamp(pos)
        if self.drag[0] == "new":
            sx, sy = self.drag[1]
            lines.append([sx, sy, x, y])
        else:
            for i, end in self.drag[3]:
                lines[i][2 * end : 2 * end + 2] = [x, y]
        return lines

    def move(self, view, pos, event):
        if self.drag is None or not (event.buttons() & Qt.MouseButton.LeftButton):
            return
        lines = self._edited(pos)
        self._dragged = lines
        self.refresh(lines)
        if self.on_drag is not None:
            self.on_drag(*self._lists_with(lines))

    def release(self, view, pos, event):
        if self.drag is None:
            return
        lines = self._edited(pos)
        kind = self.drag[0]
        self.drag = self._dragged = None
        if kind == "new":
            x1, y1, x2, y2 = lines[-1]
            if ((x2 - x1) ** 2 + (y2 - y1) ** 2) ** 0.5 < self.view.screen_to_image_distance(4):
                self.refresh()  # a click, not a line
                return
            self.selected = len(lines) - 1
            text = f"Draw line {len(lines)}"
        else:
            text = f"Move end of line {self.selected + 1}"
        self.doc.set_lines(*self._lists_with(lines), text=text)
        self.refresh()

    def delete_selected(self) -> bool:
        i = self.selected
        if i is None or i >= len(self.lines()):
            return False
        image = [x for j, x in enumerate(self.doc.image_lines) if j != i]
        frontal = [x for j, x in enumerate(self.doc.frontal_lines) if j != i]
        self.selected = None
        self.doc.set_lines(image, frontal, text=f"Delete line {i + 1}")
        return True

    def key(self, view, event) -> bool:
        if event.key() == Qt.Key.Key_Escape and self.drag is not None:
            self.drag = None
            self.refresh()
            return True
        if event.key() in (Qt.Key.Key_Delete, Qt.Key.Key_Backspace):
            return self.delete_selected()
        return False


class QuadTool(Tool):
    """Four clicks on the plane's corners, clockwise from top-left -> four line pairs (the frontal
    rectangle's edges)."""

    CORNERS = ("top-left", "top-right", "bottom-right", "bottom-left")

    def __init__(
        self, view, doc, on_done: Callable[[], None] | None = None, on_prompt: Callable[[str], None] | None = None
    ):
        self.view, self.doc, self.on_done, self.on_prompt = view, doc, on_done, on_prompt
        self.points: list[tuple[float, float]] = []
        self.items: list = []
        self._prompt()

    def _prompt(self) -> None:
        """Say which corner to click next (on screen, through ``on_prompt``)."""
        if self.on_prompt is not None and len(self.points) < 4:
            k = len(self.points)
            self.on_prompt(
                f"Quad: click the plane's {self.CORNERS[k]} corner on the photo ({k + 1} of 4"
                f"{'' if k == 0 else '; Esc starts again'})"
            )

    def _draw(self) -> None:
        scene = self.view.scene()
        for it in self.items:
            scene.removeItem(it)
        self.items = []
        for i, (x, y) in enumerate(self.points):
            dot = _screen_sized(QGraphicsEllipseItem(-_HALF, -_HALF, HANDLE_PX, HANDLE_PX), x, y)
            dot.setBrush(QBrush(line_colour(i)))
            dot.setZValue(21)
            scene.addItem(dot)
            self.items.append(dot)

    def press(self, view, pos, event):
        w, h = view.image_size()
        self.points.append((min(max(pos.x(), 0.0), w), min(max(pos.y(), 0.0), h)))
        self._draw()
        self._prompt()
        if len(self.points) == 4:
            pts = self.points
            self.points = []
            self._draw()
            image_lines = [[*pts[i], *pts[(i + 1) % 4]] for i in range(4)]
            fw, fh = self.doc.frontal_size
            corners = [(0.0, 0.0), (fw - 1.0, 0.0), (fw - 1.0, fh - 1.0), (0.0, fh - 1.0)]
            frontal_lines = [[*corners[i], *corners[(i + 1) % 4]] for i in range(4)]
            self.doc.set_lines(image_lines, frontal_lines, text="Quad")
            if self.on_done is not None:
                self.on_done()

    def key(self, view, event) -> bool:
        if event.key() == Qt.Key.Key_Escape and self.points:
            self.points = []
            self._draw()
            self._prompt()
            return True
        return False
