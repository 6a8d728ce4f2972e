"""Suggested feature lines: two vanishing directions found in the photo, and the lines they imply.

A photo of a planar texture with straight structure (mortar joints, tiles, a weave, lines of text)
shows two families of lines, each converging to a vanishing point. :func:`suggest_lines` finds
them and turns them into feature-line pairs the user can edit like drawn ones:

1. line segments (OpenCV's LSD) on the photo reduced to :data:`WORK_SIDE` pixels;
2. vanishing points by RANSAC over pairs of segments (a segment supports a point when its direction
   points at it within :data:`INLIER_DEG`), the two best-supported, mutually compatible points,
   each refined by weighted least squares over its segments;
3. rectification: the vanishing line sent to infinity (affine), then the two directions made
   perpendicular and of equal scale (metric) with a camera of square pixels whose principal point
   is the photo's centre; the two orthogonal vanishing points then fix the focal length.
   When they cannot (a vanishing point at infinity), the aspect is left to an assumed focal length
   of :data:`ASSUMED_FOCAL` times the photo's longer side, and the suggestion says so;
4. feature lines: up to three long segments of each family, extended across the textured region,
   paired with their axis-aligned images in the frontal frame.

Where segments are too few, segments joining the texture's own repeats (SIFT features matched
within the photo) take their place: the line through a feature and its repeat points at the
vanishing point of the repeat's direction on the plane.

When neither gives two families it raises :class:`~weft.core.errors.GeometryError` with one line
(:data:`REFUSAL`); it never returns a guess it has no support for.

References
----------
Yan, Lee & Lin, "Patch-based synthesis of non-frontal-parallel textures", §3 (the feature lines this
module proposes).
Hartley & Zisserman, *Multiple View Geometry*, 2nd ed., §2.7 (affine and metric rectification) and
§8.6-8.8 (vanishing points, the image of the absolute conic, focal length from two orthogonal
vanishing points).
Grompone von Gioi et al., "LSD: a fast line segment detector with a false detection control",
IPOL 2012.
Bharadwaj, Collins & Liu, "R-VPD: repeated-pattern vanishing point detection", 2024 (repeats as
evidence of vanishing directions).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import cv2
import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from ..errors import GeometryError
from ..geometry import FeatureLines
from ..image import validate_image
from .homography import apply_homography

__all__ = ["Suggestion", "suggest_lines", "suggest_for_studio", "REFUSAL", "WORK_SIDE", "INLIER_DEG", "ASSUMED_FOCAL"]

#: The one line said when the photo shows no two families of straight lines (nor of repeats).
REFUSAL = "no two families of straight lines found: draw feature lines"
WORK_SIDE = 720  # longer side (px) of the reduced photo the segments are found on
LSD_SCALE = 0.8  # LSD's own Gaussian reduction of the work image (its default)
FINE_SIDE = 1600  # a second look at up to this size when the reduced photo shows no two families
FINE_BELOW = 300  # ... and fewer segments than this (fine structure lost in the reduction)
REPEAT_SIDE = 560  # longer side of the photo the repeats are looked for on
INLIER_DEG = 1.5  # a segment supports a vanishing point when it points at it within this angle
MIN_FAMILY = 5  # segments a family needs
MIN_SPREAD_DEG = 15.0  # the two families must differ by this much in direction in the photo
ASSUMED_FOCAL = 1.2  # focal length (in photo longer sides) when the vanishing points leave it open
MIN_FOCAL = 0.5  # in half longer sides: a shorter focal length than this is no camera's (a 9 mm lens on 35 mm film)
MAX_FOCAL = 10.0  # in half longer sides: beyond it the vanishing points barely converge and leave f open
MIN_CONFIDENCE = 0.3  # a weaker suggestion is refused
THIRD_FAMILY = 0.5  # a third family with this much of the weaker one's support makes the pair ambiguous ...
BALANCED = 0.4  # ... when the weaker one has this much of the stronger one's (a lattice of cells)
MAX_FRONTAL_SIDE = 4096
_CANDIDATES = 400  # RANSAC hypotheses (pairs of segments)


@dataclass(frozen=True)
class Suggestion:
    """Feature lines proposed for a photo, and the evidence behind them.

    Attributes
    ----------
    lines : FeatureLines
        Line pairs (photo, frontal) in DESIGN.md's format; the frontal frame's axes follow the two
        families (the more horizontal one along x).
    homography : (3, 3) float64
        Frontal -> photo, the one the lines encode.
    confidence : float in [0, 1]
        How much of the photo's structure the two families explain, times how well supported the
        weaker family is (halved when the aspect rests on an assumed focal length).
    angle_deg : float
        Angle in the photo between the two recovered directions at the textured region's centre.
    vanishing_points : (2, 3) float64
        Homogeneous, in photo pixels (third coordinate 0: a direction at infinity).
    focal_px : float
        The focal length the metric step used, in photo pixels.
    aspect : str
        ``"camera"`` (fixed by the two vanishing points) or ``"assumed focal"``.
    source : str
        ``"lines"`` (straight segments) or ``"repeats"`` (the texture's own repeats).
    figures : dict
        Counts and timings for reports.
    """

    lines: FeatureLines
    homography: np.ndarray
    confidence: float
    angle_deg: float
    vanishing_points: np.ndarray
    focal_px: float
    aspect: str
    source: str
    figures: dict = field(default_factory=dict)

    def describe(self) -> str:
        """The suggestion in words, for a status line."""
        aspect = "" if self.aspect == "camera" else ", aspect from an assumed focal length"
        return (f"suggested {len(self.lines)} line pairs from {self.source}: confidence {self.confidence:.2f}, "
                f"directions {self.angle_deg:.0f}° apart{aspect}")

    def report(self) -> dict:
        """The figures ``--report`` prints (JSON-able)."""
        return {"suggest_confidence": round(self.confidence, 3), "suggest_angle_deg": round(self.angle_deg, 2),
                "suggest_source": self.source, "suggest_aspect": self.aspect,
                "suggest_focal_px": round(self.focal_px, 1), "suggest_pairs": len(self.lines),
                **{f"suggest_{k}": v for k, v in self.figures.items()}}


# -- segments ---------------------------------------------------------------------------------------

def _grey_work(photo: np.ndarray, side: int | None = None) -> tuple[np.ndarray, float]:
    """The photo as 8-bit grey, reduced so its longer side is at most ``side`` (default
    :data:`WORK_SIDE`); the factor."""
    grey = photo if photo.ndim == 2 else cv2.cvtColor(photo, cv2.COLOR_RGB2GRAY)
    h, w = grey.shape
    k = min(1.0, (side or WORK_SIDE) / max(h, w))
    if k < 1.0:
        grey = cv2.resize(grey, (max(1, round(w * k)), max(1, round(h * k))), interpolation=cv2.INTER_AREA)
    return np.clip(grey * 255.0 + 0.5, 0, 255).astype(np.uint8), k


def _line_segments(grey: np.ndarray) -> np.ndarray:
    """(N, 4) segments found by LSD, at least 1/90 of the longer side long."""
    lsd = cv2.createLineSegmentDetector(cv2.LSD_REFINE_STD, LSD_SCALE)
    found = lsd.detect(grey)[0]
    if found is None:
        return np.zeros((0, 4))
    seg = found.reshape(-1, 4).astype(np.float64)
    length = np.hypot(seg[:, 2] - seg[:, 0], seg[:, 3] - seg[:, 1])
    return seg[length >= max(6.0, max(grey.shape) / 90.0)]


def _repeat_segments(grey: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Segments joining SIFT features to their repeats elsewhere in the photo (similar descriptor,
    scale and orientation), at least three feature sizes apart."""
    sift = cv2.SIFT_create(nfeatures=1000)
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
    keep = ((i < j) & (gap > 3 * np.maximum(size[i], size[j])) & (turn < math.radians(20))
            & (np.abs(np.log(size[i] / size[j])) < 0.3) & (dists < np.quantile(dists, 0.3)))
    return np.column_stack([pts[i[keep]], pts[j[keep]]])


# -- vanishing points -----------------------------------------------------------------------------

def _homogeneous(seg: np.ndarray) -> np.ndarray:
    p = np.column_stack([seg[:, :2], np.ones(len(seg))])
    q = np.column_stack([seg[:, 2:], np.ones(len(seg))])
    ln = np.cross(p, q)
    return ln / np.hypot(ln[:, 0], ln[:, 1])[:, None]


def _support(vps: np.ndarray, mids: np.ndarray, dirs: np.ndarray, sin_tol: np.ndarray) -> np.ndarray:
    """(M, N) bool: segment n points at vanishing point m within its tolerance (sine of the angle)."""
    q = vps[:, None, :2] - vps[:, None, 2:3] * mids[None, :, :]
    cross = np.abs(dirs[None, :, 0] * q[..., 1] - dirs[None, :, 1] * q[..., 0])
    return cross <= sin_tol[None, :] * np.hypot(q[..., 0], q[..., 1]) + 1e-15


def _refine(lines: np.ndarray, weights: np.ndarray, mids: np.ndarray | None = None,
            v: np.ndarray | None = None, iterations: int = 4) -> np.ndarray:
    """The point the ``lines`` point at best: unit 3-vector. Without ``mids``, the algebraic least
    squares; with them (each line's centre) and a start ``v``, the sum of squared sines of the
    angles between each line and the direction from its centre to the point, by reweighting: the
    algebraic residual of a line is that sine times the distance (in ``v``'s scale) from its centre
    to the point, which would favour points near the long lines."""
    def solve(w: np.ndarray) -> np.ndarray:
        m = (lines * w[:, None]).T @ lines
        return np.linalg.eigh(m)[1][:, 0]

    if mids is None:
        return solve(weights)
    for _ in range(iterations):
        q = v[None, :2] - v[2] * mids
        v = solve(weights / np.maximum(np.einsum("ij,ij->i", q, q), 1e-12))
    return v


def _focal_sq(v1: np.ndarray, v2: np.ndarray) -> float | None:
    """f² from two orthogonal vanishing points about the origin (the principal point), or None when
    one of them is (near) infinity and f is left open."""
    if abs(v1[2]) < 1e-9 or abs(v2[2]) < 1e-9:
        return None
    return float(-(v1[:2] @ v2[:2]) / (v1[2] * v2[2]))


@dataclass
class _Families:
    vps: np.ndarray  # (2, 3) in normalised coordinates
    members: list  # two index arrays into the segments
    explained: float  # fraction of the segments' length in the two families


def _hypotheses(lines: np.ndarray, length: np.ndarray, pool: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Candidate vanishing points (unit 3-vectors): intersections of random pairs of segments of
    ``pool``, longer segments drawn more often."""
    p = length[pool] / length[pool].sum()
    a = rng.choice(pool, _CANDIDATES, p=p)
    b = rng.choice(pool, _CANDIDATES, p=p)
    cand = np.cross(lines[a[a != b]], lines[b[a != b]])
    norm = np.linalg.norm(cand, axis=1)
    return cand[norm > 1e-12] / norm[norm > 1e-12, None]


def _chains(seg: np.ndarray, px: float, tol: float = 1.2) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The segments joined into whole lines: two segments are links of one line when each one's end
    points lie within ``tol`` work pixels of the other's line and the gap between them is at most
    twice the longer one (links chain along a line: a joint broken at every brick, a checkerboard's
    edge); each line is fitted to its segments' end points. Returns (K, 3) lines, their lengths and
    their centres. A long line's direction is known far better than its pieces' (short segments
    cut at corners lean towards the corners)."""
    n = len(seg)
    lines = _homogeneous(seg)
    p, q = seg[:, :2], seg[:, 2:]
    d = q - p
    length = np.hypot(d[:, 0], d[:, 1])
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
        return np.maximum(np.abs(np.einsum("ij,ij->i", lines[a, :2], p[b]) + lines[a, 2]),
                          np.abs(np.einsum("ij,ij->i", lines[a, :2], q[b]) + lines[a, 2]))

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


def _near(points: np.ndarray, of: np.ndarray, margin: float) -> np.ndarray:
    """Whether each of ``points`` lies within ``margin`` of the convex hull of ``of`` (all 2-D)."""
    hull = cv2.convexHull(of.astype(np.float32))
    return np.array([cv2.pointPolygonTest(hull, (float(x), float(y)), True) >= -margin for x, y in points])


def _two_families(seg: np.ndarray, rng: np.random.Generator, px: float, lattice: bool = False) -> _Families | None:
    """Two well-supported vanishing points of segments in normalised coordinates (the principal
    point at the origin) that a camera can see as perpendicular directions: the best supported
    first, then the best supported among the other segments on the region of the first (clutter
    beside the surface counts a tenth). ``px`` is the length of a work pixel in these units: a
    short segment's direction is known only to about a pixel over its length.

    ``lattice``: the segments join repeats of a lattice, whose every translation has a vanishing
    point on the horizon (the axes and the diagonals): the four best-supported points are found in
    turn and the best-supported pair a camera can see as perpendicular is taken."""
    n = len(seg)
    if n < 2 * MIN_FAMILY:
        return None
    lines = _homogeneous(seg)
    d = seg[:, 2:] - seg[:, :2]
    length = np.hypot(d[:, 0], d[:, 1])
    dirs = d / length[:, None]
    mids = (seg[:, :2] + seg[:, 2:]) / 2
    sin_tol = np.maximum(math.sin(math.radians(INLIER_DEG)), 1.2 * px / length)

    def refine(v: np.ndarray, free: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        mem = _support(v[None], mids, dirs, sin_tol)[0] & free
        for _ in range(3):
            if mem.sum() < 2:
                break
            v = _refine(lines[mem], length[mem] ** 2, mids[mem], v)
            mem = _support(v[None], mids, dirs, sin_tol)[0] & free
        for _ in range(0 if lattice else 2):  # (repeats are no pieces of longer lines)
            if mem.sum() < 2:
                break
            merged, span, centres = _chains(seg[mem], px)
            v = _refine(merged, span ** 2, centres, v)
            mem = _support(v[None], mids, dirs, sin_tol)[0] & free
        return v, mem

    everything = np.ones(n, bool)
    if lattice:
        found, free = [], everything.copy()
        for _ in range(4):
            pool = np.flatnonzero(free)
            if len(pool) < MIN_FAMILY:
                break
            cand = _hypotheses(lines, length, pool, rng)
            sup = _support(cand, mids, dirs, sin_tol) & free
            v, mem = refine(cand[np.argmax(sup @ length)], free)
            if mem.sum() < MIN_FAMILY:
                break
            found.append((v, mem))
            free &= ~mem
        best, score = None, 0.0
        for a in range(len(found)):
            for b in range(a + 1, len(found)):
                f2 = _focal_sq(found[a][0], found[b][0])
                if f2 is None or not MIN_FOCAL ** 2 < f2 < MAX_FOCAL ** 2:
                    continue
                sc = min(found[a][1] @ length, found[b][1] @ length)
                if sc > score:
                    best, score = (found[a], found[b]), sc
        if best is None:
            return None
        explained = float((best[0][1] | best[1][1]) @ length / length.sum())
        return _Families(np.array([best[0][0], best[1][0]]), [np.flatnonzero(best[0][1]), np.flatnonzero(best[1][1])],
                         explained)
    cand = _hypotheses(lines, length, np.arange(n), rng)
    sup = _support(cand, mids, dirs, sin_tol)
    v1, mem1 = refine(cand[np.argmax(sup @ length)], everything)
    rest = np.flatnonzero(~mem1)
    if mem1.sum() < MIN_FAMILY or len(rest) < MIN_FAMILY:
        return None
    ends1 = np.vstack([seg[mem1, :2], seg[mem1, 2:]])
    weight = length * np.where(_near(mids, ends1, 0.05), 1.0, 0.1)
    cand = _hypotheses(lines, weight, rest, rng)
    sup = _support(cand, mids, dirs, sin_tol) & ~mem1
    score = sup @ weight
    for m in np.argsort(-score)[:50]:
        if sup[m].sum() < MIN_FAMILY:
            break
        f2 = _focal_sq(v1, cand[m])
        if f2 is not None and f2 <= MIN_FOCAL ** 2:  # no camera sees these two directions as perpendicular
            continue
        v2, mem2 = refine(cand[m], ~mem1)
        if mem2.sum() < MIN_FAMILY:
            continue
        f2 = _focal_sq(v1, v2)
        if f2 is not None and f2 <= MIN_FOCAL ** 2:
            continue
        # two families of comparable strength and a third nearly as strong (the edges of hexagonal
        # cells) leave it open which two are the perpendicular ones: no guess
        rest3 = np.flatnonzero(~(mem1 | mem2))
        s1, s2 = mem1 @ weight, mem2 @ weight
        if len(rest3) >= MIN_FAMILY and min(s1, s2) >= BALANCED * max(s1, s2):
            cand3 = _hypotheses(lines, weight, rest3, rng)
            sup3 = _support(cand3, mids, dirs, sin_tol) & ~(mem1 | mem2)
            g = np.median(mids[mem1 | mem2], axis=0)
            cos_max = math.cos(math.radians(MIN_SPREAD_DEG))
            d1, d2 = _direction_at(v1, g), _direction_at(v2, g)
            for m3 in np.argsort(-(sup3 @ weight))[:20]:
                d3 = _direction_at(cand3[m3], g)
                if abs(d3 @ d1) < cos_max and abs(d3 @ d2) < cos_max:  # a direction of its own
                    if sup3[m3] @ weight >= THIRD_FAMILY * min(s1, s2):
                        return None
                    break
        explained = float((mem1 | mem2) @ length / length.sum())
        return _Families(np.array([v1, v2]), [np.flatnonzero(mem1), np.flatnonzero(mem2)], explained)
    return None


def _direction_at(v: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Unit direction from point ``x`` (2,) towards the homogeneous point ``v``."""
    q = v[:2] - v[2] * x
    return q / np.linalg.norm(q)


# -- rectification ----------------------------------------------------------------------------------

def _plane_homography(v1: np.ndarray, v2: np.ndarray, focal: float, x0: np.ndarray) -> np.ndarray:
    """Plane (X, Y) -> normalised photo point for the camera K = diag(f, f, 1) (principal point at the
    origin): X along ``v1``, Y along ``v2``, the origin at photo point ``x0``, unit = 1 / f at x0."""
    kinv = np.diag([1.0 / focal, 1.0 / focal, 1.0])
    r1 = kinv @ v1
    r1 /= np.linalg.norm(r1)
    r2 = kinv @ v2
    r2 -= r1 * (r1 @ r2)
    r2 /= np.linalg.norm(r2)
    t = kinv @ np.array([x0[0], x0[1], 1.0])
    k = np.diag([focal, focal, 1.0])
    h = k @ np.column_stack([r1, r2, t])
    # X to the right and Y downwards in the photo near x0 (no mirror image, no half-turn)
    for col, axis in ((0, 0), (1, 1)):
        step = apply_homography(h, np.array([[0.0, 0.0], [1e-3 if col == 0 else 0.0, 1e-3 if col == 1 else 0.0]]))
        if step[1, axis] - step[0, axis] < 0:
            h[:, col] = -h[:, col]
    return h


def _in_front(h: np.ndarray, pts: np.ndarray) -> bool:
    w = h[2, 0] * pts[:, 0] + h[2, 1] * pts[:, 1] + h[2, 2]
    return bool(np.all(w > 1e-9) or np.all(w < -1e-9))


def _frame(h: np.ndarray, seg_px: np.ndarray, size: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """The rectangle (x0, y0, x1, y1) of plane coordinates the families cover (2-98 % of their end
    points), shrunk about its centre until it lies inside the photo; and the segments on the plane."""
    w, hgt = size
    inv = np.linalg.inv(h)
    ends = np.vstack([seg_px[:, :2], seg_px[:, 2:]])
    plane = apply_homography(inv, ends)
    lo, hi = np.percentile(plane, 2, axis=0), np.percentile(plane, 98, axis=0)
    centre = (lo + hi) / 2
    scale = 1.0
    for _ in range(40):
        a, b = centre + (lo - centre) * scale, centre + (hi - centre) * scale
        corners = np.array([[a[0], a[1]], [b[0], a[1]], [b[0], b[1]], [a[0], b[1]]])
        img = apply_homography(h, corners)
        if (_in_front(h, corners) and np.all(img[:, 0] >= 0) and np.all(img[:, 0] <= w - 1)
                and np.all(img[:, 1] >= 0) and np.all(img[:, 1] <= hgt - 1)):
            return np.array([a[0], a[1], b[0], b[1]]), apply_homography(inv, seg_px.reshape(-1, 2)).reshape(-1, 4)
        scale *= 0.93
    raise GeometryError(REFUSAL)


def _pick(positions: np.ndarray, weights: np.ndarray, lo: float, hi: float, k: int = 3) -> list[float]:
    """Up to ``k`` positions in (lo, hi), heaviest first, at least a fifth of the span apart."""
    out: list[float] = []
    span = hi - lo
    for i in np.argsort(-weights):
        p = positions[i]
        if not (lo + 0.02 * span < p < hi - 0.02 * span):
            continue
        if all(abs(p - q) > span / 5 for q in out):
            out.append(float(p))
        if len(out) == k:
            break
    return out


def suggest_lines(photo: np.ndarray, *, rng: None | int | np.random.Generator = 0,
                  repeats: bool = True) -> Suggestion:
    """Suggest feature lines for a photo of a planar texture seen at an angle.

    Parameters
    ----------
    photo : float32 (H, W) or (H, W, 3) in [0, 1]
        The non-frontal-parallel texture photo.
    rng : None, int or numpy.random.Generator, default 0
        The RANSAC's random source: the same seed gives the same lines.
    repeats : bool, default True
        When straight segments give no two families, try the texture's own repeats.

    Returns
    -------
    Suggestion
        ``lines`` (feature-line pairs for :func:`~weft.core.rectify.rectify`), the homography they
        encode, a confidence, the angle between the two directions in the photo, and figures.

    Raises
    ------
    GeometryError
        :data:`REFUSAL` when no two families of straight lines (nor of repeats) are found: a
        photo with one family only (parallel stripes), no structure, or directions no camera
        could see as perpendicular.
    ImageError
        A photo that is not a valid image.

    References
    ----------
    Yan, Lee & Lin §3 (feature lines); Hartley & Zisserman §2.7, §8.6-8.8 (rectification from
    vanishing points); Grompone von Gioi et al. 2012 (LSD); Bharadwaj, Collins & Liu 2024 (repeats).
    """
    t0 = time.perf_counter()
    photo = validate_image(photo, "photo")
    rng = np.random.default_rng(rng)
    hgt, w = photo.shape[:2]
    c = np.array([(w - 1) / 2.0, (hgt - 1) / 2.0])
    s = max(w, hgt) / 2.0

    attempts = [(WORK_SIDE, "lines"), (FINE_SIDE, "fine lines")]
    if repeats:
        attempts.append((REPEAT_SIDE, "repeats"))
    found = 0
    greys: dict = {}
    for side, source in attempts:
        if source == "fine lines":  # fine structure (a weave) may need every pixel: when few segments showed
            if max(w, hgt) <= WORK_SIDE or found >= FINE_BELOW:
                continue
            source = "lines"
        if side not in greys:
            greys[side] = _grey_work(photo, side)
        grey, k = greys[side]
        found_work = _line_segments(grey) if source == "lines" else _repeat_segments(grey, rng)
        seg_px = (found_work + 0.5) / k - 0.5
        found = max(found, len(seg_px)) if source == "lines" else found
        fam = (_two_families((seg_px - np.tile(c, 2)) / s, rng, 1.0 / (k * s), lattice=source == "repeats")
               if len(seg_px) else None)
        if fam is None:
            continue
        try:
            out = suggestion_from_families(seg_px, fam.vps, fam.members, fam.explained, (w, hgt), source=source)
        except GeometryError:
            continue
        out.figures.update({"segments": int(found), "seconds": round(time.perf_counter() - t0, 4)})
        return out
    raise GeometryError(REFUSAL)


def suggestion_from_families(seg_px: np.ndarray, vps: np.ndarray, members: list, explained: float,
                             size: tuple[int, int], *, source: str = "lines",
                             min_confidence: float = MIN_CONFIDENCE) -> Suggestion:
    """The rectification and feature lines of two families of segments (steps 3-4 of the module).

    Parameters
    ----------
    seg_px : (N, 4) segments in photo pixels.
    vps : (2, 3) their vanishing points in normalised coordinates ``(x - c) / s`` (``c`` the
        photo's centre, ``s`` half its longer side).
    members : two index arrays into ``seg_px``: the segments of each family.
    explained : fraction of the segments' length in the two families (for the confidence).
    size : (width, height) of the photo.
    source : what the segments are (``"lines"``, ``"repeats"``), for the suggestion.
    min_confidence : a suggestion less confident than this is refused.

    Raises
    ------
    GeometryError
        :data:`REFUSAL` when the two directions are closer than :data:`MIN_SPREAD_DEG` in the photo.
    """
    w, hgt = size
    c = np.array([(w - 1) / 2.0, (hgt - 1) / 2.0])
    s = max(w, hgt) / 2.0
    fam = _Families(np.asarray(vps, dtype=np.float64), [np.asarray(m) for m in members], explained)
    # normalised coordinates: u = (x - c) / s; the principal point is the origin
    used = seg_px[np.concatenate(fam.members)]
    x0 = np.median(((used[:, :2] + used[:, 2:]) / 2 - c) / s, axis=0)
    v1, v2 = fam.vps
    d1, d2 = _direction_at(v1, x0), _direction_at(v2, x0)
    angle = math.degrees(math.acos(min(1.0, abs(float(d1 @ d2)))))
    if angle < MIN_SPREAD_DEG:
        raise GeometryError(REFUSAL)
    if abs(d1[0]) < abs(d2[0]):  # the more horizontal family along x
        v1, v2 = v2, v1
        fam.members.reverse()
    members = np.concatenate(fam.members)
    f2 = _focal_sq(v1, v2)
    if f2 is not None and f2 <= MIN_FOCAL ** 2:
        raise GeometryError(REFUSAL)
    if f2 is not None and f2 < MAX_FOCAL ** 2:
        focal, aspect = math.sqrt(f2), "camera"
    else:
        focal, aspect = 2.0 * ASSUMED_FOCAL, "assumed focal"
    hn = _plane_homography(v1, v2, focal, x0)
    to_px_m = np.array([[s, 0, c[0]], [0, s, c[1]], [0, 0, 1.0]])
    h_plane = to_px_m @ hn  # plane -> photo pixels
    rect, plane_seg = _frame(h_plane, seg_px[members], (w, hgt))

    # frontal pixels: the photo's pixel density over the region, at most MAX_FRONTAL_SIDE
    quad = apply_homography(h_plane, np.array([[rect[0], rect[1]], [rect[2], rect[1]], [rect[2], rect[3]],
                                               [rect[0], rect[3]]]))
    area_px = 0.5 * abs(np.dot(quad[:, 0], np.roll(quad[:, 1], 1)) - np.dot(quad[:, 1], np.roll(quad[:, 0], 1)))
    pw, ph = rect[2] - rect[0], rect[3] - rect[1]
    scale = math.sqrt(area_px / (pw * ph))
    scale = min(scale, MAX_FRONTAL_SIDE / max(pw, ph))
    fw, fh = max(16, round(pw * scale)), max(16, round(ph * scale))
    sx, sy = pw / fw, ph / fh
    # frontal pixel (x, y), centres at integers -> plane point
    to_plane = np.array([[sx, 0, rect[0] + 0.5 * sx], [0, sy, rect[1] + 0.5 * sy], [0, 0, 1.0]])
    hom = h_plane @ to_plane
    hom /= hom[2, 2]

    fr_seg = apply_homography(np.linalg.inv(to_plane), plane_seg.reshape(-1, 2)).reshape(-1, 4)
    n1 = len(fam.members[0])
    frontal = []
    for axis, rows in ((1, fr_seg[:n1]), (0, fr_seg[n1:])):  # x family: rows at y; y family: columns at x
        pos = (rows[:, axis] + rows[:, axis + 2]) / 2
        wts = np.hypot(rows[:, 2] - rows[:, 0], rows[:, 3] - rows[:, 1])
        span = fh - 1 if axis == 1 else fw - 1
        picks = _pick(pos, wts, 0.0, span)
        if len(picks) < 2:
            picks = sorted(set(picks) | {0.0, float(span)})[:3] if len(picks) else [0.0, float(span)]
        for p in sorted(picks):
            frontal.append([0.0, p, fw - 1.0, p] if axis == 1 else [p, 0.0, p, fh - 1.0])
    frontal = np.array(frontal)
    image = np.column_stack([apply_homography(hom, frontal[:, :2]), apply_homography(hom, frontal[:, 2:])])
    image[:, 0::2] = np.clip(image[:, 0::2], 0, w - 1)
    image[:, 1::2] = np.clip(image[:, 1::2], 0, hgt - 1)
    lines = FeatureLines(np.round(image, 3), np.round(frontal, 3), (fw, fh))

    weaker = min(len(m) for m in fam.members)
    confidence = fam.explained * (1.0 - math.exp(-weaker / 8.0)) * (1.0 if aspect == "camera" else 0.5)
    if confidence < min_confidence:
        raise GeometryError(REFUSAL)
    vps_px = np.array([to_px_m @ v1, to_px_m @ v2])
    vps_px = np.where(np.abs(vps_px[:, 2:3]) > 1e-12, vps_px / np.where(np.abs(vps_px[:, 2:3]) > 1e-12,
                                                                        vps_px[:, 2:3], 1.0), vps_px)
    figures = {"family_sizes": [len(m) for m in fam.members]}
    return Suggestion(lines, hom, float(confidence), angle, vps_px, focal * s, aspect, source, figures)


def suggest_for_studio(photo: np.ndarray) -> tuple[FeatureLines, str]:
    """:func:`suggest_lines` as a studio geometry's ``suggest``: the lines and their description."""
    s = suggest_lines(photo)
    return s.lines, s.describe()
