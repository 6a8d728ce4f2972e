"""The studio's status bar: the message, the shown result's figures, the pixel and zoom read-outs,
and the progress bar with its Cancel button.

The message is shown by an elided label (the first permanent widget, stretching, the whole text in
its tooltip), so it never runs under the read-outs: ``QStatusBar`` paints its own message only left
of its first permanent widget, i.e. nowhere. The result's figures stay in a label of their own: a
menu's or a tooltip's status tip replaces (then clears) the message, never them.
"""

from __future__ import annotations

import time

import numpy as np
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QLabel, QProgressBar, QPushButton, QSizePolicy, QStatusBar


class ElidedLabel(QLabel):
    """A one-line label that shows as much of its text as fits (elided at the right) and the whole
    text in its tooltip; it takes whatever width its layout gives it."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self._full = ""
        self.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Preferred)
        self.setMinimumWidth(0)

    def full_text(self) -> str:
        return self._full

    def set_full_text(self, text: str) -> None:
        self._full = text
        self.setToolTip(text)
        self._elide()

    def resizeEvent(self, event):  # noqa: N802
        super().resizeEvent(event)
        self._elide()

    def _elide(self) -> None:
        width = self.contentsRect().width()
        super().setText(self.fontMetrics().elidedText(self._full, Qt.TextElideMode.ElideRight, max(width, 0)))


class StatusParts:
    """The widgets of a window's status bar and what they show (see the module docstring).

    ``cancel_button`` is the window's to connect; ``clock`` (``time.monotonic``) times the running
    render for the time left (a test may replace it)."""

    def __init__(self, bar: QStatusBar):
        self.bar = bar
        self.clock = time.monotonic
        self.status_label = ElidedLabel()
        bar.messageChanged.connect(self.show_status)
        bar.addPermanentWidget(self.status_label, 3)
        self.result_label = ElidedLabel()
        self.result_label.setAlignment(Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter)
        bar.addPermanentWidget(self.result_label, 2)
        self.status_label.hide()  # (until there is a message)
        self.pixel_label = QLabel("")
        # the read-out keeps its own room (a typical read-out's width), so moving the mouse does not
        # shift the message, and a longer read-out is elided rather than pushed into it
        self.pixel_label.setFixedWidth(
            self.pixel_label.fontMetrics().horizontalAdvance("texture  x 0000  y 0000  65535 65535 65535  (16-bit)") + 8
        )
        self.zoom_label = QLabel("")
        self.progress_bar = QProgressBar()
        self.progress_bar.setMaximumWidth(320)
        # room for a stage, its percentage and the time left (longer text is shortened to fit)
        self.progress_bar.setMinimumWidth(
            self.progress_bar.fontMetrics().horizontalAdvance("synthesis 100% · 10 min 5 s") + 24
        )
        self._work_started: float | None = None  # when the running render's counted work began
        self._last_fraction = 0.0
        self.progress_bar.setRange(0, 1000)
        self.cancel_button = QPushButton("Cancel")
        self.cancel_button.setToolTip("cancel the render (Esc); the previous result is kept")
        for w in (self.pixel_label, self.zoom_label, self.progress_bar, self.cancel_button):
            bar.addPermanentWidget(w)
        self.progress_bar.hide()
        self.cancel_button.hide()

    # --- the message ---------------------------------------------------------------------------
    def show_status(self, text: str) -> None:
        """The status message, whole when it fits beside the read-outs: a short message takes its
        width from the result's figures (those are elided first), a long one is elided too; with no
        message the figures have the room."""
        room = self.bar.width() - self.pixel_label.width() - self.zoom_label.sizeHint().width() - 40
        wanted = self.status_label.fontMetrics().horizontalAdvance(text) + 8 if text else 0
        self.status_label.setMinimumWidth(max(0, min(wanted, int(room * 0.75))))
        self.status_label.set_full_text(text)
        self.status_label.setVisible(bool(text))  # no message: the result's figures take its room

    # --- progress ------------------------------------------------------------------------------
    def show_progress(self, fraction: float, stage: str) -> None:
        """A running render's progress: the bar, its stage and the time left at this pace."""
        self.end_preparing()
        now = self.clock()
        if self._work_started is None or fraction < self._last_fraction:  # a new render (or stage)
            self._work_started = now
        self._last_fraction = fraction
        self.progress_bar.setValue(int(fraction * 1000))
        self._set_progress_text(stage, time_left(now - self._work_started, fraction))

    def _set_progress_text(self, stage: str, left: str) -> None:
        """The bar's text: the longest of a few wordings that fits in the bar (the whole in its tooltip)."""
        bar = self.progress_bar
        full = f"{stage} %p%" + (f" — about {left} left" if left else "")
        room = bar.contentsRect().width() - 8
        percent = f"{round(100 * bar.value() / max(bar.maximum(), 1))}%"
        metrics = bar.fontMetrics()
        for text in (
            full,
            f"{stage} %p%" + (f" · {left}" if left else ""),
            f"{stage} %p%",
            "%p%" + (f" · {left}" if left else ""),
            "%p%",
        ):
            if metrics.horizontalAdvance(text.replace("%p%", percent)) <= room:
                break
        bar.setFormat(text)
        bar.setToolTip(full.replace("%p%", percent))

    def show_preparing(self, words: str) -> None:
        """A first run: the kernels compile before any work can be counted: the bar moves without a
        percentage (the window says so in words on the result)."""
        self.progress_bar.setRange(0, 0)  # a busy indicator: no percentage ...
        self.progress_bar.setTextVisible(False)  # ... (some styles draw a stale one in it)
        self.progress_bar.setToolTip(words)

    def end_preparing(self) -> None:
        self.progress_bar.setRange(0, 1000)
        self.progress_bar.setTextVisible(True)
        self.progress_bar.setToolTip("")

    def show_busy(self, busy: bool) -> None:
        """A render over the progress delay is running (the bar and Cancel shown), or none is."""
        self._work_started, self._last_fraction = None, 0.0
        self.progress_bar.setVisible(busy)
        self.cancel_button.setVisible(busy)
        if busy:
            if self.progress_bar.maximum() > 0:  # not while preparing
                self.progress_bar.setValue(0)
        else:
            self.end_preparing()

    # --- read-outs -----------------------------------------------------------------------------
    def show_pixel(self, title: str, image: np.ndarray | None, x: int, y: int, bit_depth: int) -> None:
        """The value under the mouse in ``image`` (x < 0: none), in the counts artists read (0-255;
        0-65535 for a 16-bit picture, or a result of one)."""
        if x < 0 or image is None:
            self.pixel_label.setText("")
            return
        top = 65535 if bit_depth == 16 else 255
        v = np.atleast_1d(image[y, x])
        value = " ".join(str(int(round(float(c) * top))) for c in v)
        text = f"{title}  x {x}  y {y}  {value}" + ("  (16-bit)" if top == 65535 else "")
        metrics = self.pixel_label.fontMetrics()
        self.pixel_label.setText(metrics.elidedText(text, Qt.TextElideMode.ElideMiddle, self.pixel_label.width()))
        self.pixel_label.setToolTip(text)

    def show_zoom(self, view) -> None:
        """The % label: the zoom of ``view`` (the one the shortcuts act on), named."""
        if view.image is None:
            self.zoom_label.setText("")
            return
        self.zoom_label.setText(f"{view.title.replace('_', ' ')} {view.scale_factor() * 100:.0f}%")


def time_left(elapsed: float, fraction: float) -> str:
    """The time a render still needs at this pace, in words ("12 s", "3 min 5 s"); "" while too
    early to tell (under a second of work or 5 % done)."""
    if elapsed < 1.0 or fraction < 0.05 or fraction >= 1.0:
        return ""
    left = round(elapsed * (1.0 - fraction) / fraction)
    if left < 60:
        return f"{max(left, 1)} s"
    return f"{left // 60} min {left % 60} s"
