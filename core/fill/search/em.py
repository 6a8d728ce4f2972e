"""The EM iterations of the shared search: PatchMatch steps (propagation by jump flooding, random
search) improve the target patches' matches (E), then :func:`~weft.core.fill.vote.vote_mode` writes
the hole from them (M).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ...jobs import CancelToken
from ..common import percentile
from .patches import Flat, box_sum
from .vote import VOTE_STRIDE, vote_mode

__all__ = ["STEPS_FIRST", "em"]

STEPS_FIRST = (8, 4, 2, 1)  # propagation distances (px) of the first iteration (jump flooding)
_STEPS_LATER = (1,)  # ... and of the later ones (the matches are then mostly settled)
_SEARCH_SHRINK = 4  # random search radii: half the image, then / 4 down to 1
_SIGMA_PERCENTILE = 75  # the vote's weights exp(-d / 2 sigma^2), sigma^2 this percentile of d


def _try(fl: Flat, targets, act, sy, sx, dist, cy, cx, ok, bias: float = 0.0) -> None:
    """Replace the matches (``sy``, ``sx``, ``dist``) of the target patches ``act`` (whose pixels are
    ``targets``) by the candidates (``cy``, ``cx``, one per entry of ``act``) where they are allowed
    (``ok``, a whole source patch) and closer (with ``bias``: closer than ``1 + bias`` times the
    current match, the propagation of the pyramid's intermediate levels); in place."""
    hv, wv = fl.valid.shape
    # (an int64 below 0 is above any bound as a uint64: one comparison per axis)
    ok = ok & (cy.view(np.uint64) < hv) & (cx.view(np.uint64) < wv)
    i = np.flatnonzero(ok)
    k = act[i]
    ci, xi = cy[i], cx[i]
    keep = fl.valid[ci, xi] & ((ci != sy[k]) | (xi != sx[k]))
    i, k, ci, xi = i[keep], k[keep], ci[keep], xi[keep]
    if len(i) == 0:
        return
    d = fl.dist(targets[i], k, ci, xi)
    better = d < dist[k] if bias == 0.0 else d < dist[k] * (1.0 + bias)
    k = k[better]
    sy[k], sx[k], dist[k] = ci[better], xi[better], d[better]


def _search_step(
    fl: Flat,
    act: np.ndarray,
    sy: np.ndarray,
    sx: np.ndarray,
    dist: np.ndarray,
    steps: tuple[int, ...],
    gen: np.random.Generator,
    shrink: int,
    bias: float = 0.0,
) -> None:
    """One PatchMatch pass over the target patches ``act``, in place: each tries its neighbours'
    offsets ``steps`` px away (taken within ``1 + bias`` of its current distance), then random
    candidates around its match at radii from half the image down to 1 px, divided by ``shrink``."""
    hv, wv = fl.valid.shape
    aty, atx = fl.ty[act], fl.tx[act]
    targets = fl.gather(aty, atx)
    for s in steps:
        for dy, dx in ((0, s), (0, -s), (s, 0), (-s, 0)):
            ny, nx = aty + dy, atx + dx
            inside = (ny >= 0) & (ny < hv) & (nx >= 0) & (nx < wv)
            m = np.where(inside, fl.tmap[np.clip(ny, 0, hv - 1), np.clip(nx, 0, wv - 1)], -1)
            mm = np.maximum(m, 0)
            _try(fl, targets, act, sy, sx, dist, sy[mm] - dy, sx[mm] - dx, m >= 0, bias)
    r = max(hv, wv) // 2
    while r >= 1:
        ry = sy[act] + gen.integers(-r, r + 1, len(act))
        rx = sx[act] + gen.integers(-r, r + 1, len(act))
        _try(fl, targets, act, sy, sx, dist, ry, rx, np.ones(len(act), bool))
        r //= shrink


def em(
    fl: Flat,
    img: np.ndarray,
    hole: np.ndarray,
    sy: np.ndarray,
    sx: np.ndarray,
    dist: np.ndarray,
    *,
    iterations: int,
    gen: np.random.Generator,
    steps_first: tuple[int, ...],
    shrink: int,
    bias: float,
    worst: float,
    cancel: CancelToken | None,
    on_iteration: Callable[[int], object],
    last_stride: int | None = None,
    fixed: slice | None = None,
) -> None:
    """EM iterations on ``img``, improving the matches of ``fl``'s target patches and writing the hole, in place.

    Each iteration: (E) the inexact patches (a distance above 0; with ``worst``, at least that
    percentile of their distances) try their neighbours' offsets (``steps_first`` px away on the first
    iteration, then ``_STEPS_LATER``; taken within ``1 + bias`` of the current distance) and random
    candidates around their match (radii from half the image down to 1, divided by ``shrink``); (M)
    every hole pixel covered by an inexact patch is copied through the offset its covering patches
    agree on most (:func:`vote_mode`, weights ``exp(-d / 2 sigma^2)``). A patch that is an exact copy
    of its match is not searched again, and a pixel only such patches cover keeps its value.

    Parameters
    ----------
    fl : Flat
        The patches of ``img``.
    img : ndarray, float32 (H, W, C)
        The array ``fl`` views, written in place.
    hole : ndarray, bool (H, W)
    sy, sx, dist : ndarray
        The target patches' matches and distances, updated in place.
    iterations : int
    gen : numpy.random.Generator
    steps_first : tuple of int
        Propagation steps of the first iteration.
    shrink : int
        Divides the random search's radii.
    bias : float
        A neighbour's offset is taken within ``1 + bias`` of the current distance.
    worst : float
        As in :func:`refine_patchmatch`.
    cancel : CancelToken or None
    on_iteration : callable
        Called with the iteration's index after each.
    last_stride : int, optional
        The last vote's stride.
    fixed : slice, optional
        Channels the votes leave as they are (the guide).

    References
    ----------
    Barnes et al., "PatchMatch" (2009); Wexler, Shechtman & Irani, "Space-time completion of video" (2007).
    """
    p = fl.p
    changed = None
    for it in range(iterations):
        if cancel is not None:
            cancel.raise_if_cancelled()
        if changed is not None:  # the vote changed pixels: the distances of the patches over them are stale
            stale = np.nonzero(box_sum(changed, p)[fl.ty, fl.tx] > 0.5)[0]
            dist[stale] = fl.dist(fl.gather(fl.ty[stale], fl.tx[stale]), stale, sy[stale], sx[stale])
        inexact_d = dist[dist > 0.0]
        floor = percentile(inexact_d, worst) if worst > 0 and len(inexact_d) else 0.0
        act = np.nonzero(dist > 0.0)[0] if floor <= 0.0 else np.nonzero(dist >= floor)[0]
        if len(act) == 0:
            break
        _search_step(fl, act, sy, sx, dist, steps_first if it == 0 else _STEPS_LATER, gen, shrink, bias)
        dn = fl.normalized(dist)
        sigma2 = max(percentile(dn, _SIGMA_PERCENTILE), 1e-12)
        inexact = np.zeros((fl.h + p - 1, fl.w + p - 1), bool)  # pixels covered by a patch that is not an exact copy
        inexact[p - 1 + fl.ty[dist > 0.0], p - 1 + fl.tx[dist > 0.0]] = True
        stride = VOTE_STRIDE if last_stride is None or it < iterations - 1 else last_stride
        changed = vote_mode(
            img, hole & (box_sum(inexact, p) > 0.5), fl, sy, sx, np.exp(-dn / (2.0 * sigma2)), stride, fixed
        )
        on_iteration(it)
