"""No lost work in the studio: it asks before overwriting and before discarding unsaved
edits, autosaves unsaved edits to a recovery file, and after ``kill -9`` the next start restores them."""

import json
import os
import signal
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest
from PySide6.QtCore import QSettings
from weft.app.gui.main_window import MainWindow
from weft.app.gui.questions import Questions
from weft.core.image import save_image

from .helpers import no_job_threads, orphan_recovery, pretend_crashed
from .recovery_helper import EDITS

ROOT = Path(__file__).resolve().parents[2]
REAL_ASK_RESTORE = Questions.ask_restore  # (before the conftest replaces it)


def answer(monkeypatch, reply: bool) -> list[str]:
    """Make the window's questions answer ``reply``; returns the questions asked."""
    asked = []

    def confirm(self, question):
        asked.append(question)
        return reply

    monkeypatch.setattr(Questions, "confirm", confirm)
    return asked


@pytest.mark.parametrize("reply", [False, True])
def test_export_asks_before_overwriting(window, tmp_path, monkeypatch, reply):
    out = tmp_path / "old.png"
    out.write_bytes(b"precious")
    asked = answer(monkeypatch, reply)
    assert window.files.export_result(str(out)) is reply
    assert len(asked) == 1 and "old.png" in asked[0]
    assert (out.read_bytes() == b"precious") is (not reply)


def test_export_to_a_new_file_does_not_ask(window, tmp_path, monkeypatch):
    asked = answer(monkeypatch, False)
    assert window.files.export_result(str(tmp_path / "new.png"))
    assert asked == []


def answer_unsaved(monkeypatch, reply: str) -> list[str]:
    """Make the Save / Discard / Cancel question about unsaved edits answer ``reply``; returns what
    the user was about to do, per question."""
    asked = []

    def ask(self, doing):
        asked.append(doing)
        return reply

    monkeypatch.setattr(Questions, "ask_unsaved", ask)
    return asked


def test_close_with_unsaved_edits_asks(window, monkeypatch):
    window.doc.set_param("p", 0.5)
    asked = answer_unsaved(monkeypatch, "cancel")
    assert window.close() is False  # refused: the window stays
    assert window.isVisible() and asked == ["quit"]
    answer_unsaved(monkeypatch, "discard")
    assert window.close() is True


def test_close_when_clean_does_not_ask(window, monkeypatch):
    asked = answer(monkeypatch, False)
    asked_unsaved = answer_unsaved(monkeypatch, "cancel")
    assert window.close() is True and asked == [] and asked_unsaved == []


def test_open_session_with_unsaved_edits_asks(window, tmp_path, monkeypatch):
    session = tmp_path / "s.weft.json"
    assert window.files.save_session(str(session))
    window.doc.set_param("p", 0.5)
    asked = answer_unsaved(monkeypatch, "cancel")
    assert window.files.open_session(str(session)) is False
    assert len(asked) == 1 and window.doc.current_params.p == 0.5
    answer_unsaved(monkeypatch, "discard")
    assert window.files.open_session(str(session)) is True
    assert window.doc.current_params.p != 0.5


def test_autosave_while_edited_and_removed_when_clean(window, qtbot, private_recovery):
    window.files.autosave_throttle.setTimeout(20)
    recovery = window.files.recovery_file
    assert recovery.parent == private_recovery
    assert not recovery.exists()
    window.doc.set_param("p", 0.25)
    qtbot.waitUntil(recovery.exists, timeout=5000)
    saved = json.loads(recovery.read_text(encoding="utf-8"))
    assert saved["params"]["fast"]["p"] == 0.25
    assert all(os.path.isabs(p) for p in saved["inputs"].values())
    window.doc.undo_stack.undo()  # back to the clean state: nothing to recover
    assert not recovery.exists()
    window.doc.set_param("p", 0.75)
    qtbot.waitUntil(recovery.exists, timeout=5000)
    window.close()  # the conftest answers "discard" to the question
    assert not recovery.exists() and list(private_recovery.iterdir()) == []  # (its lock too)


