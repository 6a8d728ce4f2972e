"""Image quilting (Efros & Freeman 2001): texture synthesis and transfer by stitching blocks.

Implements everything the two write-ups in ``papers/`` describe (Ngo's "Texture Synthesis and
Transfer" and the "Image Quilting ... Poisson Blending" write-up):

* :func:`synthesize` -- a larger texture from a sample, in three modes (E&F §2, Fig. 2):
  ``random`` blocks tiled side by side; ``overlap`` blocks overlapping their left and top
  neighbours, each chosen by the SSD over the overlap against *every* source position; ``mincut``
  as ``overlap`` plus the minimum-error boundary cut (:mod:`core.seams`). Three rules pick among the
  positions: the ``tol`` best at random (Ngo), all within ``(1 + epsilon)`` times the best (E&F
  §2.1), or the best 10% of a random 10% (the Poisson write-up). Options: ``poisson`` blends a band
  around every seam by a Poisson solve (the Poisson write-up); ``tile`` makes the output wrap.
* :func:`transfer` -- the texture re-rendered to follow a target (E&F §3): the cost is
  ``alpha * overlap SSD + (1 - alpha) * correspondence SSD`` over blurred luminance (or raw
  luminance, or user-given maps), the first block the best correspondence, tol = 1; with
  ``iterations`` N > 1 the block and overlap shrink by a third per pass, alpha follows
  ``alpha_i = alpha + (0.9 - alpha)(i - 1)/(N - 1)`` (the papers' ``0.8 (i-1)/(N-1) + 0.1`` for the
  default alpha 0.1) and the cost adds ``alpha_i`` times the SSD to the previous pass's result.

How a block is chosen (the speed of it): the SSD of the block's template (the pixels already in
place, the target's correspondence map, the previous pass) against every source position is
``sum w F² - 2 sum w G F + sum w G²``. The first sum depends only on the template's weights and is
computed once per overlap shape (``cv2.filter2D`` of the squared source); the cross-correlation
is one FFT product with source spectra computed once per pass (``cv2.dft``); the per-block work
-- choosing, the dynamic-programming cut, pasting and the Poisson band -- is one call of a numba
kernel (``core._kernels.quilting``). Source and templates are centred on the source's mean so
the float32 FFT loses little to cancellation.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Mapping

import numpy as np

from .errors import ImageError, InvalidParameter
from .image import luminance, validate_image
from .jobs import CancelToken, Progress, ProgressReporter
from .params import Params, as_rng, out_of_range, param
from .registry import InputSpec, Method, Result

__all__ = ["QuiltParams", "synthesize", "transfer", "transfer_schedule", "METHOD"]

MODES = ("random", "overlap", "mincut")
RULES = ("tol", "epsilon", "sampled")
CORRESPONDENCES = ("blur", "luminance")

# Defaults that depend on what is being made (see QuiltParams).
SYNTH_BLOCK = 32
TRANSFER_BLOCK = 9  # Ngo: single-pass transfer 9 / 3
ITERATIVE_BLOCK = 31  # Ngo: iterative transfer starts at 31 / 21 ...
MIN_BLOCK, MIN_OVERLAP = 9, 3  # ... and goes down to 9 / 3
SYNTH_TOL = 2
CORR_SIGMA = 2.0  # Gaussian blur (pixels) of the luminance correspondence maps ("blur")


class _K:
    """Indices and codes of the kernel's parameter arrays (the same as ``core._kernels.quilting``'s,
    repeated here so that the numpy engine runs without importing numba; a test checks they agree)."""

    P_Y0, P_X0, P_B, P_TOP, P_LEFT, P_RIGHT, P_BOTTOM, P_WRAP = 0, 1, 2, 3, 4, 5, 6, 7
    P_MODE, P_RULE, P_TOL, P_SEED, P_POISSON, P_BAND, P_FIX_Y, P_FIX_X = 8, 9, 10, 11, 12, 13, 14, 15
    N_IPARAMS = 16
    F_CONST, F_EPS, F_U = 0, 1, 2
    N_FPARAMS = 3
    MODE_RANDOM, MODE_OVERLAP, MODE_MINCUT = 0, 1, 2
    RULE_TOL, RULE_EPSILON, RULE_SAMPLED = 0, 1, 2
    SAMPLE_FRACTION = TOP_FRACTION = 0.1


# Below this many blocks a synthesis without Poisson runs the per-block step in numpy when numba
# is not loaded yet: numba's one-time start-up (~0.6 s: import, registries, kernel cache) costs more
# than the numpy step (~0.3 ms a block) there. Both engines give the same pixels.
NUMPY_ENGINE_MAX_BLOCKS = 1024
STATIC_AHEAD = True  # transfer: static terms one row ahead on a second thread


@dataclass(frozen=True)
class QuiltParams(Params):
    """Parameters of image quilting (Efros & Freeman §2 synthesis, §3 transfer).

    ``mode`` defaults to mincut, the paper's full method. ``None`` means "derived from what is
    made": ``block`` 32 for synthesis, 9 for one transfer pass, 31 for iterative transfer;
    ``overlap`` a sixth of the block rounded up for synthesis (E&F §2.1), a third for one transfer
    pass (Ngo's 9 / 3) and two thirds for iterative transfer (Ngo's 31 / 21); ``tol`` 2 for
    synthesis and 1 for transfer.
    """

    mode: str = param("mincut", choices=MODES,
                      help="random: blocks side by side; overlap: blocks matched on their overlap; "
                           "mincut: plus the least-error cut")
    block: int = param(None, kind="int", lo=2, hi=1024, optional=True, symbol="B",
                       help="side of the square blocks in pixels (default 32; transfer 9, iterative 31)")
    overlap: int = param(None, kind="int", lo=1, hi=1023, optional=True,
                         help="overlap between neighbouring blocks in pixels, smaller than block "
                              "(default block/6 rounded up; transfer block/3, iterative 2*block/3)")
    size: tuple = param(
        None, kind="size", lo=1, hi=16384, optional=True,
        help="output size WIDTHxHEIGHT; default twice the texture's size (transfer: the target's)",
    )
    tol: int = param(None, kind="int", lo=1, hi=100000, optional=True,
                     help="rule tol: pick at random among the tol best positions (default 2; transfer 1)")
    rule: str = param("tol", choices=RULES,
                      help="how a position is picked: tol best; epsilon: within (1+epsilon) x the best; "
                           "sampled: best 10% of a random 10%")
    epsilon: float = param(0.1, lo=0.0, hi=10.0, symbol="ε", step=0.01,
                           help="rule epsilon: candidates within (1+epsilon) times the least error")
    tile: bool = param(False, help="make the output tileable: it wraps seamlessly left-right and top-bottom")
    poisson: bool = param(False, help="Poisson-blend a band around every seam (modes overlap, mincut)")
    band: int = param(4, lo=1, hi=5, help="width in pixels of the Poisson band around each seam")
    iterations: int = param(1, lo=1, hi=10, symbol="N",
                            help="transfer passes; block and overlap shrink by a third per pass")
    alpha: float = param(0.1, lo=0.0, hi=1.0, symbol="α", step=0.05,
                         help="transfer: weight of the overlap error against the correspondence error "
                              "(first pass; later passes go linearly to 0.9)")
    correspondence: str = param("blur", choices=CORRESPONDENCES,
                                help="transfer correspondence map: blurred luminance or raw luminance "
                                     "(ignored when --source-map and --target-map are given)")
    remap: bool = param(True, help="transfer: give the target's correspondence map the texture's mean and "
                                   "deviation first, so dark and bright areas do not repeat the texture's extremes")

    def check(self) -> None:
        if self.block is not None and self.overlap is not None and self.overlap >= self.block:
            raise out_of_range("overlap", self.overlap, 1, self.block - 1,
                               f"must be smaller than block = {self.block}")
        if self.poisson and self.mode == "random":
            raise InvalidParameter("parameter 'poisson' = true needs mode overlap or mincut "
                                   "(random blocks do not overlap, so there is no seam to blend)",
                                   name="poisson", value=True)


# --------------------------------------------------------------------------------------------
# settings of one pass


@dataclass(frozen=True)
class _Pass:
    mode: str
    block: int
    overlap: int
    rule: str
    tol: int
    epsilon: float
    tile: bool
    poisson: bool
    band: int
    w_overlap: float = 1.0
    w_prev: float = 0.0
    w_corr: float = 0.0
    engine: str = "auto"  # "auto", "numba" or "numpy" (tests compare the two)


def _round_half_up(x: float) -> int:
    return int(math.floor(x + 0.5))


def transfer_schedule(iterations: int, *, block: int = ITERATIVE_BLOCK, overlap: int | None = None,
                      alpha: float = 0.1) -> list[tuple[int, int, float]]:
    """Block, overlap and alpha of every pass of iterative texture transfer.

    Parameters
    ----------
    iterations : int
        N >= 1 passes.
    block : int, default 31
        First pass's block side (Ngo's 31).
    overlap : int, optional
        First pass's overlap; default two thirds of the block rounded (21 for 31), Ngo's 31 / 21.
    alpha : float, default 0.1
        First pass's alpha (0..1).

    Returns
    -------
    list of (block, overlap, alpha), one per pass.

    Notes
    -----
    E&F §3: "the block size was reduced by a third each iteration", and
    ``alpha_i = 0.8 (i - 1)/(N - 1) + 0.1``. Here ``b_i = max(b_min, round(2/3 b_{i-1}))`` and
    ``o_i = max(o_min, round(2/3 o_{i-1}))``, rounding halves up, with the floors of Ngo's finest
    scale, ``b_min = min(9, block)`` and ``o_min = min(3, overlap)``, and ``o_i < b_i``. The default
    31 / 21 gives 31/21, 21/14, 14/9, 9/6, 9/4 for N = 5. Alpha runs linearly from the given
    ``alpha`` to 0.9, ``alpha_i = alpha + (0.9 - alpha)(i - 1)/(N - 1)``, which is the papers'
    schedule for the default 0.1; one pass uses ``alpha`` itself.
    """
    if overlap is None:
        overlap = max(1, min(block - 1, _round_half_up(2 * block / 3)))
    b_min, o_min = min(MIN_BLOCK, block), min(MIN_OVERLAP, overlap)
    out = []
    b, o = block, overlap
    for i in range(iterations):
        if i > 0:
            b = max(b_min, _round_half_up(b * 2 / 3))
            o = max(o_min, _round_half_up(o * 2 / 3))
        o = min(o, b - 1)
        a = alpha if iterations == 1 else alpha + (0.9 - alpha) * i / (iterations - 1)
        out.append((b, o, float(a)))
    return out


def _grid(n: int, block: int, overlap: int, tile: bool) -> tuple[list[int], list[int], list[int], int]:
    """Block starts along one axis, the overlaps before/after each block, and the canvas length.

    Without ``tile`` the blocks step by ``block - overlap`` and the canvas is cropped to ``n``
    afterwards. With ``tile`` the canvas is exactly ``n`` and wraps: ``k = ceil(n / step)`` blocks
    start at ``round(j n / k)``, so their overlaps are ``overlap`` or a pixel more, and the last
    block overlaps the first one by its ``after`` width.
    """
    step = block - overlap
    if tile:
        k = -(-n // step)
        starts = [(j * n + k // 2) // k for j in range(k)]
        before = [0] + [starts[j - 1] + block - starts[j] for j in range(1, k)]
        after = [0] * (k - 1) + [starts[-1] + block - n]
        return starts, before, after, n
    k = 1 if n <= block else -(-(n - overlap) // step)
    starts = [j * step for j in range(k)]
    before = [0] + [overlap] * (k - 1)
    return starts, before, [0] * k, max(block, starts[-1] + block)


# --------------------------------------------------------------------------------------------
# the engine: one pass of quilting over a canvas


class _Source:
    """The source texture prepared for one block size: centred, spectra, squared sums."""

    def __init__(self, tex: np.ndarray, corr_src: np.ndarray | None, block: int):
        import cv2

        self.tex = tex  # (h, w, C) float32
        h, w, nc = tex.shape
        self.block = block
        self.ph, self.pw = h - block + 1, w - block + 1
        self.n_h, self.n_w = cv2.getOptimalDFTSize(h), cv2.getOptimalDFTSize(w)
        self.mean = float(tex.mean())
        centred = tex - np.float32(self.mean)
        self.spectra = [cv2.dft(self._pad(centred[..., c])) for c in range(nc)]
        self.sq_src = (centred.astype(np.float64) ** 2).sum(axis=2).astype(np.float32)
        if corr_src is not None:
            self.mean_c = float(corr_src.mean())
            cc = (corr_src - np.float32(self.mean_c)).astype(np.float32)
            self.spectrum_c = cv2.dft(self._pad(cc))
            self.sq_c = cc * cc
        else:
            self.mean_c = 0.0
            self.spectrum_c = None
            self.sq_c = None
        self._cache: dict = {}

    def _pad(self, img: np.ndarray) -> np.ndarray:
        out = np.zeros((self.n_h, self.n_w), dtype=np.float32)
        out[: img.shape[0], : img.shape[1]] = img
        return out

    def sq(self, key: tuple[int, int, int, int], p: _Pass) -> np.ndarray:
        """``sum_x w(x) |F(p + x)|²`` for every position p, for this overlap shape and weights."""
        cached = self._cache.get(key)
        if cached is not None:
            return cached
        import cv2

        b = self.block
        top, left, right, bottom = key
        kernel = np.zeros((b, b), dtype=np.float32)
        if p.w_overlap:
            m = np.zeros((b, b), dtype=bool)
            m[:top] = True
            m[:, :left] = True
            m[:, b - right:] = True  # an empty slice when right == 0
            m[b - bottom:] = True
            kernel += np.float32(p.w_overlap) * m
        kernel += np.float32(p.w_prev)
        out = np.zeros((self.ph, self.pw), dtype=np.float32)
        if kernel.any():
            out += cv2.filter2D(self.sq_src, cv2.CV_32F, kernel, anchor=(0, 0),
                                borderType=cv2.BORDER_CONSTANT)[: self.ph, : self.pw]
        if p.w_corr and self.sq_c is not None:
            box = np.full((b, b), np.float32(p.w_corr), dtype=np.float32)
            out += cv2.filter2D(self.sq_c, cv2.CV_32F, box, anchor=(0, 0),
                                borderType=cv2.BORDER_CONSTANT)[: self.ph, : self.pw]
        out = np.ascontiguousarray(out)
        self._cache[key] = out
        return out


def _quilt_pass(tex: np.ndarray, out_h: int, out_w: int, p: _Pass, rng: np.random.Generator, *,
                prev: np.ndarray | None = None, corr: tuple[np.ndarray, np.ndarray] | None = None,
                report: ProgressReporter | None = None, cancel: CancelToken | None = None,
                channels_out: int = 3) -> tuple[np.ndarray, int]:
    """One pass of quilting; returns the (out_h, out_w, C) image and the number of blocks."""
    import cv2

    b = p.block
    th, tw, nc = tex.shape
    ys, tops, bottoms, hc = _grid(out_h, b, p.overlap, p.tile)
    xs, lefts, rights, wc = _grid(out_w, b, p.overlap, p.tile)
    rows, cols = len(ys), len(xs)
    canvas = np.zeros((hc, wc, nc), dtype=np.float32)
    filled = np.zeros((hc, wc), dtype=np.uint8)

    def preview():
        img = canvas[:out_h, :out_w]
        return (img[..., 0] if channels_out == 1 else img).copy()

    if p.mode == "random":
        # One draw of all positions up front: the picture depends on the seed only.
        sy = rng.integers(0, th - b + 1, size=(rows, cols))
        sx = rng.integers(0, tw - b + 1, size=(rows, cols))
        for i in range(rows):
            if cancel is not None:
                cancel.raise_if_cancelled()
            y0 = ys[i]
            bh = min(b, hc - y0)
            for j in range(cols):
                x0 = xs[j]
                bw = min(b, wc - x0)
                canvas[y0:y0 + bh, x0:x0 + bw] = tex[sy[i, j]:sy[i, j] + bh, sx[i, j]:sx[i, j] + bw]
            if report is not None:
                report.update(i + 1, preview=preview)
        return canvas[:out_h, :out_w], rows * cols

    import sys

    use_numpy = (p.engine == "numpy" or p.engine == "auto" and not p.poisson and prev is None and corr is None
                 and rows * cols <= NUMPY_ENGINE_MAX_BLOCKS and "core._kernels.quilting" not in sys.modules)
    if use_numpy:
        _k = _K
        place, template = _place_block_numpy, _make_template_numpy
    else:
        from ._kernels import quilting as _k  # numba loads on first use, not with the CLI

        place, template = _k.place_block, _k.make_template
    src = _Source(tex, corr[0] if corr is not None else None, b)
    prev_c = np.zeros((1, 1, nc), dtype=np.float32)
    corr_t = np.zeros((1, 1), dtype=np.float32)
    if prev is not None:
        prev_c = _pad_to(prev, hc, wc)
    if corr is not None:
        corr_t = _pad_to(corr[1], hc, wc)
    tbuf = np.zeros((nc, src.n_h, src.n_w), dtype=np.float32)
    tcorr = np.zeros((src.n_h, src.n_w), dtype=np.float32)
    us = rng.random((rows, cols))
    seeds = rng.integers(0, 2**63 - 1, size=(rows, cols), dtype=np.int64)
    first = (int(rng.integers(0, src.ph)), int(rng.integers(0, src.pw)))
    ip = np.zeros(_k.N_IPARAMS, dtype=np.int64)
    fp = np.zeros(_k.N_FPARAMS, dtype=np.float64)
    ip[_k.P_B] = b
    ip[_k.P_WRAP] = int(p.tile)
    ip[_k.P_MODE] = {"overlap": _k.MODE_OVERLAP, "mincut": _k.MODE_MINCUT}[p.mode]
    ip[_k.P_RULE] = RULES.index(p.rule)
    ip[_k.P_TOL] = p.tol
    ip[_k.P_POISSON] = int(p.poisson)
    ip[_k.P_BAND] = p.band
    fp[_k.F_EPS] = p.epsilon
    has_static = p.w_prev != 0.0 or (p.w_corr != 0.0 and corr is not None)
    dummy_cross = np.zeros((1, 1), dtype=np.float32)
    dummy_sq = np.zeros((1, 1), dtype=np.float32)
    flags = cv2.DFT_REAL_OUTPUT | cv2.DFT_SCALE
    spectra, spectrum_c = src.spectra, src.spectrum_c
    wrap = bool(p.tile)
    static_rows = None
    if has_static:
        # The previous-pass and correspondence terms do not depend on the blocks placed in this pass:
        # their spectra are computed one block row ahead on a second thread (cv2 and the numba
        # kernels release the GIL), while this thread adds the overlap term block by block.
        from concurrent.futures import ThreadPoolExecutor

        tbuf_s = np.zeros_like(tbuf)
        tcorr_s = np.zeros_like(tcorr)

        def static_row(i):
            out = []
            for j in range(cols):
                cst = template(prev_c, prev_c, corr_t, ys[i], xs[j], b, 0, 0, 0, 0, wrap,
                               0.0, p.w_prev, p.w_corr, src.mean, src.mean_c, tbuf_s, tcorr_s)
                spec = cv2.mulSpectrums(spectrum_c, cv2.dft(tcorr_s), 0, conjB=True)
                if p.w_prev:
                    for c in range(nc):
                        spec += cv2.mulSpectrums(spectra[c], cv2.dft(tbuf_s[c]), 0, conjB=True)
                out.append((spec, cst))
            return out

        if STATIC_AHEAD:
            static_rows = ThreadPoolExecutor(max_workers=1, thread_name_prefix="weft-quilt")
    try:
        ahead = static_rows.submit(static_row, 0) if static_rows is not None else None
        for i in range(rows):
            if cancel is not None:
                cancel.raise_if_cancelled()
            row_static = static_row(i) if has_static and static_rows is None else None
            if ahead is not None:
                row_static = ahead.result()
                ahead = static_rows.submit(static_row, i + 1) if i + 1 < rows else None
            y0, top, bottom = ys[i], tops[i], bottoms[i]
            ip[_k.P_Y0], ip[_k.P_TOP], ip[_k.P_BOTTOM] = y0, top, bottom
            for j in range(cols):
                x0, left, right = xs[j], lefts[j], rights[j]
                ip[_k.P_X0], ip[_k.P_LEFT], ip[_k.P_RIGHT] = x0, left, right
                ip[_k.P_SEED] = seeds[i, j]
                fp[_k.F_U] = us[i, j]
                overlaps = top or left or right or bottom
                if overlaps or row_static is not None:
                    ip[_k.P_FIX_Y] = ip[_k.P_FIX_X] = -1
                    spec, const = (None, 0.0) if row_static is None else row_static[j]
                    if overlaps:
                        const += template(canvas, prev_c, corr_t, y0, x0, b, top, left, right, bottom, wrap,
                                          p.w_overlap, 0.0, 0.0, src.mean, src.mean_c, tbuf, tcorr)
                        for c in range(nc):
                            part = cv2.mulSpectrums(spectra[c], cv2.dft(tbuf[c]), 0, conjB=True)
                            spec = part if spec is None else spec + part
                    fp[_k.F_CONST] = const
                    cross = cv2.idft(spec, flags=flags)
                    sq = src.sq((top, left, right, bottom), p)
                else:  # synthesis, first block: a random position
                    ip[_k.P_FIX_Y], ip[_k.P_FIX_X] = first
                    cross, sq = dummy_cross, dummy_sq
                place(canvas, filled, tex, cross, sq, ip, fp)
            if report is not None:
                report.update(i + 1, preview=preview)
    finally:
        if static_rows is not None:
            static_rows.shutdown(wait=True, cancel_futures=True)
    return canvas[:out_h, :out_w], rows * cols


# --------------------------------------------------------------------------------------------
# the numpy engine: the kernel's place_block (without the Poisson band), step for step


def _splitmix_numpy(seed: int, n: int) -> np.ndarray:
    """The kernel's splitmix64 outputs 1..n for ``seed`` (uint64 arithmetic wraps, as in numba)."""
    golden = np.uint64(0x9E3779B97F4A7C15)
    with np.errstate(over="ignore"):
        z = np.uint64(seed) + golden * np.arange(1, n + 1, dtype=np.uint64)
        z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
        z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return z ^ (z >> np.uint64(31))


