"""Choosing among fills of one hole: ``auto`` runs the hybrid engine with two block sides on a hole
(not on an uncrop, where the small block costs several times the time) and keeps the fill that
looks most like the picture.

A large block (:data:`weft.core.fill.hybrid.BLOCK`) keeps a texture's large structure in one
verbatim copy; a small one (:data:`SMALL_BLOCK`) matches a hole's edge more closely where the
picture changes within a block (a rim, a gradient, lit and shaded sides). Which one wins depends on
the picture, and neither does on most pictures, so both run and the fill with the lower
:func:`score` is kept: Wexler et al.'s global coherence (the mean distance of the patches touching
the hole to their nearest source patch, the objective their EM lowers), raised by how far the
fill's detail strays from that of the known pixels around it (a smear, or a block of busier
texture than its surroundings, can be coherent patch by patch).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import cv2
import numpy as np

from .common import whole_patches
from .search import coherence

#: The second block side ``auto`` tries with the hybrid engine (the quilt engine's default).
SMALL_BLOCK = 24
#: The known pixels within this many px of the hole (beyond 2 px) give the detail a fill should have.
DETAIL_RING = 16


def _gradient(image: np.ndarray) -> np.ndarray:
    """The luminance gradient magnitude (central differences) of (H, W) or (H, W, C) ``image``."""
    grey = image if image.ndim == 2 else image[..., :3].mean(axis=2)
    gy, gx = np.gradient(np.asarray(grey, dtype=np.float32))
    return np.hypot(gx, gy)


def score(filled: np.ndarray, hole: np.ndarray, source: np.ndarray, rng=0) -> float:
    """How unlike its picture the fill of ``hole`` in ``filled`` is (lower is better): the
    :func:`~weft.core.fill.search.coherence` of the fill against the whole 7x7 patches of ``source``,
    times ``1 + |ln(detail)|``, ``detail`` the mean gradient magnitude in the hole (more than 2 px
    inside it) over that of the known pixels from 2 to :data:`DETAIL_RING` px around it.

    References
    ----------
    Wexler, Shechtman & Irani, "Space-Time Completion of Video", PAMI 29(3), 2007, §3 (global
    coherence).
    """
    hole = np.asarray(hole, dtype=bool)
    cross = cv2.getStructuringElement(cv2.MORPH_CROSS, (3, 3))
    h8 = hole.astype(np.uint8)
    inner = cv2.erode(h8, cross, iterations=2, borderType=cv2.BORDER_CONSTANT, borderValue=1) > 0
    if not inner.any():
        inner = hole
    grown = cv2.dilate(h8, cross, iterations=2) > 0
    ring = (cv2.dilate(h8, cross, iterations=DETAIL_RING) > 0) & ~grown
    beyond = source & ~grown  # the source less the blend band, which a fill may have changed
    base = coherence(filled, hole, beyond if whole_patches(beyond, 7).any() else source, rng=rng)
    g = _gradient(filled)
    known = float(g[ring].mean()) if ring.any() else 0.0
    if known <= 0.0:
        return base
    detail = max(float(g[inner].mean()) / known, 1e-3)
    return base * (1.0 + abs(math.log(detail)))


def best_of(
    run: Callable[[int, int], np.ndarray], patches: Sequence[int], hole: np.ndarray, source: np.ndarray, rng=0
) -> tuple[np.ndarray, int]:
    """``(fill, patch)``: the fill of ``run(patch, i)`` (the ``i``-th of ``patches``) with the lowest
    :func:`score` (the first on a tie); a single patch runs once and is not scored."""
    if len(patches) == 1:
        return run(patches[0], 0), patches[0]
    fills = [run(patch, i) for i, patch in enumerate(patches)]
    scores = [score(filled, hole, source, rng) for filled in fills]
    i = int(np.argmin(scores))
    return fills[i], patches[i]
