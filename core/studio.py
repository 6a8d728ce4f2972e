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
    "reduce_for_preview",
    "crop_around",
    "Around",
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
        engine): a preview around a stroke, which renders a crop (:func:`crop_around`), shows it.
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
        (:func:`crop_around`) and the crop's result is pasted into the last full result; None: a
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
        open, else of the image); :func:`crop_around` crops it with that image. A painted mask
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


def reduce_for_preview(
    studio: Studio, inputs: Mapping[str, np.ndarray], params, side: int
) -> tuple[dict[str, np.ndarray], Any]:
    """Inputs and parameters of a reduced render.

    The studio's ``preview_inputs`` that are open are scaled so the longer side of the largest is
    ``side``; else its ``preview_params`` sizes are scaled so; unchanged when already that small (or
    when the method refuses the smaller size).

    Parameters
    ----------
    studio : Studio
        The method's studio description.
    inputs : mapping of str to ndarray
        The full-size inputs.
    params : Params
        The full-size parameters.
    side : int
        The preview's longer side, pixels.

    Returns
    -------
    inputs : dict of str to ndarray
    params : Params
    """
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


#: The longest side of a preview around a stroke (:func:`crop_around`): larger crops are scaled down.
AROUND_SIDE = 160


@dataclass(frozen=True)
class Around:
    """A render of the region around a stroke (see :func:`crop_around`).

    Attributes
    ----------
    inputs, params : what the method runs on (cropped, perhaps scaled; margins parameters off).
    box : ``(x0, y0, x1, y1)`` of the crop in the painted image's pixels (exclusive ends).
    offset : ``(dx, dy)`` of the painted image in a full result (the left and top margins of an
        uncrop; (0, 0) without them).
    """

    inputs: dict
    params: Any
    box: tuple[int, int, int, int]
    offset: tuple[int, int]

    def fitted(self, part: np.ndarray) -> np.ndarray | None:
        """The crop's result ``part`` at the box's size (scaled back when it was rendered smaller), as
        :meth:`paste` pastes it; None when it cannot be (another channel layout or an empty result)."""
        from .image import resize

        x0, y0, x1, y1 = self.box
        w, h = x1 - x0, y1 - y0
        if part.shape[:2] == (h, w):
            return part
        if part.ndim not in (2, 3) or min(part.shape[:2]) < 1:
            return None
        return resize(part, (w, h), interpolation="linear")

    def paste(self, base: np.ndarray, part: np.ndarray, *, copy: bool = True) -> np.ndarray | None:
        """``base`` (a full result) with ``part`` (the crop's result, scaled back to the box) pasted
        at the box (into a copy, or with ``copy=False`` into ``base`` itself); None when they do not
        fit together (another size or channel count)."""
        x0, y0, x1, y1 = self.box
        dx, dy = self.offset
        fit = self.fitted(part)
        if (
            fit is None
            or fit.ndim != base.ndim
            or (fit.ndim == 3 and fit.shape[2] != base.shape[2])
            or y0 + dy < 0
            or x0 + dx < 0
            or y1 + dy > base.shape[0]
            or x1 + dx > base.shape[1]
        ):
            return None
        out = base.copy() if copy else base
        out[y0 + dy : y1 + dy, x0 + dx : x1 + dx] = fit
        return out


def around_region(
    stroke: tuple[float, float, float, float], width: int, height: int, *, context: int = 16
) -> tuple[int, int, int, int]:
    """The part of a painted mask that :func:`crop_around` reads for a stroke.

    The stroke's box grown by ``context``, grown again by ``context`` and a quarter of that box's
    longer side (the crop never reaches farther), clipped to the mask. Cut that part and pass it as
    ``crop_around(..., mask_part=)``: a preview around a stroke then never needs the whole mask.

    Parameters
    ----------
    stroke : (float, float, float, float)
        The stroke's ``(x0, y0, x1, y1)``.
    width, height : int
        The mask's size.
    context : int, default 16
        As in :func:`crop_around`.

    Returns
    -------
    (int, int, int, int)
        ``(x0, y0, x1, y1)``, exclusive ends.
    """
    wx0, wy0, wx1, wy1 = _stroke_window(stroke, context)
    grow = context + max(wx1 - wx0, wy1 - wy0) // 4 + 1
    return max(0, wx0 - grow), max(0, wy0 - grow), min(width, wx1 + grow), min(height, wy1 + grow)


def _stroke_window(stroke: tuple[float, float, float, float], context: int) -> tuple[int, int, int, int]:
    """The stroke's box in whole pixels grown by ``context`` (exclusive ends, not clipped): where
    :func:`crop_around` looks for painted pixels."""
    sx0, sy0, sx1, sy1 = stroke
    return (
        int(np.floor(sx0)) - context,
        int(np.floor(sy0)) - context,
        int(np.ceil(sx1)) + 1 + context,
        int(np.ceil(sy1)) + 1 + context,
    )


