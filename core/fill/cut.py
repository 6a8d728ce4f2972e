"""The quilting engine's minimum-error cut and the blend band's Poisson solve in numpy: a fill with
the default engine then never loads numba (its import and cache loads were ~0.5 s of a 0.7 s
``weft fill`` on a quiet machine, more under load), and the blocks and bands are small enough for
vectorised numpy.

* :func:`min_cut` -- E&F's dynamic-programming cut through each overlap strip of a block, one path
  per side (the new region is the intersection of the sides' new halves), as
  :func:`weft.core.seams.min_cut_mask` with its separate right and bottom paths; path pixels are new.
* :func:`poisson_cg` -- conjugate gradient on the Poisson system of a pixel set, all channels at
  once, the same system as ``weft.core._kernels.poisson.poisson_cg``.
"""

from __future__ import annotations

import numpy as np

from ..seams import accumulated_costs


def _vertical_paths(err: np.ndarray) -> np.ndarray:
    """Column of the least-error 8-connected top-to-bottom path in every row of each ``err[k]``
    ((k, h, w) -> (k, h)): the k strips' dynamic programmes run together, one numpy step per row
    (a block's up to four overlap strips in one pass); the path is traced back in plain Python on
    the accumulated costs (a strip is a few columns wide: numpy's per-call cost was 60 % of a cut).
    Ties: the lowest column, as ``np.argmin``."""
    k, h, w = err.shape
    acc = accumulated_costs(err)
    path = np.empty((k, h), dtype=np.int64)
    for s, rows in enumerate(acc.tolist()):
        x = min(range(w), key=rows[0].__getitem__)  # the first minimum
        out = [x]
        for y in range(1, h):
            r = rows[y]
            best = x - 1 if x > 0 else 0
            for xx in range(best + 1, min(x + 2, w)):
                if r[xx] < r[best]:
                    best = xx
            x = best
            out.append(x)
        path[s] = out
    return path


def _vertical_path(err: np.ndarray) -> np.ndarray:
    """Column of the least-error 8-connected top-to-bottom path in every row of ``err`` (h, w)."""
    return _vertical_paths(np.asarray(err)[None])[0]


def min_cut(err: np.ndarray, *, left: int = 0, top: int = 0, right: int = 0, bottom: int = 0) -> np.ndarray:
    """Where the new block shows after the minimum error boundary cut through its overlap strips.

    The strips of one shape (all four on a square block with equal overlaps) are cut in one pass.

    Parameters
    ----------
    err : ndarray, (h, w)
        The squared difference between the block and the canvas.
    left, top, right, bottom : int, default 0
        The widths of the overlap strips (0: none on that side).

    Returns
    -------
    ndarray, bool (h, w)

    References
    ----------
    Efros & Freeman, "Image quilting for texture synthesis and transfer" (2001), §2.1.
    """
    h, w = err.shape
    new = np.ones((h, w), dtype=bool)
    cols = np.arange(w)[None, :]
    rows = np.arange(h)[:, None]
    strips = []  # (side, strip as a top-to-bottom (rows, cols) array)
    if left > 0:
        strips.append(("left", err[:, :left]))
    if right > 0:
        strips.append(("right", err[:, w - right :]))
    if top > 0:
        strips.append(("top", err[:top, :].T))
    if bottom > 0:
        strips.append(("bottom", err[h - bottom :, :].T))
    paths = {}
    for shape in dict.fromkeys(s.shape for _, s in strips):
        group = [(side, s) for side, s in strips if s.shape == shape]
        for (side, _), path in zip(group, _vertical_paths(np.stack([s for _, s in group])), strict=True):
            paths[side] = path
    if left > 0:
        new &= cols >= paths["left"][:, None]
    if right > 0:
        new &= cols <= (paths["right"] + (w - right))[:, None]
    if top > 0:
        new &= rows >= paths["top"][None, :]
    if bottom > 0:
        new &= rows <= (paths["bottom"] + (h - bottom))[None, :]
    return new


def poisson_cg(
    nbr: np.ndarray, ndeg: np.ndarray, rhs: np.ndarray, x: np.ndarray, tol: float, max_iter: int
) -> np.ndarray:
    """Solve the discrete Poisson equation ``ndeg_p x_p - sum_{q in nbr_p} x_q = rhs_p`` by conjugate gradients.

    Parameters
    ----------
    nbr : ndarray, int (n, 4)
        Each unknown's neighbours (-1: none).
    ndeg : ndarray, (n,)
        Each unknown's neighbour count.
    rhs : ndarray, (n, C)
        The right-hand side, per channel.
    x : ndarray, (n, C)
        The start, overwritten with the solution.
    tol : float
        Stop at ``||r|| <= tol ||rhs||``.
    max_iter : int
        Most iterations.

    Returns
    -------
    ndarray, (n, C)
        ``x``.

    References
    ----------
    Pérez, Gangnet & Blake, "Poisson image editing" (2003).
    """
    n, c = rhs.shape
    idx = np.where(nbr >= 0, nbr, n)  # row n is a zero row

    def apply(v: np.ndarray) -> np.ndarray:
        ext = np.vstack([v, np.zeros((1, c))])
        return ndeg[:, None] * v - ext[idx].sum(axis=1)

    bnorm = np.sqrt((rhs * rhs).sum(axis=0))
    bnorm[bnorm == 0] = 1.0
    r = rhs - apply(x)
    p = r.copy()
    rr = (r * r).sum(axis=0)
    for _ in range(max_iter):
        if np.all(np.sqrt(rr) <= tol * bnorm):
            break
        ap = apply(p)
        pap = (p * ap).sum(axis=0)
        a = np.where(pap > 0, rr / np.where(pap > 0, pap, 1.0), 0.0)
        x += a * p
        r -= a * ap
        rr_new = (r * r).sum(axis=0)
        beta = np.where(rr > 0, rr_new / np.where(rr > 0, rr, 1.0), 0.0)
        rr = rr_new
        p = r + beta * p
    return x
