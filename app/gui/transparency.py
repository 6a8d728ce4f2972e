"""Where a picture is transparent, as image editors show it: a checkerboard and the region's outline.

:class:`TransparencyItem` is a view's overlay, in image pixels, over the picture and under the
tools' overlays (a painted mask shows over it); :func:`transparent_path` is its outline.
"""

from __future__ import annotations

import cv2
import numpy as np
from PySide6.QtCore import QPointF, QRectF, Qt
from PySide6.QtGui import QBrush, QColor, QImage, QPainter, QPainterPath, QPen, QPolygonF, QTransform
from PySide6.QtWidgets import QGraphicsItem


def transparent_path(alpha: np.ndarray | None) -> QPainterPath:
    """The outline of where ``alpha`` (H, W) in [0, 1] is under one half (what shows as transparent),
    in image pixels: polygons along the pixel edges, holes inside them kept (odd-even fill)."""
    path = QPainterPath()
    path.setFillRule(Qt.FillRule.OddEvenFill)
    if alpha is None:
        return path
    clear = np.ascontiguousarray(alpha < 0.5, dtype=np.uint8)
    if not clear.any():
        return path
    # contours of the 2x upscaled mask run along pixel edges once halved (not through pixel centres)
    big = cv2.resize(clear, None, fx=2, fy=2, interpolation=cv2.INTER_NEAREST)
    contours, _ = cv2.findContours(np.pad(big, 1), cv2.RETR_LIST, cv2.CHAIN_APPROX_SIMPLE)
    for c in contours:
        pts = (c[:, 0, :].astype(np.float64) - 1 + 0.5) / 2.0  # (padding; pixel edges)
        pts = np.round(pts)
        polygon = QPolygonF([QPointF(float(x), float(y)) for x, y in pts])
        path.addPolygon(polygon)
        path.closeSubpath()
    return path


class TransparencyItem(QGraphicsItem):
    """Where the picture is transparent: a checkerboard of constant size on screen (as image editors
    show it) over the colour stored there, and the region's outline (white under black dashes, seen
    on any picture)."""

    CHECK_PX = 8

    def __init__(self, parent=None):
        super().__init__(parent)
        self._path = QPainterPath()
        self.setZValue(3)  # over the picture, under the tools' overlays (a painted mask)

    def set_alpha(self, alpha: np.ndarray | None) -> None:
        self.prepareGeometryChange()
        self._path = transparent_path(alpha)
        self.setVisible(not self._path.isEmpty())
        self.update()

    def path(self) -> QPainterPath:
        return self._path

    def boundingRect(self) -> QRectF:  # noqa: N802 (Qt naming)
        return self._path.boundingRect().adjusted(-2, -2, 2, 2)

    def paint(self, painter, option, widget=None) -> None:
        if self._path.isEmpty():
            return
        scale = max(painter.worldTransform().m11(), 1e-6)
        tile = QImage(2 * self.CHECK_PX, 2 * self.CHECK_PX, QImage.Format.Format_RGB32)
        tile.fill(QColor(204, 204, 204))
        p = QPainter(tile)
        p.fillRect(0, 0, self.CHECK_PX, self.CHECK_PX, QColor(153, 153, 153))
        p.fillRect(self.CHECK_PX, self.CHECK_PX, self.CHECK_PX, self.CHECK_PX, QColor(153, 153, 153))
        p.end()
        brush = QBrush(tile)
        brush.setTransform(QTransform.fromScale(1 / scale, 1 / scale))  # checks of CHECK_PX screen pixels
        painter.fillPath(self._path, brush)
        for colour, style in ((QColor("white"), Qt.PenStyle.SolidLine), (QColor("black"), Qt.PenStyle.DashLine)):
            pen = QPen(colour, 1.5, style)
            pen.setCosmetic(True)
            painter.strokePath(self._path, pen)
