"""A homography from corresponding feature lines: least squares, then a robust refinement.

The points are the lines' intersections (:func:`~weft.core.rectify.lines.line_correspondences`); the
lines themselves add a constraint each point lacks: the destination line, mapped by H, must lie on
the source line. The fit minimises, in source pixels,

* for every intersection point: the distance between H(dst point) and the src point, and
* for every line: the distances of H(both dst end points) to the infinite src line (so the end
  points drawn in the two frames need not correspond, only the lines),

with a Huber loss (quadratic up to 1 px, linear beyond) and then a Cauchy loss (scale 1 px, which
all but ignores a badly drawn line), by iteratively reweighted Levenberg-Marquardt on the 8
parameters of H in Hartley-normalised coordinates. The start is
OpenCV's ``findHomography`` on the points: RANSAC when there are 6 or more (so a badly placed line
cannot drag the start), plain least squares otherwise.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import GeometryError
from .lines import FAR_MARGIN, MIN_ANGLE_DEG, Correspondences, _homogeneous_lines, all_parallel, line_correspondences

__all__ = ["HomographyFit", "fit_homography", "homography_from_points", "apply_homography"]

HUBER_PX = 1.0
RANSAC_PX = 3.0
MAX_ITER = 30


@dataclass(frozen=True)
class HomographyFit:
    """A fitted homography and how well it fits.

    Attributes
    ----------
    matrix : (3, 3) float64
        Maps destination (frontal) pixel coordinates ``(x, y, 1)`` to source (photo) coordinates,
        up to scale; scaled so that the third coordinate is +1 at the destination frame's centre.
    points : int
        Intersection points used.
    inliers : int
        Points within 3 px after the fit.
    rms_points, rms_lines : float
        Root-mean-square residuals in source pixels: point distances, and distances of the mapped
        destination line end points to their source lines.
    correspondences : Correspondences
        The intersection points themselves.
    """

    matrix: np.ndarray
    points: int
    inliers: int
    rms_points: float
    rms_lines: float
    correspondences: Correspondences

    def figures(self) -> dict:
        return {
            "points": self.points,
            "inliers": self.inliers,
            "rms_points_px": round(self.rms_points, 4),
            "rms_lines_px": round(self.rms_lines, 4),
        }


def apply_homography(h: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """Points mapped by a homography.

    Parameters
    ----------
    h : ndarray, (3, 3)
        The homography.
    pts : ndarray, (K, 2)
        Points (x, y).

    Returns
    -------
    ndarray, float64 (K, 2)
        ``h @ (x, y, 1)``, dehomogenised.
    """
    pts = np.asarray(pts, dtype=np.float64).reshape(-1, 2)
    p = pts @ h[:, :2].T + h[:, 2]
    return p[:, :2] / p[:, 2:3]


def _normaliser(pts: np.ndarray) -> np.ndarray:
    """Hartley's similarity: centroid to the origin, mean distance sqrt(2)."""
    c = pts.mean(axis=0)
    d = np.sqrt(((pts - c) ** 2).sum(axis=1)).mean()
    s = math.sqrt(2.0) / d if d > 1e-12 else 1.0
    return np.array([[s, 0.0, -s * c[0]], [0.0, s, -s * c[1]], [0.0, 0.0, 1.0]])


def _check_spread(pts: np.ndarray, what: str) -> None:
    c = pts - pts.mean(axis=0)
    sv = np.linalg.svd(c, compute_uv=False)
    if len(sv) < 2 or sv[1] <= 1e-3 * max(sv[0], 1e-12):
        raise GeometryError(
            f"the {len(pts)} intersection points in {what} lie on one line: a homography "
            f"needs 4 points with no 3 on a line (draw lines in two directions)"
        )


def homography_from_points(dst: np.ndarray, src: np.ndarray) -> np.ndarray:
    """Direct linear transform (Hartley-normalised least squares) for ``src ~ H dst``.

    Parameters
    ----------
    dst, src : ndarray, (K, 2)
        Corresponding points, K >= 4.

    Returns
    -------
    ndarray, float64 (3, 3)
        H, destination -> source.

    References
    ----------
    Hartley & Zisserman, *Multiple View Geometry*, 2nd ed., §4.1 and §4.4 (the normalised DLT);
    Yan, Lee & Lin, "Patch-based synthesis for non-frontal-parallel textures", §3.
    """
    td, ts = _normaliser(dst), _normaliser(src)
    d = apply_homography(td, dst)
    s = apply_homography(ts, src)
    k = len(d)
    a = np.zeros((2 * k, 9))
    a[0::2, 0:2] = d
    a[0::2, 2] = 1
    a[0::2, 6:8] = -d * s[:, :1]
    a[0::2, 8] = -s[:, 0]
    a[1::2, 3:5] = d
    a[1::2, 5] = 1
    a[1::2, 6:8] = -d * s[:, 1:2]
    a[1::2, 8] = -s[:, 1]
    _, _, vt = np.linalg.svd(a)
    hn = vt[-1].reshape(3, 3)
    return np.linalg.inv(ts) @ hn @ td


