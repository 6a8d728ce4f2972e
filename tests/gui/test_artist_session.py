"""The studio as an artist meets it: each test drives the window with real events."""

import dataclasses

import numpy as np
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QSlider
from weft.core.errors import WeftError


def _failing(method):
    def run(inputs, params, *, rng=None, progress=None, cancel=None):
        raise WeftError("the kernel refused these settings")

    return dataclasses.replace(method, run=run)


def test_a_failed_render_marks_the_result_stale_until_a_render_succeeds(window, qtbot, monkeypatch):
    view = window.result_view
    good = window.doc.methods["fast"]
    assert not view.stale.isVisible()
    monkeypatch.setitem(window.doc.methods, "fast", _failing(good))
    with qtbot.waitSignal(window.renderer.failed, timeout=10000):
        qtbot.keyClick(window, Qt.Key.Key_F5)  # View > Render
    assert view.stale.isVisible() and "the kernel refused these settings" in view.stale.text()
    assert view.stale.geometry().top() == 0 and view.stale.width() == view.viewport().width()
    window.statusBar().clearMessage()  # the status bar forgets; the mark stays
    assert view.stale.isVisible()
    monkeypatch.setitem(window.doc.methods, "fast", good)
    with qtbot.waitSignal(window.renderer.shown, timeout=20000):
        qtbot.keyClick(window, Qt.Key.Key_F5)
    assert not view.stale.isVisible()


def test_unticking_auto_starts_from_the_resolved_value_and_a_disabled_slider_says_why(window, qtbot):
    doc = window.doc
    doc.set_method("quilt")  # a transfer (the studio opens a target): block resolves to 9, overlap 3
    qtbot.waitUntil(
        lambda: (
            "block" in window.method_panel.params_panel.rows
            and window.method_panel.params_panel.row("block").auto.isVisible()
        ),
        timeout=5000,
    )
    row = window.method_panel.params_panel.row("block")
    assert row.auto.isChecked() and not row.editor.isEnabled()
    assert "auto" in row.editor.toolTip() and "now 9" in row.editor.toolTip()
    qtbot.mouseClick(row.auto, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: doc.current_params.block is not None, timeout=5000)
    assert doc.current_params.block == 9  # the resolved value, not the minimum 2
    assert row.editor.isEnabled() and row.editor.value() == 9
    assert "auto" not in row.editor.toolTip().split("\n")[0]
    window.renderer.cancel()


def _click_menu_item(qtbot, menu, action):
    """Open ``menu`` and click ``action`` in it with the mouse."""
    menu.popup(menu.parentWidget().mapToGlobal(menu.parentWidget().rect().center()))
    qtbot.waitUntil(menu.isVisible, timeout=5000)
    qtbot.mouseClick(menu, Qt.MouseButton.LeftButton, pos=menu.actionGeometry(action).center())


