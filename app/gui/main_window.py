"""The weft studio's main window: it assembles a few parts, each with a written contract, and wires them.

* :class:`~weft.app.gui.document.Document`: the state (inputs, method, parameters and geometry per
  method, seed); every edit an undo command; one signal per kind of change.
* :class:`~weft.app.gui.canvas.InputsPane` (left): the method's inputs, the canvas on top, with the
  tool of each geometry.
* :class:`~weft.app.gui.method_panel.MethodPanel` (dock): method list, parameters, seed, buttons.
* :class:`~weft.app.gui.render.Renderer`: listens to the document and decides what to render
  (preview or full); a result carries its recipe.
* :class:`~weft.app.gui.results.ResultState`: what the result view shows (a result, or the input and
  what to draw on it).
* :class:`~weft.app.gui.files.FileActions`: export, recipes, sessions, autosave and recovery.
* :class:`~weft.app.gui.menus.Menus`, :class:`~weft.app.gui.status.StatusParts`,
  :class:`~weft.app.gui.docks.DockLayout`, :class:`~weft.app.gui.questions.Questions`: the menus, the
  status bar, the layout policy, the questions asked in a box.

The window wires them (document changes -> views; a drag or a stroke -> the document's edit in
progress) and opens input files. Everything method-specific comes from the methods' studio
descriptions (``weft.core.studio``).
"""

from __future__ import annotations

from pathlib import Path

from PIL import Image as PILImage
from PySide6.QtCore import QSettings, Qt, Signal
from PySide6.QtWidgets import QDockWidget, QFileDialog, QMainWindow, QSplitter
from weft.core.errors import WeftError
from weft.core.examples import example
from weft.core.jobs import JobRunner
from weft.core.studio import SQUARE

from .canvas import InputsPane, titled
from .docks import DockLayout, ExampleList
from .document import Document, DocumentState, read_input
from .files import FileActions
from .menus import Menus
from .method_panel import MethodPanel
from .questions import Questions
from .render import Renderer
from .result_view import ResultView
from .results import ResultState
from .status import StatusParts
from .views import ImageView, is_image_path

OPEN_FILTER = "Images (*.png *.jpg *.jpeg *.tif *.tiff *.bmp *.webp);;All files (*)"


