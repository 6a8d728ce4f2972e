"""The ``patchmatch`` fill engine: multi-scale patch search with voting.

Wexler, Shechtman & Irani, "Space-Time Completion of Video" (PAMI 2007), with the nearest-neighbour
search of Barnes et al., "PatchMatch" (SIGGRAPH 2009):

1. An image pyramid, halving until the hole is about one patch deep (a coarse pixel is in the hole
   when any of its four fine pixels is, a source pixel when all four are; known pixels are the mean
   of their known fine pixels).
2. Newson et al.'s texture features ("Video inpainting of complex scenes", SIIMS 2014): two more
   channels, the absolute luminance derivatives averaged over 5x5, filled like the colours. Matching
   a blurred estimate on colours alone picks the flattest patches, and the fill converges to a
   smooth blur; the features keep the texture's energy in the hole and steer the search to patches
   that have it.
3. On the coarsest level the hole starts as an onion-peel diffusion of its edge (features too). Then,
   on every level, EM iterations: (E) for every patch overlapping the hole, PatchMatch finds the
   most similar patch lying wholly in the source region (random matches on the coarsest level, the
   coarser level's matches, doubled, on the finer ones; on the intermediate levels propagation
   takes a neighbour's offset unless the current match is more than twice as close, so the fill is
   laid out in large coherent copies, not a mosaic of equally good small matches); the distance is
   a sum of squared differences over all channels (an alpha channel is one more), each pixel
   weighted by its confidence: 1 on known pixels, ``1.3 ** -d`` at distance ``d`` inside the hole
   (Wexler's gamma), so the known edge decides the match; (M) each hole pixel is copied through the
   offset (match minus patch) that the patches covering it agree on most, each counted with
   ``exp(-distance / 2 sigma^2)`` (sigma^2: the 75th percentile of the level's distances). Unlike
   Wexler's weighted mean this never blurs: where the matches are coherent whole regions are copied
   verbatim, and the fill keeps the source's grain. A finer level starts from the coarser level's
   matches, doubled, and voted (mean). The very last vote averages the hole's pixels within 2 px of
   its edge instead (their patches lie mostly on known pixels and agree with them): the cut between
   a copied region and the known pixels softens to what the known texture has (seam -0.05..-0.13 on
   the 256-384 px gravel/brick/photo cases, coherence no worse).
4. With a blend band (``cuttable``: the known pixels within ``--band`` px of the hole, which the
   method passes), that last edge average is skipped and the hole and the band are refined together
   at full resolution by :func:`refine_patchmatch` (3 EM iterations copying only from beyond the
   band): the band becomes a continuation of the copies instead of a Poisson blend, and the windows
   across the hole's edge get closer to known ones (seeds 0-1 medians on the 320-384 px benchmark
   cases, against the Poisson band: gravel coherence 10.7 -> 9.7, brick 1.43 -> 1.22, photo 5.5 ->
   4.8 with its seam 0.82 -> 1.09, the truth's 1.07).

Every pixel outside the hole (and ``cuttable``) is returned exactly as given.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from ..errors import ImageError, InvalidParameter
from ..jobs import CancelToken, Progress, ProgressReporter
from ..params import as_rng

__all__ = ["fill_patchmatch", "refine_patchmatch", "warm_up", "MIN_PATCH", "MAX_PATCH"]

MIN_PATCH = 3
MAX_PATCH = 63
_GAMMA = 1.3  # Wexler's confidence decay per pixel of distance into the hole
_MIN_SOURCES = 16  # a coarser level is used only if it keeps at least this many whole source patches
_COARSEST_DEPTH = 1.0  # the pyramid stops when the hole is at most this many patches deep
_FEATURE_WEIGHT = 3.0  # weight of Newson's texture features (two extra channels) in the distance
_EM_FINEST, _EM_MIDDLE, _EM_COARSEST = 2, 4, 8  # default EM iterations per level
# ... on the finest level when the full-resolution refine follows (a band is given): 1 and 2 give the same
# figures on the four benchmark cases (seeds 0-1), 1 saves a finest-level iteration
_EM_FINEST_REFINED = 1
_SWEEPS_COARSEST, _SWEEPS_FINER = 4, 2  # PatchMatch sweeps of a level's first E step (later ones: 1)
# On the intermediate levels PatchMatch's propagation takes a neighbour's offset when its distance is
# below (1 + this) times the current match's: the fill is laid out in larger coherent copies (coherence
# -0.5..-1.0 on the gravel cases, -0.2 on brick-blob), not a mosaic of equally good small matches. Not on
# the coarsest level (there it copies whole wrong objects into a photo's hole: astronaut coherence
# 4.3 -> 5.1), nor on the finest (no effect).
_COHERENCE_BIAS = 1.0
_EDGE_BLEND = 2.0  # the final vote averages the hole's pixels this close (px) to its edge
# EM iterations of the final refine over the hole and the blend band (``cuttable``); 1 / 2 / 3 gave
# gravel coherence 11.12 / 10.31 / 9.85, object 5.11 / 4.90 / 4.82 (seeds 0-1 medians)
_BAND_REFINE = 3


def _percentile(values: np.ndarray, q: float) -> float:
    """``np.percentile(values, q)`` (linear interpolation) of a non-empty vector, in float64, by
    ``np.partition``: np.percentile imports numpy.ma (~7 ms of a fill's process start) on first use.
    Equal to np.percentile on float64 input; on float32 within a float32 rounding (numpy computes
    in the input's precision)."""
    a = np.asarray(values, dtype=np.float64).ravel()
    virtual = q / 100.0 * (len(a) - 1)
    lo = int(np.floor(virtual))
    hi = min(lo + 1, len(a) - 1)
    part = np.partition(a, [lo, hi]) if hi != lo else np.partition(a, lo)
    x0, x1 = float(part[lo]), float(part[hi])
    t = virtual - lo
    d = x1 - x0
    return x1 - d * (1.0 - t) if t >= 0.5 else x0 + d * t  # numpy's _lerp


def _box_sum(a: np.ndarray, p: int) -> np.ndarray:
    """Sums of ``a`` over every p x p window, indexed by the window's top-left corner (a bool ``a``:
    exact int32 counts from OpenCV's integral image, ~10x faster than two float64 cumsums)."""
    if a.dtype == bool:
        import cv2

        c = cv2.integral(np.ascontiguousarray(a).view(np.uint8), sdepth=cv2.CV_32S)
        return c[p:, p:] - c[:-p, p:] - c[p:, :-p] + c[:-p, :-p]
    c = np.zeros((a.shape[0] + 1, a.shape[1] + 1), np.float64)
    np.cumsum(np.cumsum(a, axis=0, dtype=np.float64), axis=1, out=c[1:, 1:])
    return c[p:, p:] - c[:-p, p:] - c[p:, :-p] + c[:-p, :-p]


def _halve(img: np.ndarray, hole: np.ndarray, source: np.ndarray):
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
    return np.ascontiguousarray(img2), hole2, source2


class _Level:
    """One pyramid level: image, hole, allowed source corners, target patches, confidences."""

    def __init__(self, img, hole, source, p):
        from scipy.ndimage import distance_transform_edt

        self.img, self.hole, self.source, self.p = img, hole, source, p
        self.valid = np.ascontiguousarray(_box_sum(source, p) >= p * p - 0.5)
        self.n_valid = int(self.valid.sum())
        touches = _box_sum(hole, p) > 0.5
        self.tpos = np.ascontiguousarray(np.argwhere(touches).astype(np.int64))
        self.tmap = np.full(touches.shape, -1, np.int64)
        self.tmap[touches] = np.arange(len(self.tpos))
        depth = distance_transform_edt(hole) if hole.any() else np.zeros(hole.shape)
        self.depth = float(depth.max())
        self.conf = np.ascontiguousarray(np.where(hole, _GAMMA ** -depth, 1.0).astype(np.float32))
        self.mean_conf = (_box_sum(self.conf, p)[touches] / (p * p)).astype(np.float64)


def _check(image, hole, source, patch, levels, iterations):
    arr = np.asarray(image)
    if arr.ndim not in (2, 3) or (arr.ndim == 3 and not 1 <= arr.shape[2] <= 4):
        raise ImageError(f"image must be (H, W) or (H, W, C) with C = 1..4 channels, got shape {arr.shape}")
    if not np.issubdtype(arr.dtype, np.floating):
        raise ImageError(f"image must be float in [0, 1], got {arr.dtype}")
    h, w = arr.shape[:2]
    if isinstance(patch, bool) or not isinstance(patch, (int, np.integer)) or not MIN_PATCH <= patch <= MAX_PATCH:
        raise InvalidParameter(f"parameter 'patch' = {patch!r} must be an integer {MIN_PATCH}..{MAX_PATCH}",
                               name="patch", value=patch)
    patch = int(patch)
    if min(h, w) < patch:
        raise ImageError(f"image is {w}x{h}: smaller than the {patch}x{patch} patch")
    for name, value in (("levels", levels), ("iterations", iterations)):
        if value is not None and (isinstance(value, bool) or not isinstance(value, (int, np.integer))
                                  or not 1 <= value <= 64):
            raise InvalidParameter(f"parameter '{name}' = {value!r} must be an integer 1..64 or None",
                                   name=name, value=value)

    def mask(m, what):
        m = np.asarray(m)
        if m.shape != (h, w):
            got = f"{m.shape[1]}x{m.shape[0]}" if m.ndim == 2 else f"of shape {m.shape}"
            raise ImageError(f"{what} is {got} but the image is {w}x{h}")
        return m.astype(bool)

    hole = mask(hole, "hole mask")
    source = ~hole if source is None else mask(source, "source mask") & ~hole
    return arr, hole, source, patch


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
        Pyramid levels (1 = finest only); default: as many as bring the hole to about one patch
        deep, as long as a level keeps 16 whole source patches and both sides >= 2 patches.
    iterations : int, optional
        EM iterations on every level; default 8 on the coarsest, 4 on intermediate, 2 on the finest
        (1 when ``cuttable`` is given: the refine follows).
    cuttable : bool array (H, W), optional
        Known pixels that may change (the method's blend band): the finished fill, these pixels and
        the hole are then refined together by :func:`refine_patchmatch`, copying only from source
        pixels outside them, so the band becomes a continuation of the copies (and the method runs
        no Poisson blend for this engine).

    Returns
    -------
    float32 array of ``image``'s shape: outside the hole equal to ``image`` bit for bit.

    Raises
    ------
    ImageError
        Wrong image or mask shape, an image smaller than the patch, or a source region without a
        single whole patch.
    InvalidParameter
        ``patch``, ``levels`` or ``iterations`` out of range.
    """
    from .._kernels import fill as kf

    arr, hole, source, p = _check(image, hole, source, patch, levels, iterations)
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

    pyramid = [_Level(img.copy(), hole, source, p)]
    if pyramid[0].n_valid == 0:
        h, w = hole.shape
        raise ImageError(f"the source region holds no whole {p}x{p} patch: leave at least a {p}x{p} square "
                         f"of known pixels to copy from (or use a smaller patch)")
    max_levels = 64 if levels is None else int(levels)
    while len(pyramid) < max_levels:
        top = pyramid[-1]
        if levels is None and top.depth <= p * _COARSEST_DEPTH:
            break
        if min((top.hole.shape[0] + 1) // 2, (top.hole.shape[1] + 1) // 2) < 2 * p:
            break
        nxt = _Level(*_halve(top.img, top.hole, top.source), p)
        if nxt.n_valid < min(_MIN_SOURCES, top.n_valid) or not nxt.hole.any():
            break
        pyramid.append(nxt)

    n = len(pyramid)
    if iterations is not None:
        schedule = [int(iterations)] * n
    else:  # by level, finest first
        finest = _EM_FINEST if cuttable is None else _EM_FINEST_REFINED
        schedule = [finest] + [_EM_MIDDLE] * (n - 2) + ([_EM_COARSEST] if n > 1 else [])
    report = ProgressReporter(progress, "fill", sum(schedule))
    state = np.array([gen.integers(1, 2 ** 62)], np.int64)
    done = 0
    nnf = None
    for li in range(n - 1, -1, -1):
        lv = pyramid[li]
        if li == n - 1:
            depth = _depth_of(lv.hole)
            order = np.argwhere(lv.hole)[np.argsort(depth[lv.hole], kind="stable")].astype(np.int64)
            kf.onion_fill(lv.img, lv.hole, np.ascontiguousarray(order[:, 0]), np.ascontiguousarray(order[:, 1]))
            nnf = _random_nnf(lv, gen)
            sweeps_first = _SWEEPS_COARSEST
        else:
            coarse = pyramid[li + 1]
            _upsample_into(lv.img, lv.hole, coarse.img)
            nnf = _upsample_nnf(lv, coarse, nnf, gen)
            # the first estimate of this level: the coarse matches, doubled, voted (an upsampled
            # image would be blurred; matched against it, the flattest patches win)
            kf.vote(lv.img, lv.hole, lv.tpos, nnf, lv.mean_conf, p)
            sweeps_first = _SWEEPS_FINER
        dist = np.empty(len(lv.tpos), np.float64)
        # intermediate levels favour the neighbours' offset (see _COHERENCE_BIAS)
        bias = _COHERENCE_BIAS if 0 < li < n - 1 else 0.0
        for it in range(schedule[li]):
            if cancel is not None:
                cancel.raise_if_cancelled()
            kf.refresh(lv.img, lv.conf, lv.tpos, nnf, dist, p)
            for s in range(sweeps_first if it == 0 else 1):
                if cancel is not None:
                    cancel.raise_if_cancelled()
                kf.patchmatch_pass(lv.img, lv.conf, lv.valid, lv.tpos, lv.tmap, nnf, dist, p, bool(s % 2), state,
                                    bias)
            dn = dist / (lv.mean_conf * (p * p))
            sigma2 = max(_percentile(dn, 75), 1e-12)
            weight = np.exp(-dn / (2.0 * sigma2))
            kf.vote_offset(lv.img, lv.hole, lv.tmap, nnf, weight, p)
            if li == 0 and it == schedule[li] - 1 and cuttable is None:
                # the hole's outermost pixels: the weighted mean of the matches (their patches lie
                # mostly on known pixels and agree with them), so the edge shows no cut
                edge = np.ascontiguousarray(lv.hole & (_depth_of(lv.hole) <= _EDGE_BLEND))
                kf.vote(lv.img, edge, lv.tpos, nnf, weight, p)
            done += 1
            report.update(done)
    res = pyramid[0].img[..., :nch]
    if out.ndim == 2:
        out[hole] = res[..., 0][hole]
    else:
        out[hole] = res[hole]
    if cuttable is not None:
        region = hole | np.asarray(cuttable, dtype=bool)
        out = refine_band(out, hole, region, source, patch=p, iterations=_BAND_REFINE, rng=gen, cancel=cancel)
    return out


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
    from scipy.ndimage import distance_transform_edt

    return distance_transform_edt(hole)


def _random_nnf(lv: _Level, gen: np.random.Generator) -> np.ndarray:
    vy, vx = np.nonzero(lv.valid)
    pick = gen.integers(0, len(vy), len(lv.tpos))
    return np.ascontiguousarray(np.stack([vy[pick], vx[pick]], axis=1).astype(np.int64))


def _upsample_nnf(lv: _Level, coarse: _Level, cnnf: np.ndarray, gen: np.random.Generator) -> np.ndarray:
    """The coarse matches, doubled, for the finer level's target patches (random where the coarse
    level had no match or the doubled one is not a whole source patch)."""
    ty, tx = lv.tpos[:, 0], lv.tpos[:, 1]
    hc, wc = coarse.tmap.shape
    m = coarse.tmap[np.minimum(ty // 2, hc - 1), np.minimum(tx // 2, wc - 1)]
    hv, wv = lv.valid.shape
    sy = np.clip(2 * cnnf[np.maximum(m, 0), 0] + ty % 2, 0, hv - 1)
    sx = np.clip(2 * cnnf[np.maximum(m, 0), 1] + tx % 2, 0, wv - 1)
    ok = (m >= 0) & lv.valid[sy, sx]
    rnd = _random_nnf(lv, gen)
    sy = np.where(ok, sy, rnd[:, 0])
    sx = np.where(ok, sx, rnd[:, 1])
    return np.ascontiguousarray(np.stack([sy, sx], axis=1).astype(np.int64))


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
    v = ((1 - ay) * ((1 - ax) * coarse[y0, x0] + ax * coarse[y0, x1])
         + ay * ((1 - ax) * coarse[y1, x0] + ax * coarse[y1, x1]))
    img[ys, xs] = v.astype(np.float32)


def warm_up() -> None:
    """Load (or compile) every kernel :func:`fill_patchmatch` uses, on tiny grey and colour inputs."""
    rng = np.random.default_rng(0)
    for shape in ((40, 40), (40, 40, 3)):
        img = rng.random(shape, dtype=np.float32)
        hole = np.zeros((40, 40), bool)
        hole[16:24, 17:25] = True
        fill_patchmatch(img, hole, patch=5, rng=0, levels=2, iterations=1)


# ------------------------------------------------------------------------------------------ refine
# Full-resolution EM from a given fill, in numpy (a fill that uses only this loads no numba: numba's
# import and its kernels' cache loads are 0.4-0.7 s of a whole `weft fill` process on this machine).

_REFINE_ITERATIONS = 3
_REFINE_CANDIDATES = 2  # source patches tried per target along the principal axis at the start
_STEPS_FIRST = (8, 4, 2, 1)  # propagation distances (px) of the first iteration (jump flooding)
_STEPS_LATER = (1,)  # ... and of the later ones (the matches are then mostly settled)
_SEARCH_SHRINK = 4  # random search radii: half the image, then / 4 down to 1
_SIGMA_PERCENTILE = 75  # the vote's weights exp(-d / 2 sigma^2), sigma^2 this percentile of d
_VOTE_STRIDE = 3  # the vote counts the covering patches at every 3rd row and column (and the last):
# 9 of 49 for a 7x7 patch, the same figures on the four benchmark cases (seeds 0-1) at a fifth of the cost


class _Flat:
    """The full-resolution refine's view of an image: target patches (those touching the hole), the
    allowed source corners, and gathering of p x p patches by their top-left corner."""

    def __init__(self, img: np.ndarray, hole: np.ndarray, source: np.ndarray, p: int):
        from numpy.lib.stride_tricks import as_strided

        h, w, c = img.shape
        self.h, self.w, self.c, self.p = h, w, c, p
        # every p x p patch by its top-left corner, as p rows of p * c contiguous values: a view of
        # ``img`` (C-contiguous), so the vote's writes are seen by the next gathers; indexing it
        # copies a patch row by row (7x faster than np.take of a (N, p * p * c) index array, which
        # had to be built for every gather: half of the refine's time)
        s0, s1, s2 = img.strides
        assert img.flags.c_contiguous and s1 == c * s2
        self.windows = as_strided(img, shape=(h - p + 1, w - p + 1, p, p * c), strides=(s0, s1, s0, s2),
                                  writeable=False)
        self.valid = _box_sum(source, p) >= p * p - 0.5
        touches = _box_sum(hole, p) > 0.5
        ty, tx = np.nonzero(touches)
        self.ty, self.tx = ty.astype(np.int64), tx.astype(np.int64)
        self.tmap = np.full(touches.shape, -1, np.int64)
        self.tmap[ty, tx] = np.arange(len(ty))

    def gather(self, ys: np.ndarray, xs: np.ndarray) -> np.ndarray:
        """(N, P * C) float32: the patches whose top-left corners are (``ys``, ``xs``), each its rows
        one after the other, a pixel's channels together."""
        return self.windows[ys, xs].reshape(len(ys), self.p * self.p * self.c)

    def dist(self, targets: np.ndarray, sy: np.ndarray, sx: np.ndarray) -> np.ndarray:
        d = targets - self.gather(sy, sx)
        return np.einsum("nk,nk->n", d, d)


def _try(fl: _Flat, targets, act, sy, sx, dist, cy, cx, ok) -> None:
    """Replace the matches (``sy``, ``sx``, ``dist``) of the target patches ``act`` (whose pixels are
    ``targets``) by the candidates (``cy``, ``cx``, one per entry of ``act``) where they are allowed
    (``ok``, a whole source patch) and closer; in place."""
    hv, wv = fl.valid.shape
    ok = ok & (cy >= 0) & (cy < hv) & (cx >= 0) & (cx < wv)
    i = np.nonzero(ok)[0]
    k = act[i]
    keep = fl.valid[cy[i], cx[i]] & ((cy[i] != sy[k]) | (cx[i] != sx[k]))
    i, k = i[keep], k[keep]
    if len(i) == 0:
        return
    d = fl.dist(targets[i], cy[i], cx[i])
    better = d < dist[k]
    i, k = i[better], k[better]
    sy[k], sx[k], dist[k] = cy[i], cx[i], d[better]


def _principal_candidates(fl: _Flat, img: np.ndarray, gen: np.random.Generator, k: int):
    """For every target patch, the ``k`` source patches nearest to it along the source patches'
    principal axis (a one-dimensional nearest-neighbour guess that finds an exact copy, as a quilted
    block holds, exactly): ``(cy, cx)`` arrays of shape (k, N)."""
    import cv2

    vy, vx = np.nonzero(fl.valid)
    pick = gen.choice(len(vy), size=min(len(vy), 2000), replace=False)
    sample = fl.gather(vy[pick], vx[pick]).astype(np.float64)
    sample -= sample.mean(axis=0)
    v = np.ones(sample.shape[1]) / np.sqrt(sample.shape[1])  # the principal axis by power iteration
    for _ in range(12):  # (numpy's SVD of the sample took 1.4 s on the loaded 2-core machine: BLAS threads)
        v = np.dot(np.dot(sample, v), sample)
        v /= max(float(np.sqrt(np.dot(v, v))), 1e-30)
    axis = v.reshape(fl.p, fl.p, fl.c).astype(np.float32)
    proj = np.zeros(img.shape[:2], np.float32)
    for ch in range(fl.c):  # the projection of every window, by its top-left corner
        proj += cv2.filter2D(np.ascontiguousarray(img[..., ch]), cv2.CV_32F, np.ascontiguousarray(axis[..., ch]),
                             anchor=(0, 0), borderType=cv2.BORDER_CONSTANT)
    src = proj[vy, vx]
    order = _stable_argsort(src)
    pos = np.searchsorted(src[order], proj[fl.ty, fl.tx])
    lo = -(k // 2)
    out_y = np.empty((k, len(pos)), np.int64)
    out_x = np.empty((k, len(pos)), np.int64)
    for c in range(k):
        j = order[np.clip(pos + lo + c, 0, len(order) - 1)]
        out_y[c], out_x[c] = vy[j], vx[j]
    return out_y, out_x


def _stable_argsort(values: np.ndarray) -> np.ndarray:
    """``np.argsort(values, kind="stable")`` of a float32 vector without NaN, 5-7x faster: each value's
    bits as an order-preserving int32 in the high half of an int64 key, its index in the low half,
    so the keys are unique and a plain (unstable) sort orders them as the stable argsort does."""
    bits = (np.asarray(values, dtype=np.float32) + np.float32(0.0)).view(np.int32)  # (-0.0 becomes 0.0)
    ordered = np.where(bits < 0, bits ^ np.int32(0x7FFFFFFF), bits).astype(np.int64)
    keys = (ordered << 32) | np.arange(len(bits), dtype=np.int64)
    keys.sort()
    return keys & np.int64(0xFFFFFFFF)


def _vote_mode(img: np.ndarray, hole: np.ndarray, fl: _Flat, sy, sx, weight) -> np.ndarray:
    """Every pixel of ``hole`` is copied through the offset (match minus target corner) that the
    target patches covering it agree on most (those at every ``_VOTE_STRIDE``-th row and column of
    corners), each counted with its ``weight``. numpy; writes ``img`` in place and returns the
    pixels whose value changed (bool (H, W))."""
    h, w, p = fl.h, fl.w, fl.p
    hy, hx = np.nonzero(hole)
    changed = np.zeros(hole.shape, bool)
    if len(hy) == 0:
        return changed
    hv, wv = fl.tmap.shape
    span = 2 * w + 1
    big = np.int64(np.iinfo(np.int64).max)
    shifts = np.array(sorted(set(range(0, p, _VOTE_STRIDE)) | {p - 1}), np.int64)
    # padded maps of each target corner's offset code and weight: pixel (y, x) is covered by the
    # patch at corner (y - i, x - j), at (y - i + p, x - j + p) in them
    cmap = np.full((hv + p, wv + p), big, np.int64)
    wmap = np.zeros((hv + p, wv + p))
    cmap[p + fl.ty, p + fl.tx] = (sy - fl.ty + h) * span + (sx - fl.tx + w)
    wmap[p + fl.ty, p + fl.tx] = weight
    yy = np.minimum(p + hy[:, None] - shifts[None, :], hv + p - 1)  # (a row beyond the corners: none)
    xx = np.minimum(p + hx[:, None] - shifts[None, :], wv + p - 1)
    idx = (yy[:, :, None] * (wv + p) + xx[:, None, :]).reshape(len(hy), -1)
    inside = ((hy[:, None] - shifts[None, :] < hv)[:, :, None]
              & (hx[:, None] - shifts[None, :] < wv)[:, None, :]).reshape(len(hy), -1)
    codes = np.where(inside, np.take(cmap.ravel(), idx), big)
    ws = np.where(inside, np.take(wmap.ravel(), idx), 0.0)
    order = np.argsort(codes, axis=1, kind="stable")
    cs = np.take_along_axis(codes, order, axis=1)
    wsorted = np.take_along_axis(ws, order, axis=1)
    cw = np.cumsum(wsorted, axis=1)
    start = np.ones(cs.shape, bool)
    start[:, 1:] = cs[:, 1:] != cs[:, :-1]
    end = np.ones(cs.shape, bool)
    end[:, :-1] = start[:, 1:]
    before = np.maximum.accumulate(np.where(start, cw - wsorted, -np.inf), axis=1)  # weight before each run
    total = np.where(end & (cs != big), cw - before, -1.0)  # each run's weight, at its last entry
    bc = cs[np.arange(len(hy)), np.argmax(total, axis=1)]
    has = bc != big
    py, px = hy[has], hx[has]
    new = img[py + bc[has] // span - h, px + bc[has] % span - w]
    changed[py, px] = (new != img[py, px]).any(axis=1)
    img[py, px] = new
    return changed


def refine_band(filled: np.ndarray, hole: np.ndarray, region: np.ndarray, source: np.ndarray, *, patch: int,
                iterations: int, rng=0, progress=None, cancel=None, worst: float = 0.0) -> np.ndarray:
    """:func:`refine_patchmatch` of a finished fill over ``region`` (the hole and the blend band's
    known pixels that may change), copying only from ``source`` pixels outside it, so the band
    becomes a continuation of the copies; over the hole alone, from the whole source, when the band
    took the last whole source patch; ``filled`` as it is when there is none either. What the
    ``quilt`` (colour), ``hybrid`` and ``patchmatch`` engines end with."""
    from .common import whole_patches

    sources = source & ~region
    if not whole_patches(sources, patch).any():
        region, sources = hole, source
        if not whole_patches(sources, patch).any():
            return filled
    return refine_patchmatch(filled, region, sources, filled, patch=patch, iterations=iterations, rng=rng,
                             progress=progress, cancel=cancel, worst=worst)


def refine_patchmatch(
    image: np.ndarray,
    hole: np.ndarray,
    source: np.ndarray | None = None,
    init: np.ndarray | None = None,
    *,
    patch: int = 7,
    iterations: int = _REFINE_ITERATIONS,
    rng: None | int | np.random.Generator = 0,
    progress: Callable[[Progress], None] | None = None,
    cancel: CancelToken | None = None,
    worst: float = 0.0,
) -> np.ndarray:
    """EM / PatchMatch iterations at full resolution, started from a given fill ``init`` (no pyramid).

    1. Every ``patch`` x ``patch`` patch touching the hole gets a match among the patches lying wholly
       in ``source``: first the source patches nearest to it along their principal axis (an exact
       copy, as a quilted block holds, is found exactly), then, on every iteration, PatchMatch
       propagation (the offset of the neighbours 8, 4, 2 and 1 px away on the first iteration --
       jump flooding, vectorised --, 1 px on later ones) and random search around the match at radii
       from half the image down to 1 px; plain SSD over all channels.
    2. Every hole pixel is copied through the offset (match minus patch) the covering patches agree
       on most, each counted with ``exp(-d / 2 sigma^2)`` (sigma^2: the 75th percentile of the
       distances): no averaging, the fill keeps its grain; where two copies meet, the seam moves to
       where the covering patches agree.

    A patch that is an exact copy of its match is not searched again, and a pixel only such patches
    cover keeps its value (any of their offsets gives it). In numpy and OpenCV: a fill that uses
    only this loads no numba.

    Parameters are as for :func:`fill_patchmatch`, plus ``init``: an array of the image's shape whose
    hole pixels are the starting fill (default: the image itself). ``iterations``: EM iterations
    (1..64, default 3). ``worst``: a percentage 0..100 (default 0): every iteration searches only the
    patches that are not exact copies and whose distance is at least this percentile of theirs (the
    hybrid engine searches the worse half: most of the gain at a fraction of the cost, since the
    judge's mean distance is dominated by the worst windows). Returns float32, every pixel outside
    the hole equal to ``image``'s bit for bit.
    """
    if isinstance(worst, bool) or not isinstance(worst, (int, float, np.integer, np.floating)) or not 0 <= worst < 100:
        raise InvalidParameter(f"parameter 'worst' = {worst!r} must be a percentage 0..100 (below 100)",
                               name="worst", value=worst)
    arr, hole, source, p = _check(image, hole, source, patch, None, iterations)
    out = np.array(arr, dtype=np.float32, copy=True)
    if not hole.any():
        return out
    start = arr if init is None else np.asarray(init)
    if start.shape != arr.shape:
        raise ImageError(f"the starting fill has shape {start.shape} but the image {arr.shape}")
    gen = as_rng(rng)
    img = np.array(out if out.ndim == 3 else out[..., None], dtype=np.float32, order="C")
    img[hole] = (start if start.ndim == 3 else start[..., None])[hole]
    fl = _Flat(img, hole, source, p)
    if not fl.valid.any():
        raise ImageError(f"the source region holds no whole {p}x{p} patch: leave at least a {p}x{p} square "
                         f"of known pixels to copy from (or use a smaller patch)")
    n = len(fl.ty)
    hv, wv = fl.valid.shape
    report = ProgressReporter(progress, "fill", iterations)
    cy, cx = _principal_candidates(fl, img, gen, _REFINE_CANDIDATES)
    targets = fl.gather(fl.ty, fl.tx)
    sy, sx = cy[0].copy(), cx[0].copy()
    dist = fl.dist(targets, sy, sx)
    everyone = np.arange(n)
    for c in range(1, len(cy)):
        _try(fl, targets, everyone, sy, sx, dist, cy[c], cx[c], np.ones(n, bool))
    for it in range(iterations):
        if cancel is not None:
            cancel.raise_if_cancelled()
        if it > 0:  # the vote changed pixels: the distances of the patches over them are stale
            stale = np.nonzero(_box_sum(changed, p)[fl.ty, fl.tx] > 0.5)[0]
            dist[stale] = fl.dist(fl.gather(fl.ty[stale], fl.tx[stale]), sy[stale], sx[stale])
        inexact_d = dist[dist > 0.0]
        floor = _percentile(inexact_d, worst) if worst > 0 and len(inexact_d) else 0.0
        act = np.nonzero(dist > 0.0)[0] if floor <= 0.0 else np.nonzero(dist >= floor)[0]
        if len(act) == 0:
            break
        aty, atx = fl.ty[act], fl.tx[act]
        targets = fl.gather(aty, atx)
        for s in _STEPS_FIRST if it == 0 else _STEPS_LATER:
            for dy, dx in ((0, s), (0, -s), (s, 0), (-s, 0)):
                ny, nx = aty + dy, atx + dx
                inside = (ny >= 0) & (ny < hv) & (nx >= 0) & (nx < wv)
                m = np.where(inside, fl.tmap[np.clip(ny, 0, hv - 1), np.clip(nx, 0, wv - 1)], -1)
                mm = np.maximum(m, 0)
                _try(fl, targets, act, sy, sx, dist, sy[mm] - dy, sx[mm] - dx, m >= 0)
        r = max(hv, wv) // 2
        while r >= 1:
            ry = sy[act] + gen.integers(-r, r + 1, len(act))
            rx = sx[act] + gen.integers(-r, r + 1, len(act))
            _try(fl, targets, act, sy, sx, dist, ry, rx, np.ones(len(act), bool))
            r //= _SEARCH_SHRINK
        dn = dist / (p * p)
        sigma2 = max(_percentile(dn, _SIGMA_PERCENTILE), 1e-12)
        inexact = np.zeros((fl.h + p - 1, fl.w + p - 1), bool)  # pixels covered by a patch that is not an exact copy
        inexact[p - 1 + fl.ty[dist > 0.0], p - 1 + fl.tx[dist > 0.0]] = True
        changed = _vote_mode(img, hole & (_box_sum(inexact, p) > 0.5), fl, sy, sx, np.exp(-dn / (2.0 * sigma2)))
        report.update(it + 1)
    if out.ndim == 2:
        out[hole] = img[..., 0][hole]
    else:
        out[hole] = img[hole]
    return out
