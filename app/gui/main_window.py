"""The weft studio's main window.

Left: the method's inputs (the texture on top with the prototype tool; the other inputs in tabs
below). Right: the result, with a before/after split. Dock: method, parameters (generated from the
specs), seed, variations. Every edit is an undo command on the document; renders run on the worker
pool (``app.gui.render``); the GUI thread only decodes nothing larger than a frame's work.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from PIL import Image as PILImage
from PySide6.QtCore import QMimeData, QSettings, QSize, QStandardPaths, Qt, QTimer, QUrl, Signal
from PySide6.QtGui import QAction, QIcon, QKeySequence, QPixmap
from PySide6.QtWidgets import (
    QComboBox,
    QDockWidget,
    QFileDialog,
    QHBoxLayout,
    QLabel,
    QListWidget,
    QListWidgetItem,
    QMainWindow,
    QProgressBar,
    QPushButton,
    QScrollArea,
    QSizePolicy,
    QSpinBox,
    QSplitter,
    QStackedWidget,
    QTabWidget,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from core import registry
from core.errors import WeftError
from core.examples import example, examples
from core.image import load_image
from core.jobs import JobRunner

from .convert import to_qimage
from .document import Document, InputImage
from .files import FilesMixin
from .params_panel import ParamsPanel
from .render import Renderer, describe
from .lines_panel import FeatureLinesPanel
from .tools import PatchTool
from .views import ImageView, ResultView, is_image_path

OPEN_FILTER = "Images (*.png *.jpg *.jpeg *.tif *.tiff *.bmp *.webp);;All files (*)"
DEFAULT_INPUTS = {"texture": "wood-grain", "target": "astronaut", "photo": "perspective"}
MAX_RECENT = 8
# The methods the studio offers (those registered): "blend" and "rectify" are command-line steps.
STUDIO_METHODS = ("fast", "quilt", "affine", "nfpt")
AUTOSAVE_MS = 2000  # unsaved edits reach the recovery file at most this long after they are made
RECOVERY_FILE = "recovery.weft.json"


def recovery_path() -> Path:
    """The crash-recovery session file: in ``WEFT_RECOVERY_DIR`` if set, else the app data folder."""
    folder = os.environ.get("WEFT_RECOVERY_DIR") or QStandardPaths.writableLocation(
        QStandardPaths.StandardLocation.AppDataLocation) or str(Path.home() / ".weft")
    return Path(folder) / RECOVERY_FILE


class _ExampleList(QListWidget):
    """The bundled examples; drag one onto a view to open it there."""

    def mimeData(self, items):  # noqa: N802 (Qt naming)
        data = QMimeData()
        data.setUrls([QUrl.fromLocalFile(i.data(Qt.ItemDataRole.UserRole)) for i in items])
        return data


class MainWindow(FilesMixin, QMainWindow):
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
        self.resize(1280, 800)
        self.settings = settings if settings is not None else QSettings("weft", "weft")
        self.doc = Document(self)
        self.renderer = Renderer(self.doc, self)
        # Opened files are decoded off the GUI thread; the result comes back through a queued signal.
        self.loader = JobRunner(max_workers=1, on_result=self._opened.emit)
        self._opened.connect(self._on_opened)
        self._dragging = False

        # views
        self.views: dict[str, ImageView] = {}
        self.result_view = ResultView(self)
        self.texture_view = self._input_view("texture")
        self.patch_tool = PatchTool(self.texture_view, self.doc, on_drag=self._prototype_dragged)
        self.texture_view.tool = self.patch_tool
        self.prototype_patch_tool = PatchTool(self._input_view("prototype_image"), self.doc,
                                              on_drag=self._prototype_dragged)
        # nfpt: the photo with its feature lines, and the frontal frame (live rectification) with its own
        self.photo_view = self._input_view("photo")
        self.lines_panel = FeatureLinesPanel(self.doc, self.photo_view, self)
        self.lines_panel.message.connect(self.show_message)
        self.first_input = QStackedWidget()
        self.first_input.addWidget(self._titled(self.texture_view, "texture — drag a square: prototype / source region"))
        self.first_input.addWidget(self._titled(self.photo_view, "photo — drag to draw feature lines; drag an end to "
                                                                  "move it; click a line + Delete to remove it"))
        self.input_tabs = QTabWidget()
        left = QSplitter(Qt.Orientation.Vertical)
        left.addWidget(self.first_input)
        left.addWidget(self.input_tabs)
        self.splitter = QSplitter(Qt.Orientation.Horizontal)
        self.splitter.addWidget(left)
        self.splitter.addWidget(self._titled(self.result_view, "result"))
        self.splitter.setStretchFactor(0, 2)
        self.splitter.setStretchFactor(1, 3)
        self.splitter.setSizes([420, 630])
        self.setCentralWidget(self.splitter)

        self._build_dock()
        self._build_examples()
        self._build_status()
        self._build_menus()

        self.doc.changed.connect(self._on_doc_changed)
        self.doc.undo_stack.indexChanged.connect(self._update_title)
        # Crash recovery: while the document has unsaved edits, it is autosaved (atomically) at most
        # every AUTOSAVE_MS; a clean document has no recovery file.
        self.recovery_file = recovery_path()
        self._autosave_timer = QTimer(self, singleShot=True, interval=AUTOSAVE_MS)
        self._autosave_timer.timeout.connect(self.autosave)
        self._owns_recovery = False  # only a file this window wrote (or restored) is removed by it
        self.renderer.shown.connect(self._on_shown)
        self.renderer.partial.connect(lambda img: self.result_view.set_image(img))
        self.renderer.progress.connect(self._on_progress)
        self.renderer.preparing.connect(self._on_preparing)
        self.renderer.busy.connect(self._on_busy)
        self.renderer.failed.connect(self._on_failed)
        self.renderer.cancelled.connect(self._on_cancelled)
        self._rebuild_method()
        self.restoreGeometry(self.settings.value("geometry", b""))
        self.restoreState(self.settings.value("state", b""))
        # The method on screen loads (or compiles) its kernels in its own first render; the other
        # methods' are loaded off the GUI thread once that first result is shown.
        self.renderer.warm_up_soon()
        if load_defaults:
            self.load_examples()
        self.offer_recovery()  # before the autosave is connected: opening the examples must not remove it
        self.doc.undo_stack.indexChanged.connect(self._schedule_autosave)
        self.doc.undo_stack.cleanChanged.connect(self._schedule_autosave)
        self.doc.changed.connect(self._schedule_autosave)
        self._schedule_autosave()

    # --- construction --------------------------------------------------------------------------
    def _titled(self, view: ImageView, title: str) -> QWidget:
        box = QWidget()
        lay = QVBoxLayout(box)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.setSpacing(0)
        label = QLabel(f"  {title}")
        label.setStyleSheet("background:#2b2b2b; color:#ddd; padding:2px;")
        label.setToolTip(title)
        # A long title must not widen its pane: it is cut instead.
        label.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Fixed)
        lay.addWidget(label)
        lay.addWidget(view)
        return box

    def _input_view(self, name: str) -> ImageView:
        view = self.views.get(name)
        if view is None:
            view = ImageView(self, title=name)
            view.hovered.connect(lambda x, y, v=view: self._on_hover(v, x, y))
            view.file_dropped.connect(lambda path, n=name: self.open_input(n, path))
            self.views[name] = view
        return view

    def _build_dock(self) -> None:
        panel = QWidget()
        lay = QVBoxLayout(panel)
        top = QHBoxLayout()
        top.addWidget(QLabel("Method"))
        self.method_box = QComboBox()
        for name, m in registry.methods().items():
            if name in STUDIO_METHODS:
                self.method_box.addItem(name)
                self.method_box.setItemData(self.method_box.count() - 1, m.summary, Qt.ItemDataRole.ToolTipRole)
        self.method_box.currentTextChanged.connect(lambda name: self.doc.set_method(name) if name else None)
        top.addWidget(self.method_box, 1)
        lay.addLayout(top)
        self.params_panel = ParamsPanel()
        self.params_panel.edited.connect(self._on_param_edited)
        scroll = QScrollArea()
        scroll.setWidgetResizable(True)
        scroll.setWidget(self.params_panel)
        lay.addWidget(scroll, 1)
        self.prototype_label = QLabel()
        self.prototype_label.setFixedSize(96, 96)
        self.prototype_label.setToolTip("the prototype patch (drag a square on the texture)")
        self.prototype_label.setStyleSheet("border:1px solid #888;")
        seed_row = QHBoxLayout()
        seed_row.addWidget(QLabel("seed"))
        self.seed_box = QSpinBox()
        self.seed_box.setRange(0, 2**31 - 1)
        self.seed_box.setValue(self.doc.seed)
        self.seed_box.setKeyboardTracking(False)
        self.seed_box.valueChanged.connect(self._on_seed)
        seed_row.addWidget(self.seed_box, 1)
        new_seed = QToolButton()
        new_seed.setText("New")
        new_seed.setToolTip("a new random seed")
        new_seed.clicked.connect(self.new_seed)
        seed_row.addWidget(new_seed)
        seed_row.addWidget(self.prototype_label)
        lay.addLayout(seed_row)
        buttons = QHBoxLayout()
        self.render_button = QPushButton("Render")
        self.render_button.setToolTip("render the full-size result (F5)")
        self.render_button.clicked.connect(lambda: self.renderer.final(now=True))
        self.compare_button = QPushButton("Compare")
        self.compare_button.setCheckable(True)
        self.compare_button.setToolTip("before/after split on the result: drag to move the divider (C)")
        self.compare_button.toggled.connect(self.result_view.set_comparing)
        self.variations_button = QPushButton("Variations…")
        self.variations_button.setToolTip("render a grid over two parameters and adopt a cell")
        self.variations_button.clicked.connect(self.open_variations)
        for b in (self.render_button, self.compare_button, self.variations_button):
            buttons.addWidget(b)
        lay.addLayout(buttons)
        dock = QDockWidget("Method", self)
        dock.setObjectName("method")
        dock.setWidget(panel)
        dock.setMinimumWidth(390)
        self.addDockWidget(Qt.DockWidgetArea.RightDockWidgetArea, dock)

    def _build_examples(self) -> None:
        self.example_list = _ExampleList()
        self.example_list.setViewMode(QListWidget.ViewMode.IconMode)
        self.example_list.setIconSize(QSize(72, 72))
        self.example_list.setResizeMode(QListWidget.ResizeMode.Adjust)
        self.example_list.setMovement(QListWidget.Movement.Static)
        self.example_list.setDragEnabled(True)
        self.example_list.setSpacing(4)
        for path in examples():
            item = QListWidgetItem(QIcon(str(path)), path.stem)
            item.setData(Qt.ItemDataRole.UserRole, str(path))
            item.setToolTip(f"{path.name}: double-click to open as texture, drag onto a view to open it there")
            self.example_list.addItem(item)
        self.example_list.itemDoubleClicked.connect(
            lambda item: self.open_input("texture", item.data(Qt.ItemDataRole.UserRole)))
        dock = QDockWidget("Examples", self)
        dock.setObjectName("examples")
        dock.setWidget(self.example_list)
        self.addDockWidget(Qt.DockWidgetArea.LeftDockWidgetArea, dock)
        self.examples_dock = dock

    def _build_status(self) -> None:
        self.pixel_label = QLabel("")
        self.zoom_label = QLabel("")
        self.progress_bar = QProgressBar()
        self.progress_bar.setMaximumWidth(220)
        self.progress_bar.setRange(0, 1000)
        self.cancel_button = QPushButton("Cancel")
        self.cancel_button.clicked.connect(self.renderer.cancel)
        for w in (self.pixel_label, self.zoom_label, self.progress_bar, self.cancel_button):
            self.statusBar().addPermanentWidget(w)
        self.progress_bar.hide()
        self.cancel_button.hide()
        for view in (self.texture_view, self.result_view):
            view.zoomed.connect(lambda s: self.zoom_label.setText(f"{s * 100:.0f}%"))
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
        self._action(m, "Open &Texture…", lambda: self.open_input_dialog("texture"), QKeySequence.StandardKey.Open)
        self._action(m, "Open T&arget…", lambda: self.open_input_dialog("target"), "Ctrl+Shift+O")
        self.open_other_menu = m.addMenu("Open Other Input")
        self.recent_menu = m.addMenu("Open &Recent")
        m.addSeparator()
        self._action(m, "Open &Session…", self.open_session_dialog, "Ctrl+Shift+L")
        self._action(m, "&Save Session…", self.save_session_dialog, QKeySequence.StandardKey.Save)
        m.addSeparator()
        self.save_result_action = self._action(m, "&Export Result…", self.save_result_dialog, "Ctrl+E")
        self._action(m, "Export &Recipe…", self.export_recipe_dialog, "Ctrl+Shift+E")
        self._action(m, "Apply to &Folder…", self.open_batch_dialog, "Ctrl+Shift+B")
        m.addSeparator()
        self._action(m, "Load Feature &Lines…", lambda: self.lines_panel.load_lines_dialog())
        self._action(m, "Save Feature Li&nes…", lambda: self.lines_panel.save_lines_dialog())
        m.addSeparator()
        self._action(m, "&Quit", self.close, QKeySequence.StandardKey.Quit)
        e = self.menuBar().addMenu("&Edit")
        undo = self.doc.undo_stack.createUndoAction(self, "&Undo")
        undo.setShortcut(QKeySequence.StandardKey.Undo)
        redo = self.doc.undo_stack.createRedoAction(self, "&Redo")
        redo.setShortcut(QKeySequence.StandardKey.Redo)
        e.addAction(undo)
        e.addAction(redo)
        self.undo_action, self.redo_action = undo, redo
        e.addSeparator()
        self._action(e, "New &Seed", self.new_seed, "Ctrl+R")
        self._action(e, "Clear &Prototype", lambda: self.doc.set_prototype(None))
        v = self.menuBar().addMenu("&View")
        self._action(v, "Zoom &In", lambda: self._focused_view().zoom_by(1.25), QKeySequence.StandardKey.ZoomIn)
        self._action(v, "Zoom &Out", lambda: self._focused_view().zoom_by(0.8), QKeySequence.StandardKey.ZoomOut)
        self._action(v, "&Fit to Window", lambda: self._focused_view().fit(), "Ctrl+0")
        self._action(v, "&Actual Size", lambda: self._focused_view().actual_size(), "Ctrl+1")
        self._action(v, "&Compare Before/After", self.compare_button.toggle, "C")
        self._action(v, "&Render", lambda: self.renderer.final(now=True), "F5")
        v.addSeparator()
        v.addAction(self.examples_dock.toggleViewAction())
        self._refresh_recent()

    # --- inputs ----------------------------------------------------------------------------------
    def load_examples(self) -> None:
        """Open the bundled default texture and target (the window opens with a result)."""
        for name, stem in DEFAULT_INPUTS.items():
            try:
                path = example(stem)
            except WeftError:
                continue
            loaded = load_image(path)  # small bundled files: a few milliseconds
            self.doc._put_input(name, InputImage(str(path), loaded.image))
        self.doc.undo_stack.clear()
        self.renderer.final(now=True)

    def open_input_dialog(self, name: str) -> None:
        start = str(self.settings.value("last_dir", ""))
        path, _ = QFileDialog.getOpenFileName(self, f"Open {name}", start, OPEN_FILTER)
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
        name, path, image = result.value
        self.settings.setValue("last_dir", str(Path(path).parent))
        self._add_recent(path)
        self.doc.set_input(name, path, image)
        self.statusBar().showMessage(f"{name}: {Path(path).name} {image.shape[1]}x{image.shape[0]}", 4000)

    def _add_recent(self, path: str) -> None:
        recent = [p for p in (self.settings.value("recent", []) or []) if p != path]
        self.settings.setValue("recent", [path] + recent[:MAX_RECENT - 1])
        self._refresh_recent()

    def _refresh_recent(self) -> None:
        self.recent_menu.clear()
        recent = self.settings.value("recent", []) or []
        if isinstance(recent, str):
            recent = [recent]
        for path in recent:
            sub = self.recent_menu.addMenu(Path(path).name)
            for inp in ("texture", "target"):
                act = sub.addAction(f"as {inp}")
                act.triggered.connect(lambda _=False, p=path, n=inp: self.open_input(n, p))
        self.recent_menu.setEnabled(bool(recent))

    # --- document changes ----------------------------------------------------------------------
    def _on_doc_changed(self, what: str) -> None:
        if what.startswith("input:"):
            name = what.split(":", 1)[1]
            view = self._input_view(name)
            view.set_image(self.doc.image(name), fit=True)
            if name == "texture":
                self.patch_tool.refresh()
                self._update_prototype_thumb()
            if name in ("texture", "prototype_image"):
                self._sync_patch_tools()
            if name == "photo":
                self.lines_panel.photo_changed()
            self._update_compare()
            self.renderer.final()
        elif what == "method":
            self._rebuild_method()
            self.renderer.final()
        elif what == "params":
            self._show_params()
            if not self._dragging:
                self.renderer.final()
        elif what == "lines":
            self.lines_panel.lines_changed()
            if self.doc.method == "nfpt":
                self.renderer.final()
        elif what == "prototype":
            self.doc.live_prototype = None
            self._sync_patch_tools()
            self._update_prototype_thumb()
            self.renderer.final()
        elif what == "seed":
            self.seed_box.blockSignals(True)
            self.seed_box.setValue(self.doc.seed)
            self.seed_box.blockSignals(False)
            self.renderer.final()

    def _rebuild_method(self) -> None:
        method = self.doc.current
        self.method_box.blockSignals(True)
        self.method_box.setCurrentText(self.doc.method)
        self.method_box.blockSignals(False)
        self.params_panel.build(method.params, hidden=("lines", "prototype"))
        self._show_params()
        self.first_input.setCurrentIndex(1 if method.inputs[0].name == "photo" else 0)
        self.input_tabs.clear()
        self.lines_panel.set_active(method.inputs[0].name == "photo")
        if method.inputs[0].name == "photo":
            self.input_tabs.addTab(self.lines_panel, "frontal frame (live rectification)")
        for inp in method.inputs[1:]:
            view = self._input_view(inp.name)
            label = inp.name.replace("_", " ") + ("" if inp.required else " (optional)")
            self.input_tabs.addTab(self._titled(view, inp.help), label)
            view.set_image(self.doc.image(inp.name))
        self.input_tabs.setVisible(self.input_tabs.count() > 0)
        self._sync_patch_tools()
        self.open_other_menu.clear()
        for inp in method.inputs:
            act = self.open_other_menu.addAction(f"{inp.name.replace('_', ' ')}…")
            act.triggered.connect(lambda _=False, n=inp.name: self.open_input_dialog(n))
        self._update_compare()

    def _show_params(self) -> None:
        params = self.doc.current_params
        auto = {}
        resolver = getattr(params, "resolved", None)
        if resolver is not None:
            try:
                resolved = resolver("target" in self.doc.inputs)
                auto = {name: getattr(resolved, name) for name in self.params_panel.rows}
            except WeftError:
                auto = {}
        self.params_panel.show_params(params, auto)

    def _on_param_edited(self, name: str, value, dragging: bool) -> None:
        try:
            self._dragging = dragging
            self.doc.set_param(name, value)
        except WeftError as e:
            self.show_message(str(e))
            self._show_params()  # back to the valid value
            return
        finally:
            self._dragging = False
        if dragging:
            self.renderer.preview()
        else:
            self.renderer.final()

    def _on_seed(self, value: int) -> None:
        self.doc.seed = int(value)
        self.doc.changed.emit("seed")

    def new_seed(self) -> None:
        self.seed_box.setValue(int(np.random.default_rng().integers(0, 2**31 - 1)))

    def _prototype_dragged(self, rect) -> None:
        self._update_prototype_thumb(rect)
        params = self.doc.current_params
        if getattr(params, "reuse_transforms", False):
            # affine with reused transforms: re-render live while the square moves (§4 prototype swap)
            self.doc.live_prototype = rect
            self.renderer.preview()

    def _prototype_source(self) -> str:
        """Which input the prototype square lies on: affine's prototype image when one is open."""
        if self.doc.method == "affine" and "prototype_image" in self.doc.inputs:
            return "prototype_image"
        return "texture"

    def _sync_patch_tools(self) -> None:
        """The prototype square is drawn (and edited) on the image it belongs to."""
        source = self._prototype_source()
        for name, tool in (("texture", self.patch_tool), ("prototype_image", self.prototype_patch_tool)):
            tool.view.tool = tool if name == source else None
            tool.rect_item.setVisible(False)
            for h in tool.handles:
                h.setVisible(False)
            if name == source:
                tool.refresh()

    def _update_prototype_thumb(self, rect=None) -> None:
        rect = rect or self.doc.prototype
        tex = self.doc.image(self._prototype_source())
        if rect is None or tex is None:
            self.prototype_label.clear()
            return
        x, y, s = rect
        patch = tex[y:y + s, x:x + s]
        if patch.size:
            pix = QPixmap.fromImage(to_qimage(patch)).scaled(96, 96, Qt.AspectRatioMode.KeepAspectRatio)
            self.prototype_label.setPixmap(pix)

    def _update_compare(self) -> None:
        self.result_view.set_compare(self.doc.image("target") if "target" in self.doc.inputs else self.doc.image("texture"))

    # --- results ---------------------------------------------------------------------------------
    def _on_shown(self, shown) -> None:
        self.result_view.set_image(shown.image)
        self.statusBar().showMessage(describe(shown))

    def _on_progress(self, fraction: float, stage: str) -> None:
        self._end_preparing()
        self.progress_bar.setValue(int(fraction * 1000))
        self.progress_bar.setFormat(f"{stage} %p%")

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
        self.progress_bar.setVisible(busy)
        self.cancel_button.setVisible(busy)
        if busy:
            if self.progress_bar.maximum() > 0:  # not while preparing
                self.progress_bar.setValue(0)
        else:
            self._end_preparing()

    def _on_failed(self, message: str) -> None:
        self.show_message(message)
        if self.renderer.last is not None:
            self.result_view.set_image(self.renderer.last.image)

    def _on_cancelled(self) -> None:
        if self.renderer.last is not None:
            self.result_view.set_image(self.renderer.last.image)
        self.statusBar().showMessage("cancelled; the previous result is kept", 4000)

    def show_message(self, text: str) -> None:
        """A one-line message in the status bar (errors never open a blocking dialog mid-drag)."""
        self.statusBar().showMessage(text, 8000)
        self.message.emit(text)

    def _on_hover(self, view: ImageView, x: int, y: int) -> None:
        img = view.image
        if x < 0 or img is None:
            self.pixel_label.setText("")
            return
        v = img[y, x]
        value = f"{float(v):.3f}" if np.ndim(v) == 0 else " ".join(f"{float(c):.3f}" for c in v)
        self.pixel_label.setText(f"{view.title}  x {x}  y {y}  {value}")

    def _focused_view(self) -> ImageView:
        for view in [self.result_view, *self.views.values()]:
            if view.hasFocus():
                return view
        return self.result_view

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
        self.setWindowTitle(f"weft — {self.doc.method}{dirty}")

    # --- shutdown --------------------------------------------------------------------------------
    def shutdown(self) -> None:
        self.renderer.shutdown()
        self.loader.shutdown(wait=True, cancel=True)
        self.lines_panel.shutdown()
        dialog = getattr(self, "_variations", None)
        if dialog is not None:
            dialog.shutdown()

    def showEvent(self, event):  # noqa: N802
        super().showEvent(event)
        if not getattr(self, "_sized", False):  # first show: give the result the larger share
            self._sized = True
            total = max(self.splitter.width(), 400)
            self.splitter.setSizes([int(total * 0.45), int(total * 0.55)])

    def closeEvent(self, event):  # noqa: N802
        if not self.doc.undo_stack.isClean() and not self._confirm("Discard your unsaved edits and quit?"):
            event.ignore()
            return
        self._autosave_timer.stop()
        if self._owns_recovery:
            self.discard_recovery()
        self.settings.setValue("geometry", self.saveGeometry())
        self.settings.setValue("state", self.saveState())
        self.shutdown()
        super().closeEvent(event)


def _load_job(name: str, path: str, *, progress=None, cancel=None):
    loaded = load_image(path)
    return name, path, loaded.image