def _select_numpy(cost: np.ndarray, rule: int, tol: int, eps: float, u: float, seed: int) -> int:
    n = cost.size
    if rule == _K.RULE_TOL:
        if tol <= 1:
            return int(np.argmin(cost))
        k = min(tol, n)
        kth = np.partition(cost, k - 1)[k - 1]
        order = np.concatenate([np.flatnonzero(cost < kth), np.flatnonzero(cost == kth)])
        return int(order[min(int(u * k), k - 1)])
    if rule == _K.RULE_EPSILON:
        thr = (1.0 + eps) * max(float(cost.min()), 0.0)
        cand = np.flatnonzero(cost <= thr)
        return int(cand[min(int(u * len(cand)), len(cand) - 1)])
    z = _splitmix_numpy(seed, n + 1)
    limit = np.uint64(int(_K.SAMPLE_FRACTION * 18446744073709551615.0))
    idx = np.flatnonzero(z[:n] < limit)
    if idx.size == 0:
        idx = np.array([int(z[n] % np.uint64(n))])
    k = max(1, int(np.ceil(_K.TOP_FRACTION * idx.size)))
    order = np.argsort(cost[idx], kind="stable")
    return int(idx[order[min(int(u * k), k - 1)]])


def _vertical_acc_numpy(err: np.ndarray) -> np.ndarray:
    h, w = err.shape
    acc = np.empty((h, w))
    acc[h - 1] = err[h - 1]
    pad = np.full(w + 2, np.inf)
    for y in range(h - 2, -1, -1):
        pad[1:-1] = acc[y + 1]
        acc[y] = err[y] + np.minimum(np.minimum(pad[1:-1], pad[:-2]), pad[2:])
    return acc


