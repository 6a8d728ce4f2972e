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

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .errors import WeftError
from .geometry import KINDS, LINES, MARGINS, MASK, SQUARE  # noqa: F401 (the kinds are re-exported)

__all__ = [
    "Studio",
    "Geometry",
    "Figure",
    "describe_figures",
    "SQUARE",
    "LINES",
    "MASK",
    "MARGINS",
    "REGION",
]

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
    live : ``live(params) -> bool``: re-render a preview while the geometry is being dragged (for a
        mask that does not preview around its stroke, :attr:`Studio.preview_around`: a reduced
        preview of the whole image while it is painted).
    needed : words for the user when the studio must not render without it (a run without it does
        something else, e.g. treats the photo as frontal): while it is not drawn the studio shows
        the input and these words instead of a result, e.g. ``"draw feature lines (or Quad…)"``.
    label : for a mask: its name on the brush's switch when one image carries several masks
        (``"hole"``, ``"sampling area"``).
    empty_is_all : for a mask: the method without this input acts as if every pixel were white (a
        region to copy from: all of it), not none; the brush then paints it as *Include* and
        *Exclude*, and the first *Exclude* starts from a mask that is white everywhere.
    suggest : ``suggest(image) -> (value, text)``: proposes the geometry for the ``on`` image (the
        value a user would draw, e.g. :class:`~weft.core.geometry.FeatureLines`) and says in a
        sentence what it found; raises ``WeftError`` (one line) when it cannot. The studio offers it
        as a button and runs it off the GUI thread; None: nothing to suggest.
    """

    kind: str
    on: tuple[str, ...]
    param: str | None = None
    help: str = ""
    live: Callable[[Any], bool] | None = None
    input: str | None = None
    needed: str = ""
    label: str = ""
    empty_is_all: bool = False
    suggest: Callable[[np.ndarray], tuple[Any, str]] | None = None

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
    whole : the value is the same whatever part of the image is rendered (a parameter, e.g. the
        engine): a preview around a stroke, which renders a crop (:func:`weft.core.preview.crop_around`), shows it.
        A figure that counts or measures pixels (``False``, the default) would describe the crop,
        not the image, and is shown only with the full result.

    ``Figure("largest verbatim copy", "%", "of the sample", digits=2).render(0.0532)`` is
    ``"largest verbatim copy 5.3 % of the sample"``.
    """

    label: str
    unit: str = ""
    after: str = ""
    digits: int = 3
    whole: bool = False

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

    def prefixed(self, words: str) -> Figure:
        """The same figure with ``words`` before its label (a figure of a step, e.g. the rectification)."""
        return Figure(f"{words} {self.label}".strip(), self.unit, self.after, self.digits, self.whole)


