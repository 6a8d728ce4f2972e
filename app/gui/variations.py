"""The variations grid: two parameters, two ranges, an n x n grid of thumbnails rendered in parallel.

It offers the parameters that change something with the current settings and inputs (the method's
``Studio.idle`` names the others); an exported grid is labelled with the parameters and values.

Clicking a cell adopts its two values (one undo step). Cells render on their own worker pool at
thumbnail size (the target or output size scaled so its longer side is ``THUMB_SIDE``), so the main
window's renders are not held up; a cell whose values the method refuses says why. The thumbnail-size
inputs are built once per grid on that pool too (the GUI thread only takes a snapshot of the
document at the click: it never blocks on image work), then the cells are submitted; a new grid or
closing the dialog cancels the preparation and the cells, and a late result of an earlier grid is
dropped.
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QPoint, QRect, QSize, Qt, QTimer, Signal
from PySide6.QtGui import QColor, QFont, QFontMetrics, QIcon, QImage, QPainter, QPixmap
from PySide6.QtWidgets import (
    QComboBox,
    QDialog,
    QDoubleSpinBox,
    QFileDialog,
    QGridLayout,
    QLabel,
    QPushButton,
    QToolButton,
    QVBoxLayout,
    QWidget,
)
from weft.core.errors import WeftError
from weft.core.image import save_image
from weft.core.jobs import JobResult
from weft.core.params import FLOAT, INT, specs
from weft.core.request import Prepared, Preview, RenderRequest

from .convert import to_qimage
from .qjobs import QtJobs
from .render_job import render_request

THUMB_SIDE = 192


def numeric_specs(params_cls) -> list:
    return [s for s in specs(params_cls) if s.kind in (INT, FLOAT) and s.lo is not None and s.hi is not None]


def grid_values(spec, lo: float, hi: float, n: int) -> list:
    """``n`` values from ``lo`` to ``hi`` (integers for int parameters, on the parameter's grid when
    it has a step, e.g. odd sides; duplicates removed)."""
    values = np.linspace(lo, hi, n)
    if spec.kind == INT:
        return list(dict.fromkeys(spec.on_grid(v, lo, hi) for v in values))
    return [round(float(v), 4) for v in values]


class VariationsDialog(QDialog):
    """See the module docstring. ``cell_done(i, j)`` fires when a thumbnail arrives."""

    cell_done = Signal(int, int)

    def __init__(self, doc, parent=None):
        super().__init__(parent)
        self.setWindowTitle(f"Variations — {doc.studio.title}")
        self.doc = doc
        self.method = doc.method
        self.runner = QtJobs(self, max_workers=2)
        self.runner.result.connect(self._on_result)
        self.cells: dict[tuple[int, int], QToolButton] = {}
        self.values: dict[tuple[int, int], tuple] = {}
        # only the parameters that change something with the current settings and inputs
        idle = doc.studio.idle_params(doc.run_params(live=False), doc.input_shapes())
        self.numeric = [s for s in numeric_specs(doc.current.params) if s.name not in idle]
        lay = QVBoxLayout(self)
        controls = QGridLayout()
        self.combo, self.lo, self.hi = [], [], []
        for row, default in enumerate((0, 1)):
            combo = QComboBox()
            combo.addItems([s.name for s in self.numeric])
            if len(self.numeric) > default:
                combo.setCurrentIndex(default)
            lo, hi = QDoubleSpinBox(), QDoubleSpinBox()
            for box in (lo, hi):
                box.setDecimals(3)
            combo.currentIndexChanged.connect(lambda _, r=row: self._reset_range(r))
            controls.addWidget(QLabel("rows" if row == 0 else "columns"), row, 0)
            controls.addWidget(combo, row, 1)
            controls.addWidget(QLabel("from"), row, 2)
            controls.addWidget(lo, row, 3)
            controls.addWidget(QLabel("to"), row, 4)
            controls.addWidget(hi, row, 5)
            self.combo.append(combo)
            self.lo.append(lo)
            self.hi.append(hi)
        self.size_box = QComboBox()
        self.size_box.addItems(["3 x 3", "4 x 4"])
        controls.addWidget(QLabel("grid"), 2, 0)
        controls.addWidget(self.size_box, 2, 1)
        self.render_button = QPushButton("Render grid")
        self.render_button.clicked.connect(self.render_grid)
        controls.addWidget(self.render_button, 2, 5)
        self.export_button = QPushButton("Export grid…")
        self.export_button.setToolTip("save the rendered cells as one PNG")
        self.export_button.setEnabled(False)
        self.export_button.clicked.connect(lambda: self.export_grid())
        controls.addWidget(self.export_button, 2, 3)
        self.images: dict[tuple[int, int], np.ndarray] = {}
        self.side = THUMB_SIDE
        self._preparing: int | None = None  # the job id of the grid's preparation while it runs
        self._cell_jobs: dict[tuple[int, int], int] = {}  # the job id of each cell submitted
        self._pending: set[tuple[int, int]] = set()  # the cells submitted and not yet arrived
        lay.addLayout(controls)
        self.grid_widget = QWidget()
        self.grid = QGridLayout(self.grid_widget)
        lay.addWidget(self.grid_widget, 1)
        self.status = QLabel("pick two parameters and their ranges, then Render grid; click a cell to adopt it")
        self.status.setWordWrap(True)  # a long message must not widen the dialog
        lay.addWidget(self.status)
        for r in (0, 1):
            self._reset_range(r)
        if len(self.numeric) < 2:
            self.render_button.setEnabled(False)
            self.status.setText(f"{self.method} has fewer than two numeric parameters")

    def _spec(self, row: int):
        return self.numeric[self.combo[row].currentIndex()]

    def _reset_range(self, row: int) -> None:
        """A range around the current value (what "auto" resolves to when it is ticked): half to
        one and a half times it, or a quarter of the parameter's range where that is narrower — so
        a block of 9 on a small texture gives 5..13, not 2..257."""
        if not self.numeric:
            return
        spec = self._spec(row)
        # the range the method accepts with the open inputs (a block fits in the sample), else the Spec's
        lo_limit, hi_limit = (
            self.doc.param_ranges().get(spec.name, (spec.lo, spec.hi))
            if self.method == self.doc.method
            else (spec.lo, spec.hi)
        )
        for box in (self.lo[row], self.hi[row]):
            box.setRange(lo_limit, hi_limit)
            box.setDecimals(0 if spec.kind == INT else 3)
            box.setSingleStep(int(spec.step or 1) if spec.kind == INT else (spec.step or (spec.hi - spec.lo) / 20))
        params = self.doc.params[self.method]
        current = getattr(params, spec.name)
        if current is None and self.method == self.doc.method:  # what "auto" resolves to, as a run resolves it
            current = self.doc.auto_values().get(spec.name)
        if current is None:
            current = spec.default if spec.default is not None else spec.lo
        span = (hi_limit - lo_limit) / 4
        if current:
            span = min(span, abs(current) / 2)
        if spec.kind == INT:
            step = int(spec.step or 1)
            span = max(step, int(span) // step * step)  # whole steps: the middle of the grid is the current value
        self.lo[row].setValue(max(lo_limit, current - span))
        self.hi[row].setValue(min(hi_limit, current + span))

    def thumb_side(self, n: int) -> int:
        """Thumbnail side so that an n x n grid (with its labels and the controls) fits the screen."""
        screen = self.screen() or (self.parentWidget().screen() if self.parentWidget() else None)
        if screen is None:
            return THUMB_SIDE
        free = screen.availableGeometry()
        by_height = (free.height() - 220) // n - 40  # controls, status, title bar; a label per cell
        by_width = (free.width() - 80) // n - 16
        return int(max(48, min(THUMB_SIDE, by_height, by_width)))

    def render_grid(self) -> None:
        """Lay out the grid's cells and start its preparation (replacing any grid being rendered).

        The document's inputs, parameters and seed are taken now; the thumbnail-size inputs (a
        painted mask's image, the reduction to ``THUMB_SIDE``) are built once per grid on a worker
        (the document's :class:`~weft.core.request.RenderRequest` in :class:`~weft.core.request.Preview`
        mode, as the main window's renders), and only then are the cells' requests, on those inputs,
        submitted (:meth:`_prepared`)."""
        self.runner.cancel()
        self._preparing = None  # a preparation or cell of an earlier grid that still arrives is dropped
        self._cell_jobs, self._pending = {}, set()
        while self.grid.count():
            item = self.grid.takeAt(0)
            if item.widget():
                item.widget().deleteLater()
        self.cells, self.values, self.images = {}, {}, {}
        self.export_button.setEnabled(False)
        n = 3 if self.size_box.currentIndex() == 0 else 4
        a, b = self._spec(0), self._spec(1)
        if a.name == b.name:
            self.status.setText("pick two different parameters")
            return
        rows = grid_values(a, self.lo[0].value(), self.hi[0].value(), n)
        cols = grid_values(b, self.lo[1].value(), self.hi[1].value(), n)
        request = render_request(self.doc, Preview(THUMB_SIDE))  # (a snapshot: nothing is built here)
        if request is None:
            self.status.setText("open the method's inputs first")
            return
        params = request.params
        self.side = side = self.thumb_side(n)
        for i, va in enumerate(rows):
            for j, vb in enumerate(cols):
                button = QToolButton()
                button.setIconSize(QSize(side, side))
                # a fixed cell: an error's text must not widen the dialog, nor a thumbnail's arrival grow it
                button.setFixedSize(side + 16, side + button.fontMetrics().height() + 20)
                button.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextUnderIcon)
                button.setText(f"{a.name}={va}  {b.name}={vb}")
                button.clicked.connect(lambda _=False, key=(i, j): self.adopt(*key))
                self.grid.addWidget(button, i, j)
                self.cells[(i, j)] = button
                self.values[(i, j)] = ((a.name, va), (b.name, vb))
                try:  # values the method refuses at any size: said at once, never run
                    params.replace(**{a.name: va, b.name: vb})
                except WeftError as e:
                    self._cell_error(button, str(e))

        def prepare_grid(*, progress=None, cancel=None):
            prepared = request.prepared()
            cancel.raise_if_cancelled()
            return request, prepared

        self._preparing = self.runner.submit("prepare", prepare_grid).id
        self.status.setText("rendering…")
        # the new cells are shown by their layout on the next turn of the event loop: fit then
        QTimer.singleShot(0, self._fit_on_screen)

    def _prepared(self, result: JobResult) -> None:
        """The grid's thumbnail inputs are built: submit one job per cell not yet refused."""
        self._preparing = None
        if result.error is not None:
            self.status.setText(_one_line(f"could not prepare the grid: {result.error}"))
            return
        request: RenderRequest
        prepared: Prepared
        request, prepared = result.value
        for key, button in self.cells.items():
            if not button.isEnabled():
                continue  # refused when laid out
            (na, va), (nb, vb) = self.values[key]
            try:
                params = prepared.params.replace(**{na: va, nb: vb})
            except WeftError as e:  # refused at thumbnail size (e.g. a size reduced below the values)
                self._cell_error(button, str(e))
                continue

            cell = RenderRequest(request.method, params, prepared.images, request.seed)

            def job(*, progress=None, cancel=None, cell=cell):
                return cell.run(cancel=cancel).image

            self._cell_jobs[key] = self.runner.submit("cell-{}-{}".format(*key), job).id
            self._pending.add(key)
        if not self._cell_jobs:
            self.status.setText("no cell can be rendered: each says why")

    def _fit_on_screen(self) -> None:
        """Grow to the new grid, then move (not past the screen's edges) so all of it is visible."""
        self.adjustSize()
        screen = self.screen()
        if screen is None:
            return
        free = screen.availableGeometry()
        frame = self.frameGeometry()
        x = min(max(frame.x(), free.x()), free.right() - frame.width())
        y = min(max(frame.y(), free.y()), free.bottom() - frame.height())
        self.move(max(x, free.x()), max(y, free.y()))

    def _on_result(self, result: JobResult) -> None:
        if result.slot == "prepare":
            if result.job_id == self._preparing:  # (else an earlier grid's: its cells are gone)
                self._prepared(result)
            return
        _, i, j = result.slot.split("-")
        key = (int(i), int(j))
        button = self.cells.get(key)
        if button is None or self._cell_jobs.get(key) != result.job_id:
            return  # a cell of an earlier grid
        if result.error is not None:
            self._cell_error(button, str(result.error))
        else:
            pix = QPixmap.fromImage(to_qimage(result.value))
            button.setIcon(QIcon(pix.scaled(self.side, self.side, Qt.AspectRatioMode.KeepAspectRatio)))
            self.images[key] = result.value
            self.export_button.setEnabled(True)
        self.cell_done.emit(*key)
        self._pending.discard(key)
        if not self._pending:
            self.status.setText("click a cell to adopt its values")

    def _cell_error(self, button: QToolButton, text: str) -> None:
        """A refused cell: the start of the reason on the cell (elided to its width), all of it in its tooltip."""
        label = button.fontMetrics().elidedText(text, Qt.TextElideMode.ElideRight, button.maximumWidth() - 12)
        button.setText(label)
        button.setToolTip(text)
        button.setEnabled(False)

    def grid_image(self) -> np.ndarray | None:
        """The rendered cells as one image (rows and columns as on screen, refused cells grey), with
        the two parameters' names and each row's and column's value written beside it, or None."""
        if not self.images:
            return None
        n = max(i for i, _ in self.cells) + 1
        h = max(im.shape[0] for im in self.images.values())
        w = max(im.shape[1] for im in self.images.values())
        gap = 4
        (na, _), (nb, _) = self.values[(0, 0)]
        rows = [self.values[(i, 0)][0][1] for i in range(n)]
        cols = [self.values[(0, j)][1][1] for j in range(n)]
        font = QFont()
        font.setPixelSize(max(11, min(16, w // 10)))
        metrics = QFontMetrics(font)
        line = metrics.height() + 4
        left = max(metrics.horizontalAdvance(f"{na} = {v}") for v in rows) + 12
        top = 2 * line + 4
        width, height = left + n * w + (n - 1) * gap, top + n * h + (n - 1) * gap
        sheet = QImage(width, height, QImage.Format.Format_RGB888)
        sheet.fill(QColor(51, 51, 51))
        painter = QPainter(sheet)
        painter.setFont(font)
        painter.setPen(QColor(235, 235, 235))
        painter.drawText(QRect(left, 0, n * w, line), Qt.AlignmentFlag.AlignCenter, f"columns: {nb}")
        for j, v in enumerate(cols):
            painter.drawText(QRect(left + j * (w + gap), line, w, line), Qt.AlignmentFlag.AlignCenter, f"{nb} = {v}")
        for i, v in enumerate(rows):
            painter.drawText(
                QRect(4, top + i * (h + gap), left - 8, h),
                Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter,
                f"{na} = {v}",
            )
        for (i, j), im in self.images.items():
            painter.drawImage(QPoint(left + j * (w + gap), top + i * (h + gap)), to_qimage(im))
        painter.end()
        bits = np.frombuffer(sheet.constBits(), np.uint8).reshape(height, sheet.bytesPerLine())
        return bits[:, : width * 3].reshape(height, width, 3).astype(np.float32) / 255.0

    def export_grid(self, path: str | None = None) -> bool:
        """Write the grid as one PNG (asks where when no path is given)."""
        image = self.grid_image()
        if image is None:
            return False
        if path is None:
            path, _ = QFileDialog.getSaveFileName(self, "Export grid", "variations.png", "PNG (*.png)")
            if not path:
                return False
        try:
            save_image(path, image)
        except WeftError as e:
            self.status.setText(str(e))
            return False
        self.status.setText(f"grid saved to {path}")
        return True

    def adopt(self, i: int, j: int) -> None:
        """Make cell (i, j)'s two values the document's (one undo step)."""
        (na, va), (nb, vb) = self.values[(i, j)]
        doc = self.doc
        if doc.method != self.method:
            self.status.setText(f"the document's method is now {doc.method}; render a new grid")
            return
        try:
            new = doc.params[self.method].replace(**{na: va, nb: vb})
        except WeftError as e:
            self.status.setText(str(e))
            return
        doc.set_params(new, f"Adopt {na}={va}, {nb}={vb}")
        self.status.setText(f"adopted {na}={va}, {nb}={vb}")

    def shutdown(self) -> None:
        self._preparing = None  # a preparation delivered (queued) before the close starts no cell
        self.runner.shutdown(wait=True, cancel=True)

    def closeEvent(self, event):  # noqa: N802
        self.shutdown()
        super().closeEvent(event)


def _one_line(text: str) -> str:
    """``text`` on one line (a status line must not grow)."""
    return " ".join(text.split())
