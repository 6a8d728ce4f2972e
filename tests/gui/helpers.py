"""Real mouse events for the GUI tests, and a check that no worker thread is left."""

import threading

from PySide6.QtCore import QEvent, QPointF, Qt
from PySide6.QtGui import QMouseEvent
from PySide6.QtWidgets import QApplication


def mouse(view, kind: str, scene_xy, buttons=Qt.MouseButton.LeftButton, key_modifiers=Qt.KeyboardModifier.NoModifier):
    """Send a real press/move/release to ``view``'s viewport at scene (image) point ``scene_xy``."""
    pos = view.mapFromScene(QPointF(*scene_xy))
    local = QPointF(pos)
    global_ = QPointF(view.viewport().mapToGlobal(pos))
    etype = {"press": QEvent.Type.MouseButtonPress, "move": QEvent.Type.MouseMove,
             "release": QEvent.Type.MouseButtonRelease}[kind]
    button = Qt.MouseButton.NoButton if kind == "move" else Qt.MouseButton.LeftButton
    held = buttons if kind != "release" else Qt.MouseButton.NoButton
    event = QMouseEvent(etype, local, global_, button, held, key_modifiers)
    QApplication.sendEvent(view.viewport(), event)


def drag(view, start, end, steps: int = 4):
    mouse(view, "press", start)
    for i in range(1, steps + 1):
        t = i / steps
        mouse(view, "move", (start[0] + t * (end[0] - start[0]), start[1] + t * (end[1] - start[1])))
    mouse(view, "release", end)


def no_job_threads() -> bool:
    return not [t for t in threading.enumerate() if t.name.startswith("weft-job") and t.is_alive()]
