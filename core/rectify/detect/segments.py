"""Segments for the suggestion: LSD line segments, segments joining the texture's repeats, and
segments chained into whole lines (:mod:`weft.core.rectify.detect`)."""

from __future__ import annotations

import math

import cv2
import numpy as np

__all__ = ["work_grey", "line_segments", "repeat_segments", "homogeneous", "chains", "WORK_SIDE", "LSD_SCALE"]

WORK_SIDE = 720  # longer side (px) of the reduced photo the segments are found on
LSD_SCALE = 0.8  # LSD's own Gaussian reduction of the work image (its default)
REPEAT_FEATURES = 500  # SIFT features the repeats are matched among
MIN_LENGTH = 1 / 120  # the shortest segment kept, as a fraction of the work image's longer side


def work_grey(photo: np.ndarray, side: int | None = None) -> tuple[np.ndarray, float]:
    """The photo as 8-bit grey, reduced so its longer side is at most ``side`` (default
    :data:`WORK_SIDE`); the factor."""
    grey = photo if photo.ndim == 2 else cv2.cvtColor(photo, cv2.COLOR_RGB2GRAY)
    h, w = grey.shape
    k = min(1.0, (side or WORK_SIDE) / max(h, w))
    if k < 1.0:
        grey = cv2.resize(grey, (max(1, round(w * k)), max(1, round(h * k))), interpolation=cv2.INTER_AREA)
    return np.clip(grey * 255.0 + 0.5, 0, 255).astype(np.uint8), k


def line_segments(grey: np.ndarray) -> np.ndarray:
    """(N, 4) segments found by LSD, at least :data:`MIN_LENGTH` of the longer side (and 6 pixels) long."""
    lsd = cv2.createLineSegmentDetector(cv2.LSD_REFINE_STD, LSD_SCALE)
    found = lsd.detect(grey)[0]
    if found is None:
        return np.zeros((0, 4))
    seg = found.reshape(-1, 4).astype(np.float64)
    length = np.hypot(seg[:, 2] - seg[:, 0], seg[:, 3] - seg[:, 1])
    return seg[length >= max(6.0, max(grey.shape) * MIN_LENGTH)]


