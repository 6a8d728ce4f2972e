"""The brush of one painted mask (``Geometry(MASK, input=...)``) over its image.

Brush and eraser (round, size with ``[`` / ``]``, shown as a circle of the brush's size on screen),
lasso (add or subtract a polygon). A brush or eraser stroke is painted into a Qt-free ``MaskStroke``
(a copy of the mask made at the press, changed in place dab by dab: a dab costs its own pixels, in
the mask and in the overlay), a lasso with ``Mask.painted_polygon``; a stroke is one undo command,
pushed on release; Esc cancels a stroke in progress. While a brush or eraser stroke is drawn,
``on_stroke(stroke, box)`` hears the ``MaskStroke`` so far and the box around the latest dab;
``on_stroke(None, None)``: the stroke ended without an edit (Esc, or a release that changed nothing).

A mask whose absence means "every pixel" (``Geometry.empty_is_all``: a region to copy from) is
painted the same way, its brush read as *Include* and its eraser as *Exclude*: with nothing painted,
an *Include* stroke starts from an empty mask (only what is painted), an *Exclude* stroke or lasso
from a mask set everywhere (all but what is painted).

The brush's default size follows the picture (:func:`default_size`); a size the user picks is kept
as a fraction of the picture's longer side, in the window's settings when it has them, so it
survives a restart and a crash recovery, and follows to a picture of another size.

Several masks on one image each have a tool; the view's bar *arms* one of them (:attr:`MaskTool.armed`):
only the armed tool paints, shows its circle and takes ``[`` / ``]``.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from PySide6.QtCore import QPointF, QRectF, QSettings, QSize, Qt
from PySide6.QtGui import QBrush, QColor, QPainterPath
from PySide6.QtWidgets import QGraphicsEllipseItem, QGraphicsPathItem
from weft.core.geometry import MASK, Mask, MaskStroke

from .mask_overlay import MASK_COLOURS, MaskOverlay
from .tools import Tool, _cosmetic

BRUSH_MIN, BRUSH_MAX = 1, 512
#: The default brush's diameter as a fraction of the picture's longer side (a 600 px photo: 24 px).
BRUSH_FRACTION = 1 / 25
BRUSH_DEFAULT = 24  # before a picture is shown
BRUSH, ERASER, LASSO_ADD, LASSO_SUBTRACT = "brush", "eraser", "lasso add", "lasso subtract"
MODES = (BRUSH, ERASER, LASSO_ADD, LASSO_SUBTRACT)


def default_size(width: int, height: int, fraction: float = BRUSH_FRACTION) -> int:
    """The brush diameter for a ``width`` x ``height`` picture: ``fraction`` of its longer side, at
    least 3 px (within ``BRUSH_MIN``..``BRUSH_MAX``)."""
    return int(min(BRUSH_MAX, max(3, BRUSH_MIN, round(max(width, height) * fraction))))


class MaskTool(Tool):
    """Paints the mask geometry ``geometry`` of the current method on ``view`` (module docstring)."""

    def __init__(
        self,
        view,
        doc,
        geometry,
        on_stroke: Callable[[Mask | None, tuple | None], None] | None = None,
        on_size: Callable[[int], None] | None = None,
    ):
        self.view, self.doc, self.geometry, self.on_stroke, self.on_size = view, doc, geometry, on_stroke, on_size
        self.geometry_key = geometry.key
        self.mode = BRUSH
        self.size = BRUSH_DEFAULT  # brush diameter in image pixels
        self.armed = True  # the one of an image's mask tools that paints (the bar's switch)
        self._sized_for: tuple[int, int] | None = None  # the picture size the brush was last sized for
        self._fraction: float | None = None  # the size the user picked, relative to that picture
        masks = [g.key for g in doc.studio.geometry if g.kind == MASK]
        index = masks.index(geometry.key) if geometry.key in masks else 0
        scene = view.scene()
        self.overlay = MaskOverlay(MASK_COLOURS[index % len(MASK_COLOURS)])
        self.overlay.setZValue(5 - 0.1 * index)  # the first mask (a hole) over the others
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

    @property
    def everywhere(self) -> bool:
        """Nothing painted means every pixel (``Geometry.empty_is_all``)."""
        return bool(getattr(self.geometry, "empty_is_all", False))

    @property
    def name(self) -> str:
        """What the mask is, in words (its label, else its input's name)."""
        return getattr(self.geometry, "label", "") or self.geometry_key.replace("_", " ")

    def mask(self) -> Mask | None:
        """The document's mask if it fits the image shown (else None)."""
        value = self.doc.value(self.geometry_key)
        w, h = self.view.image_size()
        return value if value is not None and value.shape == (h, w) else None

    def base(self, *, adding: bool = True) -> Mask:
        """The mask a stroke starts from: the document's, else empty -- or, for a mask whose absence
        means every pixel, set everywhere when the stroke takes pixels away (``adding`` False)."""
        mask = self.mask()
        if mask is not None:
            return mask
        w, h = max(self.view.image_size()[0], 1), max(self.view.image_size()[1], 1)
        if self.everywhere and not adding:
            return Mask(np.ones((h, w), dtype=bool))
        return Mask.empty(w, h)

    @property
    def radius(self) -> float:
        """The brush's radius for ``Mask.painted_line``: a diameter of ``size`` pixels."""
        return (self.size - 1) / 2.0

    def claims(self, pos, modifiers=Qt.KeyboardModifier.NoModifier) -> bool:
        """A press at scene point ``pos`` outside the image is a brush stroke, not an edge drag: a
        brush or eraser whose circle covers the centre of an image pixel there (Shift: never)."""
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

    def set_size(self, size: int, *, picked: bool = True) -> None:
        """The brush's diameter in image pixels (``picked``: by the user, remembered relative to the
        picture; else a default for the picture)."""
        size = int(min(max(size, BRUSH_MIN), BRUSH_MAX))
        if picked:
            w, h = self.view.image_size()
            if w and h:
                self._fraction = size / max(w, h)
                self._sized_for = (w, h)
                self._remember(self._fraction)
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

    # --- the brush's size, kept relative to the picture ------------------------------------------
    def _settings(self) -> QSettings | None:
        settings = getattr(self.view.window(), "settings", None)
        return settings if isinstance(settings, QSettings) else None

    def _settings_key(self) -> str:
        return f"brush/{self.geometry_key}"

    def _remember(self, fraction: float) -> None:
        settings = self._settings()
        if settings is not None:
            settings.setValue(self._settings_key(), float(fraction))

    def _remembered(self) -> float | None:
        settings = self._settings()
        if settings is None:
            return None
        try:
            value = float(settings.value(self._settings_key(), 0.0) or 0.0)
        except (TypeError, ValueError):
            return None
        return value if 0.0 < value <= 1.0 else None

    def _fit_size(self) -> None:
        """A picture of another size is shown: the brush keeps its size relative to the picture (the
        one the user picked, remembered, or the default)."""
        w, h = self.view.image_size()
        if not w or not h or self._sized_for == (w, h) or self.active:
            return
        self._sized_for = (w, h)
        fraction = self._fraction if self._fraction is not None else self._remembered()
        self.set_size(default_size(w, h, fraction if fraction is not None else BRUSH_FRACTION), picked=False)

    # --- drawing -------------------------------------------------------------------------------
    def refresh(self) -> None:
        """Draw the document's mask (the stroke so far while painting). A stroke whose mask the
        document changed under it (Ctrl+Z, another image opened) is cancelled: its release must not
        put the undone mask back."""
        if self.active and self.mask() is not self.start:
            self.cancel()
            return
        self._fit_size()
        self._draw(self.live if self.active and self.live is not None else self.mask())

    def hide(self) -> None:
        self.active = False
        self.live = None
        self.points = []
        self.lasso_item.setPath(QPainterPath())
        self.overlay.set_mask(None)
        self._show_cursor(None)

    def disarm(self) -> None:
        """Another mask of this image is painted now: a stroke in progress is cancelled, no circle."""
        self.cancel()
        self.armed = False
        self._show_cursor(None)

    def _draw(self, mask: Mask | None) -> None:
        self.overlay.set_mask(mask)

    def _show_cursor(self, pos) -> None:
        """The brush's circle at ``pos`` (the mouse pointer a small cross inside it); None hides it."""
        if pos is None or self.mode not in (BRUSH, ERASER) or not self.armed:
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
            self.touched = (
                changed
                if t is None
                else (min(t[0], changed[0]), min(t[1], changed[1]), max(t[2], changed[2]), max(t[3], changed[3]))
            )
        if self.on_stroke is not None:  # the eraser's strokes too: erased pixels are previewed unfilled
            self.on_stroke(self.live, box)

    def press(self, view, pos, event):
        if not self.armed:
            return
        self.active = True
        self.start = self.mask()
        self.touched = None
        p = self._pixel(pos)
        if self.mode in (BRUSH, ERASER):
            w, h = self.view.image_size()
            full = self.start is None and self.everywhere and self.mode == ERASER
            self.live = MaskStroke(self.base(adding=False) if full else self.start, max(w, 1), max(h, 1))
            self.overlay.begin(self.live, self.start)
            self._dab(p, p)
        else:
            self.live = self.base(adding=self.mode == LASSO_ADD)
            self.points = [p]
            self._draw_lasso()

    def move(self, view, pos, event):
        if not self.armed:
            return
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

    def stroke_words(self) -> str:
        """The undo step's text for a stroke in the current mode."""
        if self.everywhere:
            words = {BRUSH: "Include", ERASER: "Exclude", LASSO_ADD: "Lasso include", LASSO_SUBTRACT: "Lasso exclude"}
            return f"{words[self.mode]} ({self.name})"
        return {BRUSH: "Brush stroke", ERASER: "Erase", LASSO_ADD: "Lasso", LASSO_SUBTRACT: "Lasso subtract"}[self.mode]

    def release(self, view, pos, event):
        if not self.active:
            return
        text = self.stroke_words()
        if self.mode in (BRUSH, ERASER):
            if self.last is not None and self._pixel(pos) != self.last:
                self._dab(self.last, self._pixel(pos))
            stroke = self.live
            # (a stroke of one mode only paints or only erases: it changed a pixel iff its mask differs)
            changed, mask = stroke.changed, stroke.mask()  # (its bits, not a copy)
            if changed:
                self.overlay.adopt(mask)  # (drawn dab by dab already)
        else:
            self.points.append(self._pixel(pos))
            mask = self.live.painted_polygon(self.points, self.mode == LASSO_ADD)
            changed = mask != self.live
        self._end()
        if changed and self.everywhere and not mask:
            # nothing left to copy from would read as "everywhere" again: refused, the mask stays
            self._cancelled()
            return
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
        elif start is None:
            self.overlay.set_mask(None)
        self.touched = None
        self.refresh()
        if self.on_stroke is not None:
            self.on_stroke(None, None)

    def key(self, view, event) -> bool:
        if event.key() == Qt.Key.Key_Escape:
            return self.cancel()
        if not self.armed:
            return False
        if event.key() == Qt.Key.Key_BracketRight:
            self.grow(+1)
            return True
        if event.key() == Qt.Key.Key_BracketLeft:
            self.grow(-1)
            return True
        return False