def _residuals_and_jacobian(
    h8: np.ndarray,
    dst_pts: np.ndarray,
    src_pts: np.ndarray,
    line_pts: np.ndarray,
    line_coef: np.ndarray,
    jac: bool = True,
):
    """Residuals (points: 2 per point; lines: 1 per end point) and their Jacobian in the 8 params."""
    h = np.append(h8, 1.0)
    allp = np.vstack([dst_pts, line_pts])
    x, y = allp[:, 0], allp[:, 1]
    u = h[0] * x + h[1] * y + h[2]
    v = h[3] * x + h[4] * y + h[5]
    w = h[6] * x + h[7] * y + h[8]
    px, py = u / w, v / w
    k = len(dst_pts)
    r_pts = np.column_stack([px[:k] - src_pts[:, 0], py[:k] - src_pts[:, 1]]).ravel()
    a, b, c = line_coef[:, 0], line_coef[:, 1], line_coef[:, 2]
    r_lin = a * px[k:] + b * py[k:] + c
    r = np.concatenate([r_pts, r_lin])
    if not jac:
        return r, None
    one = np.ones_like(x)
    xy1 = np.column_stack([x, y, one]) / w[:, None]
    dpx = np.zeros((len(x), 8))
    dpy = np.zeros((len(x), 8))
    dpx[:, 0:3] = xy1
    dpy[:, 3:6] = xy1
    dpx[:, 6:8] = -(px[:, None]) * xy1[:, :2]
    dpy[:, 6:8] = -(py[:, None]) * xy1[:, :2]
    j_pts = np.empty((2 * k, 8))
    j_pts[0::2] = dpx[:k]
    j_pts[1::2] = dpy[:k]
    j_lin = a[:, None] * dpx[k:] + b[:, None] * dpy[k:]
    return r, np.vstack([j_pts, j_lin])


def _refine(h0: np.ndarray, dst_pts, src_pts, dst_lines, src_lines, scale_px: float, loss: str = "huber") -> np.ndarray:
    """Iteratively reweighted Levenberg-Marquardt of H in normalised coordinates, with a Huber
    (quadratic to ``scale_px``, then linear) or Cauchy (``log(1 + (r / scale)^2)``) loss."""
    line_pts = np.vstack([dst_lines[:, :2], dst_lines[:, 2:]])
    everything_d = np.vstack([dst_pts, line_pts]) if len(dst_pts) else line_pts
    everything_s = np.vstack([src_pts, src_lines[:, :2], src_lines[:, 2:]])
    td, ts = _normaliser(everything_d), _normaliser(everything_s)
    scale = ts[0, 0]  # normalised units per source pixel
    dn = apply_homography(td, dst_pts) if len(dst_pts) else dst_pts.reshape(0, 2)
    sn = apply_homography(ts, src_pts) if len(src_pts) else src_pts.reshape(0, 2)
    ln = apply_homography(td, line_pts)
    src_n = np.column_stack([apply_homography(ts, src_lines[:, :2]), apply_homography(ts, src_lines[:, 2:])])
    coef = _homogeneous_lines(src_n)
    coef = np.vstack([coef, coef])  # one per end point, in the order of line_pts
    hn = ts @ h0 @ np.linalg.inv(td)
    if abs(hn[2, 2]) < 1e-12:
        return h0
    hn = hn / hn[2, 2]
    p = hn.ravel()[:8].copy()
    delta = scale_px * scale
    lam = 1e-3

    def cost(r):
        a = np.abs(r)
        if loss == "cauchy":
            return float((0.5 * delta * delta * np.log1p((a / delta) ** 2)).sum())
        return float(np.where(a <= delta, 0.5 * r * r, delta * (a - 0.5 * delta)).sum())

    def weights(a):
        if loss == "cauchy":
            return 1.0 / (1.0 + (a / delta) ** 2)
        return np.where(a <= delta, 1.0, delta / np.maximum(a, 1e-300))

    r, jm = _residuals_and_jacobian(p, dn, sn, ln, coef)
    cur = cost(r)
    for _ in range(MAX_ITER):
        wts = weights(np.abs(r))
        jw = jm * wts[:, None]
        g = jw.T @ r
        hess = jw.T @ jm
        improved = False
        for _ in range(8):
            step = np.linalg.solve(hess + lam * np.diag(np.diag(hess) + 1e-12), -g)
            pn = p + step
            rn, _ = _residuals_and_jacobian(pn, dn, sn, ln, coef, jac=False)
            cn = cost(rn)
            if np.isfinite(cn) and cn <= cur:
                improved = True
                p, cur = pn, cn
                lam = max(lam / 10, 1e-9)
                break
            lam *= 10
        if not improved:
            break
        r, jm = _residuals_and_jacobian(p, dn, sn, ln, coef)
        if np.abs(step).max() < 1e-10:
            break
    hn = np.append(p, 1.0).reshape(3, 3)
    return np.linalg.inv(ts) @ hn @ td


