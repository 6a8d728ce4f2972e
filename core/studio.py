"""What a method tells the studio about itself (Qt-free): the studio is generic over methods.

A method that the studio offers sets ``Method.studio`` to a :class:`Studio`: its name for people,
which input is the canvas (the first view), which geometry each input carries and which parameter
(or the recipe's source region) it fills, how a preview is reduced, and which parameters are derived
from the inputs ("auto") with the values they resolve to. ``app/gui`` reads only this; it holds no
method, input or parameter name of any method, so adding a method never touches it.

Example: a method whose one input carries a square that fills its ``square`` parameter::

    Studio(title="Invert a square", canvas="image",
           geometry=(Geometry(SQUARE, on=("image",), param="square", help="drag the square to invert"),))
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Mapping

import numpy as np

from .errors import WeftError
from .geometry import KINDS, LINES, MARGINS, MASK, SQUARE  # noqa: F401 (the kinds are re-exported)

__all__ = ["Studio", "Geometry", "Figure", "describe_figures", "reduce_for_preview", "SQUARE", "LINES", "MASK",
           "MARGINS", "REGION"]

#: The key of a square that fills no parameter: the recipe's source ``region`` (the input is cropped to it).
REGION = "region"


@dataclass(frozen=True)
class Geometry:
    """One geometry the user edits with the mouse on an input.

    Attributes
    ----------
    kind : ``"square"``, ``"lines"``, ``"mask"`` or ``"margins"`` (:data:`weft.core.geometry.KINDS`):
        which tool edits it.
    on : the inputs it is drawn on, in order of preference: the first one that is open is used (the
        affine prototype lies on the prototype image when one is open, else on the texture).
    param : the ``Params`` field it fills (typed: a :class:`~weft.core.geometry.Square`,
        :class:`~weft.core.geometry.FeatureLines`); ``None`` for a square means the recipe's source
        ``region``: the first input of ``on`` is cropped to it before the method runs.
    input : for a mask only: the method's (optional) input image it *is* -- the studio paints a
        :class:`~weft.core.geometry.Mask` the size of the ``on`` image and gives it to the method as
        that input (``mask.to_image()``); a recipe names it as a PNG written beside the export, a
        session beside the session file. A mask has no ``param``.
    help : what the user does, shown as the view's title.
    live : ``live(params) -> bool``: re-render a preview while the geometry is being dragged.
    """

    kind: str
    on: tuple[str, ...]
    param: str | None = None
    help: str = ""
    live: Callable[[Any], bool] | None = None
    input: str | None = None

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"unknown geometry kind {self.kind!r} (known: {', '.join(KINDS)})")
        if self.kind == MASK:
            if self.input is None or self.param is not None:
                raise ValueError("a mask geometry names the input it is (input=...), not a parameter")
        elif self.input is not None:
            raise ValueError("only a mask geometry is an input (input=...)")
        elif self.param is None and self.kind != SQUARE:
            raise ValueError("only a square may stand for the source region (param None)")

    @property
    def key(self) -> str:
        """Its name in the document and in sessions: the parameter, the input (a mask), or :data:`REGION`."""
        if self.input is not None:
            return self.input
        return self.param if self.param is not None else REGION

    def input_for(self, open_inputs) -> str:
        """The input it is drawn on, given the names of the open inputs."""
        for name in self.on:
            if name in open_inputs:
                return name
        return self.on[-1]


@dataclass(frozen=True)
class Figure:
    """How people read one of a method's ``Result.figures`` (the report JSON keeps its key and value).

    Attributes
    ----------
    label : words before the value, e.g. ``"largest verbatim copy"``.
    unit : ``"%"`` (the value is a fraction, shown times 100), ``"px"``, ``"dB"``, ``"s"`` or ``""``.
    after : words after the value and unit, e.g. ``"of the sample"``.
    digits : significant digits of a number.

    ``Figure("largest verbatim copy", "%", "of the sample", digits=2).render(0.0532)`` is
    ``"largest verbatim copy 5.3 % of the sample"``.
    """

    label: str
    unit: str = ""
    after: str = ""
    digits: int = 3

    def render(self, value: Any) -> str:
        if isinstance(value, (bool, np.bool_)):
            text = "yes" if value else "no"
        elif isinstance(value, (int, np.integer)) and self.unit != "%":
            text = str(int(value))
        elif isinstance(value, (int, float, np.integer, np.floating)):
            v = float(value) * (100.0 if self.unit == "%" else 1.0)
            text = f"{v:.{self.digits}g}"
        else:
            text = str(value)
        if self.unit:
            text += f" {self.unit}"
        return " ".join(part for part in (self.label, text, self.after) if part)

    def prefixed(self, words: str) -> "Figure":
        """The same figure with ``words`` before its label (a figure of a step, e.g. the rectification)."""
        return Figure(f"{words} {self.label}".strip(), self.unit, self.after, self.digits)


def describe_figures(figures: Mapping[str, Any], known: Mapping[str, Figure]) -> list[str]:
    """``figures`` (a ``Result.figures``) in words: each scalar by its :class:`Figure` in ``known``,
    in the order of ``figures``; lists, tables and missing values (``None``) are left to the report.
    A key no table describes reads as its words (``"some_count"`` -> ``"some count"``)."""
    out = []
    for key, value in figures.items():
        if value is None or isinstance(value, (list, tuple, dict, np.ndarray)):
            continue
        figure = known.get(key)
        if figure is None:
            figure = Figure(key.replace("_", " "))
        out.append(figure.render(value))
    return out


@dataclass(frozen=True)
class Studio:
    """A method's studio description (see the module docstring).

    Attributes
    ----------
    title : the name people read in the method list, e.g. ``"Fast transfer (Ashikhmin)"``.
    canvas : the input shown in the first (large) view.
    geometry : what the user draws, per input (:class:`Geometry`).
    preview_inputs : inputs scaled down for a preview while a slider moves (the output follows them).
    preview_params : size parameters ``(width, height)`` scaled down for a preview instead, when
        none of ``preview_inputs`` is open.
    auto : ``auto(params, open_inputs) -> {name: value}``: what the optional ("auto") parameters
        resolve to for these inputs, shown greyed beside their "auto" box; may raise ``WeftError``.
    compare : the "before" image of Compare: the first of these inputs that is open (default the canvas).
    examples : a bundled example (``weft.core.examples``) per input, opened when the studio starts.
    rank : position in the method list (lowest first; the first is the studio's starting method).
    figures : how people read each key of the method's ``Result.figures`` (:class:`Figure`); the
        status bar shows them in words and units (:meth:`describe`), the CLI's ``--report`` keeps the keys.
    """

    title: str
    canvas: str
    geometry: tuple[Geometry, ...] = ()
    preview_inputs: tuple[str, ...] = ()
    preview_params: tuple[str, ...] = ()
    auto: Callable[[Any, frozenset], Mapping[str, Any]] | None = None
    compare: tuple[str, ...] = ()
    examples: Mapping[str, str] = field(default_factory=dict)
    rank: int = 100
    figures: Mapping[str, Figure] = field(default_factory=dict)

    def describe(self, figures: Mapping[str, Any]) -> list[str]:
        """A result's figures in words and units (see :func:`describe_figures`)."""
        return describe_figures(figures, self.figures)

    def geometry_on(self, input_name: str, open_inputs) -> tuple[Geometry, ...]:
        """The geometry drawn on ``input_name`` given the open inputs."""
        return tuple(g for g in self.geometry if g.input_for(open_inputs) == input_name)

    def resolved(self, params, open_inputs) -> dict[str, Any]:
        """What "auto" parameters resolve to (empty if the method says nothing or refuses the inputs)."""
        if self.auto is None:
            return {}
        try:
            return dict(self.auto(params, frozenset(open_inputs)))
        except WeftError:
            return {}

    def compare_input(self, open_inputs) -> str:
        for name in self.compare:
            if name in open_inputs:
                return name
        return self.canvas


def reduce_for_preview(studio: Studio, inputs: Mapping[str, np.ndarray], params, side: int
                       ) -> tuple[dict[str, np.ndarray], Any]:
    """Inputs and parameters of a reduced render: the studio's ``preview_inputs`` that are open
    scaled so the longer side of the largest is ``side``; else its ``preview_params`` sizes scaled
    so; unchanged when already that small (or when the method refuses the smaller size)."""
    from .image import resize

    scaled = [n for n in studio.preview_inputs if n in inputs]
    if scaled:
        longest = max(max(inputs[n].shape[:2]) for n in scaled)
        if longest <= side:
            return dict(inputs), params
        k = side / longest
        small = dict(inputs)
        for n in scaled:
            h, w = inputs[n].shape[:2]
            small[n] = resize(inputs[n], (max(8, round(w * k)), max(8, round(h * k))), interpolation="area")
        return small, params
    changes = {}
    for name in studio.preview_params:
        size = getattr(params, name, None)
        if size is not None and max(size) > side:
            k = side / max(size)
            changes[name] = (max(8, round(size[0] * k)), max(8, round(size[1] * k)))
    if changes:
        try:
            return dict(inputs), params.replace(**changes)
        except WeftError:  # a size the method refuses at preview scale: render at full size
            pass
    return dict(inputs), params
