"""The studio side of fill and extend: the mask tool (brush, eraser, lasso, Clear, Invert,
Fill transparent) and the margins tool (drag, Extend canvas…), driven with real mouse and key events.

The studio is generic: these tests drive it with a method registered here (it fills its painted mask
with the mean colour of the rest of the picture, and grows the canvas by its margins, filling the new
border alike), so they test the studio, not any one method; nothing in app/gui knows it.
"""

from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np
import pytest
from PySide6.QtCore import QPointF, Qt
from PySide6.QtGui import QImage
from weft.app.cli import main as weft
from weft.core import registry
from weft.core.errors import WeftError
from weft.core.geometry import Margins, Mask
from weft.core.image import load_image, read_recipe, save_image
from weft.core.params import Params, param
from weft.core.registry import InputSpec, Method, Result
from weft.core.studio import MARGINS, MASK, Figure, Geometry, Studio

from .helpers import mouse, pretend_crashed
from .test_artist_session import _click_menu_item

W, H = 80, 64


@dataclass(frozen=True)
class MeanFillParams(Params):
    grow: Margins = param(None, kind="geometry", type=Margins, optional=True, help="pixels added on each side")
    amount: float = param(1.0, lo=0.0, hi=1.0, step=0.05, help="how far towards the mean")


CALLS: list[tuple[int, int]] = []  # the picture sizes the method ran on (previews around a stroke are small)


def _mean_fill(inputs, params, *, rng=None, progress=None, cancel=None):
    picture = inputs["picture"]
    if picture.ndim == 3 and picture.shape[2] == 4:  # (its alpha is not used here)
        picture = picture[..., :3]
    CALLS.append(picture.shape[:2])
    hole = inputs.get("hole")
    if hole is None and not params.grow:
        raise WeftError("nothing to fill: give a hole or margins")
    bits = np.zeros(picture.shape[:2], bool) if hole is None else np.asarray(hole) > 0.5
    if hole is not None and hole.shape[:2] != picture.shape[:2]:
        raise WeftError("the hole is not the size of the picture")
    if params.grow:
        left, top, right, bottom = params.grow
        picture = np.pad(picture, ((top, bottom), (left, right)) + ((0, 0),) * (picture.ndim - 2))
        bits = np.pad(bits, ((top, bottom), (left, right)), constant_values=True)
    out = picture.copy()
    swatch = inputs.get("swatch")
    if bits.any() and swatch is not None:
        mean = swatch.reshape(-1, swatch.shape[-1]).mean(axis=0)
    if bits.any() and not bits.all():
        mean = picture[~bits].mean(axis=0) if swatch is None else mean
        out[bits] = picture[bits] + params.amount * (mean - picture[bits])
    return Result(out, {"hole_pixels": int(bits.sum())})


MEAN_FILL = Method(
    name="mean-fill",
    summary="fill a painted hole with the mean colour of the rest",
    params=MeanFillParams,
    inputs=(
        InputSpec("picture", "the picture", alpha=True),
        InputSpec("hole", "white = fill", required=False),
        InputSpec("swatch", "take the colour from this image instead", required=False),
    ),
    run=_mean_fill,
    studio=Studio(
        title="Mean fill",
        canvas="picture",
        preview_around="hole",
        own_inputs=("swatch",),
        figures={"hole_pixels": Figure("filled", "px")},
        geometry=(
            Geometry(MASK, on=("picture",), input="hole", help="paint the hole"),
            Geometry(MARGINS, on=("picture",), param="grow", help="drag an edge outward"),
        ),
    ),
)


SHOW_SWATCH = Method(  # another method whose input has the name of mean-fill's own "swatch" input
    name="show-swatch",
    summary="the swatch as it is",
    params=MeanFillParams,
    inputs=(InputSpec("swatch", "a swatch"),),
    run=lambda inputs, params, **kw: Result(inputs["swatch"]),
    studio=Studio(title="Show a swatch", canvas="swatch", rank=200),
)


@pytest.fixture
def plugin():
    registry.register(MEAN_FILL)
    registry.register(SHOW_SWATCH)
    yield MEAN_FILL
    registry.unregister(MEAN_FILL.name)
    registry.unregister(SHOW_SWATCH.name)


def _picture(path, seed=3, alpha=None):
    pixels = np.random.default_rng(seed).random((H, W, 3)).astype(np.float32)
    if alpha is None:
        save_image(path, pixels)
    else:  # an RGBA PNG: Qt writes it (weft's save_image writes colour only)
        rgba = np.dstack([pixels, alpha]).clip(0, 1)
        data = np.ascontiguousarray((rgba * 255 + 0.5).astype(np.uint8))
        QImage(data.data, W, H, 4 * W, QImage.Format.Format_RGBA8888).save(str(path))
    return path


def _window_on(make_window, method: str, qtbot, picture):
    """The main window on ``method`` with ``picture`` open as its picture (nothing to fill yet)."""
    window = make_window()
    box = window.method_panel.method_box
    box.setCurrentIndex(box.findData(method))
    with qtbot.waitSignal(window.renderer.failed, timeout=10000):  # nothing to fill yet
        window.open_input("picture", str(picture))
    return window


@pytest.fixture
def studio(plugin, qtbot, make_window, tmp_path):
    """The window on the mean-fill method with a picture open, its first result shown, zoomed 4x."""
    CALLS.clear()
    picture = _picture(tmp_path / "picture.png")
    window = _window_on(make_window, plugin.name, qtbot, picture)
    assert window.doc.image("picture") is not None
    view = window.inputs_pane.canvas_view
    view.actual_size()
    view.zoom_by(4.0)
    view.centerOn(W / 2, H / 2)
    window.picture = picture
    return window


def _mask(window) -> Mask | None:
    return window.doc.value("hole")


def _stroke(view, points, *, release=True):
    mouse(view, "press", points[0])
    for p in points[1:]:
        mouse(view, "move", p)
    if release:
        mouse(view, "release", points[-1])


def _previewed(window, qtbot, view, points, timeout=10000):
    """Press and drag through ``points`` without releasing; the previews shown around the stroke
    (``renderer.around_shown``), once the first has come."""
    around = []
    window.renderer.around_shown.connect(around.append)
    _stroke(view, points, release=False)
    qtbot.waitUntil(lambda: len(around) > 0, timeout=timeout)
    return around


