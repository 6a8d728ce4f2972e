"""`weft` with no arguments opens the studio on the bundled examples, with a first result."""

from PySide6.QtWidgets import QApplication
from weft.app.cli import main
from weft.app.gui.main_window import MainWindow

from .helpers import no_job_threads


def test_weft_without_arguments_opens_the_studio(qtbot, monkeypatch):
    seen = {}

    def fake_exec(app):
        # Stands in for the event loop: wait for the first result, then "quit".
        windows = [w for w in QApplication.topLevelWidgets() if isinstance(w, MainWindow) and w.isVisible()]
        assert len(windows) == 1
        window = windows[0]
        qtbot.waitUntil(lambda: window.renderer.last is not None and window.renderer.last.final, timeout=20000)
        seen["inputs"] = set(window.doc.inputs)
        seen["examples"] = window.example_list.count()
        window.close()
        return 0

    monkeypatch.setattr(QApplication, "exec", fake_exec)
    assert main([]) == 0
    assert {"texture", "target"} <= seen["inputs"] and seen["examples"] >= 10
    assert no_job_threads()
