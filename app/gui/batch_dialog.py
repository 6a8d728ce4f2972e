"""File > Apply to Folder…: the current result's recipe over every image of a folder.

The dialog runs the same engine as ``weft batch`` (:mod:`weft.core.batch`: a local process pool, outputs byte
for byte ``weft run`` on each item's recipe, written atomically, finished items skipped on a re-run) on a
worker thread (:class:`~weft.app.gui.qjobs.QtJobs`), never the GUI thread: progress, failures and time left
arrive through queued signals, Cancel stops the batch between items (running ones at their next cancel check),
and the summary line stays in the dialog at the end. The studio stays usable meanwhile.

Which input the folder's images replace is chosen among the method's inputs (its ``InputSpec`` s);
nothing here names a method, input or parameter.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import (
    QApplication,
    QCheckBox,
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QFileDialog,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QProgressBar,
    QPushButton,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)
from weft.core import batch, registry
from weft.core.errors import WeftError
from weft.core.jobs import CancelToken
from weft.core.params import Recipe

from .qjobs import QtJobs

DEFAULT_NAMES = "{stem}.png"
OUTPUT_SUBFOLDER = "weft"


def _duration(seconds: float) -> str:
    seconds = int(round(seconds))
    return f"{seconds} s" if seconds < 60 else f"{seconds // 60} min {seconds % 60:02d} s"


def default_over(recipe: Recipe) -> str:
    """The input a folder most likely replaces: the first the recipe uses after the method's first
    input (its source), e.g. the picture a look is transferred onto; else the first."""
    method = registry.get(recipe.method)
    later = [i.name for i in method.inputs[1:] if i.name in recipe.inputs]
    return later[0] if later else method.inputs[0].name


class BatchDialog(QDialog):
    """Apply ``recipe`` to a folder (see the module docstring).

    Signals: ``progressed(done, total, failed, seconds_left)`` after each item (emitted on the batch's
    worker; ``seconds_left`` < 0 while unknown); ``batch_finished(summary_line, failed, cancelled)``
    when the batch has ended, also when it was refused before any work (``failed`` = -1).
    """

    progressed = Signal(int, int, int, float)
    batch_finished = Signal(str, int, bool)

    def __init__(self, recipe_source: Callable[[], Recipe | None], parent: QWidget | None = None):
        super().__init__(parent)
        self.setWindowTitle("Apply to Folder")
        self.setModal(False)
        self.recipe_source = recipe_source  # the shown result's recipe, read again at each Run
        self.recipe = recipe = recipe_source()
        self.method = registry.get(recipe.method)
        self._cancel: CancelToken | None = None
        self.jobs: QtJobs | None = None  # one per batch: its worker thread ends with the batch

        self.over = QComboBox()
        for spec in self.method.inputs:
            self.over.addItem(spec.name.replace("_", " "), spec.name)
        self.over.setCurrentIndex(self.over.findData(default_over(recipe)))
        self.folder = QLineEdit()
        self.folder.setPlaceholderText("folder of images (PNG, JPEG, TIFF, …)")
        self.folder.textChanged.connect(self._folder_changed)
        self.browse = browse = QPushButton("Browse…")
        browse.clicked.connect(self._browse_folder)
        self.output = QLineEdit()
        self.output.setPlaceholderText(
            f"output folder (default: a '{OUTPUT_SUBFOLDER}' folder inside the input folder)"
        )
        self.browse_out = browse_out = QPushButton("Browse…")
        browse_out.clicked.connect(self._browse_output)
        self.names = QLineEdit(DEFAULT_NAMES)
        self.names.setToolTip(
            "{stem}: the input file's name without extension, {name}: with it, {index}: "
            "its position from 0 (e.g. frame_{index:04d}.png)"
        )
        self.workers = QSpinBox()
        self.workers.setRange(1, max(1, batch.default_workers()))
        self.workers.setValue(batch.default_workers())
        self.seed_per_item = QCheckBox()
        self.force = QCheckBox("redo items already done with this recipe")
        self.about = QLabel()
        self.about.setWordWrap(True)
        self._describe()

        form = QFormLayout()
        form.addRow("Apply over", self.over)
        row = QHBoxLayout()
        row.addWidget(self.folder, 1)
        row.addWidget(browse)
        form.addRow("Input folder", row)
        row = QHBoxLayout()
        row.addWidget(self.output, 1)
        row.addWidget(browse_out)
        form.addRow("Output folder", row)
        form.addRow("Output names", self.names)
        form.addRow("Worker processes", self.workers)
        form.addRow("", self.seed_per_item)
        form.addRow("", self.force)

        self.progress = QProgressBar()
        self.progress.setRange(0, 1)
        self.progress.setValue(0)
        self.status = QLabel("")
        self.status.setWordWrap(True)
        self.status.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)

        self.buttons = QDialogButtonBox()
        self.run_button = self.buttons.addButton("Run", QDialogButtonBox.ButtonRole.AcceptRole)
        self.cancel_button = self.buttons.addButton("Cancel", QDialogButtonBox.ButtonRole.RejectRole)
        self.close_button = self.buttons.addButton("Close", QDialogButtonBox.ButtonRole.DestructiveRole)
        self.run_button.clicked.connect(self.start)
        self.cancel_button.clicked.connect(self.cancel)
        self.close_button.clicked.connect(self.close)
        self.cancel_button.setEnabled(False)

        layout = QVBoxLayout(self)
        layout.addWidget(self.about)
        layout.addLayout(form)
        layout.addWidget(self.progress)
        layout.addWidget(self.status)
        layout.addWidget(self.buttons)
        self.progressed.connect(self._on_progress)
        self.batch_finished.connect(self._on_finished)
        app = QApplication.instance()
        if app is not None:  # quitting stops the batch too (finished outputs stay; a re-run resumes)
            app.aboutToQuit.connect(self.cancel)
        self.resize(640, self.sizeHint().height())

    def _describe(self) -> None:
        self.about.setText(
            f"The current result's recipe ({self.recipe.method}, seed {self.recipe.seed}) is applied "
            "to every image of the folder, each in place of the chosen input."
        )
        self.seed_per_item.setText(f"seed + item number (otherwise seed {self.recipe.seed} on every item)")

    # --- inputs --------------------------------------------------------------------------------
    def _browse_folder(self) -> None:
        path = QFileDialog.getExistingDirectory(self, "Folder of images", self.folder.text())
        if path:
            self.folder.setText(path)

    def _browse_output(self) -> None:
        path = QFileDialog.getExistingDirectory(self, "Output folder", self.output_folder() or self.folder.text())
        if path:
            self.output.setText(path)

    def _folder_changed(self, text: str) -> None:
        self.output.setPlaceholderText(
            str(Path(text) / OUTPUT_SUBFOLDER)
            if text.strip()
            else f"output folder (default: a '{OUTPUT_SUBFOLDER}' folder inside the input folder)"
        )

    def output_folder(self) -> str:
        given = self.output.text().strip()
        if given:
            return given
        folder = self.folder.text().strip()
        return str(Path(folder) / OUTPUT_SUBFOLDER) if folder else ""

    @property
    def running(self) -> bool:
        return self.jobs is not None and self.jobs.busy("batch")

    # --- running -------------------------------------------------------------------------------
    def start(self) -> None:
        """Check the batch and run it on a thread (a refusal is shown at once, nothing runs)."""
        if self.running:
            return
        recipe = self.recipe_source()
        if recipe is None:
            self.status.setText("nothing to apply yet: wait for the full-size result")
            return
        if recipe.method != self.method.name:
            self.status.setText(f"the studio's method changed to {recipe.method}: close this dialog and open it again")
            return
        self.recipe = recipe
        self._describe()
        folder = self.folder.text().strip()
        if not folder:
            self.status.setText("choose a folder of images first")
            return
        pattern = str(Path(self.output_folder()) / (self.names.text().strip() or DEFAULT_NAMES))
        over = [(self.over.currentData(), folder)]
        options = dict(seed_per_item=self.seed_per_item.isChecked(), force=self.force.isChecked())
        workers = self.workers.value()
        self._set_running(True)
        self.status.setText("starting the worker processes…")
        self.progress.setRange(0, 0)  # busy until the first item is counted
        self.jobs = jobs = QtJobs(self)
        jobs.finished.connect(lambda _id, _slot: self._job_ended(jobs))
        self._cancel = self.jobs.submit("batch", self._work, over, pattern, options, workers).token

    def _emit(self, signal, *args) -> None:
        """Emit from the batch's worker; if the dialog is gone (the window closed), stop the batch."""
        try:
            signal.emit(*args)
        except RuntimeError:  # the C++ object was deleted
            if self._cancel is not None:
                self._cancel.cancel()

    def _work(self, over, pattern, options, workers, *, progress=None, cancel=None) -> None:
        """The batch job (on its worker): plan (refusals end it at once), then run; only signals reach the GUI."""
        try:
            plan = batch.plan("the studio's recipe", over, pattern, recipe=self.recipe, **options)
            self._emit(self.progressed, len(plan.skipped), len(plan.items), 0, -1.0)
            summary = batch.run(
                plan,
                workers=workers,
                cancel=cancel,
                progress=lambda s: self._emit(
                    self.progressed,
                    s.done,
                    s.total,
                    s.failed,
                    -1.0 if s.seconds_left is None else float(s.seconds_left),
                ),
            )
        except WeftError as e:
            self._emit(self.batch_finished, " ".join(str(e).split()), -1, False)
            return
        except Exception as e:  # noqa: BLE001 - a bug must not kill the thread silently
            self._emit(self.batch_finished, f"internal error: {type(e).__name__}: {e}", -1, False)
            return
        self._emit(self.batch_finished, summary.line(), len(summary.failed), summary.cancelled)

    def cancel(self) -> None:
        """Stop the running batch: finished items stay, queued ones never start."""
        if self._cancel is not None and self.running:
            self._cancel.cancel()
            self.status.setText("cancelling…")
            self.cancel_button.setEnabled(False)

    def _set_running(self, running: bool) -> None:
        self.run_button.setEnabled(not running)
        self.cancel_button.setEnabled(running)
        for w in (
            self.over,
            self.folder,
            self.browse,
            self.output,
            self.browse_out,
            self.names,
            self.workers,
            self.seed_per_item,
            self.force,
        ):
            w.setEnabled(not running)

    def _on_progress(self, done: int, total: int, failed: int, seconds_left: float) -> None:
        self.progress.setRange(0, max(1, total))
        self.progress.setValue(done)
        if self._cancel is not None and self._cancel.cancelled:
            return  # "cancelling…" stays until the summary
        bits = [f"{done} of {total} done"]
        if failed:
            bits.append(f"{failed} failed")
        if seconds_left >= 0 and done < total:
            bits.append(f"{_duration(seconds_left)} left")
        self.status.setText(", ".join(bits))

    def _on_finished(self, line: str, failed: int, cancelled: bool) -> None:
        self._set_running(False)
        if self.progress.maximum() == 0:
            self.progress.setRange(0, 1)
        self.status.setText(line)

    def _job_ended(self, jobs: QtJobs) -> None:
        """A batch's job resolved: its worker ends; if it is the current batch and said nothing
        (cancelled before it started), say so now."""
        jobs.shutdown(wait=False, cancel=False)
        if jobs is self.jobs and not self.run_button.isEnabled():
            self.batch_finished.emit("cancelled before any item started", -1, True)

    def closeEvent(self, event):  # noqa: N802 - closing while running cancels (finished outputs stay)
        self.cancel()
        super().closeEvent(event)


def _shown_recipe(window) -> Recipe | None:
    """The recipe of the full-size result on screen (what an export would carry), or None while
    only a preview, nothing, or the input instead of a result (nothing drawn yet) is shown."""
    return None if window.nothing_to_export() is not None else window.renderer.last.recipe


def open_batch_dialog(window) -> BatchDialog | None:
    """Show the dialog for ``window``'s current result (one dialog per window, raised if open)."""
    why = window.nothing_to_export("apply")
    if why is not None:
        window.show_message(why)
        return None
    for dialog in window.findChildren(BatchDialog):
        if dialog.running:
            dialog.raise_()
            dialog.activateWindow()
            return dialog
        dialog.deleteLater()
    dialog = BatchDialog(lambda: _shown_recipe(window), window)
    dialog.show()
    return dialog
