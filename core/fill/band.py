"""The blend band around a filled hole: a Poisson solve that spreads the step at the hole's edge.

The only place where known pixels may change. The band is every pixel within ``band`` pixels
(8-connected steps, i.e. a ``(2 band + 1)``-square neighbourhood) of the hole's edge, on both sides:
known pixels up to ``band`` px outside the hole and filled pixels up to ``band`` px inside it. On
the band, the image is re-solved (Pérez et al.'s Poisson equation, the system of
:func:`weft.core.blending.poisson_blend`, solved by conjugate gradient in numpy,
:func:`weft.core.fill.cut.poisson_cg`) with the pixels
around the band as fixed (Dirichlet) values and, as the guidance field, the image's own gradients
-- except across the hole's edge, where the difference between a known and a filled pixel (the
seam) is replaced by the mean of the differences one step further on either side (the local slope
continued). So the texture's detail inside the band is kept and the seam's step is spread evenly
over the band's ``2 band`` pixels. Only the part of a step beyond ``STEP`` times the texture's own
mean step between known neighbours in the band is replaced: a seam the quilting cut already hid is
left as it is (spreading every step smoothed the texture at the edge).
``band = 0`` changes nothing outside the hole.
"""

from __future__ import annotations

import cv2
import numpy as np

_STEPS = ((1, 0), (-1, 0), (0, 1), (0, -1))
#: Only the part of a seam's step beyond STEP times the texture's own mean step (between known
#: 4-neighbours in the band) is spread; 0 = every step.
STEP = 2.0


def band_region(hole: np.ndarray, band: int, exclude: np.ndarray | None = None) -> np.ndarray:
    """The pixels the blend band may change (see the module docstring).

    Parameters
    ----------
    hole : ndarray, bool (H, W)
        The hole.
    band : int
        The band's width around the hole, pixels.
    exclude : ndarray, bool (H, W), optional
        Pixels never changed (transparent ones).

    Returns
    -------
    ndarray, bool (H, W)
    """
    if band <= 0 or not hole.any():
        return np.zeros(hole.shape, dtype=bool)
    k = np.ones((2 * band + 1, 2 * band + 1), np.uint8)
    h8 = hole.astype(np.uint8)
    outer = cv2.dilate(h8, k, borderType=cv2.BORDER_CONSTANT, borderValue=0) > 0
    inner = cv2.erode(h8, k, borderType=cv2.BORDER_CONSTANT, borderValue=1) > 0
    ring = outer & ~inner
    if exclude is not None:
        ring &= ~exclude
    return ring


def blend_band(
    image: np.ndarray, hole: np.ndarray, band: int, exclude: np.ndarray | None = None, written: np.ndarray | None = None
) -> np.ndarray:
    """``image`` with its band around ``hole`` re-solved; every other pixel is returned bit for bit.

    The seam is where written meets unwritten pixels, so that is where the step is spread: with the
    hole's edge alone, a cut that ran through the band would leave its step at the band's outer rows,
    kept as the image's own gradient.

    Parameters
    ----------
    image : ndarray, float32 (H, W, C)
        The filled image.
    hole : ndarray, bool (H, W)
        The hole.
    band : int
        The band's width, pixels.
    exclude : ndarray, bool (H, W), optional
        Pixels never changed (transparent ones).
    written : ndarray, bool (H, W), optional
        The pixels the engine wrote (default ``hole``): the hole and the band's known pixels its cut
        ran through.

    Returns
    -------
    ndarray, float32 (H, W, C)

    References
    ----------
    Pérez, Gangnet & Blake, "Poisson image editing" (2003), as in the quilting write-up's "Poisson
    Blending".
    """
    ring = band_region(hole, band, exclude)
    seam = hole if written is None else (np.asarray(written, dtype=bool) | hole)
    if not ring.any() or ring.all():
        return image
    # the solve reads the ring and pixels up to 2 px from it: it runs on that box alone (a small hole
    # in a 4096² picture: the whole-picture differences took 0.6 s)
    ry, rx = np.nonzero(ring)
    box = (slice(max(0, ry.min() - 2), ry.max() + 3), slice(max(0, rx.min() - 2), rx.max() + 3))
    out = image.copy()
    out[box] = _solve(image[box], ring[box], seam[box])
    return out


