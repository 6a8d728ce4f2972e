"""The feature-lines tool's panel: the photo's line tool and the frontal frame with live rectification.

Line i drawn on the photo goes with line i drawn in the frontal frame (numbered and coloured alike).
While an end point is dragged, the photo is rectified on a worker (latest wins) and shown in the
frontal frame, so the user sees the effect of every move; *Quad…* makes four pairs from four clicked
corners; *Suggest lines* (when the method's lines geometry declares a ``suggest``) proposes pairs
on a worker and sets them as one undo step; the frontal size sets the frame the lines live in. Lines
load from and save to DESIGN.md's JSON; the document holds them (undoable, per method) and the
render takes them from there.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PySide6.QtCore import Signal
from PySide6.QtWidgets import QFileDialog, QHBoxLayout, QLabel, QPushButton, QSizePolicy, QSpinBox, QVBoxLayout, QWidget
from weft.core.errors import WeftError
from weft.core.jobs import JobResult
from weft.core.studio import LINES

from .qjobs import QtJobs
from .tools import LineTool, QuadTool
from .views import ImageView


class FeatureLinesPanel(QWidget):
    """The frontal frame tab (see the module docstring); ``message(text)`` reports problems."""

    message = Signal(str)

    def __init__(self, doc, photo_view: ImageView, input_name: str, parent=None):
        super().__init__(parent)
        self.doc = doc
        self.photo_view = photo_view
        self.input_name = input_name  # the input the lines are drawn on
        self.active = False  # rectify only while a method with feature lines is shown
        self.photo_lines = LineTool(photo_view, doc, "image", on_drag=self._lines_dragged)
        photo_view.tool = self.photo_lines
        self.frontal_view = ImageView(self, title="frontal")
        self.frontal_lines = LineTool(self.frontal_view, doc, "frontal", on_drag=self._lines_dragged)
        self.frontal_view.tool = self.frontal_lines
        self.runner = QtJobs(self)
        self.runner.result.connect(self._on_rectified)
        self.suggest_runner = QtJobs(self)
        self.suggest_runner.result.connect(self._on_suggested)
        self._suggest_photo = None  # the photo a pending suggestion is for
        self._rectifier = None
        self._build()

    def photo_changed(self) -> None:
        self._rectifier = None
        self.photo_lines.refresh()
        self._update_rectified()

    def lines_changed(self) -> None:
        self.photo_lines.refresh()
        self.frontal_lines.refresh()
        self._sync_frontal_size()
        self._update_rectified()

    def set_active(self, on: bool) -> None:
        self.active = on
        self.suggest_button.setVisible(on and self._suggester() is not None)
        if on:
            self._update_rectified()

    def shutdown(self) -> None:
        self.suggest_runner.shutdown(wait=True, cancel=True)
        self.runner.shutdown(wait=True, cancel=True)

    def _suggester(self):
        g = self.doc.geometry_of(LINES)
        return None if g is None else g.suggest

    def suggest(self) -> None:
        """Propose line pairs for the photo on a worker; they replace the lines as one undo step."""
        suggest, photo = self._suggester(), self.doc.image(self.input_name)
        if suggest is None or photo is None:
            return
        self._suggest_photo = photo
        self.suggest_button.setEnabled(False)
        self.rectify_status.setText("looking for two families of straight lines…")

        def job(*, progress=None, cancel=None):
            return suggest(photo)

        self.suggest_runner.submit("suggest", job)

    def _on_suggested(self, result: JobResult) -> None:
        self.suggest_button.setEnabled(True)
        photo, self._suggest_photo = self._suggest_photo, None
        if result.cancelled or photo is None or self.doc.image(self.input_name) is not photo:
            return  # another photo (or none) since: the suggestion is not for it
        if result.error is not None:
            text = str(result.error) if isinstance(result.error, WeftError) else f"no suggestion: {result.error}"
            self.rectify_status.setText(text)
            self.message.emit(text)
            return
        lines, words = result.value
        self.doc.set_lines(
            lines.image_lines.tolist(),
            lines.frontal_lines.tolist(),
            text="Suggest lines",
            frontal_size=lines.frontal_size,
        )
        self.message.emit(words)

    def _build(self) -> None:
        lay = QVBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        row = QHBoxLayout()
        self.quad_button = QPushButton("Quad…")
        self.quad_button.setCheckable(True)
        self.quad_button.setToolTip(
            "click the plane's four corners on the photo, clockwise from top-left: "
            "four line pairs (the frontal rectangle's edges)"
        )
        self.quad_button.toggled.connect(self._quad_mode)
        row.addWidget(self.quad_button)
        self.suggest_button = QPushButton("Suggest lines")
        self.suggest_button.setToolTip(
            "find two families of straight lines in the photo and propose line pairs "
            "from them (edit them like drawn ones; Undo takes them back)"
        )
        self.suggest_button.clicked.connect(self.suggest)
        self.suggest_button.setVisible(False)
        row.addWidget(self.suggest_button)
        row.addWidget(QLabel("frontal size"))
        self.frontal_w, self.frontal_h = QSpinBox(), QSpinBox()
        for box_ in (self.frontal_w, self.frontal_h):
            box_.setRange(16, 8192)
            box_.setKeyboardTracking(False)
            box_.valueChanged.connect(self._frontal_size_edited)
            row.addWidget(box_)
        row.addStretch(1)
        lay.addLayout(row)
        # on a line of its own, wrapped: Quad…'s "click the top-left corner" was cut off beside the boxes
        self.rectify_status = QLabel("")
        self.rectify_status.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Preferred)
        self.rectify_status.setWordWrap(True)
        self.rectify_status.setContentsMargins(4, 0, 4, 0)
        # room for two lines always: a hint that changes length does not move the frame below it
        self.rectify_status.setMinimumHeight(2 * self.rectify_status.fontMetrics().lineSpacing() + 2)
        lay.addWidget(self.rectify_status)
        lay.addWidget(self.frontal_view, 1)
        self._sync_frontal_size()

    def _sync_frontal_size(self) -> None:
        for box_, v in ((self.frontal_w, self.doc.frontal_size[0]), (self.frontal_h, self.doc.frontal_size[1])):
            box_.blockSignals(True)
            box_.setValue(int(v))
            box_.blockSignals(False)

    def _frontal_size_edited(self, _v) -> None:
        size = (self.frontal_w.value(), self.frontal_h.value())
        if size != self.doc.frontal_size:
            self.doc.set_lines(self.doc.image_lines, self.doc.frontal_lines, text="Frontal size", frontal_size=size)

    def _quad_mode(self, on: bool) -> None:
        if on:
            self.photo_view.tool = QuadTool(
                self.photo_view,
                self.doc,
                on_done=lambda: self.quad_button.setChecked(False),
                on_prompt=self.rectify_status.setText,
            )
        else:
            self.photo_view.tool = self.photo_lines
            self._update_rectified()  # the status says the rectification again

    def _status(self, text: str) -> None:
        if not self.quad_button.isChecked():  # Quad… says which corner to click there meanwhile
            self.rectify_status.setText(text)

    def _lines_dragged(self, image_lines, frontal_lines) -> None:
        self._update_rectified(image_lines, frontal_lines)

    def _update_rectified(self, image_lines=None, frontal_lines=None) -> None:  # noqa: C901
        """Rectify the photo with the current (or the dragged) lines on the worker (latest wins)."""
        if not self.active:
            return
        photo = self.doc.image(self.input_name)
        image_lines = self.doc.image_lines if image_lines is None else image_lines
        frontal_lines = self.doc.frontal_lines if frontal_lines is None else frontal_lines
        n = min(len(image_lines), len(frontal_lines))
        w, h = self.doc.frontal_size
        if photo is None or n == 0:
            self.frontal_view.set_image(np.full((h, w), 0.25, np.float32))
            self.frontal_lines.refresh()
            self._status("draw line pairs: line i on the photo, line i here")
            return
        if self._rectifier is None:
            from weft.core.rectify import Rectifier

            self._rectifier = Rectifier(photo, interpolation="linear")
        rectifier, size = self._rectifier, self.doc.frontal_size
        lines = ([list(x) for x in image_lines[:n]], [list(x) for x in frontal_lines[:n]])

        def job(*, progress=None, cancel=None):
            return rectifier.rectify(lines[0], lines[1], size).image

        self.runner.submit("frontal", job)

    def _on_rectified(self, result: JobResult) -> None:
        if result.error is not None:
            self._status(str(result.error))
            return
        first = self.frontal_view.image is None or self.frontal_view.image.shape[:2] != result.value.shape[:2]
        self.frontal_view.set_image(result.value, fit=first)
        self.frontal_lines.refresh()
        self._status("rectified")

    def load_lines_dialog(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self, "Load feature lines", "", "Feature lines (*.json)")
        if path:
            self.load_lines(path)

    def load_lines(self, path: str) -> bool:
        from weft.core.rectify import load_feature_lines

        try:
            fl = load_feature_lines(path)
        except WeftError as e:
            self.message.emit(str(e))
            return False
        self.doc.set_lines(
            fl.image_lines.tolist(), fl.frontal_lines.tolist(), text="Load lines", frontal_size=fl.frontal_size
        )
        return True

    def save_lines_dialog(self) -> None:
        path, _ = QFileDialog.getSaveFileName(self, "Save feature lines", "", "Feature lines (*.json)")
        if path:
            self.save_lines(path)

    def save_lines(self, path: str) -> bool:
        from weft.core.image import atomic_write_bytes

        lines = self.doc.lines.complete()
        if lines is None:
            self.message.emit("no complete line pairs to save")
            return False
        try:
            atomic_write_bytes(Path(path), (lines.to_text() + "\n").encode("utf-8"))
        except WeftError as e:
            self.message.emit(str(e))
            return False
        return True