def _trace_numpy(acc: np.ndarray, y_start: int, x_start: int) -> np.ndarray:
    h, w = acc.shape
    path = np.empty(h, dtype=np.int64)
    x = x_start
    path[y_start] = x
    for y in range(y_start + 1, h):
        best, m = x, acc[y, x]
        if x > 0 and acc[y, x - 1] < m:
            m, best = acc[y, x - 1], x - 1
        if x < w - 1 and acc[y, x + 1] < m:
            best = x + 1
        x = best
        path[y] = x
    return path


def _cut_mask_numpy(err: np.ndarray, top: int, left: int, right: int, bottom: int) -> np.ndarray:
    """The kernel's ``cut_mask`` in numpy (horizontal cuts by transposition)."""
    h, w = err.shape
    mask = np.ones((h, w), dtype=bool)
    yy, xx = np.mgrid[0:h, 0:w]
    if left > 0 and top > 0:
        ev = _vertical_acc_numpy(err[:, :left])
        eh = _vertical_acc_numpy(err[:top, :].T)  # (w, top): rows = columns from the right
        corner = ev[:top, :left] + eh[:left, :top].T - err[:top, :left]
        r, c = divmod(int(np.argmin(corner)), left)
        vpath = np.zeros(h, dtype=np.int64)
        vpath[r:] = _trace_numpy(ev, r, c)[r:]
        hpath = np.zeros(w, dtype=np.int64)
        hpath[c:] = _trace_numpy(eh, c, r)[c:]
        a = np.where(yy >= r, xx >= vpath[:, None], xx >= c)
        b = np.where(xx >= c, yy >= hpath[None, :], yy >= r)
        mask &= a & b
    elif left > 0:
        ev = _vertical_acc_numpy(err[:, :left])
        vpath = _trace_numpy(ev, 0, int(np.argmin(ev[0])))
        mask &= xx >= vpath[:, None]
    elif top > 0:
        eh = _vertical_acc_numpy(err[:top, :].T)
        hpath = _trace_numpy(eh, 0, int(np.argmin(eh[0])))
        mask &= yy >= hpath[None, :]
    if right > 0:
        ev = _vertical_acc_numpy(err[:, w - right:])
        vpath = _trace_numpy(ev, 0, int(np.argmin(ev[0]))) + (w - right)
        mask &= xx <= vpath[:, None]
    if bottom > 0:
        eh = _vertical_acc_numpy(err[h - bottom:, :].T)
        hpath = _trace_numpy(eh, 0, int(np.argmin(eh[0]))) + (h - bottom)
        mask &= yy <= hpath[None, :]
    return mask