def _painted(overlay) -> np.ndarray:
    """Where the mask's overlay is drawn (its alpha), as a bool (H, W) array."""
    image = overlay.image().convertToFormat(QImage.Format.Format_RGBA8888)
    rgba = np.frombuffer(image.constBits(), np.uint8).reshape(image.height(), image.bytesPerLine() // 4, 4)
    return rgba[:, : image.width(), 3] > 0


def _final_after(window, qtbot, action):
    """Do ``action`` and wait for the full-size result it causes."""
    with qtbot.waitSignal(window.renderer.shown, timeout=10000, check_params_cb=lambda shown: shown.final):
        action()
    return window.renderer.last


def test_with_nothing_painted_the_result_shows_the_picture_and_what_to_do(studio):
    view = studio.result_view
    assert np.array_equal(view.image, studio.doc.image("picture"))
    assert view.notice.isVisible() and view.notice.text() == "Paint the hole; drag an edge outward"
    assert not view.stale.isVisible()  # not an error: there is nothing to fill yet
    assert studio.statusBar().currentMessage() == "Paint the hole; drag an edge outward"


def test_the_mask_input_is_painted_over_its_image_not_a_view_of_its_own(studio):
    assert "hole" not in studio.inputs_pane.views
    tabs = [studio.inputs_pane.tabs.tabText(i) for i in range(studio.inputs_pane.tabs.count())]
    assert not any("hole" in t for t in tabs)
    bar = studio.inputs_pane.bar()
    assert bar is not None and bar.isVisible()
    assert bar.mode_buttons["brush"].isChecked()
    assert not bar.clear_button.isEnabled()  # nothing painted yet


def test_a_brush_stroke_paints_the_pixels_under_it_and_is_one_undo_step(studio, qtbot):
    view, doc = studio.inputs_pane.canvas_view, studio.doc
    tool = studio.inputs_pane.mask_tool()
    tool.set_size(5)  # radius 2
    steps = doc.undo_stack.count()
    result = _final_after(studio, qtbot, lambda: _stroke(view, [(10.5, 20.5), (20.5, 20.5), (30.5, 20.5)]))
    mask = _mask(studio)
    assert mask is not None and mask.shape == (H, W)
    expected = Mask.empty(W, H).painted_line((10, 20), (20, 20), 2).painted_line((20, 20), (30, 20), 2)
    assert mask == expected
    assert mask.bits[20, 10:31].all() and mask.bits[18:23, 15].all() and not mask.bits[17, 15] and not mask.bits[23, 15]
    # the method got the mask: the hole is the mean of the rest, the rest untouched
    source = doc.image("picture")
    assert result.figures["hole_pixels"] == mask.area
    assert np.allclose(result.image[mask.bits], source[~mask.bits].mean(axis=0), atol=1e-5)
    assert np.array_equal(result.image[~mask.bits], source[~mask.bits])
    # the overlay shows the mask over the image: coloured where painted, clear elsewhere
    overlay = tool.overlay.image()
    assert overlay.width() == W and overlay.pixelColor(20, 20).alpha() > 0 and overlay.pixelColor(20, 40).alpha() == 0
    assert doc.undo_stack.count() == steps + 1 and doc.undo_stack.text(steps) == "Brush stroke"
    # Ctrl+Z undoes the whole stroke
    view.setFocus()
    assert studio.result_view.notice.isHidden()
    with qtbot.waitSignal(studio.renderer.failed, timeout=10000):  # nothing to fill again
        qtbot.keyClick(studio, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)
    assert _mask(studio) is None
    assert np.array_equal(studio.result_view.image, source) and studio.result_view.notice.isVisible()
    assert tool.overlay.image().isNull()


def test_square_brackets_size_the_brush_and_its_circle_cursor(studio, qtbot):
    view = studio.inputs_pane.canvas_view
    tool = studio.inputs_pane.mask_tool()
    bar = studio.inputs_pane.bar()
    tool.set_size(8)
    mouse(view, "move", (40.5, 30.5), buttons=Qt.MouseButton.NoButton)
    assert tool.cursor.isVisible()
    from PySide6.QtCore import QEvent
    from PySide6.QtWidgets import QApplication

    QApplication.sendEvent(view, QEvent(QEvent.Type.Leave))  # the mouse leaves the view: no circle
    assert not tool.cursor.isVisible()
    mouse(view, "move", (40.5, 30.5), buttons=Qt.MouseButton.NoButton)
    assert tool.cursor.isVisible()
    on_screen = view.mapFromScene(tool.cursor.rect()).boundingRect().width()
    assert abs(on_screen - 8 * view.scale_factor()) <= 2  # the brush's size on screen
    view.setFocus()
    qtbot.keyClick(view, Qt.Key.Key_BracketRight)
    assert tool.size == 10 and bar.size_box.value() == 10
    assert abs(tool.cursor.rect().width() - 10) < 1e-6
    qtbot.keyClick(view, Qt.Key.Key_BracketRight)
    qtbot.keyClick(view, Qt.Key.Key_BracketRight)
    assert tool.size > 12
    big = tool.size
    qtbot.keyClick(view, Qt.Key.Key_BracketLeft)
    assert tool.size < big
    # a larger brush paints a wider stroke
    tool.set_size(11)  # radius 5
    _final_after(studio, qtbot, lambda: _stroke(view, [(40.5, 30.5), (41.5, 30.5)]))
    column = _mask(studio).bits[:, 40]
    assert column[25:36].all() and not column[24] and not column[36]


def test_the_eraser_removes_and_esc_cancels_a_stroke_in_progress(studio, qtbot):
    view, doc = studio.inputs_pane.canvas_view, studio.doc
    tool = studio.inputs_pane.mask_tool()
    bar = studio.inputs_pane.bar()
    tool.set_size(9)
    _final_after(studio, qtbot, lambda: _stroke(view, [(10.5, 30.5), (60.5, 30.5)]))
    painted = _mask(studio)
    assert painted.bits[30, 35]
    qtbot.mouseClick(bar.mode_buttons["eraser"], Qt.MouseButton.LeftButton)
    assert tool.mode == "eraser"
    tool.set_size(3)
    _final_after(studio, qtbot, lambda: _stroke(view, [(35.5, 20.5), (35.5, 40.5)]))
    erased = _mask(studio)
    assert np.array_equal(_painted(tool.overlay), erased.bits)
    assert not erased.bits[25:36, 34:37].any() and erased.bits[30, 33] and erased.bits[30, 37]
    assert erased.area < painted.area
    assert doc.undo_stack.text(doc.undo_stack.index() - 1) == "Erase"
    # Esc in the middle of a stroke: the mask stays as it was, no undo step
    steps = doc.undo_stack.count()
    _stroke(view, [(50.5, 25.5), (50.5, 35.5)], release=False)
    assert tool.stroking
    view.setFocus()
    qtbot.keyClick(view, Qt.Key.Key_Escape)
    mouse(view, "release", (50.5, 35.5))
    assert not tool.stroking and _mask(studio) == erased and doc.undo_stack.count() == steps


def test_the_lasso_adds_and_subtracts_a_polygon(studio, qtbot):
    view = studio.inputs_pane.canvas_view
    bar = studio.inputs_pane.bar()
    qtbot.mouseClick(bar.mode_buttons["lasso add"], Qt.MouseButton.LeftButton)
    square = [(10.5, 10.5), (40.5, 10.5), (40.5, 40.5), (10.5, 40.5)]
    _final_after(studio, qtbot, lambda: _stroke(view, square))
    mask = _mask(studio)
    assert mask.bits[11:40, 11:40].all() and not mask.bits[45:, :].any() and not mask.bits[:, 45:].any()
    assert mask == Mask.empty(W, H).painted_polygon([(10, 10), (40, 10), (40, 40), (10, 40), (10, 40)])
    qtbot.mouseClick(bar.mode_buttons["lasso subtract"], Qt.MouseButton.LeftButton)
    inner = [(20.5, 20.5), (30.5, 20.5), (30.5, 30.5), (20.5, 30.5)]
    _final_after(studio, qtbot, lambda: _stroke(view, inner))
    mask = _mask(studio)
    assert not mask.bits[21:30, 21:30].any() and mask.bits[12:18, 12:38].all()


def test_clear_and_invert_are_undoable(studio, qtbot):
    view, doc = studio.inputs_pane.canvas_view, studio.doc
    bar = studio.inputs_pane.bar()
    studio.inputs_pane.mask_tool().set_size(5)
    _final_after(studio, qtbot, lambda: _stroke(view, [(20.5, 20.5), (30.5, 20.5)]))
    painted = _mask(studio)
    assert bar.clear_button.isEnabled()
    _final_after(studio, qtbot, lambda: qtbot.mouseClick(bar.invert_button, Qt.MouseButton.LeftButton))
    assert np.array_equal(_mask(studio).bits, ~painted.bits)
    with qtbot.waitSignal(studio.renderer.failed, timeout=10000):  # nothing to fill
        qtbot.mouseClick(bar.clear_button, Qt.MouseButton.LeftButton)
    assert _mask(studio) is None and not bar.clear_button.isEnabled()
    doc.undo_stack.undo()
    doc.undo_stack.undo()
    assert _mask(studio) == painted


def test_fill_transparent_paints_the_images_transparent_pixels(studio, qtbot, tmp_path):
    bar = studio.inputs_pane.bar()
    assert not bar.transparent_button.isEnabled()
    assert "no alpha channel" in bar.transparent_button.toolTip()
    alpha = np.ones((H, W), np.float32)
    alpha[:10, :] = 0.0  # a transparent band along the top
    alpha[30:40, 50:60] = 0.0
    rgba = _picture(tmp_path / "cutout.png", alpha=alpha)
    studio.open_input("picture", str(rgba))
    qtbot.waitUntil(lambda: studio.doc.inputs["picture"].path == str(rgba), timeout=10000)
    assert studio.doc.inputs["picture"].alpha is not None
    assert studio.doc.image("picture").shape == (H, W, 3)  # shown in colour ...
    assert studio.doc.method_inputs()["picture"].shape == (H, W, 4)  # ... the method gets RGBA, as weft run
    qtbot.waitUntil(bar.transparent_button.isEnabled, timeout=5000)
    result = _final_after(studio, qtbot, lambda: qtbot.mouseClick(bar.transparent_button, Qt.MouseButton.LeftButton))
    assert _mask(studio) == Mask.from_alpha(alpha)
    assert result.figures["hole_pixels"] == 10 * W + 100
    assert studio.doc.undo_stack.text(studio.doc.undo_stack.index() - 1) == "Fill transparent"


def test_a_mask_that_no_longer_fits_its_image_is_dropped_with_a_message(studio, qtbot, tmp_path):
    view = studio.inputs_pane.canvas_view
    _final_after(studio, qtbot, lambda: _stroke(view, [(20.5, 20.5), (30.5, 20.5)]))
    painted = _mask(studio)
    other = tmp_path / "other.png"
    save_image(other, np.random.default_rng(5).random((50, 70, 3)).astype(np.float32))
    with qtbot.waitSignal(studio.message, timeout=10000) as said:
        studio.open_input("picture", str(other))
    assert "does not fit" in said.args[0] and "dropped" in said.args[0]
    assert _mask(studio) is None
    qtbot.waitUntil(lambda: studio.result_view.image.shape[:2] == (50, 70), timeout=10000)
    studio.doc.undo_stack.undo()  # the old picture and its mask come back together
    assert studio.doc.inputs["picture"].path == str(studio.picture) and _mask(studio) == painted


def test_session_save_and_open_restores_the_mask_and_margins(studio, qtbot, tmp_path):
    view, doc = studio.inputs_pane.canvas_view, studio.doc
    _final_after(studio, qtbot, lambda: _stroke(view, [(20.5, 20.5), (30.5, 25.5)]))
    doc.set_margins("grow", Margins(4, 0, 8, 2))
    painted = _mask(studio)
    session = tmp_path / "s.weft.json"
    assert studio.files.save_session(str(session))
    png = tmp_path / "s.weft.mean-fill.hole.png"
    assert png.is_file() and Mask.read(png) == painted
    from PIL import Image

    assert Image.open(png).mode == "1"  # a 1-bit PNG
    doc.set_mask("hole", None, "Clear mask")
    doc.set_margins("grow", None)
    assert studio.files.open_session(str(session))
    assert _mask(studio) == painted and doc.value("grow") == Margins(4, 0, 8, 2)
    assert studio.inputs_pane.mask_tool().overlay.image().width() == W


def test_export_writes_the_mask_beside_it_and_weft_run_reproduces_the_pixels(studio, qtbot, tmp_path, capsys):
    view, doc = studio.inputs_pane.canvas_view, studio.doc
    _final_after(studio, qtbot, lambda: _stroke(view, [(15.5, 15.5), (35.5, 40.5)]))
    _final_after(studio, qtbot, lambda: doc.set_margins("grow", Margins(6, 0, 0, 3)))
    painted = _mask(studio)
    out = tmp_path / "out.png"
    assert studio.files.export_result(str(out))
    beside = tmp_path / "out.hole.png"
    assert beside.is_file() and Mask.read(beside) == painted
    recipe = read_recipe(out)
    assert '"hole": "out.hole.png"' in recipe and '"grow": [6, 0, 0, 3]' in recipe
    again = tmp_path / "again.png"
    assert weft(["run", str(out), "-o", str(again)]) == 0, capsys.readouterr().err
    exported = load_image(out).image
    assert exported.shape == (H + 3, W + 6, 3)
    assert np.array_equal(exported, load_image(again).image)
    # a recipe exported alone gets its mask beside it too
    assert studio.files.export_recipe(str(tmp_path / "r.json"))
    assert Mask.read(tmp_path / "r.hole.png") == painted


def test_mask_pngs_are_encoded_and_decoded_off_the_gui_thread(
    studio, qtbot, tmp_path, monkeypatch, capsys, private_recovery
):
    """A mask's PNG (a large one takes a tenth of a second to encode) is encoded for an export, a
    recipe, a saved session and the autosave, and decoded when a session opens, never on the GUI
    thread; the files stay right (bit-exact round trip; weft run reproduces the export)."""
    import threading

    threads: dict[str, list[bool]] = {"encode": [], "decode": []}  # on the GUI thread?
    to_png, read = Mask.to_png, Mask.read.__func__

    def encode(self):
        threads["encode"].append(threading.current_thread() is threading.main_thread())
        return to_png(self)

    def decode(cls, path, what="mask"):
        threads["decode"].append(threading.current_thread() is threading.main_thread())
        return read(cls, path, what)

    monkeypatch.setattr(Mask, "to_png", encode)
    monkeypatch.setattr(Mask, "read", classmethod(decode))
    studio.files.autosave_throttle.setTimeout(10**7)  # no autosave until asked for below
    view, doc = studio.inputs_pane.canvas_view, studio.doc
    _final_after(studio, qtbot, lambda: _stroke(view, [(15.5, 15.5), (35.5, 40.5)]))
    painted = _mask(studio)
    out = tmp_path / "out.png"
    assert studio.files.export_result(str(out))
    assert studio.files.export_recipe(str(tmp_path / "r.json"))
    session = tmp_path / "s.weft.json"
    assert studio.files.save_session(str(session))
    assert len(threads["encode"]) == 3 and not any(threads["encode"])
    # the autosave (its timer's): off the GUI thread, and nothing waits for it
    doc.set_margins("grow", Margins(0, 0, 2, 0))
    studio.files.autosave_throttle.setTimeout(10)
    recovery = studio.files.recovery_file.with_name(studio.files.recovery_file.name[:-5] + ".mean-fill.hole.png")
    qtbot.waitUntil(lambda: studio.files.recovery_file.is_file() and recovery.is_file(), timeout=10000)
    assert len(threads["encode"]) == 4 and not any(threads["encode"])
    doc.set_mask("hole", None, "Clear mask")
    assert studio.files.open_session(str(session))
    assert threads["decode"] == [False] and _mask(studio) == painted  # bit-exact
    assert Mask.read(tmp_path / "out.hole.png") == painted and Mask.read(tmp_path / "r.hole.png") == painted
    again = tmp_path / "again.png"
    assert weft(["run", str(out), "-o", str(again)]) == 0, capsys.readouterr().err
    assert np.array_equal(load_image(out).image, load_image(again).image)


def _screen_drag(view, start_scene, steps_px, *, last=True, modifiers=Qt.KeyboardModifier.NoModifier):
    """Press at a scene point, then move the mouse by screen offsets (dx, dy) from there, as a hand
    does (the scene may move under it meanwhile), and release at the last one."""
    from PySide6.QtCore import QEvent, QPointF
    from PySide6.QtGui import QMouseEvent
    from PySide6.QtWidgets import QApplication

    origin = QPointF(view.mapFromScene(QPointF(*start_scene)))

    def send(kind, at):
        etype = {
            "press": QEvent.Type.MouseButtonPress,
            "move": QEvent.Type.MouseMove,
            "release": QEvent.Type.MouseButtonRelease,
        }[kind]
        button = Qt.MouseButton.NoButton if kind == "move" else Qt.MouseButton.LeftButton
        held = Qt.MouseButton.NoButton if kind == "release" else Qt.MouseButton.LeftButton
        QApplication.sendEvent(
            view.viewport(), QMouseEvent(etype, at, QPointF(view.viewport().mapToGlobal(at)), button, held, modifiers)
        )

    send("press", origin)
    for dx, dy in steps_px:
        send("move", origin + QPointF(dx, dy))
    if last:
        send("release", origin + QPointF(*steps_px[-1]))


def test_extend_canvas_by_dragging_an_edge_outward(studio, qtbot):
    view, doc = studio.inputs_pane.canvas_view, studio.doc
    view.fit()  # the whole image with room around it
    tool = studio.inputs_pane.margins_tool()
    studio.inputs_pane.mask_tool().set_size(1)  # presses 1 px outside the image: beyond the brush's circle
    assert view.sceneRect().left() < 0 and view.sceneRect().right() > W  # room to drag in
    k = view.scale_factor()  # screen pixels per image pixel
    _screen_drag(view, (W + 1.0, H / 2), [(7 * k, 0)], last=False)
    assert tool.frame.isVisible() and tool.frame.rect().width() == W + 7  # the grown frame, drawn
    result = _final_after(studio, qtbot, lambda: _screen_drag(view, (W + 1.0, H / 2), [(14 * k, 0), (20 * k, 0)]))
    assert doc.value("grow") == Margins(0, 0, 20, 0)  # (its press started the drag again)
    assert doc.undo_stack.text(doc.undo_stack.index() - 1) == "Extend canvas 0,0,20,0"
    assert result.image.shape == (H, W + 20, 3)
    assert _mask(studio) is None  # the press outside the image painted nothing
    # the top-left corner drags two edges
    k = view.scale_factor()
    _final_after(studio, qtbot, lambda: _screen_drag(view, (-1.0, -1.0), [(-4 * k, 0), (-10 * k, -6 * k)]))
    assert doc.value("grow") == Margins(10, 6, 20, 0)
    doc.undo_stack.undo()
    assert doc.value("grow") == Margins(0, 0, 20, 0)


def test_a_brush_press_just_outside_the_image_paints_and_farther_out_or_with_shift_drags_the_edge(studio, qtbot):
    """The rule (mask_tools' docstring): outside the image a brush or eraser press paints while the
    brush's circle covers a pixel of the image; farther out, or with Shift, it drags the canvas edges;
    the pointer says which before the press (the brush's circle, or a resize arrow)."""
    view, doc = studio.inputs_pane.canvas_view, studio.doc
    view.fit()
    tool, margins = studio.inputs_pane.mask_tool(), studio.inputs_pane.margins_tool()
    tool.set_size(9)  # its circle reaches 4.5 px: the centres of the last column from up to 4 px outside
    k = view.scale_factor()
    # hover 3 px outside the right edge: the brush's circle, no resize arrow
    mouse(view, "move", (W + 3.0, H / 2), buttons=Qt.MouseButton.NoButton)
    assert tool.cursor.isVisible() and view.viewport().cursor().shape() == Qt.CursorShape.CrossCursor
    # a stroke along the border that starts 3 px outside: paint, no margins
    result = _final_after(studio, qtbot, lambda: _screen_drag(view, (W + 3.0, H / 2), [(0, -4 * k), (0, -8 * k)]))
    assert doc.value("grow") is None and not margins.frame.isVisible()
    painted = _mask(studio)
    assert painted is not None and painted.bits[:, W - 1].any() and not painted.bits[:, : W - 5].any()
    assert doc.undo_stack.text(doc.undo_stack.index() - 1) == "Brush stroke"
    assert result.image.shape == (H, W, 3)
    # 6 px out: beyond the circle -- the arrow shows, and the press drags the right edge
    mouse(view, "move", (W + 6.0, H / 2), buttons=Qt.MouseButton.NoButton)
    assert not tool.cursor.isVisible() and view.viewport().cursor().shape() == Qt.CursorShape.SizeHorCursor
    mouse(view, "move", (-6.0, -6.0), buttons=Qt.MouseButton.NoButton)  # the top-left corner: both edges
    assert view.viewport().cursor().shape() == Qt.CursorShape.SizeFDiagCursor
    _final_after(studio, qtbot, lambda: _screen_drag(view, (W + 6.0, H / 2), [(5 * k, 0), (9 * k, 0)]))
    assert doc.value("grow") == Margins(0, 0, 9, 0) and _mask(studio) == painted
    # with Shift a press 1 px outside drags the edges whatever the brush (the view refit to the grown frame)
    k = view.scale_factor()
    _final_after(
        studio,
        qtbot,
        lambda: _screen_drag(
            view, (W / 2, H + 1.0), [(0, 4 * k), (0, 6 * k)], modifiers=Qt.KeyboardModifier.ShiftModifier
        ),
    )
    assert doc.value("grow") == Margins(0, 0, 9, 6) and _mask(studio) == painted
    # back inside: the brush's circle and the cross again
    mouse(view, "move", (W / 2, H / 2), buttons=Qt.MouseButton.NoButton)
    assert tool.cursor.isVisible() and view.viewport().cursor().shape() == Qt.CursorShape.CrossCursor
    # the eraser follows the same rule; a lasso starts inside the image (a press outside drags)
    qtbot.mouseClick(studio.inputs_pane.bar().mode_buttons["eraser"], Qt.MouseButton.LeftButton)
    _final_after(studio, qtbot, lambda: _screen_drag(view, (W + 3.0, H / 2), [(0, -4 * k), (0, -8 * k)]))
    assert _mask(studio) is None and doc.value("grow") == Margins(0, 0, 9, 6)  # the stroke erased it all
    qtbot.mouseClick(studio.inputs_pane.bar().mode_buttons["lasso add"], Qt.MouseButton.LeftButton)
    _final_after(studio, qtbot, lambda: _screen_drag(view, (W + 1.0, H / 2), [(2 * k, 0), (3 * k, 0)]))
    assert doc.value("grow") == Margins(0, 0, 12, 6)


def test_square_brackets_size_the_brush_wherever_the_focus_is_but_a_text_field_keeps_them(studio, qtbot):
    """[ and ] are the window's shortcuts while the mask tool is shown: after a click on a tool
    button or on a slider (the focus is not on the canvas) they still size the brush; a text field
    with the focus types them instead."""
    from PySide6.QtWidgets import QApplication, QLineEdit, QSlider

    tool, bar = studio.inputs_pane.mask_tool(), studio.inputs_pane.bar()
    studio.activateWindow()
    qtbot.waitUntil(lambda: QApplication.activeWindow() is studio, timeout=5000)
    tool.set_size(20)
    qtbot.mouseClick(bar.mode_buttons["eraser"], Qt.MouseButton.LeftButton)  # a tool button
    button = bar.mode_buttons["eraser"]
    button.setFocus()
    assert QApplication.focusWidget() is button
    qtbot.keyClick(button, Qt.Key.Key_BracketRight)
    assert tool.size == 25 and bar.size_box.value() == 25
    qtbot.keyClick(button, Qt.Key.Key_BracketLeft)
    assert tool.size == 20
    slider = next(s for s in studio.method_panel.findChildren(QSlider) if s.isVisible())
    qtbot.mouseClick(slider, Qt.MouseButton.LeftButton, pos=slider.rect().center())  # a slider
    slider.setFocus()
    assert QApplication.focusWidget() is slider
    qtbot.keyClick(slider, Qt.Key.Key_BracketLeft)
    assert tool.size == 16
    # Edit > Mask and Canvas lists them with their keys
    texts = {a.text(): a.shortcut().toString() for a in studio.menus.geometry_menu.actions()}
    assert texts["Smaller brush"] == "[" and texts["Larger brush"] == "]"
    # a text field keeps its keys
    field = QLineEdit(studio.method_panel)
    field.show()
    field.setFocus()
    qtbot.waitUntil(lambda: QApplication.focusWidget() is field, timeout=5000)
    qtbot.keyClicks(field, "]]")
    assert field.text() == "]]" and tool.size == 16


def test_extend_canvas_dialog_takes_four_typed_fields(studio, qtbot):
    bar = studio.inputs_pane.bar()
    _click_menu_item(qtbot, studio.menus.geometry_menu, bar.extend_action)  # Edit > Mask and Canvas > Extend canvas…
    dialog = bar.dialog
    qtbot.waitUntil(dialog.isVisible, timeout=5000)
    for side, value in zip(("left", "top", "right", "bottom"), (3, 5, 0, 12), strict=True):
        box = dialog.boxes[side]
        box.selectAll()
        qtbot.keyClicks(box, str(value))
    assert dialog.result_label.text().endswith(f"{W + 3}x{H + 17}")
    result = _final_after(studio, qtbot, lambda: qtbot.keyClick(dialog, Qt.Key.Key_Return))
    assert studio.doc.value("grow") == Margins(3, 5, 0, 12)
    assert result.image.shape == (H + 17, W + 3, 3)
    frame = studio.inputs_pane.margins_tool().frame
    assert frame.isVisible() and frame.rect().topLeft() == QPointF(-3, -5)


def test_painting_previews_the_region_around_the_stroke_live(studio, qtbot):
    from weft.core.studio import AROUND_SIDE

    view = studio.inputs_pane.canvas_view
    studio.inputs_pane.mask_tool().set_size(5)
    CALLS.clear()
    around = _previewed(studio, qtbot, view, [(10.5, 10.5), (14.5, 12.5)])
    shown = around[-1]
    assert not shown.final and shown.image.shape == (H, W, 3)
    assert CALLS and max(CALLS[0]) < max(H, W) and max(CALLS[0]) <= AROUND_SIDE  # a crop, not the whole picture
    live = studio.doc.live.value
    assert np.array_equal(_painted(studio.inputs_pane.mask_tool().overlay), live.bits)  # drawn as it is painted
    # the stroke so far is filled in the preview, pasted into the picture (no full result yet: nothing
    # was painted before)
    source = studio.doc.image("picture")
    assert not np.allclose(shown.image[live.bits], source[live.bits])
    assert np.array_equal(shown.image[40:, 40:], source[40:, 40:])
    assert np.array_equal(studio.result_view.image, shown.image)
    assert _mask(studio) is None  # nothing committed before the release
    result = _final_after(studio, qtbot, lambda: mouse(view, "release", (14.5, 12.5)))
    assert result.image.shape == (H, W, 3) and _mask(studio) is not None
    # the next stroke's previews are pasted into that full result
    around.clear()
    _stroke(view, [(60.5, 50.5), (64.5, 52.5)], release=False)
    qtbot.waitUntil(lambda: len(around) > 0, timeout=10000)
    assert np.array_equal(around[-1].image[:20, :20], result.image[:20, :20])  # the first stroke, filled
    assert not np.array_equal(result.image[:20, :20], source[:20, :20])
    view.setFocus()
    with qtbot.waitSignal(studio.renderer.shown, timeout=10000):  # Esc: the full result again
        qtbot.keyClick(view, Qt.Key.Key_Escape)
    mouse(view, "release", (64.5, 52.5))
    assert np.array_equal(studio.result_view.image, result.image)


def test_previews_say_their_figures_in_the_methods_words_as_the_full_result_does(studio, qtbot):
    """The status line of a preview while a slider moves reads the figures with the method's words
    (Studio.figures: "filled 40 px"), as the full result's does, never as raw keys ("hole_pixels",
    "hole pixels"); a stroke's preview renders a crop, whose count of pixels is not the picture's: it
    says the figures come on release (test_a_strokes_preview_states_only_figures_of_the_whole_image)."""
    import re

    view = studio.inputs_pane.canvas_view
    studio.inputs_pane.mask_tool().set_size(5)
    _previewed(studio, qtbot, view, [(10.5, 10.5), (14.5, 12.5)])
    text = studio.status.result_label.full_text()
    # (a count of pixels describes the crop, not the picture: only the full result states it)
    assert re.fullmatch(
        r"preview around the stroke in \d+ ms — its \d+x\d+ crop( \(rendered at \d+x\d+\))?; "
        r"the image's figures on release",
        text,
    ), text
    result = _final_after(studio, qtbot, lambda: mouse(view, "release", (14.5, 12.5)))
    assert studio.status.result_label.full_text().endswith(f"— filled {result.figures['hole_pixels']} px")
    previews, text = _slider_previewed(studio, qtbot, "amount")  # a slider's preview
    assert re.fullmatch(rf"preview {W}x{H} in \d+ ms — filled {previews[-1].figures['hole_pixels']} px", text), text
    qtbot.waitUntil(lambda: not studio.renderer.running(), timeout=10000)  # (its release render ends the test)


def test_a_session_whose_mask_no_longer_fits_its_image_opens_without_it_and_says_so(studio, qtbot, tmp_path):
    view = studio.inputs_pane.canvas_view
    _final_after(studio, qtbot, lambda: _stroke(view, [(20.5, 20.5), (30.5, 20.5)]))
    session = tmp_path / "s.weft.json"
    assert studio.files.save_session(str(session))
    save_image(studio.picture, np.random.default_rng(9).random((40, 40, 3)).astype(np.float32))  # the file changed
    messages = []
    studio.message.connect(messages.append)
    assert studio.files.open_session(str(session))
    assert _mask(studio) is None and studio.doc.image("picture").shape == (40, 40, 3)
    assert any("must be the size of its image" in m and m.endswith("dropped") for m in messages)


def test_unsaved_masks_and_margins_reach_the_recovery_file(studio, qtbot, settings, private_recovery):
    from weft.app.gui.main_window import MainWindow

    view, doc = studio.inputs_pane.canvas_view, studio.doc
    _final_after(studio, qtbot, lambda: _stroke(view, [(20.5, 20.5), (30.5, 28.5)]))
    doc.set_margins("grow", Margins(0, 2, 0, 0))
    painted = _mask(studio)
    assert studio.files.autosave()
    file = studio.files.recovery_file
    hole = file.with_name(file.name[:-5] + ".mean-fill.hole.png")
    assert hole.is_file()
    # a new window (the first one "crashed") offers the recovery and gets the mask back
    pretend_crashed(studio)
    again = MainWindow(settings=settings, load_defaults=False)
    qtbot.addWidget(again)
    try:
        assert again.doc.method == "mean-fill" and again.doc.value("hole") == painted
        assert again.doc.value("grow") == Margins(0, 2, 0, 0)
        again.doc.undo_stack.setClean()  # saved: the recovery file and its mask go
        again.files.schedule_autosave()
        assert not file.exists() and not hole.exists()
    finally:
        again.shutdown()


def _swatch_opened_for_another_method(studio, qtbot, tmp_path):
    """Open a swatch while show-swatch is current, then make mean-fill (whose own input it is) current."""
    doc = studio.doc
    swatch = tmp_path / "swatch.png"
    save_image(swatch, np.full((8, 8, 3), 0.25, np.float32))
    doc.set_method(SHOW_SWATCH.name)
    studio.open_input("swatch", str(swatch))
    qtbot.waitUntil(lambda: doc.image("swatch") is not None, timeout=10000)
    doc.set_method(MEAN_FILL.name)
    return swatch


def test_an_own_input_opened_for_another_method_is_not_used(studio, qtbot, tmp_path):
    """mean-fill's optional "swatch" is its own (Studio.own_inputs): the swatch opened for another
    method of the studio does not change its fill; one opened for it does."""
    doc, view = studio.doc, studio.inputs_pane.canvas_view
    swatch = _swatch_opened_for_another_method(studio, qtbot, tmp_path)
    assert doc.image("swatch") is None and "swatch" not in doc.method_inputs()
    studio.inputs_pane.mask_tool().set_size(5)
    result = _final_after(studio, qtbot, lambda: _stroke(view, [(20.5, 20.5), (30.5, 20.5)]))
    bits = _mask(studio).bits
    picture = doc.image("picture")
    assert np.allclose(result.image[bits], picture[~bits].mean(axis=0), atol=1e-5)  # not the swatch's colour
    assert "swatch" not in result.recipe.inputs
    result = _final_after(studio, qtbot, lambda: studio.open_input("swatch", str(swatch)))  # opened for it
    assert np.allclose(result.image[bits], load_image(swatch).image.mean(), atol=1e-5)  # 64/255


def test_an_own_input_opened_for_another_method_stays_its_through_a_session(studio, qtbot, tmp_path):
    """Saved and reopened (or recovered) with mean-fill current, the swatch opened for another method
    is still not mean-fill's (seen under Xvfb: after a recovery, the brick open for quilt filled a
    gravel hole in fill, because a restored session counted every own input as the current method's)."""
    doc, view = studio.doc, studio.inputs_pane.canvas_view
    _swatch_opened_for_another_method(studio, qtbot, tmp_path)
    studio.inputs_pane.mask_tool().set_size(5)
    _final_after(studio, qtbot, lambda: _stroke(view, [(20.5, 20.5), (30.5, 20.5)]))
    session = tmp_path / "s.weft.json"
    assert studio.files.save_session(str(session))
    result = _final_after(studio, qtbot, lambda: studio.files.open_session(str(session)))
    assert doc.method == MEAN_FILL.name and doc.image("swatch") is None
    bits = _mask(studio).bits
    picture = doc.image("picture")
    assert np.allclose(result.image[bits], picture[~bits].mean(axis=0), atol=1e-5)  # not the swatch's colour
    doc.set_method(SHOW_SWATCH.name)
    assert doc.image("swatch") is not None  # still open for the method it was opened for


def _slider_previewed(studio, qtbot, name: str):
    """Hold parameter ``name``'s slider down and move it a quarter of its range, as a hand does, until
    its first preview shows, then release it: ``(the previews shown, the status text meanwhile)``."""
    slider = studio.method_panel.params_panel.row(name).editor
    previews = []
    studio.renderer.shown.connect(lambda shown: previews.append(shown) if not shown.final else None)
    slider.setSliderDown(True)
    slider.setValue(slider.value() - max(1, (slider.maximum() - slider.minimum()) // 4))
    qtbot.waitUntil(lambda: len(previews) > 0, timeout=10000)
    text = studio.status.result_label.full_text()
    slider.setSliderDown(False)
    slider.sliderReleased.emit()
    return previews, text


@contextmanager
def _fill_in_the_studio(make_window, qtbot):
    """The studio as it opens on its bundled examples, switched to fill with the method box (nothing
    is painted yet, so that render fails); shut down on leaving."""
    window = make_window(load_defaults=True)
    try:
        qtbot.waitUntil(lambda: window.renderer.last is not None and window.renderer.last.final, timeout=30000)
        assert window.doc.image("texture") is not None  # the other methods' texture is open
        box = window.method_panel.method_box
        with qtbot.waitSignal(window.renderer.failed, timeout=30000):  # nothing painted yet
            box.setCurrentIndex(box.findData("fill"))
        yield window
    finally:
        window.doc.undo_stack.setClean()
        window.shutdown()


def test_the_fill_method_in_the_studio_paints_previews_and_round_trips(qtbot, make_window, tmp_path, capsys):
    """The real fill, as an artist meets it: the studio opens on its examples, fill is picked, a hole
    is painted with the mouse (previewed around the stroke), filled on release, exported and re-run."""
    from scipy.ndimage import binary_dilation

    with _fill_in_the_studio(make_window, qtbot) as window:
        assert window.doc.image("texture") is None  # the other methods' texture is not fill's source
        assert window.result_view.notice.isVisible() and "Paint what to fill" in window.result_view.notice.text()
        view, doc = window.inputs_pane.canvas_view, window.doc
        image = doc.image("image")
        h, w = image.shape[:2]
        view.actual_size()
        view.zoom_by(2.0)
        view.centerOn(w / 2, h / 2)
        window.inputs_pane.mask_tool().set_size(9)
        around = []
        window.renderer.around_shown.connect(around.append)
        y = h / 2 + 0.5
        _stroke(view, [(w * 0.35, y), (w * 0.45, y), (w * 0.55, y)], release=False)
        qtbot.waitUntil(lambda: len(around) > 0, timeout=30000)
        assert around[-1].image.shape == image.shape
        result = _final_after(window, qtbot, lambda: mouse(view, "release", (w * 0.55, y)))
        hole = doc.value("mask").bits
        assert result.image.shape == image.shape and result.figures["hole_pixels"] == int(hole.sum())
        near = binary_dilation(hole, np.ones((3, 3), bool), iterations=doc.current_params.band + 1)  # (8-connected)
        assert np.array_equal(result.image[~near], image[~near])  # known pixels outside the blend band untouched
        assert not np.allclose(result.image[hole], image[hole])
        out = tmp_path / "filled.png"
        assert window.files.export_result(str(out))
        assert (tmp_path / "filled.mask.png").is_file()
        again = tmp_path / "again.png"
        assert weft(["run", str(out), "-o", str(again)]) == 0, capsys.readouterr().err
        assert np.array_equal(load_image(out).image, load_image(again).image)


SHOW_HOLE = Method(  # another method with a plain input named like mean-fill's painted mask
    name="show-hole",
    summary="the hole image as it is",
    params=MeanFillParams,
    inputs=(InputSpec("hole", "an image named like mean-fill's painted mask"),),
    run=lambda inputs, params, **kw: Result(inputs["hole"]),
    studio=Studio(title="Show a hole", canvas="hole", rank=201),
)


@pytest.fixture
def show_hole():
    registry.register(SHOW_HOLE)
    yield SHOW_HOLE
    registry.unregister(SHOW_HOLE.name)


def test_an_image_opened_as_another_methods_input_of_the_masks_name_stays_out_of_the_recipe(
    show_hole, studio, qtbot, tmp_path, capsys
):
    doc = studio.doc
    hole = np.zeros((H, W), np.float32)
    hole[10:30, 10:30] = 1
    save_image(tmp_path / "hole.png", hole)
    doc.set_method(SHOW_HOLE.name)
    _final_after(studio, qtbot, lambda: studio.open_input("hole", str(tmp_path / "hole.png")))
    with qtbot.waitSignal(studio.renderer.failed, timeout=10000):  # nothing painted for mean-fill
        doc.set_method(MEAN_FILL.name)
    result = _final_after(studio, qtbot, lambda: doc.set_margins("grow", Margins(0, 0, 8, 0)))
    assert result.figures["hole_pixels"] == 8 * H  # the margins only: show-hole's image is no hole here
    assert "hole" not in result.recipe.inputs and set(result.recipe.inputs) == {"picture"}
    out = tmp_path / "out.png"
    assert studio.files.export_result(str(out))
    assert "hole" not in read_recipe(out)
    again = tmp_path / "again.png"
    assert weft(["run", str(out), "-o", str(again)]) == 0, capsys.readouterr().err
    assert np.array_equal(load_image(out).image, load_image(again).image)


def _switch_to_mean_fill_from_show_swatch(studio, qtbot, tmp_path):
    """Show another method's result (show-swatch), then switch back to mean-fill, which has nothing
    painted: the picture is shown with what to draw, and the renderer's last result is show-swatch's."""
    swatch = tmp_path / "swatch.png"
    save_image(swatch, np.full((8, 8, 3), 0.25, np.float32))
    studio.doc.set_method(SHOW_SWATCH.name)
    _final_after(studio, qtbot, lambda: studio.open_input("swatch", str(swatch)))
    with qtbot.waitSignal(studio.renderer.failed, timeout=10000):
        studio.doc.set_method(MEAN_FILL.name)
    assert studio.renderer.last.recipe.method == SHOW_SWATCH.name  # older than what is shown
    assert np.array_equal(studio.result_view.image, studio.doc.image("picture"))


def test_with_the_input_shown_instead_of_a_result_export_and_copy_refuse(studio, qtbot, tmp_path, monkeypatch):
    from PySide6.QtWidgets import QApplication, QFileDialog

    out = tmp_path / "out.png"
    monkeypatch.setattr(QFileDialog, "getSaveFileName", lambda *a, **k: (str(out), ""))
    words = "nothing to export: paint the hole; drag an edge outward"
    _switch_to_mean_fill_from_show_swatch(studio, qtbot, tmp_path)
    studio.result_view.setFocus()
    with qtbot.waitSignal(studio.message, timeout=5000) as said:
        qtbot.keyClick(studio, Qt.Key.Key_E, Qt.KeyboardModifier.ControlModifier)  # Export Result…
    assert said.args == [words] and not out.exists()  # not show-swatch's result
    QApplication.clipboard().clear()
    with qtbot.waitSignal(studio.message, timeout=5000) as said:
        qtbot.keyClick(studio, Qt.Key.Key_C, Qt.KeyboardModifier.ControlModifier | Qt.KeyboardModifier.ShiftModifier)
    assert said.args == ["nothing to copy: paint the hole; drag an edge outward"]
    assert QApplication.clipboard().image().isNull()
    with qtbot.waitSignal(studio.message, timeout=5000) as said:  # File > Apply to Folder…
        qtbot.keyClick(studio, Qt.Key.Key_B, Qt.KeyboardModifier.ControlModifier | Qt.KeyboardModifier.ShiftModifier)
    assert said.args == ["nothing to apply: paint the hole; drag an edge outward"]
    # a fill, then Clear mask: the picture again, and the fill from before is not exported either
    view, bar = studio.inputs_pane.canvas_view, studio.inputs_pane.bar()
    studio.inputs_pane.mask_tool().set_size(9)
    _final_after(studio, qtbot, lambda: _stroke(view, [(20.5, 20.5), (40.5, 20.5)]))
    with qtbot.waitSignal(studio.renderer.failed, timeout=10000):
        qtbot.mouseClick(bar.clear_button, Qt.MouseButton.LeftButton)
    assert np.array_equal(studio.result_view.image, studio.doc.image("picture"))
    with qtbot.waitSignal(studio.message, timeout=5000) as said:
        qtbot.keyClick(studio, Qt.Key.Key_E, Qt.KeyboardModifier.ControlModifier)
    assert said.args == [words] and not out.exists()
    assert not studio.files.export_recipe(str(tmp_path / "r.json")) and not (tmp_path / "r.json").exists()
    # a result again: exported
    _final_after(studio, qtbot, lambda: studio.doc.set_margins("grow", Margins(0, 0, 4, 0)))
    qtbot.keyClick(studio, Qt.Key.Key_E, Qt.KeyboardModifier.ControlModifier)
    assert out.is_file() and load_image(out).image.shape == (H, W + 4, 3)


def test_esc_on_the_first_stroke_after_a_method_switch_shows_the_picture_again(studio, qtbot, tmp_path):
    _switch_to_mean_fill_from_show_swatch(studio, qtbot, tmp_path)
    view = studio.inputs_pane.canvas_view
    view.actual_size()
    view.zoom_by(4.0)
    view.centerOn(W / 2, H / 2)
    studio.inputs_pane.mask_tool().set_size(9)
    _previewed(studio, qtbot, view, [(20.5, 20.5), (30.5, 20.5)])
    assert not np.array_equal(studio.result_view.image, studio.doc.image("picture"))  # the stroke's preview
    view.setFocus()
    qtbot.keyClick(view, Qt.Key.Key_Escape)
    mouse(view, "release", (30.5, 20.5))
    assert np.array_equal(studio.result_view.image, studio.doc.image("picture"))  # not show-swatch's result
    assert studio.result_view.notice.isVisible()
    assert studio.result_view.notice.text() == "Paint the hole; drag an edge outward"
    assert studio.statusBar().currentMessage() == "Paint the hole; drag an edge outward"
    assert studio.doc.live is None and _mask(studio) is None


def test_a_stroke_that_changes_nothing_ends_its_preview_with_no_undo_step(studio, qtbot):
    view, doc = studio.inputs_pane.canvas_view, studio.doc
    studio.inputs_pane.mask_tool().set_size(9)
    result = _final_after(studio, qtbot, lambda: _stroke(view, [(20.5, 20.5), (40.5, 20.5)]))
    steps = doc.undo_stack.count()
    _previewed(studio, qtbot, view, [(30.5, 20.5), (31.5, 20.5)])  # over what is painted already
    assert doc.live is not None
    assert not np.array_equal(studio.result_view.image, result.image)  # the crop's own mean: other pixels
    with qtbot.waitSignal(studio.renderer.shown, timeout=10000) as shown:  # the full result again
        mouse(view, "release", (31.5, 20.5))
    assert shown.args[0] is result
    assert doc.live is None and doc.undo_stack.count() == steps
    assert np.array_equal(studio.result_view.image, result.image)


def test_an_eraser_stroke_is_previewed_live(studio, qtbot):
    view, doc = studio.inputs_pane.canvas_view, studio.doc
    tool, bar = studio.inputs_pane.mask_tool(), studio.inputs_pane.bar()
    tool.set_size(9)
    _final_after(studio, qtbot, lambda: _stroke(view, [(10.5, 30.5), (60.5, 30.5)]))
    qtbot.mouseClick(bar.mode_buttons["eraser"], Qt.MouseButton.LeftButton)
    tool.set_size(5)
    around = _previewed(studio, qtbot, view, [(35.5, 24.5), (35.5, 36.5)])
    live = doc.live.value.snapshot()  # (the tool's MaskStroke: the mask so far, copied)
    assert not live.bits[28:33, 34:37].any() and live.bits[30, 30]
    source = doc.image("picture")
    # erased pixels show the picture again (once a preview covers the last dab: the first may cover only
    # the press's), the rest of the hole stays filled
    qtbot.waitUntil(lambda: np.array_equal(around[-1].image[28:33, 34:37], source[28:33, 34:37]), timeout=10000)
    assert not np.allclose(around[-1].image[30, 20], source[30, 20])
    assert np.array_equal(studio.result_view.image, around[-1].image)
    result = _final_after(studio, qtbot, lambda: mouse(view, "release", (35.5, 36.5)))
    assert _mask(studio) == live and np.array_equal(result.image[28:33, 34:37], source[28:33, 34:37])


def test_a_parameter_change_does_not_redraw_the_masks_overlay(studio, qtbot):
    view, doc = studio.inputs_pane.canvas_view, studio.doc
    tool = studio.inputs_pane.mask_tool()
    _final_after(studio, qtbot, lambda: _stroke(view, [(20.5, 20.5), (30.5, 20.5)]))
    drawn = tool.overlay.image().cacheKey()
    for amount in (0.9, 0.8):
        _final_after(studio, qtbot, lambda amount=amount: doc.set_param("amount", amount))
    assert tool.overlay.image().cacheKey() == drawn  # the same image: not rebuilt
    assert np.array_equal(_painted(tool.overlay), _mask(studio).bits)
    # another mask is drawn: undo brings back the picture with nothing painted, redo the stroke
    doc.undo_stack.undo()  # the amount (one step: edits of one parameter merge)
    assert tool.overlay.image().cacheKey() == drawn
    doc.undo_stack.undo()
    assert tool.overlay.image().isNull()
    doc.undo_stack.redo()
    assert np.array_equal(_painted(tool.overlay), _mask(studio).bits)


def test_a_session_whose_mask_png_is_missing_or_unreadable_opens_without_it_and_says_so(studio, qtbot, tmp_path):
    view, doc = studio.inputs_pane.canvas_view, studio.doc
    _final_after(studio, qtbot, lambda: _stroke(view, [(20.5, 20.5), (30.5, 20.5)]))
    doc.set_margins("grow", Margins(0, 3, 0, 0))
    session = tmp_path / "s.weft.json"
    assert studio.files.save_session(str(session))
    png = tmp_path / "s.weft.mean-fill.hole.png"
    for spoil in (png.unlink, lambda: png.write_bytes(b"not a png")):
        spoil()
        doc.set_margins("grow", None)
        messages = []
        studio.message.connect(messages.append)
        assert studio.files.open_session(str(session))
        studio.message.disconnect(messages.append)
        assert len(messages) == 1 and messages[0].startswith(f"{session}: mean-fill: ")
        assert "s.weft.mean-fill.hole.png" in messages[0] and messages[0].endswith("; dropped")
        assert "\n" not in messages[0]
        assert _mask(studio) is None and doc.value("grow") == Margins(0, 3, 0, 0)  # the rest opened
        assert doc.inputs["picture"].path == str(studio.picture)


def test_ctrl_z_during_a_stroke_cancels_it_and_the_release_does_not_undo_the_undo(studio, qtbot):
    view, doc = studio.inputs_pane.canvas_view, studio.doc
    tool = studio.inputs_pane.mask_tool()
    tool.set_size(5)
    _final_after(studio, qtbot, lambda: _stroke(view, [(10.5, 10.5), (20.5, 10.5)]))
    first, steps = _mask(studio), doc.undo_stack.count()
    _stroke(view, [(10.5, 40.5), (20.5, 40.5)], release=False)
    assert tool.stroking
    with qtbot.waitSignal(studio.renderer.failed, timeout=10000):  # nothing to fill once undone
        qtbot.keyClick(studio, Qt.Key.Key_Z, Qt.KeyboardModifier.ControlModifier)  # the button still held
    assert not tool.stroking and _mask(studio) is None and tool.overlay.image().isNull()
    assert doc.live is None
    mouse(view, "release", (20.5, 40.5))
    assert _mask(studio) is None and doc.undo_stack.count() == steps and doc.undo_stack.canRedo()
    assert np.array_equal(studio.result_view.image, doc.image("picture"))
    doc.undo_stack.redo()
    assert _mask(studio) == first


def test_after_clear_mask_a_strokes_previews_are_pasted_into_the_picture_not_the_old_fill(studio, qtbot):
    view, bar = studio.inputs_pane.canvas_view, studio.inputs_pane.bar()
    studio.inputs_pane.mask_tool().set_size(9)
    old = _final_after(studio, qtbot, lambda: _stroke(view, [(10.5, 10.5), (30.5, 10.5)]))
    source = studio.doc.image("picture")
    assert not np.array_equal(old.image[6:15, 6:35], source[6:15, 6:35])
    with qtbot.waitSignal(studio.renderer.failed, timeout=10000):
        qtbot.mouseClick(bar.clear_button, Qt.MouseButton.LeftButton)
    around = _previewed(studio, qtbot, view, [(60.5, 50.5), (64.5, 52.5)])
    assert np.array_equal(around[-1].image[:20, :40], source[:20, :40])  # the cleared stroke is not back
    assert np.array_equal(studio.result_view.image, around[-1].image)
    view.setFocus()
    qtbot.keyClick(view, Qt.Key.Key_Escape)
    mouse(view, "release", (64.5, 52.5))
    assert np.array_equal(studio.result_view.image, source) and studio.result_view.notice.isVisible()


def test_the_mask_overlay_is_the_masks_colour_where_painted_and_clear_elsewhere(qtbot):
    from weft.app.gui.mask_tools import MASK_RGBA, MaskOverlay

    overlay = MaskOverlay()
    mask = Mask.empty(W, H).painted_line((10, 10), (50, 30), 4)
    overlay.set_mask(mask)
    image = overlay.image().convertToFormat(QImage.Format.Format_RGBA8888)
    rgba = np.frombuffer(image.constBits(), np.uint8).reshape(H, image.bytesPerLine() // 4, 4)[:, :W]
    assert (rgba[mask.bits] == MASK_RGBA).all() and not rgba[~mask.bits].any()
    # a dab's box redrawn alike
    more = mask.painted_line((60, 50), (70, 55), 3)
    overlay.update_box(more, (50, 40, 80, 64))
    image = overlay.image().convertToFormat(QImage.Format.Format_RGBA8888)
    rgba = np.frombuffer(image.constBits(), np.uint8).reshape(H, image.bytesPerLine() // 4, 4)[:, :W]
    assert (rgba[more.bits] == MASK_RGBA).all() and not rgba[~more.bits].any()


def test_a_background_autosave_that_fails_says_so_in_one_line(studio, qtbot, private_recovery):
    """The autosave timer's write runs on a worker: a failure (here the recovery folder's place is
    taken by a file) still reaches the status bar, in one line, and the studio goes on."""
    private_recovery.parent.mkdir(parents=True, exist_ok=True)
    private_recovery.write_text("not a folder")
    studio.files.autosave_throttle.setTimeout(10)
    with qtbot.waitSignal(
        studio.statusBar().messageChanged, timeout=10000, check_params_cb=lambda text: "autosave failed" in text
    ) as said:
        _stroke(studio.inputs_pane.canvas_view, [(20.5, 20.5), (30.5, 25.5)])
    text = said.args[0]
    assert text.startswith(f"{studio.files.recovery_file}: autosave failed (") and "\n" not in text
    assert _mask(studio) is not None  # the edit stands


def test_a_strokes_preview_states_only_figures_of_the_whole_image(qtbot, make_window):
    """The real fill, painted with the mouse: its preview around the stroke renders a crop, so it
    must not state the crop's hole as the image's ("filled 9.4 % of the image" while the stroke
    covered 1.3 % of it, seen in the studio); on release the full result states the image's own."""
    from weft.core.studio import AROUND_SIDE

    with _fill_in_the_studio(make_window, qtbot) as window:
        view, doc = window.inputs_pane.canvas_view, window.doc
        h, w = doc.image("image").shape[:2]
        assert max(h, w) > AROUND_SIDE  # (the crop is a part of the image)
        view.actual_size()
        view.centerOn(w / 2, h / 2)
        window.inputs_pane.mask_tool().set_size(9)
        y = h / 2 + 0.5
        around = _previewed(window, qtbot, view, [(w * 0.4, y), (w * 0.5, y)], timeout=30000)
        text = window.status.result_label.full_text()
        assert text.startswith("preview around the stroke") and "crop" in text, text
        assert "of the image" not in text, text  # the crop's hole fraction is not the image's
        studio = doc.studio
        for key, value in around[-1].figures.items():  # the crop's own figures ...
            figure = studio.figures.get(key)
            if figure is not None and not getattr(figure, "whole", False) and not isinstance(value, (list, dict)):
                assert figure.render(value) not in text, text  # ... are not stated as the image's
        assert text.endswith("the image's figures on release"), text
        # the engine is not stated either: 'auto' picks it for the part it fills (a grey crop of a colour
        # picture gets quilt, the picture patchmatch)
        assert doc.current_params.engine == "auto" and "engine" not in text, text
        result = _final_after(window, qtbot, lambda: mouse(view, "release", (w * 0.5, y)))
        hole = doc.value("mask").bits
        text = window.status.result_label.full_text()
        assert studio.figures["hole_fraction"].render(round(float(hole.mean()), 4)) in text, text  # the image's
        assert result.figures["hole_pixels"] == int(hole.sum())


def test_a_crops_status_keeps_the_figures_its_method_marks_as_the_whole_images(qtbot):
    """``Figure.whole``: a figure that does not depend on the part rendered (a parameter) is stated
    for a stroke's preview too; the rest only with the full result."""
    from weft.app.gui.render import Shown, describe

    method = Method(
        name="whole-figures",
        summary="figures",
        params=MeanFillParams,
        inputs=(InputSpec("picture", "the picture"),),
        run=_mean_fill,
        studio=Studio(
            title="Whole figures",
            canvas="picture",
            rank=300,
            figures={"engine": Figure("engine", whole=True), "hole_pixels": Figure("filled", "px")},
        ),
    )
    registry.register(method)
    try:
        figures = {"engine": "quilt", "hole_pixels": 40, "canvas": [80, 64]}
        image = np.zeros((H, W, 3), np.float32)
        crop = describe(Shown(image, 1, 0.012, figures, False, method=method.name, crop=(40, 30, 40, 30)))
        assert (
            crop == "preview around the stroke in 12 ms — its 40x30 crop: engine quilt; the image's figures on release"
        )
        full = describe(Shown(image, 2, 0.5, figures, True, method=method.name))
        assert full == f"result {W}x{H} in 500 ms — engine quilt, filled 40 px"
        only_whole = describe(
            Shown(image, 3, 0.012, {"engine": "quilt"}, False, method=method.name, crop=(40, 30, 20, 15))
        )
        assert only_whole == "preview around the stroke in 12 ms — its 40x30 crop (rendered at 20x15): engine quilt"
    finally:
        registry.unregister(method.name)


def test_a_renders_inputs_are_built_on_its_worker_not_the_gui_thread(studio, qtbot, monkeypatch):
    """A painted mask's float image, a stroke's crop and a slider preview's reduction are built by
    the render job on its worker: at 4096² they stalled the GUI thread 0.15-0.57 s per stroke preview."""
    import threading

    import weft.core.request as core_request

    on_gui: dict[str, list[bool]] = {"to_image": [], "crop_around": [], "reduce_for_preview": []}

    def recorded(name, real):
        def wrapper(*args, **kwargs):
            on_gui[name].append(threading.current_thread() is threading.main_thread())
            return real(*args, **kwargs)

        return wrapper

    monkeypatch.setattr(Mask, "to_image", recorded("to_image", Mask.to_image))
    monkeypatch.setattr(core_request, "crop_around", recorded("crop_around", core_request.crop_around))
    reduce = recorded("reduce_for_preview", core_request.reduce_for_preview)
    monkeypatch.setattr(core_request, "reduce_for_preview", reduce)
    view = studio.inputs_pane.canvas_view
    studio.inputs_pane.mask_tool().set_size(5)
    _previewed(studio, qtbot, view, [(10.5, 10.5), (14.5, 12.5)])
    _final_after(studio, qtbot, lambda: mouse(view, "release", (14.5, 12.5)))
    _slider_previewed(studio, qtbot, "amount")
    qtbot.waitUntil(lambda: not studio.renderer.running(), timeout=10000)
    assert all(on_gui.values()), on_gui  # each was called ...
    assert not any(any(flags) for flags in on_gui.values()), on_gui  # ... never on the GUI thread


def test_a_strokes_later_previews_name_the_part_they_changed(studio, qtbot):
    """A stroke's first preview is a new image (a copy of what the result view shows, made on the
    job's worker, with the crop pasted) that names the part it changed and what it is a copy of
    (``over``); each later one is pasted into that same image and names the part it changed. So the
    view converts only that part (a 4096² result is neither copied on the GUI thread nor converted
    again per preview)."""
    view = studio.inputs_pane.canvas_view
    shown_before = studio.result_view.image
    picture = studio.doc.image("picture")
    assert np.array_equal(shown_before, picture)  # (nothing painted yet: the picture)
    studio.inputs_pane.mask_tool().set_size(5)
    around = _previewed(studio, qtbot, view, [(10.5, 10.5), (14.5, 12.5)])
    first = around[0]
    assert first.over is shown_before and first.image is not shown_before and first.changed is not None
    x0, y0, x1, y1 = first.changed
    assert x0 < 10 < x1 and y0 < 10 < y1 and (x1 - x0) * (y1 - y0) < W * H
    outside = np.ones((H, W), bool)
    outside[y0:y1, x0:x1] = False
    assert np.array_equal(first.image[outside], picture[outside])  # the copy, changed only in its part
    assert not np.array_equal(first.image[y0:y1, x0:x1], picture[y0:y1, x0:x1])  # the stroke, filled
    assert np.array_equal(picture, shown_before) and shown_before is picture  # the picture is not touched
    mouse(view, "move", (40.5, 40.5))

    def covers_the_latest_dab() -> bool:  # (a preview of the earlier dabs may come first: dabs coalesce)
        box = around[-1].changed if len(around) > 1 else None
        return box is not None and box[0] < 40 < box[2] and box[1] < 40 < box[3]

    qtbot.waitUntil(covers_the_latest_dab, timeout=10000)
    last = around[-1]
    assert last.image is around[0].image and last.changed is not None and last.over is last.image
    x0, y0, x1, y1 = last.changed
    assert x0 < 40 < x1 and y0 < 40 < y1 and (x1 - x0) * (y1 - y0) < W * H
    assert studio.result_view.image is last.image
    _final_after(studio, qtbot, lambda: mouse(view, "release", (40.5, 40.5)))


def _large_picture(studio, qtbot, tmp_path, w=480, h=360, at=(105, 102)):
    """Open a ``w`` x ``h`` picture in the studio (nothing painted), zoomed 4x around ``at``."""
    path = tmp_path / "large.png"
    save_image(path, np.random.default_rng(5).random((h, w, 3)).astype(np.float32))
    with qtbot.waitSignal(studio.renderer.failed, timeout=10000):  # nothing to fill yet
        studio.open_input("picture", str(path))
    view = studio.inputs_pane.canvas_view
    qtbot.waitUntil(lambda: view.image is not None and view.image.shape[:2] == (h, w), timeout=10000)
    view.actual_size()
    view.zoom_by(4.0)
    view.centerOn(*at)
    return view


def test_a_strokes_preview_job_gets_the_part_of_the_mask_around_it_not_the_whole_mask(
    studio, qtbot, tmp_path, monkeypatch
):
    """The job of a preview around a stroke is given the part of the stroke's mask its crop can reach
    (``around_region``), cut on the GUI thread, never the whole mask (at 4096² a 64 MB float image per
    preview); the whole mask is made into an image only for the full render on release."""
    import weft.core.request as core_request
    from weft.core.studio import around_region

    w, h = 480, 360
    view = _large_picture(studio, qtbot, tmp_path, w, h)
    calls, images = [], []

    def recorded_crop(studio_, inputs, params, stroke, **kwargs):
        calls.append((set(inputs), stroke, kwargs.get("mask_part")))
        return crop_around(studio_, inputs, params, stroke, **kwargs)

    crop_around = core_request.crop_around
    monkeypatch.setattr(core_request, "crop_around", recorded_crop)
    to_image = Mask.to_image
    monkeypatch.setattr(Mask, "to_image", lambda self: images.append(self.shape) or to_image(self))
    studio.inputs_pane.mask_tool().set_size(9)  # radius 4
    CALLS.clear()
    around = _previewed(studio, qtbot, view, [(100.5, 100.5), (110.5, 104.5)])
    names, stroke, part = calls[0]
    assert "hole" not in names and "picture" in names  # the mask is not among the job's whole inputs
    bits, (x0, y0) = part
    rx0, ry0, rx1, ry1 = around_region(stroke, w, h)
    assert (x0, y0) == (rx0, ry0) and bits.shape == (ry1 - ry0, rx1 - rx0)
    assert bits.size * 10 < w * h  # a part, not the mask
    # the first preview's part is the press's dab, exactly
    dab = Mask.empty(w, h).painted_line((100, 100), (100, 100), 4)
    assert np.array_equal(bits, dab.bits[ry0:ry1, rx0:rx1])
    assert CALLS and max(CALLS[0]) < max(bits.shape)  # the method ran on a crop inside that part
    assert images == []  # no mask was made into a whole image for a preview
    shown = around[-1]
    x0, y0, x1, y1 = shown.changed
    assert x0 <= 96 and y0 <= 96 and x1 >= 105 and y1 >= 105 and (x1 - x0) * (y1 - y0) * 10 < w * h
    result = _final_after(studio, qtbot, lambda: mouse(view, "release", (110.5, 104.5)))
    assert images == [(h, w)]  # the full render's mask, once (on its worker)
    expected = Mask.empty(w, h).painted_line((100, 100), (100, 100), 4).painted_line((100, 100), (110, 104), 4)
    assert _mask(studio) == expected
    assert result.figures["hole_pixels"] == expected.area


def test_dabs_while_a_preview_runs_are_coalesced_and_the_next_preview_covers_the_latest(
    studio, qtbot, tmp_path, monkeypatch
):
    """While a stroke's preview is computed, the dabs that follow wait in one box: when it is done, one
    preview of all of them follows (the latest dab wins), not one per mouse move."""
    import threading

    import weft.core.request as core_request

    w, h = 480, 360
    view = _large_picture(studio, qtbot, tmp_path, w, h, at=(130, 102))
    gate = threading.Event()
    crop_around = core_request.crop_around
    entered = []

    def held(*args, **kwargs):
        entered.append(True)
        assert gate.wait(20)  # the first preview's job waits here until the moves are made
        return crop_around(*args, **kwargs)

    monkeypatch.setattr(core_request, "crop_around", held)
    submitted = []
    studio.renderer.submitted.connect(lambda job, slot: submitted.append(job) if slot == "preview" else None)
    around = []
    studio.renderer.around_shown.connect(around.append)
    studio.inputs_pane.mask_tool().set_size(7)  # radius 3
    points = [(100.5 + 10 * i, 100.5) for i in range(7)]
    try:
        mouse(view, "press", points[0])
        qtbot.waitUntil(lambda: bool(entered), timeout=10000)  # the press's preview runs
        for p in points[1:]:
            mouse(view, "move", p)
        assert len(submitted) == 1  # the moves wait for it
    finally:
        gate.set()

    def covers_the_last_dab() -> bool:
        box = around[-1].changed if around else None
        return box is not None and box[0] <= 157 and box[2] >= 164 and box[1] <= 97 and box[3] >= 104

    qtbot.waitUntil(covers_the_last_dab, timeout=10000)
    assert len(submitted) == 2 and len(around) == 2  # the six moves: one preview
    x0, y0, x1, y1 = around[-1].changed
    assert x0 <= 107 and x1 >= 164  # it covers every dab since the first preview
    picture = studio.doc.image("picture")
    image = around[-1].image
    assert not np.allclose(image[100, 160], picture[100, 160]) and not np.allclose(image[100, 110], picture[100, 110])
    assert np.array_equal(image[150:, :], picture[150:, :])  # nothing else changed
    _final_after(studio, qtbot, lambda: mouse(view, "release", points[-1]))
    expected = Mask.empty(w, h)
    for p0, p1 in zip([points[0]] + points[:-1], points, strict=True):
        expected = expected.painted_line((p0[0] - 0.5, p0[1] - 0.5), (p1[0] - 0.5, p1[1] - 0.5), 3)
    assert _mask(studio) == expected and np.array_equal(_painted(studio.inputs_pane.mask_tool().overlay), expected.bits)


def test_esc_restores_the_overlay_of_the_mask_a_stroke_began_on(studio, qtbot):
    """A stroke over a painted mask draws its dabs into the overlay; Esc puts back exactly the mask's
    pixels where the stroke changed them (the rest was not redrawn), brush and eraser alike."""
    view, doc = studio.inputs_pane.canvas_view, studio.doc
    tool, bar = studio.inputs_pane.mask_tool(), studio.inputs_pane.bar()
    tool.set_size(7)
    _final_after(studio, qtbot, lambda: _stroke(view, [(10.5, 20.5), (60.5, 20.5)]))
    start = _mask(studio)
    for mode, points in (
        ("brush", [(30.5, 10.5), (30.5, 40.5), (50.5, 40.5)]),
        ("eraser", [(20.5, 20.5), (40.5, 22.5)]),
    ):
        qtbot.mouseClick(bar.mode_buttons[mode], Qt.MouseButton.LeftButton)
        _stroke(view, points, release=False)
        drawn = _painted(tool.overlay)
        assert not np.array_equal(drawn, start.bits) and np.array_equal(drawn, doc.live.value.bits)
        view.setFocus()
        qtbot.keyClick(view, Qt.Key.Key_Escape)
        mouse(view, "release", points[-1])
        assert np.array_equal(_painted(tool.overlay), start.bits) and _mask(studio) is start
    # and a stroke released: the overlay is the new mask, drawn dab by dab (not rebuilt)
    qtbot.mouseClick(bar.mode_buttons["brush"], Qt.MouseButton.LeftButton)
    _final_after(studio, qtbot, lambda: _stroke(view, [(30.5, 50.5), (70.5, 50.5)]))
    assert _mask(studio) == start.painted_line((30, 50), (70, 50), 3)
    assert np.array_equal(_painted(tool.overlay), _mask(studio).bits)


@dataclass(frozen=True)
class SpreadFillParams(MeanFillParams):
    spread: int = param(None, kind="int", lo=1, hi=99, optional=True, help="auto: 3 px, more on an extended canvas")


SPREAD_FILL = Method(
    name="spread-fill",
    summary="mean fill whose auto spread grows with the canvas's margins",
    params=SpreadFillParams,
    inputs=MEAN_FILL.inputs,
    run=_mean_fill,
    studio=Studio(
        title="Spread fill",
        canvas="picture",
        preview_around="hole",
        auto=lambda params, shapes: {"spread": 3 + (params.grow.right if params.grow else 0)},
        geometry=MEAN_FILL.studio.geometry,
    ),
)


def test_an_auto_value_that_depends_on_the_margins_follows_an_edge_drag(plugin, qtbot, make_window, tmp_path):
    """An unset parameter shows the value a run resolves it to, the canvas's margins (a geometry
    parameter, edited with the mouse) included: fill's patch is 48 along an extended border, not
    the 24 it showed (or a colour picture's 7) while its run took 48. Its tooltip and the variations'
    range follow an edge drag."""
    from weft.app.gui.variations import VariationsDialog

    registry.register(SPREAD_FILL)
    try:
        window = _window_on(make_window, SPREAD_FILL.name, qtbot, _picture(tmp_path / "picture.png"))
        row = window.method_panel.params_panel.row("spread")
        assert "(now 3)" in row.editor.toolTip()
        view = window.inputs_pane.canvas_view
        view.fit()
        window.inputs_pane.mask_tool().set_size(1)  # a press 1 px outside the image drags the edge
        k = view.scale_factor()
        _final_after(window, qtbot, lambda: _screen_drag(view, (W + 1.0, H / 2), [(10 * k, 0), (20 * k, 0)]))
        assert window.doc.value("grow") == Margins(0, 0, 20, 0)
        assert "(now 23)" in row.editor.toolTip()
        dialog = VariationsDialog(window.doc, parent=window)
        qtbot.addWidget(dialog)
        dialog.combo[1].setCurrentIndex(dialog.combo[1].findText("spread"))
        assert dialog.lo[1].value() < 23 < dialog.hi[1].value()  # the grid's range centres on the resolved value
        dialog.close()
        window.shutdown()
    finally:
        registry.unregister(SPREAD_FILL.name)


def test_the_auto_patch_shows_the_patch_the_run_takes_or_none(make_window, qtbot):
    """The greyed "auto" value beside fill's patch box is the patch the result reports: on this grey
    picture the hybrid's block; with the edge guide asked for (patchmatch) its 7. (On a colour
    picture with a hole, where the pixels decide the engine, it shows no number.)"""
    with _fill_in_the_studio(make_window, qtbot) as window:
        view, doc = window.inputs_pane.canvas_view, window.doc
        h, w = doc.image("image").shape[:2]
        view.actual_size()
        view.centerOn(w / 2, h / 2)
        window.inputs_pane.mask_tool().set_size(9)
        y = h / 2 + 0.5
        first = _final_after(window, qtbot, lambda: _stroke(view, [(w * 0.4, y), (w * 0.5, y)]))
        row = window.method_panel.params_panel.row("patch")
        assert row.auto.isChecked() and doc.current_params.patch is None
        ran = first.figures["patch"]
        assert first.figures["engine"] == "hybrid" and row.editor.isVisible() and row.editor.value() == ran
        assert f"(now {ran})" in row.editor.toolTip(), (first.figures, row.editor.toolTip())
        structure = window.method_panel.params_panel.row("structure")
        result = _final_after(
            window, qtbot, lambda: structure.editor.setCurrentIndex(structure.spec.choices.index("yes"))
        )
        assert result.figures["engine"] == "patchmatch" and result.figures["patch"] == 7
        assert row.auto.isChecked() and row.editor.isVisible() and row.editor.value() == 7
        assert "(now 7)" in row.editor.toolTip()
