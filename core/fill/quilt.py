"""The quilting hole filler (Efros & Freeman 2001, §2 applied to a hole, as the quilting write-up in
``papers/`` suggests): blocks in fill-front order, SSD over known pixels only, minimum-error cut.

One block at a time, until no pixel of the hole is left:

1. **Fill-front order.** Among the unknown pixels next to a known (or already filled) one, the next
   block is centred on the one whose ``B x B`` window holds the most known or filled pixels (a box
   filter of the known mask; ties: the first in scan order). Concave corners of the hole, where the
   most context is, are filled first; the front moves inwards. On colour images that count is
   multiplied by ``1 + DATA * g / G`` (``g`` the mean gradient magnitude of the window's original
   known pixels, ``G`` that of the whole known region): edges that run into the hole are continued
   before the flat regions beside them grow over them (Criminisi et al.'s data term, simplified).
   Grey images (and RGB ones without chroma) keep the count alone: there the term pulled the front
   along texture edges.
2. **SSD over known pixels only.** The window's known and filled pixels are the template; the cost
   of every source position is the masked sum of squared differences over them, all colour channels
   (``sum M I^2 - 2 sum M T I + sum M T^2``: two ``cv2.matchTemplate`` correlations, the source's
   squares summed over its channels once), over positions whose whole
   ``B x B`` block lies in the source region (the known pixels, or ``source``). The SSD alone prefers
   flat blocks (a flat block of the right mean costs half as much as a textured one half a period
   off), which smeared a photo's hole; so ``DETAIL * n * (sigma_block - sigma_template)^2`` is added,
   ``sigma`` the standard deviation over the template's known pixels (one more correlation), so a
   fill keeps its texture's detail. A block is picked at random among those within
   ``(1 + EPSILON)`` times the best cost (E&F §2.1's rule).
3. **Locality.** Blocks are searched only within ``REACH`` px of the window, as Resynthesizer and
   Criminisi et al. prefer sources near the hole: the matches near a hole are the likeliest
   continuation, and the search costs less. Where that holds no whole block
   (the middle of a hole wider than ``2 REACH``), the reach doubles until one does, and the whole
   source is searched only when even that fails (e.g. a ``--texture``), so a long stroke across a
   large picture does not search the whole picture for each of its windows.
4. **Coarse colour guide** (colour images only). The hole is filled by diffusion (``cv2.inpaint``,
   Telea) at 1/``GUIDE_SCALE`` scale; for the window's *unknown* pixels, ``GUIDE`` times the SSD
   between the chroma (colour less its grey mean) of that guide and of the blurred source block
   is added (two more correlations): which material goes where in the hole (wood, not the
   saucer's red or the coffee), not its texture, which the known pixels' SSD matches. Grey images
   have no chroma and no guide (a grey guide pulled blocks towards flat ones).
5. **Continuing a copy.** Where earlier blocks already wrote into the window, the blocks that
   continue their copies (same source offset; the ``CONTINUE`` most frequent in the window) are
   candidates too, and the cheapest is taken when it costs at most ``(1 + COHERE)`` times the
   best: neighbouring blocks then form one verbatim copy with no seam between them, as a
   shift-map's labels do (a seam costs the judge ``fill_coherence`` most, the inside of a copy ~0).
   On grey pictures (a grey one stored as RGB too) a copy is not continued into a **thin gap**
   without a check: where none of the window's unknown pixels lies more than ``GAP_WIDTH`` px from
   a valued one (the last row of blocks, between filled rows and the hole's edge), the overlap
   says nothing about the gap, and a continued copy drew a whole mortar line into it, beside the
   real one a few px below the hole.
   There the gap is filled by diffusion (``cv2.inpaint``, Telea) from the window's own pixels,
   ``GAP`` times the SSD between that and the source block blurred by ``GAP_SIGMA`` (over the
   gap's pixels) is added to every cost, and the continuation is taken only if it still costs at
   most ``(1 + COHERE)`` times the best of those; the block picked otherwise is E&F's as before.
6. **Minimum-error cut.** On each side of the window that holds pixels filled by earlier blocks (an
   overlap strip of ``B // 3`` pixels), E&F's dynamic-programming cut
   runs over the squared difference between those pixels and the new block (one path per side, in
   numpy: :func:`weft.core.fill.cut.min_cut`, so a fill loads no numba); unknown pixels and
   the original known pixels cost a large constant there, so the cut goes through the filled ones.
   The new block replaces the unknown pixels and the filled pixels on its side of the cut. With
   ``band`` > 0 (``weft fill`` passes its ``--band``), the known pixels within ``band`` px of the
   hole count as filled ones: the cut may run through them, so a block can meet the known texture
   a little outside the hole where they agree best; every other known pixel is never written.

7. **Refine** (colour pictures only). The block seams inside the hole cost the judge most:
   :func:`weft.core.fill.search.refine_band` runs ``REFINE`` EM iteration(s) at full resolution
   over the hole and the band: every 7x7 patch touching them gets its nearest patch of the known
   pixels beyond the band, and every pixel is copied through the offset the covering patches agree
   on most, so the seams move to where the copies agree, without averaging. Each iteration searches
   only the inexact patches at or above the median of their distances (``REFINE_WORST``). The method
   then runs no Poisson band: the refine re-synthesises the band. One iteration is what the time
   allows; the ``hybrid`` engine runs more (it is the quilt with 64-px blocks and five).

Blocks are copied only from the original known pixels (never from filled ones), so errors cannot
feed on themselves.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from ..params import as_rng
from .common import Progress, check_engine_args, whole_patches
from .cut import min_cut
from .quilt_costs import GAP_SIGMA as GAP_SIGMA  # (re-exported: step 5's constants, read here)
from .quilt_costs import GAP_WIDTH as GAP_WIDTH
from .quilt_costs import _ccorr, _chroma, _coarse_guide, _gap_cost, _planes
from .quilt_order import DATA, _edges, _Front, _score

#: E&F's tolerance: a block within (1 + EPSILON) of the best cost may be chosen.
EPSILON = 0.1
#: Default block side (pixels) of the quilting engine.
BLOCK = 24
_BIG = 1e6
#: Weight of the contrast term added to the SSD (step 2 of the module docstring); 0 = E&F's SSD alone.
DETAIL = 3.0
#: How far a block moves away from its known pixels, as a fraction of their centroid's offset.
SHIFT = 2.0 / 3.0
#: Blocks are searched within this many px of their window (step 3); all of the source when none lies there.
REACH = 96
#: Weight of the coarse colour guide (step 4; colour images only); 0 = none.
GUIDE = 3.0
#: The guide is a diffusion fill of the hole at 1/GUIDE_SCALE; the blocks are blurred by GUIDE_SCALE / 2 to meet it.
GUIDE_SCALE = 4
#: A neighbouring block's copy is continued when it costs at most (1 + COHERE) times the best (step 5).
COHERE = 1.0
#: How many of the copies already in a window (the most frequent first) are tried for continuing.
CONTINUE = 4
#: EM iterations of the final patch-search refine (step 7; colour images only); 0 = none.
REFINE = 1
#: The refine searches, in each iteration, the inexact patches at or above this percentile of their distances.
REFINE_WORST = 50.0
#: The refine's patch side (the judge ``fill_coherence``'s window).
REFINE_PATCH = 7
#: Weight of the thin-gap cost on a continued copy (step 5; grey pictures only); 0 = none.
GAP = 3.0


def is_colour(img: np.ndarray, known: np.ndarray) -> bool:
    """Whether ``img`` is a colour picture on its ``known`` pixels.

    Three channels or more, not all grey (a grey picture stored as RGB has no chroma). Steps 1, 4 and
    7 run on colour only.

    Parameters
    ----------
    img : ndarray, (H, W, C)
    known : ndarray, bool (H, W)

    Returns
    -------
    bool
    """
    if img.shape[2] < 3 or not known.any():
        return False
    rgb, sub, ksub = img[..., :3], img[::7, ::7, :3], known[::7, ::7]
    if ksub.any() and float(np.abs(sub - sub.mean(axis=2, keepdims=True))[ksub].max()) > 1e-3:
        return True  # a coloured pixel among every 7th row and column: no need to look at them all
    return float(np.abs(rgb - rgb.mean(axis=2, keepdims=True))[known].max()) > 1e-3


def refines(image, hole, refine: bool | None = None) -> bool:
    """Whether :func:`fill_quilt` ends with its patch-search refine (step 7) on this image.

    The method then runs no Poisson blend band (the refine re-synthesises the band).

    Parameters
    ----------
    image : ndarray
        The picture.
    hole : ndarray, bool (H, W)
        The hole.
    refine : bool, optional
        The caller's choice; default: on colour pictures when :data:`REFINE` > 0.

    Returns
    -------
    bool
    """
    if refine is not None:
        return bool(refine) and REFINE > 0
    img = np.asarray(image)
    return REFINE > 0 and img.ndim == 3 and is_colour(img, ~np.asarray(hole, dtype=bool))


def fill_quilt(
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
    refine: bool | None = None,
) -> np.ndarray:
    """Fill ``hole`` of ``image`` with blocks quilted from ``source`` (default: the known pixels).

    Parameters
    ----------
    image : float32 (H, W) or (H, W, C), C = 1..4, in [0, 1]; values in the hole are ignored.
    hole : bool (H, W), True = pixels to fill.
    source : bool (H, W), optional: the pixels whose blocks may be copied (default ``~hole``).
    patch : int >= 3, the block side ``B`` (at most the image's smaller side).
    rng : seed or ``np.random.Generator``: same seed, same output.
    progress : gets :class:`weft.core.jobs.Progress` (stage ``"fill"``, in filled pixels) when the percentage changes.
    cancel : a ``CancelToken``, checked before every block.
    band : int >= 0, default 0: known pixels within this many px of the hole may be cut into (above).
    cuttable : bool (H, W) or None: the known pixels that may be cut into, given instead of ``band``
        (the method gives it when the engine's canvas is more than the image: the image's own band,
        without its transparent pixels; a band worked out on that canvas would reach into the image
        from the gap below it).
    refine : bool or None (default): end with step 7's refine; None = on colour pictures only
        (:func:`refines`).

    Returns
    -------
    float32, the shape of ``image``; every pixel outside ``hole`` (and, with ``band``, outside the
    band around it: :func:`weft.core.fill.band.band_region`) equals the input exactly.
    """
    img, hole, src = check_engine_args(image, hole, source, patch, "quilt")
    shape = np.shape(image)
    gen = as_rng(rng)
    h, w, c = img.shape
    b = int(patch)
    ov = max(2, b // 3)
    canvas = img.copy()
    canvas[hole] = 0.0
    known = ~hole  # original known pixels: never written
    have = known.copy()  # known or filled
    filled = np.zeros((h, w), dtype=bool)
    shift = np.zeros((2, h, w), dtype=np.int32)  # a written pixel's source less its position (dy, dx)
    span = max(h, w)  # |dy|, |dx| < span
    cutonly = np.zeros((h, w), dtype=bool)  # the band's known pixels no block has written yet
    if cuttable is not None:
        cuttable = np.asarray(cuttable, dtype=bool) & ~hole
    elif band > 0:  # known pixels within the band may be cut into: they count as filled ones
        from .band import band_region

        cuttable = band_region(hole, band) & ~hole
    if cuttable is not None:
        filled |= cuttable
        cutonly |= cuttable
    s = _search_image(canvas, hole, src, b)
    total = int(hole.sum())
    refining = refines(img, hole, refine)
    # the refine's share of the progress: about its share of the time (a fifth)
    refine_units = max(1, total // 5) if refining else 0
    report = Progress(progress, cancel, total + refine_units)
    report(0)
    # score: for an unknown pixel next to a valued one (the front), the valued pixels of the B x B
    # window centred on it; -1 elsewhere. Updated around each block only.
    score = np.full((h, w), -1.0, dtype=np.float32)
    # the structure term on colour images only; a grey picture stored as RGB (no chroma) is grey
    colour = is_colour(img, known)
    edges = _edges(canvas, known) if DATA > 0 and colour else None
    _score(have, score, b, 0, h, 0, w, edges)
    front = _Front(score)
    left = total
    while left > 0:
        py, px = front.first_max()
        if score[py, px] < 0:  # an unknown region touching nothing valued (cannot happen, kept safe)
            py, px = np.unravel_index(int(np.argmax(~have)), have.shape)  # type: ignore[assignment]  # numpy ints
        y0, x0 = _window(have, py, px, b)
        win = (slice(y0, y0 + b), slice(x0, x0 + b))
        template = np.ascontiguousarray(canvas[win])
        un = (~have[win]).astype(np.float32)
        ry0, rx0, crop, ok = _reach(s, y0, x0, b)
        cost = _block_cost(s, win, crop, ok, template, have[win].astype(np.float32), un)
        best = float(cost.min())
        cand = np.flatnonzero(cost.ravel() <= best * (1.0 + EPSILON) + 1e-9)
        pick = int(cand[gen.integers(len(cand))])
        cy, cx = divmod(pick, cost.shape[1])
        if COHERE > 0:  # continue a neighbouring block's copy when it costs little more: no seam there at all
            mine = filled[win] & ~cutonly[win]  # pixels earlier blocks wrote
            if mine.any():
                offsets = shift[:, y0 : y0 + b, x0 : x0 + b][:, mine].astype(np.int64)
                # that copy's block here, for each offset (dy, dx)
                here = [(y0 + dy - s.y0 - ry0, x0 + dx - s.x0 - rx0) for dy, dx in _frequent(offsets, span)]
                gap_check = GAP > 0 and not colour and un.any()
                cont = _continued(s, cost, best, here, crop, template, un if gap_check else None)
                if cont is not None:
                    cy, cx = cont
        cy, cx = cy + ry0, cx + rx0
        block = s.image[cy : cy + b, cx : cx + b]
        new_region = _block_region(canvas[win], block, have[win], filled[win], ov)
        left -= int(np.count_nonzero(new_region & ~have[win]))
        canvas[win][new_region] = block[new_region]
        shift[0][win][new_region] = s.y0 + cy - y0
        shift[1][win][new_region] = s.x0 + cx - x0
        filled[win] |= new_region
        cutonly[win] &= ~new_region
        have[win] |= new_region
        r = b // 2 + 1
        _score(have, score, b, max(0, y0 - r), min(h, y0 + b + r), max(0, x0 - r), min(w, x0 + b + r), edges)
        front.update(max(0, y0 - r), min(h, y0 + b + r))
        report(total - left)
    out = img.copy()
    changed = hole if cuttable is None else (hole | cuttable)
    out[changed] = canvas[changed]
    if refining:
        out = _refine(out, hole, changed, src, gen, cancel, lambda p: report(total + int(p.fraction * refine_units)))
    return out.reshape(shape)


@dataclass
class _Search:
    """The image blocks are copied from: the bounding box of the source (``image``, its corner
    ``y0``, ``x0`` on the canvas), the corners of its whole source blocks (``valid``), what the costs
    correlate with (its squares and sums over channels, its channel planes) and, on colour pictures,
    the coarse colour guide with the blurred chroma it meets (step 4; ``guide`` None otherwise).
    ``gap``: step 5's blurred source, made when first needed."""

    image: np.ndarray
    y0: int
    x0: int
    valid: np.ndarray
    sq: np.ndarray
    sum: np.ndarray
    planes: list[np.ndarray]
    guide: np.ndarray | None
    blur_sq: np.ndarray | None
    blur_planes: list[np.ndarray]
    gap: list[np.ndarray]


def _search_image(canvas: np.ndarray, hole: np.ndarray, src: np.ndarray, b: int) -> _Search:
    """The :class:`_Search` of ``src`` on ``canvas`` (its non-source pixels never inside a chosen block)."""
    ys, xs = np.nonzero(src)
    sy0, sy1, sx0, sx1 = ys.min(), ys.max() + 1, xs.min(), xs.max() + 1
    search = canvas[sy0:sy1, sx0:sx1].copy()  # never a view: the canvas is written
    guide, blur_sq, blur_planes = None, None, []
    if GUIDE > 0 and canvas.shape[2] >= 3:  # the colour (not the texture) of a coarse diffusion fill: chroma only
        guide = _chroma(_coarse_guide(canvas, hole, GUIDE_SCALE))
        blur = _chroma(cv2.GaussianBlur(search, (0, 0), GUIDE_SCALE / 2.0).reshape(search.shape))
        blur_sq = np.ascontiguousarray((blur * blur).sum(axis=2))
        blur_planes = _planes(blur)
    return _Search(
        search,
        sy0,
        sx0,
        whole_patches(src[sy0:sy1, sx0:sx1], b),
        np.ascontiguousarray((search * search).sum(axis=2)),
        np.ascontiguousarray(search.sum(axis=2)),
        _planes(search),
        guide,
        blur_sq,
        blur_planes,
        [],
    )


def _window(have: np.ndarray, py: int, px: int, b: int) -> tuple[int, int]:
    """The top-left corner of the block window centred on front pixel (``py``, ``px``), moved away from
    its valued pixels so that they fill about an overlap's width of it (a straight front: B/2 known
    -> B/3) and the block fills more."""
    h, w = have.shape
    y0 = int(min(max(py - b // 2, 0), h - b))
    x0 = int(min(max(px - b // 2, 0), w - b))
    sub = have[y0 : y0 + b, x0 : x0 + b]
    if sub.any() and not sub.all():
        ky, kx = np.nonzero(sub)
        y0 = int(min(max(y0 - round(SHIFT * (ky.mean() - (b - 1) / 2)), 0), h - b))
        x0 = int(min(max(x0 - round(SHIFT * (kx.mean() - (b - 1) / 2)), 0), w - b))
    return y0, x0


def _reach(s: _Search, y0: int, x0: int, b: int) -> tuple[int, int, tuple[slice, slice], np.ndarray]:
    """Step 3: the block corners searched for the window at (``y0``, ``x0``), the nearest reach that
    holds any (all of them when none does): ``(first row, first column, the search image's crop, the
    allowed corners in it)``."""
    hs, ws = s.valid.shape
    ry0, rx0, ry1, rx1 = 0, 0, hs, ws
    reach = REACH
    while 0 < reach < max(hs, ws):
        ry0, ry1 = max(0, y0 - s.y0 - reach), min(hs, y0 - s.y0 + reach + 1)
        rx0, rx1 = max(0, x0 - s.x0 - reach), min(ws, x0 - s.x0 + reach + 1)
        if ry0 < ry1 and rx0 < rx1 and s.valid[ry0:ry1, rx0:rx1].any():
            break
        reach *= 2
    else:
        ry0, rx0, ry1, rx1 = 0, 0, hs, ws
    return ry0, rx0, (slice(ry0, ry1 + b - 1), slice(rx0, rx1 + b - 1)), s.valid[ry0:ry1, rx0:rx1]


def _block_cost(
    s: _Search,
    win: tuple[slice, slice],
    crop: tuple[slice, slice],
    ok: np.ndarray,
    template: np.ndarray,
    weight: np.ndarray,
    un: np.ndarray,
) -> np.ndarray:
    """Steps 2 and 4: the cost of every block corner of ``s.image[crop]`` for the window ``win`` whose
    pixels are ``template``, valued where ``weight`` is 1 and unknown where ``un`` is: the masked SSD
    with the contrast term, plus the colour guide's on the unknown pixels; inf where not ``ok``."""
    c = template.shape[2]
    if weight.any():
        # masked SSD = sum M I^2 - 2 sum M T I + sum M T^2 (the squares summed over channels first)
        energy = cv2.matchTemplate(s.sq[crop], weight, cv2.TM_CCORR)  # sum M I^2
        cost = energy - 2.0 * _ccorr(s.planes, crop, template * weight[..., None])
        cost += float((weight[..., None] * template * template).sum())
        if DETAIL > 0:  # the contrast term: the block's and the template's standard deviations
            n = float(weight.sum()) * c
            s1 = cv2.matchTemplate(s.sum[crop], weight, cv2.TM_CCORR) / n
            sq = np.maximum(energy / n - s1 * s1, 0)
            tm = float((weight[..., None] * template).sum()) / n
            tv = max(float((weight[..., None] * template * template).sum()) / n - tm * tm, 0.0)
            cost += DETAIL * n * (np.sqrt(sq) - np.sqrt(tv)) ** 2
    else:
        cost = np.zeros(ok.shape, dtype=np.float32)
    if s.guide is not None and s.blur_sq is not None and un.any():
        g = np.ascontiguousarray(s.guide[win] * un[..., None])
        gc = cv2.matchTemplate(s.blur_sq[crop], un, cv2.TM_CCORR) - 2.0 * _ccorr(s.blur_planes, crop, g)
        gc += float((g * s.guide[win]).sum())
        cost = cost + GUIDE * np.maximum(gc, 0.0)
    return np.where(ok & np.isfinite(cost), np.maximum(cost, 0.0), np.inf)  # float32 rounding: >= 0


def _frequent(offsets: np.ndarray, span: int) -> list[tuple[int, int]]:
    """The :data:`CONTINUE` most frequent of the copies' ``offsets`` ((2, N) int64 rows dy, dx, each
    below ``span`` in size), the most frequent first."""
    # each offset as one int64, ordered as (dy, dx) rows are (as np.unique with axis=0 orders them, for less)
    codes, counts = np.unique((offsets[0] + span) * (2 * span + 1) + (offsets[1] + span), return_counts=True)
    shifts = np.stack([codes // (2 * span + 1) - span, codes % (2 * span + 1) - span], axis=1)
    return [(int(dy), int(dx)) for dy, dx in shifts[np.argsort(-counts, kind="stable")[:CONTINUE]]]


def _continued(
    s: _Search,
    cost: np.ndarray,
    best: float,
    here: list[tuple[int, int]],
    crop: tuple[slice, slice],
    template: np.ndarray,
    gap_of: np.ndarray | None,
) -> tuple[int, int] | None:
    """Step 5: the corner (in ``cost``) of the cheapest block that continues a copy already in the
    window (``here``: those copies' corners), when it costs at most ``(1 + COHERE)`` times the
    ``best``; with ``gap_of`` (the window's unknown pixels, on grey pictures) the thin-gap cost is
    added to every cost first. None: no continuation."""
    conts = [
        (float(cost[ty, tx]), ty, tx)
        for ty, tx in here
        if 0 <= ty < cost.shape[0] and 0 <= tx < cost.shape[1] and np.isfinite(cost[ty, tx])
    ]
    if not conts:
        return None
    c_cost, ty, tx = min(conts)
    bound = best
    if gap_of is not None:  # a continued copy must not draw into a thin gap what its sides lack
        gap = _gap_cost(template, gap_of, s.image, crop, s.gap)
        if gap is not None:
            with_gap = cost + GAP * gap
            bound = float(with_gap.min())
            c_cost, ty, tx = min((float(with_gap[ty, tx]), ty, tx) for _, ty, tx in conts)
    return (ty, tx) if c_cost <= bound * (1.0 + COHERE) + 1e-9 else None


def _block_region(window: np.ndarray, block: np.ndarray, have: np.ndarray, filled: np.ndarray, ov: int) -> np.ndarray:
    """Step 6: the window's pixels the new ``block`` writes: its unknown ones, and the ``filled`` ones
    on the block's side of the minimum-error cut through the overlap strips (``ov`` px) that hold some."""
    b = window.shape[0]
    new_region = ~have
    if filled.any():
        err = ((window - block) ** 2).sum(axis=2).astype(np.float64)
        err[~filled] = _BIG
        sides = dict(
            left=filled[:, :ov].any(),
            top=filled[:ov, :].any(),
            right=filled[:, b - ov :].any(),
            bottom=filled[b - ov :, :].any(),
        )
        cut = min_cut(err, **{k: (ov if v else 0) for k, v in sides.items()})
        new_region |= filled & cut
    return new_region


def _refine(
    out: np.ndarray, hole: np.ndarray, region: np.ndarray, src: np.ndarray, gen, cancel, progress
) -> np.ndarray:
    """Step 7: :func:`weft.core.fill.patchmatch.refine_band` over the hole and the band (``region``)."""
    from .patchmatch import refine_band

    return refine_band(
        out,
        hole,
        region,
        src,
        patch=max(3, min(REFINE_PATCH, *hole.shape)),
        iterations=REFINE,
        rng=gen,
        progress=progress,
        cancel=cancel,
        worst=REFINE_WORST,
    )
