"""The studio's layout: figures in words, a status line that never runs into the pixel read-out,
tab titles that fit, the square typed, a usable result view in a small window."""

import json
import re

import pytest
from PySide6.QtCore import QRect, Qt
from weft.core import registry
from weft.core.examples import RESOURCES
from weft.core.geometry import MASK, Mask

from .helpers import drag, mouse

SNAKE = re.compile(r"\b[a-z0-9]+(?:_[a-z0-9]+)+\b")


def _window(make_window, qtbot, size):
    w = make_window(load_defaults=True, size=size)
    qtbot.waitExposed(w)
    qtbot.waitUntil(lambda: w.renderer.last is not None and w.renderer.last.final, timeout=20000)
    return w


def _final_of(window, method):
    last = window.renderer.last
    return last is not None and last.final and last.recipe is not None and last.recipe.method == method


@pytest.mark.parametrize("method", list(registry.studio_methods()))
def test_the_status_line_gives_a_results_figures_in_words_and_units(window, qtbot, method):
    if method != window.doc.method:
        window.doc.set_method(method)
    if method == "nfpt":  # with feature lines, so the rectification's figures are there too
        data = json.loads((RESOURCES / "perspective-lines.json").read_text())
        window.doc.set_lines(data["image_lines"], data["frontal_lines"], frontal_size=data["frontal_size"])
        window.doc.set_param("size", (256, 192))
    if any(g.kind == MASK for g in window.doc.studio.geometry):  # fill: a painted hole, so it has work to do
        g = next(g for g in window.doc.studio.geometry if g.kind == MASK)
        h, w = window.doc.image(g.input_for(window.doc.inputs)).shape[:2]
        window.doc.set_mask(g.key, Mask.empty(w, h).painted_line((w / 3, h / 2), (w / 2, h / 2), 6), "Brush stroke")
    qtbot.waitUntil(lambda: _final_of(window, method) and not window.renderer.running(), timeout=60000)
    shown = window.renderer.last
    text = window.status.result_label.full_text()
    assert text.startswith("result ") and " — " in text
    assert not SNAKE.findall(text), text
    assert not [k for k in shown.figures if "_" in k and k in text], text
    words = registry.get(method).studio.describe(shown.figures)
    assert words and text.endswith(", ".join(words))
    if method == "nfpt":
        assert re.search(r"rectification error [0-9.e-]+ px", text), text
    if method == "fast":
        assert re.search(r"coherent pixels \d+(\.\d+)? %", text), text


def test_the_status_text_never_runs_into_the_pixel_read_out(qtbot, make_window):
    w = _window(make_window, qtbot, (760, 560))
    long = "result 1500x1000 in 4321 ms — " + ", ".join(f"rectification figure {i} 0.123 px" for i in range(30))
    w.statusBar().showMessage(long)
    view = w.result_view
    view.actual_size()
    view.centerOn(10.5, 12.5)
    mouse(view, "move", (10.5, 12.5), buttons=Qt.MouseButton.NoButton)
    assert re.match(r"result  x \d+  y \d+  [0-9.]+ ", w.status.pixel_label.text()), w.status.pixel_label.text()
    status, pixel, zoom = w.status.status_label, w.status.pixel_label, w.status.zoom_label
    assert status.isVisible() and pixel.isVisible()
    assert not status.geometry().intersects(pixel.geometry())
    assert not status.geometry().intersects(zoom.geometry())
    # the message shown is cut to its room (with an ellipsis); the whole of it is the tooltip
    assert status.text() != long and status.text().endswith("…")
    assert status.fontMetrics().horizontalAdvance(status.text()) <= status.contentsRect().width()
    assert status.toolTip() == long
    assert pixel.fontMetrics().horizontalAdvance(pixel.text()) <= pixel.contentsRect().width()
    # a short message is shown whole, even beside long result figures (those give way)
    w.status.result_label.set_full_text(long)
    w.statusBar().showMessage("cancelled; the previous result is kept")
    qtbot.waitUntil(lambda: status.text() == "cancelled; the previous result is kept", timeout=2000)
    assert not status.geometry().intersects(pixel.geometry())
    w.shutdown()


@pytest.mark.parametrize("size", [(1280, 800), (1024, 700)])
def test_tab_titles_are_not_clipped(qtbot, make_window, size):
    w = _window(make_window, qtbot, size)
    for method in registry.studio_methods():
        w.doc.set_method(method)
        qtbot.waitUntil(lambda m=method: w.doc.method == m, timeout=5000)
        bar = w.inputs_pane.tabs.tabBar()
        if not w.inputs_pane.tabs.isVisible():
            continue
        qtbot.waitUntil(lambda b=bar: b.width() > 0, timeout=5000)
        for i in range(bar.count()):
            rect = bar.tabRect(i)
            text = bar.tabText(i)
            assert bar.rect().contains(rect), (method, text, rect, bar.rect())  # not scrolled out of sight
            assert bar.fontMetrics().horizontalAdvance(text) < rect.width(), (method, text, rect)
            assert bar.tabToolTip(i)
    w.shutdown()


def test_the_result_view_keeps_a_usable_share_of_a_1024x700_window(qtbot, make_window):
    w = _window(make_window, qtbot, (1024, 700))
    for method in registry.studio_methods():
        w.doc.set_method(method)
        qtbot.waitUntil(lambda: w.result_view.width() >= 350, timeout=5000)
        assert w.result_view.height() >= 350
    # the Examples panel is a tab behind the Method panel, a click away
    assert w.tabifiedDockWidgets(w.method_dock) == [w.examples_dock]
    assert not w.method_dock.visibleRegion().isEmpty()
    # made wide, Examples goes back to the left; made narrow again, the result keeps its share
    w.resize(1400, 800)
    qtbot.waitUntil(lambda: w.dockWidgetArea(w.examples_dock) == Qt.DockWidgetArea.LeftDockWidgetArea, timeout=5000)
    w.resize(1024, 700)
    qtbot.waitUntil(lambda: w.result_view.width() >= 350, timeout=5000)
    w.shutdown()