def repeat_segments(grey: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Segments joining SIFT features to their repeats elsewhere in the photo (similar descriptor,
    scale and orientation), at least three feature sizes apart."""
    sift = cv2.SIFT_create(nfeatures=REPEAT_FEATURES)
    kps, desc = sift.detectAndCompute(grey, None)
    if desc is None or len(kps) < 20:
        return np.zeros((0, 4))
    pts = np.array([k.pt for k in kps])
    size = np.array([k.size for k in kps])
    ang = np.radians([k.angle for k in kps])
    matcher = cv2.BFMatcher(cv2.NORM_L2)
    knn = matcher.knnMatch(desc, desc, k=5)
    pairs, dists = [], []
    for row in knn:
        for m in row[1:]:
            pairs.append((m.queryIdx, m.trainIdx))
            dists.append(m.distance)
    if not pairs:
        return np.zeros((0, 4))
    pairs, dists = np.array(pairs), np.array(dists)
    i, j = pairs[:, 0], pairs[:, 1]
    gap = np.hypot(*(pts[i] - pts[j]).T)
    turn = np.abs(np.angle(np.exp(1j * (ang[i] - ang[j]))))
    keep = (
        (i < j)
        & (gap > 3 * np.maximum(size[i], size[j]))
        & (turn < math.radians(20))
        & (np.abs(np.log(size[i] / size[j])) < 0.3)
        & (dists < np.quantile(dists, 0.3))
    )
    return np.column_stack([pts[i[keep]], pts[j[keep]]])


def homogeneous(seg: np.ndarray) -> np.ndarray:
    p = np.column_stack([seg[:, :2], np.ones(len(seg))])
    q = np.column_stack([seg[:, 2:], np.ones(len(seg))])
    ln = np.cross(p, q)
    return ln / np.hypot(ln[:, 0], ln[:, 1])[:, None]


def chains(seg: np.ndarray, px: float, tol: float = 1.2) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The segments joined into whole lines: two segments are links of one line when each one's end
    points lie within ``tol`` work pixels of the other's line and the gap between them is at most
    twice the longer one (links chain along a line: a joint broken at every brick, a checkerboard's
    edge); each line is fitted to its segments' end points. Returns (K, 3) lines, their lengths and
    their centres. A long line's direction is known far better than its pieces' (short segments
    cut at corners lean towards the corners)."""
    n = len(seg)
    lines = homogeneous(seg)
    p, q = seg[:, :2], seg[:, 2:]
    d = q - p
    length = np.hypot(d[:, 0], d[:, 1])
    from scipy.sparse import coo_matrix  # (here: importing the studio's methods need not load SciPy)
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    ends = np.vstack([p, q])
    reach = 2.0 * np.percentile(length, 90)
    pairs = cKDTree(ends).query_pairs(reach, output_type="ndarray")
    i, j = pairs[:, 0] % n, pairs[:, 1] % n
    keep = i != j
    i, j = i[keep], j[keep]
    gap = np.hypot(*(ends[pairs[keep, 0]] - ends[pairs[keep, 1]]).T)
    near = gap <= 2 * np.maximum(length[i], length[j])
    i, j = i[near], j[near]

    def off(a, b):  # how far b's end points lie from a's line
        return np.maximum(
            np.abs(np.einsum("ij,ij->i", lines[a, :2], p[b]) + lines[a, 2]),
            np.abs(np.einsum("ij,ij->i", lines[a, :2], q[b]) + lines[a, 2]),
        )

    link = np.maximum(off(i, j), off(j, i)) <= tol * px
    linked = coo_matrix((np.ones(int(link.sum())), (i[link], j[link])), shape=(n, n))
    count, label = connected_components(linked, directed=False)
    lab = np.concatenate([label, label])
    pts = np.vstack([p, q])
    w = np.concatenate([length, length])

    def total(values):
        return np.bincount(lab, weights=values, minlength=count)

    wsum = total(w)
    c = np.column_stack([total(w * pts[:, 0]), total(w * pts[:, 1])]) / wsum[:, None]
    rel = pts - c[lab]
    cxx, cyy, cxy = total(w * rel[:, 0] ** 2), total(w * rel[:, 1] ** 2), total(w * rel[:, 0] * rel[:, 1])
    theta = 0.5 * np.arctan2(2 * cxy, cxx - cyy)  # each line's direction (principal axis)
    u = np.column_stack([np.cos(theta), np.sin(theta)])
    proj = np.einsum("ij,ij->i", rel, u[lab])
    hi = np.full(count, -np.inf)
    lo = np.full(count, np.inf)
    np.maximum.at(hi, lab, proj)
    np.minimum.at(lo, lab, proj)
    normal = np.column_stack([-u[:, 1], u[:, 0]])
    out = np.column_stack([normal, -np.einsum("ij,ij->i", normal, c)])
    return out, hi - lo, c + u * ((hi + lo) / 2)[:, None]


def refine_segments(
    grey: np.ndarray, seg: np.ndarray, reach: float, samples: int = 24, trim: float = 0.15
) -> np.ndarray:
    """The segments ``seg`` (photo pixels) refitted on the photo's own pixels: along each segment,
    away from its ends (``trim`` of its length each side: where two edges meet at a corner the edge
    bends), the sub-pixel peak of the gradient across it within ``reach`` pixels; a line fitted to
    the peaks by total least squares, the end points projected onto it. A segment found on a
    reduced photo knows its direction to about a reduced pixel over its length; at full resolution
    the many peaks fix it better. A segment with fewer than half its peaks found is kept as it was.
    ``grey`` is the photo in grey (float32, full resolution)."""
    if len(seg) == 0:
        return seg
    gx = cv2.Sobel(grey, cv2.CV_32F, 1, 0, ksize=3)
    gy = cv2.Sobel(grey, cv2.CV_32F, 0, 1, ksize=3)
    p, q = seg[:, :2], seg[:, 2:]
    d = q - p
    length = np.maximum(np.hypot(d[:, 0], d[:, 1]), 1e-9)
    u = d / length[:, None]
    nrm = np.column_stack([-u[:, 1], u[:, 0]])
    t = np.linspace(trim, 1.0 - trim, samples)
    offs = np.arange(-math.ceil(reach * 2), math.ceil(reach * 2) + 1) / 2.0  # half-pixel steps
    base = p[:, None, :] + t[None, :, None] * d[:, None, :]  # (N, S, 2)
    pts = base[:, :, None, :] + offs[None, None, :, None] * nrm[:, None, None, :]  # (N, S, O, 2)
    mx = pts[..., 0].astype(np.float32).reshape(len(seg), -1)
    my = pts[..., 1].astype(np.float32).reshape(len(seg), -1)
    sx = cv2.remap(gx, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
    sy = cv2.remap(gy, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
    mag = np.abs(sx * nrm[:, 0:1].astype(np.float32) + sy * nrm[:, 1:2].astype(np.float32))
    mag = mag.reshape(len(seg), samples, len(offs))
    k = np.argmax(mag, axis=2)
    inner = (k > 0) & (k < len(offs) - 1)
    kc = np.clip(k, 1, len(offs) - 2)
    a = np.take_along_axis(mag, (kc - 1)[..., None], 2)[..., 0]
    b = np.take_along_axis(mag, kc[..., None], 2)[..., 0]
    c = np.take_along_axis(mag, (kc + 1)[..., None], 2)[..., 0]
    den = a - 2 * b + c
    frac = np.where(den < -1e-9, 0.5 * (a - c) / np.where(den < -1e-9, den, -1.0), 0.0)
    off = offs[kc] + 0.5 * np.clip(frac, -1, 1)
    peak = base + off[..., None] * nrm[:, None, :]  # (N, S, 2)
    w = np.where(inner, b, 0.0)
    ok = inner.sum(axis=1) >= samples // 2
    wsum = np.maximum(w.sum(axis=1), 1e-12)
    c0 = np.einsum("ns,nsk->nk", w, peak) / wsum[:, None]
    rel = peak - c0[:, None, :]
    cxx = np.einsum("ns,ns->n", w, rel[..., 0] ** 2)
    cyy = np.einsum("ns,ns->n", w, rel[..., 1] ** 2)
    cxy = np.einsum("ns,ns->n", w, rel[..., 0] * rel[..., 1])
    theta = 0.5 * np.arctan2(2 * cxy, cxx - cyy)
    v = np.column_stack([np.cos(theta), np.sin(theta)])
    v *= np.sign(np.einsum("ij,ij->i", v, u))[:, None]
    new_p = c0 + np.einsum("ij,ij->i", p - c0, v)[:, None] * v
    new_q = c0 + np.einsum("ij,ij->i", q - c0, v)[:, None] * v
    turn = np.einsum("ij,ij->i", v, u)
    ok &= turn > math.cos(math.radians(10.0))  # a refit far from the segment found something else
    out = seg.copy()
    out[ok] = np.column_stack([new_p, new_q])[ok]
    return out
