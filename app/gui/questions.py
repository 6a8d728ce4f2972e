"""The studio's questions: the one place it asks the user something in a modal box.

A window has one :class:`Questions` (``window.questions``); its parts ask through it, and a test or
a script replaces its methods to answer without a box.
"""

from __future__ import annotations

from PySide6.QtWidgets import QMessageBox, QWidget


class Questions:
    """Yes/no, restore/discard and save/discard/cancel questions, in modal boxes over ``parent``."""

    def __init__(self, parent: QWidget):
        self.parent = parent

    def confirm(self, question: str) -> bool:
        """Ask a yes/no question (No is the default); True for yes."""
        answer = QMessageBox.question(
            self.parent,
            "weft",
            question,
            QMessageBox.StandardButton.Yes | QMessageBox.StandardButton.No,
            QMessageBox.StandardButton.No,
        )
        return answer == QMessageBox.StandardButton.Yes

    def ask_restore(self, question: str) -> bool:
        """Ask whether to restore a recovered session: Restore (the default: Enter restores, and Esc
        never discards the work) or Discard; True for Restore."""
        box = QMessageBox(QMessageBox.Icon.Question, "weft", question, QMessageBox.StandardButton.NoButton, self.parent)
        restore = box.addButton("Restore", QMessageBox.ButtonRole.AcceptRole)
        box.addButton("Discard", QMessageBox.ButtonRole.DestructiveRole)
        box.setDefaultButton(restore)
        box.setEscapeButton(restore)
        box.exec()
        return box.clickedButton() is restore

    def ask_unsaved(self, doing: str) -> str:
        """The document has unsaved edits and the user is about to ``doing`` (e.g. "quit"): ask
        Save / Discard / Cancel; returns "save", "discard" or "cancel"."""
        box = QMessageBox(
            QMessageBox.Icon.Question,
            "weft",
            f"Save your unsaved edits as a session before you {doing}?",
            QMessageBox.StandardButton.Save | QMessageBox.StandardButton.Discard | QMessageBox.StandardButton.Cancel,
            self.parent,
        )
        box.setDefaultButton(QMessageBox.StandardButton.Save)
        box.setEscapeButton(QMessageBox.StandardButton.Cancel)
        answer = box.exec()
        return {QMessageBox.StandardButton.Save: "save", QMessageBox.StandardButton.Discard: "discard"}.get(
            QMessageBox.StandardButton(answer), "cancel"
        )
