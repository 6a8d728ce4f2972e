"""Edges continued across a hole: the guide of ``weft fill --structure`` (the ``patchmatch`` engine).

Patch search continues an edge that crosses a hole the way the patches beside it run: a curved edge
(a saucer's rim under a removed spoon) runs on straight and then turns in a corner, or drips. This
module finds the edges that enter the hole, pairs those that are two ends of one edge, joins each
pair by a smooth curve, and returns a guide: a channel that says, for every pixel, on which side of
that structure it lies and how near. The engine matches it like a colour on its coarsest level,
fixed in the hole, so a patch beside the curve must come from beside the edge, on the same side,
and the finer levels refine that layout (:func:`fill_patchmatch`'s ``guide``).

1. **Edges**: Canny on the luminance of the known pixels, smoothed by a normalized convolution
   (Gaussian, sigma ``_SMOOTH``) so the hole makes none; its thresholds are the 92nd and 75th
   percentiles of the gradient magnitude within 20 px of the hole (the strong edges of the hole's
   surroundings, whatever the picture's contrast). Pixels within 2 px of the hole are dropped.
   A weak edge is not found (a rim against dark wood of a similar luminance continues nothing).
   The luminance's gradient, not each colour channel's: the channels' found more edges, the
   shadow's among them, and the fill washed the shadow out.
2. **Entries**: every edge of at least 12 pixels that comes within 4 px of the hole enters it at its
   pixel nearest the hole, in the direction of the principal axis of its pixels within 14 px (a
   line-like piece only: the variance along the axis at least 3 times that across), pointed at
   the hole. Each side of the entry has a colour: the mean (CIE Lab, 8-bit scale; luminance on a
   grey picture) of the known pixels 2-9 px back from it and 2-5 px aside.
3. **Pairs**: two entries are one edge's two ends when each points within 60 degrees of the chord
   joining them and their sides continue each other (the first's left is the second's right, and
   the other way round, within 30 Lab units); the best pairs first (the sum of the two angles and
   the colour difference), each entry in one pair at most.
4. Each pair is **joined** by a cubic Hermite curve whose tangents are the two directions, scaled by
   the chord's length (the curve leaves and arrives along the edge, and bends as it must between).
5. The **structure** is the curves and the paired edges' pixels within ``_EDGE_REACH`` px of the
   hole (where their surroundings are the sources that matter). Its normal: on the curve, the
   curve's own; on an edge, the dominant gradient direction (the luminance's structure tensor, sigma
   2) -- unsigned, so the side does not flip where the edge's contrast does (a red rim is darker than
   the pale wood above and brighter than its shadow below: a side told by colour or by the
   gradient's sign labelled the wood beside the rim as the saucer's side, and the fill cut the
   shadow off square) -- its sign carried from the curve outward along the edge.
6. The **guide**, a channel per continued edge (at most ``_MAX_EDGES``, the best pairs): at every
   pixel the side of its nearest pixel of that edge's structure (+1 or -1) times
   ``max(0, 1 - d / reach)``, ``d`` the distance to it: 1 on the structure, 0 beyond ``reach``.
   One channel per edge, not one for all: a side is only a convention of each edge's curve, and
   near two parallel edges (a rim and its shadow's edge) one channel flips sign half-way between
   them, a band that no source beside the edges matches.

``reach`` 48 px: the wider the guide, the more of the hole knows which side of the rim it lies on;
narrower ones left thin slivers of the rim's colour beside it, wider ones held too much of the fill
to the edge. On textures the guide pairs the texture's own edges at random, so it runs only where
``patchmatch`` fills a photo's hole (``--structure auto``) or when asked (``yes``).
"""

from __future__ import annotations

from collections import deque

import cv2
import numpy as np

from .common import percentile

__all__ = ["structure_guide", "REACH"]

#: The guide's reach in px: beyond it the guide is 0 (see the module text for the measured choice).
REACH = 48
_SMOOTH = 1.5  # the luminance's smoothing before Canny
_HIGH, _LOW = 92, 75  # Canny's thresholds: these percentiles of the gradient magnitude near the hole
_RING = 20  # ... within this many px of the hole
_MARGIN = 2  # edge pixels this near the hole are dropped (the smoothing reaches across)
_MIN_EDGE = 12  # an edge shorter than this (px) enters nothing
_NEAR = 4  # an edge enters the hole when it comes this near it
_AXIS_RADIUS = 14  # an entry's direction: the principal axis of its edge's pixels within this radius
_LINE_RATIO = 3.0  # ... of a line-like piece only (variance along / across)
_MAX_ANGLE = 60.0  # a pair's entries point within this many degrees of the chord joining them
_SIDE_TOLERANCE = 30.0  # a pair's sides continue each other within this (Lab, 8-bit scale)
_EDGE_REACH = 64  # the structure's edges: their pixels within this many px of the hole
_TENSOR = 2.0  # the structure tensor's smoothing (the edges' normals)
_MAX_EDGES = 4  # at most this many edges are continued (the best pairs), a guide channel each


