"""The studio as a user drives it: real mouse events, sliders, undo, cancel, errors, sessions, export."""

import dataclasses
import json
import re
import threading

import numpy as np
import pytest
from PySide6.QtCore import QMimeData, QPoint, QPointF, Qt, QUrl
from PySide6.QtGui import QDragEnterEvent, QDropEvent, QWheelEvent
from PySide6.QtWidgets import QApplication, QSlider
from weft.app.cli import main as cli_main
from weft.core.errors import Cancelled, WeftError
from weft.core.examples import example
from weft.core.image import load_image, read_recipe
from weft.core.registry import Method

from .helpers import drag, mouse, no_job_threads, settle


def test_opens_on_the_examples_with_a_result(window):
    assert window.doc.method == "fast"
    assert set(window.doc.inputs) >= {"texture", "target"}
    shown = window.renderer.last
    assert shown.final and shown.image.shape == window.doc.image("target").shape
    assert window.result_view.image is shown.image
    assert window.example_list.count() >= 10
    assert "result" in window.status.result_label.full_text()


@pytest.mark.parametrize("zoom", [2.0, 0.5])
def test_drawing_a_prototype_sets_the_rectangle_in_image_pixels(window, qtbot, zoom):
    view = window.inputs_pane.canvas_view
    view.actual_size()
    view.zoom_by(zoom)
    view.centerOn(40, 40)
    drag(view, (10.2, 20.2), (50.2, 44.2))
    assert window.doc.square == (10, 20, 40)  # side = larger extent, even
    # Move it by dragging inside, then resize from the bottom-right handle.
    drag(view, (30, 40), (36, 42))
    assert window.doc.square == (16, 22, 40)
    drag(view, (56, 62), (46.5, 50))
    assert window.doc.square == (16, 22, 30)
    window.doc.undo_stack.undo()
    assert window.doc.square == (16, 22, 40)
    window.doc.undo_stack.redo()
    assert window.doc.square == (16, 22, 30)


def test_escape_cancels_a_prototype_drag(window):
    view = window.inputs_pane.canvas_view
    window.doc.set_square((4, 4, 20))
    mouse(view, "press", (60, 60))
    mouse(view, "move", (90, 90))
    assert window.inputs_pane.canvas_view.tool.live is not None
    from PySide6.QtCore import QEvent
    from PySide6.QtGui import QKeyEvent

    QApplication.sendEvent(view, QKeyEvent(QEvent.Type.KeyPress, Qt.Key.Key_Escape, Qt.KeyboardModifier.NoModifier))
    mouse(view, "release", (90, 90))
    assert window.doc.square == (4, 4, 20)


def test_the_prototype_is_the_source_region_of_fast_and_is_in_the_recipe(window, qtbot, tmp_path):
    before = window.renderer.last.job_id
    window.doc.set_square((10, 10, 40))
    qtbot.waitUntil(lambda: window.renderer.last.job_id > before and window.renderer.last.final, timeout=10000)
    out = tmp_path / "r.png"
    assert window.files.export_result(str(out))
    assert json.loads(read_recipe(out))["region"] == [10, 10, 40]
    again = tmp_path / "again.png"
    assert cli_main(["run", str(out), "-o", str(again)]) == 0
    assert np.array_equal(load_image(out).image, load_image(again).image)


def test_slider_drag_previews_then_renders_full_size(window, qtbot):
    row = window.method_panel.params_panel.row("n")
    slider = row.editor
    shown = []
    window.renderer.shown.connect(lambda s: shown.append(s))
    slider.setSliderDown(True)
    for v in (7, 9, 11):
        slider.setValue(v)
    qtbot.waitUntil(lambda: any(not s.final for s in shown), timeout=10000)
    slider.setSliderDown(False)
    slider.sliderReleased.emit()
    qtbot.waitUntil(lambda: shown and shown[-1].final and window.doc.current_params.n == 11, timeout=10000)
    settle(qtbot, window)  # every result still on its way has arrived
    ids = [s.job_id for s in shown]
    assert ids == sorted(ids)  # never an older result over a newer one
    assert window.result_view.image is window.renderer.last.image
    # The drag is one undo step.
    window.doc.undo_stack.undo()
    assert window.doc.current_params.n == 5


