"""Parameters of the affine prototype model; the prototype square (:class:`weft.core.geometry.Square`)."""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import GeometryError, InvalidParameter
from ..geometry import Square
from ..params import Params, param

LOWPASS = ("add", "absorb")
COLOURS = ("pca", "yuv")
BOUNDARIES = ("auto", "none", "partial", "shaker")
FIELDS = ("none", "swirl", "zoom", "rotate")
SHAKER_STARTS = ("partial", "analysis")
MIN_SIDE = 8

Rect = Square


def check_rect(rect: Rect, shape: tuple[int, ...], what: str = "texture", name: str = "prototype") -> Rect:
    """Check that a prototype square lies inside an image.

    Parameters
    ----------
    rect : (x, y, s)
        A :class:`~weft.core.geometry.Square` (or any ``(x, y, side)``).
    shape : tuple
        The image's shape (H, W[, C]).
    what, name : str
        The image and the parameter, for the message.

    Returns
    -------
    (x, y, s), unchanged.

    Raises
    ------
    GeometryError
        One line naming the value, the pixels it spans and the image size, e.g.
        ``parameter 'prototype' = 200,10,64 does not fit: it spans x 200..263, y 10..73, outside
        the 256x256 texture``.
    """
    x, y, s = rect
    h, w = shape[:2]
    if x < 0 or y < 0 or x + s > w or y + s > h:
        if s > min(h, w):
            why = f"its side {s} is larger than the {what} ({w}x{h})"
        else:
            why = f"it spans x {x}..{x + s - 1}, y {y}..{y + s - 1}, outside the {w}x{h} {what}"
        raise GeometryError(f"parameter '{name}' = {x},{y},{s} does not fit: {why}")
    return rect


