"""The three ways a frame is warped onto another from corresponding feature lines.

* ``homography`` -- one projective map fitted to the lines (:mod:`weft.core.rectify.homography`); exact
  for a planar texture, which is what a non-frontal-parallel texture photo usually is.
* ``morph`` -- the paper's route (Yan, Lee & Lin §3, after Seitz & Dyer's view morphing): the
  fundamental matrix from >= 8 intersection points, pre-warps of both frames to parallel views
  (``cv2.stereoRectifyUncalibrated``), Beier-Neely's field morph between the pre-warped lines, and
  the post-warp (inverse of the destination's pre-warp). The three warps are composed into one
  backward map and the image is resampled once (the paper warps three times; the geometry is the
  same, with a third of the blur). **When all the points lie on one plane the fundamental matrix is
  undetermined** (a 3-parameter family of matrices fits them exactly): this is detected -- the
  points fit one homography within ``planar_tol`` pixels -- and reported as a GeometryError rather
  than producing a garbage warp. For a planar texture use ``homography``.
* ``lines`` -- Beier-Neely's field morph directly from the line pairs (``a``, ``b``, ``p`` of their
  paper), for textures on gently curved surfaces; it is not projective, so on a plane it is exact
  only on the lines themselves.

A :class:`WarpPlan` is what the fitting produces; ``plan.apply(image)`` resamples any image of the
source frame into the destination frame, so one fit serves many images (the live preview).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import GeometryError, InvalidParameter
from ..geometry.reading import _short
from .homography import HomographyFit, apply_homography, fit_homography, homography_from_points
from .lines import check_lines, line_correspondences

__all__ = ["WARPS", "WarpPlan", "plan_warp", "homography_plan", "PLANAR_TOL_PX"]

WARPS = ("homography", "morph", "lines")
PLANAR_TOL_PX = 1.0
_INTERP = {"nearest": 0, "linear": 1, "cubic": 2, "lanczos": 4}


@dataclass
class WarpPlan:
    """How to resample an image of the source frame into the destination frame.

    Attributes
    ----------
    kind : {"homography", "morph", "lines"}
    dst_size, src_size : (width, height)
    homography : (3, 3) array or None
        Destination -> source, for ``homography`` plans.
    maps : (map_x, map_y) float32 arrays or None
        Backward maps (source coordinates of every destination pixel), for ``morph`` and ``lines``.
    fit : HomographyFit or None
    figures : dict
        Cheap JSON-able numbers about the fit (points used, residuals, ...).
    """

    kind: str
    dst_size: tuple[int, int]
    src_size: tuple[int, int]
    homography: np.ndarray | None = None
    maps: tuple[np.ndarray, np.ndarray] | None = None
    fit: HomographyFit | None = None
    figures: dict = field(default_factory=dict)

    def apply(
        self, image: np.ndarray, *, interpolation: str = "cubic", supersample: int = 1, alpha: bool = False
    ) -> tuple[np.ndarray, np.ndarray]:
        """Resample ``image`` (the source frame) into the destination frame.

        Parameters
        ----------
        image : float32 (H, W) or (H, W, 3)
            An image of the source frame's size.
        interpolation : {"cubic", "linear", "nearest", "lanczos"}, default "cubic"
            OpenCV's interpolation; cubic results are clipped to [0, 1].
        supersample : int, default 1
            Sample an s x s grid per destination pixel and average (anti-aliasing where the warp
            shrinks the image, e.g. a texture put back into a receding view).
        alpha : bool, default False
            Return a float32 coverage in [0, 1] (fraction of samples that came from inside the
            source) instead of a boolean mask.

        Returns
        -------
        (image, mask)
            The warped image (zeros where nothing maps) and where it is valid: a bool mask of the
            destination pixels whose source position lies inside the source image, or the coverage.
        """
        import cv2

        flags = _INTERP.get(interpolation)
        if flags is None:
            raise InvalidParameter(
                f"parameter 'interpolation' = {interpolation!r} is not one of {', '.join(_INTERP)}",
                name="interpolation",
                value=interpolation,
            )
        sw, sh = self.src_size
        if image.shape[1] != sw or image.shape[0] != sh:
            raise GeometryError(f"the warp was fitted for a {sw}x{sh} image, not {image.shape[1]}x{image.shape[0]}")
        dw, dh = self.dst_size
        s = int(supersample)
        # Samples that land inside are interpolated from the image continued by its edge (a black
        # frame would ring into them: a cubic kernel's negative lobes over the step to 0); samples
        # outside are 0, so a supersampled pixel is its colour premultiplied by its coverage.
        if (
            self.kind == "homography"
            and self.homography is not None
            and s == 1
            and _all_in_front(self.homography, self.dst_size)
        ):
            out = cv2.warpPerspective(
                image, self.homography, (dw, dh), flags=flags | cv2.WARP_INVERSE_MAP, borderMode=cv2.BORDER_REPLICATE
            )
            ones = np.ones((sh, sw), np.uint8)
            cover = cv2.warpPerspective(
                ones,
                self.homography,
                (dw, dh),
                flags=cv2.INTER_NEAREST | cv2.WARP_INVERSE_MAP,
                borderMode=cv2.BORDER_CONSTANT,
                borderValue=0,
            )
            mask = cover.astype(bool)
            out[~mask] = 0.0
        else:
            mx, my = self._maps(s)
            out = cv2.remap(image, mx, my, flags, borderMode=cv2.BORDER_REPLICATE)
            inside = (mx >= -0.5) & (mx <= sw - 0.5) & (my >= -0.5) & (my <= sh - 0.5)
            out[~inside] = 0.0
            if s > 1:
                out = cv2.resize(out, (dw, dh), interpolation=cv2.INTER_AREA)
                cov = cv2.resize(inside.astype(np.float32), (dw, dh), interpolation=cv2.INTER_AREA)
                mask = cov if alpha else cov >= 0.999
                if alpha:
                    return _clip(out, flags), mask
            else:
                mask = inside
        if out.ndim == 3 and out.shape[2] == 1:
            out = out[..., 0]
        if alpha:
            return _clip(out, flags), mask.astype(np.float32)
        return _clip(out, flags), mask

    def _maps(self, s: int) -> tuple[np.ndarray, np.ndarray]:
        dw, dh = self.dst_size
        if s == 1 and self.maps is not None:
            return self.maps
        if self.kind == "homography":
            assert self.homography is not None  # a homography plan carries its matrix
            return homography_maps(self.homography, (dw * s, dh * s), scale=s)
        assert self.maps is not None  # morph and lines plans carry their maps
        mx, my = self.maps
        if s == 1:
            return mx, my
        # Maps of a morph are smooth: interpolate them to the finer grid (sample centres).
        import cv2

        xs = (np.arange(dw * s, dtype=np.float32) + 0.5) / s - 0.5
        ys = (np.arange(dh * s, dtype=np.float32) + 0.5) / s - 0.5
        gx, gy = np.meshgrid(xs, ys)
        fx = cv2.remap(mx, gx, gy, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
        fy = cv2.remap(my, gx, gy, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
        bad = mx < -1e5
        if bad.any():
            badf = cv2.remap(bad.astype(np.float32), gx, gy, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE) > 0
            fx[badf] = -1e6
            fy[badf] = -1e6
        return fx, fy


def _clip(out: np.ndarray, flags: int) -> np.ndarray:
    out = np.ascontiguousarray(out, dtype=np.float32)
    if flags in (2, 4):
        np.clip(out, 0.0, 1.0, out=out)
    return out


def _pair(size) -> tuple[int, int]:
    """``(width, height)`` of a size given as any pair."""
    w, h = size
    return w, h


def _all_in_front(h: np.ndarray, size: tuple[int, int]) -> bool:
    """Whether the third coordinate of ``h`` is positive over the whole frame (checked at its corners:
    it is affine in x and y)."""
    w, hgt = size
    corners = np.array([[-0.5, -0.5, 1], [w - 0.5, -0.5, 1], [w - 0.5, hgt - 0.5, 1], [-0.5, hgt - 0.5, 1]])
    return bool(np.all(corners @ h[2] > 1e-9))


def homography_maps(h: np.ndarray, size: tuple[int, int], *, scale: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """Backward maps of a homography over a frame.

    Points behind the horizon (third coordinate <= 0: ``h`` is scaled so that it is positive on the
    texture) get coordinates far outside any image.

    Parameters
    ----------
    h : ndarray, (3, 3)
        Destination -> source.
    size : (int, int)
        The destination frame's width and height (already ``scale`` times finer).
    scale : int, default 1
        With s > 1 the frame is an s-times finer grid of the destination (sample centres).

    Returns
    -------
    map_x, map_y : ndarray, float32 (H, W)
        The source coordinates of every destination pixel, for ``cv2.remap``.
    """
    w, hgt = size
    xs = (np.arange(w, dtype=np.float64) + 0.5) / scale - 0.5
    ys = (np.arange(hgt, dtype=np.float64) + 0.5) / scale - 0.5
    gx, gy = np.meshgrid(xs, ys)
    den = h[2, 0] * gx + h[2, 1] * gy + h[2, 2]
    good = den > 1e-12
    den = np.where(good, den, 1.0)
    mx = (h[0, 0] * gx + h[0, 1] * gy + h[0, 2]) / den
    my = (h[1, 0] * gx + h[1, 1] * gy + h[1, 2]) / den
    big = 1e6
    mx = np.where(good, np.clip(mx, -big, big), -big).astype(np.float32)
    my = np.where(good, np.clip(my, -big, big), -big).astype(np.float32)
    return mx, my


def _check_beier_neely(a: float, b: float, p: float) -> None:
    for name, v, lo, hi in (("a", a, 1e-3, 1000.0), ("b", b, 0.0, 4.0), ("p", p, 0.0, 2.0)):
        if not (isinstance(v, (int, float)) and math.isfinite(v) and lo <= v <= hi):
            from ..params import out_of_range

            raise out_of_range(name, v, lo, hi, "Beier-Neely weight (length^p / (a + dist))^b")


def homography_plan(
    h: np.ndarray,
    dst_size: tuple[int, int],
    src_size: tuple[int, int],
    fit: HomographyFit | None = None,
    *,
    positive_at: tuple[float, float] | None = None,
) -> WarpPlan:
    """A plan from a known homography (the fast path when it is given).

    The sign of ``h`` matters (its third coordinate must be positive where the plane is in front of
    the camera); ``positive_at``, a destination point known to be on the texture, fixes it.

    Parameters
    ----------
    h : ndarray, (3, 3)
        Destination -> source.
    dst_size, src_size : (int, int)
        The frames' width and height.
    fit : HomographyFit, optional
        The fit it came from, for the plan's figures.
    positive_at : (float, float), optional
        A destination point on the texture.

    Returns
    -------
    WarpPlan

    Raises
    ------
    GeometryError
        ``h`` is not an invertible 3x3 matrix of finite numbers.
    """
    h = np.asarray(h, dtype=np.float64)
    if h.shape != (3, 3) or not np.all(np.isfinite(h)) or abs(np.linalg.det(h)) < 1e-300:
        raise GeometryError(f"homography must be an invertible 3x3 matrix of finite numbers, not {_short(h)}")
    if positive_at is not None and float(h[2] @ np.array([positive_at[0], positive_at[1], 1.0])) < 0:
        h = -h
    figures = fit.figures() if fit is not None else {}
    return WarpPlan("homography", _pair(dst_size), _pair(src_size), homography=h, fit=fit, figures=figures)


def plan_warp(
    dst_lines: np.ndarray,
    src_lines: np.ndarray,
    dst_size: tuple[int, int],
    src_size: tuple[int, int],
    *,
    warp: str = "homography",
    a: float = 1.0,
    b: float = 2.0,
    p: float = 0.5,
    robust: bool = True,
    planar_tol: float = PLANAR_TOL_PX,
    check: bool = True,
    dst_name: str = "the frontal frame",
    src_name: str = "the photo",
    dst_key: str = "frontal line",
    src_key: str = "image line",
    src_input: str | None = None,
) -> WarpPlan:
    """Fit a warp that maps the source frame onto the destination frame from corresponding lines.

    Parameters
    ----------
    dst_lines, src_lines : (N, 4) float arrays
        Line i of the destination frame corresponds to line i of the source frame. Rectification:
        destination = frontal frame, source = photo. Re-projection: destination = the view,
        source = the synthesized texture.
    dst_size, src_size : (width, height)
    warp : {"homography", "morph", "lines"}, default "homography"
        See the module docstring.
    a, b, p : float, defaults 1, 2, 0.5
        Beier-Neely's weight ``(length^p / (a + dist))^b`` (``morph`` and ``lines``): ``a`` > 0 in
        pixels (1e-3..1000; small = a pixel on a line follows it exactly), ``b`` 0..4 (how fast a
        line's influence falls off with distance; their paper: 0.5..2), ``p`` 0..2 (0: all lines
        equal; 1: longer lines stronger).
    robust : bool, default True
        Robust homography fit (see :func:`~weft.core.rectify.homography.fit_homography`).
    planar_tol : float, default 1 px
        ``morph``: if every intersection point fits one homography within this RMS, the points are
        on one plane and the fundamental matrix is undetermined: GeometryError.
    check : bool, default True
        Reject zero-length lines and lines outside their frames.
    dst_name, src_name, dst_key, src_key : str
        How the frames and lines are named in error messages.
    src_input : str, optional
        The method input the source frame is (see :func:`~weft.core.rectify.lines.check_lines`).

    Returns
    -------
    WarpPlan

    Raises
    ------
    GeometryError
        Too few lines or points, parallel-only lines, a zero-length line, a line outside its frame,
        a planar configuration for ``morph``, a failed pre-warp.
    """
    if warp not in WARPS:
        raise InvalidParameter(f"parameter 'warp' = {warp!r} is not one of {', '.join(WARPS)}", name="warp", value=warp)
    dst_lines = np.asarray(dst_lines, dtype=np.float64).reshape(-1, 4)
    src_lines = np.asarray(src_lines, dtype=np.float64).reshape(-1, 4)
    if len(dst_lines) != len(src_lines):
        raise GeometryError(f"{len(src_lines)} {src_key}s but {len(dst_lines)} {dst_key}s: they must pair up")
    if len(dst_lines) == 0:
        raise GeometryError("no feature lines: draw lines on the photo and their positions in the frontal frame")
    if check:
        check_lines(src_lines, src_size, key=src_key, frame=src_name, input=src_input)
        check_lines(dst_lines, dst_size, key=dst_key, frame=dst_name)
    if warp == "homography":
        fit = fit_homography(dst_lines, src_lines, dst_size, src_size, robust=robust)
        return homography_plan(fit.matrix, dst_size, src_size, fit)  # the fit is positive at the frame centre
    _check_beier_neely(a, b, p)
    from .._kernels import warps as _k

    dw, dh = dst_size
    mx = np.empty((dh, dw), np.float32)
    my = np.empty((dh, dw), np.float32)
    if warp == "lines":
        eye = np.eye(3)
        _k.field_map(dst_lines, src_lines, float(a), float(b), float(p), eye, eye, mx, my)
        return WarpPlan("lines", _pair(dst_size), _pair(src_size), maps=(mx, my), figures={"lines": len(dst_lines)})
    return _morph_plan(dst_lines, src_lines, dst_size, src_size, a, b, p, planar_tol, mx, my, dst_name, src_name)


def _morph_plan(
    dst_lines,
    src_lines,
    dst_size,
    src_size,
    a,
    b,
    p,
    planar_tol,
    mx,
    my,
    dst_name="the frontal frame",
    src_name="the photo",
) -> WarpPlan:
    import cv2

    from .._kernels import warps as _k

    corr = line_correspondences(dst_lines, src_lines, dst_size, src_size, segments_only=True)
    k = len(corr)
    if k < 8:
        raise GeometryError(
            f"--warp morph needs at least 8 feature points for the fundamental matrix; the {len(dst_lines)} lines "
            f"cross at only {k} usable points ({corr.skipped_parallel} pairs parallel, {corr.skipped_far} meeting far "
            f"outside the frame, {corr.skipped_off_segment} not crossing on the segments)"
        )
    for pts, frame in ((corr.dst, dst_name), (corr.src, src_name)):
        # several lines crossing at one point give one point, however many pairs they make
        distinct = len(np.unique(np.round(pts, 2), axis=0))
        if distinct < 8:
            raise GeometryError(
                f"--warp morph needs at least 8 distinct feature points for the fundamental matrix; the {k} crossings "
                f"of the {len(dst_lines)} lines are only {distinct} distinct points in {frame}"
            )
    h = homography_from_points(corr.dst, corr.src)
    with np.errstate(divide="ignore", invalid="ignore"):  # a degenerate fit may send a point to infinity
        res = apply_homography(h, corr.dst) - corr.src
    rms = float(np.sqrt((res**2).sum(axis=1).mean()))
    if not math.isfinite(rms):
        raise GeometryError(
            f"--warp morph: the {k} feature points do not determine a fundamental matrix "
            f"(no homography of them is finite: a degenerate configuration)"
        )
    if rms <= planar_tol:
        raise GeometryError(
            f"--warp morph: all {k} feature points fit one homography within {rms:.2f} px, so they lie on one plane, "
            f"where the fundamental matrix is undetermined; use --warp homography (exact for a plane)"
        )
    f, _ = cv2.findFundamentalMat(corr.src, corr.dst, cv2.FM_8POINT)
    if f is None or f.shape != (3, 3) or not np.all(np.isfinite(f)):
        raise GeometryError(f"--warp morph: the {k} feature points do not determine a fundamental matrix")
    size = (max(dst_size[0], src_size[0]), max(dst_size[1], src_size[1]))
    ok, h_src, h_dst = cv2.stereoRectifyUncalibrated(corr.src, corr.dst, f, size)
    if not ok or not (np.all(np.isfinite(h_src)) and np.all(np.isfinite(h_dst))):
        raise GeometryError(
            "--warp morph: cannot pre-warp the two frames to parallel views (an epipole lies inside a frame)"
        )
    # Scale both pre-warps so that their third coordinate is positive on the frames.
    h_src = _positive(h_src, src_size)
    h_dst = _positive(h_dst, dst_size)

    def warp_lines(hm, ls):
        return np.column_stack([apply_homography(hm, ls[:, :2]), apply_homography(hm, ls[:, 2:])])

    src_pre = warp_lines(h_src, src_lines)
    dst_pre = warp_lines(h_dst, dst_lines)
    post = np.linalg.inv(h_src)
    centre = apply_homography(h_src, np.array([[(src_size[0] - 1) / 2, (src_size[1] - 1) / 2]]))[0]
    if float(post[2] @ np.array([centre[0], centre[1], 1.0])) < 0:
        post = -post
    _k.field_map(dst_pre, src_pre, float(a), float(b), float(p), h_dst, post, mx, my)
    figures = {"points": k, "plane_rms_px": round(rms, 3)}
    return WarpPlan("morph", _pair(dst_size), _pair(src_size), maps=(mx, my), figures=figures)


def _positive(h: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    w, hgt = size
    s = float(h[2] @ np.array([(w - 1) / 2, (hgt - 1) / 2, 1.0]))
    return h / s if abs(s) > 1e-300 else h
