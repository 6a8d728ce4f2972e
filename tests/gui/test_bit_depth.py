"""16-bit pictures in the studio: a 16-bit source exports a 16-bit PNG whose recipe records the bit
depth (``weft run`` on it writes the same samples), a 16-bit RGBA TIFF says its 4th channel is alpha,
and the pixel read-out speaks 0-255 (0-65535 for a 16-bit picture)."""

import json

import cv2
import numpy as np
from PIL import Image
from PySide6.QtCore import QPointF, QRectF
from weft.app.cli import main as weft
from weft.core.geometry import Mask
from weft.core.image import file_bit_depth, read_recipe, save_image
from weft.core.studio import MASK


def _picture16(path, alpha=False):
    rng = np.random.default_rng(5)
    y, x = np.mgrid[0:72, 0:96].astype(np.float32)
    img = np.stack([x / 95, y / 71, 0.5 + 0.3 * np.sin(x / 5)], axis=2) + rng.normal(0, 0.02, (72, 96, 3))
    img = np.clip(img, 0, 1).astype(np.float32)
    if alpha:
        a = np.ones((72, 96, 1), np.float32)
        a[20:40, 30:60] = 0.0
        img = np.concatenate([img, a], axis=2)
    save_image(path, img, bit_depth=16)
    return path


def test_a_16_bit_source_exports_16_bit_png_and_weft_run_reproduces_it(window, qtbot, tmp_path, capsys):
    doc = window.doc
    source = _picture16(tmp_path / "deep.png")
    doc.set_method("fill")
    g = next(g for g in doc.studio.geometry if g.kind == MASK)
    window.open_input(doc.studio.canvas, str(source))
    qtbot.waitUntil(
        lambda: doc.item(doc.studio.canvas) is not None and doc.item(doc.studio.canvas).path == str(source),
        timeout=10000,
    )
    h, w = doc.image(doc.studio.canvas).shape[:2]
    with qtbot.waitSignal(window.renderer.shown, timeout=60000, check_params_cb=lambda s: s.final):
        doc.set_mask(g.key, Mask.empty(w, h).painted_line((30, 30), (60, 34), 6), "Brush stroke")
    out = tmp_path / "out.png"
    assert window.files.export_result(str(out))
    assert file_bit_depth(out) == 16
    assert json.loads(read_recipe(out))["bit_depth"] == 16
    again = tmp_path / "again.png"
    assert weft(["run", str(out), "-o", str(again)]) == 0, capsys.readouterr().err
    a, b = (cv2.imread(str(p), cv2.IMREAD_UNCHANGED) for p in (out, again))
    assert a.dtype == b.dtype == np.uint16 and np.array_equal(a, b)


def test_an_8_bit_source_exports_8_bit_png_that_records_it(window, qtbot, tmp_path, capsys):
    out = tmp_path / "out.png"
    assert window.files.export_result(str(out))
    assert file_bit_depth(out) == 8 and json.loads(read_recipe(out))["bit_depth"] == 8
    again = tmp_path / "again.png"
    assert weft(["run", str(out), "-o", str(again)]) == 0, capsys.readouterr().err
    assert np.array_equal(cv2.imread(str(out), cv2.IMREAD_UNCHANGED), cv2.imread(str(again), cv2.IMREAD_UNCHANGED))


def test_a_16_bit_rgba_tiff_marks_its_alpha(tmp_path, capsys):
    """weft fill of a 16-bit RGBA picture with a transparent hole, written as TIFF: ExtraSamples says
    the 4th channel is unassociated alpha (ImageMagick and OpenCV warned without it)."""
    source = _picture16(tmp_path / "hole.png", alpha=True)
    out = tmp_path / "filled.tif"
    assert weft(["fill", str(source), "-o", str(out), "--seed", "1"]) == 0, capsys.readouterr().err
    with Image.open(out) as im:
        assert im.tag_v2.get(338) == (2,) and im.tag_v2.get(258) == (16, 16, 16, 16)
    a = cv2.imread(str(out), cv2.IMREAD_UNCHANGED)
    assert a.shape == (72, 96, 4) and a.dtype == np.uint16


def test_transparency_shows_as_a_checkerboard_with_its_outline(window, qtbot, tmp_path):
    """An RGBA picture's transparent part shows a checkerboard (not the colour stored under alpha 0)
    and its outline, as image editors show it."""
    rgba = np.zeros((72, 96, 4), np.float32)
    rgba[..., 0] = 1.0  # pure red everywhere, also under the hole
    rgba[..., 3] = 1.0
    rgba[20:40, 30:60, 3] = 0.0
    path = tmp_path / "holed.png"
    save_image(path, rgba)
    doc = window.doc
    doc.set_method("fill")
    window.open_input(doc.studio.canvas, str(path))
    qtbot.waitUntil(
        lambda: doc.item(doc.studio.canvas) is not None and doc.item(doc.studio.canvas).path == str(path), timeout=10000
    )
    view = window.inputs_pane.canvas_view
    qtbot.waitUntil(lambda: view.image is not None and view.image.shape[:2] == (72, 96), timeout=5000)
    view.actual_size()
    view.zoom_by(4.0)
    view.centerOn(45, 30)
    qtbot.wait(20)
    assert view.transparency.path().boundingRect() == QRectF(30, 20, 30, 20)
    shot = view.viewport().grab().toImage()

    def colour(x, y):
        p = view.mapFromScene(QPointF(x, y))
        c = shot.pixelColor(p)
        return c.red(), c.green(), c.blue()

    inside = {colour(31 + i * 0.9, 21 + j * 0.9) for i in range(28) for j in range(16)}
    assert (255, 0, 0) not in inside  # the red under alpha 0 is not shown ...
    assert {(153, 153, 153), (204, 204, 204)} <= inside  # ... a checkerboard is
    assert colour(10, 10) == (255, 0, 0)  # the opaque part as it is


def test_the_pixel_read_out_counts_0_255_and_0_65535_for_16_bit(window, qtbot, tmp_path):
    from PySide6.QtCore import Qt

    from .helpers import mouse

    view = window.result_view
    view.actual_size()
    view.zoom_by(4.0)
    view.centerOn(10.5, 20.5)
    mouse(view, "move", (10.5, 20.5), buttons=Qt.MouseButton.NoButton)
    expected = " ".join(str(int(round(float(c) * 255))) for c in view.image[20, 10])
    assert window.status.pixel_label.toolTip() == f"result  x 10  y 20  {expected}"
    source = _picture16(tmp_path / "deep.png")
    doc = window.doc
    window.open_input(doc.studio.canvas, str(source))
    canvas = window.inputs_pane.canvas_view
    qtbot.waitUntil(lambda: canvas.image is not None and canvas.image.shape[:2] == (72, 96), timeout=10000)
    canvas.actual_size()
    canvas.zoom_by(4.0)
    canvas.centerOn(40.5, 30.5)
    mouse(canvas, "move", (40.5, 30.5), buttons=Qt.MouseButton.NoButton)
    stored = cv2.imread(str(source), cv2.IMREAD_UNCHANGED)[30, 40][::-1]  # (BGR -> RGB)
    assert window.status.pixel_label.toolTip() == (
        f"{canvas.title}  x 40  y 30  {' '.join(str(int(v)) for v in stored)}  (16-bit)"
    )
    assert window.status.pixel_label.text() == window.status.pixel_label.toolTip()  # whole, not elided