def test_stale_results_are_dropped(window, qtbot):
    r = window.renderer
    shown = []
    r.shown.connect(lambda s: shown.append(s.job_id))
    for p in (0.1, 0.2, 0.3, 0.4, 0.5):
        window.doc.set_param("p", p)
        r.final(now=True)
    settle(qtbot, window)  # every result still on its way has arrived
    assert shown and shown == sorted(shown)
    assert r.last.job_id == r.latest_final


def _slow_method(started: threading.Event) -> Method:
    """A stand-in for ``fast`` that runs until it is cancelled."""
    from weft.core.fast import METHOD

    def run(inputs, params, *, rng=None, progress=None, cancel=None):
        started.set()
        while True:
            cancel.raise_if_cancelled()
            threading.Event().wait(0.01)

    return dataclasses.replace(METHOD, summary="slow stand-in", run=run)


def test_cancel_keeps_the_previous_result(window, qtbot, monkeypatch):
    previous = window.renderer.last
    started = threading.Event()
    monkeypatch.setitem(window.doc.methods, "fast", _slow_method(started))
    window.renderer.final(now=True)
    qtbot.waitUntil(started.is_set, timeout=5000)
    qtbot.waitUntil(window.status.cancel_button.isVisible, timeout=5000)  # long job: progress + Cancel shown
    window.status.cancel_button.click()
    qtbot.waitUntil(lambda: not window.renderer.runner.busy("final"), timeout=5000)
    assert window.renderer.last is previous
    assert window.result_view.image is previous.image
    assert not window.status.cancel_button.isVisible()


def test_an_error_in_a_job_shows_a_message_and_the_app_goes_on(window, qtbot, monkeypatch):
    previous = window.renderer.last
    real = window.doc.methods["fast"]

    def boom(inputs, params, *, rng=None, progress=None, cancel=None):
        raise WeftError("texture.png: something is wrong with it")

    monkeypatch.setitem(window.doc.methods, "fast", dataclasses.replace(real, summary="broken", run=boom))
    messages = []
    window.message.connect(messages.append)
    window.renderer.final(now=True)
    qtbot.waitUntil(lambda: bool(messages), timeout=5000)
    assert "something is wrong" in messages[-1]
    assert window.result_view.image is previous.image
    monkeypatch.setitem(window.doc.methods, "fast", real)
    window.renderer.final(now=True)
    qtbot.waitUntil(lambda: window.renderer.last is not previous, timeout=10000)


def test_invalid_value_is_refused_with_a_message(window):
    """quilt's Poisson blend needs overlapping blocks: ticked with random blocks, it is refused with
    a message and the box shows the value kept."""
    messages = []
    window.message.connect(messages.append)
    window.doc.set_method("quilt")
    window.doc.set_param("mode", "random")
    window.method_panel.params_panel.row("poisson").editor.setChecked(True)
    assert window.doc.current_params.poisson is False
    assert "needs mode overlap or mincut" in messages[-1]
    assert window.method_panel.params_panel.row("poisson").value() is False


def test_an_odd_only_slider_steps_through_odd_values(window, qtbot):
    """fast's n must be odd: the keyboard steps 5 -> 7 -> 5, and a drag or a typed value between two
    odd values lands on the next one the way it moved, without an error."""
    messages = []
    window.message.connect(messages.append)
    row = window.method_panel.params_panel.row("n")
    slider = row.editor.findChild(QSlider)
    slider.setFocus()
    qtbot.keyClick(slider, Qt.Key.Key_Right)
    assert window.doc.current_params.n == 7
    qtbot.keyClick(slider, Qt.Key.Key_Left)
    assert window.doc.current_params.n == 5
    row.editor.setValue(6)  # between 5 and 7, moving up
    assert window.doc.current_params.n == 7 and row.value() == 7
    row.editor.setValue(4)  # moving down
    assert window.doc.current_params.n == 3 and row.value() == 3
    assert not any("odd" in m for m in messages), messages


