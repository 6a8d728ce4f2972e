"""Suggest lines in the studio: a button of the lines panel (declared by the method's studio
description) proposes editable line pairs off the GUI thread, as one undo step."""

import json

import numpy as np
import pytest
from PySide6.QtCore import Qt
from weft.core.examples import RESOURCES
from weft.core.rectify.homography import apply_homography


def test_suggest_lines_button_proposes_editable_pairs_and_one_undo_removes_them(nfpt, qtbot):
    panel, doc = nfpt.inputs_pane.lines_panel, nfpt.doc
    assert panel.suggest_button.isVisible()
    before = (list(doc.image_lines), list(doc.frontal_lines))
    depth = doc.undo_stack.count()
    qtbot.mouseClick(panel.suggest_button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: doc.undo_stack.count() == depth + 1, timeout=20000)
    assert len(doc.image_lines) >= 4 and len(doc.image_lines) == len(doc.frontal_lines)
    # the suggested lines lie on the example's wall: its true homography maps them onto the photo lines
    truth = np.array(json.loads((RESOURCES / "perspective-lines.json").read_text())["homography"])
    photo_lines = np.array(doc.image_lines)
    wall = np.array([[0, 0], [511, 0], [511, 383], [0, 383]], float)
    quad = apply_homography(truth, wall)
    import cv2

    for x1, y1, x2, y2 in photo_lines:
        for p in ((x1, y1), (x2, y2)):
            assert cv2.pointPolygonTest(quad.astype(np.float32), p, True) > -3
    qtbot.waitUntil(lambda: panel.rectify_status.text() == "rectified", timeout=10000)
    w, h = doc.frontal_size
    assert panel.frontal_view.image.shape[:2] == (h, w)
    doc.undo_stack.undo()
    assert (list(doc.image_lines), list(doc.frontal_lines)) == before


def test_suggest_lines_on_a_photo_without_lines_says_so_and_keeps_the_lines(nfpt, qtbot):
    panel, doc = nfpt.inputs_pane.lines_panel, nfpt.doc
    rng = np.random.default_rng(0)
    noise = np.clip(0.5 + 0.1 * rng.standard_normal((240, 320)), 0, 1).astype(np.float32)
    doc.set_input("photo", None, noise)
    before = (list(doc.image_lines), list(doc.frontal_lines))
    depth = doc.undo_stack.count()
    messages = []
    panel.message.connect(messages.append)
    qtbot.mouseClick(panel.suggest_button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: bool(messages), timeout=20000)
    assert messages == ["no two families of straight lines found: draw feature lines"]
    assert doc.undo_stack.count() == depth
    assert (list(doc.image_lines), list(doc.frontal_lines)) == before


# -- the button belongs to whatever method declares a suggestion (the studio knows no method) -------

from dataclasses import dataclass  # noqa: E402

from weft.core import registry  # noqa: E402
from weft.core.geometry import FeatureLines  # noqa: E402
from weft.core.image import save_image  # noqa: E402
from weft.core.params import Params, param  # noqa: E402
from weft.core.registry import InputSpec, Method, Result  # noqa: E402
from weft.core.studio import LINES, Geometry, Studio  # noqa: E402

_PROPOSED = FeatureLines(
    [[5, 5, 50, 6], [6, 40, 52, 41], [5, 5, 6, 40], [50, 6, 52, 41]],
    [[0, 0, 63, 0], [0, 47, 63, 47], [0, 0, 0, 47], [63, 0, 63, 47]],
    (64, 48),
)


@dataclass(frozen=True)
class _TraceParams(Params):
    trace: FeatureLines = param(None, kind="geometry", type=FeatureLines, optional=True, help="lines to trace")


def _method(suggest):
    return Method(
        name="trace-lines",
        summary="returns its picture",
        params=_TraceParams,
        inputs=(InputSpec("picture", "the picture"),),
        run=lambda inputs, params, **_: Result(inputs["picture"].copy(), {}),
        studio=Studio(
            title="Trace lines",
            canvas="picture",
            geometry=(Geometry(LINES, on=("picture",), param="trace", help="draw lines", suggest=suggest),),
        ),
    )


@pytest.mark.parametrize("declared", [True, False])
def test_a_plugin_method_gets_the_button_only_when_it_declares_a_suggestion(declared, qtbot, make_window, tmp_path):
    method = _method((lambda image: (_PROPOSED, "four pairs")) if declared else None)
    registry.register(method)
    picture = tmp_path / "picture.png"
    save_image(picture, np.random.default_rng(2).random((60, 70, 3)).astype(np.float32))
    window = make_window()
    try:
        box = window.method_panel.method_box
        box.setCurrentIndex(box.findData(method.name))
        window.open_input("picture", str(picture))
        qtbot.waitUntil(lambda: window.doc.image("picture") is not None, timeout=10000)
        panel = window.inputs_pane.lines_panel
        assert panel.suggest_button.isVisible() == declared
        if declared:
            qtbot.mouseClick(panel.suggest_button, Qt.MouseButton.LeftButton)
            qtbot.waitUntil(lambda: len(window.doc.image_lines) == 4, timeout=10000)
            assert window.doc.frontal_size == (64, 48)
            assert window.doc.run_params().trace == _PROPOSED
    finally:
        window.shutdown()
        registry.unregister(method.name)
