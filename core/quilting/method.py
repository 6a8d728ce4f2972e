"""``weft quilt``: image quilting's parameters, the one-call Python API and the method (see the package)."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Mapping

import numpy as np

from ..errors import ImageError, InvalidParameter
from ..image import luminance, validate_image
from ..jobs import CancelToken, Progress, ProgressReporter
from ..params import Params, as_rng, out_of_range, param
from ..registry import InputSpec, Method, Result
from ..studio import SQUARE, Geometry, Studio
from ..grid import block_grid
from .engine import RULES, _K, _Pass, _pad_to, _quilt_pass  # noqa: F401 (_K: tests compare it to the kernel)

__all__ = ["QuiltParams", "synthesize", "transfer", "transfer_schedule", "METHOD"]

MODES = ("random", "overlap", "mincut")
CORRESPONDENCES = ("blur", "luminance")

# Defaults that depend on what is being made (see QuiltParams).
SYNTH_BLOCK = 32
TRANSFER_BLOCK = 9  # Ngo: single-pass transfer 9 / 3
ITERATIVE_BLOCK = 31  # Ngo: iterative transfer starts at 31 / 21 ...
MIN_BLOCK, MIN_OVERLAP = 9, 3  # ... and goes down to 9 / 3
SYNTH_TOL = 2
CORR_SIGMA = 2.0  # Gaussian blur (pixels) of the luminance correspondence maps ("blur")


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


# --------------------------------------------------------------------------------------------
# checks shared by synthesis and transfer


def _check_texture(texture) -> np.ndarray:
    tex = validate_image(texture, "texture")
    return tex if tex.ndim == 3 else tex[..., None]


def _check_block_fits(block: int, tex: np.ndarray) -> None:
    h, w = tex.shape[:2]
    if block > min(h, w):
        raise out_of_range("block", block, 2, min(h, w), f"must fit in the texture, {w}x{h}",
                           input="texture")


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


#: Seconds per source position per block for choosing a position and pasting (rule, cut), besides
#: the DFTs: ~1 ns on the 2-core machine (fitted to ``python -m benchmarks.estimates``).
SELECT_SECONDS_PER_POSITION = 1e-9
#: Bytes per output pixel of a job's peak memory (canvas, previous pass, correspondence maps and
#: preview copies, float32; measured with /usr/bin/time -v on `weft quilt` of a 256x256 texture: 2048x2048
#: synthesis 245 MB peak RSS, transfer 477 MB, of which ~100 MB are Python, NumPy, OpenCV and numba
#: and, for the transfer, 175 MB its two rows of spectra, counted separately in ``_check_limits``).
BYTES_PER_OUTPUT_PIXEL = {"synthesis": 40, "transfer": 50}
#: Bytes per texture pixel: its spectra (one per channel and the correspondence map) and the
#: squared-sum maps cached per overlap shape (up to nine), float32.
BYTES_PER_SOURCE_PIXEL = 60


def estimate_seconds(texture_shape: tuple[int, ...], out_size: tuple[int, int],
                     passes: list[tuple[int, int]], *, tile: bool = False) -> float:
    """Estimated running time of quilting on the 2-core reference machine (see :mod:`weft.core.limits`).

    Each block but the first costs ``C + 1`` DFTs of the padded source (one per channel
    and the inverse; a transfer adds its correspondence and previous-pass spectra, computed on a
    second thread one row ahead, so they do not add up) plus a position choice over every source
    position. ``passes`` are the (block, overlap) of each pass. Against real runs (``python -m
    benchmarks.estimates``) it comes within 0.8..1.8x.
    """
    from ..limits import dft_seconds

    h, w = texture_shape[:2]
    channels = texture_shape[2] if len(texture_shape) == 3 else 1
    width, height = out_size
    dft = dft_seconds(h, w)
    total = 0.0
    for block, overlap in passes:
        blocks = _blocks(height, width, block, overlap, tile)
        positions = (h - block + 1) * (w - block + 1)
        total += blocks * ((channels + 1) * dft + SELECT_SECONDS_PER_POSITION * positions)
    return total


def _memory_need(tex_shape: tuple[int, ...], out_w: int, out_h: int, passes: list[tuple[int, int]], *,
                 tile: bool, transfer: bool) -> float:
    """Estimated peak bytes of quilting ``out_w`` x ``out_h`` from a texture of ``tex_shape``."""
    h, w = tex_shape[:2]
    need = (BYTES_PER_OUTPUT_PIXEL["transfer" if transfer else "synthesis"] * out_w * out_h
            + BYTES_PER_SOURCE_PIXEL * h * w)
    if transfer:  # two block rows of texture-sized spectra (the row in use and the one computed ahead)
        import cv2

        cols = max(len(block_grid(out_w, b, o, tile)[0]) for b, o in passes)
        need += 2 * cols * cv2.getOptimalDFTSize(h) * cv2.getOptimalDFTSize(w) * 4
    return need


def _transfer_passes(params: QuiltParams) -> list[tuple[int, int, float]]:
    """Block, overlap and alpha of each pass of a transfer with these parameters (defaults resolved)."""
    n = params.iterations
    b = params.block if params.block is not None else (TRANSFER_BLOCK if n == 1 else ITERATIVE_BLOCK)
    ov = params.overlap if params.overlap is not None else max(1, min(b - 1, _round_half_up(b / 3 if n == 1 else 2 * b / 3)))
    return transfer_schedule(n, block=b, overlap=ov, alpha=params.alpha)


def memory_estimate(shapes: Mapping[str, tuple[int, ...]], params: QuiltParams) -> float:
    """Estimated peak bytes of one run on inputs of these shapes (what the run's own check uses);
    0 for a random-mode synthesis, which has no such check."""
    tex = shapes["texture"]
    if shapes.get("target") is not None:
        out_h, out_w = shapes["target"][:2]
        passes = [(b, o) for b, o, _ in _transfer_passes(params)]
        return _memory_need(tex, out_w, out_h, passes, tile=params.tile, transfer=True)
    if params.mode == "random":
        return 0.0
    b = params.block or SYNTH_BLOCK
    ov = params.overlap if params.overlap is not None else max(1, -(-b // 6))
    out_w, out_h = params.size if params.size is not None else (2 * tex[1], 2 * tex[0])
    return _memory_need(tex, out_w, out_h, [(b, ov)], tile=params.tile, transfer=False)


def _check_limits(tex: np.ndarray, out_w: int, out_h: int, passes: list[tuple[int, int]], *,
                  tile: bool, transfer: bool) -> None:
    """Refuse up front an output over the pixel limit, beyond available memory, or too long to quilt."""
    from ..limits import check_duration, check_memory, check_output_size

    check_output_size(out_w, out_h, "the target" if transfer else "parameter 'size'")
    h, w = tex.shape[:2]
    need = _memory_need(tex.shape, out_w, out_h, passes, tile=tile, transfer=transfer)
    check_memory(need, f"quilting {out_w}x{out_h} from a {w}x{h} texture",
                 f"use a smaller {'target' if transfer else 'size'} or a smaller part of the texture")
    seconds = estimate_seconds(tex.shape, (out_w, out_h), passes, tile=tile)
    blocks = sum(_blocks(out_h, out_w, b, o, tile) for b, o in passes)
    first = passes[0][0]
    what = (f"{'transfer' if transfer else 'quilting'} of {out_w}x{out_h} from a {w}x{h} texture "
            f"({blocks:,} blocks of {first if len(passes) == 1 else f'{first} to {passes[-1][0]}'} px"
            f"{f' in {len(passes)} passes' if len(passes) > 1 else ''})")
    advice = ("use a larger block, fewer iterations, a smaller target or a smaller part of the texture" if transfer
              else "use a larger block, a smaller size or a smaller part of the texture")
    check_duration(seconds, what, advice)


def synthesize(
    texture: np.ndarray,
    *,
    size: tuple[int, int] | None = None,
    block: int | None = None,
    overlap: int | None = None,
    mode: str = "mincut",
    tol: int | None = None,
    rule: str = "tol",
    epsilon: float = 0.1,
    tile: bool = False,
    poisson: bool = False,
    band: int = 4,
    rng: None | int | np.random.Generator = None,
    progress: Callable[[Progress], None] | None = None,
    cancel: CancelToken | None = None,
    record: dict | None = None,
) -> np.ndarray:
    """Synthesize a texture of ``size`` from the sample ``texture`` by quilting blocks (E&F §2).

    Parameters
    ----------
    texture : float32 array (H, W) or (H, W, 3) in [0, 1]
        The sample texture.
    size : (width, height), optional
        Output size in pixels (1..16384 per side). Default: twice the texture's size.
    block : int, optional
        Block side B in pixels, 2..min(H, W) of the texture; default (None) 32.
    overlap : int, optional
        Overlap between neighbouring blocks, 1..B-1; default ceil(B / 6) (E&F §2.1: "the size of
        the overlap was 1/6 of the size of the block"). Unused in ``random`` mode.
    mode : {"random", "overlap", "mincut"}, default "mincut"
        ``random``: blocks from uniformly random positions, side by side, no overlap (E&F Fig. 2a).
        ``overlap``: blocks step by B - overlap; each is chosen by the SSD between its overlap with
        the pixels already in place (left and top strips) and the same strips at *every* position
        of the texture, and pasted over them (Fig. 2b). ``mincut``: as ``overlap``, then pasted only
        on its side of the minimum-error boundary cut through the overlap (Fig. 2c, :mod:`weft.core.seams`).
    tol : int, optional
        Default (None) 2. Rule ``tol``: pick uniformly among the ``tol`` lowest-SSD positions (Ngo's ``tol``; 1 =
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
        ``overlap`` and ``mincut``). See :func:`weft.core.blending.poisson_blend`.
    band : int, default 4
        Width of the Poisson band, 1..5 pixels: ceil(band/2) on the existing side of the seam,
        floor(band/2) on the new block's side, limited to pixels that existed before the paste.
    rng : None, int or numpy Generator
        The same seed gives the same pixels.
    progress, cancel
        Progress callback (called once per block row, with the partial image as preview) and
        cancel token (checked once per block row).
    record : dict, optional
        Receives ``"sources"``: the (height, width, 2) int32 sample coordinates each output pixel
        was copied from (-1 where none), for :func:`weft.core.metrics.verbatim_fraction`.

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
    return _synthesize(texture, params, rng=rng, progress=progress, cancel=cancel, record=record)


def _synthesize(texture: np.ndarray, params: QuiltParams, *, rng=None, progress=None, cancel=None,
                record: dict | None = None) -> np.ndarray:
    """:func:`synthesize` with its options in ``params`` (``None`` block and tol: the synthesis defaults)."""
    if params.block is None or params.tol is None:
        params = params.replace(block=params.block or SYNTH_BLOCK, tol=params.tol or SYNTH_TOL)
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
    if params.mode != "random":
        _check_limits(tex, out_w, out_h, [(b, ov)], tile=params.tile, transfer=False)
    else:
        from ..limits import check_output_size

        check_output_size(out_w, out_h)
    p = _Pass(params.mode, b, ov, params.rule, params.tol, params.epsilon, params.tile,
              params.poisson, params.band)
    rng = as_rng(rng)
    rows = len(block_grid(out_h, b, ov if params.mode != "random" else 0, params.tile and params.mode != "random")[0])
    report = ProgressReporter(progress, "quilting", rows)
    if params.mode == "random":
        p = _Pass("random", b, 0, "tol", 1, 0.0, False, False, 1)
    img, _ = _quilt_pass(tex, out_h, out_w, p, rng, report=report, cancel=cancel, channels_out=tex.shape[2],
                         record=record)
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
    tol: int | None = None,
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
        Position rule as in :func:`synthesize`; transfer takes the best (tol None means 1, Ngo), the
        first block being the best correspondence.
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
    return _transfer(texture, target, params, source_map=source_map, target_map=target_map, return_all=return_all,
                     rng=rng, progress=progress, cancel=cancel)


def _transfer(texture: np.ndarray, target: np.ndarray, params: QuiltParams, *, source_map=None, target_map=None,
              return_all: bool = False, rng=None, progress=None, cancel=None) -> np.ndarray | list[np.ndarray]:
    """:func:`transfer` with its options in ``params`` (``None`` tol: the transfer default, 1)."""
    if params.tol is None:
        params = params.replace(tol=1)
    if params.mode == "random":
        raise InvalidParameter("parameter 'mode' = 'random' is not one of overlap, mincut "
                               "(transfer matches blocks on their overlap)", name="mode", value="random")
    tex = _check_texture(texture)
    tgt = validate_image(target, "target")
    H, W = tgt.shape[:2]
    n = params.iterations
    schedule = _transfer_passes(params)
    b, ov = schedule[0][:2]
    _check_block_fits(b, tex)
    if params.overlap is not None:
        _check_overlap(b, params.overlap)
    if params.tile:
        _check_tile_size(b, W, H)
    _check_limits(tex, W, H, [(bi, oi) for bi, oi, _ in schedule], tile=params.tile, transfer=True)
    cs, ct = _correspondence_maps(tex, tgt, params.correspondence, source_map, target_map)
    if params.remap:
        ct = _remap(cs, ct)
    rng = as_rng(rng)
    results = []
    prev = None
    for i, (bi, oi, ai) in enumerate(schedule):
        p = _Pass(params.mode, bi, oi, params.rule, params.tol, params.epsilon, params.tile,
                  params.poisson, params.band, w_overlap=ai, w_prev=ai if i > 0 else 0.0, w_corr=1.0 - ai)
        rows = len(block_grid(H, bi, oi, params.tile)[0])
        report = ProgressReporter(progress, f"transfer {i + 1}/{n}", rows)
        img, _ = _quilt_pass(tex, H, W, p, rng, prev=prev, corr=(cs, ct), report=report, cancel=cancel,
                             channels_out=tex.shape[2])
        prev = np.ascontiguousarray(img)
        results.append(_finish(img, tex.shape[2]))
    return results if return_all else results[-1]


# --------------------------------------------------------------------------------------------
# the `weft quilt` command


def _blocks(n_h: int, n_w: int, block: int, overlap: int, tile: bool) -> int:
    return len(block_grid(n_h, block, overlap, tile)[0]) * len(block_grid(n_w, block, overlap, tile)[0])


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
        record: dict = {}
        image = _synthesize(texture, params, rng=rng, progress=progress, cancel=cancel, record=record)
        h, w = image.shape[:2]
        if mode == "random":
            blocks = -(-h // block) * -(-w // block)
        else:
            ov = params.overlap if params.overlap is not None else max(1, -(-block // 6))
            blocks = _blocks(h, w, block, ov, params.tile)
        from ..metrics import verbatim_fraction

        return Result(image, {"blocks": blocks,
                              "verbatim_fraction": round(verbatim_fraction(record["sources"], texture.shape), 4)})
    if params.size is not None:
        raise InvalidParameter("parameter 'size' cannot be given with a target: the transfer has the target's size",
                               name="size", value=params.size)
    images = _transfer(texture, target, params, source_map=maps["source_map"], target_map=maps["target_map"],
                       return_all=True, rng=rng, progress=progress, cancel=cancel)
    image = images[-1]
    return Result(image, {"iterations": len(images)})


def warm_up() -> None:
    """Load (or compile) every numba kernel a run can use, on tiny inputs, so that no run compiles:
    the four selection kernels (tol, tol 1, epsilon, sampled), the cut and paste, the Poisson band
    and the templates of a transfer.

    For the GUI's background start-up; ``METHOD.warm_up_in_cli`` is False: a small synthesis on the
    command line (the numpy engine, see ``NUMPY_ENGINE_MAX_BLOCKS``) would otherwise pay numba's
    start-up for nothing, and a larger run compiles only the kernels it uses. A CLI run's reported
    ``seconds`` therefore include that load.
    """
    rng = np.random.default_rng(0)
    tex = rng.random((12, 12), dtype=np.float32)
    # Poisson: always the numba engine (which loads numba, so the next calls use it too)
    synthesize(tex, size=(16, 16), block=6, overlap=2, mode="mincut", poisson=True, rng=0)
    for rule in ("epsilon", "sampled"):
        synthesize(tex, size=(16, 16), block=6, overlap=2, mode="mincut", rule=rule, rng=0)
    transfer(tex, tex, block=6, overlap=2, rng=0)


METHOD = Method(
    name="quilt",
    summary="image quilting (Efros & Freeman): synthesize a larger texture from blocks of a sample, "
            "or transfer it onto a target",
    params=QuiltParams,
    inputs=(
        InputSpec("texture", "the sample texture image", min_side=2),
        InputSpec("target", "transfer: the picture to re-render with the texture", required=False),
        InputSpec("source_map", "transfer: the texture's correspondence map (with --target-map)", required=False),
        InputSpec("target_map", "transfer: the target's correspondence map (with --source-map)", required=False),
    ),
    run=_run,
    warm_up=warm_up,
    warm_up_in_cli=False,
    memory=memory_estimate,
    studio=Studio(
        title="Image quilting (Efros & Freeman)",
        canvas="texture",
        geometry=(Geometry(SQUARE, on=("texture",),
                           help="drag a square: the source region (blocks come only from it)"),),
        preview_inputs=("target", "target_map"), preview_params=("size",), compare=("target", "texture"),
        examples={"texture": "wood-grain", "target": "astronaut"}, rank=1),
)
