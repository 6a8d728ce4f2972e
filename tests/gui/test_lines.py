"""Feature lines in the studio (nfpt): draw, edit, delete, undo, quad preset, live rectification, files."""

import json

import pytest
from PySide6.QtCore import QEvent, Qt
from PySide6.QtGui import QKeyEvent
from PySide6.QtWidgets import QApplication
from weft.core.examples import RESOURCES
from weft.core.geometry import Square

from .helpers import drag, mouse


def _key(widget, key):
    QApplication.sendEvent(widget, QKeyEvent(QEvent.Type.KeyPress, key, Qt.KeyboardModifier.NoModifier))


def test_draw_edit_delete_lines_with_undo(nfpt):
    doc, photo, frontal = nfpt.doc, nfpt.inputs_pane.canvas_view, nfpt.inputs_pane.lines_panel.frontal_view
    photo.actual_size()
    photo.zoom_by(2.0)
    photo.centerOn(100, 100)
    drag(photo, (60.0, 80.0), (160.0, 90.0))
    assert len(doc.image_lines) == 1
    assert doc.image_lines[0] == pytest.approx([60, 80, 160, 90], abs=0.6)
    drag(frontal, (10.0, 10.0), (200.0, 10.0))
    assert len(doc.frontal_lines) == 1
    # Drag the photo line's second end point.
    drag(photo, (160.0, 90.0), (170.0, 120.0))
    assert doc.image_lines[0][2:] == pytest.approx([170, 120], abs=0.6)
    doc.undo_stack.undo()
    assert doc.image_lines[0][2:] == pytest.approx([160, 90], abs=0.6)
    doc.undo_stack.redo()
    # Click the line to select it, Delete removes the pair from both views.
    mouse(photo, "press", (110.0, 100.0))
    mouse(photo, "release", (110.0, 100.0))
    assert nfpt.inputs_pane.lines_panel.photo_lines.selected == 0
    _key(photo, Qt.Key.Key_Delete)
    assert doc.image_lines == [] and doc.frontal_lines == []
    doc.undo_stack.undo()
    assert len(doc.image_lines) == 1 and len(doc.frontal_lines) == 1


def test_escape_cancels_a_line_in_progress(nfpt):
    photo = nfpt.inputs_pane.canvas_view
    before = list(nfpt.doc.image_lines)
    mouse(photo, "press", (50.0, 50.0))
    mouse(photo, "move", (120.0, 60.0))
    _key(photo, Qt.Key.Key_Escape)
    mouse(photo, "release", (120.0, 60.0))
    assert nfpt.doc.image_lines == before


def test_quad_preset_and_live_rectification(nfpt, qtbot):
    data = json.loads((RESOURCES / "perspective-lines.json").read_text())
    corners = [line[:2] for line in data["image_lines"][:4]]  # the plane's corners, clockwise
    nfpt.inputs_pane.lines_panel.quad_button.setChecked(True)
    for x, y in corners:
        mouse(nfpt.inputs_pane.canvas_view, "press", (x, y))
        mouse(nfpt.inputs_pane.canvas_view, "release", (x, y))
    assert not nfpt.inputs_pane.lines_panel.quad_button.isChecked()
    doc = nfpt.doc
    assert len(doc.image_lines) == 4 and len(doc.frontal_lines) == 4
    w, h = doc.frontal_size
    assert doc.frontal_lines[1] == pytest.approx([w - 1, 0, w - 1, h - 1])
    qtbot.waitUntil(lambda: nfpt.inputs_pane.lines_panel.rectify_status.text() == "rectified", timeout=10000)
    assert nfpt.inputs_pane.lines_panel.frontal_view.image.shape[:2] == (h, w)
    # The render uses the lines: the recipe carries them as their JSON object (held typed until then).
    recipe = doc.recipe()
    assert recipe.params["lines"]["image_lines"] == doc.image_lines


def test_too_few_lines_say_why(nfpt, qtbot):
    doc = nfpt.doc
    doc.set_lines([[10, 10, 100, 12]], [[0, 0, 200, 0]])
    qtbot.waitUntil(lambda: nfpt.inputs_pane.lines_panel.rectify_status.text() not in ("", "rectified"), timeout=10000)
    assert "line" in nfpt.inputs_pane.lines_panel.rectify_status.text()


def test_lines_file_round_trip(nfpt, tmp_path):
    doc = nfpt.doc
    assert nfpt.inputs_pane.lines_panel.load_lines(str(RESOURCES / "perspective-lines.json"))
    assert len(doc.image_lines) == 6 and doc.frontal_size == (512, 384)
    out = tmp_path / "lines.json"
    assert nfpt.inputs_pane.lines_panel.save_lines(str(out))
    saved = json.loads(out.read_text())
    assert saved["image_lines"] == doc.image_lines and saved["frontal_size"] == [512, 384]
    bad = tmp_path / "bad.json"
    bad.write_text('{"image_lines": [[0, 0, 1]], "frontal_size": [10, 10]}')
    messages = []
    nfpt.message.connect(messages.append)
    assert not nfpt.inputs_pane.lines_panel.load_lines(str(bad))
    assert messages and "\n" not in messages[-1]


