"""Fill and extend: heal a painted region, remove an object, uncrop.

``weft fill IMAGE --mask MASK -o OUT`` fills the white region of the mask from the rest of the image
(or only from ``--source-mask``'s white region, or from a second image ``--texture``);
``--extend L,T,R,B`` or ``--size WxH --anchor ...`` grows the canvas and fills the new border (uncrop).
With no mask, an image's transparent pixels (alpha < 50 %) are the hole.

Engines (``--engine``): the table :data:`weft.core.fill.engines.TABLE` says what each is, its default
patch and how the method runs it; every engine returns every pixel outside the hole unchanged (but
the blend band's, when it takes them). The shared patch search (PatchMatch and EM voting) is
:mod:`weft.core.fill.search`. ``auto`` (the default, :func:`~weft.core.fill.params.auto_engine`)
runs ``patchmatch`` with the edge guide where it pairs edges across a hole inside a colour picture
(or when ``structure`` is yes), else ``hybrid``; the figures name the engine and the patch that
ran. The suite that chose it is ``python -m benchmarks.fill_suite`` (its results in
``benchmarks/results/fill_suite.json``).

**Known pixels** are never changed except within the blend band (``--band``, default 2 px): the
quilting engine's minimum-error cut may run through the known pixels within ``band`` px of the hole,
and then (on grey pictures) the pixels within ``band`` px (8-connected) of the hole's edge, on both
sides, are re-solved by a Poisson equation whose guidance is the image's own gradients except
across the hole's edge, where the step beyond twice the texture's own is replaced by the continued
slope of both sides (:mod:`weft.core.fill.band`; ``patchmatch``, ``hybrid`` and ``quilt`` on colour
pictures re-synthesise the band instead); every pixel further away is bit-identical to the input.
``--band 0``: no known pixel changes.

**Alpha.** The image keeps its alpha channel (``InputSpec.alpha``): with no mask its transparent pixels
are the hole; transparent pixels are never copied from; the output is RGBA (grey+alpha is written
as RGBA) with every filled pixel, and an uncrop's new border, opaque. **Bit depth.** The command line
writes the image's own bit depth (8 or 16) unless ``--bit-depth`` says otherwise (``Method.depth_from``).
"""

from __future__ import annotations

import numpy as np

from ..geometry import Margins
from .method import METHOD, fill_image, warm_up
from .params import ANCHORS, DEFAULT_ENGINE, DEFAULT_PATCH, ENGINES, FillParams, structure_value
from .quilt import fill_quilt

__all__ = [
    "ANCHORS",
    "DEFAULT_ENGINE",
    "DEFAULT_PATCH",
    "ENGINES",
    "FillParams",
    "METHOD",
    "fill",
    "fill_quilt",
    "warm_up",
]


def fill(
    image,
    mask=None,
    *,
    extend=None,
    size=None,
    anchor="center",
    engine=None,
    patch=None,
    band=2,
    structure="auto",
    source_mask=None,
    texture=None,
    seed=0,
    progress=None,
    cancel=None,
) -> np.ndarray:
    """Fill the hole of ``image`` and/or extend its canvas; returns the filled float32 image.

    Parameters
    ----------
    image : ndarray, float in [0, 1] (or uint8/uint16): (H, W) grey, (H, W, 3) RGB, (H, W, 2) grey+alpha
        or (H, W, 4) RGBA. With alpha and no ``mask``, the transparent pixels (alpha < 0.5) are the hole.
    mask : ndarray (H, W) (bool, or an image whose white > 50 % is the hole), optional.
    extend : ``Margins`` or ``(left, top, right, bottom)`` or ``"L,T,R,B"``: pixels added (and filled).
    size, anchor : ``(width, height)`` of a larger canvas, and where the image sits on it
        (:data:`ANCHORS`); not with ``extend``.
    engine : ``"auto"`` (the default, :data:`DEFAULT_ENGINE`: ``patchmatch`` with the edge guide where
        it finds edges crossing a hole inside a colour picture, else ``hybrid``; ``patchmatch``
        with ``structure`` = yes), ``"hybrid"``, ``"quilt"`` or ``"patchmatch"``.
    patch : patch side (engine default :data:`DEFAULT_PATCH`). band : the blend band in px (0: none).
    structure : continue the strong edges that cross the hole along smooth curves
        (:mod:`weft.core.fill.structure`): ``"auto"`` (the default) whenever the ``patchmatch`` engine
        fills from the picture itself, ``"yes"`` always (``auto`` then runs ``patchmatch``), ``"no"``
        never; ``True`` / ``False`` are read as ``"yes"`` / ``"no"``.
    source_mask : (H, W) (of the texture when one is given): the only pixels to copy from.
    texture : ndarray: copy from this image instead of the rest of ``image``.
    seed : int or ``np.random.Generator``: the same seed gives the same pixels.
    progress, cancel : as every method (``weft.core.jobs``).

    Returns
    -------
    ndarray float32: the image's channels (RGBA if it had alpha), on the grown canvas for an uncrop.

    Raises ``WeftError`` (one line) for nothing to fill, a mask of another size, too little to copy from.
    """
    params = FillParams(
        engine=engine or DEFAULT_ENGINE,
        patch=patch,
        band=band,
        structure=structure_value(structure),
        extend=None if extend is None else Margins.coerce(extend),
        size=None if size is None else tuple(size),
        anchor=anchor,
    )
    out, _figures = fill_image(
        image, mask, params=params, source_mask=source_mask, texture=texture, rng=seed, progress=progress, cancel=cancel
    )
    return out