def _recorded_autosaves(window, monkeypatch) -> list[float]:
    """The value of the fast method's ``p`` in each recovery file written from now on, in order."""
    import weft.app.gui.files as files

    written, real = [], files.write_files

    def recording(to_write):
        real(to_write)
        written.append(json.loads(window.files.recovery_file.read_text(encoding="utf-8"))["params"]["fast"]["p"])

    monkeypatch.setattr(files, "write_files", recording)
    return written


def test_a_burst_of_edits_is_autosaved_once_with_its_last_state(window, qtbot, monkeypatch):
    written = _recorded_autosaves(window, monkeypatch)
    window.files.autosave_throttle.setTimeout(1500)
    for p in (0.1, 0.2, 0.3, 0.4, 0.5):  # (well within the interval)
        window.doc.set_param("p", p)
    qtbot.waitUntil(lambda: len(written) >= 1, timeout=10000)
    window.doc.set_param("p", 0.9)  # a later edit: its own write, after the burst's
    qtbot.waitUntil(lambda: 0.9 in written, timeout=10000)
    assert written == [0.5, 0.9]


def test_edits_that_go_on_are_autosaved_while_they_go_on(window, qtbot, monkeypatch):
    """The autosave is a throttle, not a debounce: painting without a pause longer than the autosave
    interval still reaches the recovery file."""
    from PySide6.QtCore import QTimer

    written = _recorded_autosaves(window, monkeypatch)
    window.files.autosave_throttle.setTimeout(300)
    edits = []

    def edit():
        edits.append(len(edits))
        window.doc.set_param("p", 0.2 + 0.1 * (len(edits) % 2))
        if len(edits) >= 300:
            ticker.stop()

    ticker = QTimer(interval=30)  # edits keep coming well past the autosave interval
    ticker.timeout.connect(edit)
    ticker.start()
    try:
        qtbot.waitUntil(lambda: bool(written), timeout=10000)
        assert ticker.isActive() and len(edits) < 300  # written while the edits go on
    finally:
        ticker.stop()


def answer_restore(monkeypatch, reply: bool) -> list[str]:
    """Make the question "restore a recovered session?" answer ``reply``; returns the questions asked."""
    asked = []

    def ask(self, question):
        asked.append(question)
        return reply

    monkeypatch.setattr(Questions, "ask_restore", ask)
    return asked


def test_recovery_declined_is_removed(qtbot, settings, private_recovery, monkeypatch):
    recovery = orphan_recovery(private_recovery, settings, "{}")
    asked = answer_restore(monkeypatch, False)
    w = MainWindow(settings=settings, load_defaults=False)
    qtbot.addWidget(w)
    assert len(asked) == 1 and not recovery.exists()
    assert list(private_recovery.iterdir()) == []  # its lock too
    w.shutdown()


def test_a_second_window_never_offers_or_removes_the_first_windows_work(
    window, qtbot, settings, private_recovery, monkeypatch
):
    """Two studios at once: the second does not offer the first one's recovery file (its window
    runs), so declining cannot remove it; each window autosaves to a file of its own."""
    window.doc.set_param("p", 0.25)
    assert window.files.autosave()
    first = window.files.recovery_file
    assert first.is_file()
    asked = answer_restore(monkeypatch, False)
    second = MainWindow(settings=settings)
    qtbot.addWidget(second)
    assert asked == [] and first.is_file()
    second.doc.set_param("p", 0.75)
    assert second.files.autosave()
    assert second.files.recovery_file != first and second.files.recovery_file.is_file()
    assert json.loads(first.read_text(encoding="utf-8"))["params"]["fast"]["p"] == 0.25
    # the first window "crashes": a third window offers its work (and only its: the second runs)
    pretend_crashed(window)
    asked = answer_restore(monkeypatch, True)
    third = MainWindow(settings=settings, load_defaults=False)
    qtbot.addWidget(third)
    assert len(asked) == 1 and third.doc.params["fast"].p == 0.25 and third.files.recovery_file == first
    assert second.files.recovery_file.is_file()
    for w in (second, third):
        w.shutdown()


