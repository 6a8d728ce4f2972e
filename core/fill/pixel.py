"""The coherent pixel filler (Ashikhmin 2001, "Synthesizing natural textures", with the hole's
neighbourhood as the constraint): one pixel at a time, from the hole's edge inwards.

The hole's pixels are visited in onion order (by distance to the known region, then scan order;
:func:`weft.core.fill.common.onion_order`), so every pixel has valued neighbours when its turn
comes. Its candidates are Ashikhmin's coherent ones -- each filled neighbour's source position
shifted by the offset between the two pixels, which continues the copied patch -- plus
``RANDOM_CANDIDATES`` random source positions (how a new patch starts, and the only candidates next to
known pixels). Each is scored by the mean squared difference over the valued pixels (known and
filled, all channels) of the ``n x n`` neighbourhood, and the cheapest is copied. Source positions
are those whose whole ``n x n`` window lies in the source region. The per-pixel loop is a numba
kernel (``weft.core._kernels.fill_pixel``).
"""

from __future__ import annotations

import numpy as np

from ..params import as_rng
from .common import Progress, check_engine_args, onion_order, whole_patches

#: Default neighbourhood side of the pixel engine.
NEIGHBOURHOOD = 7
#: Random candidates per pixel besides the coherent ones.
RANDOM_CANDIDATES = 48
_CHUNK = 2048


def fill_pixel(image, hole, source=None, *, patch=NEIGHBOURHOOD, rng=0, progress=None, cancel=None) -> np.ndarray:
    """Fill ``hole`` of ``image`` pixel by pixel from ``source`` (default: the known pixels).

    Same arguments and guarantees as :func:`weft.core.fill.quilt.fill_quilt`; ``patch`` is the
    neighbourhood side ``n`` (odd; an even one is used as ``n + 1``, which must fit the source). ``cancel`` is checked every
    2048 pixels.
    """
    if isinstance(patch, (int, np.integer)) and not isinstance(patch, bool):
        patch = int(patch) | 1  # odd: a centred window
    img, hole, src = check_engine_args(image, hole, source, patch, "pixel")
    shape = np.shape(image)
    from .._kernels import fill_pixel as _k

    r = int(patch) // 2
    n = 2 * r + 1
    h, w, c = img.shape
    canvas = img.copy()
    canvas[hole] = 0.0
    valid = np.zeros((h, w), dtype=bool)
    whole = whole_patches(src, n)
    valid[r:r + whole.shape[0], r:r + whole.shape[1]] = whole  # centre positions
    have = ~hole
    pos = np.full((h, w, 2), -1, dtype=np.int64)
    order = onion_order(hole)
    state = np.array([as_rng(rng).integers(1, 2**63, dtype=np.uint64)], dtype=np.uint64)
    report = Progress(progress, cancel, len(order))
    report(0)
    for start in range(0, len(order), _CHUNK):
        stop = min(len(order), start + _CHUNK)
        _k.fill_pixels(canvas, have, pos, img, valid, order, start, stop, r, RANDOM_CANDIDATES, state)
        report(stop)
    out = img.copy()
    out[hole] = canvas[hole]
    return out.reshape(shape)
