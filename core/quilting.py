"""Image quilting (Efros & Freeman 2001): texture synthesis by stitching blocks of the sample.

This module currently implements the first of the paper's three synthesis modes, *random*: blocks
of ``block x block`` pixels are copied from uniformly random positions of the texture and tiled
without overlap (the write-up's Fig. 1 left column, "random placement of blocks"). The output is
cropped to the requested size, so the last column and row of blocks may be partial.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Mapping

import numpy as np

from .image import validate_image
from .jobs import CancelToken, Progress, ProgressReporter
from .params import Params, as_rng, out_of_range, param
from .registry import InputSpec, Method, Result


@dataclass(frozen=True)
class QuiltParams(Params):
    """Parameters of image quilting (Efros & Freeman §2)."""

    mode: str = param("random", choices=("random",), help="how blocks are chosen: random = uniformly random blocks")
    block: int = param(32, lo=2, hi=1024, symbol="B", help="side of the square blocks, in pixels")
    size: tuple = param(
        None, kind="size", lo=1, hi=16384, optional=True,
        help="output size WIDTHxHEIGHT; default twice the texture's size",
    )


def synthesize(
    texture: np.ndarray,
    *,
    size: tuple[int, int] | None = None,
    block: int = 32,
    mode: str = "random",
    rng: None | int | np.random.Generator = None,
    progress: Callable[[Progress], None] | None = None,
    cancel: CancelToken | None = None,
) -> np.ndarray:
    """Synthesize a texture of ``size`` from the sample ``texture`` by quilting blocks.

    Parameters
    ----------
    texture : float32 array (H, W) or (H, W, 3) in [0, 1]
        The sample texture.
    size : (width, height), optional
        Output size in pixels (1..16384 per side). Default: twice the texture's size.
    block : int, default 32
        Block side B in pixels, 2..min(H, W) of the texture.
    mode : {"random"}
        ``random``: each block is copied from a uniformly random position (§2, first method).
    rng : None, int or numpy Generator
        The same seed gives the same pixels.
    progress, cancel
        Progress callback (called once per block row, with the partial image as preview) and
        cancel token (checked once per block row).

    Returns
    -------
    float32 array of shape (height, width[, 3]), same channel count as ``texture``.
    """
    params = QuiltParams(mode=mode, block=block, size=size)
    texture = validate_image(texture, "texture")
    h, w = texture.shape[:2]
    if params.block > min(h, w):
        raise out_of_range("block", params.block, 2, min(h, w), f"must fit in the texture, {w}x{h}")
    out_w, out_h = params.size if params.size is not None else (2 * w, 2 * h)
    rng = as_rng(rng)
    b = params.block
    out = np.zeros((out_h, out_w) + texture.shape[2:], dtype=np.float32)
    rows = -(-out_h // b)
    cols = -(-out_w // b)
    report = ProgressReporter(progress, "quilting", rows)
    # One draw of all positions up front: the sequence (and so the picture) depends on the seed only.
    ys = rng.integers(0, h - b + 1, size=(rows, cols))
    xs = rng.integers(0, w - b + 1, size=(rows, cols))
    for i in range(rows):
        if cancel is not None:
            cancel.raise_if_cancelled()
        y0 = i * b
        bh = min(b, out_h - y0)
        for j in range(cols):
            x0 = j * b
            bw = min(b, out_w - x0)
            sy, sx = ys[i, j], xs[i, j]
            out[y0:y0 + bh, x0:x0 + bw] = texture[sy:sy + bh, sx:sx + bw]
        report.update(i + 1, preview=lambda: out.copy())
    return out


def _run(inputs: Mapping[str, np.ndarray], params: QuiltParams, *, rng=None, progress=None, cancel=None) -> Result:
    texture = inputs["texture"]
    image = synthesize(
        texture, size=params.size, block=params.block, mode=params.mode,
        rng=rng, progress=progress, cancel=cancel,
    )
    h, w = image.shape[:2]
    blocks = -(-h // params.block) * -(-w // params.block)
    return Result(image, {"blocks": blocks})


METHOD = Method(
    name="quilt",
    summary="image quilting (Efros & Freeman): synthesize a larger texture from blocks of a sample",
    params=QuiltParams,
    inputs=(InputSpec("texture", "the sample texture image"),),
    run=_run,
)
