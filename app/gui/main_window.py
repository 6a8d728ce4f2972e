"""The main window: the bundled examples on the left, the chosen image in a zoomable view.

Images are decoded on the worker pool (``core.jobs.JobRunner``) and come back to the GUI thread
through a queued Qt signal, so opening a large file never freezes the window; a failed open keeps
the image that was shown and says why in the status bar.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PySide6.QtCore import QObject, QPointF, QSize, Qt, Signal
from PySide6.QtGui import QAction, QIcon, QKeySequence, QPainter, QPixmap
from PySide6.QtWidgets import (
    QDockWidget,
    QFileDialog,
    QGraphicsPixmapItem,
    QGraphicsScene,
    QGraphicsView,
    QLabel,
    QListWidget,
    QListWidgetItem,
    QMainWindow,
)

from core import registry
from core.examples import examples
from core.image import load_image
from core.jobs import JobResult, JobRunner

from .convert import to_qimage

OPEN_FILTER = "Images (*.png *.jpg *.jpeg *.tif *.tiff *.bmp *.webp);;All files (*)"


class ImageView(QGraphicsView):
    """A zoomable, pannable view of one image; reports the pixel under the mouse.

    Wheel zooms under the cursor, left-drag pans, ``fit()`` fits the window, ``actual_size()`` is 1:1.
    ``hovered(x, y)`` carries image pixel coordinates (-1, -1 when outside the image).
    """

    hovered = Signal(int, int)
    zoomed = Signal(float)

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setScene(QGraphicsScene(self))
        self._item = QGraphicsPixmapItem()
        self._item.setTransformationMode(Qt.TransformationMode.FastTransformation)
        self.scene().addItem(self._item)
        self.image: np.ndarray | None = None
        self.setTransformationAnchor(QGraphicsView.ViewportAnchor.NoAnchor)
        self.setResizeAnchor(QGraphicsView.ViewportAnchor.AnchorViewCenter)
        self.setDragMode(QGraphicsView.DragMode.ScrollHandDrag)
        self.setRenderHint(QPainter.RenderHint.SmoothPixmapTransform, False)
        self.setMouseTracking(True)
        self.setBackgroundBrush(Qt.GlobalColor.darkGray)

    def set_image(self, image: np.ndarray, *, fit: bool = True) -> None:
        self.image = image
        self._item.setPixmap(QPixmap.fromImage(to_qimage(image)))
        self.scene().setSceneRect(self._item.boundingRect())
        if fit:
            self.fit()

    def scale_factor(self) -> float:
        return self.transform().m11()

    def fit(self) -> None:
        if self.image is not None:
            self.fitInView(self._item, Qt.AspectRatioMode.KeepAspectRatio)
            self.zoomed.emit(self.scale_factor())

    def actual_size(self) -> None:
        self.resetTransform()
        self.zoomed.emit(1.0)

    def zoom_by(self, factor: float, at=None) -> None:
        """Zoom by ``factor`` keeping the image point under view position ``at`` (default: centre) fixed."""
        new = self.scale_factor() * factor
        if not 1 / 64 <= new <= 64:
            return
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

    def image_pos(self, view_pos) -> tuple[int, int]:
        p: QPointF = self.mapToScene(view_pos)
        x, y = int(np.floor(p.x())), int(np.floor(p.y()))
        if self.image is None or not (0 <= x < self.image.shape[1] and 0 <= y < self.image.shape[0]):
            return -1, -1
        return x, y

    def mouseMoveEvent(self, event):  # noqa: N802
        self.hovered.emit(*self.image_pos(event.position().toPoint()))
        super().mouseMoveEvent(event)


class _Bridge(QObject):
    """Carries job results from worker threads to the GUI thread (queued connection)."""

    finished = Signal(object)


class MainWindow(QMainWindow):
    """The examples browser: pick a bundled example or open a file, zoom and inspect pixels."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setWindowTitle("weft")
        self.resize(1100, 720)
        self.view = ImageView(self)
        self.setCentralWidget(self.view)
        self.current_path: Path | None = None
        self.pixel_label = QLabel("")
        self.zoom_label = QLabel("")
        self.statusBar().addPermanentWidget(self.pixel_label)
        self.statusBar().addPermanentWidget(self.zoom_label)

        self._bridge = _Bridge(self)
        self._bridge.finished.connect(self._on_job_done)
        self.runner = JobRunner(max_workers=2, on_result=self._bridge.finished.emit)
        # Load the methods' compiled kernels off the GUI thread, so the first result is not slow.
        self.runner.submit("warm-up", _warm_up_job)

        self.example_list = QListWidget()
        self.example_list.setViewMode(QListWidget.ViewMode.IconMode)
        self.example_list.setIconSize(QSize(96, 96))
        self.example_list.setResizeMode(QListWidget.ResizeMode.Adjust)
        self.example_list.setMovement(QListWidget.Movement.Static)
        self.example_list.setSpacing(6)
        for path in examples():
            item = QListWidgetItem(QIcon(str(path)), path.stem)
            item.setData(Qt.ItemDataRole.UserRole, str(path))
            item.setToolTip(str(path))
            self.example_list.addItem(item)
        self.example_list.currentItemChanged.connect(self._on_example)
        dock = QDockWidget("Examples", self)
        dock.setObjectName("examples")
        dock.setWidget(self.example_list)
        dock.setMinimumWidth(250)
        self.addDockWidget(Qt.DockWidgetArea.LeftDockWidgetArea, dock)

        self.view.hovered.connect(self._on_hover)
        self.view.zoomed.connect(lambda s: self.zoom_label.setText(f"{s * 100:.0f}%"))
        self._build_menus()
        if self.example_list.count():
            self.example_list.setCurrentRow(0)
        else:
            self.statusBar().showMessage("no bundled examples found (resources/ is missing); use File > Open")

    def _build_menus(self) -> None:
        file_menu = self.menuBar().addMenu("&File")
        self.open_action = QAction("&Open Image…", self, shortcut=QKeySequence.StandardKey.Open)
        self.open_action.triggered.connect(self._open_dialog)
        file_menu.addAction(self.open_action)
        file_menu.addSeparator()
        quit_action = QAction("&Quit", self, shortcut=QKeySequence.StandardKey.Quit)
        quit_action.triggered.connect(self.close)
        file_menu.addAction(quit_action)
        view_menu = self.menuBar().addMenu("&View")
        for text, keys, slot in (
            ("Zoom &In", QKeySequence.StandardKey.ZoomIn, lambda: self.view.zoom_by(1.25)),
            ("Zoom &Out", QKeySequence.StandardKey.ZoomOut, lambda: self.view.zoom_by(0.8)),
            ("&Fit to Window", QKeySequence("Ctrl+0"), self.view.fit),
            ("&Actual Size", QKeySequence("Ctrl+1"), self.view.actual_size),
        ):
            action = QAction(text, self, shortcut=keys)
            action.triggered.connect(slot)
            view_menu.addAction(action)

    # --- loading -----------------------------------------------------------------------------
    def open_path(self, path: str | Path) -> None:
        """Decode ``path`` on the worker pool; the result (or error) arrives in ``_on_loaded``."""
        path = Path(path)
        self.statusBar().showMessage(f"opening {path.name}…")
        self.runner.submit("open", _load_job, str(path))

    def _on_job_done(self, result: JobResult) -> None:
        if result.slot == "open":
            self._on_loaded(result)
        elif result.error is not None:
            self.statusBar().showMessage(f"{result.slot} failed: {result.error}")

    def _on_loaded(self, result: JobResult) -> None:
        if result.error is not None:
            self.statusBar().showMessage(f"could not open: {result.error}")
            return
        path, loaded = result.value
        self.current_path = Path(path)
        self.view.set_image(loaded.image)
        info = loaded.info
        notes = f" — {', '.join(info.notes)}" if info.notes else ""
        self.setWindowTitle(f"{self.current_path.name} — weft")
        self.statusBar().showMessage(
            f"{self.current_path.name}: {info.width}x{info.height}, {info.format}, {info.bit_depth}-bit{notes}"
        )

    def _on_example(self, item: QListWidgetItem | None, _previous=None) -> None:
        if item is not None:
            self.open_path(item.data(Qt.ItemDataRole.UserRole))

    def _open_dialog(self) -> None:
        start = str(self.current_path.parent) if self.current_path else ""
        path, _ = QFileDialog.getOpenFileName(self, "Open image", start, OPEN_FILTER)
        if path:
            self.open_path(path)

    def _on_hover(self, x: int, y: int) -> None:
        img = self.view.image
        if x < 0 or img is None:
            self.pixel_label.setText("")
            return
        v = img[y, x]
        value = f"{float(v):.3f}" if np.ndim(v) == 0 else " ".join(f"{float(c):.3f}" for c in v)
        self.pixel_label.setText(f"x {x}  y {y}  value {value}")

    # --- shutdown ----------------------------------------------------------------------------
    def shutdown(self) -> None:
        self.runner.shutdown(wait=True, cancel=True)

    def closeEvent(self, event):  # noqa: N802
        self.shutdown()
        super().closeEvent(event)


def _warm_up_job(*, progress=None, cancel=None) -> None:
    registry.warm_up_all()


def _load_job(path: str, *, progress=None, cancel=None):
    loaded = load_image(path)
    if cancel is not None:
        cancel.raise_if_cancelled()
    return path, loaded
