"""The suggestion itself (:mod:`weft.core.rectify.detect`): segments -> two families -> the
rectifying homography, affine then metric -> feature-line pairs, or the one-line refusal."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import cv2
import numpy as np

from ...errors import GeometryError
from ...geometry import FeatureLines
from ...image import validate_image
from ..homography import apply_homography
from .segments import WORK_SIDE, line_segments, refine_segments, repeat_segments, work_grey
from .vanishing import MAX_FOCAL, MIN_FOCAL, MIN_SPREAD_DEG, Families, direction_at, focal_sq, two_families

__all__ = [
    "Suggestion",
    "suggest_lines",
    "suggestion_from_families",
    "suggest_for_studio",
    "REFUSAL",
    "ASSUMED_FOCAL",
    "MIN_CONFIDENCE",
]

#: The one line said when the photo shows no two families of straight lines (nor of repeats).
REFUSAL = "no two families of straight lines found: draw feature lines"
FINE_SIDE = 1600  # a second look at up to this size when the reduced photo shows no two families
FINE_BELOW = 300  # ... and fewer segments than this (fine structure lost in the reduction)
REPEAT_SIDE = 400  # longer side of the photo the repeats are looked for on (SIFT doubles it inside)
ASSUMED_FOCAL = 1.2  # focal length (in photo longer sides) when the vanishing points leave it open
MIN_CONFIDENCE = 0.3  # a weaker suggestion is refused
MAX_FRONTAL_SIDE = 4096
REFINE_REACH = 1.5  # work pixels either side of a segment its full-resolution refit looks


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
        return (
            f"suggested {len(self.lines)} line pairs from {self.source}: confidence {self.confidence:.2f}, "
            f"directions {self.angle_deg:.0f}° apart{aspect}"
        )

    def report(self) -> dict:
        """The figures ``--report`` prints (JSON-able)."""
        return {
            "suggest_confidence": round(self.confidence, 3),
            "suggest_angle_deg": round(self.angle_deg, 2),
            "suggest_source": self.source,
            "suggest_aspect": self.aspect,
            "suggest_focal_px": round(self.focal_px, 1),
            "suggest_pairs": len(self.lines),
            **{f"suggest_{k}": v for k, v in self.figures.items()},
        }


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
        if (
            _in_front(h, corners)
            and np.all(img[:, 0] >= 0)
            and np.all(img[:, 0] <= w - 1)
            and np.all(img[:, 1] >= 0)
            and np.all(img[:, 1] <= hgt - 1)
        ):
            return np.array([a[0], a[1], b[0], b[1]]), apply_homography(inv, seg_px.reshape(-1, 2)).reshape(-1, 4)
        scale *= 0.93
    raise GeometryError(REFUSAL)


def _pick(positions: np.ndarray, weights: np.ndarray, lo: float, hi: float, k: int = 2) -> list[float]:
    """Up to ``k`` positions in (lo, hi), heaviest first, at least two fifths of the span apart."""
    out: list[float] = []
    span = hi - lo
    for i in np.argsort(-weights):
        p = positions[i]
        if not (lo + 0.02 * span < p < hi - 0.02 * span):
            continue
        if all(abs(p - q) > 0.4 * span for q in out):
            out.append(float(p))
        if len(out) == k:
            break
    return out


def suggest_lines(photo: np.ndarray, *, rng: None | int | np.random.Generator = 0, repeats: bool = True) -> Suggestion:
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
    full = photo if photo.ndim == 2 else cv2.cvtColor(photo, cv2.COLOR_RGB2GRAY)  # once for every look
    greys: dict = {}
    for side, source in attempts:
        if source == "fine lines":  # fine structure (a weave) may need every pixel: when few segments showed
            if max(w, hgt) <= WORK_SIDE or found >= FINE_BELOW:
                continue
            source = "lines"
        if side not in greys:
            greys[side] = work_grey(full, side)
        grey, k = greys[side]
        found_work = line_segments(grey) if source == "lines" else repeat_segments(grey, rng)
        seg_px = (found_work + 0.5) / k - 0.5
        if source == "lines":
            seg_px = refine_segments(full, seg_px, REFINE_REACH / k)
        found = max(found, len(seg_px)) if source == "lines" else found
        fam = (
            two_families((seg_px - np.tile(c, 2)) / s, rng, 1.0 / (k * s), lattice=source == "repeats")
            if len(seg_px)
            else None
        )
        if fam is None:
            continue
        try:
            out = suggestion_from_families(seg_px, fam.vps, fam.members, fam.explained, (w, hgt), source=source)
        except GeometryError:
            continue
        out.figures.update({"segments": int(found), "seconds": round(time.perf_counter() - t0, 4)})
        return out
    raise GeometryError(REFUSAL)


def suggestion_from_families(
    seg_px: np.ndarray,
    vps: np.ndarray,
    members: list,
    explained: float,
    size: tuple[int, int],
    *,
    source: str = "lines",
    min_confidence: float = MIN_CONFIDENCE,
) -> Suggestion:
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
    fam = Families(np.asarray(vps, dtype=np.float64), [np.asarray(m) for m in members], explained)
    # normalised coordinates: u = (x - c) / s; the principal point is the origin
    used = seg_px[np.concatenate(fam.members)]
    x0 = np.median(((used[:, :2] + used[:, 2:]) / 2 - c) / s, axis=0)
    v1, v2 = fam.vps
    d1, d2 = direction_at(v1, x0), direction_at(v2, x0)
    angle = math.degrees(math.acos(min(1.0, abs(float(d1 @ d2)))))
    if angle < MIN_SPREAD_DEG:
        raise GeometryError(REFUSAL)
    if abs(d1[0]) < abs(d2[0]):  # the more horizontal family along x
        v1, v2 = v2, v1
        fam.members.reverse()
    members = np.concatenate(fam.members)
    f2 = focal_sq(v1, v2)
    if f2 is not None and f2 <= MIN_FOCAL**2:
        raise GeometryError(REFUSAL)
    if f2 is not None and f2 < MAX_FOCAL**2:
        focal, aspect = math.sqrt(f2), "camera"
    else:
        focal, aspect = 2.0 * ASSUMED_FOCAL, "assumed focal"
    hn = _plane_homography(v1, v2, focal, x0)
    to_px_m = np.array([[s, 0, c[0]], [0, s, c[1]], [0, 0, 1.0]])
    h_plane = to_px_m @ hn  # plane -> photo pixels
    rect, plane_seg = _frame(h_plane, seg_px[members], (w, hgt))

    # frontal pixels: the photo's pixel density over the region, at most MAX_FRONTAL_SIDE
    quad = apply_homography(
        h_plane, np.array([[rect[0], rect[1]], [rect[2], rect[1]], [rect[2], rect[3]], [rect[0], rect[3]]])
    )
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
        if len(picks) == 1:  # the frame's edge farther from it
            picks.append(0.0 if picks[0] > span / 2 else float(span))
        elif not picks:
            picks = [0.0, float(span)]
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
    vps_px = np.where(
        np.abs(vps_px[:, 2:3]) > 1e-12, vps_px / np.where(np.abs(vps_px[:, 2:3]) > 1e-12, vps_px[:, 2:3], 1.0), vps_px
    )
    figures = {"family_sizes": [len(m) for m in fam.members]}
    return Suggestion(lines, hom, float(confidence), angle, vps_px, focal * s, aspect, source, figures)


def suggest_for_studio(photo: np.ndarray) -> tuple[FeatureLines, str]:
    """:func:`suggest_lines` as a studio geometry's ``suggest``: the lines and their description."""
    s = suggest_lines(photo)
    return s.lines, s.describe()
