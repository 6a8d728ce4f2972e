"""Shared fixtures of the GUI tests: a studio window with private settings."""

import pytest
from PySide6.QtCore import QSettings
from weft.app.gui.main_window import MainWindow
from weft.app.gui.questions import Questions


@pytest.fixture(autouse=True)
def private_recovery(tmp_path, monkeypatch):
    """Every GUI test autosaves into its own folder, and the window's questions are answered yes,
    "restore" to a recovered session, and "discard" to unsaved edits (a test that cares replaces
    ``Questions.confirm`` or ``Questions.ask_unsaved`` itself)."""
    folder = tmp_path / "recovery"
    monkeypatch.setenv("WEFT_RECOVERY_DIR", str(folder))
    monkeypatch.setattr(Questions, "confirm", lambda self, question: True)
    monkeypatch.setattr(Questions, "ask_restore", lambda self, question: True)
    monkeypatch.setattr(Questions, "ask_unsaved", lambda self, doing: "discard")
    return folder


@pytest.fixture
def settings(tmp_path):
    return QSettings(str(tmp_path / "weft.ini"), QSettings.Format.IniFormat)


@pytest.fixture
def make_window(qtbot, settings):
    """Make shown studio windows, each shut down after the test: ``make_window()`` opens nothing,
    ``make_window(load_defaults=True)`` the bundled examples; ``size`` is the window's size."""
    made = []

    def make(*, load_defaults: bool = False, size: tuple[int, int] = (1300, 820)) -> MainWindow:
        w = MainWindow(settings=settings, load_defaults=load_defaults)
        qtbot.addWidget(w)
        w.resize(*size)
        w.show()
        made.append(w)
        return w

    yield make
    for w in made:
        w.shutdown()


@pytest.fixture
def window(make_window, qtbot):
    """The studio as it opens on its bundled examples, its first full-size result shown."""
    w = make_window(load_defaults=True)
    qtbot.waitUntil(lambda: w.renderer.last is not None and w.renderer.last.final, timeout=20000)
    return w


@pytest.fixture
def nfpt(window, qtbot):
    """The studio switched to the nfpt method on its bundled photo, a result of it shown."""
    window.doc.set_method("nfpt")
    assert window.doc.image("photo") is not None
    qtbot.waitUntil(lambda: window.renderer.last.job_id > 0, timeout=20000)
    return window
