"""The examples window: shows every bundled example, loads off the GUI thread, survives bad files."""

import threading

import numpy as np
import pytest
from PySide6.QtCore import QEvent, QPoint, QPointF, Qt
from PySide6.QtGui import QMouseEvent, QWheelEvent
from PySide6.QtWidgets import QApplication

from app.gui.main_window import MainWindow
from core.examples import examples
from core.image import load_image


@pytest.fixture
def window(qtbot):
    w = MainWindow()
    qtbot.addWidget(w)
    w.show()
    yield w
    w.shutdown()


def test_opens_on_the_bundled_examples(window, qtbot):
    assert len(examples()) >= 5
    assert window.example_list.count() == len(examples())
    qtbot.waitUntil(lambda: window.view.image is not None, timeout=5000)
    assert window.current_path == examples()[0]
    assert window.view.image.shape[:2] == load_image(examples()[0]).image.shape[:2]


def test_clicking_an_example_shows_it(window, qtbot):
    qtbot.waitUntil(lambda: window.view.image is not None, timeout=5000)
    item = window.example_list.item(2)
    rect = window.example_list.visualItemRect(item)
    qtbot.mouseClick(window.example_list.viewport(), Qt.MouseButton.LeftButton, pos=rect.center())
    qtbot.waitUntil(lambda: window.current_path == examples()[2], timeout=5000)
    assert str(examples()[2].name) in window.statusBar().currentMessage()


def test_bad_file_keeps_the_previous_image(window, qtbot, tmp_path):
    qtbot.waitUntil(lambda: window.view.image is not None, timeout=5000)
    before = window.view.image
    bad = tmp_path / "broken.png"
    bad.write_text("not an image")
    window.open_path(bad)
    qtbot.waitUntil(lambda: "could not open" in window.statusBar().currentMessage(), timeout=5000)
    assert "broken.png" in window.statusBar().currentMessage()
    assert window.view.image is before


def test_hover_reports_pixel_coordinates_and_value(window, qtbot):
    qtbot.waitUntil(lambda: window.view.image is not None, timeout=5000)
    window.view.actual_size()
    window.view.zoom_by(4.0)  # a pixel spans 4 screen pixels: no rounding ambiguity
    view = window.view
    view.centerOn(10.5, 20.5)
    pos = view.mapFromScene(10.5, 20.5)
    move = QMouseEvent(QEvent.Type.MouseMove, QPointF(pos), QPointF(view.viewport().mapToGlobal(pos)),
                       Qt.MouseButton.NoButton, Qt.MouseButton.NoButton, Qt.KeyboardModifier.NoModifier)
    QApplication.sendEvent(view.viewport(), move)
    qtbot.waitUntil(lambda: window.pixel_label.text().startswith("x 10  y 20"), timeout=2000)
    v = view.image[20, 10]
    assert f"{float(np.ravel(v)[0]):.3f}" in window.pixel_label.text()


def test_wheel_zooms_under_the_mouse(window, qtbot):
    qtbot.waitUntil(lambda: window.view.image is not None, timeout=5000)
    view = window.view
    view.actual_size()
    view.zoom_by(4.0)  # larger than the viewport, so the view can scroll
    start = view.scale_factor()
    pos = view.mapFromScene(40.0, 30.0)
    event = QWheelEvent(QPointF(pos), QPointF(view.viewport().mapToGlobal(pos)), QPoint(0, 0), QPoint(0, 120),
                        Qt.MouseButton.NoButton, Qt.KeyboardModifier.NoModifier, Qt.ScrollPhase.NoScrollPhase, False)
    QApplication.sendEvent(view.viewport(), event)
    assert view.scale_factor() == pytest.approx(start * 1.25)
    # The image point under the cursor stays under the cursor.
    after = view.mapToScene(pos)
    assert abs(after.x() - 40.0) < 1.5 and abs(after.y() - 30.0) < 1.5


def test_no_worker_thread_left_after_shutdown(window, qtbot):
    qtbot.waitUntil(lambda: window.view.image is not None, timeout=5000)
    window.shutdown()
    assert not [t for t in threading.enumerate() if t.name.startswith("weft-job") and t.is_alive()]


def test_kernels_warm_up_in_the_background_without_error(window, qtbot):
    qtbot.waitUntil(lambda: not window.runner.busy("warm-up"), timeout=60000)
    job = window.runner.latest("warm-up")
    assert job.result(timeout=1).ok
