"""The document: everything the user has set up, and the undo commands that change it.

Views listen to ``Document.changed(name)`` and never own state. Every edit goes through
``Document.push(command)`` onto one ``QUndoStack``; consecutive changes of one parameter merge into
one undo step (a slider drag is one step). Names emitted: ``"input:<name>"``, ``"method"``,
``"params"``, ``"prototype"``, ``"lines"``, ``"seed"``.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from PySide6.QtCore import QObject, Signal
from PySide6.QtGui import QUndoCommand, QUndoStack

from core import registry
from core.errors import WeftError
from core.image import crop_square
from core.params import MAX_SIDE, Params, Recipe, read_json_file, specs

SESSION_VERSION = 1
_MERGE_PARAM = 1001


@dataclass(frozen=True)
class InputImage:
    """An input picture: where it came from and its pixels (float32, as ``core.image.load_image``)."""

    path: str | None
    image: np.ndarray


class Document(QObject):
    """Inputs, method, parameters of every method, prototype rectangle, feature lines, seed."""

    changed = Signal(str)

    def __init__(self, parent=None):
        super().__init__(parent)
        self.undo_stack = QUndoStack(self)
        self.inputs: dict[str, InputImage] = {}
        self.methods = registry.methods()
        self.method = "fast" if "fast" in self.methods else next(iter(self.methods))
        self.params: dict[str, Params] = {name: m.params() for name, m in self.methods.items()}
        self.prototype: tuple[int, int, int] | None = None
        self.image_lines: list[list[float]] = []
        self.frontal_lines: list[list[float]] = []
        self.frontal_size: tuple[int, int] = (512, 512)
        self.seed = 1
        # The prototype square while it is being dragged (not an edit yet: no undo step until release).
        self.live_prototype: tuple[int, int, int] | None = None

    # --- reading -------------------------------------------------------------------------------
    @property
    def current(self) -> registry.Method:
        return self.methods[self.method]

    @property
    def current_params(self) -> Params:
        return self.params[self.method]

    def image(self, name: str) -> np.ndarray | None:
        item = self.inputs.get(name)
        return None if item is None else item.image

    def missing_inputs(self) -> list[str]:
        return [i.name for i in self.current.inputs if i.required and i.name not in self.inputs]

    def source_region(self) -> tuple[int, int, int] | None:
        """The prototype rectangle, when the current method uses it as its source region (methods
        with a ``prototype`` parameter of their own, such as ``affine``, use it as that instead)."""
        if self.prototype is None or any(s.name == "prototype" for s in specs(self.current.params)):
            return None
        return self.prototype

    def method_inputs(self) -> dict[str, np.ndarray]:
        """The current method's loaded inputs; the texture cropped to the source region if there is one."""
        out = {i.name: self.inputs[i.name].image for i in self.current.inputs if i.name in self.inputs}
        region = self.source_region()
        first = self.current.inputs[0].name
        if region is not None and first in out:
            out[first] = crop_square(out[first], region, what=first)
        return out

    def lines_json(self) -> str | None:
        """The feature lines as DESIGN.md's JSON text (complete pairs only), or None if there are none."""
        n = min(len(self.image_lines), len(self.frontal_lines))
        if n == 0:
            return None
        return json.dumps({"image_lines": self.image_lines[:n], "frontal_lines": self.frontal_lines[:n],
                           "frontal_size": list(self.frontal_size)})

    def run_params(self) -> Params:
        """The current method's parameters as a run uses them: a method with a ``lines`` parameter
        (nfpt) gets the document's feature lines as JSON text, one with a ``prototype`` parameter
        (affine) the prototype square as ``"X,Y,S"`` (the one being dragged, if any), so recipes need
        no extra file and the mouse is the one way to set them."""
        params = self.current_params
        names = {s.name for s in specs(self.current.params)}
        if "lines" in names:
            params = params.replace(lines=self.lines_json())
        if "prototype" in names:
            rect = self.live_prototype or self.prototype
            params = params.replace(prototype=",".join(str(int(v)) for v in rect) if rect else None)
        return params

    def recipe(self, relative_to: str | Path | None = None) -> Recipe:
        """The recipe that reproduces the current result (``weft run`` gives the same pixels)."""
        names = {i.name for i in self.current.inputs}
        inputs = {}
        for name, item in self.inputs.items():
            if name in names and item.path:
                inputs[name] = _relative(item.path, relative_to)
        return Recipe(method=self.method, params=self.run_params().to_dict(), inputs=inputs, seed=self.seed,
                      region=self.source_region())

    # --- edits (undoable) ----------------------------------------------------------------------
    def push(self, command: QUndoCommand) -> None:
        self.undo_stack.push(command)

    def set_param(self, name: str, value: Any) -> None:
        """Undoable change of one parameter of the current method (validated first)."""
        new = self.current_params.replace(**{name: value})
        if new != self.current_params:
            self.push(SetParams(self, self.method, new, f"{name} = {value}", merge_key=name))

    def set_input(self, name: str, path: str | None, image: np.ndarray) -> None:
        self.push(SetInput(self, name, InputImage(path, image)))

    def set_method(self, method: str) -> None:
        if method != self.method:
            self.push(SetMethod(self, method))

    def set_prototype(self, rect: tuple[int, int, int] | None) -> None:
        if rect != self.prototype:
            self.push(SetPrototype(self, rect))

    def set_lines(self, image_lines, frontal_lines, text: str = "Edit lines", frontal_size=None) -> None:
        new = ([list(map(float, ln)) for ln in image_lines], [list(map(float, ln)) for ln in frontal_lines])
        size = tuple(frontal_size) if frontal_size is not None else self.frontal_size
        if new != (self.image_lines, self.frontal_lines) or size != self.frontal_size:
            self.push(SetLines(self, *new, text, frontal_size=size))

    # --- raw mutators (used by the commands) ---------------------------------------------------
    def _put_params(self, method: str, params: Params) -> None:
        self.params[method] = params
        self.changed.emit("params")

    def _put_input(self, name: str, item: InputImage | None) -> None:
        if item is None:
            self.inputs.pop(name, None)
        else:
            self.inputs[name] = item
        self.changed.emit(f"input:{name}")

    def _put_method(self, method: str) -> None:
        self.method = method
        self.changed.emit("method")

    def _put_prototype(self, rect) -> None:
        self.prototype = rect
        self.changed.emit("prototype")

    def _put_lines(self, image_lines, frontal_lines, frontal_size=None) -> None:
        self.image_lines = [list(x) for x in image_lines]
        self.frontal_lines = [list(x) for x in frontal_lines]
        if frontal_size is not None:
            self.frontal_size = (int(frontal_size[0]), int(frontal_size[1]))
        self.changed.emit("lines")

    # --- sessions ------------------------------------------------------------------------------
    def session_dict(self, relative_to: str | Path | None = None) -> dict:
        return {
            "weft_session": SESSION_VERSION,
            "method": self.method,
            "params": {name: p.to_dict() for name, p in self.params.items()},
            "inputs": {name: _relative(item.path, relative_to) for name, item in self.inputs.items() if item.path},
            "prototype": list(self.prototype) if self.prototype else None,
            "lines": {"image_lines": self.image_lines, "frontal_lines": self.frontal_lines,
                      "frontal_size": list(self.frontal_size)},
            "seed": self.seed,
        }

    def save_session(self, path: str | Path) -> None:
        from core.image import atomic_write_bytes

        path = Path(path)
        text = json.dumps(self.session_dict(relative_to=path.resolve().parent), indent=1)
        atomic_write_bytes(path, (text + "\n").encode("utf-8"))