def test_affine_prototype_by_mouse_and_live_swap(window, qtbot):
    doc = window.doc
    doc.set_method("affine")
    doc.set_param("block", 16)
    view = window.inputs_pane.canvas_view
    view.actual_size()
    view.zoom_by(2.0)
    view.centerOn(50, 50)
    drag(view, (20.2, 24.2), (52.2, 40.2))
    assert doc.square == (20, 24, 32)
    assert doc.run_params().prototype == Square(20, 24, 32)
    qtbot.waitUntil(
        lambda: window.renderer.last.final and window.renderer.last.figures.get("prototype") == [20, 24, 32],
        timeout=30000,
    )
    # With reuse_transforms, moving the square re-renders while the mouse moves (previews).
    doc.set_param("reuse_transforms", True)
    qtbot.waitUntil(lambda: not window.renderer.runner.busy("final"), timeout=30000)
    shown = []
    window.renderer.shown.connect(lambda s: shown.append(s))
    mouse(view, "press", (30.0, 30.0))
    for x in range(31, 40):
        mouse(view, "move", (float(x), 30.0))
        qtbot.wait(30)
    qtbot.waitUntil(lambda: any(not s.final for s in shown), timeout=30000)
    mouse(view, "release", (40.0, 30.0))
    assert doc.square == (30, 24, 32)
    qtbot.waitUntil(lambda: shown[-1].final and shown[-1].figures.get("prototype") == [30, 24, 32], timeout=30000)


def _at_global(view, kind, global_pos, buttons=Qt.MouseButton.LeftButton):
    """A real mouse event at a fixed place on the screen, wherever the view has moved meanwhile."""
    from PySide6.QtCore import QPointF
    from PySide6.QtGui import QMouseEvent

    local = QPointF(view.viewport().mapFromGlobal(global_pos))
    etype = {
        "press": QEvent.Type.MouseButtonPress,
        "move": QEvent.Type.MouseMove,
        "release": QEvent.Type.MouseButtonRelease,
    }[kind]
    button = Qt.MouseButton.NoButton if kind == "move" else Qt.MouseButton.LeftButton
    held = buttons if kind != "release" else Qt.MouseButton.NoButton
    QApplication.sendEvent(
        view.viewport(), QMouseEvent(etype, local, QPointF(global_pos), button, held, Qt.KeyboardModifier.NoModifier)
    )


def test_the_frontal_frame_does_not_move_under_a_drag(nfpt, qtbot):
    """After Quad… and one pair deleted, the hint above the frontal frame says why it cannot rectify
    (two lines); drawing the 4th frontal line makes it rectify mid-drag. The frame must not move or
    zoom under the mouse: the line ends where the mouse went."""
    from PySide6.QtCore import QPointF
    from PySide6.QtWidgets import QGraphicsLineItem

    data = json.loads((RESOURCES / "perspective-lines.json").read_text())
    doc, panel = nfpt.doc, nfpt.inputs_pane.lines_panel
    nfpt.resize(1100, 760)
    panel.quad_button.setChecked(True)
    for x, y in [line[:2] for line in data["image_lines"][:4]]:
        mouse(nfpt.inputs_pane.canvas_view, "press", (x, y))
        mouse(nfpt.inputs_pane.canvas_view, "release", (x, y))
    image_lines, frontal_lines = [list(x) for x in doc.image_lines], [list(x) for x in doc.frontal_lines]
    doc.set_lines(image_lines[:3], frontal_lines[:3], text="Delete line 4")
    qtbot.waitUntil(lambda: "needs at least 4" in panel.rectify_status.text(), timeout=10000)
    doc.set_lines(image_lines, frontal_lines[:3], text="Draw line 4")  # the 4th line on the photo
    qtbot.wait(50)
    frontal = panel.frontal_view
    qtbot.waitUntil(lambda: not frontal.converting, timeout=5000)
    w, h = doc.frontal_size
    start, end = (0.3 * w, 0.2 * h), (0.3 * w, 0.8 * h)  # straight down
    to_global = lambda p: QPointF(frontal.viewport().mapToGlobal(frontal.mapFromScene(QPointF(*p))))  # noqa: E731
    g0, g1 = to_global(start), to_global(end)
    scale = frontal.scale_factor()
    _at_global(frontal, "press", g0)
    for i in range(1, 21):
        t = i / 20
        _at_global(frontal, "move", g0 + (g1 - g0) * t)
        qtbot.wait(15)  # (the live rectification comes back meanwhile and changes the hint)
        if i == 10:
            qtbot.waitUntil(lambda: panel.rectify_status.text() == "rectified", timeout=10000)
            qtbot.wait(50)
            # the new rectification redrew the frame's lines: the one being drawn is among them
            drawn = [it for it in panel.frontal_lines.items if isinstance(it, QGraphicsLineItem)]
            assert len(drawn) == 4
    assert frontal.scale_factor() == pytest.approx(scale)  # no zoom mid-drag ...
    assert frontal.mapToScene(frontal.viewport().mapFromGlobal(g1.toPoint())).y() == pytest.approx(end[1], abs=1.0)
    _at_global(frontal, "release", g1)
    assert len(doc.frontal_lines) == 4
    assert doc.frontal_lines[3] == pytest.approx([*start, *end], abs=1.0)