def _widgets_over_the_examples_title(w):
    """Visible widgets of the window, not the Examples dock's own, that overlap its title bar."""
    from PySide6.QtCore import QPoint
    from PySide6.QtWidgets import QWidget

    dock = w.examples_dock
    top_left = dock.mapTo(w, QPoint(0, 0))
    title = QRect(top_left.x(), top_left.y(), dock.width(), dock.widget().geometry().top())
    assert title.height() > 0
    over = []
    for child in w.findChildren(QWidget):
        if (
            not child.isVisible()
            or child.isWindow()
            or child is dock
            or child.isAncestorOf(dock)
            or dock.isAncestorOf(child)
        ):
            continue
        if QRect(child.mapTo(w, QPoint(0, 0)), child.size()).intersects(title):
            over.append(child)
    return over


def test_no_widget_is_painted_over_the_examples_dock_title(qtbot, make_window):
    """Seen under Xvfb: a view made for an input no method had shown yet (parented to the window and
    never laid out) was painted over the Examples title; every input's view now lives in its pane."""
    w = _window(make_window, qtbot, (1280, 800))
    assert not _widgets_over_the_examples_title(w)
    for method in registry.studio_methods():
        w.doc.set_method(method)
        qtbot.waitUntil(lambda m=method: w.doc.method == m, timeout=5000)
        assert not _widgets_over_the_examples_title(w), method
    from weft.app.gui.views import ImageView

    stray = ImageView(w)  # the old way a view was made: the check sees it
    stray.show()
    assert stray in _widgets_over_the_examples_title(w)
    stray.deleteLater()
    w.shutdown()


def test_the_square_can_be_typed_and_the_edit_undone(window, qtbot):
    panel = window.method_panel
    x_box, y_box, side_box = panel.square_boxes
    assert panel.square_row.isVisible()
    drag(window.inputs_pane.canvas_view, (20, 20), (60, 60))
    qtbot.waitUntil(lambda: window.doc.square is not None, timeout=5000)
    before = window.doc.square
    assert (x_box.value(), y_box.value(), side_box.value()) == tuple(before)
    for box, text in ((x_box, "30"), (side_box, "24")):
        box.lineEdit().selectAll()
        qtbot.keyClicks(box.lineEdit(), text)
        qtbot.keyClick(box.lineEdit(), Qt.Key.Key_Return)
    assert tuple(window.doc.square) == (30, before[1], 24)
    assert window.menus.undo_action.text().endswith("Square")
    qtbot.keyClick(window, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)  # the side's edit
    qtbot.keyClick(window, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)  # the corner's
    assert window.doc.square == before
    assert (x_box.value(), y_box.value(), side_box.value()) == tuple(before)
    # a square that leaves the image is refused with the CLI's words, and the boxes go back
    w = window.doc.image(window.doc.studio.canvas).shape[1]
    messages = []
    window.message.connect(messages.append)
    x_box.lineEdit().selectAll()
    qtbot.keyClicks(x_box.lineEdit(), str(w - 4))
    qtbot.keyClick(x_box.lineEdit(), Qt.Key.Key_Return)
    assert window.doc.square == before
    assert messages and messages[-1].startswith(
        f"parameter 'region' = {w - 4},{before[1]},{before[2]} leaves the texture"
    )
    assert x_box.value() == before[0]


def test_a_square_can_be_typed_when_none_is_drawn(window, qtbot):
    panel = window.method_panel
    x_box, y_box, side_box = panel.square_boxes
    assert window.doc.square is None
    assert [b.text() for b in panel.square_boxes] == ["–", "–", "–"]  # blank: nothing drawn
    side_box.lineEdit().selectAll()
    qtbot.keyClicks(side_box.lineEdit(), "40")
    qtbot.keyClick(side_box.lineEdit(), Qt.Key.Key_Return)
    assert tuple(window.doc.square) == (0, 0, 40)  # at the corner
    assert [b.text() for b in panel.square_boxes] == ["0", "0", "40"]
    qtbot.keyClick(window, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert window.doc.square is None and side_box.text() == "–"


def test_quads_prompt_is_not_cut_off_in_a_narrow_pane(qtbot, make_window):
    w = _window(make_window, qtbot, (1024, 700))
    w.doc.set_method("nfpt")
    qtbot.waitUntil(lambda: w.inputs_pane.lines_panel is not None and w.inputs_pane.lines_panel.active, timeout=5000)
    panel = w.inputs_pane.lines_panel
    w.inputs_pane.tabs.setCurrentWidget(panel)
    qtbot.mouseClick(panel.quad_button, Qt.MouseButton.LeftButton)
    status = panel.rectify_status
    qtbot.waitUntil(lambda: status.isVisible() and "top-left corner" in status.text(), timeout=5000)

    # every word is inside the label (it wraps) and the label inside the panel
    def fits():
        room = status.contentsRect()
        need = status.fontMetrics().boundingRect(
            QRect(0, 0, room.width(), 10**4), Qt.TextFlag.TextWordWrap, status.text()
        )
        return need.width() <= room.width() and need.height() <= room.height()

    qtbot.waitUntil(fits, timeout=5000)
    assert panel.rect().contains(status.geometry())
    w.shutdown()