def _normalise_sign(h: np.ndarray, dst_size: tuple[int, int]) -> np.ndarray:
    w, hgt = dst_size
    centre = np.array([(w - 1) / 2, (hgt - 1) / 2, 1.0])
    s = float(h[2] @ centre)
    if not math.isfinite(s) or abs(s) < 1e-300:
        raise GeometryError(
            "the feature lines map the centre of the frontal frame to infinity (the lines are inconsistent)"
        )
    return h / s


# Degenerate line sets can send a point to infinity (under the first estimate, a trial step of the
# refinement, or the fit itself): the refinement rejects non-finite costs, so numpy need not warn
# (a warning would be a second line on the CLI's stderr).
@np.errstate(divide="ignore", invalid="ignore", over="ignore")
def fit_homography(
    dst_lines: np.ndarray,
    src_lines: np.ndarray,
    dst_size: tuple[int, int],
    src_size: tuple[int, int],
    *,
    robust: bool = True,
    min_angle: float = MIN_ANGLE_DEG,
    margin: float = FAR_MARGIN,
) -> HomographyFit:
    """The homography mapping the destination frame onto the source frame, from line pairs.

    Parameters
    ----------
    dst_lines, src_lines : (N, 4) float arrays, N >= 4
        Corresponding lines ``[x1, y1, x2, y2]``: e.g. the frontal lines (destination) and the lines
        drawn on the photo (source).
    dst_size, src_size : (width, height)
        The two frames (for the "far outside" test of the intersections).
    robust : bool, default True
        Start from a RANSAC fit (3 px) when there are 6 or more points and refine with a Huber then
        a Cauchy loss (1 px); ``False`` uses plain least squares throughout.
    min_angle, margin
        Which line pairs give points; see :func:`~weft.core.rectify.lines.line_correspondences`.

    Returns
    -------
    HomographyFit
        ``matrix`` maps destination -> source (frontal -> photo), the paper's direction of
        rectification being its inverse. It is exact for a planar texture (section 3 of Yan, Lee &
        Lin uses a view morph instead; see :mod:`weft.core.rectify.warps` for that route).

    Raises
    ------
    GeometryError
        Fewer than 4 lines; all lines parallel; fewer than 4 usable intersection points (naming how
        many pairs were near-parallel or met far outside a frame); the points on one line.
    """
    n = len(dst_lines)
    if n < 4:
        raise GeometryError(
            f"a homography needs at least 4 feature lines, got {n} (draw 4 or more lines in at least two directions)"
        )
    if all_parallel([dst_lines, src_lines], min_angle):
        raise GeometryError(
            f"all {n} feature lines are parallel (within {min_angle:g}°): they do not cross, "
            f"so they give no points; draw lines in at least two directions"
        )
    corr = line_correspondences(dst_lines, src_lines, dst_size, src_size, min_angle=min_angle, margin=margin)
    k = len(corr)
    if k < 4:
        pairs = n * (n - 1) // 2
        raise GeometryError(
            f"only {k} of the {pairs} line pairs meet at a usable point (need 4): {corr.skipped_parallel} are "
            f"parallel within {min_angle:g}° and {corr.skipped_far} meet far outside the frame; "
            f"draw lines that cross each other inside the texture"
        )
    _check_spread(corr.dst, "the frontal frame")
    _check_spread(corr.src, "the photo")
    import cv2

    h0 = None
    if robust and k >= 6:
        h0, _ = cv2.findHomography(corr.dst, corr.src, cv2.RANSAC, RANSAC_PX, maxIters=2000, confidence=0.999)
    if h0 is None:
        h0 = homography_from_points(corr.dst, corr.src)
    if not np.all(np.isfinite(h0)) or abs(np.linalg.det(h0)) < 1e-300:
        raise GeometryError("the feature lines do not define a homography (degenerate configuration)")
    if robust:
        h = _refine(h0, corr.dst, corr.src, dst_lines, src_lines, HUBER_PX, "huber")
        h = _refine(h, corr.dst, corr.src, dst_lines, src_lines, HUBER_PX, "cauchy")
    else:
        h = _refine(h0, corr.dst, corr.src, dst_lines, src_lines, 1e9, "huber")
    if not np.all(np.isfinite(h)):
        h = h0
    h = _normalise_sign(h, dst_size)
    pts = apply_homography(h, corr.dst)
    d_pts = np.sqrt(((pts - corr.src) ** 2).sum(axis=1))
    ends = np.vstack([apply_homography(h, dst_lines[:, :2]), apply_homography(h, dst_lines[:, 2:])])
    coef = _homogeneous_lines(src_lines)
    coef = np.vstack([coef, coef])
    d_lin = ends[:, 0] * coef[:, 0] + ends[:, 1] * coef[:, 1] + coef[:, 2]
    return HomographyFit(
        h,
        k,
        int((d_pts <= RANSAC_PX).sum()),
        float(np.sqrt(np.mean(d_pts**2))),
        float(np.sqrt(np.mean(d_lin**2))),
        corr,
    )
