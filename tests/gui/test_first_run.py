"""The studio on a first run: the method on screen prepares its kernels in its own render, says so in
words on the result (not a bare 0 %), leaves the compile out of the render time, and only then are
the other methods warmed up in the background.

The "compile" is the fast method's warm-up raising numba's compile events
(``registry.compile_started/compile_ended``) and held open on a ``threading.Event`` until the test
has seen the words: no timing."""

import dataclasses
import threading
import time

import numpy as np
import pytest
from weft.app.gui.document import InputImage
from weft.app.gui.main_window import MainWindow
from weft.core import registry


@pytest.fixture
def cold_fast(monkeypatch):
    """'fast' whose kernels are not loaded yet; its warm-up compiles until ``release`` is set."""
    release = threading.Event()
    started = threading.Event()
    real = registry.get("fast")

    def warm_up():
        registry.compile_started()
        started.set()
        try:
            release.wait(60)
        finally:
            registry.compile_ended()

    monkeypatch.setitem(registry._loaded, "fast", dataclasses.replace(real, warm_up=warm_up))
    monkeypatch.setattr(registry, "_warm", set())
    background = []
    monkeypatch.setattr(registry, "warm_up_all", lambda first=None, cancel=None: background.append(first) or [])
    return release, started, background


def test_first_render_prepares_in_words_then_shows_the_result_and_warms_the_rest(qtbot, settings, cold_fast):
    release, started, background = cold_fast
    window = MainWindow(settings=settings, load_defaults=False)
    qtbot.addWidget(window)
    window.show()
    rng = np.random.default_rng(1)
    window.doc.put_input("texture", InputImage(None, rng.random((32, 32, 3)).astype(np.float32)))
    window.doc.put_input("target", InputImage(None, rng.random((40, 48, 3)).astype(np.float32)))
    assert window.doc.method == "fast"
    window.renderer.final(now=True)

    words = "preparing the fast method — first run only"
    seen = []
    window.renderer.preparing.connect(seen.append)
    qtbot.waitUntil(
        lambda: window.result_view.notice.isVisible() and window.result_view.notice.text() == words, timeout=20000
    )
    held_from = time.perf_counter()
    assert seen == ["loading the fast method", words]  # words at once, then what it turned out to be
    qtbot.waitUntil(lambda: window.status.progress_bar.isVisible(), timeout=20000)
    assert window.status.progress_bar.maximum() == 0  # a busy bar, no percentage
    assert not window.status.progress_bar.isTextVisible() and window.status.progress_bar.toolTip() == words
    assert window.renderer.runner.latest("warm-up") is None  # nothing competes with the visible method
    assert window.renderer.last is None

    with qtbot.waitSignal(window.renderer.shown, timeout=30000) as shown:
        held = time.perf_counter() - held_from  # the compile lasted at least this long
        release.set()
    result = shown.args[0]
    assert result.final and result.image.shape == (40, 48, 3)
    assert result.compiled and result.prepared >= held  # the compile, measured apart ...
    message = window.status.result_label.full_text()
    assert message.startswith(f"result 48x40 in {result.seconds * 1000:.0f} ms (after preparing its kernels for ")
    assert message.split(" — ")[0].endswith(" s, first run only)")  # ... and not counted as render time
    qtbot.waitUntil(lambda: not window.result_view.notice.isVisible(), timeout=5000)
    assert window.status.progress_bar.maximum() == 1000 and window.status.progress_bar.isTextVisible()
    assert registry.is_warm("fast")
    qtbot.waitUntil(lambda: background == ["fast"], timeout=10000)  # the others, once the result is in

    # a second render: kernels loaded, no words, nothing prepared
    with qtbot.waitSignal(window.renderer.shown, timeout=30000) as again:
        window.renderer.final(now=True)
    assert again.args[0].prepared == 0.0 and not again.args[0].compiled
    assert "preparing" not in window.status.result_label.full_text()
    window.doc.undo_stack.setClean()
    window.shutdown()


def test_a_warm_method_renders_without_preparing(qtbot, settings, cold_fast, monkeypatch):
    release, started, background = cold_fast
    registry._warm.add("fast")  # its kernels already loaded in this process
    window = MainWindow(settings=settings, load_defaults=False)
    qtbot.addWidget(window)
    seen = []
    window.renderer.preparing.connect(seen.append)
    rng = np.random.default_rng(2)
    window.doc.put_input("texture", InputImage(None, rng.random((32, 32)).astype(np.float32)))
    window.doc.put_input("target", InputImage(None, rng.random((24, 24)).astype(np.float32)))
    with qtbot.waitSignal(window.renderer.shown, timeout=30000) as shown:
        window.renderer.final(now=True)
    assert shown.args[0].prepared == 0.0 and seen == [] and not started.is_set()
    window.doc.undo_stack.setClean()
    window.shutdown()


def test_waiting_behind_another_methods_compile_says_preparing_at_once(qtbot, settings, monkeypatch):
    """The background warm-up compiles another method (holding numba's lock): a render of a cold
    method waits for it; the words come at once, and the wait is not render time."""
    release = threading.Event()
    real = registry.get("fast")
    monkeypatch.setitem(registry._loaded, "fast", dataclasses.replace(real, warm_up=lambda: release.wait(60)))
    monkeypatch.setattr(registry, "_warm", set())
    monkeypatch.setattr(registry, "warm_up_all", lambda first=None, cancel=None: [])
    window = MainWindow(settings=settings, load_defaults=False)
    qtbot.addWidget(window)
    seen = []
    window.renderer.preparing.connect(seen.append)
    rng = np.random.default_rng(3)
    window.doc.put_input("texture", InputImage(None, rng.random((32, 32)).astype(np.float32)))
    window.doc.put_input("target", InputImage(None, rng.random((24, 24)).astype(np.float32)))
    registry.compile_started()  # another thread's compile under way
    try:
        window.renderer.final(now=True)
        qtbot.waitUntil(lambda: len(seen) == 2, timeout=20000)
        assert seen == ["loading the fast method", "preparing the fast method — first run only"]
        assert window.result_view.notice.text() == seen[-1]
        with qtbot.waitSignal(window.renderer.shown, timeout=30000) as shown:
            release.set()
    finally:
        registry.compile_ended()
    assert shown.args[0].compiled and shown.args[0].prepared > 0
    assert "(after preparing its kernels for " in window.status.result_label.full_text()
    window.doc.undo_stack.setClean()
    window.shutdown()
