"""The weft desktop studio (PySide6). Only this package imports Qt."""

from __future__ import annotations


def run_gui(argv: list[str] | None = None, *, images: list[str] | None = None) -> int:
    """Open the main window on the bundled examples (then on ``images``, given as the current
    method's first inputs in order) and run the Qt event loop."""
    import sys

    from PySide6.QtWidgets import QApplication

    from .main_window import MainWindow

    app = QApplication.instance() or QApplication(sys.argv[:1] if argv is None else argv)
    app.setApplicationName("weft")
    app.setOrganizationName("weft")
    window = MainWindow()
    window.show()
    if images:
        window.open_images(images)
    try:
        return app.exec()
    finally:
        window.shutdown()
