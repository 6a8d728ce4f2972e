"""Checks shared by quilting's synthesis and transfer: input sizes, and the up-front limits (time and
memory estimates)."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..errors import InvalidParameter
from ..grid import block_grid
from ..image import validate_image
from ..params import out_of_range
from .params import ITERATIVE_BLOCK, TRANSFER_BLOCK, QuiltParams, _round_half_up, synth_block, transfer_schedule

# --------------------------------------------------------------------------------------------
# checks shared by synthesis and transfer


def _check_texture(texture) -> np.ndarray:
    tex = validate_image(texture, "texture")
    return tex if tex.ndim == 3 else tex[..., None]


def _check_block_fits(block: int, tex: np.ndarray) -> None:
    h, w = tex.shape[:2]
    if block > min(h, w):
        raise out_of_range("block", block, 2, min(h, w), f"must fit in the texture, {w}x{h}", input="texture")


def _check_overlap(block: int, overlap: int) -> None:
    if overlap >= block:
        raise out_of_range("overlap", overlap, 1, block - 1, f"must be smaller than block = {block}")


def _check_tile_size(block: int, w: int, h: int) -> None:
    if min(w, h) < block:
        raise InvalidParameter(
            f"parameter 'size' = {w}x{h} is too small for a tileable output with block = {block} "
            f"(each side must be at least the block)",
            name="size",
            value=(w, h),
        )


def _finish(img: np.ndarray, channels: int) -> np.ndarray:
    img = np.ascontiguousarray(img, dtype=np.float32)
    return img[..., 0].copy() if channels == 1 else img


# --------------------------------------------------------------------------------------------
# synthesis


#: Seconds per source position per block for choosing a position and pasting (rule, cut), besides
#: the DFTs, on the 2-core reference machine (fitted by ``python -m benchmarks.estimates``).
SELECT_SECONDS_PER_POSITION = 1e-9
#: Seconds per block besides its DFTs and position choice (overlap costs, the cut, pasting, the
#: Python around them), ``SECONDS_PER_BLOCK + SECONDS_PER_BLOCK_SIDE * block``: what dominates small
#: blocks (fitted to ``python -m benchmarks.limits``, ``benchmarks/results/limits.json``).
SECONDS_PER_BLOCK = 4e-4
SECONDS_PER_BLOCK_SIDE = 1.4e-4
#: Bytes per output pixel of a job's peak memory (canvas, previous pass, correspondence maps and
#: preview copies, float32), fitted to the peak memory of ``weft quilt`` runs without the libraries'
#: share and without a transfer's two rows of spectra, which ``_check_limits`` counts separately.
BYTES_PER_OUTPUT_PIXEL = {"synthesis": 40, "transfer": 50}
#: Bytes per texture pixel: its spectra (one per channel and the correspondence map) and the
#: squared-sum maps cached per overlap shape (up to nine), float32.
BYTES_PER_SOURCE_PIXEL = 60


def estimate_seconds(
    texture_shape: tuple[int, ...], out_size: tuple[int, int], passes: list[tuple[int, int]], *, tile: bool = False
) -> float:
    """Estimated running time of quilting on the 2-core reference machine (see :mod:`weft.core.limits`).

    Each block but the first costs ``C + 1`` DFTs of the padded source (one per channel and the
    inverse; a transfer adds its correspondence and previous-pass spectra, computed on a second thread
    one row ahead, so they do not add up) plus a position choice over every source position, plus a
    fixed cost per block (:data:`SECONDS_PER_BLOCK`). Fitted by ``python -m benchmarks.limits``.

    Parameters
    ----------
    texture_shape : tuple of int
        The sample's shape (H, W[, C]).
    out_size : (int, int)
        The output's width and height.
    passes : list of (int, int)
        The (block, overlap) of each pass.
    tile : bool, default False
        A tileable output (the canvas wraps).

    Returns
    -------
    float
        Seconds.
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
        total += blocks * (
            (channels + 1) * dft
            + SELECT_SECONDS_PER_POSITION * positions
            + SECONDS_PER_BLOCK
            + SECONDS_PER_BLOCK_SIDE * block
        )
    return total