def test_undo_redo_parameters_and_method(window):
    doc = window.doc
    doc.set_param("w", 2.0)
    doc.set_param("w", 3.0)  # merges with the previous change of w
    doc.set_param("iterations", 2)
    doc.set_method("quilt")
    assert window.method_panel.params_panel.params_cls is doc.methods["quilt"].params
    doc.undo_stack.undo()
    assert doc.method == "fast" and window.method_panel.params_panel.params_cls is doc.methods["fast"].params
    doc.undo_stack.undo()
    assert doc.current_params.iterations == 1
    doc.undo_stack.undo()
    assert doc.current_params.w == 1.0
    doc.undo_stack.redo()
    assert doc.current_params.w == 3.0
    assert window.method_panel.params_panel.row("w").value() == 3.0


def test_dropping_a_file_on_the_target_view_opens_it(window, qtbot):
    view = window.inputs_pane.views["target"]
    path = str(example("camera"))
    data = QMimeData()
    data.setUrls([QUrl.fromLocalFile(path)])
    enter = QDragEnterEvent(
        QPoint(10, 10), Qt.DropAction.CopyAction, data, Qt.MouseButton.NoButton, Qt.KeyboardModifier.NoModifier
    )
    assert QApplication.sendEvent(view.viewport(), enter) and enter.isAccepted()
    drop = QDropEvent(
        QPointF(10, 10), Qt.DropAction.CopyAction, data, Qt.MouseButton.NoButton, Qt.KeyboardModifier.NoModifier
    )
    QApplication.sendEvent(view.viewport(), drop)
    qtbot.waitUntil(lambda: window.doc.inputs["target"].path == path, timeout=5000)
    assert window.doc.image("target").shape == (256, 256)
    window.doc.undo_stack.undo()
    assert window.doc.inputs["target"].path != path


def test_opening_a_corrupt_file_keeps_the_document(window, qtbot, tmp_path):
    bad = tmp_path / "broken.png"
    bad.write_text("not an image")
    before = window.doc.inputs["texture"]
    messages = []
    window.message.connect(messages.append)
    window.open_input("texture", str(bad))
    qtbot.waitUntil(lambda: bool(messages), timeout=5000)
    assert "broken.png" in messages[-1]
    assert window.doc.inputs["texture"] is before


def test_session_round_trip(window, qtbot, tmp_path):
    doc = window.doc
    doc.set_param("p", 0.3)
    doc.set_square((2, 4, 16))
    window.method_panel.seed_box.setValue(42)
    path = tmp_path / "s.weft.json"
    assert window.files.save_session(str(path))
    data = json.loads(path.read_text())
    assert (
        data["params"]["fast"]["p"] == 0.3
        and data["seed"] == 42
        and data["geometry"] == {"fast": {"region": [2, 4, 16]}}
    )
    doc.set_param("p", 0.9)
    doc.set_square(None)
    window.method_panel.seed_box.setValue(1)
    assert window.files.open_session(str(path))
    assert doc.current_params.p == 0.3 and doc.square == (2, 4, 16) and doc.seed == 42
    assert window.method_panel.seed_box.value() == 42 and window.method_panel.params_panel.row("p").value() == 0.3
    bad = tmp_path / "bad.json"
    bad.write_text("{")
    messages = []
    window.message.connect(messages.append)
    assert not window.files.open_session(str(bad))
    assert "not a weft session" in messages[-1]


def test_export_png_jpeg_tiff_and_weft_run_reproduces_bit_for_bit(window, qtbot, tmp_path):
    png = tmp_path / "out.png"
    assert window.files.export_result(str(png))
    recipe = json.loads(read_recipe(png))
    assert recipe["method"] == "fast" and recipe["seed"] == window.doc.seed
    again = tmp_path / "again.png"
    assert cli_main(["run", str(png), "-o", str(again)]) == 0
    assert np.array_equal(load_image(png).image, load_image(again).image)
    tif = tmp_path / "out.tif"
    assert window.files.export_result(str(tif))
    assert load_image(tif).info.bit_depth == 16
    jpg = tmp_path / "out.jpg"
    assert window.files.export_result(str(jpg))
    assert load_image(jpg).image.shape == window.renderer.last.image.shape


