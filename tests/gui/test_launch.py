"""`weft` with no arguments opens the main window on the bundled examples."""

import threading

from PySide6.QtWidgets import QApplication

from app.cli import main
from app.gui.main_window import MainWindow


def test_weft_without_arguments_opens_the_examples_window(qtbot, monkeypatch):
    seen = {}

    def fake_exec(app):
        # Stands in for the event loop: let the window load its first example, then "quit".
        windows = [w for w in QApplication.topLevelWidgets() if isinstance(w, MainWindow) and w.isVisible()]
        assert len(windows) == 1
        window = windows[0]
        qtbot.waitUntil(lambda: window.view.image is not None, timeout=5000)
        seen["examples"] = window.example_list.count()
        seen["title"] = window.windowTitle()
        return 0

    monkeypatch.setattr(QApplication, "exec", fake_exec)
    assert main([]) == 0
    assert seen["examples"] >= 5 and seen["title"].endswith("— weft")
    assert not [t for t in threading.enumerate() if t.name.startswith("weft-job") and t.is_alive()]