def test_a_first_launch_offers_no_strangers_recovery_file(qtbot, tmp_path, settings, private_recovery, monkeypatch):
    """A recovery file left by a weft that ran with other settings (another user of the account, an
    earlier setup) is a stranger's: a first launch (new settings) neither offers nor removes it."""
    theirs = QSettings(str(tmp_path / "theirs.ini"), QSettings.Format.IniFormat)
    stranger = orphan_recovery(private_recovery, theirs, "{}")
    asked = answer_restore(monkeypatch, True)
    w = MainWindow(settings=settings, load_defaults=False)
    qtbot.addWidget(w)
    assert asked == [] and stranger.is_file()
    w.shutdown()


def test_the_restore_question_restores_on_enter(qtbot, settings, private_recovery, monkeypatch, tmp_path):
    """The question's default button is Restore: Enter keeps the work."""
    from PySide6.QtCore import Qt, QTimer
    from PySide6.QtWidgets import QApplication, QMessageBox

    monkeypatch.setattr(Questions, "ask_restore", REAL_ASK_RESTORE)
    target = tmp_path / "t.png"
    save_image(target, np.random.default_rng(1).random((40, 48, 3), dtype=np.float32))
    session = {
        "weft_session": 1,
        "method": "fast",
        "params": {"fast": {"p": 0.31}},
        "inputs": {"target": str(target)},
        "geometry": {},
        "seed": 5,
    }
    orphan_recovery(private_recovery, settings, json.dumps(session))
    seen = []

    def press_enter():
        box = QApplication.activeModalWidget()
        if not isinstance(box, QMessageBox):
            QTimer.singleShot(20, press_enter)
            return
        seen.append(box.text())
        qtbot.keyClick(box, Qt.Key.Key_Return)

    QTimer.singleShot(0, press_enter)
    w = MainWindow(settings=settings, load_defaults=False)
    qtbot.addWidget(w)
    assert seen and "Restore" in seen[0]
    assert w.doc.params["fast"].p == 0.31 and w.doc.seed == 5
    w.shutdown()


def test_ctrl_s_after_a_recovery_saves_to_the_sessions_file(
    window, qtbot, settings, private_recovery, tmp_path, monkeypatch
):
    from PySide6.QtCore import Qt
    from PySide6.QtWidgets import QFileDialog

    session = tmp_path / "mine.weft.json"
    assert window.files.save_session(str(session))
    window.doc.set_param("p", 0.4)
    assert window.files.autosave()
    pretend_crashed(window)
    again = MainWindow(settings=settings, load_defaults=False)
    qtbot.addWidget(again)
    asked = []
    monkeypatch.setattr(QFileDialog, "getSaveFileName", lambda *a, **k: asked.append(a) or ("", ""))
    again.show()
    again.activateWindow()
    qtbot.waitUntil(again.isActiveWindow, timeout=5000)
    qtbot.keyClick(again, Qt.Key.Key_S, Qt.KeyboardModifier.ControlModifier)
    assert asked == []  # saved where the session was, no dialog
    assert json.loads(session.read_text(encoding="utf-8"))["params"]["fast"]["p"] == 0.4
    assert again.doc.undo_stack.isClean()
    again.shutdown()


def test_unreadable_recovery_file_says_so_in_one_line(qtbot, settings, private_recovery):
    recovery = orphan_recovery(private_recovery, settings, "{not json")
    messages = []
    w = MainWindow(settings=settings, load_defaults=False)
    qtbot.addWidget(w)
    # the message went out during construction: read it from the status bar
    messages.append(w.statusBar().currentMessage())
    assert "could not restore" in messages[0] and "\n" not in messages[0]
    assert recovery.exists()  # kept: the user may still want it
    w.shutdown()


