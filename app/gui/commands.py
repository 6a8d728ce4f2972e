"""The document's undo commands: each edit of :class:`~weft.app.gui.document.Document` is one of them,
on its one ``QUndoStack``; they change the document through its ``put_*`` methods only."""

from __future__ import annotations

from pathlib import Path

from PySide6.QtGui import QUndoCommand
from weft.core.geometry import MASK
from weft.core.params import Params

_MERGE_PARAM = 1001


class SetParams(QUndoCommand):
    """Replace the parameters of one method; consecutive edits of one parameter merge."""

    def __init__(self, doc, method: str, new: Params, text: str, merge_key: str | None = None):
        super().__init__(text)
        self.doc, self.method, self.new = doc, method, new
        self.old = doc.params[method]
        self.merge_key = merge_key

    def id(self) -> int:  # noqa: A003 (Qt naming)
        return _MERGE_PARAM if self.merge_key else -1

    def mergeWith(self, other) -> bool:  # noqa: N802
        if not isinstance(other, SetParams) or (other.method, other.merge_key) != (self.method, self.merge_key):
            return False
        self.new = other.new
        self.setText(other.text())
        return True

    def redo(self):
        self.doc.put_params(self.method, self.new)

    def undo(self):
        self.doc.put_params(self.method, self.old)


class SetInput(QUndoCommand):
    """Open (or clear) an input; masks painted on it that do not fit the new image go with the same step."""

    def __init__(self, doc, name: str, item):
        if item is None:
            super().__init__(f"Clear {name.replace('_', ' ')}")
        else:
            label = Path(item.path).name if item.path else "image"
            super().__init__(f"Open {name} {label}")
        self.doc, self.name, self.new = doc, name, item
        self.old = doc.inputs.get(name)
        after = {**doc.inputs, name: item} if item is not None else {k: v for k, v in doc.inputs.items() if k != name}
        self.dropped = []  # (method, key, mask) that no longer fit
        for method, m in doc.methods.items():
            for g in m.studio.geometry:
                mask = doc.geometry[method].get(g.key)
                if g.kind != MASK or mask is None or g.input_for(after) != name or item is None:
                    continue
                if mask.shape != item.image.shape[:2]:
                    self.dropped.append((method, g.key, mask))

    def redo(self):
        self.doc.put_input(self.name, self.new, dropped=[(method, key) for method, key, _mask in self.dropped])
        for method, key, mask in self.dropped:
            h, w = self.new.image.shape[:2]
            self.doc.message.emit(
                f"the {key.replace('_', ' ')} of {method} ({mask.size[0]}x{mask.size[1]}) does not "
                f"fit the new {self.name.replace('_', ' ')} ({w}x{h}): dropped (Ctrl+Z brings it back)"
            )

    def undo(self):
        self.doc.put_input(self.name, self.old, restored=self.dropped)


class SetMethod(QUndoCommand):
    def __init__(self, doc, method: str):
        super().__init__(f"Method {method}")
        self.doc, self.new, self.old = doc, method, doc.method

    def redo(self):
        self.doc.put_method(self.new)

    def undo(self):
        self.doc.put_method(self.old)


class SetSeed(QUndoCommand):
    def __init__(self, doc, seed: int):
        super().__init__(f"Seed {seed}")
        self.doc, self.new, self.old = doc, seed, doc.seed

    def redo(self):
        self.doc.put_seed(self.new)

    def undo(self):
        self.doc.put_seed(self.old)


class SetGeometry(QUndoCommand):
    """Replace one geometry value of one method."""

    def __init__(self, doc, method: str, key: str, value, text: str):
        super().__init__(text)
        self.doc, self.method, self.key, self.new = doc, method, key, value
        self.old = doc.geometry[method].get(key)

    def redo(self):
        self.doc.put_geometry(self.method, self.key, self.new)

    def undo(self):
        self.doc.put_geometry(self.method, self.key, self.old)