MAX_SEED = 2**31 - 1  # the studio's seed box
FRONTAL_SIDES = (2, MAX_SIDE)  # what a feature-lines file may give (core.rectify)


def read_session(path: str | Path) -> dict:
    """Parse and validate a session file (JSON only, at most ``core.params.MAX_FILE_BYTES``); input
    paths come back absolute, relative ones resolved against the session's folder. ``WeftError`` with
    one line naming the file if anything is wrong, so a bad file never half-replaces a document."""
    path = Path(path)
    data = read_json_file(path, "weft session")
    try:
        return _session_from_data(data, path.resolve().parent)
    except WeftError as e:
        raise WeftError(f"{path}: {e}") from None


def _session_from_data(data: Any, base: Path) -> dict:
    if not isinstance(data, dict) or data.get("weft_session") != SESSION_VERSION:
        raise WeftError(f"not a weft session file (version {SESSION_VERSION})")
    methods = registry.methods()
    if data.get("method") not in methods:
        raise WeftError(f"unknown method {data.get('method')!r}")
    raw_params = _get(data, "params", dict, "an object of method name -> parameters", {})
    params = {}
    for name, values in raw_params.items():
        if name in methods:  # a method this version lacks is skipped, not fatal
            try:
                params[name] = methods[name].params.from_dict(values)
            except WeftError as e:
                raise WeftError(f"{name}: {e}") from None
    known_inputs = {i.name for m in methods.values() for i in m.inputs}
    inputs = {}
    for name, value in _get(data, "inputs", dict, "an object of input name -> image file", {}).items():
        if name not in known_inputs:
            raise WeftError(f"unknown input {name!r} (known: {', '.join(sorted(known_inputs))})")
        if not isinstance(value, str) or not value or "\0" in value:
            raise WeftError(f"input {name!r} = {value!r} is not a file path")
        inputs[name] = value if os.path.isabs(value) else str(base / value)
    proto = data.get("prototype")
    if proto is not None and (not isinstance(proto, list) or len(proto) != 3 or not _ints(proto, 0)
                              or proto[2] < 1):
        raise WeftError(f"prototype = {proto!r} must be [x, y, side] in pixels, or null")
    lines = _get(data, "lines", dict, "an object {image_lines, frontal_lines, frontal_size}", {})
    image_lines = _lines(lines, "image_lines")
    frontal_lines = _lines(lines, "frontal_lines")
    lo, hi = FRONTAL_SIDES
    frontal_size = lines.get("frontal_size", [512, 512])
    if not isinstance(frontal_size, list) or len(frontal_size) != 2 or not _ints(frontal_size, lo, hi):
        raise WeftError(f"frontal_size = {frontal_size!r} must be [width, height], each {lo}..{hi}")
    seed = data.get("seed", 1)
    if not _ints([seed], 0, MAX_SEED):
        raise WeftError(f"seed = {seed!r} must be an integer in 0..{MAX_SEED}")
    return {"method": data["method"], "params": params, "inputs": inputs,
            "prototype": tuple(proto) if proto else None,
            "image_lines": image_lines, "frontal_lines": frontal_lines,
            "frontal_size": tuple(frontal_size), "seed": seed}