@pytest.mark.slow
def test_kill_9_then_restart_offers_to_restore(qtbot, tmp_path, private_recovery, monkeypatch):
    """A real studio process is edited, autosaves, and is killed with SIGKILL; the next start restores."""
    target = tmp_path / "my target ü.png"
    save_image(target, np.random.default_rng(1).random((48, 64, 3), dtype=np.float32))
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen", WEFT_RECOVERY_DIR=str(private_recovery))
    proc = subprocess.Popen(
        [sys.executable, str(ROOT / "tests" / "gui" / "recovery_helper.py"), str(target), str(tmp_path / "first.ini")],
        cwd=ROOT,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    line = []
    reader = threading.Thread(target=lambda: line.append(proc.stdout.readline()), daemon=True)
    reader.start()
    reader.join(60)
    ini = QSettings(str(tmp_path / "first.ini"), QSettings.Format.IniFormat)  # the same user's settings
    try:
        assert line and line[0].strip() == "AUTOSAVED", (line, proc.poll())
        # while the first studio runs, a second one started does not offer (nor remove) its work
        asked = answer_restore(monkeypatch, False)
        w = MainWindow(settings=ini, load_defaults=False)
        qtbot.addWidget(w)
        assert asked == []
        w.shutdown()
    finally:
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(10)
        proc.stdout.close()
        proc.stderr.close()
    assert proc.returncode == -signal.SIGKILL
    (recovery,) = private_recovery.glob("recovery-*.weft.json")

    asked = answer_restore(monkeypatch, True)
    w = MainWindow(settings=ini)
    qtbot.addWidget(w)
    doc = w.doc
    assert len(asked) == 1 and "Restore" in asked[0]
    assert doc.inputs["target"].path == str(target)
    assert doc.inputs["target"].image.shape == (48, 64, 3)
    assert doc.params["fast"].p == EDITS["p"]
    assert doc.square == tuple(EDITS["prototype"])
    lines = doc.value("lines", "nfpt")
    assert [list(x) for x in lines.image_lines] == EDITS["image_lines"]
    assert [list(x) for x in lines.frontal_lines] == EDITS["frontal_lines"]
    assert doc.seed == EDITS["seed"] and w.method_panel.seed_box.value() == EDITS["seed"]
    assert not doc.undo_stack.isClean()  # still unsaved: the recovery file stays until saved or discarded
    assert w.windowTitle().endswith(" *")  # and the title says so
    assert recovery.exists()
    w.close()
    assert not recovery.exists()
    assert no_job_threads()


def test_export_to_a_full_disk_keeps_the_old_file_and_says_why(window, tmp_path, monkeypatch):
    if not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full on this system")
    out = tmp_path / "old.png"
    out.write_bytes(b"precious")

    def to_dev_full(fd, mode="r", *a, **k):
        os.close(fd)
        return open("/dev/full", mode, buffering=0)

    monkeypatch.setattr("weft.core.image.files.os.fdopen", to_dev_full)
    messages = []
    window.message.connect(messages.append)
    assert window.files.export_result(str(out)) is False
    assert out.read_bytes() == b"precious"
    assert len(messages) == 1 and "old.png" in messages[0] and "No space left" in messages[0]


def test_export_over_an_input_is_refused_without_asking(window, tmp_path, monkeypatch):
    texture = tmp_path / "texture.png"
    save_image(texture, window.doc.image("texture"))
    window.doc.set_input("texture", str(texture), window.doc.image("texture"))
    before = texture.read_bytes()
    asked = answer(monkeypatch, True)
    messages = []
    window.message.connect(messages.append)
    assert window.files.export_result(str(texture)) is False
    assert asked == [] and texture.read_bytes() == before
    assert len(messages) == 1 and "texture.png" in messages[0] and "input" in messages[0]


def test_export_over_an_input_through_another_name_is_refused(window, tmp_path, monkeypatch):
    """A hard link (or a second mount of the folder) is the input under another path."""
    texture = tmp_path / "texture.png"
    save_image(texture, window.doc.image("texture"))
    window.doc.set_input("texture", str(texture), window.doc.image("texture"))
    other = tmp_path / "other"
    other.mkdir()
    alias = other / "same-file.png"
    os.link(texture, alias)
    before = texture.read_bytes()
    asked = answer(monkeypatch, True)
    assert window.files.export_result(str(alias)) is False
    assert asked == [] and texture.read_bytes() == before
