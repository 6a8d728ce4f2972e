"""The sampling brush, as Content-Aware Fill has it: on fill's picture the brush paints either the
hole or the sampling area (fill's ``source_mask`` input, the same as ``--source-mask`` on the command
line), switched on the bar over the picture. Real mouse events on the view's viewport, the real fill.

The picture has three flat-ish regions of distinct colour (left: red, top right: blue, bottom right:
green) so that where a fill copied from shows in its pixels.
"""

import json
from contextlib import contextmanager

import numpy as np
import pytest
from PySide6.QtCore import Qt
from weft.app.cli import main as weft
from weft.core.geometry import Mask
from weft.core.image import load_image, read_recipe, save_image

from .helpers import mouse

W, H = 96, 72
RED, BLUE, GREEN = (0.8, 0.2, 0.1), (0.1, 0.3, 0.8), (0.1, 0.8, 0.2)
HOLE = [(18.5, 30.5), (26.5, 38.5)]  # a short diagonal stroke in the red half
BOTTOM_RIGHT = [(62.5, 56.5), (86.5, 56.5)]  # with a 25 px brush: rows 44..68 of the green region


def _picture(path):
    rng = np.random.default_rng(5)
    pixels = np.empty((H, W, 3), np.float32)
    pixels[:, : W // 2] = RED
    pixels[: H // 2, W // 2 :] = BLUE
    pixels[H // 2 :, W // 2 :] = GREEN
    pixels += rng.uniform(-0.05, 0.05, pixels.shape).astype(np.float32)
    save_image(path, pixels.clip(0, 1))
    return path


def _stroke(view, points, *, release=True):
    mouse(view, "press", points[0])
    for p in points[1:]:
        mouse(view, "move", p)
    if release:
        mouse(view, "release", points[-1])


def _final_after(window, qtbot, action, timeout=30000):
    with qtbot.waitSignal(window.renderer.shown, timeout=timeout, check_params_cb=lambda shown: shown.final):
        action()
    return window.renderer.last


@contextmanager
def _fill_window(make_window, qtbot, picture, size=(1300, 820)):
    window = make_window(size=size)
    try:
        box = window.method_panel.method_box
        box.setCurrentIndex(box.findData("fill"))
        with qtbot.waitSignal(window.renderer.failed, timeout=30000):  # nothing to fill yet
            window.open_input("image", str(picture))
        view = window.inputs_pane.canvas_view
        view.actual_size()
        view.zoom_by(4.0)
        view.centerOn(W / 2, H / 2)
        yield window
    finally:
        window.doc.undo_stack.setClean()
        window.shutdown()


@pytest.fixture
def fill(qtbot, make_window, tmp_path):
    """Fill on the three-colour picture with a hole painted in its red half (filled red)."""
    with _fill_window(make_window, qtbot, _picture(tmp_path / "three.png")) as window:
        window.inputs_pane.mask_tool().set_size(7)
        _final_after(window, qtbot, lambda: _stroke(window.inputs_pane.canvas_view, HOLE))
        yield window


def _hole_inside(window) -> np.ndarray:
    """The hole's pixels away from its edge (the blend band mixes the edge with what is around)."""
    from scipy.ndimage import binary_erosion

    return binary_erosion(window.doc.value("mask").bits, iterations=2)


def _colour_of(image, where) -> np.ndarray:
    return image[where].mean(axis=0)


def _near(colour, expected, tol=0.12) -> bool:
    return bool(np.abs(np.asarray(colour) - np.asarray(expected)).max() < tol)


def _sampling(window, qtbot):
    """Switch the brush to the sampling area with a click on the bar's switch; its tool."""
    bar = window.inputs_pane.bar()
    qtbot.mouseClick(bar.target_button(1), Qt.MouseButton.LeftButton)
    tool = bar.mask_tool
    assert tool is not window.inputs_pane.mask_tool() and tool.armed and tool.everywhere
    return bar, tool


def test_a_sampling_stroke_sets_where_fill_copies_from_and_undo_restores_it(fill, qtbot):
    window, doc, view = fill, fill.doc, fill.inputs_pane.canvas_view
    inside = _hole_inside(window)
    assert inside.sum() > 10
    before = window.renderer.last.image
    assert _near(_colour_of(before, inside), RED)  # copied from the red around it
    bar, tool = _sampling(window, qtbot)
    assert bar.mode_buttons["brush"].text() == "Include" and bar.mode_buttons["eraser"].text() == "Exclude"
    assert "everywhere outside the hole" in window.statusBar().currentMessage()
    hole_tool = window.inputs_pane.mask_tool()
    assert not hole_tool.armed
    tool.set_size(25)
    steps = doc.undo_stack.count()
    result = _final_after(window, qtbot, lambda: _stroke(view, BOTTOM_RIGHT))
    painted = doc.value("source_mask")
    assert painted == Mask.empty(W, H).painted_line((62, 56), (86, 56), 12)  # only what was painted
    assert doc.value("mask").bits[inside].all()  # the hole is as it was
    assert doc.undo_stack.count() == steps + 1 and doc.undo_stack.text(steps).startswith("Include")
    # the fill copied only from the painted region: green in the hole, no red, no blue
    assert _near(_colour_of(result.image, inside), GREEN), _colour_of(result.image, inside)
    assert result.figures["source_pixels"] == painted.area
    # its overlay: its own colour where painted, distinct from the hole's
    from weft.app.gui.mask_overlay import MASK_COLOURS

    sample = tool.overlay.image().pixelColor(70, 56)
    hole = hole_tool.overlay.image().pixelColor(22, 34)
    assert sample.alpha() > 0 and tool.overlay.image().pixelColor(20, 10).alpha() == 0
    assert (
        (sample.red(), sample.green(), sample.blue()) == MASK_COLOURS[1][:3] != (hole.red(), hole.green(), hole.blue())
    )
    # Ctrl+Z: the sampling area is gone (everywhere again), the hole red again
    view.setFocus()
    again = _final_after(
        window, qtbot, lambda: qtbot.keyClick(window, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    )
    assert doc.value("source_mask") is None and doc.value("mask") is not None
    assert tool.overlay.image().isNull()
    assert _near(_colour_of(again.image, inside), RED)


def test_exclude_on_nothing_painted_keeps_fill_from_copying_there(fill, qtbot):
    """Exclude starts from everything (outside the hole) and takes the painted part away."""
    window, doc, view = fill, fill.doc, fill.inputs_pane.canvas_view
    bar, tool = _sampling(window, qtbot)
    qtbot.mouseClick(bar.mode_buttons["eraser"], Qt.MouseButton.LeftButton)
    assert tool.mode == "eraser"
    tool.set_size(49)  # radius 24
    # exclude the whole red half and the blue quarter: only green is left to copy from
    result = _final_after(window, qtbot, lambda: _stroke(view, [(23.5, 71.5), (23.5, 11.5), (95.5, 11.5)]))
    painted = doc.value("source_mask")
    assert painted is not None and doc.undo_stack.text(doc.undo_stack.index() - 1).startswith("Exclude")
    assert painted.bits[36:, 48:].all()  # green: left to copy from
    assert not painted.bits[:36, 3:].any() and not painted.bits[3:, :48].any()  # (the brush is round: a corner)
    assert _near(_colour_of(result.image, _hole_inside(window)), GREEN)


def test_the_live_preview_follows_a_sampling_stroke(fill, qtbot):
    """While the sampling area is painted (before the release), a preview of the whole picture with
    the stroke so far is rendered and shown, as a hole stroke's preview is."""
    window, view = fill, fill.inputs_pane.canvas_view
    bar, tool = _sampling(window, qtbot)
    tool.set_size(25)
    previews = []
    window.renderer.shown.connect(lambda shown: previews.append(shown) if not shown.final else None)
    _stroke(view, BOTTOM_RIGHT, release=False)
    qtbot.waitUntil(lambda: len(previews) > 0, timeout=30000)
    assert window.doc.value("source_mask") is None  # not an edit yet
    preview = previews[-1].image
    ph, pw = preview.shape[:2]
    inside = _hole_inside(window)
    ys, xs = np.nonzero(inside)
    small = np.zeros((ph, pw), bool)
    small[(ys * ph) // H, (xs * pw) // W] = True
    assert _near(_colour_of(preview, small), GREEN, tol=0.2)  # the stroke so far is what it copies from
    assert window.result_view.image is preview
    result = _final_after(window, qtbot, lambda: mouse(view, "release", BOTTOM_RIGHT[-1]))
    assert _near(_colour_of(result.image, inside), GREEN)


def test_esc_cancels_a_sampling_stroke_and_the_result_comes_back(fill, qtbot):
    window, view, doc = fill, fill.inputs_pane.canvas_view, fill.doc
    last = window.renderer.last
    bar, tool = _sampling(window, qtbot)
    tool.set_size(25)
    steps = doc.undo_stack.count()
    _stroke(view, BOTTOM_RIGHT, release=False)
    view.setFocus()
    with qtbot.waitSignal(window.renderer.shown, timeout=10000, check_params_cb=lambda s: s is last):
        qtbot.keyClick(view, Qt.Key.Key_Escape)
    mouse(view, "release", BOTTOM_RIGHT[-1])
    assert doc.value("source_mask") is None and doc.undo_stack.count() == steps and doc.live is None


def test_the_sampling_area_round_trips_through_a_session_and_an_export_reproduced_by_weft_run(
    fill, qtbot, settings, tmp_path, capsys
):
    window, doc, view = fill, fill.doc, fill.inputs_pane.canvas_view
    bar, tool = _sampling(window, qtbot)
    tool.set_size(25)
    result = _final_after(window, qtbot, lambda: _stroke(view, BOTTOM_RIGHT))
    painted, hole = doc.value("source_mask"), doc.value("mask")
    # the session keeps both masks as 1-bit PNGs beside it
    session = tmp_path / "s.weft.json"
    assert window.files.save_session(str(session))
    assert Mask.read(tmp_path / "s.weft.fill.source_mask.png") == painted
    data = json.loads(session.read_text())
    assert data["geometry"]["fill"]["source_mask"] == "s.weft.fill.source_mask.png"
    doc.set_mask("source_mask", None, "clear")
    assert window.files.open_session(str(session))
    assert doc.value("source_mask") == painted and doc.value("mask") == hole
    assert tool.overlay.image().width() == W
    # the export names it in its recipe, a PNG beside it; weft run gives the same pixels
    out = tmp_path / "out.png"
    shown = _final_after(window, qtbot, lambda: window.renderer.final(now=True))
    assert np.array_equal(shown.image, result.image)
    assert window.files.export_result(str(out))
    recipe = json.loads(read_recipe(out))
    assert recipe["inputs"]["source_mask"] == "out.source_mask.png" and recipe["inputs"]["mask"] == "out.mask.png"
    assert Mask.read(tmp_path / "out.source_mask.png") == painted
    again = tmp_path / "again.png"
    assert weft(["run", str(out), "-o", str(again)]) == 0, capsys.readouterr().err
    assert np.array_equal(load_image(out).image, load_image(again).image)
    # and the command line's --source-mask with the same files gives those pixels too
    cli = tmp_path / "cli.png"
    assert (
        weft(
            [
                "fill",
                str(tmp_path / "three.png"),
                "--mask",
                str(tmp_path / "out.mask.png"),
                "--source-mask",
                str(tmp_path / "out.source_mask.png"),
                "--seed",
                str(doc.seed),
                "-o",
                str(cli),
            ]
        )
        == 0
    )
    assert np.array_equal(load_image(out).image, load_image(cli).image)


def test_the_brush_is_sized_to_the_picture_and_keeps_its_size_through_a_recovery(
    qtbot, make_window, settings, tmp_path
):
    """The default brush is a 25th of the picture's longer side (a 600 px photo: 24 px; a 4000 px
    one: 160 px, not 24); a size picked is kept relative to the picture in the settings, so a
    restarted studio (a crash recovery) paints with it again."""
    from weft.app.gui.mask_tool import default_size

    assert default_size(600, 400) == 24 and default_size(4000, 3000) == 160 and default_size(40, 30) == 3
    big = tmp_path / "big.png"
    save_image(big, np.random.default_rng(1).random((300, 500, 3)).astype(np.float32))
    with _fill_window(make_window, qtbot, big) as window:
        tool, bar = window.inputs_pane.mask_tool(), window.inputs_pane.bar()
        assert tool.size == 20 and bar.size_box.value() == 20
        window.inputs_pane.canvas_view.setFocus()
        qtbot.keyClick(window.inputs_pane.canvas_view, Qt.Key.Key_BracketRight)
        assert tool.size == 25
    settings.sync()
    with _fill_window(make_window, qtbot, big) as window:  # the next studio, on the same picture
        assert window.inputs_pane.mask_tool().size == 25
        assert window.inputs_pane.bar().size_box.value() == 25
    with _fill_window(make_window, qtbot, _picture(tmp_path / "small.png")) as window:  # 96 px: the same share
        assert window.inputs_pane.mask_tool().size == 5


@pytest.mark.parametrize("size", [(1024, 700), (1440, 900)])
def test_every_button_over_the_picture_shows_and_the_picture_is_the_large_view(
    qtbot, make_window, settings, tmp_path, size
):
    """No button of the bar hides behind an overflow menu, at 1024x700 as at 1440x900 (Fill
    transparent and Extend canvas… did, and the brush size at 1024); the picture painted on has the
    larger share of the window, beside the result."""
    with _fill_window(make_window, qtbot, _picture(tmp_path / "three.png"), size=size) as window:
        bar = window.inputs_pane.bar()
        qtbot.waitUntil(lambda: bar.width() > 0, timeout=5000)
        buttons = [
            bar.target_button(0),
            bar.target_button(1),
            *bar.mode_buttons.values(),
            bar.size_box,
            bar.clear_button,
            bar.invert_button,
            bar.transparent_button,
            bar.extend_button,
        ]
        for button in buttons:
            assert button.isVisible(), (size, button)
            row = button.parentWidget()
            assert row.rect().contains(button.geometry()), (size, button, button.geometry(), row.rect())
        # the picture painted on gets most of the inputs' height, and the larger share of the width
        # while the result keeps a usable 350 px (at 1024 px the result's 350 px leave it 45 %)
        pane = window.inputs_pane
        assert (
            pane.sizes()[0] >= 0.75 * sum(pane.sizes())
            and window.inputs_pane.canvas_view.height() > 0.6 * pane.height()
        )
        assert window.result_view.width() >= 350
        if size[0] >= 1280:
            assert window.inputs_pane.canvas_view.width() > window.result_view.width()
        else:
            assert pane.width() >= 0.44 * (pane.width() + window.result_view.width())
        # View > Large Picture to Paint (Ctrl+L): the picture gets the larger share at any width, remembered
        assert window.menus.paint_large_action.isEnabled() and not window.menus.paint_large_action.isChecked()
        qtbot.keyClick(window, Qt.Key.Key_L, Qt.KeyboardModifier.ControlModifier)
        assert window.menus.paint_large_action.isChecked() and settings.value("paint_large", type=bool)
        qtbot.waitUntil(lambda: window.inputs_pane.canvas_view.width() > 1.5 * window.result_view.width(), timeout=5000)
        qtbot.keyClick(window, Qt.Key.Key_L, Qt.KeyboardModifier.ControlModifier)
        qtbot.waitUntil(lambda: window.result_view.width() >= 350, timeout=5000)
