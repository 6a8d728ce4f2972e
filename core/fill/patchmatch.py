"""The ``patchmatch`` fill engine: multi-scale patch search with voting.

Wexler, Shechtman & Irani, "Space-Time Completion of Video" (PAMI 2007), with the search of Barnes
et al., "PatchMatch" (SIGGRAPH 2009) from :mod:`weft.core.fill.search`:

1. An image pyramid, halving until the hole is about two patches deep (one for a hole along the
   border: an uncrop). A coarse pixel is in the hole when any of its four fine pixels is, a source
   pixel when all four are; known pixels are the mean of their known fine pixels.
2. Newson et al.'s texture features ("Video inpainting of complex scenes", SIIMS 2014): two more
   channels, the absolute luminance derivatives averaged over 5x5, filled like the colours, so the
   search does not settle on the flattest patches and the fill keeps the texture's energy.
3. The coarsest level starts from an onion-peel diffusion of the hole's edge. Every level but the
   finest runs EM iterations (:func:`weft.core.fill.search.em.em`) with each target pixel's squared
   difference weighted by its confidence (1 known, ``GAMMA ** -d`` at depth ``d`` in the hole), so
   the known edge decides the match. A finer level starts from the coarser level's matches, doubled
   and voted (an upsampled image would be blurred, and the flattest patches would match it best).
4. The finest level is refined at full resolution on the image's own channels over the hole and
   the blend band (``cuttable``) by :func:`weft.core.fill.search.refine_band`, so the band becomes a
   continuation of the copies instead of a Poisson blend.

An optional ``guide`` (:mod:`weft.core.fill.structure`: where the edges that cross the hole run) is
matched on the coarsest level only, at full confidence, and never written: it lays the fill out, and
the finer levels mend the copies' seams from that layout.

Every pixel outside the hole (and ``cuttable``) is returned exactly as given.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..errors import ImageError
from ..jobs import CancelToken, Progress, ProgressReporter
from ..params import as_rng
from .common import touches_border, whole_patches
from .search import MAX_PATCH, MIN_PATCH, STEPS_FIRST, Flat, check_inputs, em, refine_band, refine_patchmatch, vote_mode

__all__ = ["fill_patchmatch", "refine_patchmatch", "refine_band", "MIN_PATCH", "MAX_PATCH"]

GAMMA = 1.3  # Wexler's confidence decay per pixel of distance into the hole
_MIN_SOURCES = 16  # a coarser level is used only if it keeps at least this many whole source patches
# the pyramid stops when the hole is at most this many patches deep: at one patch the coarsest
# level's diffused start matches whatever has the mean colour of the hole's surroundings (a cup's
# crema for a saucer's hole); an uncrop keeps one, or its structure (brick's mortar) is not continued
_COARSEST_DEPTH = 2.0
_COARSEST_DEPTH_BORDER = 1.0
_FEATURE_WEIGHT = 3.0  # weight of Newson's texture features (two extra channels) in the distance
# EM iterations per level: none on the finest (the final refine follows), 8 on the intermediate
# levels, 12 on the coarsest, which lays the fill out; fewer with a guide, which lays it out itself
_EM_FINEST, _EM_MIDDLE, _EM_COARSEST = 0, 8, 12
_EM_MIDDLE_GUIDED, _EM_COARSEST_GUIDED = 6, 8
# the final refine's last vote counts every covering patch: with a sparse vote neighbouring pixels of
# an incoherent region go through different offsets and the fill is speckled
_LAST_STRIDE = 1
_PYRAMID_SHRINK = 2  # the pyramid's random search radii: half the level, then / 2 down to 1 px
# on the intermediate levels propagation takes a neighbour's offset unless the current match is more
# than (1 + this) times closer: the fill is laid out in large coherent copies, not a mosaic of equally
# good small matches (not on the coarsest level, where it copies whole wrong objects into the hole)
_COHERENCE_BIAS = 1.0
# the guide's weight in the distance, shared by its channels (one per continued edge): each channel
# at full weight broke a rim where several edges along it were paired
_GUIDE_WEIGHT = 1.0
# the final refine: EM iterations (one more with a guide, which mends the layout's seams), searching
# the inexact patches whose distance is at least this percentile of theirs
_FINAL_REFINE, _FINAL_WORST = 3, 50
_FINAL_REFINE_GUIDED = 4


def _halve(img: np.ndarray, hole: np.ndarray, source: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The next coarser level: 2x2 blocks (an odd last row/column is its own block)."""
    h, w = hole.shape
    ph, pw = h % 2, w % 2
    if ph or pw:
        img = np.pad(img, ((0, ph), (0, pw), (0, 0)), mode="edge")
        hole = np.pad(hole, ((0, ph), (0, pw)), mode="edge")
        source = np.pad(source, ((0, ph), (0, pw)), mode="edge")
    h2, w2 = hole.shape[0] // 2, hole.shape[1] // 2
    known = (~hole).astype(np.float32)
    kb = known.reshape(h2, 2, w2, 2).sum(axis=(1, 3))
    vb = (img * known[..., None]).reshape(h2, 2, w2, 2, -1).sum(axis=(1, 3))
    img2 = np.where(kb[..., None] > 0, vb / np.maximum(kb, 1.0)[..., None], 0.0).astype(np.float32)
    hole2 = hole.reshape(h2, 2, w2, 2).any(axis=(1, 3))
    source2 = source.reshape(h2, 2, w2, 2).all(axis=(1, 3)) & ~hole2
    return np.ascontiguousarray(img2), hole2, source2  # type: ignore[return-value]  # numpy's stubs: any/all with an axis may be a bool