def _make_template_numpy(canvas, prev, corr_t, y0, x0, b, top, left, right, bottom, wrap,
                         w_overlap, w_prev, w_corr, mean, mean_c, tbuf, tcorr):
    """The kernel's ``make_template`` for synthesis (overlap term only), in numpy (same values)."""
    if w_prev or w_corr:
        raise NotImplementedError("the numpy engine quilts synthesis only")
    hc, wc, nc = canvas.shape
    iy = (y0 + np.arange(b)) % hc
    ix = (x0 + np.arange(b)) % wc
    m = np.zeros((b, b), dtype=bool)
    m[:top] = m[:, :left] = True
    m[:, b - right:] = True
    m[b - bottom:] = True
    o = canvas[np.ix_(iy, ix)].astype(np.float64) - mean
    v = np.where(m[..., None], w_overlap * o, 0.0)
    tbuf[:, :b, :b] = v.transpose(2, 0, 1)
    terms = (v * o)[m]  # (w o) o in the kernel's loop order: row, column, channel
    return float(np.cumsum(terms.ravel())[-1]) if terms.size else 0.0


def _place_block_numpy(canvas, filled, tex, cross, sq, ip, fp):
    """``core._kernels.quilting.place_block`` without the Poisson band, in numpy (same pixels)."""
    hc, wc, nc = canvas.shape
    b = int(ip[_K.P_B])
    y0, x0 = int(ip[_K.P_Y0]), int(ip[_K.P_X0])
    top, left, right, bottom = (int(ip[i]) for i in (_K.P_TOP, _K.P_LEFT, _K.P_RIGHT, _K.P_BOTTOM))
    ph, pw = tex.shape[0] - b + 1, tex.shape[1] - b + 1
    if ip[_K.P_FIX_Y] >= 0:
        sy, sx = int(ip[_K.P_FIX_Y]), int(ip[_K.P_FIX_X])
    else:
        cost = sq[:ph, :pw].astype(np.float64) - 2.0 * cross[:ph, :pw].astype(np.float64) + fp[_K.F_CONST]
        cost = np.maximum(cost, 0.0).ravel()
        k = _select_numpy(cost, int(ip[_K.P_RULE]), int(ip[_K.P_TOL]), float(fp[_K.F_EPS]), float(fp[_K.F_U]),
                          int(ip[_K.P_SEED]))
        sy, sx = divmod(k, pw)
    iy = (y0 + np.arange(b)) % hc
    ix = (x0 + np.arange(b)) % wc
    block = tex[sy:sy + b, sx:sx + b]
    if ip[_K.P_MODE] == _K.MODE_MINCUT and (top or left or right or bottom):
        old = canvas[np.ix_(iy, ix)]
        d = old - block
        err = (d * d).astype(np.float64).sum(axis=2)
        strips = np.zeros((b, b), dtype=bool)
        strips[:top] = strips[:, :left] = True
        strips[:, b - right:] = True
        strips[b - bottom:] = True
        err[~(strips & (filled[np.ix_(iy, ix)] != 0))] = 0.0
        mask = _cut_mask_numpy(err, top, left, right, bottom)
        merged = np.where(mask[..., None], block, old)
        canvas[np.ix_(iy, ix)] = merged
        f = filled[np.ix_(iy, ix)]
        f[mask] = 1
        filled[np.ix_(iy, ix)] = f
    else:
        canvas[np.ix_(iy, ix)] = block
        filled[np.ix_(iy, ix)] = 1
    return sy, sx


