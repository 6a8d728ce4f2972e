"""The quilting engine: one pass of block quilting over a canvas.

For every block: the SSD of its template against every source position (the squared-sum term once
per overlap shape with ``cv2.filter2D``, the cross-term as one FFT product with the source spectra
computed once per pass: :mod:`weft.core.quilting.costs`), then the numba kernels of
``weft.core._kernels.quilting``: the choice (one kernel per selection rule), the overlap error, the
cut (``weft.core._kernels.seams``), the paste, the Poisson band (only with ``poisson``), so that a
run compiles only the kernels it uses -- or, for small syntheses while numba is not loaded yet, the
same steps in numpy (:mod:`weft.core.quilting.numpy_kernels`, pixel for pixel the same; a test
checks it).
"""

from __future__ import annotations

import numpy as np

from ..grid import block_grid
from ..jobs import CancelToken, ProgressReporter
from . import codes as _K  # the kernel's array codes, without importing numba (a test checks it)
from .costs import _forbid_continuations, _neighbours, _penalise_usage, _Source
from .pass_options import _Pass
from .steps import NUMPY_ENGINE_MAX_BLOCKS, _steps, _uses_numpy

__all__ = ["NUMPY_ENGINE_MAX_BLOCKS", "RULES", "_Pass", "_quilt_pass"]

RULES = ("tol", "epsilon", "sampled")


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
    if p.mode == "random":
        canvas = _Canvas(tex.shape[2], out_h, out_w, p, channels_out, record is not None)
        _random_blocks(canvas, tex, p.block, rng, report, cancel)
        return canvas.result(record)
    quilt = _OverlapPass(tex, out_h, out_w, p, rng, prev, corr, channels_out, record is not None)
    quilt.run(report, cancel)
    return quilt.result(record)


class _Canvas:
    """The canvas a pass fills: its block grid, its pixels, which of them are filled and (when
    recorded) the source coordinates each was copied from."""

    def __init__(self, nc: int, out_h: int, out_w: int, p: _Pass, channels_out: int, record: bool):
        b = p.block
        self.out_h, self.out_w, self.channels_out = out_h, out_w, channels_out
        self.ys, self.tops, self.bottoms, self.hc = block_grid(out_h, b, p.overlap, p.tile)
        self.xs, self.lefts, self.rights, self.wc = block_grid(out_w, b, p.overlap, p.tile)
        self.rows, self.cols = len(self.ys), len(self.xs)
        self.canvas = np.zeros((self.hc, self.wc, nc), dtype=np.float32)
        self.filled = np.zeros((self.hc, self.wc), dtype=np.uint8)
        self.sources = np.full((self.hc, self.wc, 2), -1, dtype=np.int32) if record else None

    def preview(self) -> np.ndarray:
        """The output as far as it is built (a copy), in the output's channels."""
        img = self.canvas[: self.out_h, : self.out_w]
        return (img[..., 0] if self.channels_out == 1 else img).copy()

    def result(self, record: dict | None) -> tuple[np.ndarray, int]:
        """The output and the number of blocks; the source coordinates into ``record``."""
        if record is not None and self.sources is not None:
            record["sources"] = self.sources[: self.out_h, : self.out_w].copy()
        return self.canvas[: self.out_h, : self.out_w], self.rows * self.cols


def _random_blocks(
    canvas: _Canvas,
    tex: np.ndarray,
    b: int,
    rng: np.random.Generator,
    report: ProgressReporter | None,
    cancel: CancelToken | None,
) -> None:
    """Mode ``random``: blocks from random source positions, side by side."""
    th, tw = tex.shape[:2]
    rows, cols, ys, xs, hc, wc = canvas.rows, canvas.cols, canvas.ys, canvas.xs, canvas.hc, canvas.wc
    sources = canvas.sources
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
            canvas.canvas[y0 : y0 + bh, x0 : x0 + bw] = tex[sy[i, j] : sy[i, j] + bh, sx[i, j] : sx[i, j] + bw]
            if sources is not None:
                sources[y0 : y0 + bh, x0 : x0 + bw, 0] = (sy[i, j] + np.arange(bh))[:, None]
                sources[y0 : y0 + bh, x0 : x0 + bw, 1] = (sx[i, j] + np.arange(bw))[None, :]
        if report is not None:
            report.update(i + 1, preview=canvas.preview)