def structure_guide(
    image: np.ndarray, hole: np.ndarray, known: np.ndarray | None = None, *, reach: int = REACH
) -> tuple[np.ndarray | None, int]:
    """The guide of the module text for filling ``hole`` in ``image``, and the number of edges it continues.

    Parameters
    ----------
    image : ndarray, float (H, W) or (H, W, 3) in [0, 1]
        The picture (an alpha channel is not passed; values in the hole are ignored).
    hole : ndarray, bool (H, W)
        The hole.
    known : ndarray, bool (H, W), optional
        The pixels whose edges count (default: all outside the hole; a transparent region outside the
        hole is not known).
    reach : int, default REACH
        The guide's reach from the continued structure, pixels (beyond it the guide is 0).

    Returns
    -------
    guide : ndarray, float32 (H, W, n) in [-1, 1], or None
        A channel per edge (at most ``_MAX_EDGES``, the best pairs); None when no two edges entering
        the hole pair up (nothing to continue).
    n : int
    """
    hole = np.asarray(hole, dtype=bool)
    known = ~hole if known is None else (np.asarray(known, dtype=bool) & ~hole)
    if not hole.any() or not known.any():
        return None, 0
    img = np.asarray(image, dtype=np.float32)
    h, w = hole.shape
    img8 = np.clip(np.rint(np.nan_to_num(img) * 255.0), 0, 255).astype(np.uint8)
    if img8.ndim == 3:
        rgb8 = np.ascontiguousarray(img8[..., :3])
        lum = cv2.cvtColor(rgb8, cv2.COLOR_RGB2GRAY).astype(np.float32)
    else:
        rgb8 = None
        lum = img8.astype(np.float32)
    unknown = ~known
    smooth = _smooth_known(lum, known)
    edges, (gx, gy) = _edges(smooth, unknown)
    n, comp = cv2.connectedComponents(edges.astype(np.uint8), connectivity=8)
    entries = _entries(comp, n, unknown, hole)
    if len(entries) < 2:
        return None, 0
    sides = [_side_colours(rgb8, lum, p, d, known) for p, d, _ in entries]
    pairs = _pairs(entries, sides)
    if not pairs:
        return None, 0
    jxx = cv2.GaussianBlur(gx * gx, (0, 0), _TENSOR)
    jxy = cv2.GaussianBlur(gx * gy, (0, 0), _TENSOR)
    jyy = cv2.GaussianBlur(gy * gy, (0, 0), _TENSOR)
    angle = 0.5 * np.arctan2(2.0 * jxy, jxx - jyy)  # the dominant gradient direction, unsigned
    depth = cv2.distanceTransform((~hole).astype(np.uint8), cv2.DIST_L2, 3)
    channels = []
    for a, b in pairs[:_MAX_EDGES]:
        # the structure: the curve, and the paired edges near the hole
        (pa, ta, ca), (pb, tb, cb) = entries[a], entries[b]
        struct = np.zeros((h, w), bool)
        nx_ = np.zeros((h, w), np.float32)
        ny_ = np.zeros((h, w), np.float32)
        curve = _hermite(pa, ta, pb, tb)
        tang = np.gradient(curve, axis=0)
        tang /= np.maximum(np.hypot(tang[:, 0], tang[:, 1]), 1e-9)[:, None]
        xy = np.rint(curve).astype(np.int64)
        ok = (xy[:, 0] >= 0) & (xy[:, 0] < w) & (xy[:, 1] >= 0) & (xy[:, 1] < h)
        xs, ys, t = xy[ok, 0], xy[ok, 1], tang[ok]
        struct[ys, xs] = True
        nx_[ys, xs], ny_[ys, xs] = -t[:, 1], t[:, 0]
        ey, ex = np.nonzero(((comp == ca) | (comp == cb)) & (depth <= _EDGE_REACH) & ~struct)
        struct[ey, ex] = True
        nx_[ey, ex], ny_[ey, ex] = np.cos(angle[ey, ex]), np.sin(angle[ey, ex])
        reached = _orient(struct, nx_, ny_, list(zip(ys.tolist(), xs.tolist(), strict=True)))
        d, labels = cv2.distanceTransformWithLabels(
            (~reached).astype(np.uint8), cv2.DIST_L2, 5, labelType=cv2.DIST_LABEL_PIXEL
        )
        # within reach only (beyond it the guide is 0): label k (from 1) is the k-th structure
        # pixel in row-major order
        zy, zx = np.nonzero(reached)
        by, bx = np.nonzero(d < reach)
        k = labels[by, bx] - 1
        qy, qx = zy[k], zx[k]
        side = np.where((bx - qx) * nx_[qy, qx] + (by - qy) * ny_[qy, qx] >= 0, 1.0, -1.0)
        channel = np.zeros((h, w), np.float32)
        channel[by, bx] = side * (1.0 - d[by, bx] / float(reach))
        channels.append(channel)
    return np.stack(channels, axis=2), len(channels)


