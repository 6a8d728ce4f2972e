"""The window's menus (File, Edit, View) and what they offer for the current method.

Ctrl+O opens the current method's first input, Ctrl+Shift+O its second (the texture and the target of
a transfer); "Open Input" lists them all, "Open Recent" offers each recent file as each input, and
"Clear Input" the method's optional inputs. The File menu keeps its length for every method (an
entry a method lacks is disabled), so a habitual click never lands on another entry.
"""

from __future__ import annotations

from pathlib import Path

from PySide6.QtGui import QAction, QKeySequence

MAX_RECENT = 8


class Menus:
    """Builds ``window``'s menu bar; :meth:`show_method` sets the entries for the current method.

    ``window`` is the studio's main window: its public parts (``doc``, ``files``, ``renderer``,
    ``inputs_pane``, ``method_panel``, ``method_dock``, ``examples_dock``, ``settings``) and actions
    (``open_input``, ``open_input_dialog``, ``open_batch_dialog``, ``copy_result``, ``zoom_view``,
    ``reset_layout``, ``toggle_paint_large``).
    """

    def __init__(self, window):
        self.window = window
        self.doc = window.doc
        self._build_file()
        self._build_edit()
        self._build_view()
        self.refresh_recent()

    def _action(self, menu, text, slot, shortcut=None, tip=None) -> QAction:
        action = QAction(text, self.window)
        if shortcut is not None:
            action.setShortcut(QKeySequence(shortcut))
        if tip:
            action.setStatusTip(tip)
        action.triggered.connect(slot)
        menu.addAction(action)
        return action

    def _build_file(self) -> None:
        w, files = self.window, self.window.files
        m = w.menuBar().addMenu("&File")
        self.open_first_action = self._action(m, "&Open…", lambda: self._open_nth(0), QKeySequence.StandardKey.Open)
        self.open_second_action = self._action(m, "Open &Second Input…", lambda: self._open_nth(1), "Ctrl+Shift+O")
        self.open_other_menu = m.addMenu("Open Input")
        self.recent_menu = m.addMenu("Open &Recent")
        self.clear_input_menu = m.addMenu("&Clear Input")  # the current method's optional inputs
        m.addSeparator()
        self._action(m, "Open &Session…", files.open_session_dialog, "Ctrl+Shift+L")
        self._action(
            m,
            "&Save Session",
            files.save_session_quick,
            QKeySequence.StandardKey.Save,
            tip="save to the session file last saved or opened (asks where the first time)",
        )
        self._action(m, "Save Session &As…", files.save_session_dialog, QKeySequence.StandardKey.SaveAs)
        m.addSeparator()
        self.save_result_action = self._action(m, "&Export Result…", files.save_result_dialog, "Ctrl+E")
        self._action(m, "Export &Recipe…", files.export_recipe_dialog, "Ctrl+Shift+E")
        self._action(m, "Apply to &Folder…", w.open_batch_dialog, "Ctrl+Shift+B")
        m.addSeparator()
        self.file_menu = m
        lines = w.inputs_pane
        self.load_lines_action = self._action(m, "Load Feature &Lines…", lambda: lines.lines_panel.load_lines_dialog())
        self.save_lines_action = self._action(m, "Save Feature Li&nes…", lambda: lines.lines_panel.save_lines_dialog())
        m.addSeparator()
        self._action(m, "&Quit", w.close, "Ctrl+Q")  # StandardKey.Quit is empty on some desktops

    def _build_edit(self) -> None:
        w = self.window
        e = w.menuBar().addMenu("&Edit")
        undo = self.doc.undo_stack.createUndoAction(w, "&Undo")
        undo.setShortcut(QKeySequence.StandardKey.Undo)
        redo = self.doc.undo_stack.createRedoAction(w, "&Redo")
        redo.setShortcut(QKeySequence.StandardKey.Redo)
        e.addAction(undo)
        e.addAction(redo)
        self.undo_action, self.redo_action = undo, redo
        e.addSeparator()
        self.copy_result_action = self._action(
            e, "&Copy Result", w.copy_result, "Ctrl+Shift+C", tip="copy the full-size result shown to the clipboard"
        )
        self._action(e, "New &Seed", w.method_panel.new_seed, "Ctrl+R")
        self.clear_square_action = self._action(e, "Clear S&quare", lambda: self.doc.set_square(None))
        self.geometry_menu = e.addMenu("&Mask and Canvas")  # the mask and margins tools' actions, if any
        self.geometry_menu.setToolTipsVisible(True)  # a disabled action says why

    def _build_view(self) -> None:
        w = self.window
        v = w.menuBar().addMenu("&View")
        self._action(v, "Zoom &In", lambda: w.zoom_view().zoom_by(1.25), QKeySequence.StandardKey.ZoomIn)
        self._action(v, "Zoom &Out", lambda: w.zoom_view().zoom_by(0.8), QKeySequence.StandardKey.ZoomOut)
        self._action(v, "&Fit to Window", lambda: w.zoom_view().fit(), "Ctrl+0")
        self._action(v, "&Actual Size", lambda: w.zoom_view().actual_size(), "Ctrl+1")
        self._action(v, "&Compare Before/After", w.method_panel.compare_button.toggle, "C")
        self._action(v, "&Render", lambda: w.renderer.final(now=True), "F5")
        v.addSeparator()
        # every dock can be brought back from here (closing the Method dock hides every control)
        for dock in (w.method_dock, w.examples_dock):
            toggle = dock.toggleViewAction()
            toggle.setText(f"{dock.windowTitle()} Panel")
            toggle.setStatusTip(f"show or hide the {dock.windowTitle()} panel")
            v.addAction(toggle)
        self.paint_large_action = self._action(
            v,
            "Large &Picture to Paint",
            w.toggle_paint_large,
            "Ctrl+L",
            tip="the picture you paint on gets the larger share of the window, "
            "the result the smaller (a method that paints on its picture)",
        )
        self.paint_large_action.setCheckable(True)
        self.paint_large_action.setChecked(w.settings.value("paint_large", False, type=bool))
        self.reset_layout_action = self._action(
            v,
            "Reset &Layout",
            w.reset_layout,
            tip="put every panel back where it was when the studio was first opened",
        )
        self.view_menu = v

    # --- per method ----------------------------------------------------------------------------
    def _open_nth(self, i: int) -> None:
        inputs = self.doc.current.inputs
        if i < len(inputs):
            self.window.open_input_dialog(inputs[i].name)

    def show_method(self) -> None:
        """The entries for the current method: its inputs, its lines, its square, its geometry tools."""
        pane = self.window.inputs_pane
        self.paint_large_action.setEnabled(pane.paints_on_canvas())
        has_lines = pane.lines_panel is not None and pane.lines_panel.active
        self.load_lines_action.setEnabled(has_lines)
        self.save_lines_action.setEnabled(has_lines)
        self.clear_square_action.setEnabled(pane.square_on() is not None)
        for action in self.geometry_menu.actions():
            self.geometry_menu.removeAction(action)  # (not clear(): the bar owns them)
        bar = pane.bar()
        for action in [] if bar is None else bar.menu_actions():
            self.geometry_menu.addAction(action)
        self.geometry_menu.setEnabled(bar is not None)
        inputs = self.doc.current.inputs
        self.open_first_action.setText(f"&Open {inputs[0].name.replace('_', ' ')}…")
        self.open_second_action.setEnabled(len(inputs) > 1)
        self.open_second_action.setText(
            f"Open {inputs[1].name.replace('_', ' ')}…" if len(inputs) > 1 else "Open Second Input…"
        )
        self.open_other_menu.clear()
        for inp in inputs:
            act = self.open_other_menu.addAction(f"{inp.name.replace('_', ' ')}…")
            act.triggered.connect(lambda _=False, n=inp.name: self.window.open_input_dialog(n))
        self.refresh_recent()
        self.refresh_clear_inputs()

    def add_recent(self, path: str) -> None:
        settings = self.window.settings
        recent = [p for p in (settings.value("recent", []) or []) if p != path]
        settings.setValue("recent", [path] + recent[: MAX_RECENT - 1])
        self.refresh_recent()

    def refresh_recent(self) -> None:
        self.recent_menu.clear()
        recent = self.window.settings.value("recent", []) or []
        if isinstance(recent, str):
            recent = [recent]
        for path in recent:
            sub = self.recent_menu.addMenu(Path(path).name)
            for inp in [i.name for i in self.doc.current.inputs]:
                act = sub.addAction(f"as {inp.replace('_', ' ')}")
                act.triggered.connect(lambda _=False, p=path, n=inp: self.window.open_input(n, p))
        self.recent_menu.setEnabled(bool(recent))

    def refresh_clear_inputs(self) -> None:
        """File > Clear Input: one entry per optional input of the current method, enabled while open."""
        self.clear_input_menu.clear()
        optional = [i.name for i in self.doc.current.inputs if not i.required]
        for name in optional:
            act = self.clear_input_menu.addAction(f"{name.replace('_', ' ')}")
            act.setEnabled(self.doc.image(name) is not None)
            act.triggered.connect(lambda _=False, n=name: self.doc.clear_input(n))
        self.clear_input_menu.setEnabled(any(self.doc.image(n) is not None for n in optional))
