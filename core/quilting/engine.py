"""The quilting engine: one pass of block quilting over a canvas.

For every block: the SSD of its template against every source position (the squared-sum term once
per overlap shape with ``cv2.filter2D``, the cross-term as one FFT product with the source spectra
computed once per pass), then the numba kernels of ``weft.core._kernels.quilting``: the choice (one
kernel per selection rule), the overlap error, the cut (``weft.core._kernels.seams``), the paste, the
Poisson band (only with ``poisson``), so that a run compiles only the kernels it uses -- or, for small
syntheses while numba is not loaded yet, the same steps in numpy (``_choose_*_numpy``, ``_place_block_numpy``,
pixel for pixel the same; a test checks it).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..grid import block_grid
from ..jobs import CancelToken, ProgressReporter
from ..seams import accumulated_costs
from . import codes as _K  # the kernel's array codes, without importing numba (a test checks it)

RULES = ("tol", "epsilon", "sampled")


# Below this many blocks a synthesis without Poisson runs the per-block step in numpy when numba
# is not loaded yet: numba's one-time start-up (~0.6 s: import, registries, kernel cache) costs more
# than the numpy step (~0.5 ms a block of 32 with the seam rule's 8 cuts, which run as one stacked
# dynamic program: quilt-mincut-512, 400 blocks, ~0.2 s) there. Both engines give the same pixels.
NUMPY_ENGINE_MAX_BLOCKS = 1024
#: Synthesis never takes a source position within this many pixels of the continuation of a
#: neighbouring block's piece of the sample, across the seam (see ``_forbid_continuations``); -1: off.
AVOID_RADIUS = 4
#: Synthesis adds to every position's cost ``USAGE_WEIGHT`` x a random match's error over the
#: block's overlap x how often the sample pixels under the block were pasted already, relative to
#: the average sample pixel (see ``_penalise_usage``); 0: off.
USAGE_WEIGHT = 0.04
#: The seam rule of min-cut synthesis with rule tol: the ``SEAM_POOL`` x tol lowest-cost positions
#: are cut, and the one whose cut runs through the least error is taken; 0: the plain tol rule.
SEAM_POOL = 4
#: The cross-correlation written at a forbidden position: its SSD becomes ~2e30, so every rule ranks
#: it behind every allowed position (and still picks among them when nothing else is left).
_FORBIDDEN_CROSS = np.float32(-1e30)


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
    avoid: int | None = (
        None  # radius of _forbid_continuations, -1 off; None: AVOID_RADIUS for synthesis, off for transfer
    )
    usage: float | None = None  # weight of _penalise_usage, 0 off; None: USAGE_WEIGHT for synthesis, off for transfer
    seam_pool: int | None = (
        None  # candidates per tol of the seam rule, 0 off; None: SEAM_POOL for synthesis, off for transfer
    )


def _forbid_continuations(
    cross: np.ndarray, ph: int, pw: int, y0: int, x0: int, neighbours: list[tuple[int, int, int, int]], radius: int
) -> None:
    """Forbid the source positions that would continue a neighbouring block's piece of the sample.

    A block whose neighbour (at canvas (ny, nx)) came from source (nsy, nsx) matches that
    neighbour's overlap exactly at ``(nsy + y0 - ny, nsx + x0 - nx)``: the sample continued as it
    is (SSD 0 over that overlap, so the tol 2 rule takes it one time in two, and runs of it are
    verbatim copies of the sample several blocks long). Nearby positions are the same strip to the
    eye, and so is the same band of the sample shifted along the seam: on brick_128 a chain of
    blocks down the first column kept coming from the sample's few columns of long bricks without
    mortar joints (each one matching the joint-free overlap above it best), an 80-pixel strip.
    So, with ``_FORBIDDEN_CROSS`` written into ``cross`` (every rule then ranks those last):

    * the neighbour above (or below, wrapped): every position within ``radius`` columns of the
      continuation's column, at any row -- the block does not come from the same band of columns;
    * the neighbour on the left (or right, wrapped): every position within ``radius`` rows of the
      continuation's row, at any column;
    * a diagonal neighbour (the overlaps' corners): the positions within ``radius`` pixels
      (Chebyshev) of the continuation.

    A verbatim region is thus at most about one block (plus what the cut leaves of it), and no
    strip of the sample runs across several blocks. ``radius`` 0 forbids the exact continuation
    (and its row or column) only.
    """
    for nsy, nsx, ny, nx in neighbours:
        cy, cx = nsy + y0 - ny, nsx + x0 - nx
        ya, yb = max(cy - radius, 0), min(cy + radius + 1, ph)
        xa, xb = max(cx - radius, 0), min(cx + radius + 1, pw)
        if nx == x0:  # above or below: the same source columns, at any row
            ya, yb = 0, ph
        elif ny == y0:  # left or right: the same source rows, at any column
            xa, xb = 0, pw
        if ya < yb and xa < xb:
            cross[ya:yb, xa:xb] = _FORBIDDEN_CROSS


def _penalise_usage(cross: np.ndarray, usage: np.ndarray, ph: int, pw: int, b: int, weight: float) -> None:
    """Add ``weight`` x (how often the sample pixels under a block at each position were pasted,
    relative to the average sample pixel) to every position's cost, through ``cross``.

    ``usage`` (h, w) counts, for every sample pixel, the output pixels copied from it so far (after
    the cut). Without it the tol rule keeps drawing from the parts of the sample that match well
    most often and leaves others out of the output (on brick_128, T1: the top rows and left columns
    of the sample, completeness 0.021); with it the output covers the whole sample. ``weight`` is in
    the units of the cost (the caller scales it by a random match's error over the overlap), and the
    cost is ``sq - 2 cross + const``, so the penalty goes into ``cross`` halved and negated.
    """
    import cv2

    mean = float(usage.mean())
    if mean <= 0.0:
        return
    under = cv2.boxFilter(usage, cv2.CV_32F, (b, b), normalize=False, anchor=(0, 0), borderType=cv2.BORDER_CONSTANT)[
        :ph, :pw
    ]
    cross[:ph, :pw] -= np.float32(0.5 * weight / (b * b * mean)) * under


def _neighbours(
    chosen: np.ndarray, i: int, j: int, ys: list[int], xs: list[int], hc: int, wc: int, tile: bool
) -> list[tuple[int, int, int, int]]:
    """(source y, source x, canvas y, canvas x) of the blocks already placed that overlap block (i, j)."""
    rows, cols = chosen.shape[:2]
    cand = [(i, j - 1, 0, 0), (i - 1, j, 0, 0), (i - 1, j - 1, 0, 0), (i - 1, j + 1, 0, 0)]
    if tile:  # the last column and row overlap the first ones, placed one canvas width/height further
        if j == cols - 1:
            cand += [(i, 0, 0, wc), (i - 1, 0, 0, wc)]
        if i == rows - 1:
            cand += [(0, j, hc, 0), (0, j - 1, hc, 0), (0, j + 1, hc, 0)]
    out = []
    for ni, nj, oy, ox in cand:
        if 0 <= ni < rows and 0 <= nj < cols and chosen[ni, nj, 0] >= 0 and (ni, nj) != (i, j):
            out.append((int(chosen[ni, nj, 0]), int(chosen[ni, nj, 1]), ys[ni] + oy, xs[nj] + ox))
    return out


def _record(sources: np.ndarray, y0: int, x0: int, sy: int, sx: int, b: int, mask: np.ndarray | None) -> None:
    """Write the source coordinates of the pixels a block pasted (all, or where ``mask``) into ``sources``."""
    hc, wc = sources.shape[:2]
    ar = np.arange(b)
    if y0 + b <= hc and x0 + b <= wc:  # inside the canvas: a view, written in place
        iy, ix = slice(y0, y0 + b), slice(x0, x0 + b)
    else:  # a tileable canvas's last blocks wrap around
        iy, ix = np.ix_((y0 + ar) % hc, (x0 + ar) % wc)
    sub = sources[iy, ix]
    new_y = np.broadcast_to((sy + ar)[:, None], (b, b))
    new_x = np.broadcast_to((sx + ar)[None, :], (b, b))
    if mask is None:
        sub[..., 0], sub[..., 1] = new_y, new_x
    else:
        m = mask.astype(bool)
        sub[..., 0][m] = new_y[m]
        sub[..., 1][m] = new_x[m]
    sources[iy, ix] = sub


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
            m[:, b - right :] = True  # an empty slice when right == 0
            m[b - bottom :] = True
            kernel += np.float32(p.w_overlap) * m
        kernel += np.float32(p.w_prev)
        out = np.zeros((self.ph, self.pw), dtype=np.float32)
        if kernel.any():
            out += cv2.filter2D(self.sq_src, cv2.CV_32F, kernel, anchor=(0, 0), borderType=cv2.BORDER_CONSTANT)[
                : self.ph, : self.pw
            ]
        if p.w_corr and self.sq_c is not None:
            box = np.full((b, b), np.float32(p.w_corr), dtype=np.float32)
            out += cv2.filter2D(self.sq_c, cv2.CV_32F, box, anchor=(0, 0), borderType=cv2.BORDER_CONSTANT)[
                : self.ph, : self.pw
            ]
        out = np.ascontiguousarray(out)
        self._cache[key] = out
        return out


def _quilt_pass(
    tex: np.ndarray,
    out_h: int,
    out_w: int,
    p: _Pass,
    rng: np.random.Generator,
    *,
    prev: np.ndarray | None = None,
    corr: tuple[np.ndarray, np.ndarray] | None = None,
    report: ProgressReporter | None = None,
    cancel: CancelToken | None = None,
    channels_out: int = 3,
    record: dict | None = None,
) -> tuple[np.ndarray, int]:
    """One pass of quilting; returns the (out_h, out_w, C) image and the number of blocks.

    With ``record`` (a dict), ``record["sources"]`` is set to the (out_h, out_w, 2) int32 source
    coordinates each output pixel was copied from (-1 where none), for
    ``weft.core.metrics.verbatim_fraction``; a Poisson band's pixels count as copied.
    """
    import cv2

    b = p.block
    th, tw, nc = tex.shape
    ys, tops, bottoms, hc = block_grid(out_h, b, p.overlap, p.tile)
    xs, lefts, rights, wc = block_grid(out_w, b, p.overlap, p.tile)
    rows, cols = len(ys), len(xs)
    canvas = np.zeros((hc, wc, nc), dtype=np.float32)
    filled = np.zeros((hc, wc), dtype=np.uint8)

    def preview():
        img = canvas[:out_h, :out_w]
        return (img[..., 0] if channels_out == 1 else img).copy()

    sources = np.full((hc, wc, 2), -1, dtype=np.int32) if record is not None else None

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
                canvas[y0 : y0 + bh, x0 : x0 + bw] = tex[sy[i, j] : sy[i, j] + bh, sx[i, j] : sx[i, j] + bw]
                if sources is not None:
                    sources[y0 : y0 + bh, x0 : x0 + bw, 0] = (sy[i, j] + np.arange(bh))[:, None]
                    sources[y0 : y0 + bh, x0 : x0 + bw, 1] = (sx[i, j] + np.arange(bw))[None, :]
            if report is not None:
                report.update(i + 1, preview=preview)
        if record is not None:
            record["sources"] = sources[:out_h, :out_w].copy()
        return canvas[:out_h, :out_w], rows * cols

    import sys

    synthesis = prev is None and corr is None
    pool = p.seam_pool if p.seam_pool is not None else (SEAM_POOL if synthesis else 0)
    pool = pool * p.tol if p.mode == "mincut" and p.rule == "tol" and pool > 0 else 0
    use_numpy = (
        p.engine == "numpy"
        or p.engine == "auto"
        and not p.poisson
        and synthesis
        and rows * cols <= NUMPY_ENGINE_MAX_BLOCKS
        and "weft.core._kernels.quilting" not in sys.modules
    )
    if use_numpy:
        place, template, blend = _place_block_numpy, _make_template_numpy, None
        error, cut = _block_error_numpy, _cut_mask_into_numpy
        by_best, by_tol, by_eps, by_sampled = (
            _choose_best_numpy,
            _choose_tol_numpy,
            _choose_epsilon_numpy,
            _choose_sampled_numpy,
        )
        by_seam, best_k, seam_error, seam_cut, block_error = _by_seam_numpy, None, None, None, None
    else:
        from .._kernels import quilting as _k  # numba loads on first use, not with the CLI
        from .._kernels import seams as _seams

        place, template, blend = _k.place_block, _k.make_template, _k.poisson_band
        error, cut = _k.block_error, _seams.cut_mask
        by_seam, best_k, seam_error, seam_cut, block_error = (
            _by_seam,
            _k.best_k,
            _k.seam_error,
            _seams.cut_mask,
            _k.block_error,
        )
        by_best, by_tol, by_eps, by_sampled = _k.choose_best, _k.choose_tol, _k.choose_epsilon, _k.choose_sampled
    # one kernel per rule (a run compiles only the one it uses); all take (cross, sq, const, cost, u, seed)
    if p.rule == "sampled":
        choose = by_sampled
    elif p.rule == "epsilon":
        choose = lambda cross, sq, const, cost, u, seed: by_eps(cross, sq, const, cost, p.epsilon, u)  # noqa: E731
    elif p.tol > 1:
        choose = lambda cross, sq, const, cost, u, seed: by_tol(cross, sq, const, cost, p.tol, u)  # noqa: E731
    else:
        choose = lambda cross, sq, const, cost, u, seed: by_best(cross, sq, const, cost)  # noqa: E731
    src = _Source(tex, corr[0] if corr is not None else None, b)
    prev_c = np.zeros((1, 1, nc), dtype=np.float32)
    corr_t = np.zeros((1, 1), dtype=np.float32)
    if prev is not None:
        prev_c = _pad_to(prev, hc, wc)
    if corr is not None:
        corr_t = _pad_to(corr[1], hc, wc)
    tbuf = np.zeros((nc, src.n_h, src.n_w), dtype=np.float32)
    # Per-block spectra and correlation written into these, not into fresh arrays: freeing a few
    # hundred kB per block made glibc trim and re-fault the heap (9.7 M page faults, 40 % of the time
    # in the kernel, for 1024² from 256² with block 6).
    fwd, part, acc, cross_buf = (np.empty((src.n_h, src.n_w), dtype=np.float32) for _ in range(4))
    cost_buf = np.empty(src.ph * src.pw, dtype=np.float64)
    tcorr = np.zeros((src.n_h, src.n_w), dtype=np.float32)
    us = rng.random((rows, cols))
    seeds = rng.integers(0, 2**63 - 1, size=(rows, cols), dtype=np.int64)
    first = (int(rng.integers(0, src.ph)), int(rng.integers(0, src.pw)))
    avoid = p.avoid if p.avoid is not None else (AVOID_RADIUS if synthesis else -1)
    usage_weight = p.usage if p.usage is not None else (USAGE_WEIGHT if synthesis else 0.0)
    usage = np.zeros((th, tw), dtype=np.float32) if usage_weight > 0 else None
    # a random match's expected squared error per overlap pixel: 2 x the variance, per channel
    random_error = 2.0 * float(tex.astype(np.float64).var()) * nc
    candidates = np.empty(max(pool, 1), dtype=np.int64)
    chosen = np.full((rows, cols, 2), -1, dtype=np.int64)  # each block's source position
    ip = np.zeros(_K.N_IPARAMS, dtype=np.int64)
    ip[_K.P_B] = b
    ip[_K.P_WRAP] = int(p.tile)
    ip[_K.P_MODE] = {"overlap": _K.MODE_OVERLAP, "mincut": _K.MODE_MINCUT}[p.mode]
    ip[_K.P_POISSON] = int(p.poisson)
    ip[_K.P_BAND] = p.band
    # place_block's work buffers: the cut, and the window around the block for the Poisson band
    ws = b + 2 * (p.band + 2 if p.poisson else 0)
    err, mask = np.empty((b, b), dtype=np.float64), np.empty((b, b), dtype=np.uint8)
    mincut = p.mode == "mincut"
    win = np.empty((2, ws), dtype=np.int64)
    label, old = np.empty((ws, ws), dtype=np.int8), np.empty((ws, ws, nc), dtype=np.float32)
    has_static = p.w_prev != 0.0 or (p.w_corr != 0.0 and corr is not None)
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
        fwd_s, part_s = np.empty_like(fwd), np.empty_like(part)
        # two rows of spectra, written alternately: the row being used and the one computed ahead
        row_specs = [np.empty((cols, src.n_h, src.n_w), dtype=np.float32) for _ in range(2)]

        def static_row(i):
            out = []
            specs = row_specs[i % 2]
            for j in range(cols):
                cst = template(
                    prev_c,
                    prev_c,
                    corr_t,
                    ys[i],
                    xs[j],
                    b,
                    0,
                    0,
                    0,
                    0,
                    wrap,
                    0.0,
                    p.w_prev,
                    p.w_corr,
                    src.mean,
                    src.mean_c,
                    tbuf_s,
                    tcorr_s,
                )
                spec = cv2.mulSpectrums(spectrum_c, cv2.dft(tcorr_s, dst=fwd_s), 0, c=specs[j], conjB=True)
                if p.w_prev:
                    for c in range(nc):
                        cv2.mulSpectrums(spectra[c], cv2.dft(tbuf_s[c], dst=fwd_s), 0, c=part_s, conjB=True)
                        spec = np.add(spec, part_s, out=spec)
                out.append((spec, cst))
            return out

        # transfer: the static terms of the next row are computed one row ahead on a second thread
        static_rows = ThreadPoolExecutor(max_workers=1, thread_name_prefix="weft-quilt")
    try:
        ahead = static_rows.submit(static_row, 0) if static_rows is not None else None
        for i in range(rows):
            if cancel is not None:
                cancel.raise_if_cancelled()
            row_static = None
            if ahead is not None:
                row_static = ahead.result()
                ahead = static_rows.submit(static_row, i + 1) if i + 1 < rows else None
            y0, top, bottom = ys[i], tops[i], bottoms[i]
            ip[_K.P_Y0], ip[_K.P_TOP], ip[_K.P_BOTTOM] = y0, top, bottom
            for j in range(cols):
                x0, left, right = xs[j], lefts[j], rights[j]
                ip[_K.P_X0], ip[_K.P_LEFT], ip[_K.P_RIGHT] = x0, left, right
                overlaps = top or left or right or bottom
                if overlaps or row_static is not None:
                    spec, const = (None, 0.0) if row_static is None else row_static[j]
                    if overlaps:
                        const += template(
                            canvas,
                            prev_c,
                            corr_t,
                            y0,
                            x0,
                            b,
                            top,
                            left,
                            right,
                            bottom,
                            wrap,
                            p.w_overlap,
                            0.0,
                            0.0,
                            src.mean,
                            src.mean_c,
                            tbuf,
                            tcorr,
                        )
                        for c in range(nc):
                            cv2.dft(tbuf[c], dst=fwd)
                            if spec is None:
                                spec = cv2.mulSpectrums(spectra[c], fwd, 0, c=acc, conjB=True)
                            else:
                                cv2.mulSpectrums(spectra[c], fwd, 0, c=part, conjB=True)
                                spec = np.add(spec, part, out=acc)
                    cross = cv2.idft(spec, dst=cross_buf, flags=flags)
                    if usage is not None and overlaps:
                        n_overlap = b * b - (b - top - bottom) * (b - left - right)
                        _penalise_usage(cross, usage, src.ph, src.pw, b, usage_weight * random_error * n_overlap)
                    if avoid >= 0:
                        _forbid_continuations(
                            cross, src.ph, src.pw, y0, x0, _neighbours(chosen, i, j, ys, xs, hc, wc, wrap), avoid
                        )
                    sq = src.sq((top, left, right, bottom), p)
                    seam_cut_done = bool(pool and overlaps)
                    if seam_cut_done:  # the winner's cut is left in mask
                        pick = by_seam(
                            cross,
                            sq,
                            float(const),
                            cost_buf,
                            pool,
                            candidates,
                            canvas,
                            filled,
                            tex,
                            ip,
                            err,
                            mask,
                            best_k,
                            block_error,
                            seam_cut,
                            seam_error,
                            src.pw,
                        )
                    else:
                        pick = int(choose(cross, sq, float(const), cost_buf, us[i, j], seeds[i, j]))
                    ip[_K.P_SY], ip[_K.P_SX] = divmod(pick, src.pw)
                else:  # synthesis, first block: a random position
                    ip[_K.P_SY], ip[_K.P_SX] = first
                    seam_cut_done = False
                if mincut and overlaps and not seam_cut_done:
                    error(canvas, filled, tex, ip, err)
                    cut(err, top, left, right, bottom, mask)
                place(canvas, filled, tex, ip, mask, win, label, old)
                chosen[i, j] = ip[_K.P_SY], ip[_K.P_SX]
                if usage is not None:
                    sy, sx = int(ip[_K.P_SY]), int(ip[_K.P_SX])
                    usage[sy : sy + b, sx : sx + b] += mask if mincut and overlaps else np.float32(1.0)
                if sources is not None:
                    _record(
                        sources, y0, x0, int(ip[_K.P_SY]), int(ip[_K.P_SX]), b, mask if mincut and overlaps else None
                    )
                if blend is not None and p.poisson:
                    blend(canvas, old, label, win, p.band)
            if report is not None:
                report.update(i + 1, preview=preview)
    finally:
        if static_rows is not None:
            static_rows.shutdown(wait=True, cancel_futures=True)
    if record is not None:
        record["sources"] = sources[:out_h, :out_w].copy()
    return canvas[:out_h, :out_w], rows * cols


def _by_seam(
    cross,
    sq,
    const,
    cost_buf,
    pool,
    candidates,
    canvas,
    filled,
    tex,
    ip,
    err,
    mask,
    best_k,
    block_error,
    cut,
    seam_error,
    pw,
) -> int:
    """The seam rule: of the ``pool`` lowest-cost positions (the tol rule's candidates), the one
    whose minimum-error cut runs through the least error (``seam_error``; ties: the earlier
    candidate). The overlap SSD ranks a block by its whole overlap, but what shows is the error
    along the cut; on brick_128 (T1) cutting 8 candidates instead of drawing one of the best 2
    lowers coherence (fewer broken mortar joints at the seams). The winner's cut is left in
    ``mask`` (the caller pastes with it)."""
    n = int(best_k(cross, sq, const, cost_buf, pool, candidates))
    best, best_err = int(candidates[0]), np.inf
    best_mask = np.empty_like(mask)
    for c in candidates[:n]:
        ip[_K.P_SY], ip[_K.P_SX] = divmod(int(c), pw)
        block_error(canvas, filled, tex, ip, err)
        cut(err, int(ip[_K.P_TOP]), int(ip[_K.P_LEFT]), int(ip[_K.P_RIGHT]), int(ip[_K.P_BOTTOM]), mask)
        e = float(seam_error(err, mask))
        if e < best_err:
            best, best_err = int(c), e
            best_mask[...] = mask
    mask[...] = best_mask
    return best


# --------------------------------------------------------------------------------------------
# the numpy engine: the kernels' selection rules and place_block (no Poisson band), step for step


def _splitmix_numpy(seed: int, n: int) -> np.ndarray:
    """The kernel's splitmix64 outputs 1..n for ``seed`` (uint64 arithmetic wraps, as in numba)."""
    golden = np.uint64(0x9E3779B97F4A7C15)
    with np.errstate(over="ignore"):
        z = np.uint64(seed) + golden * np.arange(1, n + 1, dtype=np.uint64)
        z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
        z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return z ^ (z >> np.uint64(31))


def _cost_numpy(cross, sq, const):
    ph, pw = sq.shape
    cost = sq.astype(np.float64) - 2.0 * cross[:ph, :pw].astype(np.float64) + const
    return np.maximum(cost, 0.0).ravel()


def _choose_best_numpy(cross, sq, const, cost_buf=None) -> int:
    return int(np.argmin(_cost_numpy(cross, sq, const)))


def _choose_tol_numpy(cross, sq, const, cost_buf, tol: int, u: float) -> int:
    cost = _cost_numpy(cross, sq, const)
    k = min(tol, cost.size)
    kth = np.partition(cost, k - 1)[k - 1]
    order = np.concatenate([np.flatnonzero(cost < kth), np.flatnonzero(cost == kth)])
    return int(order[min(int(u * k), k - 1)])


def _best_k_numpy(cross, sq, const, cost_buf, k: int, out: np.ndarray) -> int:
    cost = _cost_numpy(cross, sq, const)
    k = min(k, cost.size)
    kth = np.partition(cost, k - 1)[k - 1]
    order = np.concatenate([np.flatnonzero(cost < kth), np.flatnonzero(cost == kth)])[:k]
    out[:k] = order
    return k


def _seam_error_numpy(err: np.ndarray, mask: np.ndarray) -> float:
    """The kernel's ``seam_error`` (summed in the same order)."""
    m = mask.astype(bool)
    off = np.zeros_like(m)  # a 4-neighbour inside the block keeps the old pixel
    off[1:] |= ~m[:-1]
    off[:-1] |= ~m[1:]
    off[:, 1:] |= ~m[:, :-1]
    off[:, :-1] |= ~m[:, 1:]
    vals = err[m & off]
    return float(np.cumsum(vals)[-1]) if vals.size else 0.0


def _choose_epsilon_numpy(cross, sq, const, cost_buf, eps: float, u: float) -> int:
    cost = _cost_numpy(cross, sq, const)
    thr = (1.0 + eps) * max(float(cost.min()), 0.0)
    cand = np.flatnonzero(cost <= thr)
    return int(cand[min(int(u * len(cand)), len(cand) - 1)])


def _choose_sampled_numpy(cross, sq, const, cost_buf, u: float, seed: int) -> int:
    cost = _cost_numpy(cross, sq, const)
    n = cost.size
    z = _splitmix_numpy(int(seed), n + 1)
    limit = np.uint64(int(_K.SAMPLE_FRACTION * 18446744073709551615.0))
    idx = np.flatnonzero(z[:n] < limit)
    if idx.size == 0:
        idx = np.array([int(z[n] % np.uint64(n))])
    k = max(1, int(np.ceil(_K.TOP_FRACTION * idx.size)))
    order = np.argsort(cost[idx], kind="stable")
    return int(idx[order[min(int(u * k), k - 1)]])


def _vertical_accs_numpy(strips: list[np.ndarray]) -> list[np.ndarray]:
    """:func:`weft.core.seams.accumulated_costs` of each (K, h, w) stack of ``strips``; stacks of one shape (a
    square block's left and transposed top strips) run as one program."""
    if len(strips) > 1 and all(s.shape == strips[0].shape for s in strips):
        acc = accumulated_costs(np.concatenate(strips))
        k = strips[0].shape[0]
        return [acc[i * k : (i + 1) * k] for i in range(len(strips))]
    return [accumulated_costs(s) for s in strips]


def _trace_scalar(acc: np.ndarray, y_start, x_start) -> np.ndarray:
    """:func:`_trace_numpy` by scalar steps on Python floats: cheaper for a small stack (a single
    cut: ~6 against ~40 us)."""
    k, h, w = acc.shape
    rows_k = acc.tolist()
    out = []
    for i in range(k):
        rows, x, y0 = rows_k[i], int(x_start[i]), int(y_start[i])
        path = [0] * h
        path[y0] = x
        for y in range(y0 + 1, h):
            r = rows[y]
            best, m = x, r[x]
            if x > 0 and r[x - 1] < m:
                m, best = r[x - 1], x - 1
            if x < w - 1 and r[x + 1] < m:
                best = x + 1
            x = best
            path[y] = x
        out.append(path)
    return np.array(out, dtype=np.int64).reshape(k, h)


def _trace_numpy(acc: np.ndarray, y_start, x_start) -> np.ndarray:
    """The kernel's ``_trace_down`` for a stack (K, h, w), each from its own (y_start, x_start);
    the path is 0 above its start.

    Each cell's step into it from the row above (-1, 0 or +1: the kernel's choice, the centre first,
    then the left if strictly less, then the right if strictly less than both) is found for the
    whole stack at once; the walk then takes one gather a row for all K paths (a Python loop of
    scalar steps per path cost twice as much with the seam rule's 24 candidates: 110 against 290 us
    for 24 cuts of 56 x 10; :func:`_trace_scalar` is kept for small stacks, K x h <= 256)."""
    k, h, w = acc.shape
    if k * h <= 256:
        return _trace_scalar(acc, y_start, x_start)
    inf = np.full((k, h, 1), np.inf)
    left = np.concatenate([inf, acc[:, :, :-1]], axis=2)
    right = np.concatenate([acc[:, :, 1:], inf], axis=2)
    go_left = left < acc
    m = np.where(go_left, left, acc)
    step = np.where(right < m, 1, np.where(go_left, -1, 0))
    y_start = np.asarray(y_start, dtype=np.int64)
    before = np.arange(h)[None, :] <= y_start[:, None]  # (K, h): rows a path has not entered yet
    step[before] = 0  # it stays in its start column until its start row
    nxt = (step + np.arange(w)).ravel()  # at [i, y, x]: the column path i at (y - 1, x) moves to in row y
    x = np.asarray(x_start, dtype=np.int64).copy()
    y0 = int(y_start.min())
    path = np.zeros((h, k), dtype=np.int64)
    path[y0] = x
    base = np.arange(k) * (h * w)
    for y in range(y0 + 1, h):
        x = path[y] = nxt[base + y * w + x]
    path = path.T.copy()
    path[np.arange(h)[None, :] < y_start[:, None]] = 0
    return path


def _cut_mask_numpy(err: np.ndarray, top: int, left: int, right: int, bottom: int) -> np.ndarray:
    """The kernel's ``cut_mask`` in numpy (horizontal cuts by transposition), for one error surface
    (h, w) or a stack of them (K, h, w) (the seam rule's candidates, cut together). The dynamic
    programs of all sides run together when their strips have one shape (see
    :func:`_vertical_accs_numpy`)."""
    if err.ndim == 2:
        return _cut_mask_numpy(err[None], top, left, right, bottom)[0]
    k, h, w = err.shape
    mask = np.ones((k, h, w), dtype=bool)
    yy, xx = np.arange(h)[:, None], np.arange(w)[None, :]
    zero = np.zeros(k, dtype=np.int64)
    strips, sides = [], []
    if left > 0:
        strips.append(err[:, :, :left])
        sides.append("left")
    if top > 0:
        strips.append(err[:, :top, :].transpose(0, 2, 1))
        sides.append("top")  # (K, w, top): rows = columns
    if right > 0:
        strips.append(err[:, :, w - right :])
        sides.append("right")
    if bottom > 0:
        strips.append(err[:, h - bottom :, :].transpose(0, 2, 1))
        sides.append("bottom")
    accs = dict(zip(sides, _vertical_accs_numpy(strips), strict=True))
    if left > 0 and top > 0:
        ev, eh = accs["left"], accs["top"]
        corner = ev[:, :top, :left] + eh[:, :left, :top].transpose(0, 2, 1) - err[:, :top, :left]
        r, c = np.divmod(corner.reshape(k, -1).argmin(axis=1), left)
        vpath = _trace_numpy(ev, r, c)
        hpath = _trace_numpy(eh, c, r)
        r3, c3 = r[:, None, None], c[:, None, None]
        a = np.where(yy >= r3, xx >= vpath[:, :, None], xx >= c3)
        b = np.where(xx >= c3, yy >= hpath[:, None, :], yy >= r3)
        mask &= a & b
    elif left > 0:
        ev = accs["left"]
        mask &= xx >= _trace_numpy(ev, zero, ev[:, 0].argmin(axis=1))[:, :, None]
    elif top > 0:
        eh = accs["top"]
        mask &= yy >= _trace_numpy(eh, zero, eh[:, 0].argmin(axis=1))[:, None, :]
    if right > 0:
        ev = accs["right"]
        mask &= xx <= (_trace_numpy(ev, zero, ev[:, 0].argmin(axis=1)) + (w - right))[:, :, None]
    if bottom > 0:
        eh = accs["bottom"]
        mask &= yy <= (_trace_numpy(eh, zero, eh[:, 0].argmin(axis=1)) + (h - bottom))[:, None, :]
    return mask


def _make_template_numpy(
    canvas,
    prev,
    corr_t,
    y0,
    x0,
    b,
    top,
    left,
    right,
    bottom,
    wrap,
    w_overlap,
    w_prev,
    w_corr,
    mean,
    mean_c,
    tbuf,
    tcorr,
):
    """The kernel's ``make_template`` for synthesis (overlap term only), in numpy (same values)."""
    if w_prev or w_corr:
        raise RuntimeError(
            "internal: the numpy engine quilts synthesis only (_quilt_pass never sends it transfer terms)"
        )
    hc, wc, nc = canvas.shape
    iy = (y0 + np.arange(b)) % hc
    ix = (x0 + np.arange(b)) % wc
    m = np.zeros((b, b), dtype=bool)
    m[:top] = m[:, :left] = True
    m[:, b - right :] = True
    m[b - bottom :] = True
    o = canvas[np.ix_(iy, ix)].astype(np.float64) - mean
    v = np.where(m[..., None], w_overlap * o, 0.0)
    tbuf[:, :b, :b] = v.transpose(2, 0, 1)
    terms = (v * o)[m]  # (w o) o in the kernel's loop order: row, column, channel
    return float(np.cumsum(terms.ravel())[-1]) if terms.size else 0.0


def _block_errors_numpy(canvas, filled, tex, ip, positions) -> np.ndarray:
    """The kernel's ``block_error`` in numpy for the block of ``ip`` taken from each source
    position ``(sy, sx)`` of ``positions``: a (K, B, B) stack."""
    hc, wc, nc = canvas.shape
    b = int(ip[_K.P_B])
    y0, x0 = int(ip[_K.P_Y0]), int(ip[_K.P_X0])
    top, left, right, bottom = (int(ip[i]) for i in (_K.P_TOP, _K.P_LEFT, _K.P_RIGHT, _K.P_BOTTOM))
    iy = (y0 + np.arange(b)) % hc
    ix = (x0 + np.arange(b)) % wc
    blocks = np.stack([tex[sy : sy + b, sx : sx + b] for sy, sx in positions])
    d = canvas[np.ix_(iy, ix)][None] - blocks
    e = (d * d).astype(np.float64).sum(axis=3)
    strips = np.zeros((b, b), dtype=bool)
    strips[:top] = strips[:, :left] = True
    strips[:, b - right :] = True
    strips[b - bottom :] = True
    e[:, ~(strips & (filled[np.ix_(iy, ix)] != 0))] = 0.0
    return e


def _block_error_numpy(canvas, filled, tex, ip, err: np.ndarray) -> None:
    """The kernel's ``block_error`` in numpy, into ``err``."""
    err[...] = _block_errors_numpy(canvas, filled, tex, ip, [(int(ip[_K.P_SY]), int(ip[_K.P_SX]))])[0]


def _seam_errors_numpy(err: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """:func:`_seam_error_numpy` of a stack (K, h, w) at once (the same sums: the cumulative sum
    in row-major order with zeros between the terms adds the same terms in the same order)."""
    m = mask.astype(bool)
    off = np.zeros_like(m)
    off[:, 1:] |= ~m[:, :-1]
    off[:, :-1] |= ~m[:, 1:]
    off[:, :, 1:] |= ~m[:, :, :-1]
    off[:, :, :-1] |= ~m[:, :, 1:]
    vals = np.where(m & off, err, 0.0).reshape(len(err), -1)
    return np.cumsum(vals, axis=1)[:, -1]


def _by_seam_numpy(
    cross, sq, const, cost_buf, pool, candidates, canvas, filled, tex, ip, err, mask, *kernels_and_pw
) -> int:
    """:func:`_by_seam` in numpy, the candidates' cuts computed together (same choice, the
    winner's cut left in ``mask``)."""
    pw = kernels_and_pw[-1]
    n = _best_k_numpy(cross, sq, const, cost_buf, pool, candidates)
    cands = [int(c) for c in candidates[:n]]
    errs = _block_errors_numpy(canvas, filled, tex, ip, [divmod(c, pw) for c in cands])
    masks = _cut_mask_numpy(errs, *(int(ip[i]) for i in (_K.P_TOP, _K.P_LEFT, _K.P_RIGHT, _K.P_BOTTOM)))
    best = int(np.argmin(_seam_errors_numpy(errs, masks)))
    mask[...] = masks[best]
    return cands[best]


def _cut_mask_into_numpy(err, top, left, right, bottom, mask) -> None:
    """The kernel's ``cut_mask`` signature: the cut of ``err`` written into ``mask``."""
    mask[...] = _cut_mask_numpy(err, int(top), int(left), int(right), int(bottom))


def _place_block_numpy(canvas, filled, tex, ip, mask, *work):
    """The kernel's ``place_block`` (no Poisson band), in numpy (same pixels): in min-cut mode a
    block with overlaps pastes where ``mask`` (the caller's cut) is 1.

    The other arguments are the kernel's work buffers (the Poisson band's), unused here.
    """
    hc, wc, nc = canvas.shape
    b = int(ip[_K.P_B])
    y0, x0 = int(ip[_K.P_Y0]), int(ip[_K.P_X0])
    top, left, right, bottom = (int(ip[i]) for i in (_K.P_TOP, _K.P_LEFT, _K.P_RIGHT, _K.P_BOTTOM))
    sy, sx = int(ip[_K.P_SY]), int(ip[_K.P_SX])
    if y0 + b <= hc and x0 + b <= wc:  # the block lies inside the canvas: views
        iy, ix = slice(y0, y0 + b), slice(x0, x0 + b)
    else:  # a tileable canvas's last blocks wrap around
        iy, ix = np.ix_((y0 + np.arange(b)) % hc, (x0 + np.arange(b)) % wc)
    block = tex[sy : sy + b, sx : sx + b]
    if ip[_K.P_MODE] == _K.MODE_MINCUT and (top or left or right or bottom):
        m = mask.astype(bool)
        canvas[iy, ix] = np.where(m[..., None], block, canvas[iy, ix])
        f = filled[iy, ix]
        f[m] = 1
        filled[iy, ix] = f
    else:
        canvas[iy, ix] = block
        filled[iy, ix] = 1


def _pad_to(img: np.ndarray, h: int, w: int) -> np.ndarray:
    """``img`` grown to (h, w) by repeating its last row/column (the canvas may exceed the output)."""
    ph, pw = h - img.shape[0], w - img.shape[1]
    if ph == 0 and pw == 0:
        return np.ascontiguousarray(img, dtype=np.float32)
    pad = [(0, ph), (0, pw)] + [(0, 0)] * (img.ndim - 2)
    return np.ascontiguousarray(np.pad(img, pad, mode="edge"), dtype=np.float32)