class MainWindow(QMainWindow):
    """The studio window (see the module docstring).

    Signals: ``message(text)`` each one-line message shown in the status bar.
    """

    message = Signal(str)
    _opened = Signal(object)

    def __init__(self, parent=None, *, settings: QSettings | None = None, load_defaults: bool = True):
        super().__init__(parent)
        # Register all of Pillow's format plugins here, on the GUI thread, before any worker runs:
        # Pillow imports them on the first file it cannot identify, and that import racing the
        # kernels' compilation on another worker crashes the process.
        PILImage.init()
        self.setWindowTitle("weft")
        # 1280x800, within the screen with room for the window manager's frame
        room = self.screen().availableGeometry() if self.screen() is not None else None
        self.resize(min(1280, room.width()) if room else 1280, min(800, room.height() - 48) if room else 800)
        self.settings = settings if settings is not None else QSettings("weft", "weft")
        self.questions = Questions(self)
        self.doc = Document(self)
        self.renderer = Renderer(self.doc, self)
        # Opened files are decoded off the GUI thread; the result comes back through a queued signal.
        self.loader = JobRunner(max_workers=1, on_result=self._opened.emit)
        self._opened.connect(self._on_opened)
        self._variations = None
        self._build_parts()
        self._wire()
        self._show_method()
        self.dock_layout.default_state = self.saveState()  # View > Reset Layout returns to it
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
        self.files.schedule_autosave()

    # --- construction --------------------------------------------------------------------------
    def _build_parts(self) -> None:
        self.result_view = ResultView(self)
        self.inputs_pane = InputsPane(self.doc, self)
        self._pointer_view: ImageView | None = None  # the view the mouse last moved over
        self.splitter = QSplitter(Qt.Orientation.Horizontal)
        self.splitter.addWidget(self.inputs_pane)
        self.splitter.addWidget(titled(self.result_view, "result"))
        self.splitter.setStretchFactor(0, 2)
        self.splitter.setStretchFactor(1, 3)
        self.splitter.setSizes([420, 630])
        self.setCentralWidget(self.splitter)
        self.method_panel = MethodPanel(self.doc, self)
        self.method_dock = self._dock("Method", "method", self.method_panel, Qt.DockWidgetArea.RightDockWidgetArea)
        self.files = FileActions(self, self.doc, self.renderer)
        self.example_list = ExampleList(lambda path: self.open_input(self.doc.studio.canvas, path))
        self.examples_dock = self._dock("Examples", "examples", self.example_list, Qt.DockWidgetArea.LeftDockWidgetArea)
        self.status = StatusParts(self.statusBar())
        self.results = ResultState(
            self.doc,
            self.renderer,
            self.result_view,
            self.status.result_label,
            self.statusBar(),
            self.show_message,
            self,
        )
        self.menus = Menus(self)
        self.dock_layout = DockLayout(
            self,
            self.method_dock,
            self.examples_dock,
            self.splitter,
            self.inputs_pane.paints_on_canvas,
            self.menus.paint_large_action.isChecked,
        )

    def _dock(self, title: str, name: str, widget, area) -> QDockWidget:
        dock = QDockWidget(title, self)
        dock.setObjectName(name)
        dock.setWidget(widget)
        self.addDockWidget(area, dock)
        return dock

    def _wire(self) -> None:
        doc, pane, panel, renderer = self.doc, self.inputs_pane, self.method_panel, self.renderer
        pane.message.connect(self.show_message)
        doc.message.connect(self.show_message)
        panel.message.connect(self.show_message)
        # a drag or a stroke is the document's edit in progress: the renderer decides what it renders
        pane.dragging.connect(doc.set_live)
        pane.painting.connect(lambda key, mask, box: doc.end_live() if mask is None else doc.set_live(key, mask, box))
        pane.hovered.connect(self._on_hover)
        pane.zoomed.connect(self._on_zoomed)
        pane.open_requested.connect(self.open_input)
        pane.clear_requested.connect(doc.clear_input)
        panel.render_requested.connect(lambda: renderer.final(now=True))
        panel.variations_requested.connect(self.open_variations)
        panel.compare_button.toggled.connect(self.result_view.set_comparing)
        # document changes -> the views (the renderer listens for itself)
        doc.input_changed.connect(self._on_input_changed)
        doc.method_changed.connect(self._show_method)
        doc.restored.connect(self._show_method)
        doc.params_changed.connect(self._on_params_changed)
        doc.geometry_changed.connect(self._on_geometry_changed)
        doc.seed_changed.connect(panel.show_seed)
        doc.live_changed.connect(self._on_live_changed)
        doc.undo_stack.indexChanged.connect(self._update_title)
        doc.undo_stack.cleanChanged.connect(self._update_title)
        renderer.progress.connect(self.status.show_progress)
        renderer.preparing.connect(self.status.show_preparing)
        renderer.busy.connect(self.status.show_busy)
        self.status.cancel_button.clicked.connect(renderer.cancel)
        self.result_view.zoomed.connect(lambda s: self._on_zoomed(self.result_view, s))
        self.result_view.hovered.connect(lambda x, y: self._on_hover(self.result_view, x, y))

    # --- document changes -> views -------------------------------------------------------------
    def _on_input_changed(self, name: str) -> None:
        self.inputs_pane.input_changed(name)
        self.menus.refresh_clear_inputs()
        self.method_panel.show_square()
        self.method_panel.show_params()

    def _on_params_changed(self) -> None:
        self.method_panel.show_params()
        self.inputs_pane.sync_tools()

    def _on_geometry_changed(self) -> None:
        self.inputs_pane.geometry_changed()
        self.method_panel.show_square()
        self.method_panel.show_params()  # an "auto" value may depend on the source region's size

    def _on_live_changed(self, edit) -> None:
        if edit is None or edit.param:
            return
        g = next((g for g in self.doc.studio.geometry if g.key == edit.key), None)
        if g is not None and g.kind == SQUARE:
            self.method_panel.show_square(edit.value)

    def _show_method(self) -> None:
        """The current method (changed, or the document restored): its panes, menus and split."""
        self.inputs_pane.rebuild()
        self.dock_layout.resplit_for_method()
        self.method_panel.show_method()
        self.method_panel.show_seed()
        self.menus.show_method()
        self._update_title()

    def _schedule_autosave(self, *_args) -> None:
        self.files.schedule_autosave()

    def _update_title(self, *_args) -> None:
        dirty = "" if self.doc.undo_stack.isClean() else " *"
        self.setWindowTitle(f"weft — {self.doc.studio.title}{dirty}")

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
        self.menus.add_recent(path)
        self.doc.set_input(name, path, image, item.with_alpha, item.bit_depth)
        self.statusBar().showMessage(f"{name}: {Path(path).name} {image.shape[1]}x{image.shape[0]}", 4000)

    # --- what the parts ask of the window --------------------------------------------------------
    def show_message(self, text: str) -> None:
        """A one-line message in the status bar (errors never open a blocking dialog mid-drag)."""
        self.statusBar().showMessage(text, 8000)
        self.message.emit(text)

    def nothing_to_export(self, doing: str = "export") -> str | None:
        """Why there is no result to export or copy now (one line), or None (``ResultState``)."""
        return self.results.nothing_to_export(doing)

    def copy_result(self) -> bool:
        """Put the shown full-size result (not a preview) on the clipboard as an image."""
        return self.results.copy_result()

    def may_drop_edits(self, doing: str) -> bool:
        """True when there is nothing unsaved, or the user saved (a session) or discarded it."""
        if self.doc.undo_stack.isClean():
            return True
        answer = self.questions.ask_unsaved(doing)
        if answer == "save":
            return self.files.save_session_dialog()
        return answer == "discard"

    def open_variations(self) -> None:
        from .variations import VariationsDialog

        self._variations = VariationsDialog(self.doc, self)
        self._variations.show()

    @property
    def variations(self):
        """The Variations dialog last opened (None before)."""
        return self._variations

    def open_batch_dialog(self) -> None:
        from .batch_dialog import open_batch_dialog

        open_batch_dialog(self)

    # --- views, zoom, layout ---------------------------------------------------------------------
    def _on_hover(self, view: ImageView, x: int, y: int) -> None:
        if view is not self._pointer_view:
            self._pointer_view = view
            self.status.show_zoom(view)
        self.status.show_pixel(view.title, view.image, x, y, self._bit_depth(view))

    def _bit_depth(self, view: ImageView) -> int:
        """The bits per sample of what ``view`` shows: its input's file's; for the result, 16 when one
        of the current method's open inputs is 16-bit (a PNG export of it is)."""
        if view is self.result_view:
            items = [self.doc.item(i.name) for i in self.doc.current.inputs]
            return 16 if any(item is not None and item.bit_depth == 16 for item in items) else 8
        name = next((n for n, v in self.inputs_pane.views.items() if v is view), None)
        item = None if name is None else self.doc.item(name)
        return 8 if item is None else item.bit_depth

    def zoom_view(self) -> ImageView:
        """The view the zoom shortcuts act on: the one under the mouse (the last it moved over),
        else the focused one, else the result."""
        view = self._pointer_view
        if view is not None and view.isVisible():
            return view
        for view in [self.result_view, *self.inputs_pane.views.values()]:
            if view.hasFocus():
                return view
        return self.result_view

    def _on_zoomed(self, view: ImageView, scale: float) -> None:
        if view is self.zoom_view():
            self.status.show_zoom(view)

    def reset_layout(self) -> None:
        """View > Reset Layout: every panel shown and docked where the studio first put it."""
        self.dock_layout.reset()

    def toggle_paint_large(self) -> None:
        """View > Large Picture to Paint: the split follows at once, and the choice is remembered."""
        self.settings.setValue("paint_large", self.menus.paint_large_action.isChecked())
        self.dock_layout.resplit()

    # --- shutdown and events ---------------------------------------------------------------------
    def shutdown(self) -> None:
        self.renderer.shutdown()
        self.loader.shutdown(wait=True, cancel=True)
        self.files.shutdown()
        self.inputs_pane.shutdown()
        if self._variations is not None:
            self._variations.shutdown()

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
        self.dock_layout.first_show(self._restored_layout)  # (the first show gives the result its share)

    def resizeEvent(self, event):  # noqa: N802
        super().resizeEvent(event)
        if hasattr(self, "dock_layout"):
            self.dock_layout.resized(event.oldSize().width())

    def closeEvent(self, event):  # noqa: N802
        if not self.may_drop_edits("quit"):
            event.ignore()
            return
        self.files.close()
        self.settings.setValue("geometry", self.saveGeometry())
        self.settings.setValue("state", self.saveState())
        self.shutdown()
        super().closeEvent(event)


def _load_job(name: str, path: str, *, progress=None, cancel=None):
    return name, path, read_input(path)
