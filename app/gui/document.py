"""The document: everything the user has set up; every edit an undo command (``commands.py``).

Contract: views listen to the document's signals and never own state; they read its public
attributes and change it only through its setters (``set_param``, ``set_params``, ``set_input``,
``set_method``, ``set_seed``, ``set_geometry``/``set_square``/``set_lines``/``set_mask``) or
:meth:`Document.restore`. Every setter pushes one ``QUndoCommand`` onto one ``QUndoStack`` (consecutive
changes of one parameter merge: a slider drag is one step). One signal per kind of change:
``input_changed(name)``, ``method_changed()``, ``params_changed()``, ``geometry_changed()``,
``seed_changed()``, ``restored()`` (everything changed), and ``changed()`` after any of them.
``message(text)`` says what an edit did on the side (a mask of another size dropped).

An edit in progress (a square dragged, a mask stroke painted, a slider held) is the document's
:attr:`~Document.live` edit, set through :meth:`~Document.set_live` and :meth:`~Document.drag_param`
and heard as ``live_changed(LiveEdit | None)``: it is not an undo step until it is let go (the
setter's edit), and :meth:`~Document.end_live` drops it (Esc, a release that changed nothing).

A mask geometry (``Geometry(MASK, input=...)``) is an input of its method that the user paints: its
:class:`~weft.core.geometry.Mask` is held as geometry (undoable, per method) and given to the method
as that input (``mask.to_image()``) when it is the size of the image it is painted on; opening an
image file as that input makes it the mask. Its session (:meth:`Document.session`, a
:class:`~weft.core.session.Session`) keeps it as a 1-bit PNG beside the session file.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from PySide6.QtCore import QObject, Signal
from PySide6.QtGui import QUndoCommand, QUndoStack
from weft.core import registry
from weft.core.errors import WeftError
from weft.core.geometry import LINES, MASK, SQUARE, LineDraft, Margins, Mask, MaskStroke, Square
from weft.core.params import Params, Recipe
from weft.core.session import Session
from weft.core.studio import Geometry, Studio

from .commands import SetGeometry, SetInput, SetMethod, SetParams, SetSeed
from .state import DocumentState, InputImage, LiveEdit, read_input

__all__ = ["Document", "DocumentState", "InputImage", "LiveEdit", "read_input"]


class Document(QObject):
    """Inputs, method, parameters and geometry of every method, seed (see the module docstring).

    Geometry belongs to its method: ``geometry[method][key]`` holds the typed value of each geometry
    the method's studio description lists (the key is the parameter it fills, or ``"region"``), so a
    square drawn for one method never reaches another. ``params`` hold the rest; :meth:`run_params`
    puts the geometry in (typed: no text in between).
    """

    input_changed = Signal(str)  # the input's name
    method_changed = Signal()
    params_changed = Signal()
    geometry_changed = Signal()
    seed_changed = Signal()
    restored = Signal()  # everything changed at once (restore)
    changed = Signal()  # after each of the above
    live_changed = Signal(object)  # the edit in progress: a LiveEdit, or None when it was dropped
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
        self._live: LiveEdit | None = None

    # --- reading -------------------------------------------------------------------------------
    @property
    def live(self) -> LiveEdit | None:
        """The edit in progress (a geometry dragged or painted, a slider held), or None."""
        return self._live

    def _live_geometry(self, key: str) -> tuple[bool, Any]:
        """``(True, value)`` when geometry ``key`` is being dragged or painted, else ``(False, None)``."""
        live = self._live
        if live is None or live.param or live.key != key:
            return False, None
        return True, live.value

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
            dragged, value = self._live_geometry(g.key)
            if live and dragged:
                mask = value
                if isinstance(mask, MaskStroke):  # a stroke being painted: the mask so far (a copy)
                    mask = mask.snapshot()
            on = self.image(g.input_for(self.inputs))
            if mask is not None and mask and on is not None and mask.shape == on.shape[:2]:
                out[g.input] = mask
        return out

    def method_inputs(self, *, live: bool = False) -> dict[str, np.ndarray]:
        """The current method's loaded inputs (its painted masks among them, as images; with
        ``live`` the stroke being drawn), uncropped: a render request crops to the source region."""
        return self.deferred_inputs(live=live)()

    def deferred_inputs(self, *, live: bool = False) -> Callable[..., dict[str, np.ndarray]]:
        """:meth:`method_inputs` captured now and built when called, on any thread: the slow part
        (a painted mask's float image, 64 MB for a 4096² mask) is left to the call, so a render job
        does it on its worker, not the GUI thread. The call takes ``names`` (default all): only those
        inputs."""
        arrays, masks, _, _ = self._input_parts(live)

        def build(names=None) -> dict[str, np.ndarray]:
            out = {n: a for n, a in arrays.items() if names is None or n in names}
            out.update({n: m.to_image() for n, m in masks.items() if names is None or n in names})
            return out

        return build

    def input_shapes(self) -> dict[str, tuple[int, ...]]:
        """The shapes of what a render of the current method runs on (input name -> array shape: the
        source region's crop included), without building it: what its "auto" parameters depend on
        (``Studio.resolved``)."""
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
            dragged, moving = self._live_geometry(g.key)
            if live and dragged:
                value = moving
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
        choice made from a list, each its own step. A slider held (:meth:`drag_param`) is let go
        here: ``live_changed(None)`` follows, whether the value changed or not."""
        ending = self._live is not None and self._live.param
        if ending:
            self._live = None
        try:
            new = self.current_params.replace(**{name: value})
            if new != self.current_params:
                self.push(SetParams(self, self.method, new, f"{name} = {value}", merge_key=name if merge else None))
        finally:
            if ending:
                self.live_changed.emit(None)

    def drag_param(self, name: str, value: Any) -> None:
        """A slider of the current method is held at ``value``: the change is made (one undo step
        with the drag's other moves) while :attr:`live` says the slider is still held; letting it
        go is :meth:`set_param` (or :meth:`end_live`)."""
        new = self.current_params.replace(**{name: value})
        self._live = LiveEdit(name, value, param=True)
        if new != self.current_params:
            self.push(SetParams(self, self.method, new, f"{name} = {value}", merge_key=name))

    def set_live(self, key: str, value: Any, box: tuple | None = None) -> None:
        """Geometry ``key`` of the current method is being dragged or painted: ``value`` so far
        (``box``: a stroke's latest dab). Not an edit: the setter's edit on release replaces it."""
        self._live = LiveEdit(key, value, None if box is None else tuple(box))
        self.live_changed.emit(self._live)

    def end_live(self) -> None:
        """The edit in progress ended without an edit (Esc, a release that changed nothing)."""
        if self._live is not None:
            self._live = None
            self.live_changed.emit(None)

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
        the state lacks are closed). Listeners get ``restored()`` once."""
        self.inputs = dict(state.inputs)
        if state.method is not None:
            if state.method not in self.methods:
                raise WeftError(f"the studio does not offer method {state.method!r}")
            self.method = state.method
        self.params = {name: m.params() for name, m in self.methods.items()}
        self.params.update({k: v for k, v in state.params.items() if k in self.methods})
        self.geometry = {name: dict(state.geometry.get(name, {})) for name in self.methods}
        self.seed = int(state.seed)
        self._live = None
        self.undo_stack.clear()
        self.restored.emit()
        self.changed.emit()

    # --- the undo commands' changes (commands.py; nothing else calls them) ---------------------
    def put_params(self, method: str, params: Params) -> None:
        self.params[method] = params
        self.params_changed.emit()
        self.changed.emit()

    def put_input(self, name: str, item: InputImage | None, dropped=(), restored=()) -> None:
        """Open (or close) input ``name``; ``dropped`` (method, key) masks that no longer fit it go,
        ``restored`` (method, key, mask) ones come back (an undo)."""
        for method, key in dropped:
            self.geometry[method].pop(key, None)
        for method, key, mask in restored:
            self.geometry[method][key] = mask
        if item is None:
            self.inputs.pop(name, None)
        else:
            self.inputs[name] = item
        self.input_changed.emit(name)
        if dropped or restored:
            self.geometry_changed.emit()
        self.changed.emit()

    def put_method(self, method: str) -> None:
        self.method = method
        self._live = None
        self.method_changed.emit()
        self.changed.emit()

    def put_geometry(self, method: str, key: str, value) -> None:
        if value is None:
            self.geometry[method].pop(key, None)
        else:
            self.geometry[method][key] = value
        self._live = None  # (the edit the live one was: it ends here, no live_changed)
        self.geometry_changed.emit()
        self.changed.emit()

    def put_seed(self, seed: int) -> None:
        self.seed = seed
        self.seed_changed.emit()
        self.changed.emit()

    # --- sessions ---------------------------------------------------------------------------
    def session(self, *, saved_as: str | None = None) -> Session:
        """The document as a :class:`~weft.core.session.Session` (immutable: it can be written on
        any thread, with its masks, while the document goes on changing)."""
        opened = {name: item for name, item in self.inputs.items() if item.path}
        return Session(
            method=self.method,
            params=dict(self.params),
            inputs={name: item.path for name, item in opened.items()},
            # which method an input was opened for, where a method takes it only then (Studio.own_inputs)
            opened_for={name: item.opened_for for name, item in opened.items() if item.opened_for is not None},
            geometry={name: dict(values) for name, values in self.geometry.items() if values},
            seed=self.seed,
            saved_as=saved_as,
        )