def _smooth_known(lum: np.ndarray, known: np.ndarray) -> np.ndarray:
    k = known.astype(np.float32)
    num = cv2.GaussianBlur(lum * k, (0, 0), _SMOOTH)
    den = cv2.GaussianBlur(k, (0, 0), _SMOOTH)
    return np.where(den > 1e-3, num / np.maximum(den, 1e-3), 0.0).astype(np.float32)


def _edges(smooth: np.ndarray, unknown: np.ndarray):
    """Canny's edges of the smoothed luminance, away from the unknown pixels, and its gradients."""
    gx = cv2.Sobel(smooth, cv2.CV_32F, 1, 0)
    gy = cv2.Sobel(smooth, cv2.CV_32F, 0, 1)
    mag = np.hypot(gx, gy)
    u8 = unknown.astype(np.uint8)
    far = cv2.dilate(u8, np.ones((2 * _MARGIN + 1,) * 2, np.uint8)) == 0
    ring = (cv2.dilate(u8, np.ones((2 * _RING + 1,) * 2, np.uint8)) > 0) & far
    if not ring.any():
        return np.zeros(unknown.shape, bool), (gx, gy)
    values = mag[ring]
    hi, lo = percentile(values, _HIGH), percentile(values, _LOW)  # (np.percentile imports numpy.ma: 7 ms)
    if hi <= 0:
        return np.zeros(unknown.shape, bool), (gx, gy)
    e = (
        cv2.Canny(
            np.ascontiguousarray(np.clip(gx, -32767, 32767).astype(np.int16)),
            np.ascontiguousarray(np.clip(gy, -32767, 32767).astype(np.int16)),
            float(lo),
            float(hi),
            L2gradient=True,
        )
        > 0
    )
    return e & far, (gx, gy)


def _entries(comp: np.ndarray, n: int, unknown: np.ndarray, hole: np.ndarray):
    """``[(point (x, y), direction (dx, dy) into the hole, component label)]``."""
    near = cv2.dilate(unknown.astype(np.uint8), np.ones((2 * _NEAR + 1,) * 2, np.uint8)) > 0
    dist = cv2.distanceTransform((~unknown).astype(np.uint8), cv2.DIST_L2, 3)
    hy, hx = np.nonzero(hole)
    out = []
    labels, counts = np.unique(comp[near & (comp > 0)], return_counts=True)
    sizes = np.bincount(comp.ravel(), minlength=n)
    for lab in labels:
        if sizes[lab] < _MIN_EDGE:
            continue
        cy, cx = np.nonzero(comp == lab)
        touch = near[cy, cx]
        j = np.argmin(np.where(touch, dist[cy, cx], np.inf))
        p = np.array([cx[j], cy[j]], float)
        sel = (cx - p[0]) ** 2 + (cy - p[1]) ** 2 <= _AXIS_RADIUS**2
        pts = np.stack([cx[sel], cy[sel]], 1).astype(float)
        if len(pts) < 5:
            continue
        c = pts - pts.mean(0)
        ev, vec = np.linalg.eigh(c.T @ c)
        if ev[1] < _LINE_RATIO * max(ev[0], 1e-6):
            continue
        d = vec[:, 1]
        q = np.argmin((hx - p[0]) ** 2 + (hy - p[1]) ** 2)
        if d @ np.array([hx[q] - p[0], hy[q] - p[1]], float) < 0:
            d = -d
        out.append((p, d, int(lab)))
    return out


def _side_colours(rgb8: np.ndarray | None, lum: np.ndarray, p: np.ndarray, t: np.ndarray, known: np.ndarray):
    """The mean colour (:func:`_lab` of ``rgb8``; ``lum`` on a grey picture) of the known pixels on
    the left and on the right of an entry (``None`` for a side without any)."""
    h, w = known.shape
    nrm = np.array([-t[1], t[0]])
    back = np.arange(2, 10, dtype=float)
    aside = np.arange(2, 6, dtype=float)
    out: list[np.ndarray | None] = []
    for sgn in (1.0, -1.0):
        pts = (
            p[None, None, :] - t[None, None, :] * back[:, None, None] + sgn * nrm[None, None, :] * aside[None, :, None]
        )
        xy = np.rint(pts.reshape(-1, 2)).astype(np.int64)
        ok = (xy[:, 0] >= 0) & (xy[:, 0] < w) & (xy[:, 1] >= 0) & (xy[:, 1] < h)
        xy = xy[ok]
        ok = known[xy[:, 1], xy[:, 0]]
        if not ok.any():
            out.append(None)
        elif rgb8 is None:
            out.append(lum[xy[ok, 1], xy[ok, 0]][:, None].mean(axis=0))
        else:
            out.append(_lab(rgb8[xy[ok, 1], xy[ok, 0]]).mean(axis=0))
    return out