class _OverlapPass(_Canvas):
    """One pass of the modes ``overlap`` and ``mincut``: every block chosen by its cost against
    every source position, then cut (mincut) and pasted, row by row."""

    def __init__(
        self,
        tex: np.ndarray,
        out_h: int,
        out_w: int,
        p: _Pass,
        rng: np.random.Generator,
        prev: np.ndarray | None,
        corr: tuple[np.ndarray, np.ndarray] | None,
        channels_out: int,
        record: bool,
    ):
        import cv2

        th, tw, nc = tex.shape
        super().__init__(nc, out_h, out_w, p, channels_out, record)
        b = p.block
        self.tex, self.p, self.b, self.nc = tex, p, b, nc
        hc, wc, rows, cols = self.hc, self.wc, self.rows, self.cols
        synthesis = prev is None and corr is None
        pool = p.seam_pool if p.seam_pool is not None else (SEAM_POOL if synthesis else 0)
        self.pool = pool * p.tol if p.mode == "mincut" and p.rule == "tol" and pool > 0 else 0
        self.steps = _steps(p, _uses_numpy(p, synthesis, rows * cols))
        self.src = src = _Source(tex, corr[0] if corr is not None else None, b)
        self.prev_c = np.zeros((1, 1, nc), dtype=np.float32)
        self.corr_t = np.zeros((1, 1), dtype=np.float32)
        if prev is not None:
            self.prev_c = _pad_to(prev, hc, wc)
        if corr is not None:
            self.corr_t = _pad_to(corr[1], hc, wc)
        self.tbuf = np.zeros((nc, src.n_h, src.n_w), dtype=np.float32)
        # Per-block spectra and correlation written into these, not into fresh arrays: freeing a few
        # hundred kB per block makes glibc trim and re-fault the heap.
        self.fwd, self.part, self.acc, self.cross_buf = (
            np.empty((src.n_h, src.n_w), dtype=np.float32) for _ in range(4)
        )
        self.cost_buf = np.empty(src.ph * src.pw, dtype=np.float64)
        self.tcorr = np.zeros((src.n_h, src.n_w), dtype=np.float32)
        self.us = rng.random((rows, cols))
        self.seeds = rng.integers(0, 2**63 - 1, size=(rows, cols), dtype=np.int64)
        self.first = (int(rng.integers(0, src.ph)), int(rng.integers(0, src.pw)))
        self.avoid = p.avoid if p.avoid is not None else (AVOID_RADIUS if synthesis else -1)
        self.usage_weight = p.usage if p.usage is not None else (USAGE_WEIGHT if synthesis else 0.0)
        self.usage = np.zeros((th, tw), dtype=np.float32) if self.usage_weight > 0 else None
        # a random match's expected squared error per overlap pixel: 2 x the variance, per channel
        self.random_error = 2.0 * float(tex.astype(np.float64).var()) * nc
        self.candidates = np.empty(max(self.pool, 1), dtype=np.int64)
        self.chosen = np.full((rows, cols, 2), -1, dtype=np.int64)  # each block's source position
        self.ip = ip = np.zeros(_K.N_IPARAMS, dtype=np.int64)
        ip[_K.P_B] = b
        ip[_K.P_WRAP] = int(p.tile)
        ip[_K.P_MODE] = {"overlap": _K.MODE_OVERLAP, "mincut": _K.MODE_MINCUT}[p.mode]
        ip[_K.P_POISSON] = int(p.poisson)
        ip[_K.P_BAND] = p.band
        # place_block's work buffers: the cut, and the window around the block for the Poisson band
        ws = b + 2 * (p.band + 2 if p.poisson else 0)
        self.err, self.mask = np.empty((b, b), dtype=np.float64), np.empty((b, b), dtype=np.uint8)
        self.mincut = p.mode == "mincut"
        self.win = np.empty((2, ws), dtype=np.int64)
        self.label, self.old = np.empty((ws, ws), dtype=np.int8), np.empty((ws, ws, nc), dtype=np.float32)
        self.has_static = p.w_prev != 0.0 or (p.w_corr != 0.0 and corr is not None)
        self.flags = cv2.DFT_REAL_OUTPUT | cv2.DFT_SCALE
        self.wrap = bool(p.tile)

    def run(self, report: ProgressReporter | None, cancel: CancelToken | None) -> None:
        """Place every block, row by row; the static terms of the cost (transfer) a row ahead."""
        static = _StaticRows(self) if self.has_static else None
        try:
            for i in range(self.rows):
                if cancel is not None:
                    cancel.raise_if_cancelled()
                row_static = static.take(i) if static is not None else None
                self._row(i, row_static)
                if report is not None:
                    report.update(i + 1, preview=self.preview)
        finally:
            if static is not None:
                static.close()

    def _row(self, i: int, row_static: list | None) -> None:
        ip = self.ip
        y0, top, bottom = self.ys[i], self.tops[i], self.bottoms[i]
        ip[_K.P_Y0], ip[_K.P_TOP], ip[_K.P_BOTTOM] = y0, top, bottom
        for j in range(self.cols):
            x0, left, right = self.xs[j], self.lefts[j], self.rights[j]
            ip[_K.P_X0], ip[_K.P_LEFT], ip[_K.P_RIGHT] = x0, left, right
            overlaps = top or left or right or bottom
            if overlaps or row_static is not None:
                cross, const = self._cross(i, j, y0, x0, (top, left, right, bottom), overlaps, row_static)
                seam_cut_done = self._choose(i, j, cross, const, (top, left, right, bottom), overlaps)
            else:  # synthesis, first block: a random position
                ip[_K.P_SY], ip[_K.P_SX] = self.first
                seam_cut_done = False
            self._paste(i, j, y0, x0, (top, left, right, bottom), overlaps, seam_cut_done)

    def _cross(
        self,
        i: int,
        j: int,
        y0: int,
        x0: int,
        sides: tuple[int, int, int, int],
        overlaps: int,
        row_static: list | None,
    ) -> tuple[np.ndarray, float]:
        """The cross-correlation of block (i, j)'s template with every source position (the usage
        penalty and the forbidden continuations written into it), and the cost's constant term."""
        import cv2

        p, src, nc = self.p, self.src, self.nc
        top, left, right, bottom = sides
        spec, const = (None, 0.0) if row_static is None else row_static[j]
        if overlaps:
            const += self.steps.template(
                self.canvas,
                self.prev_c,
                self.corr_t,
                y0,
                x0,
                self.b,
                top,
                left,
                right,
                bottom,
                self.wrap,
                p.w_overlap,
                0.0,
                0.0,
                src.mean,
                src.mean_c,
                self.tbuf,
                self.tcorr,
            )
            fwd, part, acc = self.fwd, self.part, self.acc
            for c in range(nc):
                cv2.dft(self.tbuf[c], dst=fwd)
                if spec is None:
                    spec = cv2.mulSpectrums(src.spectra[c], fwd, 0, c=acc, conjB=True)
                else:
                    cv2.mulSpectrums(src.spectra[c], fwd, 0, c=part, conjB=True)
                    spec = np.add(spec, part, out=acc)
        cross = cv2.idft(spec, dst=self.cross_buf, flags=self.flags)  # type: ignore[arg-type]  # nc >= 1 set spec
        b = self.b
        if self.usage is not None and overlaps:
            n_overlap = b * b - (b - top - bottom) * (b - left - right)
            _penalise_usage(cross, self.usage, src.ph, src.pw, b, self.usage_weight * self.random_error * n_overlap)
        if self.avoid >= 0:
            neighbours = _neighbours(self.chosen, i, j, self.ys, self.xs, self.hc, self.wc, self.wrap)
            _forbid_continuations(cross, src.ph, src.pw, y0, x0, neighbours, self.avoid)
        return cross, const

    def _choose(
        self, i: int, j: int, cross: np.ndarray, const: float, sides: tuple[int, int, int, int], overlaps: int
    ) -> bool:
        """Choose block (i, j)'s source position into the parameter array; True when the seam rule
        chose it (its cut is then left in ``mask``)."""
        src, steps, ip = self.src, self.steps, self.ip
        sq = src.sq(sides, self.p)
        seam_cut_done = bool(self.pool and overlaps)
        if seam_cut_done:  # the winner's cut is left in mask
            pick = steps.by_seam(
                cross,
                sq,
                float(const),
                self.cost_buf,
                self.pool,
                self.candidates,
                self.canvas,
                self.filled,
                self.tex,
                ip,
                self.err,
                self.mask,
                steps.best_k,
                steps.block_error,
                steps.seam_cut,
                steps.seam_error,
                src.pw,
            )
        else:
            pick = int(steps.choose(cross, sq, float(const), self.cost_buf, self.us[i, j], self.seeds[i, j]))
        ip[_K.P_SY], ip[_K.P_SX] = divmod(pick, src.pw)
        return seam_cut_done

    def _paste(
        self, i: int, j: int, y0: int, x0: int, sides: tuple[int, int, int, int], overlaps: int, seam_cut_done: bool
    ) -> None:
        """Cut (mincut) and paste block (i, j) from its chosen position; keep count of what it used."""
        steps, ip, b, mask = self.steps, self.ip, self.b, self.mask
        top, left, right, bottom = sides
        if self.mincut and overlaps and not seam_cut_done:
            steps.error(self.canvas, self.filled, self.tex, ip, self.err)
            steps.cut(self.err, top, left, right, bottom, mask)
        steps.place(self.canvas, self.filled, self.tex, ip, mask, self.win, self.label, self.old)
        self.chosen[i, j] = ip[_K.P_SY], ip[_K.P_SX]
        if self.usage is not None:
            sy, sx = int(ip[_K.P_SY]), int(ip[_K.P_SX])
            self.usage[sy : sy + b, sx : sx + b] += mask if self.mincut and overlaps else np.float32(1.0)
        if self.sources is not None:
            _record(
                self.sources,
                y0,
                x0,
                int(ip[_K.P_SY]),
                int(ip[_K.P_SX]),
                b,
                mask if self.mincut and overlaps else None,
            )
        if steps.blend is not None and self.p.poisson:
            steps.blend(self.canvas, self.old, self.label, self.win, self.p.band)


