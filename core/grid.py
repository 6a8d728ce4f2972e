"""The block layout shared by the patch-based methods (quilting, NFPT): where blocks start along
one axis and how they overlap."""

from __future__ import annotations


def block_grid(n: int, block: int, overlap: int, tile: bool) -> tuple[list[int], list[int], list[int], int]:
    """Block starts along one axis, the overlaps before/after each block, and the canvas length.

    Without ``tile`` the blocks step by ``block - overlap`` and the canvas is cropped to ``n``
    afterwards. With ``tile`` the canvas is exactly ``n`` and wraps: ``k = ceil(n / step)`` blocks
    start at ``round(j n / k)``, so their overlaps are ``overlap`` or a pixel more, and the last
    block overlaps the first one by its ``after`` width.

    Parameters
    ----------
    n : int
        The output's length along this axis, pixels.
    block : int
        The block side, pixels.
    overlap : int
        The overlap between neighbouring blocks, 0..block-1.
    tile : bool
        Whether the output wraps around (a tileable result).

    Returns
    -------
    starts, before, after : list of int
        Each block's first pixel, its overlap with the previous block and (``tile`` only, else 0)
        with the next one across the wrap.
    length : int
        The canvas length the blocks cover (``n`` with ``tile``, else at least ``n``).

    References
    ----------
    Efros & Freeman, "Image quilting for texture synthesis and transfer" (2001), §2.1 (blocks
    stepping by block - overlap in raster order).
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
