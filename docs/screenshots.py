"""Render README screenshots from the real app: ``QT_QPA_PLATFORM=offscreen python docs/screenshots.py``.

Each shot opens the real main window, waits until its jobs have delivered, and grabs the window
into ``docs/images/``.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from PySide6.QtWidgets import QApplication  # noqa: E402

from app.gui.main_window import MainWindow  # noqa: E402

OUT = Path(__file__).resolve().parent / "images"


def _wait(app: QApplication, condition, timeout: float = 10.0) -> None:
    end = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > end:
            raise RuntimeError("timed out waiting for the window")
        app.processEvents()
        time.sleep(0.01)


def main() -> int:
    app = QApplication.instance() or QApplication(sys.argv[:1])
    OUT.mkdir(parents=True, exist_ok=True)
    window = MainWindow()
    window.resize(1100, 700)
    window.show()
    _wait(app, lambda: window.view.image is not None)
    target = next(i for i in range(window.example_list.count()) if window.example_list.item(i).text() == "brick")
    window.example_list.setCurrentRow(target)
    _wait(app, lambda: window.current_path is not None and window.current_path.stem == "brick")
    window.view.fit()
    app.processEvents()
    path = OUT / "main-window.png"
    window.grab().save(str(path))
    print(path)
    window.shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