def describe_figures(figures: Mapping[str, Any], known: Mapping[str, Figure], *, crop: bool = False) -> list[str]:
    """A result's figures in words.

    Lists, tables and missing values (``None``) are left to the report. A key no table describes reads
    as its words (``"some_count"`` -> ``"some count"``).

    Parameters
    ----------
    figures : mapping
        A ``Result.figures``.
    known : mapping of str to Figure
        How each figure reads.
    crop : bool, default False
        The figures of a render of a crop (a preview around a stroke): only those ``known`` as
        :attr:`Figure.whole` (the others, and unknown keys, would describe the crop, not the image).

    Returns
    -------
    list of str
        One phrase per scalar, in the order of ``figures``.
    """
    out = []
    for key, value in figures.items():
        if value is None or isinstance(value, (list, tuple, dict, np.ndarray)):
            continue
        figure = known.get(key)
        if crop and (figure is None or not figure.whole):
            continue
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
    auto : ``auto(params, shapes) -> {name: value}``: what the optional ("auto") parameters resolve
        to for these inputs, shown greyed beside their "auto" box; ``shapes`` maps each open input's
        name to the shape of the array the method would get (a source region's crop, a painted
        mask's image), so a default may depend on an input's size (quilt's block on the sample's);
        may raise ``WeftError``.
    compare : the "before" image of Compare: the first of these inputs that is open (default the canvas).
    examples : a bundled example (``weft.core.examples``) per input, opened when the studio starts.
    rank : position in the method list (lowest first; the first is the studio's starting method).
    figures : how people read each key of the method's ``Result.figures`` (:class:`Figure`); the
        status bar shows them in words and units (:meth:`describe`), the CLI's ``--report`` keeps the keys.
    preview_around : the input of a mask geometry whose painting previews *around the stroke*: while a
        stroke is drawn, the method runs on a crop of its inputs around the painted region
        (:func:`weft.core.preview.crop_around`) and the crop's result is pasted into the last full result; None: a
        stroke previews nothing until it is released. Such a preview states only the figures that
        hold for the whole image (:attr:`Figure.whole`).
    own_inputs : optional inputs the method takes only when they were opened for it (while it was the
        studio's method): the studio shares inputs by name between methods, and an image opened as
        another method's input of that name must not change what this one does (``fill``'s optional
        ``texture``, a source to copy from, is not ``quilt``'s texture).
    limits : ``limits(params, shapes) -> {name: (lo, hi)}``: the narrower range a parameter accepts
        with inputs of these shapes and the other parameters' values (quilt's block must fit in the
        sample: ``2..112`` for a 112x128 texture, against ``2..1024`` in general), the range the
        method's own check would name in its error; the studio's sliders and tooltips follow it
        (:meth:`ranges`). Takes the same ``shapes`` as ``auto``; may raise ``WeftError``.
    idle : ``idle(params, shapes) -> names``: the parameters that change nothing with these settings
        and inputs (nfpt's ``a``, ``b``, ``p`` with the homography warp): Variations does not offer
        them. Takes the same ``shapes`` as ``auto``.
    masks_of : inputs that are masks of another input without being painted (opened as files): each
        belongs to the first of its images that is open (a source mask of a texture when one is
        open, else of the image); :func:`weft.core.preview.crop_around` crops it with that image. A painted mask
        (a :class:`Geometry` of kind ``mask``) is cropped with its image without being listed here.
    """

    title: str
    canvas: str
    geometry: tuple[Geometry, ...] = ()
    preview_inputs: tuple[str, ...] = ()
    preview_params: tuple[str, ...] = ()
    auto: Callable[[Any, Mapping[str, tuple]], Mapping[str, Any]] | None = None
    compare: tuple[str, ...] = ()
    examples: Mapping[str, str] = field(default_factory=dict)
    rank: int = 100
    figures: Mapping[str, Figure] = field(default_factory=dict)
    preview_around: str | None = None
    own_inputs: tuple[str, ...] = ()
    masks_of: Mapping[str, tuple[str, ...]] = field(default_factory=dict)
    limits: Callable[[Any, Mapping[str, tuple]], Mapping[str, tuple]] | None = None
    idle: Callable[[Any, Mapping[str, tuple]], Any] | None = None

    def describe(self, figures: Mapping[str, Any], *, crop: bool = False) -> list[str]:
        """A result's figures in words and units (see :func:`describe_figures`; ``crop``: of a
        preview around a stroke, only the :attr:`Figure.whole` ones)."""
        return describe_figures(figures, self.figures, crop=crop)

    def geometry_on(self, input_name: str, open_inputs) -> tuple[Geometry, ...]:
        """The geometry drawn on ``input_name`` given the open inputs."""
        return tuple(g for g in self.geometry if g.input_for(open_inputs) == input_name)

    def resolved(self, params, shapes: Mapping[str, tuple]) -> dict[str, Any]:
        """What "auto" parameters resolve to for inputs of these shapes (input name -> array shape;
        empty if the method says nothing or refuses the inputs)."""
        if self.auto is None:
            return {}
        try:
            return dict(self.auto(params, {name: tuple(shape) for name, shape in shapes.items()}))
        except WeftError:
            return {}

    def ranges(self, params, shapes: Mapping[str, tuple]) -> dict[str, tuple]:
        """The range each parameter accepts now, for inputs of these shapes and the other parameters'
        values (:attr:`limits`, each within its ``Spec``'s range; a parameter not named keeps its
        Spec's range). Empty if the method says nothing or refuses the inputs."""
        if self.limits is None:
            return {}
        try:
            found = dict(self.limits(params, {name: tuple(shape) for name, shape in shapes.items()}))
        except WeftError:
            return {}
        from .params import specs

        bounds = {spec.name: (spec.lo, spec.hi) for spec in specs(type(params))}
        out = {}
        for name, (lo, hi) in found.items():
            spec_lo, spec_hi = bounds.get(name, (None, None))
            lo = lo if spec_lo is None else max(lo, spec_lo)
            hi = hi if spec_hi is None else min(hi, spec_hi)
            if lo <= hi:
                out[name] = (lo, hi)
        return out

    def idle_params(self, params, shapes: Mapping[str, tuple]) -> frozenset:
        """The parameters that change nothing with these settings and inputs (:attr:`idle`)."""
        if self.idle is None:
            return frozenset()
        try:
            return frozenset(self.idle(params, {name: tuple(shape) for name, shape in shapes.items()}))
        except WeftError:
            return frozenset()

    def compare_input(self, open_inputs) -> str:
        for name in self.compare:
            if name in open_inputs:
                return name
        return self.canvas