class _Level:
    """One pyramid level: its image (colours and features), hole, source pixels, the count of whole
    source patches, the hole's depth and every pixel's confidence (1 known, ``GAMMA ** -depth`` in
    the hole)."""

    def __init__(self, img, hole, source, p):
        self.img, self.hole, self.source, self.p = img, hole, source, p
        self.n_valid = int(np.count_nonzero(whole_patches(source, p)))
        depth = _depth_of(hole)
        self.depth = float(depth.max()) if hole.any() else 0.0
        self.conf = np.ascontiguousarray(np.where(hole, GAMMA**-depth, 1.0).astype(np.float32))


def fill_patchmatch(
    image: np.ndarray,
    hole: np.ndarray,
    source: np.ndarray | None = None,
    *,
    patch: int = 7,
    rng: None | int | np.random.Generator = 0,
    progress: Callable[[Progress], None] | None = None,
    cancel: CancelToken | None = None,
    levels: int | None = None,
    iterations: int | None = None,
    cuttable: np.ndarray | None = None,
    guide: np.ndarray | None = None,
) -> np.ndarray:
    """Fill the ``hole`` of ``image`` with patches of its ``source`` region (see the module text).

    Parameters
    ----------
    image : float array (H, W) or (H, W, C), C = 1..4, values in [0, 1]
        The image; values inside the hole are ignored (may be anything, NaN included). An alpha
        channel is one more channel to match and fill.
    hole : bool array (H, W)
        True where pixels are unknown and filled. An empty hole returns a copy of ``image``.
    source : bool array (H, W), optional
        Pixels whose patches may be copied (default: everything outside the hole; hole pixels are
        never a source). Only patches lying wholly in it are used.
    patch : int, 3..63, default 7
        Patch side in pixels.
    rng : int seed or numpy Generator, default 0
        Same seed, same output.
    progress : callable, optional
        Gets a :class:`weft.core.jobs.Progress` (stage ``"fill"``, one unit per EM iteration) when
        the percentage changes.
    cancel : CancelToken, optional
        Checked before every PatchMatch sweep; raises :class:`weft.core.errors.Cancelled`.
    levels : int, optional
        Pyramid levels (1 = finest only); default: as many as bring the hole to about two patches
        deep (one when it touches the image's border), as long as a level keeps 16 whole source
        patches and both sides >= 2 patches.
    iterations : int, optional
        EM iterations on every level (all channels, confidence-weighted); default 12 on the
        coarsest, 8 on the intermediate ones (with a ``guide`` 8 and 6), none on the finest (a single
        level gets the coarsest's). Three refine iterations on the image's own channels always follow (four
        with a ``guide``: :func:`refine_band`).
    cuttable : bool array (H, W), optional
        Known pixels that may change (the method's blend band): the finished fill, these pixels and
        the hole are then refined together by :func:`refine_patchmatch`, copying only from source
        pixels outside them, so the band becomes a continuation of the copies (and the method runs
        no Poisson blend for this engine).
    guide : float array (H, W) or (H, W, K), K = 1..8, optional
        Channels known everywhere, the hole included (:func:`weft.core.fill.structure.structure_guide`:
        for each edge continued across the hole, the side of it and the nearness to it). On the
        coarsest pyramid level (their 2x2 means) they are matched like colours (weight
        ``_GUIDE_WEIGHT`` / K), at full confidence in the hole, and never filled: the votes leave them
        alone. They lay the fill out; the finer levels and the final refine (``_FINAL_REFINE_GUIDED``
        iterations) do not see them, and mend the copies' seams from that layout.

    Returns
    -------
    float32 array of ``image``'s shape: outside the hole equal to ``image`` bit for bit.

    Raises
    ------
    ImageError
        Wrong image, mask or guide shape, a guide with NaN or infinite values, an image smaller than
        the patch, or a source region without a single whole patch.
    InvalidParameter
        ``patch``, ``levels`` or ``iterations`` out of range.
    """
    arr, hole, source, p = check_inputs(image, hole, source, patch, levels, iterations)
    if guide is not None:
        guide = _checked_guide(guide, hole)
    out = np.array(arr, dtype=np.float32, copy=True)
    if not hole.any():
        return out
    gen = as_rng(rng)
    img = out if out.ndim == 3 else out[..., None]
    img = np.ascontiguousarray(img, dtype=np.float32)
    img[hole] = 0.0
    nch = img.shape[2]
    if _FEATURE_WEIGHT > 0:
        img = np.ascontiguousarray(np.concatenate([img, _FEATURE_WEIGHT * _texture_features(img, hole)], axis=2))

    pyramid = _pyramid(img, hole, source, p, levels)
    n = len(pyramid)
    top = pyramid[-1]
    _onion_fill(top.img, top.hole)  # the coarsest level's start
    fixed = None  # the guide's channels on the coarsest level: never filled, matched at full confidence
    if guide is not None:
        for _ in range(n - 1):  # the guide is known in the hole too: the plain 2x2 means
            guide = _halve_plain(guide)
        fixed = slice(top.img.shape[2], top.img.shape[2] + guide.shape[2])
        # several edges share the weight: each channel is scaled by 1 / their number
        weight = _GUIDE_WEIGHT / guide.shape[2]
        top.img = np.ascontiguousarray(np.concatenate([top.img, weight * guide], axis=2))
    schedule = _schedule(iterations, n, guide is not None)
    final = _FINAL_REFINE if guide is None else _FINAL_REFINE_GUIDED
    report = ProgressReporter(progress, "fill", sum(schedule) + final)
    done = 0
    fl = sy = sx = None
    for li in range(n - 1, -1, -1):
        lv = pyramid[li]
        im = lv.img
        if li == n - 1:
            fl = Flat(im, lv.hole, lv.source, p, conf=lv.conf, fixed=fixed)
            sy, sx = _random_matches(fl, gen)
        else:
            fixed = None  # the guide steers the coarsest level's layout only
            _upsample_into(im, lv.hole, pyramid[li + 1].img[..., : im.shape[2]])
            coarse, fl = fl, Flat(im, lv.hole, lv.source, p, conf=lv.conf)
            sy, sx = _upsample_matches(fl, coarse, sy, sx, gen)  # type: ignore[arg-type]  # set on the coarsest level, the loop's first
            # the first estimate of this level: the coarse matches, doubled, voted (an upsampled
            # image would be blurred; matched against it, the flattest patches win)
            vote_mode(im, lv.hole, fl, sy, sx, np.ones(len(sy)))
        if schedule[li] > 0:
            everyone = np.arange(len(fl.ty))
            dist = fl.dist(fl.gather(fl.ty, fl.tx), everyone, sy, sx)
            bias = _COHERENCE_BIAS if 0 < li < n - 1 else 0.0

            def step(_it, done0=done):
                report.update(done0 + _it + 1)

            em(
                fl,
                im,
                lv.hole,
                sy,
                sx,
                dist,
                iterations=schedule[li],
                gen=gen,
                steps_first=STEPS_FIRST,
                shrink=_PYRAMID_SHRINK,
                bias=bias,
                worst=0.0,
                cancel=cancel,
                on_iteration=step,
                fixed=fixed,
            )
            done += schedule[li]
    res = pyramid[0].img[..., :nch]
    if out.ndim == 2:
        out[hole] = res[..., 0][hole]
    else:
        out[hole] = res[hole]
    region = hole if cuttable is None else (hole | np.asarray(cuttable, dtype=bool))
    units = sum(schedule)

    def refine_progress(pr: Progress, done0=units) -> None:
        report.update(done0 + int(round(pr.fraction * final)))

    return refine_band(
        out,
        hole,
        region,
        source,
        patch=p,
        iterations=final,
        rng=gen,
        progress=refine_progress if progress is not None else None,
        cancel=cancel,
        worst=_FINAL_WORST,
        last_vote_stride=_LAST_STRIDE,
    )


