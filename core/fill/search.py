"""The patch-search core every fill engine shares: PatchMatch and EM voting, in numpy.

Barnes et al., "PatchMatch" (SIGGRAPH 2009): nearest-neighbour fields found by propagation and random
search, vectorised here (every target patch at once; propagation by jump flooding instead of a scan
order). Wexler, Shechtman & Irani, "Space-Time Completion of Video" (PAMI 2007): each EM iteration
searches the patches touching the hole (E) and writes each hole pixel from its covering patches'
matches (M). The vote is a weighted *mode* of offsets, not Wexler's weighted mean, so copies keep
their grain and a fill never blurs. :func:`refine_patchmatch` runs this at full resolution from a
given fill; :mod:`weft.core.fill.patchmatch` runs it on every level of a pyramid. numpy and OpenCV
only: a fill loads no numba.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..errors import ImageError, InvalidParameter
from ..jobs import CancelToken, Progress, ProgressReporter
from ..params import as_rng
from .common import percentile, whole_patches

__all__ = ["MIN_PATCH", "MAX_PATCH", "refine_patchmatch", "refine_band"]

MIN_PATCH = 3
MAX_PATCH = 63
REFINE_ITERATIONS = 3
_REFINE_CANDIDATES = 2  # source patches tried per target along the principal axis at the start
STEPS_FIRST = (8, 4, 2, 1)  # propagation distances (px) of the first iteration (jump flooding)
_STEPS_LATER = (1,)  # ... and of the later ones (the matches are then mostly settled)
_SEARCH_SHRINK = 4  # random search radii: half the image, then / 4 down to 1
_SIGMA_PERCENTILE = 75  # the vote's weights exp(-d / 2 sigma^2), sigma^2 this percentile of d
# the vote counts the covering patches at every 3rd row and column (and the last): as good as all of
# them at a fifth of the cost, except in the last vote of a fill (see refine_patchmatch)
VOTE_STRIDE = 3


def box_sum(a: np.ndarray, p: int) -> np.ndarray:
    """Sums of ``a`` over every p x p window, indexed by the window's top-left corner.

    Parameters
    ----------
    a : ndarray, (H, W)
        Values; a bool ``a`` gives exact int32 counts from OpenCV's integral image.
    p : int
        The window side.

    Returns
    -------
    ndarray, (H - p + 1, W - p + 1)
    """
    if a.dtype == bool:
        import cv2

        c = cv2.integral(np.ascontiguousarray(a).view(np.uint8), sdepth=cv2.CV_32S)
        return c[p:, p:] - c[:-p, p:] - c[p:, :-p] + c[:-p, :-p]
    c = np.zeros((a.shape[0] + 1, a.shape[1] + 1), np.float64)
    np.cumsum(np.cumsum(a, axis=0, dtype=np.float64), axis=1, out=c[1:, 1:])
    return c[p:, p:] - c[:-p, p:] - c[p:, :-p] + c[:-p, :-p]


def check_inputs(image, hole, source, patch, levels, iterations):
    """Validate the inputs of a patch-search fill.

    Parameters
    ----------
    image : array_like, (H, W) or (H, W, C) with C = 1..4
        Float in [0, 1].
    hole : array_like, bool (H, W)
        The pixels to fill.
    source : array_like, bool (H, W) or None
        The pixels to copy from (default all outside the hole).
    patch : int
        The patch side, MIN_PATCH..MAX_PATCH, at most the image's shorter side.
    levels, iterations : int or None
        1..64, or None.

    Returns
    -------
    image : ndarray
    hole, source : ndarray, bool (H, W)
        ``source`` never includes the hole.
    patch : int

    Raises
    ------
    ImageError
        A bad shape or type, or masks of another size than the image.
    InvalidParameter
        A bad ``patch``, ``levels`` or ``iterations``.
    """
    arr = np.asarray(image)
    if arr.ndim not in (2, 3) or (arr.ndim == 3 and not 1 <= arr.shape[2] <= 4):
        raise ImageError(f"image must be (H, W) or (H, W, C) with C = 1..4 channels, got shape {arr.shape}")
    if not np.issubdtype(arr.dtype, np.floating):
        raise ImageError(f"image must be float in [0, 1], got {arr.dtype}")
    h, w = arr.shape[:2]
    if isinstance(patch, bool) or not isinstance(patch, (int, np.integer)) or not MIN_PATCH <= patch <= MAX_PATCH:
        raise InvalidParameter(
            f"parameter 'patch' = {patch!r} must be an integer {MIN_PATCH}..{MAX_PATCH}", name="patch", value=patch
        )
    patch = int(patch)
    if min(h, w) < patch:
        raise ImageError(f"image is {w}x{h}: smaller than the {patch}x{patch} patch")
    for name, value in (("levels", levels), ("iterations", iterations)):
        if value is not None and (
            isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not 1 <= value <= 64
        ):
            raise InvalidParameter(
                f"parameter '{name}' = {value!r} must be an integer 1..64 or None", name=name, value=value
            )

    def mask(m, what):
        m = np.asarray(m)
        if m.shape != (h, w):
            got = f"{m.shape[1]}x{m.shape[0]}" if m.ndim == 2 else f"of shape {m.shape}"
            raise ImageError(f"{what} is {got} but the image is {w}x{h}")
        return m.astype(bool)

    hole = mask(hole, "hole mask")
    source = ~hole if source is None else mask(source, "source mask") & ~hole
    return arr, hole, source, patch


class Flat:
    """An image as the patch search sees it: target patches (those touching the hole), the allowed
    source corners, gathering of p x p patches by their top-left corner, and the distance of target
    patches to candidates: the plain SSD, or with ``conf`` (H, W) each target pixel's squared
    difference weighted by its confidence (the pyramid's levels), except on the ``fixed`` channels
    (the guide, known in the hole), weighted 1."""

    def __init__(
        self,
        img: np.ndarray,
        hole: np.ndarray,
        source: np.ndarray,
        p: int,
        conf: np.ndarray | None = None,
        fixed: slice | None = None,
    ):
        from numpy.lib.stride_tricks import as_strided

        h, w, c = img.shape
        self.h, self.w, self.c, self.p = h, w, c, p
        # every p x p patch by its top-left corner, as p rows of p * c contiguous values: a view of
        # ``img`` (C-contiguous), so the vote's writes are seen by the next gathers; indexing it
        # copies a patch row by row (7x faster than np.take of a (N, p * p * c) index array, which
        # had to be built for every gather: half of the refine's time)
        s0, s1, s2 = img.strides
        assert img.flags.c_contiguous and s1 == c * s2
        self.windows = as_strided(
            img, shape=(h - p + 1, w - p + 1, p, p * c), strides=(s0, s1, s0, s2), writeable=False
        )
        self.valid = whole_patches(source, p)
        touches = box_sum(hole, p) > 0.5
        ty, tx = np.nonzero(touches)
        self.ty, self.tx = ty.astype(np.int64), tx.astype(np.int64)
        self.tmap: np.ndarray = np.full(touches.shape, -1, np.int64)
        self.tmap[ty, tx] = np.arange(len(ty))
        self.weights = None  # (N, P * C) float32: the target patches' confidences, a pixel's repeated per channel
        self.mean_conf = None  # (N,) float64: their means over the patch
        if conf is not None:
            cw = as_strided(conf, shape=(h - p + 1, w - p + 1, p, p), strides=conf.strides * 2, writeable=False)
            c_ = cw[self.ty, self.tx].reshape(len(ty), p * p)
            self.weights = np.ascontiguousarray(np.repeat(c_, c, axis=1), dtype=np.float32)
            if fixed is not None:  # channels known in the hole (the guide) count in full there
                self.weights.reshape(len(ty), p * p, c)[:, :, fixed] = 1.0
            self.mean_conf = c_.mean(axis=1, dtype=np.float64)

    def gather(self, ys: np.ndarray, xs: np.ndarray) -> np.ndarray:
        """(N, P * C) float32: the patches whose top-left corners are (``ys``, ``xs``), each its rows
        one after the other, a pixel's channels together."""
        return self.windows[ys, xs].reshape(len(ys), self.p * self.p * self.c)

    def dist(self, targets: np.ndarray, k: np.ndarray, sy: np.ndarray, sx: np.ndarray) -> np.ndarray:
        """The distances of the target patches ``k`` (whose pixels are ``targets``) to the patches at
        (``sy``, ``sx``)."""
        d = self.gather(sy, sx)  # a fresh copy (fancy indexing): worked on in place
        np.subtract(targets, d, out=d)
        if self.weights is None:
            return np.einsum("nk,nk->n", d, d)
        np.multiply(d, d, out=d)  # (a three-operand einsum is 1.6x slower than squaring, then two)
        return np.einsum("nk,nk->n", self.weights[k], d)

    def normalized(self, dist: np.ndarray) -> np.ndarray:
        """Distances per patch pixel (and per unit of confidence), for the vote's weights."""
        p2 = self.p * self.p
        return dist / p2 if self.mean_conf is None else dist / (self.mean_conf * p2)


def _try(fl: Flat, targets, act, sy, sx, dist, cy, cx, ok, bias: float = 0.0) -> None:
    """Replace the matches (``sy``, ``sx``, ``dist``) of the target patches ``act`` (whose pixels are
    ``targets``) by the candidates (``cy``, ``cx``, one per entry of ``act``) where they are allowed
    (``ok``, a whole source patch) and closer (with ``bias``: closer than ``1 + bias`` times the
    current match, the propagation of the pyramid's intermediate levels); in place."""
    hv, wv = fl.valid.shape
    # (an int64 below 0 is above any bound as a uint64: one comparison per axis)
    ok = ok & (cy.view(np.uint64) < hv) & (cx.view(np.uint64) < wv)
    i = np.flatnonzero(ok)
    k = act[i]
    ci, xi = cy[i], cx[i]
    keep = fl.valid[ci, xi] & ((ci != sy[k]) | (xi != sx[k]))
    i, k, ci, xi = i[keep], k[keep], ci[keep], xi[keep]
    if len(i) == 0:
        return
    d = fl.dist(targets[i], k, ci, xi)
    better = d < dist[k] if bias == 0.0 else d < dist[k] * (1.0 + bias)
    k = k[better]
    sy[k], sx[k], dist[k] = ci[better], xi[better], d[better]


def _principal_candidates(fl: Flat, img: np.ndarray, gen: np.random.Generator, k: int):
    """For every target patch, the ``k`` source patches nearest to it along the source patches'
    principal axis (a one-dimensional nearest-neighbour guess that finds an exact copy, as a quilted
    block holds, exactly): ``(cy, cx)`` arrays of shape (k, N)."""
    import cv2

    vy, vx = np.nonzero(fl.valid)
    pick = gen.choice(len(vy), size=min(len(vy), 2000), replace=False)
    sample = fl.gather(vy[pick], vx[pick]).astype(np.float64)
    sample -= sample.mean(axis=0)
    v = np.ones(sample.shape[1]) / np.sqrt(sample.shape[1])  # the principal axis by power iteration
    for _ in range(12):  # (not numpy's SVD, whose BLAS threads made it far slower)
        v = np.dot(np.dot(sample, v), sample)
        v /= max(float(np.sqrt(np.dot(v, v))), 1e-30)
    axis = v.reshape(fl.p, fl.p, fl.c).astype(np.float32)
    proj = np.zeros(img.shape[:2], np.float32)
    for ch in range(fl.c):  # the projection of every window, by its top-left corner
        proj += cv2.filter2D(
            np.ascontiguousarray(img[..., ch]),
            cv2.CV_32F,
            np.ascontiguousarray(axis[..., ch]),
            anchor=(0, 0),
            borderType=cv2.BORDER_CONSTANT,
        )
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


def vote_mode(
    img: np.ndarray, hole: np.ndarray, fl: Flat, sy, sx, weight, stride: int = VOTE_STRIDE, fixed: slice | None = None
) -> np.ndarray:
    """Copy every pixel of ``hole`` through the offset its covering target patches agree on most.

    The covering patches are those at every ``stride``-th row and column of corners, and the last,
    each counted with its ``weight``. Each covering patch is one int64 key: its offset's code in the
    high bits, its weight as an integer (``weight * 2**(bits - 6)``, at least 1: a pixel whose votes all
    weigh nearly nothing takes its most frequent offset) in the low ones; a plain sort of each pixel's
    keys groups equal offsets, and exact integer sums weigh them (the result of a stable argsort of
    the codes and float sums, for less).

    Parameters
    ----------
    img : ndarray, float32 (H, W, C)
        Written in place, but for its ``fixed`` channels.
    hole : ndarray, bool (H, W)
    fl : Flat
        The target patches and their geometry.
    sy, sx : ndarray
        Each target patch's match (top-left corner).
    weight : ndarray
        Each target patch's weight, 0..1.
    stride : int, default VOTE_STRIDE
        Which corners vote.
    fixed : slice, optional
        Channels left as they are (the guide's, the last ones).

    Returns
    -------
    ndarray, bool (H, W)
        The pixels whose value changed.

    References
    ----------
    Wexler, Shechtman & Irani, "Space-time completion of video" (2007), §3 (the vote), with the mode
    of the offsets in place of their mean.
    """
    h, w, p = fl.h, fl.w, fl.p
    hy, hx = np.nonzero(hole)
    changed = np.zeros(hole.shape, bool)
    if len(hy) == 0:
        return changed
    hv, wv = fl.tmap.shape
    span = 2 * w + 1
    none = (2 * h + 1) * span  # the codes are 0 .. none - 1; ``none``: no covering patch
    wbits = 62 - int(none).bit_length()
    shifts = np.array(sorted(set(range(0, p, stride)) | {p - 1}), np.int64)
    # a padded map of each target corner's key: pixel (y, x) is covered by the patch at corner
    # (y - i, x - j), at (y - i + p, x - j + p) in it
    kmap = np.full((hv + p, wv + p), np.int64(none) << wbits, np.int64)
    q = np.maximum(np.rint(np.asarray(weight, np.float64) * float(1 << (wbits - 6))), 1).astype(np.int64)
    kmap[p + fl.ty, p + fl.tx] = (((sy - fl.ty + h) * span + (sx - fl.tx + w)) << wbits) | q
    yy = np.minimum(p + hy[:, None] - shifts[None, :], hv + p - 1)  # (a row beyond the corners: none)
    xx = np.minimum(p + hx[:, None] - shifts[None, :], wv + p - 1)
    idx = (yy[:, :, None] * (wv + p) + xx[:, None, :]).reshape(len(hy), -1)
    inside = (
        (hy[:, None] - shifts[None, :] < hv)[:, :, None] & (hx[:, None] - shifts[None, :] < wv)[:, None, :]
    ).reshape(len(hy), -1)
    keys = np.where(inside, np.take(kmap.ravel(), idx), np.int64(none) << wbits)
    keys.sort(axis=1)
    cs = keys >> wbits
    ws = keys & ((np.int64(1) << wbits) - 1)
    cw = np.cumsum(ws, axis=1)
    start = np.ones(cs.shape, bool)
    start[:, 1:] = cs[:, 1:] != cs[:, :-1]
    end = np.ones(cs.shape, bool)
    end[:, :-1] = start[:, 1:]
    before = np.maximum.accumulate(np.where(start, cw - ws, -1), axis=1)  # weight before each run
    total = np.where(end & (cs != none), cw - before, -1)  # each run's weight, at its last entry
    bc = cs[np.arange(len(hy)), np.argmax(total, axis=1)]
    has = bc != none
    py, px = hy[has], hx[has]
    cols = slice(None) if fixed is None else slice(0, fixed.start)
    new = img[py + bc[has] // span - h, px + bc[has] % span - w, cols]
    changed[py, px] = (new != img[py, px, cols]).any(axis=1)
    img[py, px, cols] = new
    return changed


def refine_band(
    filled: np.ndarray,
    hole: np.ndarray,
    region: np.ndarray,
    source: np.ndarray,
    *,
    patch: int,
    iterations: int,
    rng=0,
    progress=None,
    cancel=None,
    worst: float = 0.0,
    last_vote_stride: int | None = None,
) -> np.ndarray:
    """:func:`refine_patchmatch` of a finished fill over ``region``, copying from ``source`` outside it.

    The band becomes a continuation of the copies. Over the hole alone, from the whole source, when
    the band took the last whole source patch; ``filled`` as it is when there is none either. What the
    ``quilt`` (colour), ``hybrid`` and ``patchmatch`` engines end with.

    Parameters
    ----------
    filled : ndarray, float32 (H, W, C)
        The finished fill.
    hole : ndarray, bool (H, W)
        The hole.
    region : ndarray, bool (H, W)
        The hole and the blend band's known pixels that may change.
    source : ndarray, bool (H, W)
        The pixels to copy from.
    patch, iterations, rng, progress, cancel, worst, last_vote_stride
        As in :func:`refine_patchmatch`.

    Returns
    -------
    ndarray, float32 (H, W, C)
    """
    sources = source & ~region
    if not whole_patches(sources, patch).any():
        region, sources = hole, source
        if not whole_patches(sources, patch).any():
            return filled
    return refine_patchmatch(
        filled,
        region,
        sources,
        filled,
        patch=patch,
        iterations=iterations,
        rng=rng,
        progress=progress,
        cancel=cancel,
        worst=worst,
        last_vote_stride=last_vote_stride,
    )


def refine_patchmatch(
    image: np.ndarray,
    hole: np.ndarray,
    source: np.ndarray | None = None,
    init: np.ndarray | None = None,
    *,
    patch: int = 7,
    iterations: int = REFINE_ITERATIONS,
    rng: None | int | np.random.Generator = 0,
    progress: Callable[[Progress], None] | None = None,
    cancel: CancelToken | None = None,
    worst: float = 0.0,
    last_vote_stride: int | None = None,
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
    cover keeps its value (any of their offsets gives it). In numpy and OpenCV: a fill that uses only
    this loads no numba.

    Parameters
    ----------
    image : ndarray, float (H, W) or (H, W, C) in [0, 1]
        The picture.
    hole : ndarray, bool (H, W)
        The pixels to fill.
    source : ndarray, bool (H, W), optional
        The pixels to copy from (default all outside the hole).
    init : ndarray, optional
        An array of the image's shape whose hole pixels are the starting fill (default: the image).
    patch : int, default 7
        The patch side.
    iterations : int, default REFINE_ITERATIONS
        EM iterations, 1..64.
    rng : None, int or numpy.random.Generator, default 0
        Seed.
    progress : callable, optional
        Receives :class:`weft.core.jobs.Progress`, one unit per iteration.
    cancel : CancelToken, optional
        Checked every iteration.
    worst : float, default 0
        A percentage 0..100: every iteration searches only the patches that are not exact copies and
        whose distance is at least this percentile of theirs (the hybrid engine searches the worse
        half, where most of the gain is).
    last_vote_stride : int, optional
        The last iteration's vote counts the covering patches at every this-th corner row and column
        (default: every ``VOTE_STRIDE``-th, as the others; the ``patchmatch`` engine's final refine
        counts every one).

    Returns
    -------
    ndarray, float32
        Every pixel outside the hole equal to ``image``'s bit for bit.

    Raises
    ------
    ImageError
        Bad shapes (see :func:`check_inputs`), or an ``init`` of another shape.
    InvalidParameter
        A bad ``patch``, ``iterations`` or ``worst``.

    References
    ----------
    Barnes et al., "PatchMatch" (2009); Wexler, Shechtman & Irani, "Space-time completion of video" (2007).
    """
    if isinstance(worst, bool) or not isinstance(worst, (int, float, np.integer, np.floating)) or not 0 <= worst < 100:
        raise InvalidParameter(
            f"parameter 'worst' = {worst!r} must be a percentage 0..100 (below 100)", name="worst", value=worst
        )
    arr, hole, source, p = check_inputs(image, hole, source, patch, None, iterations)
    out = np.array(arr, dtype=np.float32, copy=True)
    if not hole.any():
        return out
    start = arr if init is None else np.asarray(init)
    if start.shape != arr.shape:
        raise ImageError(f"the starting fill has shape {start.shape} but the image {arr.shape}")
    gen = as_rng(rng)
    img = np.array(out if out.ndim == 3 else out[..., None], dtype=np.float32, order="C")
    img[hole] = (start if start.ndim == 3 else start[..., None])[hole]
    fl = Flat(img, hole, source, p)
    if not fl.valid.any():
        raise ImageError(
            f"the source region holds no whole {p}x{p} patch: leave at least a {p}x{p} square "
            f"of known pixels to copy from (or use a smaller patch)"
        )
    n = len(fl.ty)
    report = ProgressReporter(progress, "fill", iterations)
    cy, cx = _principal_candidates(fl, img, gen, _REFINE_CANDIDATES)
    targets = fl.gather(fl.ty, fl.tx)
    sy, sx = cy[0].copy(), cx[0].copy()
    everyone = np.arange(n)
    dist = fl.dist(targets, everyone, sy, sx)
    for c in range(1, len(cy)):
        _try(fl, targets, everyone, sy, sx, dist, cy[c], cx[c], np.ones(n, bool))
    em(
        fl,
        img,
        hole,
        sy,
        sx,
        dist,
        iterations=iterations,
        gen=gen,
        steps_first=STEPS_FIRST,
        shrink=_SEARCH_SHRINK,
        bias=0.0,
        worst=worst,
        cancel=cancel,
        on_iteration=lambda it: report.update(it + 1),
        last_stride=last_vote_stride,
    )
    if out.ndim == 2:
        out[hole] = img[..., 0][hole]
    else:
        out[hole] = img[hole]
    return out


def _search_step(
    fl: Flat,
    act: np.ndarray,
    sy: np.ndarray,
    sx: np.ndarray,
    dist: np.ndarray,
    steps: tuple[int, ...],
    gen: np.random.Generator,
    shrink: int,
    bias: float = 0.0,
) -> None:
    """One PatchMatch pass over the target patches ``act``, in place: each tries its neighbours'
    offsets ``steps`` px away (taken within ``1 + bias`` of its current distance), then random
    candidates around its match at radii from half the image down to 1 px, divided by ``shrink``."""
    hv, wv = fl.valid.shape
    aty, atx = fl.ty[act], fl.tx[act]
    targets = fl.gather(aty, atx)
    for s in steps:
        for dy, dx in ((0, s), (0, -s), (s, 0), (-s, 0)):
            ny, nx = aty + dy, atx + dx
            inside = (ny >= 0) & (ny < hv) & (nx >= 0) & (nx < wv)
            m = np.where(inside, fl.tmap[np.clip(ny, 0, hv - 1), np.clip(nx, 0, wv - 1)], -1)
            mm = np.maximum(m, 0)
            _try(fl, targets, act, sy, sx, dist, sy[mm] - dy, sx[mm] - dx, m >= 0, bias)
    r = max(hv, wv) // 2
    while r >= 1:
        ry = sy[act] + gen.integers(-r, r + 1, len(act))
        rx = sx[act] + gen.integers(-r, r + 1, len(act))
        _try(fl, targets, act, sy, sx, dist, ry, rx, np.ones(len(act), bool))
        r //= shrink


def em(
    fl: Flat,
    img: np.ndarray,
    hole: np.ndarray,
    sy: np.ndarray,
    sx: np.ndarray,
    dist: np.ndarray,
    *,
    iterations: int,
    gen: np.random.Generator,
    steps_first: tuple[int, ...],
    shrink: int,
    bias: float,
    worst: float,
    cancel: CancelToken | None,
    on_iteration: Callable[[int], object],
    last_stride: int | None = None,
    fixed: slice | None = None,
) -> None:
    """EM iterations on ``img``, improving the matches of ``fl``'s target patches and writing the hole, in place.

    Each iteration: (E) the inexact patches (a distance above 0; with ``worst``, at least that
    percentile of their distances) try their neighbours' offsets (``steps_first`` px away on the first
    iteration, then ``_STEPS_LATER``; taken within ``1 + bias`` of the current distance) and random
    candidates around their match (radii from half the image down to 1, divided by ``shrink``); (M)
    every hole pixel covered by an inexact patch is copied through the offset its covering patches
    agree on most (:func:`vote_mode`, weights ``exp(-d / 2 sigma^2)``). A patch that is an exact copy
    of its match is not searched again, and a pixel only such patches cover keeps its value.

    Parameters
    ----------
    fl : Flat
        The patches of ``img``.
    img : ndarray, float32 (H, W, C)
        The array ``fl`` views, written in place.
    hole : ndarray, bool (H, W)
    sy, sx, dist : ndarray
        The target patches' matches and distances, updated in place.
    iterations : int
    gen : numpy.random.Generator
    steps_first : tuple of int
        Propagation steps of the first iteration.
    shrink : int
        Divides the random search's radii.
    bias : float
        A neighbour's offset is taken within ``1 + bias`` of the current distance.
    worst : float
        As in :func:`refine_patchmatch`.
    cancel : CancelToken or None
    on_iteration : callable
        Called with the iteration's index after each.
    last_stride : int, optional
        The last vote's stride.
    fixed : slice, optional
        Channels the votes leave as they are (the guide).

    References
    ----------
    Barnes et al., "PatchMatch" (2009); Wexler, Shechtman & Irani, "Space-time completion of video" (2007).
    """
    p = fl.p
    changed = None
    for it in range(iterations):
        if cancel is not None:
            cancel.raise_if_cancelled()
        if changed is not None:  # the vote changed pixels: the distances of the patches over them are stale
            stale = np.nonzero(box_sum(changed, p)[fl.ty, fl.tx] > 0.5)[0]
            dist[stale] = fl.dist(fl.gather(fl.ty[stale], fl.tx[stale]), stale, sy[stale], sx[stale])
        inexact_d = dist[dist > 0.0]
        floor = percentile(inexact_d, worst) if worst > 0 and len(inexact_d) else 0.0
        act = np.nonzero(dist > 0.0)[0] if floor <= 0.0 else np.nonzero(dist >= floor)[0]
        if len(act) == 0:
            break
        _search_step(fl, act, sy, sx, dist, steps_first if it == 0 else _STEPS_LATER, gen, shrink, bias)
        dn = fl.normalized(dist)
        sigma2 = max(percentile(dn, _SIGMA_PERCENTILE), 1e-12)
        inexact = np.zeros((fl.h + p - 1, fl.w + p - 1), bool)  # pixels covered by a patch that is not an exact copy
        inexact[p - 1 + fl.ty[dist > 0.0], p - 1 + fl.tx[dist > 0.0]] = True
        stride = VOTE_STRIDE if last_stride is None or it < iterations - 1 else last_stride
        changed = vote_mode(
            img, hole & (box_sum(inexact, p) > 0.5), fl, sy, sx, np.exp(-dn / (2.0 * sigma2)), stride, fixed
        )
        on_iteration(it)