def _pad_to(img: np.ndarray, h: int, w: int) -> np.ndarray:
    """``img`` grown to (h, w) by repeating its last row/column (the canvas may exceed the output)."""
    ph, pw = h - img.shape[0], w - img.shape[1]
    if ph == 0 and pw == 0:
        return np.ascontiguousarray(img, dtype=np.float32)
    pad = [(0, ph), (0, pw)] + [(0, 0)] * (img.ndim - 2)
    return np.ascontiguousarray(np.pad(img, pad, mode="edge"), dtype=np.float32)


# --------------------------------------------------------------------------------------------
# checks shared by synthesis and transfer


def _check_texture(texture) -> np.ndarray:
    tex = validate_image(texture, "texture")
    return tex if tex.ndim == 3 else tex[..., None]


def _check_block_fits(block: int, tex: np.ndarray) -> None:
    h, w = tex.shape[:2]
    if block > min(h, w):
        raise out_of_range("block", block, 2, min(h, w), f"must fit in the texture, {w}x{h}")


def _check_overlap(block: int, overlap: int) -> None:
    if overlap >= block:
        raise out_of_range("overlap", overlap, 1, block - 1, f"must be smaller than block = {block}")


def _check_tile_size(block: int, w: int, h: int) -> None:
    if min(w, h) < block:
        raise InvalidParameter(
            f"parameter 'size' = {w}x{h} is too small for a tileable output with block = {block} "
            f"(each side must be at least the block)", name="size", value=(w, h))


