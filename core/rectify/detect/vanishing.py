"""Vanishing points of two families of segments (:mod:`weft.core.rectify.detect`): RANSAC over
pairs of segments, refinement on the angles over whole lines, the compatibility of two points with a
camera that sees their directions as perpendicular."""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from .segments import chains, homogeneous

__all__ = [
    "Families",
    "two_families",
    "refine_point",
    "focal_sq",
    "direction_at",
    "INLIER_DEG",
    "MIN_FAMILY",
    "MIN_FOCAL",
    "MIN_SPREAD_DEG",
]

INLIER_DEG = 1.5  # a segment supports a vanishing point when it points at it within this angle
MIN_FAMILY = 5  # segments a family needs
MIN_SPREAD_DEG = 15.0  # the two families must differ by this much in direction in the photo
MAX_FOCAL = 10.0  # in half longer sides: beyond it the vanishing points barely converge and leave f open
MIN_FOCAL = 0.5  # in half longer sides: a shorter focal length than this is no camera's (a 9 mm lens on 35 mm film)
THIRD_FAMILY = 0.5  # a third family with this much of the weaker one's support makes the pair ambiguous ...
BALANCED = 0.4  # ... when the weaker one has this much of the stronger one's (a lattice of cells)
_CANDIDATES = 400  # RANSAC hypotheses (pairs of segments)


def support(vps: np.ndarray, mids: np.ndarray, dirs: np.ndarray, sin_tol: np.ndarray) -> np.ndarray:
    """Which segments point at which vanishing points.

    Parameters
    ----------
    vps : ndarray, (M, 3)
        Homogeneous points.
    mids : ndarray, (N, 2)
        The segments' centres.
    dirs : ndarray, (N, 2)
        Their unit directions.
    sin_tol : ndarray, (N,)
        Each segment's tolerance, the sine of an angle.

    Returns
    -------
    ndarray, bool (M, N)
        True where segment n points at point m within its tolerance.
    """
    v = vps.astype(np.float32)
    m = mids.astype(np.float32)
    qx = v[:, None, 0] - v[:, None, 2] * m[None, :, 0]
    qy = v[:, None, 1] - v[:, None, 2] * m[None, :, 1]
    cross = dirs[None, :, 0].astype(np.float32) * qy - dirs[None, :, 1].astype(np.float32) * qx
    return cross * cross <= (sin_tol * sin_tol).astype(np.float32)[None, :] * (qx * qx + qy * qy)


def refine_point(
    lines: np.ndarray,
    weights: np.ndarray,
    mids: np.ndarray | None = None,
    v: np.ndarray | None = None,
    iterations: int = 4,
) -> np.ndarray:
    """The point the ``lines`` point at best, as a unit 3-vector.

    Without ``mids``, the algebraic least squares; with them (each line's centre) and a start ``v``,
    the sum of squared sines of the angles between each line and the direction from its centre to the
    point, by reweighting: the algebraic residual of a line is that sine times the distance (in
    ``v``'s scale) from its centre to the point, which would favour points near the long lines. A
    Cauchy weight (scale twice the robust spread of the sines, at least 0.3 degrees) keeps stray
    members from pulling.

    Parameters
    ----------
    lines : ndarray, (N, 3)
        Homogeneous lines.
    weights : ndarray, (N,)
        Their weights (lengths).
    mids : ndarray, (N, 2), optional
        Their centres.
    v : ndarray, (3,), optional
        The start point (with ``mids``).
    iterations : int, default 4
        Reweighting steps.

    Returns
    -------
    ndarray, (3,)

    References
    ----------
    Hartley & Zisserman, *Multiple View Geometry*, 2nd ed., §8.6 (vanishing points).
    """

    def solve(w: np.ndarray) -> np.ndarray:
        m = (lines * w[:, None]).T @ lines
        return np.linalg.eigh(m)[1][:, 0]

    if mids is None:
        return solve(weights)
    assert v is not None  # the centres come with a start point
    for _ in range(iterations):
        q = v[None, :2] - v[2] * mids
        qq = np.maximum(np.einsum("ij,ij->i", q, q), 1e-12)
        sine = np.abs(lines @ v) / np.sqrt(qq)
        scale = max(math.sin(math.radians(0.3)), 1.4826 * float(np.median(sine)))
        robust = 1.0 / (1.0 + (sine / (2.0 * scale)) ** 2)  # Cauchy: a stray segment barely counts
        v = solve(weights * robust / qq)
    return v


