"""Proof that the studio learns a method from the method itself.

A method registered at run time -- it inverts the pixels of a square of its one input -- is driven
through the studio with real mouse events: it is in the method list, its square is drawn with the
mouse, it renders and previews, its exported PNG's recipe is reproduced by ``weft run``, and it
survives a session round trip. Nothing in app/gui knows it.
"""

from dataclasses import dataclass

import numpy as np
import pytest
from weft.app.cli import main as weft
from weft.core import registry
from weft.core.geometry import Square
from weft.core.image import load_image, read_recipe, save_image
from weft.core.params import Params, param
from weft.core.registry import InputSpec, Method, Result
from weft.core.studio import SQUARE, Geometry, Studio

from .helpers import drag


@dataclass(frozen=True)
class InvertParams(Params):
    square: Square = param(None, kind="geometry", type=Square, optional=True, help="the square to invert")
    amount: float = param(1.0, lo=0.0, hi=1.0, step=0.05, help="how far towards the inverse")


def _invert(inputs, params, *, rng=None, progress=None, cancel=None):
    image = inputs["picture"].copy()
    if params.square is not None:
        x, y, s = params.square
        part = image[y : y + s, x : x + s]
        image[y : y + s, x : x + s] = part + params.amount * (1.0 - 2.0 * part)
    return Result(image, {"inverted": 0 if params.square is None else params.square.side**2})


INVERT = Method(
    name="invert-square",
    summary="invert the pixels of a square",
    params=InvertParams,
    inputs=(InputSpec("picture", "the picture"),),
    run=_invert,
    studio=Studio(
        title="Invert a square",
        canvas="picture",
        geometry=(Geometry(SQUARE, on=("picture",), param="square", help="drag the square to invert"),),
    ),
)


@pytest.fixture
def plugin():
    registry.register(INVERT)
    yield INVERT
    registry.unregister(INVERT.name)


def test_a_method_registered_at_run_time_is_driven_through_the_studio(plugin, qtbot, make_window, tmp_path, capsys):
    picture = tmp_path / "picture.png"
    pixels = np.random.default_rng(3).random((64, 80, 3)).astype(np.float32)
    save_image(picture, pixels)
    window = make_window()
    try:
        box = window.method_panel.method_box
        index = box.findData(plugin.name)
        assert index >= 0 and box.itemText(index) == "Invert a square"  # in the method list
        box.setCurrentIndex(index)
        assert window.doc.method == plugin.name
        window.open_input("picture", str(picture))
        qtbot.waitUntil(lambda: window.doc.image("picture") is not None, timeout=10000)
        qtbot.waitUntil(lambda: window.renderer.last is not None and window.renderer.last.final, timeout=10000)
        assert np.allclose(window.renderer.last.image, load_image(picture).image)  # no square yet: unchanged

        # the square is drawn with the mouse on the canvas
        view = window.inputs_pane.canvas_view
        view.actual_size()
        view.zoom_by(2.0)
        view.centerOn(30, 30)
        drag(view, (10.2, 12.2), (30.2, 28.2))
        assert window.doc.square == (10, 12, 20)
        assert window.doc.run_params().square == Square(10, 12, 20)
        qtbot.waitUntil(
            lambda: window.renderer.last.final and window.renderer.last.figures.get("inverted") == 400, timeout=10000
        )
        shown = window.renderer.last.image
        source = load_image(picture).image
        assert np.allclose(shown[12:32, 10:30], 1.0 - source[12:32, 10:30], atol=1e-6)
        assert np.array_equal(shown[40:], source[40:])

        # a slider drag previews, the release renders full size
        results = []
        window.renderer.shown.connect(results.append)
        row = window.method_panel.params_panel.row("amount")
        row.editor.setSliderDown(True)
        row.editor.setValue(0.5)
        qtbot.waitUntil(lambda: any(not r.final for r in results), timeout=10000)
        row.editor.setSliderDown(False)
        row.editor.sliderReleased.emit()
        qtbot.waitUntil(lambda: results[-1].final and window.doc.current_params.amount == 0.5, timeout=10000)

        # export: the PNG's recipe is the result's, and weft run reproduces it
        out = tmp_path / "out.png"
        assert window.files.export_result(str(out))
        assert '"square": [10, 12, 20]' in read_recipe(out)
        again = tmp_path / "again.png"
        assert weft(["run", str(out), "-o", str(again)]) == 0, capsys.readouterr().err
        assert np.array_equal(load_image(out).image, load_image(again).image)

        # a session round trip keeps its square and parameter
        session = tmp_path / "s.weft.json"
        assert window.files.save_session(str(session))
        window.doc.set_square(None)
        window.doc.set_param("amount", 1.0)
        assert window.files.open_session(str(session))
        assert window.doc.method == plugin.name and window.doc.square == (10, 12, 20)
        assert window.doc.current_params.amount == 0.5
    finally:
        window.shutdown()