def _memory_need(
    tex_shape: tuple[int, ...], out_w: int, out_h: int, passes: list[tuple[int, int]], *, tile: bool, transfer: bool
) -> float:
    """Estimated peak bytes of quilting ``out_w`` x ``out_h`` from a texture of ``tex_shape``."""
    h, w = tex_shape[:2]
    need = (
        BYTES_PER_OUTPUT_PIXEL["transfer" if transfer else "synthesis"] * out_w * out_h + BYTES_PER_SOURCE_PIXEL * h * w
    )
    if transfer:  # two block rows of texture-sized spectra (the row in use and the one computed ahead)
        import cv2

        cols = max(len(block_grid(out_w, b, o, tile)[0]) for b, o in passes)
        need += 2 * cols * cv2.getOptimalDFTSize(h) * cv2.getOptimalDFTSize(w) * 4
    return need


def _transfer_passes(params: QuiltParams) -> list[tuple[int, int, float]]:
    """Block, overlap and alpha of each pass of a transfer with these parameters (defaults resolved)."""
    n = params.iterations
    b = params.block if params.block is not None else (TRANSFER_BLOCK if n == 1 else ITERATIVE_BLOCK)
    ov = (
        params.overlap
        if params.overlap is not None
        else max(1, min(b - 1, _round_half_up(b / 3 if n == 1 else 2 * b / 3)))
    )
    return transfer_schedule(n, block=b, overlap=ov, alpha=params.alpha)


def memory_estimate(shapes: Mapping[str, tuple[int, ...]], params: QuiltParams) -> float:
    """Estimated peak bytes of one run on inputs of these shapes (what the run's own check uses).

    Parameters
    ----------
    shapes : mapping of str to tuple of int
        Input name -> array shape.
    params : QuiltParams
        The run's parameters.

    Returns
    -------
    float
        Bytes; 0 for a random-mode synthesis, which has no such check.
    """
    tex = shapes["texture"]
    if shapes.get("target") is not None:
        out_h, out_w = shapes["target"][:2]
        passes = [(b, o) for b, o, _ in _transfer_passes(params)]
        return _memory_need(tex, out_w, out_h, passes, tile=params.tile, transfer=True)
    if params.mode == "random":
        return 0.0
    b = params.block or synth_block(tex)
    ov = params.overlap if params.overlap is not None else max(1, -(-b // 6))
    out_w, out_h = params.size if params.size is not None else (2 * tex[1], 2 * tex[0])
    return _memory_need(tex, out_w, out_h, [(b, ov)], tile=params.tile, transfer=False)


def _check_limits(
    tex: np.ndarray, out_w: int, out_h: int, passes: list[tuple[int, int]], *, tile: bool, transfer: bool
) -> None:
    """Refuse up front an output over the pixel limit, beyond available memory, or too long to quilt."""
    from ..limits import check_duration, check_memory, check_output_size

    check_output_size(out_w, out_h, "the target" if transfer else "parameter 'size'")
    h, w = tex.shape[:2]
    need = _memory_need(tex.shape, out_w, out_h, passes, tile=tile, transfer=transfer)
    check_memory(
        need,
        f"quilting {out_w}x{out_h} from a {w}x{h} texture",
        f"use a smaller {'target' if transfer else 'size'} or a smaller part of the texture",
    )
    seconds = estimate_seconds(tex.shape, (out_w, out_h), passes, tile=tile)
    blocks = sum(_blocks(out_h, out_w, b, o, tile) for b, o in passes)
    first = passes[0][0]
    what = (
        f"{'transfer' if transfer else 'quilting'} of {out_w}x{out_h} from a {w}x{h} texture "
        f"({blocks:,} blocks of {first if len(passes) == 1 else f'{first} to {passes[-1][0]}'} px"
        f"{f' in {len(passes)} passes' if len(passes) > 1 else ''})"
    )
    advice = (
        "use a larger block, fewer iterations, a smaller target or a smaller part of the texture"
        if transfer
        else "use a larger block, a smaller size or a smaller part of the texture"
    )
    check_duration(seconds, what, advice)


def _blocks(n_h: int, n_w: int, block: int, overlap: int, tile: bool) -> int:
    return len(block_grid(n_h, block, overlap, tile)[0]) * len(block_grid(n_w, block, overlap, tile)[0])