def test_compare_split_and_wheel_zoom_on_the_result(window):
    view = window.result_view
    window.method_panel.compare_button.click()
    assert view.comparing and view._clip.isVisible()
    view.actual_size()
    mouse(view, "press", (64, 10))
    mouse(view, "release", (64, 10))
    assert view.split == pytest.approx(64 / view.image.shape[1], abs=0.02)
    view.zoom_by(4.0)
    start = view.scale_factor()
    pos = view.mapFromScene(40.0, 30.0)
    wheel = QWheelEvent(
        QPointF(pos),
        QPointF(view.viewport().mapToGlobal(pos)),
        QPoint(0, 0),
        QPoint(0, 120),
        Qt.MouseButton.NoButton,
        Qt.KeyboardModifier.NoModifier,
        Qt.ScrollPhase.NoScrollPhase,
        False,
    )
    QApplication.sendEvent(view.viewport(), wheel)
    assert view.scale_factor() == pytest.approx(start * 1.25)
    after = view.mapToScene(pos)
    assert abs(after.x() - 40.0) < 1.5 and abs(after.y() - 30.0) < 1.5


def test_hover_shows_pixel_coordinates_and_value(window):
    view = window.result_view
    view.actual_size()
    view.zoom_by(4.0)
    view.centerOn(10.5, 20.5)
    mouse(view, "move", (10.5, 20.5), buttons=Qt.MouseButton.NoButton)
    assert window.status.pixel_label.text().startswith("result  x 10  y 20")


def test_variations_grid_renders_and_adopts_a_cell(window, qtbot):
    window.open_variations()
    dialog = window.variations
    dialog.combo[0].setCurrentText("p")
    dialog.combo[1].setCurrentText("target_weight")
    dialog.lo[0].setValue(0.0)
    dialog.hi[0].setValue(0.5)
    dialog.lo[1].setValue(0.0)
    dialog.hi[1].setValue(4.0)
    done = set()
    dialog.cell_done.connect(lambda i, j: done.add((i, j)))
    dialog.render_grid()
    qtbot.waitUntil(lambda: len(done) == 9, timeout=30000)
    assert all(not b.icon().isNull() for b in dialog.cells.values())
    steps = window.doc.undo_stack.count()
    dialog.cells[(2, 1)].click()
    assert window.doc.current_params.p == 0.5 and window.doc.current_params.target_weight == 2.0
    assert window.doc.undo_stack.count() == steps + 1
    dialog.close()


def test_no_worker_thread_left_after_close(qtbot, settings):
    from weft.app.gui.main_window import MainWindow

    w = MainWindow(settings=settings)
    qtbot.addWidget(w)
    w.show()
    qtbot.waitUntil(lambda: w.renderer.last is not None, timeout=20000)
    w.close()
    assert no_job_threads()


def test_a_file_still_opening_when_its_window_is_deleted_tells_nobody_and_logs_nothing(
    qtbot, settings, tmp_path, monkeypatch, caplog
):
    """The decode of File > Open outlives the window it was for: its result reaches no deleted object,
    and no error is logged."""
    import shiboken6
    import weft.app.gui.main_window as main_window
    from weft.app.gui.main_window import MainWindow

    started, release = threading.Event(), threading.Event()
    real = main_window.read_input

    def held(path):
        started.set()
        assert release.wait(10)
        return real(path)

    monkeypatch.setattr(main_window, "read_input", held)
    w = MainWindow(settings=settings, load_defaults=False)
    w.renderer.shutdown()
    w.files.shutdown()
    w.inputs_pane.shutdown()
    loader = w.loader.runner
    w.open_input("texture", str(example("wood-grain")))
    assert started.wait(10)
    shiboken6.delete(w)  # (the window and its parts are gone; the decode goes on)
    release.set()
    job = loader.latest("open-texture")
    assert job is not None and job.result(timeout=10).value is not None
    loader.shutdown()
    assert "callback failed" not in caplog.text


def test_slow_stand_in_is_cancellable_directly():
    """The stand-in used above really blocks until cancelled (so the cancel test means something)."""
    from weft.core.jobs import CancelToken

    started, token = threading.Event(), CancelToken()
    method = _slow_method(started)
    t = threading.Thread(target=lambda: pytest.raises(Cancelled, method.run, {}, None, cancel=token))
    t.start()
    assert started.wait(5)
    assert t.is_alive()
    token.cancel()
    t.join(5)
    assert not t.is_alive()


