"""The Qt binding must not lose references when Qt calls our undo commands (PySide6 6.12.0 did:
every undo()/redo() dropped a reference to None, and the process aborted at exit after many undos)."""

import sys

from PySide6.QtGui import QUndoCommand, QUndoStack


class _Noop(QUndoCommand):
    def redo(self):
        pass

    def undo(self):
        pass


def test_undo_and_redo_keep_reference_counts(qapp):
    stack = QUndoStack()
    for _ in range(50):
        stack.push(_Noop("step"))
    before = sys.getrefcount(None)
    for _ in range(50):
        stack.undo()
    for _ in range(50):
        stack.redo()
    assert sys.getrefcount(None) - before >= -5  # a lost reference per call would be -100
