"""The variations grid: two parameters, two ranges, an n x n grid of thumbnails rendered in parallel.

Clicking a cell adopts its two values (one undo step). Cells render on their own worker pool at
thumbnail size (the target or output size scaled so its longer side is ``THUMB_SIDE``), so the main
window's renders are not held up; a cell whose values the method refuses says why.
"""

from __future__ import annotations

import numpy as np
from PySide6.QtCore import QSize, Qt, Signal
from PySide6.QtGui import QIcon, QPixmap
from PySide6.QtWidgets import (
    QComboBox,
    QDialog,
    QDoubleSpinBox,
    QGridLayout,
    QLabel,
    QPushButton,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from weft.core.errors import WeftError
from weft.core.jobs import JobResult, JobRunner
from weft.core.params import FLOAT, INT, specs
from weft.core.studio import reduce_for_preview

from .convert import to_qimage

THUMB_SIDE = 192


def numeric_specs(params_cls) -> list:
    return [s for s in specs(params_cls) if s.kind in (INT, FLOAT) and s.lo is not None and s.hi is not None]


def grid_values(spec, lo: float, hi: float, n: int) -> list:
    """``n`` values from ``lo`` to ``hi`` (integers for int parameters, duplicates removed)."""
    values = np.linspace(lo, hi, n)
    if spec.kind == INT:
        return [int(round(v)) for v in values]
    return [round(float(v), 4) for v in values]


class VariationsDialog(QDialog):
    """See the module docstring. ``cell_done(i, j)`` fires when a thumbnail arrives."""

    cell_done = Signal(int, int)
    _delivered = Signal(object)

    def __init__(self, doc, parent=None):
        super().__init__(parent)
        self.setWindowTitle(f"Variations — {doc.studio.title}")
        self.doc = doc
        self.method = doc.method
        self.runner = JobRunner(max_workers=2, on_result=self._delivered.emit)
        self._delivered.connect(self._on_result)
        self.cells: dict[tuple[int, int], QToolButton] = {}
        self.values: dict[tuple[int, int], tuple] = {}
        self.numeric = numeric_specs(doc.current.params)
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
        lay.addLayout(controls)
        self.grid_widget = QWidget()
        self.grid = QGridLayout(self.grid_widget)
        lay.addWidget(self.grid_widget, 1)
        self.status = QLabel("pick two parameters and their ranges, then Render grid; click a cell to adopt it")
        lay.addWidget(self.status)
        for r in (0, 1):
            self._reset_range(r)
        if len(self.numeric) < 2:
            self.render_button.setEnabled(False)
            self.status.setText(f"{self.method} has fewer than two numeric parameters")

    def _spec(self, row: int):
        return self.numeric[self.combo[row].currentIndex()]

    def _reset_range(self, row: int) -> None:
        if not self.numeric:
            return
        spec = self._spec(row)
        for box in (self.lo[row], self.hi[row]):
            box.setRange(spec.lo, spec.hi)
            box.setSingleStep(1 if spec.kind == INT else (spec.step or (spec.hi - spec.lo) / 20))
        current = getattr(self.doc.params[self.method], spec.name)
        if current is None:
            current = spec.default if spec.default is not None else spec.lo
        span = (spec.hi - spec.lo) / 4
        self.lo[row].setValue(max(spec.lo, current - span))
        self.hi[row].setValue(min(spec.hi, current + span))

    def render_grid(self) -> None:
        """Submit one thumbnail job per cell (replacing any grid being rendered)."""
        self.runner.cancel()
        while self.grid.count():
            item = self.grid.takeAt(0)
            if item.widget():
                item.widget().deleteLater()
        self.cells, self.values = {}, {}
        n = 3 if self.size_box.currentIndex() == 0 else 4
        a, b = self._spec(0), self._spec(1)
        if a.name == b.name:
            self.status.setText("pick two different parameters")
            return
        rows = grid_values(a, self.lo[0].value(), self.hi[0].value(), n)
        cols = grid_values(b, self.lo[1].value(), self.hi[1].value(), n)
        built = _thumb_inputs(self.doc)
        if built is None:
            self.status.setText("open the method's inputs first")
            return
        inputs, base = built
        method, seed = self.doc.current, self.doc.seed
        for i, va in enumerate(rows):
            for j, vb in enumerate(cols):
                button = QToolButton()
                button.setIconSize(QSize(THUMB_SIDE, THUMB_SIDE))
                button.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextUnderIcon)
                button.setText(f"{a.name}={va}  {b.name}={vb}")
                button.clicked.connect(lambda _=False, key=(i, j): self.adopt(*key))
                self.grid.addWidget(button, i, j)
                self.cells[(i, j)] = button
                self.values[(i, j)] = ((a.name, va), (b.name, vb))
                try:
                    params = base.replace(**{a.name: va, b.name: vb})
                except WeftError as e:
                    button.setText(str(e))
                    button.setEnabled(False)
                    continue

                def job(*, progress=None, cancel=None, params=params):
                    return method.run(inputs, params, rng=seed, cancel=cancel).image

                self.runner.submit(f"cell-{i}-{j}", job)
        self.status.setText("rendering…")

    def _on_result(self, result: JobResult) -> None:
        _, i, j = result.slot.split("-")
        key = (int(i), int(j))
        button = self.cells.get(key)
        if button is None:
            return
        if result.error is not None:
            button.setText(str(result.error))
            button.setEnabled(False)
        else:
            pix = QPixmap.fromImage(to_qimage(result.value))
            button.setIcon(QIcon(pix.scaled(THUMB_SIDE, THUMB_SIDE, Qt.AspectRatioMode.KeepAspectRatio)))
        self.cell_done.emit(*key)
        if not self.runner.busy():
            self.status.setText("click a cell to adopt its values")

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
        self.runner.shutdown(wait=True, cancel=True)

    def closeEvent(self, event):  # noqa: N802
        self.shutdown()
        super().closeEvent(event)


def _thumb_inputs(doc):
    """Thumbnail-size inputs and the current parameters, or None if inputs are missing."""
    if doc.missing_inputs():
        return None
    return reduce_for_preview(doc.studio, doc.method_inputs(), doc.run_params(), THUMB_SIDE)
