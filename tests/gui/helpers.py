"""Real mouse events for the GUI tests, and a check that no worker thread is left."""

import dataclasses
import threading

from PySide6.QtCore import QEvent, QPointF, Qt
from PySide6.QtGui import QMouseEvent
from PySide6.QtWidgets import QApplication


def mouse(view, kind: str, scene_xy, buttons=Qt.MouseButton.LeftButton, key_modifiers=Qt.KeyboardModifier.NoModifier):
    """Send a real press/move/release to ``view``'s viewport at scene (image) point ``scene_xy``."""
    pos = view.mapFromScene(QPointF(*scene_xy))
    local = QPointF(pos)
    global_ = QPointF(view.viewport().mapToGlobal(pos))
    etype = {
        "press": QEvent.Type.MouseButtonPress,
        "move": QEvent.Type.MouseMove,
        "release": QEvent.Type.MouseButtonRelease,
    }[kind]
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


def settle(qtbot, window, timeout: int = 30000) -> None:
    """Wait until ``window`` has no render or file load running, queued or about to start, and every
    result its workers queued for the GUI thread has been delivered: anything that was going to
    arrive has arrived, so an assertion that something did *not* happen can be made now (no fixed wait)."""
    from PySide6.QtCore import QCoreApplication

    renderer = window.renderer
    started: list[int] = []

    def idle() -> bool:
        busy = renderer.runner.busy("preview") or renderer.runner.busy("final") or window.loader.busy()
        return not (busy or renderer.running())

    def count(job_id: int, slot: str) -> None:
        started.append(job_id)

    renderer.submitted.connect(count)
    try:
        while True:
            qtbot.waitUntil(idle, timeout=timeout)
            before = len(started)
            # a job leaves the runner's books after queueing its result: deliver what is queued
            QCoreApplication.sendPostedEvents()
            QCoreApplication.processEvents()
            if idle() and len(started) == before:  # nothing delivered started another render
                return
    finally:
        renderer.submitted.disconnect(count)


def no_job_threads() -> bool:
    return not [t for t in threading.enumerate() if t.name.startswith("weft-job") and t.is_alive()]


def dead_pid() -> int:
    """The process id of a process that has ended."""
    import subprocess
    import sys

    proc = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    return int(proc.stdout)


def pretend_crashed(window) -> None:
    """Make ``window``'s recovery file look like one left by a window that died (its lock names a
    process that has ended): as after a crash, a new window may offer it."""
    import json

    from weft.app.gui import recovery

    window.files.autosave_throttle.cancel()
    lock = recovery.lock_path(window.files.recovery_file)
    owner = json.loads(lock.read_text(encoding="utf-8"))
    owner.update(pid=dead_pid(), started=None)
    lock.write_text(json.dumps(owner), encoding="utf-8")
    window.files._owns_recovery = False  # (the "dead" window removes nothing)


def orphan_recovery(folder, settings, text: str):
    """A recovery file (``text``) with a lock naming an ended process that ran with ``settings``: what a
    crashed window leaves. Returns its path."""
    from weft.app.gui import recovery

    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"recovery-crashed-{dead_pid()}-0000abcd.weft.json"
    path.write_text(text, encoding="utf-8")
    owner = dataclasses.replace(recovery.Owner.me(recovery.settings_id(settings)), pid=dead_pid(), started=None)
    recovery.write_lock(path, owner)
    return path
