"""The document: everything the user has set up, and the undo commands that change it.

Contract: views listen to ``Document.changed(name)`` and never own state; they read the document's
public attributes and change it only through its setters (``set_param``, ``set_params``,
``set_input``, ``set_method``, ``set_seed``, ``set_geometry``/``set_square``/``set_lines``/``set_mask``) or
:meth:`Document.restore`. Every setter pushes one ``QUndoCommand`` onto one ``QUndoStack`` (consecutive
changes of one parameter merge: a slider drag is one step). Names emitted: ``"input:<name>"``,
``"method"``, ``"params"``, ``"geometry"``, ``"seed"``, ``"restored"`` (everything changed).
``message(text)`` says what an edit did on the side (a mask of another size dropped).

A mask geometry (``Geometry(MASK, input=...)``) is an input of its method that the user paints: its
:class:`~weft.core.geometry.Mask` is held as geometry (undoable, per method) and given to the method
as that input (``mask.to_image()``) when it is the size of the image it is painted on; opening an
image file as that input makes it the mask. A session keeps it as a 1-bit PNG beside the session file.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from PySide6.QtCore import QObject, Signal
from PySide6.QtGui import QUndoCommand, QUndoStack
from weft.core import registry
from weft.core.errors import WeftError
from weft.core.geometry import LINES, MASK, SQUARE, LineDraft, Margins, Mask, MaskStroke, Square
from weft.core.params import Params, Recipe, relative_path
from weft.core.session import SESSION_VERSION, mask_file, read_session  # noqa: F401 (read_session: the studio reads sessions)
from weft.core.studio import Geometry, Studio

_MERGE_PARAM = 1001


@dataclass(frozen=True)
class InputImage:
    """An input picture: where it came from, its pixels (float32, as ``weft.core.image.load_image``)
    and, when the file has an alpha channel, the pixels with it (``load_image(..., alpha=True)``:
    (H, W, 2) or (H, W, 4)). A method gets what ``weft run`` gives it: the pixels with alpha for an
    input whose ``InputSpec.alpha`` asks for them, the others without; "Fill transparent" paints a
    mask from :attr:`alpha`."""

    path: str | None
    image: np.ndarray
    with_alpha: np.ndarray | None = None
    opened_for: str | None = None  # the method that was current when it was opened (Studio.own_inputs)
    bit_depth: int = 8  # of the file (16 for a 16-bit PNG or TIFF): the pixel read-out counts in it

    @property
    def alpha(self) -> np.ndarray | None:
        """The alpha channel (H, W) in [0, 1], or None."""
        return None if self.with_alpha is None else self.with_alpha[..., -1]


def read_input(path: str | Path) -> InputImage:
    """Decode an image file as an input (its pixels as ``load_image`` gives them, and with its alpha
    when it has one). Slow for a large file: call it off the GUI thread. ``WeftError`` naming the file."""
    from weft.core.image import load_image

    loaded = load_image(path)
    with_alpha = None
    if loaded.info.had_alpha:
        kept = load_image(path, alpha=True).image
        if kept.ndim == 3 and kept.shape[2] in (2, 4) and kept.shape[:2] == loaded.image.shape[:2]:
            with_alpha = kept
    return InputImage(str(path), loaded.image, with_alpha, bit_depth=loaded.info.bit_depth)


@dataclass(frozen=True)
class DocumentState:
    """A whole document at once, for :meth:`Document.restore` (sessions, crash recovery, the bundled
    examples, screenshots, benchmarks). ``geometry`` maps method -> geometry key -> typed value
    (:class:`~weft.core.geometry.Square`, :class:`~weft.core.geometry.LineDraft`, a
    :class:`~weft.core.geometry.Mask`, :class:`~weft.core.geometry.Margins`); what is not given is empty
    or default."""

    inputs: dict[str, InputImage] = field(default_factory=dict)
    method: str | None = None
    params: dict[str, Params] = field(default_factory=dict)
    geometry: dict[str, dict[str, Any]] = field(default_factory=dict)
    seed: int = 1


class Document(QObject):
    """Inputs, method, parameters and geometry of every method, seed (see the module docstring).

    Geometry belongs to its method: ``geometry[method][key]`` holds the typed value of each geometry
    the method's studio description lists (the key is the parameter it fills, or ``"region"``), so a
    square drawn for one method never reaches another. ``params`` hold the rest; :meth:`run_params`
    puts the geometry in (typed: no text in between).
    """

    changed = Signal(str)
    message = Signal(str)

    def __init__(self, parent=None):
        super().__init__(parent)
        self.undo_stack = QUndoStack(self)
        self.inputs: dict[str, InputImage] = {}
        self.methods = registry.studio_methods()
        self.method = next(iter(self.methods))
        self.params: dict[str, Params] = {name: m.params() for name, m in self.methods.items()}
        self.geometry: dict[str, dict[str, Any]] = {name: {} for name in self.methods}
        self.seed = 1
        # The geometry being dragged (key, value): not an edit yet, no undo step until release. A mask
        # being painted is the tool's ``MaskStroke`` (its bits change in place, dab by dab).
        self.live: tuple[str, Any] | None = None

    # --- reading -------------------------------------------------------------------------------
    @property
    def current(self) -> registry.Method:
        return self.methods[self.method]

    @property
    def studio(self) -> Studio:
        return self.current.studio

    @property
    def current_params(self) -> Params:
        return self.params[self.method]

    def item(self, name: str) -> InputImage | None:
        """Input ``name`` as the current method sees it: None if not open, or if it is one of the
        method's own inputs (``Studio.own_inputs``) opened for another method."""
        item = self.inputs.get(name)
        if item is not None and name in self.studio.own_inputs and item.opened_for != self.method:
            return None
        return item

    def image(self, name: str) -> np.ndarray | None:
        item = self.item(name)
        return None if item is None else item.image

    def missing_inputs(self) -> list[str]:
        return [i.name for i in self.current.inputs if i.required and i.name not in self.inputs]

    def geometry_of(self, kind: str, method: str | None = None) -> Geometry | None:
        """The (first) geometry of ``kind`` the method (default the current one) has."""
        method = method or self.method
        return next((g for g in self.methods[method].studio.geometry if g.kind == kind), None)

    def value(self, key: str, method: str | None = None) -> Any:
        """The typed value of one geometry of a method (default the current one), or None."""
        return self.geometry[method or self.method].get(key)

    @property
    def square(self) -> Square | None:
        """The current method's square (its source region or a square parameter), or None."""
        g = self.geometry_of(SQUARE)
        return None if g is None else self.value(g.key)

    @property
    def lines(self) -> LineDraft:
        """The current method's feature lines being drawn (empty if it has none)."""
        g = self.geometry_of(LINES)
        value = None if g is None else self.value(g.key)
        return value if value is not None else LineDraft()

    @property
    def image_lines(self) -> list[list[float]]:
        return [list(x) for x in self.lines.image_lines]

    @property
    def frontal_lines(self) -> list[list[float]]:
        return [list(x) for x in self.lines.frontal_lines]

    @property
    def frontal_size(self) -> tuple[int, int]:
        return self.lines.frontal_size

    def region(self, method: str | None = None) -> Square | None:
        """The source region of a method (a square that fills no parameter), or None."""
        method = method or self.method
        g = next((g for g in self.methods[method].studio.geometry if g.param is None and g.kind == SQUARE), None)
        return None if g is None else self.value(g.key, method)

    def mask_geometry(self, input_name: str, method: str | None = None) -> Geometry | None:
        """The mask geometry of a method (default the current one) that *is* input ``input_name``."""
        method = method or self.method
        return next((g for g in self.methods[method].studio.geometry if g.kind == MASK and g.input == input_name), None)

    def masks(self, *, live: bool = False) -> dict[str, Mask]:
        """The current method's painted masks that it gets as inputs (input name -> mask): those not
        empty and the size of the image they are painted on (with ``live``, the stroke being drawn)."""
        out = {}
        for g in self.studio.geometry:
            if g.kind != MASK:
                continue
            mask = self.value(g.key)
            if live and self.live is not None and self.live[0] == g.key:
                mask = self.live[1]
                if isinstance(mask, MaskStroke):  # a stroke being painted: the mask so far (a copy)
                    mask = mask.snapshot()
            on = self.image(g.input_for(self.inputs))
            if mask is not None and mask and on is not None and mask.shape == on.shape[:2]:
                out[g.input] = mask
        return out

    def method_inputs(self, *, live: bool = False) -> dict[str, np.ndarray]:
        """The current method's loaded inputs (its painted masks among them, as images; with
        ``live`` the stroke being drawn); the canvas cropped to the source region if there is one."""
        return self.deferred_inputs(live=live)()

    def deferred_inputs(self, *, live: bool = False) -> Callable[..., dict[str, np.ndarray]]:
        """:meth:`method_inputs` captured now and built when called, on any thread: the slow part
        (a painted mask's float image and a crop to the source region) is
        left to the call, so a render job does it on its worker, not the GUI thread. The call
        takes ``names`` (default all): only those inputs."""
        arrays, masks, region, on = self._input_parts(live)

        def build(names=None) -> dict[str, np.ndarray]:
            out = {n: a for n, a in arrays.items() if names is None or n in names}
            out.update({n: m.to_image() for n, m in masks.items() if names is None or n in names})
            if region is not None and on in out:
                out[on] = region.crop(out[on], what=on.replace("_", " "))
            return out

        return build

    def input_shapes(self) -> dict[str, tuple[int, ...]]:
        """The shapes of what :meth:`method_inputs` gives the current method (input name -> array
        shape), without building it: what its "auto" parameters depend on (``Studio.resolved``)."""
        arrays, masks, region, on = self._input_parts(False)
        out = {name: a.shape for name, a in arrays.items()}
        out.update({name: mask.shape for name, mask in masks.items()})
        if region is not None and on in out:
            shape = out[on]
            if region.x + region.side <= shape[1] and region.y + region.side <= shape[0]:
                out[on] = (region.side, region.side) + tuple(shape[2:])
        return out

    def auto_values(self) -> dict[str, Any]:
        """What the current method's unset ("auto") parameters resolve to now (``Studio.resolved``),
        as a run resolves them: with the parameters a run takes, the geometry's among them (an
        extended canvas can change them), and the shapes of its inputs."""
        return self.studio.resolved(self.run_params(live=False), self.input_shapes())

    def param_ranges(self) -> dict[str, tuple]:
        """The range each of the current method's parameters accepts now, with its open inputs and
        the other parameters' values (``Studio.ranges``; a parameter not named keeps its Spec's)."""
        return self.studio.ranges(self.run_params(live=False), self.input_shapes())

    def _input_parts(self, live: bool):
        """What the current method's inputs are made of: the open images it gets (name -> array, with
        alpha where its ``InputSpec`` asks), its painted masks (name -> ``Mask``), and its source region
        with the name of the input it crops (or None, None)."""
        painted = {g.input for g in self.studio.geometry if g.kind == MASK}
        arrays = {}
        for spec in self.current.inputs:
            item = self.item(spec.name)
            if item is not None and spec.name not in painted:
                keep = spec.alpha and item.with_alpha is not None
                arrays[spec.name] = item.with_alpha if keep else item.image
        masks = self.masks(live=live)  # (immutable: safe to read on another thread)
        g = next((g for g in self.studio.geometry if g.param is None and g.kind == SQUARE), None)
        region = self.region() if g is not None else None
        return arrays, masks, region, None if g is None else g.on[0]

    def run_params(self, *, live: bool = True) -> Params:
        """The current method's parameters as a run uses them: its geometry put into the parameters it
        fills (typed; with ``live``, the one being dragged instead of the stored one)."""
        params = self.current_params
        changes = {}
        for g in self.studio.geometry:
            if g.param is None:
                continue  # the source region (a crop) or a mask (an input)
            value = self.value(g.key)
            if live and self.live is not None and self.live[0] == g.key:
                value = self.live[1]
            if isinstance(value, LineDraft):
                value = value.complete()
            changes[g.param] = value
        return params.replace(**changes) if changes else params

    def nothing_drawn(self) -> str | None:
        """What the user must draw before the current method renders in the studio (the words of a
        geometry it needs, ``Geometry.needed``, that is not drawn), or None."""
        params = self.run_params(live=False)
        for g in self.studio.geometry:
            if g.needed and (getattr(params, g.param, None) if g.param is not None else self.value(g.key)) is None:
                return g.needed
        return None

    def recipe(self, params: Params | None = None) -> Recipe:
        """The recipe of a render of the document now with ``params`` (default :meth:`run_params`);
        input paths absolute (``Recipe.to_json(relative_to=...)`` writes them relative to its file).
        Its inputs are the files of :meth:`method_inputs`: never a painted mask's name (an image opened
        under that name for another method is not what this method ran on); the export adds the
        painted masks the result was rendered with."""
        painted = {g.input for g in self.studio.geometry if g.kind == MASK}
        inputs = {}
        for spec in self.current.inputs:  # what method_inputs gives the method: its painted masks are
            item = self.item(spec.name)  # not files (export writes them beside the result)
            if item is not None and item.path and spec.name not in painted:
                inputs[spec.name] = item.path
        params = self.run_params(live=False) if params is None else params
        return Recipe(method=self.method, params=params.to_dict(), inputs=inputs, seed=self.seed, region=self.region())

    # --- edits (undoable) ----------------------------------------------------------------------
    def push(self, command: QUndoCommand) -> None:
        self.undo_stack.push(command)

    def set_param(self, name: str, value: Any, *, merge: bool = True) -> None:
        """Undoable change of one parameter of the current method (validated first). ``merge``: one
        undo step with the change of the same parameter just before (a slider's drag); False for a
        choice made from a list, each its own step."""
        new = self.current_params.replace(**{name: value})
        if new != self.current_params:
            self.push(SetParams(self, self.method, new, f"{name} = {value}", merge_key=name if merge else None))

    def set_params(self, params: Params, text: str) -> None:
        """Undoable change of several parameters of the current method at once (one step)."""
        if params != self.current_params:
            self.push(SetParams(self, self.method, params, text))

    def set_input(
        self, name: str, path: str | None, image: np.ndarray, with_alpha: np.ndarray | None = None, bit_depth: int = 8
    ) -> None:
        """Undoable opening of an input image. An input the current method paints (a mask geometry)
        becomes that mask (refused in one line if it is not the size of its image). Masks painted on
        this input that do not fit the new image are dropped (said in ``message``; undo brings them back)."""
        g = self.mask_geometry(name)
        if g is not None:
            on = g.input_for(self.inputs)
            try:
                mask = Mask.from_image(image, name.replace("_", " "))
                if self.image(on) is not None:
                    mask.check_size(self.image(on).shape, what=on.replace("_", " "), name=name.replace("_", " "))
            except WeftError as e:
                shown = Path(path).name if path else name
                self.message.emit(f"{shown}: {e}")
                return
            self.set_mask(g.key, mask, f"Open {name.replace('_', ' ')} {Path(path).name if path else ''}".strip())
            return
        self.push(SetInput(self, name, InputImage(path, image, with_alpha, self.method, bit_depth)))

    def clear_input(self, name: str) -> None:
        """Undoable removal of an open input (the method then runs without it)."""
        if self.item(name) is not None:
            self.push(SetInput(self, name, None))

    def set_method(self, method: str) -> None:
        if method != self.method:
            self.push(SetMethod(self, method))

    def set_seed(self, seed: int) -> None:
        """Undoable change of the seed (it marks the document unsaved like any edit)."""
        seed = int(seed)
        if seed != self.seed:
            self.push(SetSeed(self, seed))

    def set_geometry(self, key: str, value: Any, text: str) -> None:
        """Undoable change of one geometry of the current method."""
        if value != self.value(key):
            self.push(SetGeometry(self, self.method, key, value, text))

    def set_mask(self, key: str, mask: Mask | None, text: str) -> None:
        """Undoable change of a mask geometry of the current method (an empty mask clears it)."""
        self.set_geometry(key, mask if mask is not None and mask else None, text)

    def set_margins(self, key: str, margins: Margins | None, text: str = "Extend canvas") -> None:
        """Undoable change of a margins geometry of the current method (no margins clears it)."""
        self.set_geometry(key, margins if margins else None, text)

    def set_square(self, rect) -> None:
        """Set (or with None clear) the current method's square; nothing if it has none."""
        g = self.geometry_of(SQUARE)
        if g is not None:
            self.set_geometry(g.key, None if rect is None else Square(*rect), "Square" if rect else "Clear square")

    def set_lines(self, image_lines, frontal_lines, text: str = "Edit lines", frontal_size=None) -> None:
        """Set the current method's feature lines (pairs may be unfinished); nothing if it has none."""
        g = self.geometry_of(LINES)
        if g is None:
            return
        size = tuple(frontal_size) if frontal_size is not None else self.frontal_size
        draft = LineDraft(tuple(map(tuple, image_lines)), tuple(map(tuple, frontal_lines)), size)
        if draft != self.lines:
            self.set_geometry(g.key, draft, text)

    # --- the whole document at once ------------------------------------------------------------
    def restore(self, state: DocumentState) -> None:
        """Replace the whole document by ``state``: one clean state with no undo history (inputs
        the state lacks are closed). Listeners get ``changed("restored")`` once."""
        self.inputs = dict(state.inputs)
        if state.method is not None:
            if state.method not in self.methods:
                raise WeftError(f"the studio does not offer method {state.method!r}")
            self.method = state.method
        self.params = {name: m.params() for name, m in self.methods.items()}
        self.params.update({k: v for k, v in state.params.items() if k in self.methods})
        self.geometry = {name: dict(state.geometry.get(name, {})) for name in self.methods}
        self.seed = int(state.seed)
        self.live = None
        self.undo_stack.clear()
        self.changed.emit("restored")

    # --- raw mutators (used by the undo commands of this module only) --------------------------
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
        self.live = None
        self.changed.emit("method")

    def _put_geometry(self, method: str, key: str, value) -> None:
        if value is None:
            self.geometry[method].pop(key, None)
        else:
            self.geometry[method][key] = value
        self.live = None
        self.changed.emit("geometry")

    def _put_seed(self, seed: int) -> None:
        self.seed = seed
        self.changed.emit("seed")

    # --- sessions ------------------------------------------------------------------------------
    def session_dict(self, relative_to: str | Path | None = None, *, session: str | Path | None = None) -> dict:
        """The session JSON object. A mask is the name of its PNG beside ``session`` (the file the
        JSON goes to; :meth:`session_masks` says what to write there); without ``session`` masks are
        left out."""

        def path(p):
            return p if relative_to is None else relative_path(p, relative_to)

        def geometry(method, key, value):
            if isinstance(value, Mask):
                return None if session is None else path(str(mask_file(session, method, key)))
            return value.to_json()

        return {
            "weft_session": SESSION_VERSION,
            "method": self.method,
            "params": {name: p.to_dict() for name, p in self.params.items()},
            "inputs": {name: path(item.path) for name, item in self.inputs.items() if item.path},
            # which method an input was opened for, where a method takes it only then (Studio.own_inputs)
            "opened_for": {
                name: item.opened_for for name, item in self.inputs.items() if item.path and item.opened_for is not None
            },
            "geometry": {
                name: {key: geometry(name, key, value) for key, value in values.items()}
                for name, values in self.geometry.items()
                if values
            },
            "seed": self.seed,
        }

    def session_masks(self, session: str | Path) -> dict[Path, Mask]:
        """The mask PNGs a session at ``session`` keeps beside it: file -> mask."""
        return {
            mask_file(session, name, key): value
            for name, values in self.geometry.items()
            for key, value in values.items()
            if isinstance(value, Mask)
        }

    def session_writer(self, path: str | Path) -> Callable[[], None]:
        """Writing the session at ``path``, captured now: a function that encodes its masks as 1-bit
        PNGs beside it and writes them, then the JSON, each file atomically -- on any thread (the
        studio runs it off the GUI thread: a large mask's PNG takes a tenth of a second to encode).
        Masks are immutable and the JSON text is made here, so later edits do not reach it."""
        from weft.core.image import atomic_write_bytes

        path = Path(path)
        masks = self.session_masks(path)
        text = json.dumps(self.session_dict(relative_to=path.resolve().parent, session=path), indent=1)

        def write() -> None:
            for file, mask in masks.items():
                try:
                    mask.save(file)
                except OSError as e:
                    raise WeftError(f"{file}: cannot write the mask ({e.strerror or e})") from None
            atomic_write_bytes(path, (text + "\n").encode("utf-8"))

        return write

    def save_session(self, path: str | Path) -> None:
        """Write the session (its masks first, as 1-bit PNGs beside it), each file atomically, here
        and now (:meth:`session_writer` is the same, to be run elsewhere)."""
        self.session_writer(path)()


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
    """Open (or clear) an input; masks painted on it that do not fit the new image go with the same step."""

    def __init__(self, doc: Document, name: str, item: InputImage | None):
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
        for method, key, _mask in self.dropped:
            self.doc.geometry[method].pop(key, None)
        self.doc._put_input(self.name, self.new)
        for method, key, mask in self.dropped:
            h, w = self.new.image.shape[:2]
            self.doc.message.emit(
                f"the {key.replace('_', ' ')} of {method} ({mask.size[0]}x{mask.size[1]}) does not "
                f"fit the new {self.name.replace('_', ' ')} ({w}x{h}): dropped (Ctrl+Z brings it back)"
            )
        if self.dropped:
            self.doc.changed.emit("geometry")

    def undo(self):
        for method, key, mask in self.dropped:
            self.doc.geometry[method][key] = mask
        self.doc._put_input(self.name, self.old)
        if self.dropped:
            self.doc.changed.emit("geometry")


class SetMethod(QUndoCommand):
    def __init__(self, doc: Document, method: str):
        super().__init__(f"Method {method}")
        self.doc, self.new, self.old = doc, method, doc.method

    def redo(self):
        self.doc._put_method(self.new)

    def undo(self):
        self.doc._put_method(self.old)


class SetSeed(QUndoCommand):
    def __init__(self, doc: Document, seed: int):
        super().__init__(f"Seed {seed}")
        self.doc, self.new, self.old = doc, seed, doc.seed

    def redo(self):
        self.doc._put_seed(self.new)

    def undo(self):
        self.doc._put_seed(self.old)


class SetGeometry(QUndoCommand):
    """Replace one geometry value of one method."""

    def __init__(self, doc: Document, method: str, key: str, value, text: str):
        super().__init__(text)
        self.doc, self.method, self.key, self.new = doc, method, key, value
        self.old = doc.geometry[method].get(key)

    def redo(self):
        self.doc._put_geometry(self.method, self.key, self.new)

    def undo(self):
        self.doc._put_geometry(self.method, self.key, self.old)