def crop_around(
    studio: Studio,
    inputs: Mapping[str, np.ndarray],
    params,
    stroke: tuple[float, float, float, float],
    *,
    side: int = AROUND_SIDE,
    context: int = 16,
    mask_part: tuple[np.ndarray, tuple[int, int]] | None = None,
) -> Around | None:
    """What to render while a stroke paints the mask input ``studio.preview_around``.

    The inputs are cropped around the painted region near the stroke, so the preview costs a fraction
    of a full render. The crop is the bounding box of the mask's pixels within the stroke's box grown
    by ``context`` px, grown again by ``context`` px and by a quarter of its side (known pixels around
    the hole to copy from), clipped to the image. Only what belongs to the painted image is cropped
    alike: the image, the masks painted on it, and the masks ``studio.masks_of`` gives to it (a source
    mask opened as a file, unless its texture is open); every other input (a second texture to copy
    from, even of the image's size) is kept whole. A crop longer than ``side`` is scaled down to it
    (``area``, a mask thresholded back to 0/1). Parameters filled by a margins geometry on that image
    are reset to their defaults (the crop is not uncropped) and their left/top margins give
    :attr:`Around.offset`.

    Parameters
    ----------
    studio : Studio
        The method's studio description.
    inputs : mapping of str to ndarray
        The full-size inputs.
    params : Params
        The full-size parameters.
    stroke : (float, float, float, float)
        The stroke's ``(x0, y0, x1, y1)`` in the painted image's pixels (brush radius included).
    side : int, default AROUND_SIDE
        The crop's longest side.
    context : int, default 16
        Pixels of context around the stroke.
    mask_part : (ndarray, (int, int)), optional
        ``(bits, (x, y))``: the painted mask is not in ``inputs``; ``bits`` (bool or float) is its
        part at ``(x, y)``, covering at least :func:`around_region` of the stroke.

    Returns
    -------
    Around or None
        None when the studio previews no mask that way, the mask is not open, or there is nothing
        painted near the stroke (nothing to fill).

    Raises
    ------
    ValueError
        ``mask_part`` does not cover the stroke's region.
    """
    from .geometry import Margins
    from .image import resize
    from .params import specs

    name = studio.preview_around
    g = next((g for g in studio.geometry if g.kind == MASK and g.input == name), None)
    if g is None or name is None or (name not in inputs and mask_part is None):
        return None
    on = g.input_for(inputs)
    if on not in inputs:
        return None
    h, w = inputs[on].shape[:2]
    if mask_part is None:
        mask, (px, py) = np.asarray(inputs[name]), (0, 0)
        if mask.shape[:2] != (h, w):
            return None
    else:
        mask, (px, py) = np.asarray(mask_part[0]), mask_part[1]
        rx0, ry0, rx1, ry1 = around_region(stroke, w, h, context=context)
        if px > rx0 or py > ry0 or px + mask.shape[1] < rx1 or py + mask.shape[0] < ry1:
            raise ValueError(
                f"the mask's part {mask.shape[1]}x{mask.shape[0]} at ({px}, {py}) does not cover "
                f"the stroke's region {(rx0, ry0, rx1, ry1)}"
            )
    plane = mask if mask.ndim == 2 else mask[..., 0]
    wx0, wy0, wx1, wy1 = _stroke_window(stroke, context)
    wx0, wy0, wx1, wy1 = max(0, wx0), max(0, wy0), min(w, wx1), min(h, wy1)
    if wx0 >= wx1 or wy0 >= wy1:
        return None
    near = plane[wy0 - py : wy1 - py, wx0 - px : wx1 - px] > 0.5
    rows, cols = np.flatnonzero(near.any(axis=1)), np.flatnonzero(near.any(axis=0))
    if not len(rows):
        return None
    bx0, bx1 = wx0 + int(cols[0]), wx0 + int(cols[-1]) + 1
    by0, by1 = wy0 + int(rows[0]), wy0 + int(rows[-1]) + 1
    grow = context + max(bx1 - bx0, by1 - by0) // 4
    x0, y0, x1, y1 = max(0, bx0 - grow), max(0, by0 - grow), min(w, bx1 + grow), min(h, by1 + grow)
    k = min(1.0, side / max(x1 - x0, y1 - y0))
    size = (max(8, round((x1 - x0) * k)), max(8, round((y1 - y0) * k)))
    small = dict(inputs)
    crop = {on} | {m.input for m in studio.geometry if m.kind == MASK and m.input_for(inputs) == on}
    crop |= {n for n, of in studio.masks_of.items() if next((i for i in of if i in inputs), None) == on}
    for n in dict.fromkeys([*inputs, name] if mask_part is not None else inputs):  # (each input once)
        if n == name and mask_part is not None:  # (the painted mask's part, as a 0/1 image)
            part = (plane[y0 - py : y1 - py, x0 - px : x1 - px] > 0.5).astype(np.float32)
        elif n not in crop or inputs[n].shape[:2] != (h, w):  # a mask of another size: the method says so
            continue
        else:
            part = np.ascontiguousarray(inputs[n][y0:y1, x0:x1])
        if k < 1.0:
            part = resize(part, size, interpolation="area")
            if n != on:  # a mask stays a mask
                part = (part > 0.5).astype(np.float32)
        small[n] = part
    changes, offset = {}, (0, 0)
    defaults = {s.name: s.default for s in specs(type(params))}
    for m in studio.geometry:
        if m.kind == MARGINS and m.param is not None and m.input_for(inputs) == on:
            value = getattr(params, m.param, None)
            if value:
                margins = Margins.coerce(value, m.param)
                offset = (margins.left, margins.top)
                changes[m.param] = defaults.get(m.param)
    if changes:
        params = params.replace(**changes)
    return Around(small, params, (x0, y0, x1, y1), offset)