def test_every_dock_is_in_the_view_menu_and_reset_layout_restores_it(window, qtbot):
    from PySide6.QtWidgets import QAbstractButton, QDockWidget

    docks = window.findChildren(QDockWidget)
    menu = window.menus.view_menu
    assert {d.toggleViewAction() for d in docks} <= set(menu.actions())
    method = window.method_dock
    close = method.findChild(QAbstractButton, "qt_dockwidget_closebutton")
    qtbot.mouseClick(close, Qt.MouseButton.LeftButton)  # every control gone ...
    qtbot.waitUntil(lambda: not method.isVisible(), timeout=5000)
    _click_menu_item(qtbot, menu, method.toggleViewAction())  # ... and back from the View menu
    qtbot.waitUntil(method.isVisible, timeout=5000)
    # move things around: Method floats, Examples closes
    float_button = method.findChild(QAbstractButton, "qt_dockwidget_floatbutton")
    qtbot.mouseClick(float_button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(method.isFloating, timeout=5000)
    qtbot.mouseClick(
        window.examples_dock.findChild(QAbstractButton, "qt_dockwidget_closebutton"), Qt.MouseButton.LeftButton
    )
    qtbot.waitUntil(lambda: not window.examples_dock.isVisible(), timeout=5000)
    _click_menu_item(qtbot, menu, window.menus.reset_layout_action)
    qtbot.waitUntil(lambda: all(d.isVisible() and not d.isFloating() for d in docks), timeout=5000)
    assert window.dockWidgetArea(method) == Qt.DockWidgetArea.RightDockWidgetArea
    assert window.dockWidgetArea(window.examples_dock) == Qt.DockWidgetArea.LeftDockWidgetArea


def test_zoom_shortcuts_act_on_the_view_under_the_mouse_and_the_label_shows_its_zoom(window, qtbot):
    from .helpers import mouse

    result, canvas = window.result_view, window.inputs_pane.canvas_view
    canvas.setFocus()  # the keyboard focus is on the canvas ...
    qtbot.waitUntil(canvas.hasFocus, timeout=5000)
    canvas_scale = canvas.scale_factor()
    assert abs(result.scale_factor() - 1.0) > 0.01  # the result is fitted, not at 100%
    w, h = result.image_size()
    mouse(result, "move", (w / 2, h / 2))  # ... the mouse over the result
    qtbot.keyClick(window, Qt.Key.Key_1, Qt.KeyboardModifier.ControlModifier)  # Actual Size
    qtbot.waitUntil(lambda: abs(result.scale_factor() - 1.0) < 1e-6, timeout=5000)
    assert canvas.scale_factor() == canvas_scale
    assert window.status.zoom_label.text() == "result 100%"
    cw, ch = canvas.image_size()
    mouse(canvas, "move", (cw / 2, ch / 2))
    assert window.status.zoom_label.text() == f"{canvas.title} {canvas_scale * 100:.0f}%"
    qtbot.keyClick(window, Qt.Key.Key_Plus, Qt.KeyboardModifier.ControlModifier)  # Zoom In
    qtbot.waitUntil(lambda: abs(canvas.scale_factor() - canvas_scale * 1.25) < 1e-6, timeout=5000)
    assert abs(result.scale_factor() - 1.0) < 1e-6
    assert window.status.zoom_label.text() == f"{canvas.title} {canvas_scale * 125:.0f}%"


def test_an_optional_input_can_be_cleared_from_its_tab_and_the_clear_undone(window, qtbot):
    doc = window.doc
    target = doc.image("target")
    assert window.renderer.last.image.shape[:2] == target.shape[:2]  # a transfer onto the target
    box = window.inputs_pane.box("target")
    window.inputs_pane.tabs.setCurrentWidget(box)
    qtbot.waitUntil(box.clear_button.isVisible, timeout=5000)
    assert not window.inputs_pane.box("texture").clear_button.isVisible()  # required: no Clear
    with qtbot.waitSignal(
        window.renderer.shown,
        timeout=20000,
        check_params_cb=lambda shown: shown.final and "target" not in shown.recipe.inputs,
    ):
        qtbot.mouseClick(box.clear_button, Qt.MouseButton.LeftButton)
    assert doc.image("target") is None and not box.clear_button.isEnabled()
    assert window.renderer.last.image.shape[:2] != target.shape[:2]  # plain synthesis now
    assert [a.text() for a in window.menus.clear_input_menu.actions()] == ["target", "mask"]  # File > Clear Input
    assert not window.menus.clear_input_menu.isEnabled()  # neither is open now
    with qtbot.waitSignal(
        window.renderer.shown,
        timeout=20000,
        check_params_cb=lambda shown: shown.final and "target" in shown.recipe.inputs,
    ):
        qtbot.keyClick(window, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)  # Undo
    assert doc.image("target") is target and box.clear_button.isEnabled()
    assert window.renderer.last.image.shape[:2] == target.shape[:2]


def _click_in_box_when_shown(qtbot, button):
    """Once a modal message box is up, click its ``button`` with the mouse; returns the box's text."""
    from PySide6.QtCore import QTimer
    from PySide6.QtWidgets import QApplication, QMessageBox

    seen = []

    def poll():
        box = QApplication.activeModalWidget()
        if not isinstance(box, QMessageBox):
            QTimer.singleShot(20, poll)
            return
        seen.append((box.text(), sorted(b.text().replace("&", "") for b in box.buttons())))
        qtbot.mouseClick(box.button(button), Qt.MouseButton.LeftButton)

    QTimer.singleShot(0, poll)
    return seen


def test_quitting_with_unsaved_edits_offers_save_discard_cancel(window, qtbot, monkeypatch, tmp_path):
    from PySide6.QtWidgets import QFileDialog, QMessageBox
    from weft.app.gui.questions import Questions

    monkeypatch.undo()  # the real question, not the conftest's answer ...
    monkeypatch.setenv("WEFT_RECOVERY_DIR", str(tmp_path / "recovery"))  # ... with a private autosave
    monkeypatch.setattr(Questions, "confirm", lambda self, question: True)
    window.doc.set_param("p", 0.5)
    seen = _click_in_box_when_shown(qtbot, QMessageBox.StandardButton.Cancel)
    qtbot.keyClick(window, Qt.Key.Key_Q, Qt.KeyboardModifier.ControlModifier)  # File > Quit
    assert seen and seen[0][1] == ["Cancel", "Discard", "Save"] and "quit" in seen[0][0]
    assert window.isVisible()  # Cancel: the window stays, edits kept
    session = tmp_path / "kept.weft.json"
    monkeypatch.setattr(QFileDialog, "getSaveFileName", lambda *a, **k: (str(session), ""))
    window.activateWindow()  # the box has gone: the window is active again
    qtbot.waitUntil(window.isActiveWindow, timeout=5000)
    seen = _click_in_box_when_shown(qtbot, QMessageBox.StandardButton.Save)
    qtbot.keyClick(window, Qt.Key.Key_Q, Qt.KeyboardModifier.ControlModifier)
    assert seen and not window.isVisible()  # Save: the session is written, then the studio quits
    assert session.exists() and '"p": 0.5' in session.read_text(encoding="utf-8")


def test_esc_cancels_a_running_render_and_keeps_the_previous_result(window, qtbot, monkeypatch):
    import threading

    shown = window.renderer.last
    started = threading.Event()

    def run(inputs, params, *, rng=None, progress=None, cancel=None):
        started.set()
        while True:
            cancel.raise_if_cancelled()
            threading.Event().wait(0.01)

    monkeypatch.setitem(window.doc.methods, "fast", dataclasses.replace(window.doc.methods["fast"], run=run))
    qtbot.keyClick(window, Qt.Key.Key_F5)
    qtbot.waitUntil(started.is_set, timeout=5000)
    with qtbot.waitSignal(window.renderer.cancelled, timeout=5000):
        qtbot.keyClick(window.result_view, Qt.Key.Key_Escape)  # the view has no use for it: the window's
    qtbot.waitUntil(lambda: not window.renderer.runner.busy("final"), timeout=5000)
    assert window.renderer.last is shown and window.result_view.image is shown.image


def test_square_handles_keep_their_size_on_screen_through_zooming(window, qtbot):
    from weft.app.gui.tools import HANDLE_PX

    from .helpers import drag, mouse

    view = window.inputs_pane.canvas_view
    drag(view, (20, 20), (60, 60))  # a source square on the texture
    qtbot.waitUntil(lambda: window.doc.square is not None, timeout=5000)
    tool = view.tool

    def on_screen():
        sizes = []
        for h in tool.handles:
            r = h.deviceTransform(view.viewportTransform()).mapRect(h.boundingRect())
            sizes.append(round(r.width()))
        return sizes

    first = on_screen()
    assert all(abs(s - HANDLE_PX) <= 2 for s in first), first
    w, h = view.image_size()
    mouse(view, "move", (w / 2, h / 2))
    before = view.scale_factor()
    for _ in range(3):
        qtbot.keyClick(window, Qt.Key.Key_Plus, Qt.KeyboardModifier.ControlModifier)
    qtbot.waitUntil(lambda: abs(view.scale_factor() - before * 1.25**3) < 1e-6, timeout=5000)
    assert on_screen() == first
    qtbot.keyClick(window, Qt.Key.Key_0, Qt.KeyboardModifier.ControlModifier)
    assert on_screen() == first


def _fills_view(view) -> bool:
    w, h = view.image_size()
    shown = view.mapFromScene(0, 0, w, h).boundingRect()
    vp = view.viewport().rect()
    return (
        (abs(shown.width() - vp.width()) <= 3 or abs(shown.height() - vp.height()) <= 3)
        and shown.width() <= vp.width() + 3
        and shown.height() <= vp.height() + 3
    )


def test_a_result_of_another_size_refits_unless_the_user_zoomed(window, qtbot):
    """A new result size refits the result view; a hand zoom is kept."""
    from .helpers import mouse

    view = window.result_view
    old = view.image_size()
    assert _fills_view(view)
    box = window.inputs_pane.box("target")
    window.inputs_pane.tabs.setCurrentWidget(box)
    qtbot.waitUntil(box.clear_button.isVisible, timeout=5000)
    qtbot.mouseClick(box.clear_button, Qt.MouseButton.LeftButton)  # synthesis: twice the texture
    qtbot.waitUntil(lambda: view.image_size() != old and window.renderer.last.final, timeout=20000)
    assert _fills_view(view)
    w, h = view.image_size()
    mouse(view, "move", (w / 2, h / 2))
    qtbot.keyClick(window, Qt.Key.Key_1, Qt.KeyboardModifier.ControlModifier)  # the user zooms: 100%
    with qtbot.waitSignal(window.renderer.shown, timeout=20000, check_params_cb=lambda s: s.final):
        qtbot.keyClick(window, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)  # the target is back
    assert view.image_size() == old and abs(view.scale_factor() - 1.0) < 1e-6


def test_variations_default_to_ranges_near_the_resolved_values_fit_the_screen_and_export(window, qtbot, tmp_path):
    from weft.core.image import load_image

    window.doc.set_method("quilt")  # a transfer: block resolves to 9, overlap to 3 (texture 112x128)
    qtbot.mouseClick(window.method_panel.variations_button, Qt.MouseButton.LeftButton)
    dialog = window.variations
    qtbot.waitUntil(dialog.isVisible, timeout=5000)
    assert [dialog._spec(0).name, dialog._spec(1).name] == ["block", "overlap"]
    assert (dialog.lo[0].value(), dialog.hi[0].value()) == (5, 13) and dialog.lo[0].decimals() == 0
    assert (dialog.lo[1].value(), dialog.hi[1].value()) == (2, 4)
    dialog.hi[1].lineEdit().selectAll()
    qtbot.keyClicks(dialog.hi[1], "6")  # overlap 2, 4, 6: 6 is not smaller than block 5
    qtbot.keyClick(dialog.hi[1], Qt.Key.Key_Return)
    assert dialog.hi[1].value() == 6
    done = set()
    dialog.cell_done.connect(lambda i, j: done.add((i, j)))
    qtbot.mouseClick(dialog.render_button, Qt.MouseButton.LeftButton)
    run = {k for k, b in dialog.cells.items() if b.isEnabled()}
    refused = set(dialog.cells) - run  # overlap >= block: refused up front, never run
    assert refused == {(0, 2)} and "smaller than block" in dialog.cells[(0, 2)].toolTip()
    qtbot.waitUntil(lambda: done == run, timeout=60000)
    assert all(not dialog.cells[k].icon().isNull() for k in run)  # every cell that ran is valid
    free = dialog.screen().availableGeometry()
    qtbot.waitUntil(lambda: free.contains(dialog.frameGeometry()), timeout=5000)  # all of it on the screen
    assert dialog.height() > 3 * dialog.side  # (the grid itself, not the empty dialog)
    assert dialog.cells[(0, 2)].width() == dialog.cells[(0, 0)].width()  # the error did not widen its cell
    out = tmp_path / "grid.png"
    assert dialog.export_button.isEnabled() and dialog.export_grid(str(out))
    grid = load_image(out).image
    cell = dialog.images[(1, 1)]
    assert grid.shape[0] >= 3 * cell.shape[0] and grid.shape[1] >= 3 * cell.shape[1]
    dialog.close()


def test_ctrl_shift_c_copies_the_full_size_result_to_the_clipboard(window, qtbot):
    import numpy as np
    from PySide6.QtWidgets import QApplication

    clipboard = QApplication.clipboard()
    clipboard.clear()
    with qtbot.waitSignal(clipboard.dataChanged, timeout=5000):
        qtbot.keyClick(window, Qt.Key.Key_C, Qt.KeyboardModifier.ControlModifier | Qt.KeyboardModifier.ShiftModifier)
    image = clipboard.image()
    shown = window.renderer.last.image
    assert (image.width(), image.height()) == (shown.shape[1], shown.shape[0])
    pixel = image.pixelColor(10, 20)
    assert np.allclose([pixel.redF(), pixel.greenF(), pixel.blueF()], shown[20, 10, :3], atol=1 / 255 + 1e-6)


def test_save_dialogs_start_in_the_last_folder_with_a_suggested_name(window, qtbot, monkeypatch, tmp_path):
    from PySide6.QtWidgets import QFileDialog

    asked = []
    out = tmp_path / "renders" / "mine.png"
    out.parent.mkdir()
    replies = iter([str(out), ""])
    monkeypatch.setattr(
        QFileDialog,
        "getSaveFileName",
        lambda parent, caption, start, filters: asked.append(start) or (next(replies), ""),
    )
    qtbot.keyClick(window, Qt.Key.Key_E, Qt.KeyboardModifier.ControlModifier)  # Export Result…
    assert out.exists()
    canvas = window.doc.inputs[window.doc.studio.canvas].path
    from pathlib import Path

    assert asked[0] == str(Path.home() / f"{Path(canvas).stem}-fast.png")  # no folder used yet: home
    qtbot.keyClick(window, Qt.Key.Key_E, Qt.KeyboardModifier.ControlModifier | Qt.KeyboardModifier.ShiftModifier)
    assert asked[1] == str(out.parent / f"{Path(canvas).stem}-fast.json")  # the folder used last


def test_quad_says_on_screen_which_corner_to_click(window, qtbot):
    from .helpers import mouse

    window.doc.set_method("nfpt")
    qtbot.waitUntil(
        lambda: window.inputs_pane.lines_panel is not None and window.inputs_pane.lines_panel.active, timeout=5000
    )
    panel = window.inputs_pane.lines_panel
    window.inputs_pane.tabs.setCurrentWidget(panel)
    qtbot.mouseClick(panel.quad_button, Qt.MouseButton.LeftButton)
    assert "top-left corner" in panel.rectify_status.text() and "1 of 4" in panel.rectify_status.text()
    view = panel.photo_view
    for k, (x, y) in enumerate([(10, 10), (100, 12), (98, 90)]):
        mouse(view, "press", (x, y))
        mouse(view, "release", (x, y))
        assert f"{k + 2} of 4" in panel.rectify_status.text()
    assert "bottom-left corner" in panel.rectify_status.text()
    qtbot.keyClick(view, Qt.Key.Key_Escape)  # start again
    assert "top-left corner" in panel.rectify_status.text()


def test_the_square_thumbnail_is_labelled(window, qtbot):
    from .helpers import drag

    caption = window.method_panel.square_caption
    assert caption.isVisible() and caption.text() == "source region: none drawn"
    drag(window.inputs_pane.canvas_view, (20, 20), (60, 60))
    qtbot.waitUntil(lambda: window.doc.square is not None, timeout=5000)
    assert caption.text() == f"source region {window.doc.square[2]} px"
    window.doc.set_method("affine")
    qtbot.waitUntil(lambda: caption.text().startswith("prototype"), timeout=5000)


def test_weft_image_target_opens_the_studio_on_those_images(window, qtbot, monkeypatch, tmp_path):
    import numpy as np
    from weft.app import cli
    from weft.app import gui as gui_package
    from weft.core.image import save_image

    tex, tgt = tmp_path / "tex.png", tmp_path / "tgt.png"
    save_image(tex, np.full((40, 30, 3), 0.25, np.float32))
    save_image(tgt, np.full((50, 60, 3), 0.75, np.float32))
    opened = []
    monkeypatch.setattr(gui_package, "run_gui", lambda argv=None, *, images=None: opened.append(images) or 0)
    assert cli.main([str(tex), str(tgt)]) == 0 and opened == [[str(tex), str(tgt)]]
    window.open_images(opened[0])  # what run_gui does with them once the window is up
    qtbot.waitUntil(
        lambda: window.doc.inputs["texture"].path == str(tex) and window.doc.inputs["target"].path == str(tgt),
        timeout=10000,
    )
    assert window.doc.image("target").shape == (50, 60, 3)


def test_a_long_render_shows_an_estimate_of_the_time_left(window, qtbot, monkeypatch):
    import threading

    from weft.core.jobs import Progress

    def run(inputs, params, *, rng=None, progress=None, cancel=None):
        for k in range(1, 1000):
            cancel.raise_if_cancelled()
            threading.Event().wait(0.02)
            progress(Progress("quilting", k, 1000))  # 0.1 % every 0.02 s: about 20 s in all

    monkeypatch.setitem(window.doc.methods, "fast", dataclasses.replace(window.doc.methods["fast"], run=run))
    qtbot.keyClick(window, Qt.Key.Key_F5)
    bar = window.status.progress_bar
    qtbot.waitUntil(lambda: bar.isVisible() and "left" in bar.format(), timeout=15000)
    import re

    assert re.fullmatch(r"quilting %p% — about (\d+ min )?\d+ s left", bar.format()), bar.format()
    qtbot.keyClick(window.result_view, Qt.Key.Key_Escape)
    qtbot.waitUntil(lambda: not window.renderer.runner.busy("final"), timeout=5000)


def test_the_zoom_label_follows_a_refit_when_the_window_is_resized(window, qtbot):
    """A fitted view refits when its pane changes size; the % label must show the new zoom (it kept
    the zoom of the first, tiny layout: 'result 9%' over a result shown at 143%)."""
    from .helpers import mouse

    result = window.result_view
    w, h = result.image_size()
    mouse(result, "move", (w / 2, h / 2))
    window.result_view.fit()
    before = result.scale_factor()
    window.resize(window.width() + 300, window.height() + 200)
    qtbot.waitUntil(lambda: abs(result.scale_factor() - before) > 0.01, timeout=5000)
    qtbot.waitUntil(
        lambda: window.status.zoom_label.text() == f"result {result.scale_factor() * 100:.0f}%", timeout=5000
    )


def test_auto_block_follows_the_sample_and_its_source_region(window, qtbot):
    """Quilting's synthesis block defaults to a share of the sample's size, so what the
    studio shows beside "auto" follows the texture, then the square drawn on it (the source region
    is the sample a run quilts from)."""
    from .helpers import drag

    doc = window.doc
    doc.set_method("quilt")
    doc.clear_input("target")  # a synthesis: the wood-grain sample, 128x112
    qtbot.waitUntil(
        lambda: (
            "block" in window.method_panel.params_panel.rows
            and window.method_panel.params_panel.row("block").auto.isVisible()
        ),
        timeout=5000,
    )
    row = window.method_panel.params_panel.row("block")
    qtbot.waitUntil(lambda: "now 49" in row.editor.toolTip(), timeout=5000)  # 7/16 of 112
    view = window.inputs_pane.views["texture"]
    window.inputs_pane.tabs.setCurrentIndex(0)
    view.actual_size()
    view.centerOn(40, 40)
    drag(view, (8.2, 8.2), (72.2, 72.2))
    assert doc.square == (8, 8, 64)
    qtbot.waitUntil(lambda: "now 28" in row.editor.toolTip(), timeout=5000)  # 7/16 of 64
    qtbot.mouseClick(row.auto, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: doc.current_params.block is not None, timeout=5000)
    assert doc.current_params.block == 28 and row.editor.value() == 28
    window.renderer.cancel()


def test_a_slider_runs_only_over_what_the_open_inputs_allow(window, qtbot, tmp_path):
    """Quilt's block on a 112x128 texture, "auto" unticked: the slider ends at 112 (the block must
    fit in the sample), its tooltip says so, and its far end renders (it said "outside 2..112")."""
    from weft.core.image import save_image

    doc = window.doc
    texture = tmp_path / "small.png"
    save_image(texture, np.random.default_rng(3).random((128, 112, 3), dtype=np.float32))
    doc.set_method("quilt")
    doc.clear_input("target")  # synthesis
    window.open_input("texture", str(texture))
    qtbot.waitUntil(
        lambda: doc.image("texture") is not None and doc.image("texture").shape[:2] == (128, 112), timeout=10000
    )
    qtbot.waitUntil(lambda: window.method_panel.params_panel.row("block").auto.isVisible(), timeout=5000)
    row = window.method_panel.params_panel.row("block")
    qtbot.mouseClick(row.auto, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: doc.current_params.block is not None, timeout=5000)
    assert row.editor.maximum() == 112
    assert "range 2..112 for these inputs" in row.toolTip() and "2..1024 in general" in row.toolTip()
    slider = row.editor.findChild(QSlider)  # the slider beside the value's label
    slider.setFocus()
    qtbot.keyClick(slider, Qt.Key.Key_End)  # the far end, as a user drags it there
    qtbot.waitUntil(lambda: doc.current_params.block == 112, timeout=5000)
    qtbot.waitUntil(
        lambda: (
            window.renderer.last.final
            and window.renderer.last.recipe.params.get("block") == 112
            and not window.renderer.running()
        ),
        timeout=60000,
    )
    assert not window.result_view.stale.isVisible()
    overlap = window.method_panel.params_panel.row("overlap")
    assert overlap.editor.maximum() == 111  # smaller than the block
