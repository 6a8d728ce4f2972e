"""Open Session on a named pipe: refused at once in one line, the document kept (a read of a pipe
without a writer would wait forever)."""

from __future__ import annotations

import os
import threading

import pytest


def _unblock_readers(fifo: str, stop: threading.Event) -> None:
    """Should anything open the pipe for reading, give it an empty write end so the test ends (and
    fails on the message) instead of hanging."""
    while not stop.wait(0.2):
        try:
            fd = os.open(fifo, os.O_WRONLY | os.O_NONBLOCK)
        except OSError:  # no reader yet
            continue
        os.close(fd)


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no named pipes on this system")
def test_open_session_on_a_fifo_is_refused_and_keeps_the_document(window, qtbot, tmp_path):
    fifo = str(tmp_path / "s.weft.json")
    os.mkfifo(fifo)
    stop = threading.Event()
    guard = threading.Thread(target=_unblock_readers, args=(fifo, stop), daemon=True)
    guard.start()
    before = {name: inp.path for name, inp in window.doc.inputs.items()}
    messages = []
    window.message.connect(messages.append)
    try:
        assert window.files.open_session(fifo) is False
    finally:
        stop.set()
        guard.join()
    assert messages == [f"{fifo}: is a named pipe (FIFO), not a weft session file"]
    assert {name: inp.path for name, inp in window.doc.inputs.items()} == before
