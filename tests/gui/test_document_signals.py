"""The document says what changed with one signal per kind of change; an edit in progress is its
live edit; the renderer alone decides what a change renders (a preview or the full size)."""

import dataclasses

import numpy as np
import pytest
from PySide6.QtCore import Qt
from weft.app.gui.document import Document
from weft.app.gui.render import FailureKind, RenderFailure
from weft.core.errors import WeftError

SIGNALS = ("input_changed", "method_changed", "params_changed", "geometry_changed", "seed_changed", "restored")


@pytest.fixture
def heard(qtbot):
    doc = Document()
    log: list[tuple] = []
    for name in SIGNALS:
        getattr(doc, name).connect(lambda *args, n=name: log.append((n, *args)))
    doc.live_changed.connect(lambda edit: log.append(("live_changed", edit)))
    return doc, log


def test_each_kind_of_change_has_its_own_signal_and_undo_says_it_again(heard):
    doc, log = heard
    doc.set_method("affine")
    doc.set_method("fast")
    doc.set_input("texture", None, np.zeros((20, 24, 3), np.float32))
    doc.set_param("p", 0.4)
    doc.set_seed(9)
    doc.set_square((2, 3, 10))
    assert log == [
        ("method_changed",),
        ("method_changed",),
        ("input_changed", "texture"),
        ("params_changed",),
        ("seed_changed",),
        ("geometry_changed",),
    ]
    log.clear()
    doc.undo_stack.undo()  # the square
    doc.undo_stack.undo()  # the seed
    assert log == [("geometry_changed",), ("seed_changed",)] and doc.seed == 1 and doc.square is None


def test_a_slider_held_is_the_live_edit_until_it_is_let_go(heard):
    doc, log = heard
    doc.set_method("fast")
    log.clear()
    doc.drag_param("p", 0.3)
    doc.drag_param("p", 0.35)
    assert doc.live is not None and doc.live.param and doc.live.key == "p"
    assert log == [("params_changed",), ("params_changed",)]
    doc.set_param("p", 0.35)  # let go on the value it shows: no change, but the drag ended
    assert doc.live is None and log[-1] == ("live_changed", None)
    assert doc.undo_stack.count() == 1 and doc.current_params.p == 0.35  # the drag is one undo step


def test_a_geometry_dragged_is_the_live_edit_and_its_edit_replaces_it(heard):
    doc, log = heard
    doc.set_method("affine")
    log.clear()
    doc.set_live("prototype", (1, 2, 8))
    assert doc.live.value == (1, 2, 8) and not doc.live.param
    assert doc.run_params().prototype == (1, 2, 8) and doc.run_params(live=False).prototype is None
    doc.set_square((1, 2, 8))  # the release: the edit, no live_changed (the edit says it)
    assert doc.live is None and [name for name, *_ in log] == ["live_changed", "geometry_changed"]
    assert log[0][1].value == (1, 2, 8)
    doc.set_live("prototype", (4, 4, 8))
    doc.end_live()  # Esc: nothing changed
    assert doc.live is None and log[-1] == ("live_changed", None) and doc.square == (1, 2, 8)


def _slots(window):
    slots = []
    window.renderer.submitted.connect(lambda _job, slot: slots.append(slot))
    return slots


def test_the_renderer_previews_while_a_slider_is_held_and_renders_in_full_on_release(window, qtbot):
    doc = window.doc
    assert doc.method == "fast"
    slots = _slots(window)
    doc.drag_param("p", 0.3)
    qtbot.waitUntil(lambda: slots == ["preview"], timeout=5000)
    doc.set_param("p", 0.3)  # released where it was dragged to
    qtbot.waitUntil(lambda: slots[-1:] == ["final"], timeout=5000)
    qtbot.waitUntil(
        lambda: window.renderer.last.final and window.renderer.last.recipe.params["p"] == 0.3, timeout=20000
    )
    assert "preview" not in slots[slots.index("final") :]


def test_a_slider_held_and_moved_previews_then_renders_in_full_when_let_go(window, qtbot):
    row = window.method_panel.params_panel.row("n")
    slider = row.editor
    slots = _slots(window)
    slider.setSliderDown(True)  # the user holds the handle ...
    slider.setValue(slider.value() + 2)
    qtbot.waitUntil(lambda: "preview" in slots, timeout=5000)
    assert "final" not in slots
    slider.setSliderDown(False)  # ... and lets go
    qtbot.waitUntil(lambda: slots[-1:] == ["final"], timeout=5000)


def test_a_failed_render_carries_its_kind(window, qtbot, monkeypatch):
    good = window.doc.methods["fast"]

    def refuse(*args, **kwargs):
        raise WeftError("the kernel refused these settings")

    monkeypatch.setitem(window.doc.methods, "fast", dataclasses.replace(good, run=refuse))
    with qtbot.waitSignal(window.renderer.failed, timeout=10000) as failed:
        qtbot.keyClick(window, Qt.Key.Key_F5)
    failure = failed.args[0]
    assert isinstance(failure, RenderFailure) and failure.kind is FailureKind.RENDER
    assert "the kernel refused these settings" in failure.message
    assert window.result_view.stale.isVisible()  # the shown result is marked out of date