def default_rect(shape: tuple[int, ...], block: int, what: str = "image") -> Rect:
    """The default prototype: a square of side ``2B`` (64 for B = 32) in the middle of the image.

    Its side is reduced to the largest even number the image holds (at least 8), so a small image
    still gets a prototype; the paper uses a 64x64 prototype with 32x32 patches (§5).

    Parameters
    ----------
    shape : tuple of int
        The image's shape (H, W[, C]).
    block : int
        The patch side B.
    what : str, default "image"
        The image, for the message (``"texture"``, ``"prototype image"``).

    Returns
    -------
    Square

    Raises
    ------
    GeometryError
        The image is smaller than 8x8 pixels.

    References
    ----------
    Smith & Bhalerao, "Texture transfer using affine transformation groups and patch boundary matching", §5.
    """
    h, w = shape[:2]
    s = min(2 * block, (min(h, w) // 2) * 2)
    if s < MIN_SIDE:
        raise GeometryError(f"the {what} is {w}x{h}; a prototype needs at least {MIN_SIDE}x{MIN_SIDE} pixels")
    return Square((w - s) // 2, (h - s) // 2, s)


@dataclass(frozen=True)
class AffineParams(Params):
    """Parameters of the affine prototype model (Smith & Bhalerao)."""

    prototype: Square | None = param(
        None,
        kind="geometry",
        type=Square,
        optional=True,
        help="the patch every part of the result is drawn from: square X,Y,S (top-left corner "
        "and side, pixels) in the prototype image or the texture; a patch holding one clear"
        " element works best; default a 2B square in the middle",
    )
    block: int = param(
        32,
        lo=8,
        hi=256,
        step=2,
        symbol="B",
        help="side of the patches (even), overlapping by half: smaller"
        " follows the texture more closely and costs more time, "
        "larger smooths it",
    )
    segments: int = param(
        32,
        lo=4,
        hi=128,
        step=2,
        symbol="N",
        help="angular segments of each patch's spectrum, used to "
        "find its orientation (even): more finds finer angles "
        "and costs time",
    )
    lowpass: str = param(
        "add",
        choices=LOWPASS,
        help="add: draw only the detail and keep the picture's own shading and colour (its "
        "subsampled lowpass); absorb: draw everything from the unfiltered (colour) prototype "
        "(§3.3, §3.4)",
    )
    colour: str = param(
        "pca",
        choices=COLOURS,
        help="the grey the transforms are found on: pca = the main direction of the colours "
        "(follows a colour texture), yuv = luma Y (§3.4)",
    )
    propagate: bool = param(
        True,
        help="also try the neighbouring patches' transforms (top-down, then bottom-up), which "
        "keeps neighbours consistent; off = the paper's eight candidates only",
    )
    refine: int = param(
        2,
        lo=0,
        hi=20,
        help="Levenberg-Marquardt steps polishing each patch's transform and position to sub-pixel:"
        " a truer reproduction (0 = the paper's pipeline)",
    )
    reuse_transforms: bool = param(
        False,
        help="keep the transforms found for --analysis-prototype of the texture and draw"
        " them with --prototype (a prototype swap, §4): the layout stays, the look "
        "changes",
    )
    analysis_prototype: Square | None = param(
        None,
        kind="geometry",
        type=Square,
        optional=True,
        help="with --reuse-transforms: the texture square X,Y,S the transforms are "
        "computed for; default the default prototype",
    )
    boundary: str = param(
        "auto",
        choices=BOUNDARIES,
        help="how neighbouring patches are lined up (§4): none = where the analysis put them "
        "(§2.3); partial = one pass in raster order; shaker = the shaker box moves each "
        "patch until it agrees with all its neighbours (fewest doubled edges); auto = shaker"
        " with a field, else none",
    )
    iterations: int = param(
        20, lo=1, hi=500, help="shaker box: most passes over the patches; more can remove more doubled edges"
    )
    per_radius: int = param(
        5,
        lo=1,
        hi=100,
        help="shaker box: passes at each search radius (B/4, then down by one after each run); "
        "more settles each radius before it narrows",
    )
    shaker_start: str = param(
        "partial",
        choices=SHAKER_STARTS,
        help="shaker box: start from the partial-correlation positions or from the analysis ones",
    )
    field: str = param(
        "none",
        choices=FIELDS,
        help="make a new texture from a transform field (swirl, zoom, rotate) instead of the "
        "texture's own transforms (Fig. 6)",
    )
    field_strength: float = param(
        1.0, lo=0.0, hi=2.0, step=0.05, help="how strongly the field turns or zooms the prototype"
    )
    size: tuple[int, int] | None = param(
        None,
        kind="size",
        lo=16,
        hi=8192,
        optional=True,
        help="output size WIDTHxHEIGHT with a field; default the texture's",
    )

    def check(self) -> None:
        if self.block % 2:
            raise InvalidParameter(
                f"parameter 'block' = {self.block} must be even (patches overlap by B/2)",
                name="block",
                value=self.block,
            )
        if self.segments % 2:
            raise InvalidParameter(
                f"parameter 'segments' = {self.segments} must be even (the spectrum's half-plane symmetry, eqs. 14-16)",
                name="segments",
                value=self.segments,
            )
        if self.prototype is not None:
            self.prototype.check_side("prototype", minimum=MIN_SIDE, even=True)
        if self.analysis_prototype is not None:
            self.analysis_prototype.check_side("analysis_prototype", minimum=MIN_SIDE, even=True)
            if not self.reuse_transforms:
                raise InvalidParameter(
                    "parameter 'analysis_prototype' only applies with reuse_transforms (--reuse-transforms true)",
                    name="analysis_prototype",
                    value=self.analysis_prototype,
                )
        if self.field != "none" and self.reuse_transforms:
            raise InvalidParameter(
                f"parameter 'reuse_transforms' has no meaning with field '{self.field}' "
                f"(a field's transforms do not depend on the prototype)",
                name="reuse_transforms",
                value=True,
            )
        if self.size is not None and self.field == "none":
            raise InvalidParameter(
                "parameter 'size' only applies with a field (--field swirl|zoom|rotate); "
                "synthesis reproduces the texture at its own size",
                name="size",
                value=self.size,
            )

    def resolved_boundary(self) -> str:
        """``boundary`` with ``auto`` made explicit: ``shaker`` with a field, else ``none``."""
        if self.boundary == "auto":
            return "shaker" if self.field != "none" else "none"
        return self.boundary