class _StaticRows:
    """The previous-pass and correspondence terms of a transfer's cost, one block row ahead.

    They do not depend on the blocks placed in this pass: their spectra are computed one block row
    ahead on a second thread (cv2 and the numba kernels release the GIL), while the pass adds the
    overlap term block by block.
    """

    def __init__(self, quilt: _OverlapPass):
        from concurrent.futures import ThreadPoolExecutor

        self.q = quilt
        self.tbuf = np.zeros_like(quilt.tbuf)
        self.tcorr = np.zeros_like(quilt.tcorr)
        self.fwd, self.part = np.empty_like(quilt.fwd), np.empty_like(quilt.part)
        # two rows of spectra, written alternately: the row being used and the one computed ahead
        src = quilt.src
        self.specs = [np.empty((quilt.cols, src.n_h, src.n_w), dtype=np.float32) for _ in range(2)]
        self.pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="weft-quilt")
        self.ahead = self.pool.submit(self._row, 0)

    def take(self, i: int) -> list:
        """Row i's (spectrum, constant) per block; the next row starts on the second thread."""
        row = self.ahead.result()
        if i + 1 < self.q.rows:
            self.ahead = self.pool.submit(self._row, i + 1)
        return row

    def close(self) -> None:
        self.pool.shutdown(wait=True, cancel_futures=True)

    def _row(self, i: int) -> list:
        import cv2

        q = self.q
        p, src = q.p, q.src
        out = []
        specs = self.specs[i % 2]
        for j in range(q.cols):
            cst = q.steps.template(
                q.prev_c,
                q.prev_c,
                q.corr_t,
                q.ys[i],
                q.xs[j],
                q.b,
                0,
                0,
                0,
                0,
                q.wrap,
                0.0,
                p.w_prev,
                p.w_corr,
                src.mean,
                src.mean_c,
                self.tbuf,
                self.tcorr,
            )
            assert src.spectrum_c is not None  # a transfer's source has its correspondence map
            spec = cv2.mulSpectrums(src.spectrum_c, cv2.dft(self.tcorr, dst=self.fwd), 0, c=specs[j], conjB=True)
            if p.w_prev:
                for c in range(q.nc):
                    cv2.mulSpectrums(src.spectra[c], cv2.dft(self.tbuf[c], dst=self.fwd), 0, c=self.part, conjB=True)
                    spec = np.add(spec, self.part, out=spec)
            out.append((spec, cst))
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


def _pad_to(img: np.ndarray, h: int, w: int) -> np.ndarray:
    """``img`` grown to (h, w) by repeating its last row/column (the canvas may exceed the output)."""
    ph, pw = h - img.shape[0], w - img.shape[1]
    if ph == 0 and pw == 0:
        return np.ascontiguousarray(img, dtype=np.float32)
    pad = [(0, ph), (0, pw)] + [(0, 0)] * (img.ndim - 2)
    return np.ascontiguousarray(np.pad(img, pad, mode="edge"), dtype=np.float32)
