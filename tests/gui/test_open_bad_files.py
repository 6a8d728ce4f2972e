"""Opening a broken file in the studio keeps the document and says, in one line, which file."""

import pytest

from tests.data.make_corpus import BROKEN, make_corpus

from .helpers import settle


@pytest.fixture(scope="module")
def corpus(tmp_path_factory):
    return make_corpus(tmp_path_factory.mktemp("corpus"))


@pytest.mark.parametrize("item", BROKEN)
def test_gui_open_keeps_document_and_says_which_file(corpus, window, qtbot, item):
    path = corpus[item]
    before = {name: (inp.path, inp.image) for name, inp in window.doc.inputs.items()}
    undo_count = window.doc.undo_stack.count()
    messages = []
    window.message.connect(messages.append)
    window.open_input("texture", str(path))
    qtbot.waitUntil(lambda: bool(messages), timeout=10000)
    settle(qtbot, window)  # anything else it was going to say has been said
    assert len(messages) == 1
    assert path.name in messages[0] and "\n" not in messages[0]
    after = {name: (inp.path, inp.image) for name, inp in window.doc.inputs.items()}
    assert after.keys() == before.keys()
    assert all(after[k][0] == before[k][0] and after[k][1] is before[k][1] for k in before)
    assert window.doc.undo_stack.count() == undo_count


@pytest.mark.parametrize("item", BROKEN)
def test_gui_drop_keeps_document_and_says_which_file(corpus, window, qtbot, item):
    from PySide6.QtCore import QMimeData, QPoint, QPointF, Qt, QUrl
    from PySide6.QtGui import QDragEnterEvent, QDropEvent
    from PySide6.QtWidgets import QApplication

    path = corpus[item]
    view = window.inputs_pane.views["target"]
    before = window.doc.inputs["target"]
    undo_count = window.doc.undo_stack.count()
    messages = []
    window.message.connect(messages.append)
    data = QMimeData()
    data.setUrls([QUrl.fromLocalFile(str(path))])
    enter = QDragEnterEvent(
        QPoint(10, 10), Qt.DropAction.CopyAction, data, Qt.MouseButton.NoButton, Qt.KeyboardModifier.NoModifier
    )
    QApplication.sendEvent(view.viewport(), enter)
    if item != "directory":  # a folder may be turned away at the door; a file named .png is let in
        assert enter.isAccepted()
    if enter.isAccepted():
        drop = QDropEvent(
            QPointF(10, 10), Qt.DropAction.CopyAction, data, Qt.MouseButton.NoButton, Qt.KeyboardModifier.NoModifier
        )
        QApplication.sendEvent(view.viewport(), drop)
        qtbot.waitUntil(lambda: bool(messages), timeout=10000)
        settle(qtbot, window)  # anything else it was going to say has been said
        assert len(messages) == 1 and path.name in messages[0] and "\n" not in messages[0]
    assert window.doc.inputs["target"] is before
    assert window.doc.undo_stack.count() == undo_count
