"""Studio sessions are JSON with paths relative to the session file, so a project
folder can move; a session that names a missing image, or is not a session at all, is one message
naming the file, and the document (inputs, parameters, undo history) stays as it was."""

import json
import os
import pickle
import shutil

import numpy as np
import pytest
from weft.core.image import load_image, save_image

from .helpers import settle


def _image(path, seed, side=24):
    path.parent.mkdir(parents=True, exist_ok=True)
    save_image(path, np.random.default_rng(seed).random((side, side, 3)).astype(np.float32))
    return path


def _state(doc):
    """What must not change when a session is refused (images by identity: not even re-read)."""
    return (
        {name: (item.path, id(item.image)) for name, item in doc.inputs.items()},
        doc.method,
        dict(doc.params),
        doc.square,
        doc.seed,
        [list(x) for x in doc.image_lines],
        [list(x) for x in doc.frontal_lines],
        doc.frontal_size,
        doc.undo_stack.count(),
        doc.undo_stack.index(),
        doc.undo_stack.isClean(),
    )


class _Exploit:
    """Unpickling this creates a file."""

    def __init__(self, path):
        self.path = str(path)

    def __reduce__(self):
        return (open, (self.path, "w"))


@pytest.fixture
def edited(window):
    """The window with unsaved edits: a parameter and a prototype (two undo steps)."""
    doc = window.doc
    doc.set_param("p", 0.3)
    doc.set_square((2, 4, 16))
    assert doc.undo_stack.count() == 2 and not doc.undo_stack.isClean()
    return window


def test_saved_session_is_json_relative_to_itself_and_opens_after_the_folder_moves(window, qtbot, tmp_path):
    doc = window.doc
    project = tmp_path / "project"
    files = {
        "texture": project / "tex.png",
        "target": project / "img" / "target.png",
        "photo": project / "photo.png",
        "image": project / "img" / "hole.png",
    }  # (every input the studio has open: fill's image too)
    for i, (name, path) in enumerate(files.items()):
        doc.set_input(name, str(_image(path, i)), load_image(path).image)
    doc.set_param("p", 0.3)
    session = project / "s.weft.json"
    assert window.files.save_session(str(session))

    data = json.loads(session.read_text(encoding="utf-8"))  # plain JSON, nothing else
    assert data["inputs"] == {
        "texture": "tex.png",
        "target": os.path.join("img", "target.png"),
        "photo": "photo.png",
        "image": os.path.join("img", "hole.png"),
    }
    assert data["weft_session"] == 1 and data["method"] == "fast" and data["params"]["fast"]["p"] == 0.3
    assert doc.undo_stack.isClean()

    moved = tmp_path / "elsewhere" / "deeper" / "project"
    moved.parent.mkdir(parents=True)
    shutil.move(project, moved)
    assert not project.exists()
    doc.set_param("p", 0.7)
    assert window.files.open_session(str(moved / "s.weft.json"))
    for name, path in files.items():
        new = moved / path.relative_to(project)
        assert doc.inputs[name].path == str(new)
        assert np.array_equal(doc.inputs[name].image, load_image(new).image)
    assert doc.current_params.p == 0.3 and doc.undo_stack.count() == 0
    qtbot.waitUntil(
        lambda: window.renderer.last.final and window.renderer.last.image.shape == (24, 24, 3), timeout=20000
    )


def test_a_session_naming_a_missing_image_says_which_and_keeps_the_document(edited, qtbot, tmp_path):
    window, doc = edited, edited.doc
    _image(tmp_path / "tex.png", 0)
    session = tmp_path / "s.weft.json"
    data = doc.session().to_data(tmp_path / "s.weft.json")
    data["inputs"] = {"texture": "tex.png", "target": "gone.png"}
    session.write_text(json.dumps(data))
    before = _state(doc)
    messages = []
    window.message.connect(messages.append)
    assert window.files.open_session(str(session)) is False
    settle(qtbot, window)  # anything else it was going to say has been said
    assert messages == [f"{session}: the target image: {tmp_path / 'gone.png'}: no such file"]
    assert _state(doc) == before
    # the undo history still works, and a good session still opens: the studio goes on
    doc.undo_stack.undo()
    assert doc.square is None and doc.current_params.p == 0.3
    data["inputs"] = {"texture": "tex.png", "target": "tex.png"}
    session.write_text(json.dumps(data))
    assert window.files.open_session(str(session))
    assert doc.inputs["target"].path == str(tmp_path / "tex.png") and len(messages) == 1