def _finish(img: np.ndarray, channels: int) -> np.ndarray:
    img = np.ascontiguousarray(img, dtype=np.float32)
    return img[..., 0].copy() if channels == 1 else img


# --------------------------------------------------------------------------------------------
# synthesis


def synthesize(
    texture: np.ndarray,
    *,
    size: tuple[int, int] | None = None,
    block: int = SYNTH_BLOCK,
    overlap: int | None = None,
    mode: str = "mincut",
    tol: int = SYNTH_TOL,
    rule: str = "tol",
    epsilon: float = 0.1,
    tile: bool = False,
    poisson: bool = False,
    band: int = 4,
    rng: None | int | np.random.Generator = None,
    progress: Callable[[Progress], None] | None = None,
    cancel: CancelToken | None = None,
) -> np.ndarray:
    """Synthesize a texture of ``size`` from the sample ``texture`` by quilting blocks (E&F §2).

    Parameters
    ----------
    texture : float32 array (H, W) or (H, W, 3) in [0, 1]
        The sample texture.
    size : (width, height), optional
        Output size in pixels (1..16384 per side). Default: twice the texture's size.
    block : int, default 32
        Block side B in pixels, 2..min(H, W) of the texture.
    overlap : int, optional
        Overlap between neighbouring blocks, 1..B-1; default ceil(B / 6) (E&F §2.1: "the size of
        the overlap was 1/6 of the size of the block"). Unused in ``random`` mode.
    mode : {"random", "overlap", "mincut"}, default "mincut"
        ``random``: blocks from uniformly random positions, side by side, no overlap (E&F Fig. 2a).
        ``overlap``: blocks step by B - overlap; each is chosen by the SSD between its overlap with
        the pixels already in place (left and top strips) and the same strips at *every* position
        of the texture, and pasted over them (Fig. 2b). ``mincut``: as ``overlap``, then pasted only
        on its side of the minimum-error boundary cut through the overlap (Fig. 2c, :mod:`core.seams`).
    tol : int, default 2
        Rule ``tol``: pick uniformly among the ``tol`` lowest-SSD positions (Ngo's ``tol``; 1 =
        always the best). 2 keeps seams nearly invisible yet uses the whole sample (brick 128² ->
        512², block 32/6, mincut: coherence 0.024, completeness 0.011; a pure best match repeats).
    rule : {"tol", "epsilon", "sampled"}, default "tol"
        ``epsilon``: pick uniformly among positions with SSD <= (1 + epsilon) x the least (E&F
        §2.1, "within 0.1 times the error of the best"). ``sampled``: draw a random 10% of the
        positions, pick uniformly among the best 10% of those (the Poisson write-up, step 1).
    epsilon : float, default 0.1
        Tolerance of rule ``epsilon``, 0..10. With an exact match (SSD 0) only exact matches qualify.
    tile : bool, default False
        Make the output tileable: blocks are laid on a torus (the last column and row of blocks
        overlap the first ones and are matched, cut and blended against them too), so the image
        wraps seamlessly. Needs each side >= B; block overlaps are then ``overlap`` or one more
        pixel, so that the blocks fit the size exactly.
    poisson : bool, default False
        After each paste, solve a Poisson equation on a band of ``band`` pixels around the seam
        with the existing pixels as the source of gradients (the Poisson write-up; modes
        ``overlap`` and ``mincut``). See :func:`core.blending.poisson_blend`.
    band : int, default 4
        Width of the Poisson band, 1..5 pixels: ceil(band/2) on the existing side of the seam,
        floor(band/2) on the new block's side, limited to pixels that existed before the paste.
    rng : None, int or numpy Generator
        The same seed gives the same pixels.
    progress, cancel
        Progress callback (called once per block row, with the partial image as preview) and
        cancel token (checked once per block row).

    Returns
    -------
    float32 array of shape (height, width[, 3]), same channel count as ``texture``.

    Notes
    -----
    Ambiguities resolved: the first block of ``overlap``/``mincut`` is a random position; the
    overlap region of ``overlap`` mode is overwritten by the new block (Ngo: "will overwrite a
    portion of T_prev"); the output is quilted on a canvas of whole blocks and cropped; SSDs are
    summed over colour channels.
    """
    params = QuiltParams(mode=mode, block=block, overlap=overlap, size=size, tol=tol, rule=rule,
                         epsilon=epsilon, tile=tile, poisson=poisson, band=band)
    tex = _check_texture(texture)
    h, w = tex.shape[:2]
    b = params.block
    _check_block_fits(b, tex)
    ov = params.overlap if params.overlap is not None else max(1, -(-b // 6))
    if params.mode != "random":
        _check_overlap(b, ov)
    else:
        ov = min(ov, b - 1)
    out_w, out_h = params.size if params.size is not None else (2 * w, 2 * h)
    if params.tile and params.mode != "random":
        _check_tile_size(b, out_w, out_h)
    p = _Pass(params.mode, b, ov, params.rule, params.tol, params.epsilon, params.tile,
              params.poisson, params.band)
    rng = as_rng(rng)
    rows = len(_grid(out_h, b, ov if params.mode != "random" else 0, params.tile and params.mode != "random")[0])
    report = ProgressReporter(progress, "quilting", rows)
    if params.mode == "random":
        p = _Pass("random", b, 0, "tol", 1, 0.0, False, False, 1)
    img, _ = _quilt_pass(tex, out_h, out_w, p, rng, report=report, cancel=cancel, channels_out=tex.shape[2])
    return _finish(img, tex.shape[2])


# --------------------------------------------------------------------------------------------
# transfer


def _remap(cs: np.ndarray, ct: np.ndarray) -> np.ndarray:
    """Hertzmann et al. (2001) luminance remapping: ``ct`` linearly mapped to ``cs``'s mean and deviation."""
    sd_t = float(ct.std())
    scale = float(cs.std()) / sd_t if sd_t > 1e-6 else 1.0
    return np.ascontiguousarray((ct - ct.mean()) * scale + cs.mean(), dtype=np.float32)


def _correspondence_maps(tex, target, kind, source_map, target_map):
    import cv2

    if (source_map is None) != (target_map is None):
        missing = "target_map" if target_map is None else "source_map"
        raise InvalidParameter(f"parameter '{missing}' is required when the other correspondence map is given",
                               name=missing)
    if source_map is not None:
        sm = validate_image(source_map, "source map")
        tm = validate_image(target_map, "target map")
        for m, ref, what, of in ((sm, tex, "source map", "texture"), (tm, target, "target map", "target")):
            if m.shape[:2] != ref.shape[:2]:
                raise ImageError(f"{what} is {m.shape[1]}x{m.shape[0]} but the {of} is "
                                 f"{ref.shape[1]}x{ref.shape[0]}; they must be the same size")
        cs = luminance(sm) if sm.ndim == 3 else sm
        ct = luminance(tm) if tm.ndim == 3 else tm
        return np.ascontiguousarray(cs, np.float32), np.ascontiguousarray(ct, np.float32)
    cs = luminance(tex[..., 0] if tex.shape[2] == 1 else tex)
    ct = luminance(target)
    if kind == "blur":
        cs = cv2.GaussianBlur(cs, (0, 0), CORR_SIGMA)
        ct = cv2.GaussianBlur(ct, (0, 0), CORR_SIGMA)
    return np.ascontiguousarray(cs, np.float32), np.ascontiguousarray(ct, np.float32)


def transfer(
    texture: np.ndarray,
    target: np.ndarray,
    *,
    block: int | None = None,
    overlap: int | None = None,
    alpha: float = 0.1,
    iterations: int = 1,
    mode: str = "mincut",
    correspondence: str = "blur",
    source_map: np.ndarray | None = None,
    target_map: np.ndarray | None = None,
    tol: int = 1,
    rule: str = "tol",
    epsilon: float = 0.1,
    remap: bool = True,
    tile: bool = False,
    poisson: bool = False,
    band: int = 4,
    return_all: bool = False,
    rng: None | int | np.random.Generator = None,
    progress: Callable[[Progress], None] | None = None,
    cancel: CancelToken | None = None,
) -> np.ndarray | list[np.ndarray]:
    """Texture transfer: re-render ``target`` with blocks of ``texture`` (E&F §3).

    Parameters
    ----------
    texture : float32 array (h, w) or (h, w, 3) in [0, 1]
        The texture the result is made of.
    target : float32 array (H, W) or (H, W, 3)
        The picture the result follows; the result has its size and the texture's channels.
    block : int, optional
        Block side, 2..min(h, w). Default 9 for one pass (Ngo), 31 for ``iterations`` > 1 (Ngo's
        31 / 21 down to 9 / 3). With iterations it is the first pass's block.
    overlap : int, optional
        Overlap, 1..block-1. Default round(block / 3) for one pass (9 -> 3), round(2 block / 3)
        for iterative transfer (31 -> 21).
    alpha : float, default 0.1
        Weight of the overlap error, 0..1; the correspondence error gets 1 - alpha (E&F §3).
    iterations : int, default 1
        Passes N, 1..10; see :func:`transfer_schedule` for the block, overlap and alpha of each.
        Passes after the first add ``alpha_i`` times the SSD between the candidate and the previous
        pass's result over the whole block, as the Poisson write-up's
        ``error = alpha (overlap + previous) + (1 - alpha) correspondence``.
    mode : {"overlap", "mincut"}, default "mincut"
        As in :func:`synthesize`; the cut uses the overlap error only (the correspondence decides
        which block, the seam goes where the two blocks agree).
    correspondence : {"blur", "luminance"}, default "blur"
        Correspondence maps of texture and target: their Rec. 601 luminance blurred by a Gaussian
        of sigma 2 pixels (E&F: "blurred luminance") or unblurred.
    source_map, target_map : arrays, optional
        User-given correspondence maps (both or neither), the texture's and the target's size;
        colour maps are reduced to luminance. They replace ``correspondence``.
    remap : bool, default True
        Map the target's correspondence map linearly to the texture map's mean and standard
        deviation first (Hertzmann et al. 2001's luminance remapping; not in E&F). Without it a
        target brighter or darker than most of the texture is rendered from the texture's few
        extreme spots, repeated (camera in gravel: the sky is one bright stone tiled; coherence
        0.30 against 0.21 with remapping, fidelity 0.99 against 0.98). ``False`` is the papers'
        behaviour.
    tol, rule, epsilon
        Position rule as in :func:`synthesize`; transfer takes the best (tol = 1, Ngo), the first
        block being the best correspondence.
    tile, poisson, band
        As in :func:`synthesize` (a tileable transfer wraps the texture seamlessly; the target is
        not periodic, so its picture may not continue across the wrap).
    return_all : bool, default False
        Return the list of every pass's result instead of the last one.
    rng, progress, cancel
        As in :func:`synthesize`; the progress stage is ``"transfer i/N"``, once per block row.

    Returns
    -------
    float32 array (H, W[, 3]) with the texture's channels, or a list of them (``return_all``).
    """
    params = QuiltParams(mode=mode, block=block, overlap=overlap, tol=tol, rule=rule, epsilon=epsilon,
                         tile=tile, poisson=poisson, band=band, iterations=iterations, alpha=alpha,
                         correspondence=correspondence, remap=remap)
    if params.mode == "random":
        raise InvalidParameter("parameter 'mode' = 'random' is not one of overlap, mincut "
                               "(transfer matches blocks on their overlap)", name="mode", value="random")
    tex = _check_texture(texture)
    tgt = validate_image(target, "target")
    H, W = tgt.shape[:2]
    n = params.iterations
    b = params.block if params.block is not None else (TRANSFER_BLOCK if n == 1 else ITERATIVE_BLOCK)
    _check_block_fits(b, tex)
    if params.overlap is not None:
        ov = params.overlap
        _check_overlap(b, ov)
    else:
        ov = max(1, min(b - 1, _round_half_up(b / 3 if n == 1 else 2 * b / 3)))
    if params.tile:
        _check_tile_size(b, W, H)
    cs, ct = _correspondence_maps(tex, tgt, params.correspondence, source_map, target_map)
    if params.remap:
        ct = _remap(cs, ct)
    rng = as_rng(rng)
    results = []
    prev = None
    for i, (bi, oi, ai) in enumerate(transfer_schedule(n, block=b, overlap=ov, alpha=params.alpha)):
        p = _Pass(params.mode, bi, oi, params.rule, params.tol, params.epsilon, params.tile,
                  params.poisson, params.band, w_overlap=ai, w_prev=ai if i > 0 else 0.0, w_corr=1.0 - ai)
        rows = len(_grid(H, bi, oi, params.tile)[0])
        report = ProgressReporter(progress, f"transfer {i + 1}/{n}", rows)
        img, _ = _quilt_pass(tex, H, W, p, rng, prev=prev, corr=(cs, ct), report=report, cancel=cancel,
                             channels_out=tex.shape[2])
        prev = np.ascontiguousarray(img)
        results.append(_finish(img, tex.shape[2]))
    return results if return_all else results[-1]


# --------------------------------------------------------------------------------------------
# the `weft quilt` command


def _blocks(n_h: int, n_w: int, block: int, overlap: int, tile: bool) -> int:
    return len(_grid(n_h, block, overlap, tile)[0]) * len(_grid(n_w, block, overlap, tile)[0])


def _run(inputs: Mapping[str, np.ndarray], params: QuiltParams, *, rng=None, progress=None, cancel=None) -> Result:
    texture = inputs["texture"]
    target = inputs.get("target")
    maps = {k: inputs.get(k) for k in ("source_map", "target_map")}
    if target is None:
        for name in ("source_map", "target_map"):
            if maps[name] is not None:
                raise InvalidParameter(f"input '{name.replace('_', '-')}' needs a target (--target)", name=name)
        if params.iterations > 1:
            raise out_of_range("iterations", params.iterations, 1, 1, "more passes need a target (--target)")
        mode = params.mode
        block = params.block or SYNTH_BLOCK
        image = synthesize(
            texture, size=params.size, block=block, overlap=params.overlap, mode=mode,
            tol=params.tol or SYNTH_TOL, rule=params.rule, epsilon=params.epsilon, tile=params.tile,
            poisson=params.poisson, band=params.band, rng=rng, progress=progress, cancel=cancel,
        )
        h, w = image.shape[:2]
        if mode == "random":
            blocks = -(-h // block) * -(-w // block)
        else:
            ov = params.overlap if params.overlap is not None else max(1, -(-block // 6))
            blocks = _blocks(h, w, block, ov, params.tile)
        return Result(image, {"blocks": blocks})
    if params.size is not None:
        raise InvalidParameter("parameter 'size' cannot be given with a target: the transfer has the target's size",
                               name="size", value=params.size)
    images = transfer(
        texture, target, block=params.block, overlap=params.overlap, alpha=params.alpha,
        iterations=params.iterations, mode=params.mode, correspondence=params.correspondence,
        source_map=maps["source_map"], target_map=maps["target_map"], remap=params.remap,
        tol=params.tol or 1, rule=params.rule,
        epsilon=params.epsilon, tile=params.tile, poisson=params.poisson, band=params.band,
        return_all=True, rng=rng, progress=progress, cancel=cancel,
    )
    image = images[-1]
    return Result(image, {"iterations": len(images)})


def warm_up() -> None:
    """Load (or compile) the numba kernels on tiny inputs, so the first real run is not charged with it.

    For the GUI's background start-up; ``METHOD.warm_up_in_cli`` is False: a small synthesis on the
    command line (the numpy engine, see ``NUMPY_ENGINE_MAX_BLOCKS``) would otherwise pay numba's
    ~0.6 s start-up for nothing. A CLI transfer's reported ``seconds`` therefore include that load.
    """
    rng = np.random.default_rng(0)
    tex = rng.random((12, 12), dtype=np.float32)
    synthesize(tex, size=(16, 16), block=6, overlap=2, mode="mincut", poisson=True, rng=0)
    transfer(tex, tex, block=6, overlap=2, rng=0)


METHOD = Method(
    name="quilt",
    summary="image quilting (Efros & Freeman): synthesize a larger texture from blocks of a sample, "
            "or transfer it onto a target",
    params=QuiltParams,
    inputs=(
        InputSpec("texture", "the sample texture image"),
        InputSpec("target", "transfer: the picture to re-render with the texture", required=False),
        InputSpec("source_map", "transfer: the texture's correspondence map (with --target-map)", required=False),
        InputSpec("target_map", "transfer: the target's correspondence map (with --source-map)", required=False),
    ),
    run=_run,
    warm_up=warm_up,
    warm_up_in_cli=False,
)
