"""A result carries its recipe; geometry belongs to its method; the seed is an edit."""

import dataclasses
import json
import threading

import numpy as np
from weft.core.image import load_image, read_recipe


def _slow(method, started):
    def run(inputs, params, *, rng=None, progress=None, cancel=None):
        started.set()
        while True:
            cancel.raise_if_cancelled()
            threading.Event().wait(0.01)

    return dataclasses.replace(method, run=run)


def _cancelled_render(window, qtbot, monkeypatch):
    """Show a result with p 0.3, then set p 0.6 and cancel its render: the panel says 0.6, the
    pixels on screen are 0.3's. Returns the shown result."""
    doc = window.doc
    doc.set_param("p", 0.3)
    qtbot.waitUntil(
        lambda: window.renderer.last.final and window.renderer.last.recipe.params["p"] == 0.3, timeout=20000
    )
    shown = window.renderer.last
    started = threading.Event()
    monkeypatch.setitem(doc.methods, "fast", _slow(doc.methods["fast"], started))
    doc.set_param("p", 0.6)  # its render is cancelled: the panel says 0.6, the pixels are 0.3's
    qtbot.waitUntil(started.is_set, timeout=5000)
    window.renderer.cancel()
    qtbot.waitUntil(lambda: not window.renderer.runner.busy("final"), timeout=5000)
    assert window.renderer.last is shown and doc.current_params.p == 0.6
    return shown


def test_export_after_a_cancelled_render_writes_the_recipe_of_the_shown_pixels(window, qtbot, tmp_path, monkeypatch):
    shown = _cancelled_render(window, qtbot, monkeypatch)
    out = tmp_path / "out.png"
    assert window.files.export_result(str(out))
    recipe = json.loads(read_recipe(out))
    assert recipe["params"]["p"] == 0.3 and recipe["seed"] == shown.recipe.seed
    assert np.array_equal(load_image(out).image, np.round(shown.image * 255) / 255)
    recipe_file = tmp_path / "r.json"
    assert window.files.export_recipe(str(recipe_file))
    assert json.loads(recipe_file.read_text())["params"]["p"] == 0.3


def test_compare_shows_the_input_of_the_shown_result(window, qtbot, monkeypatch):
    doc = window.doc
    old_target = doc.image("target")
    assert window.renderer.last.before is old_target and window.result_view.compare_image is old_target
    started = threading.Event()
    monkeypatch.setitem(doc.methods, "fast", _slow(doc.methods["fast"], started))
    doc.set_input("target", None, np.zeros((40, 50, 3), np.float32))  # its render never finishes
    qtbot.waitUntil(started.is_set, timeout=5000)
    window.renderer.cancel()
    assert window.result_view.compare_image is old_target  # still the shown result's own input


def test_a_square_stays_with_its_method(window, qtbot):
    doc = window.doc
    photo = doc.image("photo")
    doc.set_method("affine")
    doc.set_square((8, 8, 32))  # affine's prototype
    assert doc.run_params().prototype == (8, 8, 32)
    doc.set_method("nfpt")  # no square here: nothing crops the photo, no region in the recipe
    assert doc.square is None and doc.region() is None
    assert doc.method_inputs()["photo"].shape == photo.shape
    assert doc.recipe().region is None
    doc.set_method("fast")  # fast's source region is its own, still unset
    assert doc.square is None and doc.recipe().region is None
    assert doc.method_inputs()["texture"].shape == doc.image("texture").shape
    doc.set_square((0, 0, 20))
    doc.set_method("affine")
    assert doc.square == (8, 8, 32) and doc.run_params().prototype == (8, 8, 32)
    doc.set_method("fast")
    assert doc.region() == (0, 0, 20)


def test_lines_stay_with_their_method(window):
    doc = window.doc
    doc.set_method("nfpt")
    doc.set_lines([[1, 1, 30, 1]], [[0, 0, 20, 0]])
    assert len(doc.run_params().lines) == 1
    doc.set_method("fast")
    assert doc.image_lines == [] and doc.lines.complete() is None
    doc.set_method("nfpt")
    assert doc.image_lines == [[1.0, 1.0, 30.0, 1.0]]


def test_a_seed_change_is_an_undo_step_and_unsaved(window, qtbot):
    doc = window.doc
    doc.undo_stack.setClean()
    old = doc.seed
    window.method_panel.seed_box.setValue(old + 41)
    assert doc.seed == old + 41 and doc.undo_stack.count() == 1 and not doc.undo_stack.isClean()
    assert "*" in window.windowTitle()
    doc.undo_stack.undo()
    assert doc.seed == old and window.method_panel.seed_box.value() == old and doc.undo_stack.isClean()
    doc.undo_stack.redo()
    assert doc.seed == old + 41 and window.method_panel.seed_box.value() == old + 41


def test_the_affine_square_is_drawn_on_the_prototype_image_once_one_is_open(window, qtbot):
    from .helpers import drag

    doc = window.doc
    doc.set_method("affine")
    texture_view = window.inputs_pane.views["texture"]
    assert texture_view.tool is not None and texture_view.tool.square is None
    other = np.random.default_rng(2).random((96, 96, 3)).astype(np.float32)
    doc.set_input("prototype_image", None, other)
    view = window.inputs_pane.views["prototype_image"]
    assert view.tool is not None and texture_view.tool is None  # the square moved to the prototype image
    window.inputs_pane.tabs.setCurrentIndex(0)
    view.actual_size()
    view.zoom_by(2.0)
    view.centerOn(30, 30)
    drag(view, (10.2, 10.2), (42.2, 42.2))
    assert doc.square == (10, 10, 32)
    qtbot.waitUntil(
        lambda: window.renderer.last.final and window.renderer.last.figures.get("prototype") == [10, 10, 32],
        timeout=30000,
    )


def test_apply_to_folder_takes_the_recipe_of_the_shown_pixels(window, qtbot, monkeypatch):
    from weft.app.gui.batch_dialog import BatchDialog

    _cancelled_render(window, qtbot, monkeypatch)
    window.open_batch_dialog()
    dialog = window.findChild(BatchDialog)
    assert dialog.recipe.params["p"] == 0.3 and dialog.recipe_source().params["p"] == 0.3
    dialog.close()
