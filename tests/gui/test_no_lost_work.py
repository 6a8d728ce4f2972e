"""Issue 8.5: no lost work in the studio — it asks before overwriting and before discarding unsaved
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
from weft.core.image import save_image

from .helpers import no_job_threads
from .recovery_helper import EDITS

ROOT = Path(__file__).resolve().parents[2]


def answer(monkeypatch, reply: bool) -> list[str]:
    """Make the window's questions answer ``reply``; returns the questions asked."""
    asked = []

    def confirm(self, question):
        asked.append(question)
        return reply

    monkeypatch.setattr(MainWindow, "_confirm", confirm)
    return asked


@pytest.mark.parametrize("reply", [False, True])
def test_export_asks_before_overwriting(window, tmp_path, monkeypatch, reply):
    out = tmp_path / "old.png"
    out.write_bytes(b"precious")
    asked = answer(monkeypatch, reply)
    assert window.export_result(str(out)) is reply
    assert len(asked) == 1 and "old.png" in asked[0]
    assert (out.read_bytes() == b"precious") is (not reply)


def test_export_to_a_new_file_does_not_ask(window, tmp_path, monkeypatch):
    asked = answer(monkeypatch, False)
    assert window.export_result(str(tmp_path / "new.png"))
    assert asked == []


def answer_unsaved(monkeypatch, reply: str) -> list[str]:
    """Make the Save / Discard / Cancel question about unsaved edits answer ``reply``; returns what
    the user was about to do, per question."""
    asked = []

    def ask(self, doing):
        asked.append(doing)
        return reply

    monkeypatch.setattr(MainWindow, "_ask_unsaved", ask)
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
    assert window.save_session(str(session))
    window.doc.set_param("p", 0.5)
    asked = answer_unsaved(monkeypatch, "cancel")
    assert window.open_session(str(session)) is False
    assert len(asked) == 1 and window.doc.current_params.p == 0.5
    answer_unsaved(monkeypatch, "discard")
    assert window.open_session(str(session)) is True
    assert window.doc.current_params.p != 0.5


def test_autosave_while_edited_and_removed_when_clean(window, qtbot, private_recovery):
    window._autosave_timer.setInterval(20)
    recovery = private_recovery / "recovery.weft.json"
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
    assert not recovery.exists()


def test_recovery_declined_is_removed(qtbot, settings, private_recovery, monkeypatch):
    private_recovery.mkdir()
    recovery = private_recovery / "recovery.weft.json"
    recovery.write_text("{}", encoding="utf-8")
    asked = answer(monkeypatch, False)
    w = MainWindow(settings=settings, load_defaults=False)
    qtbot.addWidget(w)
    assert len(asked) == 1 and not recovery.exists()
    w.shutdown()


def test_unreadable_recovery_file_says_so_in_one_line(qtbot, settings, private_recovery):
    private_recovery.mkdir()
    recovery = private_recovery / "recovery.weft.json"
    recovery.write_text("{not json", encoding="utf-8")
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
    proc = subprocess.Popen([sys.executable, str(ROOT / "tests" / "gui" / "recovery_helper.py"), str(target),
                             str(tmp_path / "first.ini")], cwd=ROOT, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    line = []
    reader = threading.Thread(target=lambda: line.append(proc.stdout.readline()), daemon=True)
    reader.start()
    reader.join(60)
    try:
        assert line and line[0].strip() == "AUTOSAVED", (line, proc.poll())
    finally:
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(10)
        proc.stdout.close()
        proc.stderr.close()
    assert proc.returncode == -signal.SIGKILL
    recovery = private_recovery / "recovery.weft.json"
    assert recovery.is_file()

    asked = answer(monkeypatch, True)
    w = MainWindow(settings=QSettings(str(tmp_path / "second.ini"), QSettings.Format.IniFormat))
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
    assert doc.seed == EDITS["seed"] and w.seed_box.value() == EDITS["seed"]
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
    assert window.export_result(str(out)) is False
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
    assert window.export_result(str(texture)) is False
    assert asked == [] and texture.read_bytes() == before
    assert len(messages) == 1 and "texture.png" in messages[0] and "input" in messages[0]