def _checked_guide(guide, hole: np.ndarray) -> np.ndarray:
    """The ``guide`` as (H, W, K) float32, refused when of another size than the hole, with more than
    8 channels, or with NaN or infinite values."""
    given = np.asarray(guide, dtype=np.float32)
    out = given[..., None] if given.ndim == 2 else given
    if out.ndim != 3 or out.shape[:2] != hole.shape or not 1 <= out.shape[2] <= 8:
        raise ImageError(
            f"the guide has shape {given.shape}; it must be (H, W) or (H, W, 1..8) with the "
            f"image's {hole.shape[1]}x{hole.shape[0]}"
        )
    if not np.isfinite(out).all():
        raise ImageError("the guide holds NaN or infinite values")
    return out


def _pyramid(img: np.ndarray, hole: np.ndarray, source: np.ndarray, p: int, levels: int | None) -> list[_Level]:
    """The levels, finest first (step 1): ``levels`` of them, or by default halving until the hole is
    about :data:`_COARSEST_DEPTH` patches deep (:data:`_COARSEST_DEPTH_BORDER` along the border), as
    long as a level keeps its whole source patches and both sides at least two patches."""
    pyramid = [_Level(img.copy(), hole, source, p)]
    if pyramid[0].n_valid == 0:
        raise ImageError(
            f"the source region holds no whole {p}x{p} patch: leave at least a {p}x{p} square "
            f"of known pixels to copy from (or use a smaller patch)"
        )
    max_levels = 64 if levels is None else int(levels)
    deep = p * (_COARSEST_DEPTH_BORDER if touches_border(hole) else _COARSEST_DEPTH)
    while len(pyramid) < max_levels:
        top = pyramid[-1]
        if levels is None and top.depth <= deep:
            break
        if min((top.hole.shape[0] + 1) // 2, (top.hole.shape[1] + 1) // 2) < 2 * p:
            break
        nxt = _Level(*_halve(top.img, top.hole, top.source), p)
        if nxt.n_valid < min(_MIN_SOURCES, top.n_valid) or not nxt.hole.any():
            break
        pyramid.append(nxt)
    return pyramid


def _schedule(iterations: int | None, n: int, guided: bool) -> list[int]:
    """EM iterations on each of the ``n`` levels, finest first: ``iterations`` on every one, or by
    level (a single level is the coarsest; fewer with a guide, which lays the fill out itself)."""
    if iterations is not None:
        return [int(iterations)] * n
    middle, coarsest = (_EM_MIDDLE_GUIDED, _EM_COARSEST_GUIDED) if guided else (_EM_MIDDLE, _EM_COARSEST)
    return ([_EM_FINEST] + [middle] * (n - 2) + [coarsest]) if n > 1 else [coarsest]


def _halve_plain(a: np.ndarray) -> np.ndarray:
    """The 2x2 means of (H, W, K) channels known everywhere (an odd last row/column padded by its
    edge, as :func:`_halve` pads), float32."""
    h, w = a.shape[:2]
    a = np.pad(a, ((0, h % 2), (0, w % 2), (0, 0)), mode="edge")
    return a.reshape(a.shape[0] // 2, 2, a.shape[1] // 2, 2, -1).mean(axis=(1, 3), dtype=np.float32)


def _texture_features(img: np.ndarray, hole: np.ndarray) -> np.ndarray:
    """Newson et al.'s texture features: the absolute horizontal and vertical luminance derivatives
    averaged over a 5x5 window, from known pixels only (normalized convolution), (H, W, 2) float32."""
    import cv2

    lum = img.mean(axis=2) if img.shape[2] < 3 else img[..., :3].mean(axis=2)
    known = (~hole).astype(np.float32)
    feats = []
    for axis in (1, 0):
        fwd = np.roll(lum, -1, axis=axis)
        bwd = np.roll(lum, 1, axis=axis)
        kf_ = np.roll(known, -1, axis=axis) * np.roll(known, 1, axis=axis) * known
        if axis == 1:
            kf_[:, 0] = kf_[:, -1] = 0
        else:
            kf_[0, :] = kf_[-1, :] = 0
        g = np.abs(fwd - bwd) * 0.5 * kf_
        num = cv2.boxFilter(g.astype(np.float32), -1, (5, 5), normalize=False, borderType=cv2.BORDER_CONSTANT)
        den = cv2.boxFilter(kf_.astype(np.float32), -1, (5, 5), normalize=False, borderType=cv2.BORDER_CONSTANT)
        feats.append(np.where(den > 0, num / np.maximum(den, 1e-6), 0.0))
    out = np.stack(feats, axis=2).astype(np.float32)
    out[hole] = 0.0
    return out


def _depth_of(hole: np.ndarray) -> np.ndarray:
    """Every hole pixel's Euclidean distance (px) to the nearest known pixel, 0 outside the hole
    (OpenCV's exact transform: ``scipy.ndimage``'s import alone is 0.1 s of a fill's process)."""
    import cv2

    if not hole.any():
        return np.zeros(hole.shape, np.float32)
    return cv2.distanceTransform(np.ascontiguousarray(hole).view(np.uint8), cv2.DIST_L2, cv2.DIST_MASK_PRECISE)


def _onion_fill(img: np.ndarray, hole: np.ndarray) -> None:
    """The coarsest level's start: the hole filled ring by ring from its edge, each pixel of a ring
    the mean of its known or already filled 8-neighbours. Writes ``img`` (H, W, C) in place."""
    import cv2

    done = ~hole
    todo = hole.copy()
    ones = np.ones((3, 3), np.float32)
    while todo.any():
        known = done.astype(np.float32)
        count = cv2.filter2D(known, -1, ones, borderType=cv2.BORDER_CONSTANT)
        ring = todo & (count > 0)
        if not ring.any():
            break
        sums = np.stack(
            [
                cv2.filter2D(np.ascontiguousarray(img[..., c] * known), -1, ones, borderType=cv2.BORDER_CONSTANT)
                for c in range(img.shape[2])
            ],
            axis=2,
        )
        img[ring] = sums[ring] / count[ring][:, None]
        done |= ring
        todo &= ~ring


def _upsample_matches(fl: Flat, coarse: Flat, sy: np.ndarray, sx: np.ndarray, gen: np.random.Generator):
    """The coarser level's matches (``sy``, ``sx`` of ``coarse``'s target patches), doubled, for the
    finer level's target patches (random where the coarse level had no match or the doubled one is
    not a whole source patch)."""
    hc, wc = coarse.tmap.shape
    m = coarse.tmap[np.minimum(fl.ty // 2, hc - 1), np.minimum(fl.tx // 2, wc - 1)]
    hv, wv = fl.valid.shape
    ny = np.clip(2 * sy[np.maximum(m, 0)] + fl.ty % 2, 0, hv - 1)
    nx = np.clip(2 * sx[np.maximum(m, 0)] + fl.tx % 2, 0, wv - 1)
    ok = (m >= 0) & fl.valid[ny, nx]
    ry, rx = _random_matches(fl, gen)
    return np.where(ok, ny, ry), np.where(ok, nx, rx)


def _random_matches(fl: Flat, gen: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """A whole source patch drawn at random for each of ``fl``'s target patches (int64 corners)."""
    vy, vx = np.nonzero(fl.valid)
    pick = gen.integers(0, len(vy), len(fl.ty))
    return vy[pick].astype(np.int64), vx[pick].astype(np.int64)


def _upsample_into(img: np.ndarray, hole: np.ndarray, coarse: np.ndarray) -> None:
    """Set the hole pixels of ``img`` from the coarser level's result (bilinear, pixel centres)."""
    h, w = hole.shape
    hc, wc = coarse.shape[:2]
    ys, xs = np.nonzero(hole)
    fy = np.clip((ys + 0.5) / 2.0 - 0.5, 0, hc - 1)
    fx = np.clip((xs + 0.5) / 2.0 - 0.5, 0, wc - 1)
    y0 = np.floor(fy).astype(np.int64)
    x0 = np.floor(fx).astype(np.int64)
    y1 = np.minimum(y0 + 1, hc - 1)
    x1 = np.minimum(x0 + 1, wc - 1)
    ay = (fy - y0)[:, None]
    ax = (fx - x0)[:, None]
    v = (1 - ay) * ((1 - ax) * coarse[y0, x0] + ax * coarse[y0, x1]) + ay * (
        (1 - ax) * coarse[y1, x0] + ax * coarse[y1, x1]
    )
    img[ys, xs] = v.astype(np.float32)