def test_a_session_that_is_not_a_session_keeps_the_document(edited, qtbot, tmp_path):
    window, doc = edited, edited.doc
    sentinel = tmp_path / "EXECUTED"
    _image(tmp_path / "tex.png", 0)
    good = doc.session().to_data(tmp_path / "s.weft.json")
    good["inputs"] = {"texture": "tex.png", "target": "tex.png"}

    def field(**kw):
        return json.dumps(dict(good, **kw)).encode()

    cases = {
        "pickle": (pickle.dumps(_Exploit(sentinel)), "not UTF-8"),
        "code": (f"__import__('os').system('touch {sentinel}')".encode(), "not valid JSON"),
        "truncated": (json.dumps(good).encode()[:60], "not valid JSON"),
        "yaml": (b"weft_session: 1\nmethod: fast\n", "not valid JSON"),
        "nan": (json.dumps(good).replace(f'"seed": {good["seed"]}', '"seed": NaN').encode(), "NaN"),
        "deep": (b"[" * 100_000 + b"]" * 100_000, "nested too deeply"),
        "list": (b"[]", "not a weft session file"),
        "inputs_list": (field(inputs=["tex.png"]), "inputs must be an object"),
        "prototype_outside": (field(prototype=[100, 100, 16]), "leaves the texture (24x24)"),
        "bad_lines": (
            field(lines={"image_lines": [[1]], "frontal_lines": [], "frontal_size": [64, 64]}),
            "image_lines[0] = [1] must be [x1, y1, x2, y2]",
        ),
        "huge_seed": (field(seed=2**40), "seed = 1099511627776 must be an integer"),
        "not_a_studio_method": (field(method="blend"), "the studio does not offer method 'blend'"),
    }
    messages = []
    window.message.connect(messages.append)
    before = _state(doc)
    for name, (data, fragment) in cases.items():
        path = tmp_path / f"{name}.weft.json"
        path.write_bytes(data)
        del messages[:]
        assert window.files.open_session(str(path)) is False, name
        settle(qtbot, window)  # anything else it was going to say has been said
        assert len(messages) == 1 and "\n" not in messages[0], (name, messages)
        assert messages[0].startswith(f"{path}: ") and fragment in messages[0], (name, messages)
        assert _state(doc) == before, name
    assert not sentinel.exists()
    assert window.isVisible()
    path = tmp_path / "good.weft.json"
    path.write_text(json.dumps(good))
    assert window.files.open_session(str(path))  # and a good one still opens


def _runs_off_gui_thread(monkeypatch, module, name, action):
    """Run ``action()`` with ``module.name`` replaced by a wrapper that records its thread and waits until
    a timer of the GUI thread has fired, which happens only if that thread keeps running its event loop;
    return the recorded "was it the GUI thread" flags."""
    import threading

    from PySide6.QtCore import QTimer

    real = getattr(module, name)
    working, gui_ran = threading.Event(), threading.Event()
    on_gui_thread = []

    def slow(*args, **kwargs):
        on_gui_thread.append(threading.current_thread() is threading.main_thread())
        working.set()
        assert gui_ran.wait(10), "the GUI thread was blocked meanwhile"
        return real(*args, **kwargs)

    timer = QTimer()
    timer.timeout.connect(lambda: working.is_set() and gui_ran.set())
    timer.start(5)
    monkeypatch.setattr(module, name, slow)
    try:
        assert action()
    finally:
        timer.stop()
        monkeypatch.setattr(module, name, real)
    return on_gui_thread


def test_session_images_are_decoded_off_the_gui_thread_while_it_keeps_running(window, qtbot, tmp_path, monkeypatch):
    """A session's images may be large: the GUI thread keeps running its event loop while they decode."""
    import weft.app.gui.files as files

    texture = _image(tmp_path / "tex.png", 7)
    window.doc.set_input("texture", str(texture), load_image(texture).image)
    session = tmp_path / "s.weft.json"
    assert window.files.save_session(str(session))
    flags = _runs_off_gui_thread(monkeypatch, files, "read_input", lambda: window.files.open_session(str(session)))
    assert flags and not any(flags)  # every image of the session, none on the GUI thread
    assert window.doc.inputs["texture"].path == str(texture)


def test_export_is_encoded_off_the_gui_thread(window, qtbot, tmp_path, monkeypatch):
    import weft.app.gui.files as files

    qtbot.waitUntil(lambda: window.renderer.last is not None and window.renderer.last.final, timeout=30000)
    out = tmp_path / "out.png"
    flags = _runs_off_gui_thread(monkeypatch, files, "save_image", lambda: window.files.export_result(str(out)))
    assert flags == [False]
    written, shown = load_image(out).image, window.renderer.last.image
    assert written.shape == shown.shape
    assert float(np.abs(written - shown).max()) <= 0.5 / 255 + 1e-6  # the shown result, to 8 bits


def test_a_wait_started_inside_another_wait_leaves_that_one_its_result(qtbot):
    """off_gui_thread runs a local event loop; a second wait started from it (a close event) is queued
    behind the first one's work and never cancels it: both return their own values."""
    import threading

    from PySide6.QtCore import QTimer
    from weft.app.gui.files import off_gui_thread
    from weft.app.gui.qjobs import QtJobs

    jobs = QtJobs()
    busy = threading.Event()
    jobs.submit("other", lambda **_: busy.wait(10))  # (its worker is busy: the first wait's work is queued)
    inner = []

    def nested():
        inner.append(off_gui_thread(jobs, lambda: "inner"))

    QTimer.singleShot(0, nested)
    QTimer.singleShot(0, busy.set)
    assert off_gui_thread(jobs, lambda: "outer") == "outer"
    assert inner == ["inner"]
    jobs.shutdown()