def _lab(rgb8: np.ndarray) -> np.ndarray:
    """CIE Lab of (N, 3) uint8 sRGB pixels on OpenCV's 8-bit scale (L * 255 / 100, a + 128, b + 128),
    as ``cv2.cvtColor(..., COLOR_RGB2LAB)`` computes it. In numpy for the few pixels an entry's sides
    hold: OpenCV builds its tables on the first call, 67 ms of a ``weft fill`` process."""
    c = rgb8.astype(np.float64) / 255.0
    lin = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    xyz = (
        lin
        @ np.array([[0.412453, 0.357580, 0.180423], [0.212671, 0.715160, 0.072169], [0.019334, 0.119193, 0.950227]]).T
    )
    xyz /= np.array([0.950456, 1.0, 1.088754])
    f = np.where(xyz > 0.008856, np.cbrt(xyz), 7.787 * xyz + 16.0 / 116.0)
    lightness = np.where(xyz[:, 1] > 0.008856, 116.0 * f[:, 1] - 16.0, 903.3 * xyz[:, 1])
    return np.stack(
        [lightness * 255.0 / 100.0, 500.0 * (f[:, 0] - f[:, 1]) + 128.0, 200.0 * (f[:, 1] - f[:, 2]) + 128.0], axis=1
    )


def _pairs(entries, sides) -> list[tuple[int, int]]:
    cands = []
    for a in range(len(entries)):
        for b in range(a + 1, len(entries)):
            (pa, ta, _), (pb, tb, _) = entries[a], entries[b]
            chord = pb - pa
            length = float(np.hypot(*chord))
            if length < 3:
                continue
            chord = chord / length
            aa = np.degrees(np.arccos(np.clip(ta @ chord, -1, 1)))
            ab = np.degrees(np.arccos(np.clip(-tb @ chord, -1, 1)))
            if aa >= _MAX_ANGLE or ab >= _MAX_ANGLE:
                continue
            (la, ra), (lb, rb) = sides[a], sides[b]
            if la is None or ra is None or lb is None or rb is None:
                continue
            dc = max(float(np.linalg.norm(la - rb)), float(np.linalg.norm(ra - lb)))  # a's left goes on as b's right
            if dc > _SIDE_TOLERANCE:
                continue
            cands.append((aa + ab + dc, a, b))
    cands.sort()
    used: set[int] = set()
    pairs = []
    for _cost, a, b in cands:
        if a in used or b in used:
            continue
        used |= {a, b}
        pairs.append((a, b))
    return pairs


def _hermite(p0, t0, p1, t1, n: int = 400) -> np.ndarray:
    """(n, 2) points of the cubic Hermite curve from ``p0`` (leaving along ``t0``) to ``p1``
    (arriving against ``t1``, the direction pointing into the hole from there)."""
    p0 = np.asarray(p0, float)
    p1 = np.asarray(p1, float)
    length = float(np.hypot(*(p1 - p0)))
    m0, m1 = np.asarray(t0, float) * length, -np.asarray(t1, float) * length
    s = np.linspace(0.0, 1.0, n)[:, None]
    return (
        (2 * s**3 - 3 * s**2 + 1) * p0 + (s**3 - 2 * s**2 + s) * m0 + (-2 * s**3 + 3 * s**2) * p1 + (s**3 - s**2) * m1
    )


def _orient(struct: np.ndarray, nx_: np.ndarray, ny_: np.ndarray, seeds) -> np.ndarray:
    """Flip the normals of the structure's pixels, breadth first from the ``seeds`` (the curves'
    pixels, whose normals are signed), so each agrees with the pixel it was reached from; in place.
    Returns the pixels reached (a piece of edge the curves do not reach is dropped)."""
    h, w = struct.shape
    done = np.zeros((h, w), bool)
    queue: deque[tuple[int, int]] = deque()
    for y, x in seeds:
        if not done[y, x]:
            done[y, x] = True
            queue.append((y, x))
    while queue:
        y, x = queue.popleft()
        for yy in (y - 1, y, y + 1):
            for xx in (x - 1, x, x + 1):
                if 0 <= yy < h and 0 <= xx < w and struct[yy, xx] and not done[yy, xx]:
                    if nx_[yy, xx] * nx_[y, x] + ny_[yy, xx] * ny_[y, x] < 0:
                        nx_[yy, xx] = -nx_[yy, xx]
                        ny_[yy, xx] = -ny_[yy, xx]
                    done[yy, xx] = True
                    queue.append((yy, xx))
    return done
