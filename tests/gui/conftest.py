"""Shared fixtures of the GUI tests: a studio window with private settings."""

import pytest
from PySide6.QtCore import QSettings
from weft.app.gui.main_window import MainWindow


@pytest.fixture(autouse=True)
def private_recovery(tmp_path, monkeypatch):
    """Every GUI test autosaves into its own folder, and the window's questions are answered yes,
    "restore" to a recovered session, and "discard" to unsaved edits (a test that cares replaces
    ``MainWindow._confirm`` or ``MainWindow._ask_unsaved`` itself)."""
    folder = tmp_path / "recovery"
    monkeypatch.setenv("WEFT_RECOVERY_DIR", str(folder))
    monkeypatch.setattr(MainWindow, "_confirm", lambda self, question: True)
    monkeypatch.setattr(MainWindow, "_ask_restore", lambda self, question: True)
    monkeypatch.setattr(MainWindow, "_ask_unsaved", lambda self, doing: "discard")
    return folder


@pytest.fixture
def settings(tmp_path):
    return QSettings(str(tmp_path / "weft.ini"), QSettings.Format.IniFormat)


@pytest.fixture
def window(qtbot, settings):
    w = MainWindow(settings=settings)
    qtbot.addWidget(w)
    w.resize(1300, 820)
    w.show()
    qtbot.waitUntil(lambda: w.renderer.last is not None and w.renderer.last.final, timeout=20000)
    yield w
    w.shutdown()