def test_result_figures_stay_while_a_menu_shows_status_tips(window, qtbot):
    """Hovering a menu entry shows its status tip and closing the menu clears the status message:
    the shown result's figures stay on the status line all along."""
    from PySide6.QtCore import Qt
    from PySide6.QtTest import QTest
    from PySide6.QtWidgets import QLabel

    def figures_shown() -> bool:
        return any(
            label.isVisible() and re.match(r"result \d+x\d+ in \d+ ms", label.text())
            for label in window.statusBar().findChildren(QLabel)
        )

    assert figures_shown()
    menu = window.menus.view_menu
    action = window.menus.reset_layout_action  # (has a status tip)
    menu.popup(window.mapToGlobal(window.rect().center()))
    qtbot.waitUntil(menu.isVisible, timeout=5000)
    QTest.mouseMove(menu, menu.actionGeometry(action).center())
    qtbot.waitUntil(lambda: window.statusBar().currentMessage() == action.statusTip(), timeout=5000)
    assert figures_shown()
    QTest.keyClick(menu, Qt.Key.Key_Escape)
    qtbot.waitUntil(lambda: not menu.isVisible(), timeout=5000)
    qtbot.waitUntil(lambda: window.statusBar().currentMessage() == "", timeout=5000)
    assert figures_shown()


def test_progress_text_fits_the_bar(window, qtbot):
    """A long stage with the time left still reads whole in the bar (shortened to what fits; the
    whole text in its tooltip), at the default size and in a narrow window."""
    now = [1000.0]
    window.status.clock = lambda: now[0]
    for width in (1280, 1024):
        window.resize(width, 760)
        window.status.progress_bar.show()
        qtbot.wait(10)
        window.status.show_progress(0.05, "nfpt synthesis")
        now[0] += 10  # 10 s of work so far: the time left is known
        window.status.show_progress(0.63, "nfpt synthesis")
        bar = window.status.progress_bar
        assert bar.value() == 630
        text = bar.text()
        assert "63%" in text
        assert bar.fontMetrics().horizontalAdvance(text) <= bar.contentsRect().width(), (width, text)
        assert "about 6 s left" in bar.toolTip()
    window.status.progress_bar.hide()


def test_the_file_menu_keeps_its_entries_in_place_for_every_method(window, qtbot):
    """A habitual click lands on the same entry whatever the method (it landed on Quit)."""
    from weft.core import registry

    layouts = {}
    for name in registry.studio_methods():
        window.doc.set_method(name)
        menu = window.menus.file_menu
        menu.popup(window.mapToGlobal(window.rect().center()))
        qtbot.waitUntil(menu.isVisible, timeout=5000)
        quit_action = next(a for a in menu.actions() if a.text() == "&Quit")
        layouts[name] = (len([a for a in menu.actions() if a.isVisible()]), menu.actionGeometry(quit_action).top())
        menu.hide()
    assert len(set(layouts.values())) == 1, layouts


def test_each_choice_from_a_list_is_its_own_undo_step(window, qtbot):
    """Four picks in a parameter's combo box are four undo steps (they merged into one); a slider's
    moves still merge."""
    from PySide6.QtCore import Qt

    doc = window.doc
    combo = window.method_panel.params_panel.row("metric").editor
    before = doc.undo_stack.count()
    combo.setFocus()
    picked = []
    for key in (Qt.Key.Key_Down, Qt.Key.Key_Down, Qt.Key.Key_Up, Qt.Key.Key_Up):
        qtbot.keyClick(combo, key)
        picked.append(doc.current_params.metric)
    assert picked == ["target", "artistic", "target", "full"]
    assert doc.undo_stack.count() == before + 4
    doc.undo_stack.undo()
    assert doc.current_params.metric == "target"
    slider = window.method_panel.params_panel.row("iterations").editor.findChild(QSlider)
    slider.setFocus()
    steps = doc.undo_stack.index()
    for _ in range(2):
        qtbot.keyClick(slider, Qt.Key.Key_Right)
    assert doc.current_params.iterations == 3 and doc.undo_stack.index() == steps + 1