def _get(data: dict, key: str, kind: type, what: str, default):
    value = data.get(key)
    if value is None:
        return default
    if not isinstance(value, kind):
        raise WeftError(f"{key} must be {what}")
    return value


def _ints(values, lo: int, hi: int | None = None) -> bool:
    return all(isinstance(v, int) and not isinstance(v, bool) and lo <= v and (hi is None or v <= hi)
               for v in values)


def _lines(lines: dict, key: str) -> list[list[float]]:
    value = lines.get(key, [])
    if (not isinstance(value, list)
            or not all(isinstance(ln, list) and len(ln) == 4
                       and all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in ln)
                       for ln in value)):
        raise WeftError(f"{key} must be a list of [x1, y1, x2, y2] in pixels")
    return [[float(v) for v in ln] for ln in value]


def _relative(path: str | None, base: str | Path | None) -> str | None:
    if path is None or base is None:
        return path
    try:
        return os.path.relpath(Path(path).resolve(), Path(base).resolve())
    except ValueError:
        return str(Path(path).resolve())


# --- undo commands -------------------------------------------------------------------------------


class SetParams(QUndoCommand):
    """Replace the parameters of one method; consecutive edits of one parameter merge."""

    def __init__(self, doc: Document, method: str, new: Params, text: str, merge_key: str | None = None):
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
        self.doc._put_params(self.method, self.new)

    def undo(self):
        self.doc._put_params(self.method, self.old)


class SetInput(QUndoCommand):
    def __init__(self, doc: Document, name: str, item: InputImage):
        label = Path(item.path).name if item.path else "image"
        super().__init__(f"Open {name} {label}")
        self.doc, self.name, self.new = doc, name, item
        self.old = doc.inputs.get(name)

    def redo(self):
        self.doc._put_input(self.name, self.new)

    def undo(self):
        self.doc._put_input(self.name, self.old)


class SetMethod(QUndoCommand):
    def __init__(self, doc: Document, method: str):
        super().__init__(f"Method {method}")
        self.doc, self.new, self.old = doc, method, doc.method

    def redo(self):
        self.doc._put_method(self.new)

    def undo(self):
        self.doc._put_method(self.old)


class SetPrototype(QUndoCommand):
    def __init__(self, doc: Document, rect):
        super().__init__("Prototype" if rect else "Clear prototype")
        self.doc, self.new, self.old = doc, rect, doc.prototype

    def redo(self):
        self.doc._put_prototype(self.new)

    def undo(self):
        self.doc._put_prototype(self.old)


class SetLines(QUndoCommand):
    def __init__(self, doc: Document, image_lines, frontal_lines, text: str, frontal_size=None):
        super().__init__(text)
        self.doc = doc
        self.new = (image_lines, frontal_lines, frontal_size or doc.frontal_size)
        self.old = ([list(x) for x in doc.image_lines], [list(x) for x in doc.frontal_lines], doc.frontal_size)

    def redo(self):
        self.doc._put_lines(*self.new)

    def undo(self):
        self.doc._put_lines(*self.old)
