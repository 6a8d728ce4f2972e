"""The weft studio's main window: it assembles a few parts, each with a written contract.

* :class:`~weft.app.gui.document.Document`: the state (inputs, method, parameters and geometry per
  method, seed); every edit an undo command.
* :class:`~weft.app.gui.canvas.InputsPane` (left): the method's inputs, the canvas on top, with the
  tool of each geometry.
* :class:`~weft.app.gui.method_panel.MethodPanel` (dock): method list, parameters, seed, buttons.
* :class:`~weft.app.gui.render.Renderer`: preview and final jobs on the worker pool; a result carries
  its recipe.
* :class:`~weft.app.gui.files.FileActions`: export, recipes, sessions, autosave and recovery.

The window wires them (document changes -> parts; results -> result view, status bar) and holds the
menus. Everything method-specific comes from the methods' studio descriptions (``weft.core.studio``).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from PIL import Image as PILImage
from PySide6.QtCore import QMimeData, QSettings, QSize, Qt, QUrl, Signal
from PySide6.QtGui import QAction, QIcon, QKeySequence
from PySide6.QtWidgets import (
    QApplication,
    QDockWidget,
    QFileDialog,
    QLabel,
    QListWidget,
    QListWidgetItem,
    QMainWindow,
    QMessageBox,
    QProgressBar,
    QPushButton,
    QSizePolicy,
    QSplitter,
)
from weft.core.errors import WeftError
from weft.core.examples import example, examples
from weft.core.jobs import JobRunner
from weft.core.studio import MARGINS, MASK, SQUARE

from .canvas import InputsPane, titled
from .convert import to_qimage
from .document import Document, DocumentState, read_input
from .files import FileActions
from .method_panel import MethodPanel
from .render import Renderer, describe
from .views import ImageView, ResultView, is_image_path

OPEN_FILTER = "Images (*.png *.jpg *.jpeg *.tif *.tiff *.bmp *.webp);;All files (*)"
MAX_RECENT = 8
NARROW = 1200  # a window narrower than this (px) gets the Examples panel as a tab behind the Method panel
EXAMPLES_WIDTH = 170  # the Examples panel's width in a wider window: two columns of thumbnails


RESULT_MIN = 360  # the result view's width (px) when the picture painted on takes the larger share


class _ExampleList(QListWidget):
    """The bundled examples; drag one onto a view to open it there."""

    def mimeData(self, items):  # noqa: N802 (Qt naming)
        data = QMimeData()
        data.setUrls([QUrl.fromLocalFile(i.data(Qt.ItemDataRole.UserRole)) for i in items])
        return data


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


class MainWindow(QMainWindow):
    """The studio window (see the module docstring)."""

    message = Signal(str)
    _opened = Signal(object)

    def __init__(self, parent=None, *, settings: QSettings | None = None, load_defaults: bool = True):
        super().__init__(parent)
        # Register all of Pillow's format plugins here, on the GUI thread, before any worker runs:
        # Pillow imports them on the first file it cannot identify, and that import racing the
        # kernels' compilation on another worker crashed the process (seen in the test suite).
        PILImage.init()
        self.setWindowTitle("weft")
        # 1280x800, within the screen with room for the window manager's frame (a 1280x800 window on
        # a 1280x800 screen had its status bar below the screen's edge, seen under Xvfb)
        room = self.screen().availableGeometry() if self.screen() is not None else None
        self.resize(min(1280, room.width()) if room else 1280, min(800, room.height() - 48) if room else 800)
        self.settings = settings if settings is not None else QSettings("weft", "weft")
        self.doc = Document(self)
        self.renderer = Renderer(self.doc, self)
        # What to draw, while the result view shows the canvas input instead of a result (the method
        # has nothing to do yet): then there is no result to export or copy (renderer.last is older).
        self._input_shown: str | None = None
        # Opened files are decoded off the GUI thread; the result comes back through a queued signal.
        self.loader = JobRunner(max_workers=1, on_result=self._opened.emit)
        self._opened.connect(self._on_opened)

        self.result_view = ResultView(self)
        self.inputs_pane = InputsPane(self.doc, self)
        self.inputs_pane.message.connect(self.show_message)
        self.inputs_pane.dragging.connect(self._geometry_dragged)
        self.inputs_pane.painting.connect(self._mask_painted)
        self.doc.message.connect(self.show_message)
        self.inputs_pane.hovered.connect(self._on_hover)
        self.inputs_pane.zoomed.connect(self._on_zoomed)
        self._pointer_view: ImageView | None = None  # the view the mouse last moved over
        self.inputs_pane.open_requested.connect(self.open_input)
        self.inputs_pane.clear_requested.connect(self.doc.clear_input)
        self.splitter = QSplitter(Qt.Orientation.Horizontal)
        self.splitter.addWidget(self.inputs_pane)
        self.splitter.addWidget(titled(self.result_view, "result"))
        self.splitter.setStretchFactor(0, 2)
        self.splitter.setStretchFactor(1, 3)
        self.splitter.setSizes([420, 630])
        self.setCentralWidget(self.splitter)

        self.method_panel = MethodPanel(self.doc, self)
        self.method_panel.message.connect(self.show_message)
        self.method_panel.preview_requested.connect(self.renderer.preview)
        self.method_panel.final_requested.connect(self.renderer.final)
        self.method_panel.render_requested.connect(lambda: self.renderer.final(now=True))
        self.method_panel.variations_requested.connect(self.open_variations)
        self.method_panel.compare_button.toggled.connect(self.result_view.set_comparing)
        dock = QDockWidget("Method", self)
        dock.setObjectName("method")
        dock.setWidget(self.method_panel)
        self.addDockWidget(Qt.DockWidgetArea.RightDockWidgetArea, dock)
        self.method_dock = dock
        self.files = FileActions(self, self.doc, self.renderer)
        self._build_examples()
        self._build_status()
        self._build_menus()

        self.doc.changed.connect(self._on_doc_changed)
        self.doc.undo_stack.indexChanged.connect(self._update_title)
        self.doc.undo_stack.cleanChanged.connect(self._update_title)
        self.renderer.shown.connect(self._on_shown)
        self.renderer.around_shown.connect(self._on_around_shown)
        self.renderer.partial.connect(lambda img: self.result_view.set_image(img))
        self.renderer.progress.connect(self._on_progress)
        self.renderer.preparing.connect(self._on_preparing)
        self.renderer.busy.connect(self._on_busy)
        self.renderer.failed.connect(self._on_failed)
        self.renderer.needs.connect(self._on_needs)
        self.renderer.cancelled.connect(self._on_cancelled)
        self._rebuild_method()
        self._default_layout = self.saveState()  # View > Reset Layout returns to it
        self.restoreGeometry(self.settings.value("geometry", b""))
        # a layout the user left last time is kept; else the first show lays the docks out for the window's size
        self._restored_layout = bool(self.restoreState(self.settings.value("state", b"")))
        # The method on screen loads (or compiles) its kernels in its own first render; the other
        # methods' are loaded off the GUI thread once that first result is shown.
        self.renderer.warm_up_soon()
        if load_defaults:
            self.load_examples()
        self.files.offer_recovery()  # before the autosave is connected: opening the examples must not remove it
        # connected to the window (not to its files part): gone with it before its children are
        self.doc.undo_stack.indexChanged.connect(self._schedule_autosave)
        self.doc.undo_stack.cleanChanged.connect(self._schedule_autosave)
        self.doc.changed.connect(self._schedule_autosave)
        self.files._schedule_autosave()

    # --- the parts, as tests and scripts reach them ----------------------------------------------
    @property
    def views(self) -> dict[str, ImageView]:
        return self.inputs_pane.views

    @property
    def canvas_view(self) -> ImageView:
        """The view of the current method's canvas input."""
        return self.inputs_pane.canvas_view

    @property
    def lines_panel(self):
        return self.inputs_pane.lines_panel

    @property
    def input_tabs(self):
        return self.inputs_pane.tabs

    @property
    def params_panel(self):
        return self.method_panel.params_panel

    @property
    def seed_box(self):
        return self.method_panel.seed_box

    @property
    def compare_button(self):
        return self.method_panel.compare_button

    @property
    def recovery_file(self) -> Path:
        return self.files.recovery_file

    @property
    def _autosave_timer(self):
        return self.files._autosave_timer

    def export_result(self, path: str) -> bool:
        return self.files.export_result(path)

    def export_recipe(self, path: str) -> bool:
        return self.files.export_recipe(path)

    def save_session(self, path: str) -> bool:
        return self.files.save_session(path)

    def open_session(self, path: str) -> bool:
        return self.files.open_session(path)

    def autosave(self) -> bool:
        return self.files.autosave()

    def new_seed(self) -> None:
        self.method_panel.new_seed()

    def _schedule_autosave(self, *_args) -> None:
        self.files._schedule_autosave()

    def _confirm(self, question: str) -> bool:
        """Ask a yes/no question in a modal box; True for yes. The one place the studio asks
        (tests replace it)."""
        answer = QMessageBox.question(
            self,
            "weft",
            question,
            QMessageBox.StandardButton.Yes | QMessageBox.StandardButton.No,
            QMessageBox.StandardButton.No,
        )
        return answer == QMessageBox.StandardButton.Yes

    def _ask_restore(self, question: str) -> bool:
        """Ask whether to restore a recovered session: Restore (the default: Enter restores) or
        Discard; True for Restore (tests replace it)."""
        box = QMessageBox(QMessageBox.Icon.Question, "weft", question, QMessageBox.StandardButton.NoButton, self)
        restore = box.addButton("Restore", QMessageBox.ButtonRole.AcceptRole)
        box.addButton("Discard", QMessageBox.ButtonRole.DestructiveRole)
        box.setDefaultButton(restore)
        box.setEscapeButton(restore)  # (closing the box keeps the work: Esc never discards it)
        box.exec()
        return box.clickedButton() is restore

    def _ask_unsaved(self, doing: str) -> str:
        """The document has unsaved edits and the user is about to ``doing`` (e.g. "quit"): ask
        Save / Discard / Cancel in a modal box; returns "save", "discard" or "cancel"."""
        box = QMessageBox(
            QMessageBox.Icon.Question,
            "weft",
            f"Save your unsaved edits as a session before you {doing}?",
            QMessageBox.StandardButton.Save | QMessageBox.StandardButton.Discard | QMessageBox.StandardButton.Cancel,
            self,
        )
        box.setDefaultButton(QMessageBox.StandardButton.Save)
        box.setEscapeButton(QMessageBox.StandardButton.Cancel)
        answer = box.exec()
        return {QMessageBox.StandardButton.Save: "save", QMessageBox.StandardButton.Discard: "discard"}.get(
            QMessageBox.StandardButton(answer), "cancel"
        )

    def may_drop_edits(self, doing: str) -> bool:
        """True when there is nothing unsaved, or the user saved (a session) or discarded it."""
        if self.doc.undo_stack.isClean():
            return True
        answer = self._ask_unsaved(doing)
        if answer == "save":
            return self.files.save_session_dialog()
        return answer == "discard"

    # --- construction --------------------------------------------------------------------------
    def _build_examples(self) -> None:
        self.example_list = _ExampleList()
        self.example_list.setViewMode(QListWidget.ViewMode.IconMode)
        self.example_list.setIconSize(QSize(64, 64))
        self.example_list.setResizeMode(QListWidget.ResizeMode.Adjust)
        self.example_list.setMovement(QListWidget.Movement.Static)
        self.example_list.setDragEnabled(True)
        self.example_list.setSpacing(4)
        for path in examples():
            item = QListWidgetItem(QIcon(str(path)), path.stem)
            item.setData(Qt.ItemDataRole.UserRole, str(path))
            item.setToolTip(
                f"{path.name}: double-click to open it as the method's first input, drag onto a view to open it there"
            )
            self.example_list.addItem(item)
        self.example_list.itemDoubleClicked.connect(
            lambda item: self.open_input(self.doc.studio.canvas, item.data(Qt.ItemDataRole.UserRole))
        )
        dock = QDockWidget("Examples", self)
        dock.setObjectName("examples")
        dock.setWidget(self.example_list)
        self.addDockWidget(Qt.DockWidgetArea.LeftDockWidgetArea, dock)
        self.examples_dock = dock

    def _show_status(self, text: str) -> None:
        """The status message, whole when it fits beside the read-outs: a short message takes its
        width from the result's figures (those are elided first), a long one is elided too; with no
        message the figures have the room."""
        bar = self.statusBar()
        room = bar.width() - self.pixel_label.width() - self.zoom_label.sizeHint().width() - 40
        wanted = self.status_label.fontMetrics().horizontalAdvance(text) + 8 if text else 0
        self.status_label.setMinimumWidth(max(0, min(wanted, int(room * 0.75))))
        self.status_label.set_full_text(text)
        self.status_label.setVisible(bool(text))  # no message: the result's figures take its room

    def _build_status(self) -> None:
        # The status bar's message is shown by status_label, the first permanent widget (stretching,
        # elided, the whole text in its tooltip), so it never runs under the pixel read-out: QStatusBar
        # paints its own message only left of its first permanent widget, i.e. nowhere.
        self.status_label = ElidedLabel()
        self.statusBar().messageChanged.connect(self._show_status)
        self.statusBar().addPermanentWidget(self.status_label, 3)
        # the shown result's figures stay in a widget of their own: a menu's or a tooltip's status
        # tip replaces (then clears) the status message, never them
        self.result_label = ElidedLabel()
        self.result_label.setAlignment(Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter)
        self.statusBar().addPermanentWidget(self.result_label, 2)
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
        self.cancel_button.clicked.connect(self.renderer.cancel)
        self.cancel_button.setToolTip("cancel the render (Esc); the previous result is kept")
        for w in (self.pixel_label, self.zoom_label, self.progress_bar, self.cancel_button):
            self.statusBar().addPermanentWidget(w)
        self.progress_bar.hide()
        self.cancel_button.hide()
        self.result_view.zoomed.connect(lambda s: self._on_zoomed(self.result_view, s))
        self.result_view.hovered.connect(lambda x, y: self._on_hover(self.result_view, x, y))

    def _action(self, menu, text, slot, shortcut=None, tip=None) -> QAction:
        action = QAction(text, self)
        if shortcut is not None:
            action.setShortcut(QKeySequence(shortcut))
        if tip:
            action.setStatusTip(tip)
        action.triggered.connect(slot)
        menu.addAction(action)
        return action

    def _build_menus(self) -> None:
        m = self.menuBar().addMenu("&File")
        # Ctrl+O opens the current method's first input, Ctrl+Shift+O its second (the texture and the
        # target of a transfer); "Open Input" lists them all.
        self.open_first_action = self._action(m, "&Open…", lambda: self._open_nth(0), QKeySequence.StandardKey.Open)
        self.open_second_action = self._action(m, "Open &Second Input…", lambda: self._open_nth(1), "Ctrl+Shift+O")
        self.open_other_menu = m.addMenu("Open Input")
        self.recent_menu = m.addMenu("Open &Recent")
        self.clear_input_menu = m.addMenu("&Clear Input")  # the current method's optional inputs
        m.addSeparator()
        self._action(m, "Open &Session…", self.files.open_session_dialog, "Ctrl+Shift+L")
        self._action(
            m,
            "&Save Session",
            self.files.save_session_quick,
            QKeySequence.StandardKey.Save,
            tip="save to the session file last saved or opened (asks where the first time)",
        )
        self._action(m, "Save Session &As…", self.files.save_session_dialog, QKeySequence.StandardKey.SaveAs)
        m.addSeparator()
        self.save_result_action = self._action(m, "&Export Result…", self.files.save_result_dialog, "Ctrl+E")
        self._action(m, "Export &Recipe…", self.files.export_recipe_dialog, "Ctrl+Shift+E")
        self._action(m, "Apply to &Folder…", self.open_batch_dialog, "Ctrl+Shift+B")
        m.addSeparator()
        self.file_menu = m
        self.load_lines_action = self._action(m, "Load Feature &Lines…", lambda: self.lines_panel.load_lines_dialog())
        self.save_lines_action = self._action(m, "Save Feature Li&nes…", lambda: self.lines_panel.save_lines_dialog())
        m.addSeparator()
        self._action(m, "&Quit", self.close, "Ctrl+Q")  # StandardKey.Quit is empty on some desktops
        e = self.menuBar().addMenu("&Edit")
        undo = self.doc.undo_stack.createUndoAction(self, "&Undo")
        undo.setShortcut(QKeySequence.StandardKey.Undo)
        redo = self.doc.undo_stack.createRedoAction(self, "&Redo")
        redo.setShortcut(QKeySequence.StandardKey.Redo)
        e.addAction(undo)
        e.addAction(redo)
        self.undo_action, self.redo_action = undo, redo
        e.addSeparator()
        self.copy_result_action = self._action(
            e, "&Copy Result", self.copy_result, "Ctrl+Shift+C", tip="copy the full-size result shown to the clipboard"
        )
        self._action(e, "New &Seed", self.method_panel.new_seed, "Ctrl+R")
        self.clear_square_action = self._action(e, "Clear S&quare", lambda: self.doc.set_square(None))
        self.geometry_menu = e.addMenu("&Mask and Canvas")  # the mask and margins tools' actions, if any
        self.geometry_menu.setToolTipsVisible(True)  # a disabled action says why
        v = self.menuBar().addMenu("&View")
        self._action(v, "Zoom &In", lambda: self._zoom_view().zoom_by(1.25), QKeySequence.StandardKey.ZoomIn)
        self._action(v, "Zoom &Out", lambda: self._zoom_view().zoom_by(0.8), QKeySequence.StandardKey.ZoomOut)
        self._action(v, "&Fit to Window", lambda: self._zoom_view().fit(), "Ctrl+0")
        self._action(v, "&Actual Size", lambda: self._zoom_view().actual_size(), "Ctrl+1")
        self._action(v, "&Compare Before/After", self.method_panel.compare_button.toggle, "C")
        self._action(v, "&Render", lambda: self.renderer.final(now=True), "F5")
        v.addSeparator()
        # every dock can be brought back from here (closing the Method dock hides every control)
        for dock in (self.method_dock, self.examples_dock):
            toggle = dock.toggleViewAction()
            toggle.setText(f"{dock.windowTitle()} Panel")
            toggle.setStatusTip(f"show or hide the {dock.windowTitle()} panel")
            v.addAction(toggle)
        self.paint_large_action = self._action(
            v,
            "Large &Picture to Paint",
            self._toggle_paint_large,
            "Ctrl+L",
            tip="the picture you paint on gets the larger share of the window, "
            "the result the smaller (a method that paints on its picture)",
        )
        self.paint_large_action.setCheckable(True)
        self.paint_large_action.setChecked(self.settings.value("paint_large", False, type=bool))
        self.reset_layout_action = self._action(
            v,
            "Reset &Layout",
            self.reset_layout,
            tip="put every panel back where it was when the studio was first opened",
        )
        self.view_menu = v
        self._refresh_recent()

    def reset_layout(self) -> None:
        """Every panel shown and docked where the studio first put it; the result gets the larger share."""
        self.restoreState(self._default_layout)
        for dock in (self.method_dock, self.examples_dock):
            dock.setFloating(False)
            dock.show()
        self._lay_out_for_width()

    def _lay_out_for_width(self) -> None:
        """Dock widths for the window's width, so the result view keeps a usable share: below
        NARROW px the Examples panel becomes a tab behind the Method panel (the result view is
        ~200 px wide at 1024 px otherwise), and the Method panel takes at most 30 % of the width
        (its parameters scroll); the splitter gives the result 55 % of the rest."""
        width = self.width()
        method_width = max(self.method_panel.minimumSizeHint().width(), min(390, int(width * 0.3)))
        if width < NARROW:
            if (
                self.dockWidgetArea(self.examples_dock) != self.dockWidgetArea(self.method_dock)
                and not self.examples_dock.isFloating()
                and not self.method_dock.isFloating()
            ):
                self.tabifyDockWidget(self.method_dock, self.examples_dock)
            self.method_dock.raise_()
            self.resizeDocks([self.method_dock], [method_width], Qt.Orientation.Horizontal)
        else:
            if (
                self.dockWidgetArea(self.examples_dock) != Qt.DockWidgetArea.LeftDockWidgetArea
                and not self.examples_dock.isFloating()
            ):
                self.addDockWidget(Qt.DockWidgetArea.LeftDockWidgetArea, self.examples_dock)
            self.resizeDocks(
                [self.examples_dock, self.method_dock], [EXAMPLES_WIDTH, method_width], Qt.Orientation.Horizontal
            )
        total = max(self.width() - method_width - (0 if width < NARROW else EXAMPLES_WIDTH) - 24, 400)
        self._split(total)

    # --- inputs ----------------------------------------------------------------------------------
    def load_examples(self) -> None:
        """Open the bundled examples the methods name for their inputs (the window opens with a result)."""
        inputs = {}
        for method in self.doc.methods.values():
            for name, stem in method.studio.examples.items():
                if name in inputs:
                    continue
                try:
                    path = example(stem)
                except WeftError:
                    continue
                inputs[name] = read_input(path)  # small files: milliseconds
        self.doc.restore(DocumentState(inputs=inputs, method=self.doc.method, seed=self.doc.seed))
        self.renderer.final(now=True)

    def open_images(self, paths: list[str]) -> None:
        """Open ``paths`` as the current method's inputs in order (``weft IMAGE [TARGET]``)."""
        for spec, path in zip(self.doc.current.inputs, paths, strict=False):
            self.open_input(spec.name, path)

    def _open_nth(self, i: int) -> None:
        inputs = self.doc.current.inputs
        if i < len(inputs):
            self.open_input_dialog(inputs[i].name)

    def open_input_dialog(self, name: str) -> None:
        start = str(self.settings.value("last_dir", ""))
        path, _ = QFileDialog.getOpenFileName(self, f"Open {name.replace('_', ' ')}", start, OPEN_FILTER)
        if path:
            self.open_input(name, path)

    def open_input(self, name: str, path: str) -> None:
        """Decode ``path`` off the GUI thread and make it input ``name`` (undoable)."""
        if not is_image_path(path) and not Path(path).is_file():
            self.show_message(f"{path}: not an image file")
            return
        self.statusBar().showMessage(f"opening {Path(path).name}…")
        self.loader.submit(f"open-{name}", _load_job, name, str(path))

    def _on_opened(self, result) -> None:
        if result.cancelled:
            return
        if result.error is not None:
            self.show_message(f"could not open: {result.error}")
            return
        name, path, item = result.value
        image = item.image
        self.settings.setValue("last_dir", str(Path(path).parent))
        self._add_recent(path)
        self.doc.set_input(name, path, image, item.with_alpha, item.bit_depth)
        self.statusBar().showMessage(f"{name}: {Path(path).name} {image.shape[1]}x{image.shape[0]}", 4000)

    def _add_recent(self, path: str) -> None:
        recent = [p for p in (self.settings.value("recent", []) or []) if p != path]
        self.settings.setValue("recent", [path] + recent[: MAX_RECENT - 1])
        self._refresh_recent()

    def _refresh_recent(self) -> None:
        self.recent_menu.clear()
        recent = self.settings.value("recent", []) or []
        if isinstance(recent, str):
            recent = [recent]
        for path in recent:
            sub = self.recent_menu.addMenu(Path(path).name)
            for inp in [i.name for i in self.doc.current.inputs]:
                act = sub.addAction(f"as {inp.replace('_', ' ')}")
                act.triggered.connect(lambda _=False, p=path, n=inp: self.open_input(n, p))
        self.recent_menu.setEnabled(bool(recent))

    # --- document changes ----------------------------------------------------------------------
    # --- the painted picture on the large view (a method that paints on its canvas) ----------------
    def _canvas_share(self, total: int) -> float:
        """The inputs pane's share of the splitter's ``total`` width: when the method paints on its
        canvas, the larger (up to 60 %; the result, a preview, beside it keeps RESULT_MIN px), else
        45 % (the result is what is looked at)."""
        if not self.inputs_pane.paints_on_canvas():
            return 0.45
        if self.paint_large_action.isChecked():
            return 0.68
        return max(0.45, min(0.6, (total - RESULT_MIN) / max(total, 1)))

    def _toggle_paint_large(self) -> None:
        """View > Large Picture to Paint: the split follows at once, and the choice is remembered."""
        self.settings.setValue("paint_large", self.paint_large_action.isChecked())
        self._split(max(sum(self.splitter.sizes()), 400))

    def _split(self, total: int) -> None:
        share = self._canvas_share(total)
        self._split_share = self.inputs_pane.paints_on_canvas()
        self.splitter.setSizes([int(total * share), total - int(total * share)])

    def _resplit_for_method(self) -> None:
        """After a method change: the split follows whether the new method paints on its canvas."""
        if (
            getattr(self, "_sized", False)
            and getattr(self, "_split_share", None) != self.inputs_pane.paints_on_canvas()
        ):
            self._split(max(sum(self.splitter.sizes()), 400))

    def _on_doc_changed(self, what: str) -> None:
        if what.startswith("input:"):
            self.inputs_pane.input_changed(what.split(":", 1)[1])
            self._refresh_clear_inputs()
            self.method_panel.show_square()
            self.method_panel.show_params()
            self.renderer.final()
        elif what in ("method", "restored"):
            self._rebuild_method()
            self.method_panel.show_seed()
            self.renderer.final()
        elif what == "params":
            self.method_panel.show_params()
            self.inputs_pane.sync_tools()
            if not self.method_panel.dragging:
                self.renderer.final()
        elif what == "geometry":
            self.inputs_pane.geometry_changed()
            self.method_panel.show_square()
            self.method_panel.show_params()  # an "auto" value may depend on the source region's size
            self.renderer.final()
        elif what == "seed":
            self.method_panel.show_seed()
            self.renderer.final()

    def _rebuild_method(self) -> None:
        self.inputs_pane.rebuild()
        self._resplit_for_method()
        self.paint_large_action.setEnabled(self.inputs_pane.paints_on_canvas())
        self.method_panel.show_method()
        has_lines = self.lines_panel is not None and self.lines_panel.active
        self.load_lines_action.setEnabled(has_lines)
        self.save_lines_action.setEnabled(has_lines)
        self.clear_square_action.setEnabled(self.inputs_pane.square_on() is not None)
        for action in self.geometry_menu.actions():
            self.geometry_menu.removeAction(action)  # (not clear(): the bar owns them)
        bar = self.inputs_pane.bar()
        for action in [] if bar is None else bar.menu_actions():
            self.geometry_menu.addAction(action)
        self.geometry_menu.setEnabled(bar is not None)
        inputs = self.doc.current.inputs
        self.open_first_action.setText(f"&Open {inputs[0].name.replace('_', ' ')}…")
        # (always there, disabled when the method has one input: the File menu keeps its length, so
        # a habitual click never lands on another entry)
        self.open_second_action.setEnabled(len(inputs) > 1)
        self.open_second_action.setText(
            f"Open {inputs[1].name.replace('_', ' ')}…" if len(inputs) > 1 else "Open Second Input…"
        )
        self.open_other_menu.clear()
        for inp in inputs:
            act = self.open_other_menu.addAction(f"{inp.name.replace('_', ' ')}…")
            act.triggered.connect(lambda _=False, n=inp.name: self.open_input_dialog(n))
        self._refresh_recent()
        self._refresh_clear_inputs()
        self._update_title()

    def _refresh_clear_inputs(self) -> None:
        """File > Clear Input: one entry per optional input of the current method, enabled while open."""
        self.clear_input_menu.clear()
        optional = [i.name for i in self.doc.current.inputs if not i.required]
        for name in optional:
            act = self.clear_input_menu.addAction(f"{name.replace('_', ' ')}")
            act.setEnabled(self.doc.image(name) is not None)
            act.triggered.connect(lambda _=False, n=name: self.doc.clear_input(n))
        self.clear_input_menu.setEnabled(any(self.doc.image(n) is not None for n in optional))

    def _geometry_dragged(self, key: str, value) -> None:
        g = next((g for g in self.doc.studio.geometry if g.key == key), None)
        if g is not None and g.kind == SQUARE:
            self.method_panel.show_square(value)
        if g is not None and g.live is not None and g.live(self.doc.current_params):
            # the method asks for a live result while the square moves (affine's prototype swap)
            self.doc.live = (key, value)
            self.renderer.preview()

    def _mask_painted(self, key: str, mask, box) -> None:
        """A mask stroke in progress: render the region around it (if the method previews strokes so),
        or a reduced preview of the whole image (a mask whose geometry asks for it live: a sampling
        area changes the whole fill); ``mask`` None: the stroke was cancelled."""
        g = self.doc.mask_geometry(key)
        if g is not None and key != self.doc.studio.preview_around:
            self.doc.live = None if mask is None else (key, mask)
            if mask is None:
                self.renderer.stroke_cancelled()
            elif g.live is not None and g.live(self.doc.current_params):
                self.renderer.preview()
            return
        if mask is None:
            self.doc.live = None
            if not self.renderer.stroke_cancelled():
                self._show_before()
            return
        self.doc.live = (key, mask)
        self.renderer.preview_around(box)

    # --- results ---------------------------------------------------------------------------------
    def _on_around_shown(self, shown) -> None:
        self.result_view.set_notice(None)
        # (only the part pasted is redrawn: the rest is what the view shows already)
        self.result_view.set_image(shown.image, changed=shown.changed, over=shown.over)
        self.result_label.set_full_text(describe(shown))  # (it says it is around the stroke)

    def _on_shown(self, shown) -> None:
        self._input_shown = None
        self.result_view.set_stale(None)  # a render succeeded: what is shown follows the panel
        self.result_view.set_notice(None)
        self.result_view.set_image(shown.image)
        if shown.before is not None and shown.before is not self.result_view.compare_image:
            self.result_view.set_compare(shown.before)  # the input of this result, not of the panel
        self.result_label.set_full_text(describe(shown))

    def _on_progress(self, fraction: float, stage: str) -> None:
        self._end_preparing()
        now = time.monotonic()
        if self._work_started is None or fraction < self._last_fraction:  # a new render (or stage)
            self._work_started = now
        self._last_fraction = fraction
        self.progress_bar.setValue(int(fraction * 1000))
        left = _time_left(now - self._work_started, fraction)
        self._set_progress_text(stage, left)

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

    def _on_preparing(self, words: str) -> None:
        """A first run: the method's kernels compile before any work can be counted — say so in
        words on the result and keep the bar moving without a percentage."""
        self.result_view.set_notice(words)
        self.progress_bar.setRange(0, 0)  # a busy indicator: no percentage ...
        self.progress_bar.setTextVisible(False)  # ... (some styles draw a stale one in it)
        self.progress_bar.setToolTip(words)

    def _end_preparing(self) -> None:
        self.result_view.set_notice(None)
        self.progress_bar.setRange(0, 1000)
        self.progress_bar.setTextVisible(True)
        self.progress_bar.setToolTip("")

    def _on_busy(self, busy: bool) -> None:
        self._work_started, self._last_fraction = None, 0.0
        self.progress_bar.setVisible(busy)
        self.cancel_button.setVisible(busy)
        if busy:
            if self.progress_bar.maximum() > 0:  # not while preparing
                self.progress_bar.setValue(0)
        else:
            self._end_preparing()

    def _nothing_drawn(self) -> str | None:
        """What to draw, when the current method works on a drawn region (a mask, margins) and none
        is drawn yet: its geometry's help, e.g. "paint what to fill"."""
        # (a mask that means "every pixel" unpainted, a sampling area, is not what there is to do)
        geometry = [g for g in self.doc.studio.geometry if not g.empty_is_all]
        if not any(g.kind in (MASK, MARGINS) for g in geometry) or any(
            self.doc.value(g.key) is not None for g in geometry
        ):
            return None
        words = "; ".join(g.help for g in geometry if g.help) or "draw on the input"
        return words[0].upper() + words[1:]

    def _on_failed(self, message: str) -> None:
        draw = self._nothing_drawn()
        # nothing drawn yet is not a failure: the status line says what to do, not "render failed"
        # with the command line's options (seen under Xvfb: "give a mask (--mask MASK), ...")
        self.show_message(draw if message.startswith("render failed") and draw is not None else message)
        if message.startswith("render failed") and draw is not None:
            # nothing drawn yet (the method has nothing to do): the input, and what to draw on it
            self._input_shown, self.renderer.input_shown = draw, True
            self._show_before()
            return
        if message.startswith("render failed"):  # not a warm-up's: the result no longer matches the panel
            self.result_view.set_stale(
                f"Out of date — {message}. The result shown is from earlier settings (F5 renders again)."
            )
        if self.renderer.last is not None:
            self.result_view.set_image(self.renderer.last.image)

    def _on_needs(self, words: str) -> None:
        """The method renders nothing until something is drawn: the input, and what to draw on it."""
        self._input_shown, self.renderer.input_shown = words[0].upper() + words[1:], True
        self._show_before()

    def _show_before(self) -> None:
        """Show again what the result view showed before a stroke's previews or a cancelled render:
        the canvas input and what to draw on it while nothing is drawn, else the last result."""
        if self._input_shown is not None:
            self.result_view.set_stale(None)
            self.result_label.set_full_text("")  # (no result is shown)
            self.result_view.set_image(self.doc.image(self.doc.studio.canvas))
            self.result_view.set_notice(self._input_shown)
            self.statusBar().showMessage(self._input_shown, 8000)
        elif self.renderer.last is not None:
            self.result_view.set_image(self.renderer.last.image)
            self.result_label.set_full_text(describe(self.renderer.last))

    def nothing_to_export(self, doing: str = "export") -> str | None:
        """Why there is no result to export or copy now (one line), or None: none rendered in full
        yet, or the input shown instead of one (the method has nothing to do: what to draw)."""
        if self._input_shown is not None:
            return f"nothing to {doing}: {self._input_shown[0].lower()}{self._input_shown[1:]}"
        if self.renderer.last is None or not self.renderer.last.final:
            return f"nothing to {doing} yet: wait for the full-size result"
        return None

    def _on_cancelled(self) -> None:
        self._show_before()
        self.statusBar().showMessage("cancelled; the previous result is kept", 4000)

    def copy_result(self) -> bool:
        """Put the shown full-size result (not a preview) on the clipboard as an image."""
        why = self.nothing_to_export("copy")
        if why is not None:
            self.show_message(why)
            return False
        shown = self.renderer.last
        QApplication.clipboard().setImage(to_qimage(shown.image))
        h, w = shown.image.shape[:2]
        self.statusBar().showMessage(f"result {w}x{h} copied to the clipboard", 4000)
        return True

    def show_message(self, text: str) -> None:
        """A one-line message in the status bar (errors never open a blocking dialog mid-drag)."""
        self.statusBar().showMessage(text, 8000)
        self.message.emit(text)

    def _on_hover(self, view: ImageView, x: int, y: int) -> None:
        if view is not self._pointer_view:
            self._pointer_view = view
            self._show_zoom(view)
        img = view.image
        if x < 0 or img is None:
            self.pixel_label.setText("")
            return
        # in the counts artists read (0-255; 0-65535 for a 16-bit picture, or a result of one)
        top = 65535 if self._bit_depth(view) == 16 else 255
        v = np.atleast_1d(img[y, x])
        value = " ".join(str(int(round(float(c) * top))) for c in v)
        text = f"{view.title}  x {x}  y {y}  {value}" + ("  (16-bit)" if top == 65535 else "")
        metrics = self.pixel_label.fontMetrics()
        self.pixel_label.setText(metrics.elidedText(text, Qt.TextElideMode.ElideMiddle, self.pixel_label.width()))
        self.pixel_label.setToolTip(text)

    def _bit_depth(self, view: ImageView) -> int:
        """The bits per sample of what ``view`` shows: its input's file's; for the result, 16 when one
        of the current method's open inputs is 16-bit (a PNG export of it is)."""
        if view is self.result_view:
            items = [self.doc.item(i.name) for i in self.doc.current.inputs]
            return 16 if any(item is not None and item.bit_depth == 16 for item in items) else 8
        name = next((n for n, v in self.views.items() if v is view), None)
        item = None if name is None else self.doc.item(name)
        return 8 if item is None else item.bit_depth

    def _zoom_view(self) -> ImageView:
        """The view the zoom shortcuts act on: the one under the mouse (the last it moved over),
        else the focused one, else the result."""
        view = self._pointer_view
        if view is not None and view.isVisible():
            return view
        for view in [self.result_view, *self.views.values()]:
            if view.hasFocus():
                return view
        return self.result_view

    def _on_zoomed(self, view: ImageView, scale: float) -> None:
        if view is self._zoom_view():
            self._show_zoom(view)

    def _show_zoom(self, view: ImageView) -> None:
        """The % label: the zoom of the view the shortcuts act on, named."""
        if view.image is None:
            self.zoom_label.setText("")
            return
        self.zoom_label.setText(f"{view.title.replace('_', ' ')} {view.scale_factor() * 100:.0f}%")

    def open_variations(self) -> None:
        from .variations import VariationsDialog

        dialog = VariationsDialog(self.doc, self)
        dialog.show()
        self._variations = dialog

    def open_batch_dialog(self) -> None:
        from .batch_dialog import open_batch_dialog

        open_batch_dialog(self)

    def _update_title(self, *_args) -> None:
        dirty = "" if self.doc.undo_stack.isClean() else " *"
        self.setWindowTitle(f"weft — {self.doc.studio.title}{dirty}")

    # --- shutdown --------------------------------------------------------------------------------
    def shutdown(self) -> None:
        self.renderer.shutdown()
        self.loader.shutdown(wait=True, cancel=True)
        self.files.shutdown()
        self.inputs_pane.shutdown()
        dialog = getattr(self, "_variations", None)
        if dialog is not None:
            dialog.shutdown()

    def keyPressEvent(self, event):  # noqa: N802
        # Esc cancels a running render. Not a shortcut: a view's tool that uses Esc (a square drag,
        # Quad… clicks) accepts it first; only an Esc nothing used reaches the window.
        if event.key() == Qt.Key.Key_Escape and self.renderer.running():
            self.renderer.cancel()
            event.accept()
            return
        super().keyPressEvent(event)

    def showEvent(self, event):  # noqa: N802
        super().showEvent(event)
        if not getattr(self, "_sized", False):  # first show: give the result the larger share
            self._sized = True
            if self._restored_layout:
                total = max(self.splitter.width(), 400)
                self._split(total)
            else:
                self._lay_out_for_width()

    def resizeEvent(self, event):  # noqa: N802
        super().resizeEvent(event)
        old = event.oldSize().width()
        if getattr(self, "_sized", False) and old > 0 and (old < NARROW) != (self.width() < NARROW):
            self._lay_out_for_width()  # made narrow (or wide again): the result view keeps its share

    def closeEvent(self, event):  # noqa: N802
        if not self.may_drop_edits("quit"):
            event.ignore()
            return
        self.files._autosave_timer.stop()
        if self.files._owns_recovery:
            self.files.discard_recovery()
        self.settings.setValue("geometry", self.saveGeometry())
        self.settings.setValue("state", self.saveState())
        self.shutdown()
        super().closeEvent(event)


def _time_left(elapsed: float, fraction: float) -> str:
    """The time a render still needs at this pace, in words ("12 s", "3 min 5 s"); "" while too
    early to tell (under a second of work or 5 % done)."""
    if elapsed < 1.0 or fraction < 0.05 or fraction >= 1.0:
        return ""
    left = round(elapsed * (1.0 - fraction) / fraction)
    if left < 60:
        return f"{max(left, 1)} s"
    return f"{left // 60} min {left % 60} s"


def _load_job(name: str, path: str, *, progress=None, cancel=None):
    return name, path, read_input(path)