def focal_sq(v1: np.ndarray, v2: np.ndarray) -> float | None:
    """f² from two orthogonal vanishing points about the origin (the principal point).

    Parameters
    ----------
    v1, v2 : ndarray, (3,)
        Homogeneous vanishing points in normalised coordinates.

    Returns
    -------
    float or None
        None when one of them is (near) infinity and f is left open.

    References
    ----------
    Hartley & Zisserman, *Multiple View Geometry*, 2nd ed., §8.8 (the image of the absolute conic).
    """
    if abs(v1[2]) < 1e-9 or abs(v2[2]) < 1e-9:
        return None
    return float(-(v1[:2] @ v2[:2]) / (v1[2] * v2[2]))


@dataclass
class Families:
    vps: np.ndarray  # (2, 3) in normalised coordinates
    members: list  # two index arrays into the segments
    explained: float  # fraction of the segments' length in the two families


def hypotheses(lines: np.ndarray, length: np.ndarray, pool: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Candidate vanishing points: intersections of random pairs of segments, longer segments drawn more often.

    Parameters
    ----------
    lines : ndarray, (N, 3)
        The segments' homogeneous lines.
    length : ndarray, (N,)
        Their lengths.
    pool : ndarray, int
        The segments to draw from.
    rng : numpy.random.Generator

    Returns
    -------
    ndarray, (K, 3)
        Unit 3-vectors.
    """
    p = length[pool] / length[pool].sum()
    a = rng.choice(pool, _CANDIDATES, p=p)
    b = rng.choice(pool, _CANDIDATES, p=p)
    cand = np.cross(lines[a[a != b]], lines[b[a != b]])
    norm = np.linalg.norm(cand, axis=1)
    return cand[norm > 1e-12] / norm[norm > 1e-12, None]


def near(points: np.ndarray, of: np.ndarray, margin: float) -> np.ndarray:
    """Whether each of ``points`` lies within ``margin`` of the convex hull of ``of`` (all 2-D).

    Parameters
    ----------
    points : ndarray, (K, 2)
    of : ndarray, (N, 2)
    margin : float

    Returns
    -------
    ndarray, bool (K,)
    """
    hull = cv2.convexHull(of.astype(np.float32))
    return np.array([cv2.pointPolygonTest(hull, (float(x), float(y)), True) >= -margin for x, y in points])


def two_families(seg: np.ndarray, rng: np.random.Generator, px: float, lattice: bool = False) -> Families | None:
    """Two well-supported vanishing points that a camera can see as perpendicular directions.

    The best supported first, then the best supported among the other segments on the region of the
    first (clutter beside the surface counts a tenth).

    Parameters
    ----------
    seg : ndarray, (N, 4)
        Segments in normalised coordinates (the principal point at the origin).
    rng : numpy.random.Generator
        For the hypotheses.
    px : float
        The length of a work pixel in these units: a short segment's direction is known only to about
        a pixel over its length.
    lattice : bool, default False
        The segments join repeats of a lattice, whose every translation has a vanishing point on the
        horizon (the axes and the diagonals): the four best-supported points are found in turn and the
        best-supported pair a camera can see as perpendicular is taken.

    Returns
    -------
    Families or None
        None when there are no two such families.

    References
    ----------
    Hartley & Zisserman, *Multiple View Geometry*, 2nd ed., §8.6-8.8.
    """
    n = len(seg)
    if n < 2 * MIN_FAMILY:
        return None
    lines = homogeneous(seg)
    d = seg[:, 2:] - seg[:, :2]
    length = np.hypot(d[:, 0], d[:, 1])
    dirs = d / length[:, None]
    mids = (seg[:, :2] + seg[:, 2:]) / 2
    sin_tol = np.maximum(math.sin(math.radians(INLIER_DEG)), 1.2 * px / length)

    def refine(v: np.ndarray, free: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        mem = support(v[None], mids, dirs, sin_tol)[0] & free
        for _ in range(3):
            if mem.sum() < 2:
                break
            v = refine_point(lines[mem], length[mem] ** 2, mids[mem], v)
            mem = support(v[None], mids, dirs, sin_tol)[0] & free
        for _ in range(0 if lattice else 2):  # (repeats are no pieces of longer lines)
            if mem.sum() < 2:
                break
            merged, span, centres = chains(seg[mem], px)
            v = refine_point(merged, span**2, centres, v)
            mem = support(v[None], mids, dirs, sin_tol)[0] & free
        return v, mem

    everything = np.ones(n, bool)
    if lattice:
        found, free = [], everything.copy()
        for _ in range(4):
            pool = np.flatnonzero(free)
            if len(pool) < MIN_FAMILY:
                break
            cand = hypotheses(lines, length, pool, rng)
            sup = support(cand, mids, dirs, sin_tol) & free
            v, mem = refine(cand[np.argmax(sup @ length)], free)
            if mem.sum() < MIN_FAMILY:
                break
            found.append((v, mem))
            free &= ~mem
        best, score = None, 0.0
        for a in range(len(found)):
            for b in range(a + 1, len(found)):
                f2 = focal_sq(found[a][0], found[b][0])
                if f2 is None or not MIN_FOCAL**2 < f2 < MAX_FOCAL**2:
                    continue
                sc = min(found[a][1] @ length, found[b][1] @ length)
                if sc > score:
                    best, score = (found[a], found[b]), sc
        if best is None:
            return None
        explained = float((best[0][1] | best[1][1]) @ length / length.sum())
        return Families(
            np.array([best[0][0], best[1][0]]), [np.flatnonzero(best[0][1]), np.flatnonzero(best[1][1])], explained
        )
    cand = hypotheses(lines, length, np.arange(n), rng)
    sup = support(cand, mids, dirs, sin_tol)
    v1, mem1 = refine(cand[np.argmax(sup @ length)], everything)
    rest = np.flatnonzero(~mem1)
    if mem1.sum() < MIN_FAMILY or len(rest) < MIN_FAMILY:
        return None
    ends1 = np.vstack([seg[mem1, :2], seg[mem1, 2:]])
    weight = length * np.where(near(mids, ends1, 0.05), 1.0, 0.1)
    cand = hypotheses(lines, weight, rest, rng)
    sup = support(cand, mids, dirs, sin_tol) & ~mem1
    score = sup @ weight
    for m in np.argsort(-score)[:50]:
        if sup[m].sum() < MIN_FAMILY:
            break
        f2 = focal_sq(v1, cand[m])
        if f2 is not None and f2 <= MIN_FOCAL**2:  # no camera sees these two directions as perpendicular
            continue
        v2, mem2 = refine(cand[m], ~mem1)
        if mem2.sum() < MIN_FAMILY:
            continue
        f2 = focal_sq(v1, v2)
        if f2 is not None and f2 <= MIN_FOCAL**2:
            continue
        # two families of comparable strength and a third nearly as strong (the edges of hexagonal
        # cells) leave it open which two are the perpendicular ones: no guess
        rest3 = np.flatnonzero(~(mem1 | mem2))
        s1, s2 = mem1 @ weight, mem2 @ weight
        if len(rest3) >= MIN_FAMILY and min(s1, s2) >= BALANCED * max(s1, s2):
            cand3 = hypotheses(lines, weight, rest3, rng)
            sup3 = support(cand3, mids, dirs, sin_tol) & ~(mem1 | mem2)
            g = np.median(mids[mem1 | mem2], axis=0)
            cos_max = math.cos(math.radians(MIN_SPREAD_DEG))
            d1, d2 = direction_at(v1, g), direction_at(v2, g)
            for m3 in np.argsort(-(sup3 @ weight))[:20]:
                d3 = direction_at(cand3[m3], g)
                if abs(d3 @ d1) < cos_max and abs(d3 @ d2) < cos_max:  # a direction of its own
                    if sup3[m3] @ weight >= THIRD_FAMILY * min(s1, s2):
                        return None
                    break
        explained = float((mem1 | mem2) @ length / length.sum())
        return Families(np.array([v1, v2]), [np.flatnonzero(mem1), np.flatnonzero(mem2)], explained)
    return None


def direction_at(v: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Unit direction from point ``x`` towards the homogeneous point ``v``.

    Parameters
    ----------
    v : ndarray, (3,)
    x : ndarray, (2,)

    Returns
    -------
    ndarray, (2,)
    """
    q = v[:2] - v[2] * x
    return q / np.linalg.norm(q)
