"""Quilting synthesis, E&F §2: :func:`synthesize`."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..grid import block_grid
from ..jobs import CancelToken, Progress, ProgressReporter
from ..params import as_rng
from .checks import _check_block_fits, _check_limits, _check_overlap, _check_texture, _check_tile_size, _finish
from .engine import _Pass, _quilt_pass
from .params import QuiltParams, synth_block, synth_tol

# --------------------------------------------------------------------------------------------
# synthesis


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
        Block side B in pixels, 2..min(H, W) of the texture; default (None) 7/16 of min(H, W)
        rounded, at most 56 (:func:`weft.core.quilting.params.synth_block`).
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
        Default (None) 2, or 6 from block 48 up. Rule ``tol``: pick uniformly among the ``tol`` lowest-SSD
        positions (Ngo's ``tol``; 1 = always the best). In ``mincut`` mode the seam rule takes its place: of
        the ``4 x tol`` lowest-cost positions, the one whose minimum-error cut runs through the least error
        (``weft.core.quilting.engine.SEAM_POOL``).
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
    Beyond the paper, a block's cost has two more terms in synthesis (``weft.core.quilting.engine``):
    no block continues a neighbour's piece of the sample (``AVOID_RADIUS``), and positions whose
    sample pixels were pasted more often than the average cost more (``USAGE_WEIGHT``), so the
    output covers the whole sample.

    Ambiguities resolved: the first block of ``overlap``/``mincut`` is a random position; the
    overlap region of ``overlap`` mode is overwritten by the new block (Ngo: "will overwrite a
    portion of T_prev"); the output is quilted on a canvas of whole blocks and cropped; SSDs are
    summed over colour channels.
    """
    params = QuiltParams(
        mode=mode,
        block=block,
        overlap=overlap,
        size=size,
        tol=tol,
        rule=rule,
        epsilon=epsilon,
        tile=tile,
        poisson=poisson,
        band=band,
    )
    return _synthesize(texture, params, rng=rng, progress=progress, cancel=cancel, record=record)


def _synthesize(
    texture: np.ndarray, params: QuiltParams, *, rng=None, progress=None, cancel=None, record: dict | None = None
) -> np.ndarray:
    """:func:`synthesize` with its options in ``params`` (``None`` block and tol: the synthesis defaults)."""
    tex = _check_texture(texture)
    b = params.block or synth_block(tex.shape)
    tol = params.tol or synth_tol(b)
    if params.block is None or params.tol is None:
        params = params.replace(block=b, tol=tol)
    h, w = tex.shape[:2]
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
    p = _Pass(params.mode, b, ov, params.rule, tol, params.epsilon, params.tile, params.poisson, params.band)
    rng = as_rng(rng)
    rows = len(block_grid(out_h, b, ov if params.mode != "random" else 0, params.tile and params.mode != "random")[0])
    report = ProgressReporter(progress, "quilting", rows)
    if params.mode == "random":
        p = _Pass("random", b, 0, "tol", 1, 0.0, False, False, 1)
    img, _ = _quilt_pass(
        tex, out_h, out_w, p, rng, report=report, cancel=cancel, channels_out=tex.shape[2], record=record
    )
    return _finish(img, tex.shape[2])
