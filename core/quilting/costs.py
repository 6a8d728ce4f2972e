"""What a block's cost is made of, besides its SSD: the source prepared once per pass (centred,
spectra, squared sums per overlap shape), the usage penalty, and the source positions forbidden
because they would continue a neighbouring block's piece of the sample.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from .pass_options import _Pass

#: The cross-correlation written at a forbidden position: its SSD becomes ~2e30, so every rule ranks
#: it behind every allowed position (and still picks among them when nothing else is left).
_FORBIDDEN_CROSS = np.float32(-1e30)


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


class _Source:
    """The source texture prepared for one block size: centred, spectra, squared sums."""

    spectrum_c: np.ndarray | None  # the correspondence map's, when there is one
    sq_c: np.ndarray | None

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
