"""Fill and extend: heal a painted region, remove an object, uncrop.

``weft fill IMAGE --mask MASK -o OUT`` fills the white region of the mask from the rest of the image
(or only from ``--source-mask``'s white region, or from a second image ``--texture``);
``--extend L,T,R,B`` or ``--size WxH --anchor ...`` grows the canvas and fills the new border (uncrop).
With no mask, an image's transparent pixels (alpha < 50 %) are the hole.

Engines (``--engine``), all with one signature ``fill_x(image, hole, source=None, *, patch, rng,
progress, cancel)`` and the guarantee that every pixel outside the hole is returned unchanged (the
quilt engine's cut may also run through the known pixels of the blend band, when the method gives it
``band`` or ``cuttable``; :mod:`weft.core.fill.band` then re-solves that band):

* ``quilt`` (:func:`weft.core.fill.quilt.fill_quilt`) -- the quilting paper's hole filling: blocks in
  fill-front order, SSD over known pixels only, minimum-error cut;
* ``pixel`` (:func:`weft.core.fill.pixel.fill_pixel`) -- Ashikhmin-style coherent pixel synthesis in
  onion order with the hole's neighbourhood as the constraint;
* ``patchmatch`` (:func:`weft.core.fill.patchmatch.fill_patchmatch`) -- multi-scale
  patch search with voting (Wexler et al., Barnes et al.);
* ``hybrid`` (:func:`weft.core.fill.hybrid.fill_hybrid`) -- the quilt engine with 48-px blocks, then
  :func:`weft.core.fill.patchmatch.refine_patchmatch` (full-resolution patch search and voting from
  that fill) over the hole and the blend band.

``patchmatch`` and ``hybrid`` are given the band too (``cuttable``) and re-synthesise it with the
hole; the method then runs no Poisson blend for them.

**The default engine is** :data:`~weft.core.fill.params.DEFAULT_ENGINE`, ``auto``
(:func:`~weft.core.fill.params.auto_engine`): ``patchmatch`` for a hole inside a colour picture,
with the edge guide of :mod:`weft.core.fill.structure` (``structure`` ``auto``), ``quilt``
otherwise; the figures name the engine that ran. Measured on the fill benchmark's cases (seeds 0-4 medians,
``python -m benchmarks.fill --seeds 0-4``; coherence / detail / seam against the truth's): on the
photo ``patchmatch`` is the most coherent of weft's engines (without the guide 4.45 / 1.02 / -0.04
against ``quilt``'s 5.40 / 1.08 / +0.01); with the guide, which continues the saucer's rim where
patch search alone drips it, 5.05 / 1.00 / +0.05 (at the benchmark's seed 4.78 against G'MIC's
6.58 and 1.2x shift-map's 4.99), in a whole process of 0.34-0.35 s against G'MIC's 0.36-0.37 s
(interleaved, medians of 15, two rounds); on the grey textures and the uncrop ``quilt`` is the
more coherent (gravel 9.01 against 9.24, brick 1.05 against 1.35, uncrop 0.81 against 0.85) and
the quicker (0.19-0.27 s whole processes),
and it keeps brick mortar straight where ``patchmatch`` bends it. ``hybrid`` (quilt with 48-px
blocks, then the refine) is more coherent than ``quilt`` on the textures but leaves a red ghost of
the spoon's handle on the photo (coherence 5.56 there, in 0.28 s against G'MIC's 0.38 s in the
benchmark run); ``pixel`` is the least coherent everywhere. Neither ``quilt`` nor ``patchmatch``
loads numba: a fill's first run costs what the second does. The README's "Fill and extend against
the peers" has the tables and the pictures.

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
from .pixel import fill_pixel
from .quilt import fill_quilt

__all__ = ["ANCHORS", "DEFAULT_ENGINE", "DEFAULT_PATCH", "ENGINES", "FillParams", "METHOD", "fill", "fill_pixel",
           "fill_quilt", "warm_up"]


def fill(image, mask=None, *, extend=None, size=None, anchor="center", engine=None, patch=None, band=2,
         structure="auto", source_mask=None, texture=None, seed=0, progress=None, cancel=None) -> np.ndarray:
    """Fill the hole of ``image`` and/or extend its canvas; returns the filled float32 image.

    Parameters
    ----------
    image : ndarray, float in [0, 1] (or uint8/uint16): (H, W) grey, (H, W, 3) RGB, (H, W, 2) grey+alpha
        or (H, W, 4) RGBA. With alpha and no ``mask``, the transparent pixels (alpha < 0.5) are the hole.
    mask : ndarray (H, W) (bool, or an image whose white > 50 % is the hole), optional.
    extend : ``Margins`` or ``(left, top, right, bottom)`` or ``"L,T,R,B"``: pixels added (and filled).
    size, anchor : ``(width, height)`` of a larger canvas, and where the image sits on it
        (:data:`ANCHORS`); not with ``extend``.
    engine : ``"auto"`` (the default, :data:`DEFAULT_ENGINE`: ``patchmatch`` for a hole inside a colour
        picture, ``quilt`` otherwise), ``"quilt"``, ``"pixel"``, ``"patchmatch"`` or ``"hybrid"``.
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
    params = FillParams(engine=engine or DEFAULT_ENGINE, patch=patch, band=band, structure=structure_value(structure),
                        extend=None if extend is None else Margins.coerce(extend),
                        size=None if size is None else tuple(size), anchor=anchor)
    out, _figures = fill_image(image, mask, params=params, source_mask=source_mask, texture=texture, rng=seed,
                               progress=progress, cancel=cancel)
    return out