def _solve(image: np.ndarray, ring: np.ndarray, seam: np.ndarray) -> np.ndarray:
    """:func:`blend_band`'s Poisson solve of ``ring`` in ``image`` (every pixel the solve reads lies in
    ``image``), the seam between ``seam`` and the other pixels: ``image`` with the ring re-solved."""
    h, w, c = image.shape
    f = image.astype(np.float64)
    ys, xs = np.nonzero(ring)
    n = len(ys)
    index = np.full((h, w), -1, dtype=np.int64)
    index[ys, xs] = np.arange(n)
    nbr = np.full((n, 4), -1, dtype=np.int64)
    ndeg = np.zeros(n)
    rhs = np.zeros((n, c))

    def at(yy, xx):
        ok = (yy >= 0) & (yy < h) & (xx >= 0) & (xx < w)
        return ok, np.clip(yy, 0, h - 1), np.clip(xx, 0, w - 1)

    # the texture's own step size: the mean absolute difference between 4-neighbours in the band
    scale = 0.0
    if STEP > 0:
        dyy = np.abs(np.diff(f, axis=0)).mean(axis=2)
        dxx = np.abs(np.diff(f, axis=1)).mean(axis=2)
        known_y = ~seam[1:] & ~seam[:-1] & ring[1:]
        known_x = ~seam[:, 1:] & ~seam[:, :-1] & ring[:, 1:]
        vals = np.concatenate([dyy[known_y], dxx[known_x]])
        scale = float(vals.mean()) if vals.size else 0.0
    for k, (dy, dx) in enumerate(_STEPS):
        qy, qx = ys + dy, xs + dx
        valid, qyc, qxc = at(qy, qx)
        g = f[ys, xs] - f[qyc, qxc]
        cross = valid & (seam[ys, xs] != seam[qyc, qxc])
        if cross.any():  # the seam: continue the slope of both sides instead
            by_ok, byy, bxx = at(ys - dy, xs - dx)  # one step back on p's side
            fy_ok, fyy, fxx = at(qy + dy, qx + dx)  # one step on q's side
            by_ok &= seam[byy, bxx] == seam[ys, xs]
            fy_ok &= seam[fyy, fxx] == seam[qyc, qxc]
            back = f[byy, bxx] - f[ys, xs]
            fwd = f[qyc, qxc] - f[fyy, fxx]
            wsum = (by_ok.astype(np.float64) + fy_ok)[:, None]
            slope = (back * by_ok[:, None] + fwd * fy_ok[:, None]) / np.maximum(wsum, 1.0)
            if STEP > 0:  # only the part of the step beyond the texture's own variation is spread
                excess = g - slope
                keep = np.clip(excess, -STEP * scale, STEP * scale)
                slope = slope + keep
            g = np.where(cross[:, None], slope, g)
        i = np.nonzero(valid)[0]
        ndeg[i] += 1
        rhs[i] += g[i]
        j = index[qyc[i], qxc[i]]
        inside = j >= 0
        nbr[i[inside], k] = j[inside]
        outside = i[~inside]
        rhs[outside] += f[qyc[outside], qxc[outside]]
    x = f[ys, xs].copy()
    from .cut import poisson_cg  # numpy: a band is small, and a fill then loads no numba

    poisson_cg(nbr, ndeg, rhs, x, 1e-6, int(20 * np.sqrt(n)) + 200)
    out = image.copy()
    out[ys, xs] = np.clip(x, 0.0, 1.0).astype(np.float32)
    return out
