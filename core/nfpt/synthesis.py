"""Feature-weighted patch synthesis with seam repair (Yan, Lee & Lin §2, steps 1-7).

1. A random patch of the source goes to the output's top-left corner.
2. The next patch (scan-line order, stepping by block - overlap like image quilting) is the source
   position whose L-shaped neighbourhood -- the overlap with the patches already placed, left strip
   and top strip -- matches best under the feature-weighted similarity of eqs. 1-3:
   ``Sim = sum_L P_diff (W_d + W_s)`` with ``W_d`` a Gaussian of the pixel's distance to the patch
   boundary (eq. 1) and ``W_s`` a Gaussian of its feature strength, its difference to the L-shape's
   dominant colour (eq. 2). Every position of the source is searched, by FFT correlation.
3. The patch is pasted on its side of the minimum-error boundary cut (step 4; :mod:`weft.core.seams`).
6. Pixels in a band around each cut where the two patches disagree by more than a threshold are
   re-synthesized pixel by pixel by neighbourhood matching against the source.
7. Optionally, the re-synthesized pixels are replaced by a Gaussian filtering of the result.

Choices where the paper is ambiguous (it gives no numbers; "more details can refer to [14]"):

* ``P_diff`` is the squared difference of **luminance** (Rec. 601). Squared, so that the weighted
  sum over every source position is two template DFTs and one inverse per patch; luminance, so that
  it is one channel (colour would take four template DFTs instead of two). The cut, the mismatch
  test and the repair use all colour channels.
* Units: ``d`` in pixels, from the pixel's centre to the edge between the L-shape and the patch's
  new part (0.5 next to it; in the corner square, the Euclidean distance to the corner). Intensities
  are in [0, 1], so eq. 2's 255 is 1. Each W keeps the paper's ``1 / (sqrt(2 pi) sigma)`` with its
  own sigma: ``sigma_d`` in pixels (default overlap / 2), ``sigma_s`` in intensity (default 0.35,
  where W_s ranges from about 0 on the background to 1.1 on a full-contrast feature, against W_d's
  0.07 maximum for the default overlap, so features dominate as the paper intends).
* Eq. 2 reads ``(M - P) - 255``; that sign would count only pixels darker than the background as
  features, so the feature strength is ``|P - M|`` (the RMS over colour channels). ``M`` is the mean
  colour of the L-shape's pixels in the most populated cell of an 8-level-per-channel colour
  histogram (32 levels for grey).
* "Best match": uniformly one of the ``tol`` best positions (default 2), as quilting's tol rule;
  tol = 1 is the paper's literal best match, which repeats verbatim runs of the source.
* Repair band and mismatch (Fig. 1c-d): pixels of the L-shape within ``band`` pixels (Chebyshev) of
  the cut, on both sides, where the two overlapping patches differ by more than ``threshold`` (RMS
  over channels, intensities in [0, 1]; default 0.1, i.e. 25 of 255 levels). They are re-synthesized
  after all patches are placed (steps 5-6), in scan-line order, each repaired pixel becoming known.
  "Neighbourhood matching against the source" is limited to Ashikhmin's coherent candidates: every
  known pixel of the ``n x n`` window proposes the source pixel continuing its own source; the one
  whose window best matches the known pixels (mean squared colour difference) is copied. A search of
  the whole source per pixel would cost a patch search per pixel. A pixel a later patch covers loses
  its mark from the older seam.
* ``smooth``: a Gaussian of sigma 0.8 px over the result, copied onto the repaired pixels only.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..errors import ImageError
from ..grid import block_grid
from ..image import luminance, validate_image
from ..jobs import CancelToken, Progress, ProgressReporter
from ..params import as_rng, out_of_range

__all__ = ["Synthesis", "synthesize_patches", "distance_weights", "SMOOTH_SIGMA"]

SMOOTH_SIGMA = 0.8


@dataclass(frozen=True)
class Synthesis:
    """A synthesized texture and what it took: ``image``, ``patches`` placed, ``repaired`` pixels,
    ``pos`` (flat source index ``y * Ws + x`` of every output pixel), ``repaired_mask``."""

    image: np.ndarray
    patches: int
    repaired: int
    pos: np.ndarray
    repaired_mask: np.ndarray

    def figures(self) -> dict:
        h, w = self.image.shape[:2]
        return {
            "patches": self.patches,
            "repaired_pixels": int(self.repaired),
            "repaired_fraction": round(self.repaired / float(h * w), 5),
        }


def distance_weights(block: int, top: int, left: int, sigma_d: float) -> np.ndarray:
    """W_d of eq. 1 on the L-shape of a patch (0 outside it).

    ``d`` is the distance from the pixel's centre to the edge between the L and the patch's new part
    (see the module docstring).

    Parameters
    ----------
    block : int
        The patch side.
    top, left : int
        The widths of the overlap strips (0: no strip on that side).
    sigma_d : float
        The Gaussian's sigma, pixels.

    Returns
    -------
    ndarray, float64 (block, block)

    References
    ----------
    Yan, Lee & Lin, "Patch-based synthesis for non-frontal-parallel textures", §2, eq. 1.
    """
    ys = np.arange(block, dtype=np.float64)[:, None]
    xs = np.arange(block, dtype=np.float64)[None, :]
    dy = np.maximum(top - 0.5 - ys, 0.0) if top else np.zeros_like(ys)
    dx = np.maximum(left - 0.5 - xs, 0.0) if left else np.zeros_like(xs)
    in_l = (ys < top) | (xs < left)
    d = np.where((ys < top) & (xs < left), np.hypot(dy, dx), np.maximum(dy, dx))
    wd = np.exp(-d * d / (2.0 * sigma_d * sigma_d)) / (math.sqrt(2.0 * math.pi) * sigma_d)
    return np.ascontiguousarray(np.where(in_l, wd, 0.0))


def _valid_positions(mask: np.ndarray | None, shape: tuple[int, int], block: int) -> np.ndarray:
    """uint8 (ph, pw): 1 where the block x block source patch lies wholly inside ``mask``."""
    hs, ws = shape
    ph, pw = hs - block + 1, ws - block + 1
    if mask is None:
        return np.ones((ph, pw), np.uint8)
    bad = (~mask).astype(np.int64)
    ii = np.zeros((hs + 1, ws + 1), np.int64)
    ii[1:, 1:] = bad.cumsum(0).cumsum(1)
    s = ii[block:, block:] - ii[:-block, block:] - ii[block:, :-block] + ii[:-block, :-block]
    return (s[:ph, :pw] == 0).astype(np.uint8)


def _seam_band(cut: np.ndarray, in_l: np.ndarray, top: int, left: int, band: int) -> np.ndarray:
    """Pixels of the L within ``band`` pixels of the cut (the edge between old and new pixels)."""
    import cv2

    b = cut.shape[0]
    pad = np.pad(cut, 1, mode="edge")
    if left:
        pad[:, 0] = False  # the old pixels of the left neighbour
    if top:
        pad[0, :] = False
    edge = np.zeros_like(pad)
    edge[:, 1:] |= pad[:, 1:] != pad[:, :-1]
    edge[:, :-1] |= pad[:, 1:] != pad[:, :-1]
    edge[1:, :] |= pad[1:, :] != pad[:-1, :]
    edge[:-1, :] |= pad[1:, :] != pad[:-1, :]
    k = np.ones((2 * band + 1, 2 * band + 1), np.uint8)
    near = cv2.dilate(edge.astype(np.uint8), k)[1 : b + 1, 1 : b + 1].astype(bool)
    return near & in_l


class _Search:
    """Eq. 3 for every source position at once: ``Sim(p) = sum_L w (Y_out - Y_src(p + .))^2``.

    With S the source luminance centred on its mean and T the output's L-shape (centred alike), the
    sum is ``corr(S^2, w) - 2 corr(S, w T) + sum w T^2``: two template spectra and one inverse DFT
    per patch, the source spectra computed once (as :mod:`weft.core.quilting` does for its SSD).
    """

    def __init__(self, src_y: np.ndarray, mean: float, levels: int, sigma_s: float):
        import cv2

        self.hs, self.ws = src_y.shape
        self.mean = float(mean)
        self.levels = levels
        self.sigma_s = float(sigma_s)
        self.n_h, self.n_w = cv2.getOptimalDFTSize(self.hs), cv2.getOptimalDFTSize(self.ws)
        yc = (src_y - np.float32(mean)).astype(np.float32)
        self.spec1 = cv2.dft(self._padded(yc))
        self.spec2 = cv2.dft(self._padded(yc * yc))
        self.w_buf = np.zeros((self.n_h, self.n_w), np.float32)
        self.tw_buf = np.zeros((self.n_h, self.n_w), np.float32)
        # per-patch spectra and the cost map go into these: fresh arrays every patch make glibc trim
        # and re-fault the heap
        self._fwd, self._spec, self._cross, self._cmap = (np.empty((self.n_h, self.n_w), np.float32) for _ in range(4))

    def _padded(self, img: np.ndarray) -> np.ndarray:
        out = np.zeros((self.n_h, self.n_w), np.float32)
        out[: self.hs, : self.ws] = img
        return out

    def cost(self, canvas_y: np.ndarray, canvas: np.ndarray, y0: int, x0: int, wd: np.ndarray):
        """(cmap, const): the similarity of position (py, px) is ``cmap[py, px] + const``."""
        import cv2

        from .._kernels import nfpt as _k

        const = _k.l_template(
            canvas_y, canvas, y0, x0, wd.shape[0], wd, self.sigma_s, self.levels, self.mean, self.w_buf, self.tw_buf
        )
        spec = cv2.mulSpectrums(self.spec2, cv2.dft(self.w_buf, dst=self._fwd), 0, c=self._spec, conjB=True)
        cross = cv2.mulSpectrums(self.spec1, cv2.dft(self.tw_buf, dst=self._fwd), 0, c=self._cross, conjB=True)
        cv2.scaleAdd(cross, -2.0, spec, dst=spec)
        return cv2.idft(spec, dst=self._cmap, flags=cv2.DFT_REAL_OUTPUT | cv2.DFT_SCALE), const


def synthesize_patches(
    texture: np.ndarray,
    size: tuple[int, int],
    *,
    block: int,
    overlap: int,
    sigma_d: float,
    sigma_s: float,
    tol: int,
    repair: bool,
    band: int,
    threshold: float,
    n: int,
    smooth: bool,
    shift: int = 0,
    mask: np.ndarray | None = None,
    rng: None | int | np.random.Generator = None,
    progress: Callable[[Progress], None] | None = None,
    cancel: CancelToken | None = None,
) -> Synthesis:
    """The engine of :func:`weft.core.nfpt.synthesize`, its parameters already validated.

    Parameters
    ----------
    texture : ndarray, float32 (H, W) or (H, W, 3)
        The (frontal) source texture.
    size : (int, int)
        The output's width and height.
    block, overlap, sigma_d, sigma_s, tol, repair, band, threshold, n, smooth
        As in :func:`weft.core.nfpt.synthesize`.
    shift : int, default 0
        A shift of the block grid, pixels.
    mask : ndarray, bool (H, W), optional
        Where the source may be sampled (the rectified photo's valid part); default everywhere.
    rng, progress, cancel
        Seed or generator; progress callback; cancel token.

    Returns
    -------
    Synthesis
        The image and what it took (patches, repaired pixels, source positions).

    Raises
    ------
    InvalidParameter
        ``block`` does not fit in the texture.
    ImageError
        The mask's size is not the texture's, or it leaves no whole patch to sample.

    References
    ----------
    Yan, Lee & Lin, "Patch-based synthesis for non-frontal-parallel textures", §2, steps 1-7.
    """
    from .._kernels import nfpt as _k

    tex, mask, valid = _checked_source(texture, block, mask)
    hs, ws, nc = tex.shape
    rng = as_rng(rng)
    width, height = size
    ys, _, _, hc = block_grid(height, block, overlap, False)  # the patch grid quilting uses too
    xs, _, _, wc = block_grid(width, block, overlap, False)
    rows, cols = len(ys), len(xs)

    src_y = luminance(tex[..., 0] if nc == 1 else tex)
    mean = float(src_y[mask].mean()) if mask is not None else float(src_y.mean())
    levels = 8 if nc == 3 else 32
    search = _Search(src_y, mean, levels, sigma_s)
    canvas = _Canvas(hc, wc, nc, height, width)
    flat_index = np.arange(hs, dtype=np.int32)[:, None] * ws + np.arange(ws, dtype=np.int32)[None, :]
    wd_cache: dict[tuple[int, int], tuple[np.ndarray, np.ndarray]] = {}
    us = rng.random((rows, cols))
    ph, pw = valid.shape
    first_choices = np.flatnonzero(valid)
    first = int(first_choices[rng.integers(0, len(first_choices))])
    thr2 = threshold * threshold * nc

    stage_total = rows + (1 if repair else 0)
    report = ProgressReporter(progress, "nfpt synthesis", stage_total)

    for i in range(rows):
        if cancel is not None:
            cancel.raise_if_cancelled()
        y0 = ys[i]
        top = overlap if i > 0 else 0
        for j in range(cols):
            x0 = xs[j]
            left = overlap if j > 0 else 0
            in_l = None
            if top == 0 and left == 0:
                k = first
            else:
                key = (top, left)
                if key not in wd_cache:
                    wd = distance_weights(block, top, left, sigma_d)
                    wd_cache[key] = (wd, wd > 0)
                wd, in_l = wd_cache[key]
                cmap, const = search.cost(canvas.y, canvas.image, y0, x0, wd)
                k = int(_k.select(cmap, const, valid, tol, us[i, j]))
            sy, sx = divmod(k, pw)
            canvas.paste(
                tex, src_y, flat_index, (sy, sx), (y0, x0), block, top, left, in_l, band if repair else None, thr2
            )
        report.update(i + 1, preview=canvas.preview)

    repaired = 0
    if repair and canvas.todo.any():
        repaired = _repair_seams(canvas, tex, mask, n, shift, smooth, cancel)
        report.update(stage_total, preview=canvas.preview)
    return canvas.result(rows * cols, repaired)


def _checked_source(
    texture: np.ndarray, block: int, mask: np.ndarray | None
) -> tuple[np.ndarray, np.ndarray | None, np.ndarray]:
    """The source as (H, W, C) float32, its mask as bool, and the patch positions wholly inside it."""
    tex = validate_image(texture, "texture")
    if tex.ndim == 2:
        tex = tex[..., None]
    hs, ws, nc = tex.shape
    if block > min(hs, ws):
        raise out_of_range("block", block, 8, min(hs, ws), f"must fit in the source texture, {ws}x{hs}")
    if mask is not None:
        mask = np.asarray(mask, dtype=bool)
        if mask.shape != (hs, ws):
            raise ImageError(f"source mask is {mask.shape[1]}x{mask.shape[0]}, the texture {ws}x{hs}: they must match")
    valid = _valid_positions(mask, (hs, ws), block)
    if not valid.any():
        raise ImageError(
            f"no {block}x{block} patch of the source lies wholly inside its valid part "
            f"(the rectified area is too small for the block; use a smaller --block)"
        )
    return tex, mask, valid


class _Canvas:
    """The output being built (``image``, its luminance ``y``), the flat source index each pixel was
    copied from (``pos``, -1 where none) and the pixels to repair (``todo``: 1 to do, 2 done)."""

    def __init__(self, hc: int, wc: int, nc: int, height: int, width: int):
        self.image = np.zeros((hc, wc, nc), np.float32)
        self.y = np.zeros((hc, wc), np.float32)
        self.pos = np.full((hc, wc), -1, np.int32)
        self.todo = np.zeros((hc, wc), np.uint8)
        self.height, self.width = height, width

    def paste(
        self,
        tex: np.ndarray,
        src_y: np.ndarray,
        flat_index: np.ndarray,
        source: tuple[int, int],
        at: tuple[int, int],
        block: int,
        top: int,
        left: int,
        in_l: np.ndarray | None,
        band: int | None,
        thr2: float,
    ) -> None:
        """Paste the source patch at ``source`` to ``at`` on its side of the minimum-error cut through
        the L-shaped overlap; with a repair ``band``, mark the mismatched pixels near the cut."""
        from .. import seams

        (sy, sx), (y0, x0) = source, at
        new = tex[sy : sy + block, sx : sx + block]
        foot = (slice(y0, y0 + block), slice(x0, x0 + block))
        if in_l is not None:  # (None for the first patch, which overlaps nothing)
            old = self.image[foot]
            err = seams.overlap_error(old, new)
            err[~in_l] = 0.0
            cut = seams.min_cut_mask(err, left=left, top=top)
            if band is not None:
                near = _seam_band(cut, in_l, top, left, band)
                self.todo[foot][cut] = 0  # pixels the new patch covers are no longer by an older seam
                self.todo[foot][near & (err > thr2)] = 1
        else:
            cut = np.ones((block, block), bool)
        self.image[foot][cut] = new[cut]
        self.y[foot][cut] = src_y[sy : sy + block, sx : sx + block][cut]
        self.pos[foot][cut] = flat_index[sy : sy + block, sx : sx + block][cut]

    def preview(self) -> np.ndarray:
        img = self.image[: self.height, : self.width]
        return (img[..., 0] if img.shape[2] == 1 else img).copy()

    def result(self, patches: int, repaired: int) -> Synthesis:
        height, width = self.height, self.width
        out = np.ascontiguousarray(self.image[:height, :width])
        if out.shape[2] == 1:
            out = np.ascontiguousarray(out[..., 0])
        return Synthesis(
            out,
            patches,
            repaired,
            np.ascontiguousarray(self.pos[:height, :width]),
            np.ascontiguousarray(self.todo[:height, :width] == 2),
        )


def _repair_seams(
    canvas: _Canvas,
    tex: np.ndarray,
    mask: np.ndarray | None,
    n: int,
    shift: int,
    smooth: bool,
    cancel: CancelToken | None,
) -> int:
    """Re-make the marked pixels near the seams by neighbourhood matching (scan-line order), then
    smooth them when asked; returns how many pixels of the output were re-made."""
    import cv2

    from .._kernels import nfpt as _k

    hs, ws = tex.shape[:2]
    todo = canvas.todo
    allowed = np.ascontiguousarray(mask, dtype=np.uint8) if mask is not None else np.ones((hs, ws), np.uint8)
    half = n // 2
    order = np.flatnonzero(todo.ravel() == 1).astype(np.int64)  # scan-line order
    step = max(1, -(-len(order) // 16))
    for c0 in range(0, len(order), step):
        if cancel is not None:
            cancel.raise_if_cancelled()
        _k.repair(canvas.image, canvas.pos, todo, tex, allowed, half, shift, order[c0 : c0 + step])
    done = todo[: canvas.height, : canvas.width] == 2
    repaired = int(done.sum())
    if smooth and repaired:
        blurred = cv2.GaussianBlur(canvas.image, (0, 0), SMOOTH_SIGMA, borderType=cv2.BORDER_REFLECT)
        if blurred.ndim == 2:
            blurred = blurred[..., None]
        sel = todo == 2
        canvas.image[sel] = blurred[sel]
    return repaired
