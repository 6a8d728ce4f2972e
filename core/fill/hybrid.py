"""The ``hybrid`` fill engine: the quilting engine's fill, refined by full-resolution patch search.

1. :func:`weft.core.fill.quilt.fill_quilt` lays the hole out in large verbatim blocks (64 px by
   default, twice the quilt engine's: fewer seams inside the hole) cut along minimum-error seams, the
   cut free to run through the known pixels of the blend band: straight structure such as brick
   mortar continues through the hole.
2. :func:`weft.core.fill.search.refine_patchmatch` then runs EM / PatchMatch iterations at full
   resolution from that fill over the hole *and the band* (no pyramid, so nothing is re-invented from
   a blurred estimate): every 7x7 patch touching them gets its nearest patch of the known pixels
   beyond the band (the blocks' own sources are found exactly), and every pixel is copied through the
   offset the covering patches agree on most. The seams between blocks, and between the fill and
   the known texture, move to where the copies agree, without averaging: the texture keeps its grain
   and the band ends up a continuation of the known pixels (so the method runs no Poisson blend for
   this engine).

Known pixels change only within the band (``cuttable``, which the method gives for ``--band``);
without one the refine works on the hole alone. Both steps run in numpy and OpenCV: a fill with this
engine loads no numba.
"""

from __future__ import annotations

import numpy as np

from ..jobs import ProgressReporter
from ..params import as_rng
from .quilt import fill_quilt

#: The quilting block of the hybrid engine (its ``patch``): twice the quilt engine's 24, so the hole
#: holds fewer seams, and the engine is quicker than with 24.
BLOCK = 64
#: The refine's patch side (the coherence metric's window).
REFINE_PATCH = 7
#: EM iterations of the refine.
REFINE_ITERATIONS = 5


def fill_hybrid(
    image,
    hole,
    source=None,
    *,
    patch=BLOCK,
    rng=0,
    progress=None,
    cancel=None,
    band=0,
    cuttable=None,
    refine_patch=REFINE_PATCH,
    iterations=REFINE_ITERATIONS,
) -> np.ndarray:
    """Fill ``hole`` by quilting, then refine it by patch search.

    :func:`~weft.core.fill.quilt.fill_quilt` fills the hole, then
    :func:`~weft.core.fill.patchmatch.refine_patchmatch` refines the hole and the band's changed pixels,
    copying only from source pixels outside them. Every pixel outside the hole and the band equals the
    input exactly.

    Parameters
    ----------
    image : array_like, (H, W) or (H, W, C), float in [0, 1]
        The picture.
    hole : array_like, bool (H, W)
        The pixels to fill.
    source : array_like, bool (H, W), optional
        The pixels to copy from (default all outside the hole).
    patch : int, default BLOCK
        The quilting's block side.
    rng : None, int or numpy.random.Generator, default 0
        Seed.
    progress : callable, optional
        Receives :class:`weft.core.jobs.Progress`: the quilting's filled pixels, then one unit per
        refine iteration.
    cancel : CancelToken, optional
        Checked by both steps.
    band : int, default 0
        Known pixels around the hole the cut, and then the refine, may change.
    cuttable : ndarray, bool (H, W), optional
        Those pixels, when the caller worked them out.
    refine_patch : int, default REFINE_PATCH
        The refine's patch side.
    iterations : int, default REFINE_ITERATIONS
        The refine's EM iterations.

    Returns
    -------
    ndarray, float32

    Raises
    ------
    WeftError
        As :func:`~weft.core.fill.quilt.fill_quilt`.

    References
    ----------
    Efros & Freeman, "Image quilting for texture synthesis and transfer" (2001), §2; Barnes et al.,
    "PatchMatch" (2009); Wexler, Shechtman & Irani, "Space-time completion of video" (2007).
    """
    from .band import band_region
    from .patchmatch import refine_band

    gen = as_rng(rng)
    holes = np.asarray(hole, dtype=bool)
    total = max(1, int(holes.sum()))
    span = total + int(iterations)

    report = ProgressReporter(progress, "fill", span)

    def quilt_progress(p):
        report.update(int(p.fraction * total))

    def refine_progress(p):
        report.update(total + int(round(p.fraction * iterations)))

    quilted = fill_quilt(
        image,
        holes,
        source,
        patch=patch,
        rng=gen,
        progress=quilt_progress,
        cancel=cancel,
        band=band,
        cuttable=cuttable,
        refine=False,
    )  # (its own refine follows)
    if cuttable is not None:
        region = holes | np.asarray(cuttable, dtype=bool)
    else:
        region = holes | band_region(holes, band) if band > 0 else holes
    allowed = ~holes if source is None else np.asarray(source, dtype=bool) & ~holes
    rp = max(3, min(int(refine_patch), int(patch), *holes.shape))
    return refine_band(
        quilted,
        holes,
        region,
        allowed,
        patch=rp,
        iterations=iterations,
        rng=gen,
        progress=refine_progress,
        cancel=cancel,
    )
