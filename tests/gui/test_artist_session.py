"""Issue 14: the studio as an artist meets it — each bug's test drives the window with real events."""

import dataclasses

from PySide6.QtCore import Qt

from weft.core.errors import WeftError


def _failing(method):
    def run(inputs, params, *, rng=None, progress=None, cancel=None):
        raise WeftError("the kernel refused these settings")

    return dataclasses.replace(method, run=run)


def test_a_failed_render_marks_the_result_stale_until_a_render_succeeds(window, qtbot, monkeypatch):
    view = window.result_view
    good = window.doc.methods["fast"]
    assert not view.stale.isVisible()
    monkeypatch.setitem(window.doc.methods, "fast", _failing(good))
    with qtbot.waitSignal(window.renderer.failed, timeout=10000):
        qtbot.keyClick(window, Qt.Key.Key_F5)  # View > Render
    assert view.stale.isVisible() and "the kernel refused these settings" in view.stale.text()
    assert view.stale.geometry().top() == 0 and view.stale.width() == view.viewport().width()
    window.statusBar().clearMessage()  # the status bar forgets; the mark stays
    assert view.stale.isVisible()
    monkeypatch.setitem(window.doc.methods, "fast", good)
    with qtbot.waitSignal(window.renderer.shown, timeout=20000):
        qtbot.keyClick(window, Qt.Key.Key_F5)
    assert not view.stale.isVisible()


def test_unticking_auto_starts_from_the_resolved_value_and_a_disabled_slider_says_why(window, qtbot):
    doc = window.doc
    doc.set_method("quilt")  # a transfer (the studio opens a target): block resolves to 9, overlap 3
    qtbot.waitUntil(lambda: "block" in window.params_panel.rows
                    and window.params_panel.row("block").auto.isVisible(), timeout=5000)
    row = window.params_panel.row("block")
    assert row.auto.isChecked() and not row.editor.isEnabled()
    assert "auto" in row.editor.toolTip() and "now 9" in row.editor.toolTip()
    qtbot.mouseClick(row.auto, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: doc.current_params.block is not None, timeout=5000)
    assert doc.current_params.block == 9  # the resolved value, not the minimum 2
    assert row.editor.isEnabled() and row.editor.value() == 9
    assert "auto" not in row.editor.toolTip().split("\n")[0]
    window.renderer.cancel()