def test_quad_corners_move_together(nfpt, qtbot):
    """Dragging a corner of Quad…'s lines moves both lines that meet there (the quad stays closed),
    on the photo and in the frontal frame; Alt-drag moves one end alone."""
    from PySide6.QtCore import Qt as _Qt

    data = json.loads((RESOURCES / "perspective-lines.json").read_text())
    corners = [line[:2] for line in data["image_lines"][:4]]
    doc, panel = nfpt.doc, nfpt.inputs_pane.lines_panel
    panel.quad_button.setChecked(True)
    for x, y in corners:
        mouse(nfpt.inputs_pane.canvas_view, "press", (x, y))
        mouse(nfpt.inputs_pane.canvas_view, "release", (x, y))
    x, y = corners[1]  # the top-right corner: the end of line 1 and the start of line 2
    drag(nfpt.inputs_pane.canvas_view, (x, y), (x + 12, y + 9))
    assert doc.image_lines[0][2:] == pytest.approx([x + 12, y + 9], abs=0.6)
    assert doc.image_lines[1][:2] == pytest.approx([x + 12, y + 9], abs=0.6)
    assert doc.undo_stack.undoText().startswith("Move end")
    frontal = panel.frontal_view
    qtbot.waitUntil(lambda: frontal.image is not None and not frontal.converting, timeout=10000)
    w, h = doc.frontal_size
    corner = (w - 1.0, h - 1.0)  # lines 2 and 3 meet there
    drag(frontal, corner, (w - 40.0, h - 30.0))
    assert doc.frontal_lines[1][2:] == pytest.approx([w - 40, h - 30], abs=1.0)
    assert doc.frontal_lines[2][:2] == pytest.approx([w - 40, h - 30], abs=1.0)
    before = [list(v) for v in doc.image_lines]
    x, y = before[2][:2]
    mouse(nfpt.inputs_pane.canvas_view, "press", (x, y), key_modifiers=_Qt.KeyboardModifier.AltModifier)
    mouse(nfpt.inputs_pane.canvas_view, "move", (x - 10, y), key_modifiers=_Qt.KeyboardModifier.AltModifier)
    mouse(nfpt.inputs_pane.canvas_view, "release", (x - 10, y), key_modifiers=_Qt.KeyboardModifier.AltModifier)
    moved = [doc.image_lines[2][:2], doc.image_lines[1][2:]]  # the two ends that met there
    assert sorted(abs(m[0] - (x - 10)) < 0.6 for m in moved) == [False, True]  # Alt: one alone
    assert before[2][:2] in moved or before[1][2:] in moved


def test_nfpt_without_lines_shows_the_photo_and_says_what_to_draw(window, qtbot):
    """Switching to nfpt on the perspective photo with no lines renders nothing (it rendered a
    collage of sky strips and bricks): the result view shows the photo and says to draw feature
    lines or use Quad…; four Quad clicks then render."""
    submitted = []
    window.renderer.submitted.connect(lambda job_id, slot: submitted.append(slot))
    window.doc.set_method("nfpt")
    assert window.doc.value("lines") is None
    view = window.result_view
    qtbot.waitUntil(lambda: view.notice.isVisible() and "feature lines" in view.notice.text(), timeout=10000)
    assert "Quad" in view.notice.text()
    qtbot.waitUntil(lambda: view.image is window.doc.image("photo"), timeout=5000)
    assert submitted == [] and not window.renderer.running()
    assert window.nothing_to_export().startswith("nothing to export: draw feature lines")
    data = json.loads((RESOURCES / "perspective-lines.json").read_text())
    window.doc.set_param("size", (128, 96))
    window.inputs_pane.lines_panel.quad_button.setChecked(True)
    for x, y in [line[:2] for line in data["image_lines"][:4]]:
        mouse(window.inputs_pane.canvas_view, "press", (x, y))
        mouse(window.inputs_pane.canvas_view, "release", (x, y))
    qtbot.waitUntil(lambda: window.renderer.last.final and window.renderer.last.recipe.method == "nfpt", timeout=60000)
    assert not view.notice.isVisible() and window.nothing_to_export() is None
