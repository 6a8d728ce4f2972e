"""``weft rectify``: rectification's parameters, Python API and method (see the package)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from ..errors import GeometryError, InvalidParameter
from ..image import validate_image
from ..jobs import ProgressReporter
from ..params import Params, param
from ..registry import InputSpec, Method, Result
from ..studio import Figure
from .lines import FeatureLines, load_feature_lines
from .warps import WARPS, WarpPlan, homography_plan, plan_warp

INTERPOLATIONS = ("cubic", "linear", "lanczos")


@dataclass(frozen=True)
class WarpParams(Params):
    """The rectification parameters, shared by ``weft rectify`` and ``weft nfpt`` (which add theirs)."""

    lines: FeatureLines | None = param(
        None,
        kind="geometry",
        type=FeatureLines,
        optional=True,
        help="the lines drawn on the photo and where each lies seen from the front: a JSON "
        "file {image_lines, frontal_lines, frontal_size}, or that JSON text itself, "
        "starting with { (nfpt without lines takes the photo as frontal)",
    )
    warp: str = param(
        "homography",
        choices=WARPS,
        help="how the photo is straightened: homography = exact for a flat surface, outvotes a badly "
        "drawn line; morph = the paper's view morph, for surfaces that are not one plane (needs "
        "8 points off one plane); lines = Beier-Neely field morph, bends between the lines, for "
        "gently curved surfaces",
    )
    a: float = param(
        1.0,
        lo=0.001,
        hi=1000.0,
        symbol="a",
        step=0.1,
        help="Beier-Neely (morph, lines): distance in pixels within which a line pulls at full "
        "strength (weight (length^p / (a + dist))^b); small values make the warp snap to the "
        "lines, large ones smooth it",
    )
    b: float = param(
        2.0,
        lo=0.0,
        hi=4.0,
        symbol="b",
        step=0.1,
        help="Beier-Neely (morph, lines): how fast a line's pull falls off with distance; higher keeps"
        " each line's effect local",
    )
    p: float = param(
        0.5,
        lo=0.0,
        hi=2.0,
        symbol="p",
        step=0.1,
        help="Beier-Neely (morph, lines): how much more long lines pull than short ones (0 = all equal)",
    )


@dataclass(frozen=True)
class RectifyParams(WarpParams):
    """Parameters of ``weft rectify`` (and the rectification step of ``weft nfpt``)."""

    size: tuple[int, int] | None = param(
        None,
        kind="size",
        lo=2,
        hi=16384,
        optional=True,
        help="size WIDTHxHEIGHT of the rectified image; default the lines' frontal_size "
        "(frontal coordinates are scaled to it)",
    )
    interpolation: str = param(
        "cubic",
        choices=INTERPOLATIONS,
        help="resampling of the photo: cubic (sharp), linear (quick, softer), lanczos "
        "(sharpest, may ring at hard edges)",
    )


@dataclass(frozen=True)
class Rectified:
    """A rectified (frontal) image and how it was made.

    Attributes
    ----------
    image : float32 (h, w[, 3])
        The frontal image, ``frontal_size``; zero where nothing of the photo maps.
    mask : bool (h, w)
        Where the frontal pixel's source lies inside the photo.
    homography : (3, 3) float64 or None
        Frontal -> photo (``homography`` warp; None for the morphs).
    plan : WarpPlan
        The fitted warp; ``plan.apply(other_image)`` warps another image of the photo's size alike.
    figures : dict
        Cheap JSON-able numbers: points used, residuals, coverage.
    """

    image: np.ndarray
    mask: np.ndarray
    homography: np.ndarray | None
    plan: WarpPlan
    figures: Mapping = field(default_factory=dict)


def scale_lines(lines: np.ndarray, from_size: tuple[int, int], to_size: tuple[int, int]) -> np.ndarray:
    """Lines of a frame of ``from_size`` in a frame of ``to_size`` (pixel areas mapped onto each other).

    Parameters
    ----------
    lines : array_like, (N, 4)
        Lines ``x1, y1, x2, y2`` in pixel coordinates of the first frame.
    from_size, to_size : (int, int)
        The frames' width and height.

    Returns
    -------
    ndarray, float64 (N, 4)
    """
    sx = to_size[0] / from_size[0]
    sy = to_size[1] / from_size[1]
    out = np.array(lines, dtype=np.float64).reshape(-1, 4).copy()
    out[:, 0::2] = (out[:, 0::2] + 0.5) * sx - 0.5
    out[:, 1::2] = (out[:, 1::2] + 0.5) * sy - 0.5
    return out


class Rectifier:
    """Rectifies one photo again and again (the live path: a line end point being dragged).

    Parameters
    ----------
    photo : float32 (H, W) or (H, W, 3) in [0, 1]
        Validated once here.
    interpolation : {"cubic", "linear", "lanczos"}, default "cubic"
        Resampling of the photo. Cubic keeps a sub-pixel-accurate rectification sharp; linear is
        faster and blurs a little more.

    Examples
    --------
    >>> r = Rectifier(photo)                                                    # doctest: +SKIP
    >>> out = r.rectify(image_lines, frontal_lines, (512, 384))                 # doctest: +SKIP
    >>> out.image.shape, out.homography                                         # doctest: +SKIP
    """

    def __init__(self, photo: np.ndarray, *, interpolation: str = "cubic") -> None:
        if interpolation not in INTERPOLATIONS:
            raise InvalidParameter(
                f"parameter 'interpolation' = {interpolation!r} is not one of {', '.join(INTERPOLATIONS)}",
                name="interpolation",
                value=interpolation,
            )
        self.photo = validate_image(photo, "photo")
        self.size = (self.photo.shape[1], self.photo.shape[0])
        self.interpolation = interpolation

    def plan(
        self,
        image_lines,
        frontal_lines,
        frontal_size,
        *,
        warp: str = "homography",
        a: float = 1.0,
        b: float = 2.0,
        p: float = 0.5,
    ) -> WarpPlan:
        """Fit the warp only (see :func:`rectify` for the parameters)."""
        frontal_size = _check_size(frontal_size)
        return plan_warp(
            np.asarray(frontal_lines, dtype=np.float64),
            np.asarray(image_lines, dtype=np.float64),
            frontal_size,
            self.size,
            warp=warp,
            a=a,
            b=b,
            p=p,
            src_input="photo",
        )

    def rectify(
        self,
        image_lines,
        frontal_lines,
        frontal_size,
        *,
        warp: str = "homography",
        a: float = 1.0,
        b: float = 2.0,
        p: float = 0.5,
    ) -> Rectified:
        """Fit the warp and resample the photo into the frontal frame (see :func:`rectify`)."""
        return self.apply(self.plan(image_lines, frontal_lines, frontal_size, warp=warp, a=a, b=b, p=p))

    def warp(self, homography: np.ndarray, frontal_size) -> Rectified:
        """Resample with a known homography (frontal -> photo): no fitting at all."""
        frontal_size = _check_size(frontal_size)
        w, h = frontal_size
        return self.apply(homography_plan(homography, frontal_size, self.size, positive_at=((w - 1) / 2, (h - 1) / 2)))

    def apply(self, plan: WarpPlan) -> Rectified:
        """Resample the photo with a fitted plan."""
        image, mask = plan.apply(self.photo, interpolation=self.interpolation)
        figures = dict(plan.figures)
        figures["warp"] = plan.kind
        figures["coverage"] = round(float(mask.mean()), 4)
        return Rectified(image, mask, plan.homography, plan, figures)


def _check_size(size) -> tuple[int, int]:
    from ..params import MAX_SIDE

    try:
        w, h = (int(size[0]), int(size[1]))
    except (TypeError, ValueError, IndexError):
        raise GeometryError(f"frontal_size = {size!r} must be (width, height)") from None
    if not (2 <= w <= MAX_SIDE and 2 <= h <= MAX_SIDE):
        raise GeometryError(f"frontal_size = {w}x{h} has a side outside 2..{MAX_SIDE}")
    return w, h


def rectify(
    photo: np.ndarray,
    image_lines,
    frontal_lines,
    frontal_size,
    *,
    warp: str = "homography",
    a: float = 1.0,
    b: float = 2.0,
    p: float = 0.5,
    interpolation: str = "cubic",
) -> Rectified:
    """Rectify a photo of a texture seen at an angle, from corresponding feature lines (§3).

    Parameters
    ----------
    photo : float32 (H, W) or (H, W, 3) in [0, 1]
        The non-frontal-parallel texture photo, I_0 of the paper.
    image_lines : (N, 4) array-like
        Lines ``[x1, y1, x2, y2]`` drawn on the photo (pixels, origin top-left, pixel centres at
        integers). End points must lie inside the photo (2 px of slack); no line shorter than 1 px.
    frontal_lines : (N, 4) array-like
        Where each line lies in the frontal frame (line i <-> line i), inside the frame.
    frontal_size : (width, height)
        The frontal frame, 2..16384 per side; the output's size.
    warp : {"homography", "morph", "lines"}, default "homography"
        ``homography``: needs >= 4 lines giving >= 4 intersection points, not all on one line;
        exact for a plane. ``morph``: the paper's route (fundamental matrix from >= 8 points where
        the segments cross, pre-warp to parallel views, Beier-Neely morph, post-warp, composed into
        one resampling); raises GeometryError when the points lie on one plane (F undetermined).
        ``lines``: Beier-Neely field morph from the line pairs (>= 1 line); end point i of a photo
        line corresponds to end point i of its frontal line.
    a, b, p : float, defaults 1, 2, 0.5
        Beier-Neely weight ``(length^p / (a + dist))^b`` (morph, lines); ranges 1e-3..1000,
        0..4, 0..2.
    interpolation : {"cubic", "linear", "lanczos"}, default "cubic"

    Returns
    -------
    Rectified
        ``image`` (frontal_size, the photo's channels), ``mask``, ``homography`` (frontal -> photo,
        for the homography warp), ``plan`` and ``figures`` (points, inliers, RMS residuals in px,
        coverage).

    Raises
    ------
    GeometryError
        Too few lines, parallel-only lines, zero-length lines, lines outside the image, too few
        usable intersections, a planar configuration for ``morph`` (one line, naming the line).
    ImageError
        A photo that is not a valid image.
    """
    return Rectifier(photo, interpolation=interpolation).rectify(
        image_lines, frontal_lines, frontal_size, warp=warp, a=a, b=b, p=p
    )


def rectify_feature_lines(
    photo: np.ndarray,
    lines: FeatureLines | str,
    *,
    size: tuple[int, int] | None = None,
    warp: str = "homography",
    a: float = 1.0,
    b: float = 2.0,
    p: float = 0.5,
    interpolation: str = "cubic",
) -> Rectified:
    """:func:`rectify` with parsed feature lines (or a JSON file name / JSON text).

    Parameters
    ----------
    photo : ndarray, float32 (H, W) or (H, W, 3)
        The photo of the texture.
    lines : FeatureLines or str
        The feature lines, or a JSON file name or JSON text (see :func:`load_feature_lines`).
    size : (int, int), optional
        Rescales the frontal frame: the frontal lines are scaled from ``lines.frontal_size`` to
        ``size`` and the output has that size.
    warp, a, b, p, interpolation
        As in :func:`rectify`.

    Returns
    -------
    Rectified

    Raises
    ------
    GeometryError
        Malformed or degenerate lines (see :func:`rectify`).

    References
    ----------
    Yan, Lee & Lin, "Patch-based synthesis for non-frontal-parallel textures", §3.
    """
    if not isinstance(lines, FeatureLines):
        lines = load_feature_lines(lines)
    frontal, fsize = lines.frontal_lines, lines.frontal_size
    if size is not None:
        frontal = scale_lines(frontal, fsize, size)
        fsize = _check_size(size)
    return rectify(photo, lines.image_lines, frontal, fsize, warp=warp, a=a, b=b, p=p, interpolation=interpolation)


def _run(inputs: Mapping[str, np.ndarray], params: RectifyParams, *, rng=None, progress=None, cancel=None) -> Result:
    if params.lines is None:
        raise InvalidParameter(
            "weft rectify needs --lines L.json (feature lines on the photo and in the frontal frame)", name="lines"
        )
    lines = params.lines
    report = ProgressReporter(progress, "rectify", 1)
    if cancel is not None:
        cancel.raise_if_cancelled()
    out = rectify_feature_lines(
        inputs["photo"],
        lines,
        size=params.size,
        warp=params.warp,
        a=params.a,
        b=params.b,
        p=params.p,
        interpolation=params.interpolation,
    )
    report.update(1, preview=out.image)
    figures = dict(out.figures)
    if out.homography is not None:
        figures["homography"] = homography_figure(out.homography)
    return Result(out.image, figures)


#: How people read the rectification's figures (a method that rectifies, e.g. NFPT, shows them in its
#: status line through its studio description; the report keeps the keys).
FIGURES = {
    "points": Figure("points"),
    "inliers": Figure("inliers"),
    "rms_points_px": Figure("error", "px", digits=2),
    "rms_lines_px": Figure("line error", "px", digits=2),
    "lines": Figure("lines"),
    "plane_rms_px": Figure("plane error", "px", digits=2),
    "warp": Figure("warp"),
    "view": Figure("view"),
    "coverage": Figure("coverage", "%"),
}


def homography_figure(h: np.ndarray) -> list[list[float]]:
    """A homography as nested lists for reports.

    Parameters
    ----------
    h : ndarray, (3, 3)
        The homography.

    Returns
    -------
    list of list of float
        ``h`` scaled to ``h[2][2] = 1``, as in the bundled example's JSON.
    """
    h = np.asarray(h, dtype=np.float64)
    if abs(h[2, 2]) > 1e-12:
        h = h / h[2, 2]
    return [[round(float(v), 10) for v in row] for row in h]


def warm_up() -> None:
    """Load the Beier-Neely kernel (numba's cache) on a tiny frame."""
    from .._kernels import warps as _k

    mx = np.empty((2, 2), np.float32)
    my = np.empty((2, 2), np.float32)
    lines = np.array([[0.0, 0.0, 1.0, 1.0]])
    _k.field_map(lines, lines, 1.0, 2.0, 0.5, np.eye(3), np.eye(3), mx, my)


METHOD = Method(
    name="rectify",
    summary="rectify a photo of a texture seen at an angle from feature lines (Yan, Lee & Lin §3)",
    params=RectifyParams,
    inputs=(InputSpec("photo", "the photo of the texture (non-frontal-parallel)"),),
    run=_run,
    warm_up=warm_up,
    # The default homography warp is numpy + OpenCV: loading the numba kernel of the morphs before
    # every command would cost more than the run itself; the studio still loads it.
    warm_up_in_cli=False,
)
