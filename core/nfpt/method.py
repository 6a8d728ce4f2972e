"""``weft nfpt``: the NFPT pipeline's parameters, Python API and method (see the package)."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import GeometryError, InvalidParameter
from ..image import validate_image
from ..jobs import CancelToken, Progress
from ..params import out_of_range, param
from ..rectify import FIGURES as RECTIFY_FIGURES
from ..rectify import FeatureLines, View, WarpParams
from ..rectify.detect import suggest_for_studio
from ..registry import InputSpec, Method, Result
from ..studio import LINES, Figure, Geometry, Studio
from .synthesis import Synthesis, synthesize_patches

DEFAULT_BLOCK = 48
DEFAULT_OVERLAP = 12
# the frontal area kept from a rectification: pixels this far from the photo's edge or from the
# unmapped part are not used as source (cubic resampling reads 2 pixels around each sample)
_MASK_ERODE = 2


@dataclass(frozen=True)
class NfptParams(WarpParams):
    """Parameters of ``weft nfpt`` (Yan, Lee & Lin): rectification (the fields of ``WarpParams``),
    synthesis, repair, re-projection."""

    size: tuple = param(
        None,
        kind="size",
        lo=8,
        hi=16384,
        optional=True,
        help="size WIDTHxHEIGHT of the synthesized frontal texture; default twice the rectified one",
    )
    block: int = param(
        DEFAULT_BLOCK,
        lo=8,
        hi=512,
        symbol="B",
        help="side of the square patches copied: larger "
        "keeps larger texture elements (whole bricks) "
        "whole, smaller mixes them more",
    )
    overlap: int = param(
        DEFAULT_OVERLAP,
        lo=2,
        hi=256,
        help="how much each patch overlaps those already placed (the L-shaped neighbourhood): more"
        " matches and hides seams better; at most block/2",
    )
    sigma_d: float = param(
        None,
        kind="float",
        lo=0.1,
        hi=256.0,
        optional=True,
        symbol="σ_d",
        step=0.1,
        help="eq. 1: how far from the patch's edge, in pixels, the match still weighs pixels "
        "fully; small = only the edge counts (default overlap / 2)",
    )
    sigma_s: float = param(
        0.35,
        lo=0.01,
        hi=10.0,
        symbol="σ_s",
        step=0.01,
        help="eq. 2: how much the match favours feature pixels, those unlike the patch's "
        "dominant colour (mortar, cracks); smaller weighs features more (intensity 0..1)",
    )
    tol: int = param(
        2, lo=1, hi=64, help="variety: pick at random among the tol best-matching patches (1 = always the best)"
    )
    repair: bool = param(
        True,
        help="steps 4-7: re-make, pixel by pixel, the pixels along each seam where the two "
        "patches disagree, so broken lines join",
    )
    band: int = param(2, lo=1, hi=16, help="repair band: how many pixels on each side of a seam may be re-made")
    threshold: float = param(
        0.1,
        lo=0.0,
        hi=1.0,
        step=0.01,
        help="repair: how different the two patches must be at a pixel (RMS over channels, "
        "intensity 0..1) for it to be re-made; lower repairs more",
    )
    n: int = param(
        5,
        lo=3,
        hi=15,
        help="repair: side of the neighbourhood matched when a pixel is re-made (odd); "
        "larger follows larger structures",
    )
    smooth: bool = param(
        False, help="step 7: blur the re-made pixels slightly (Gaussian) to hide what the repair leaves"
    )
    view: View = param(
        None,
        kind="geometry",
        type=View,
        optional=True,
        help="put the result into this view: a JSON file (or the JSON text, starting with {), "
        '{"quad": [[x, y] x 4], "size": [w, h]} or view image_lines + texture frontal_lines; '
        "texture pixel coordinates",
    )
    into_photo: bool = param(
        False,
        help="put the larger synthesized texture back into the photo in place of the textured plane (a bigger wall)",
    )

    def check(self) -> None:
        if self.overlap * 2 > self.block:
            raise out_of_range("overlap", self.overlap, 2, self.block // 2, f"at most half of block = {self.block}")
        if self.n % 2 == 0:
            raise InvalidParameter(f"parameter 'n' = {self.n} must be odd (3, 5, 7, ...)", name="n", value=self.n)
        if self.view is not None and self.into_photo:
            raise InvalidParameter(
                "parameters 'view' and 'into_photo' exclude each other: give one of them", name="view", value=self.view
            )


def synthesize(
    texture: np.ndarray,
    *,
    size: tuple[int, int] | None = None,
    block: int = DEFAULT_BLOCK,
    overlap: int = DEFAULT_OVERLAP,
    sigma_d: float | None = None,
    sigma_s: float = 0.35,
    tol: int = 2,
    repair: bool = True,
    band: int = 2,
    threshold: float = 0.1,
    n: int = 5,
    smooth: bool = False,
    mask: np.ndarray | None = None,
    rng: None | int | np.random.Generator = None,
    progress: Callable[[Progress], None] | None = None,
    cancel: CancelToken | None = None,
    return_details: bool = False,
) -> np.ndarray | Synthesis:
    """Feature-weighted patch-based texture synthesis with seam repair (Yan, Lee & Lin §2).

    Parameters
    ----------
    texture : float32 (H, W) or (H, W, 3) in [0, 1]
        A frontal-parallel texture (e.g. a rectified photo).
    size : (width, height), optional
        Output size, 8..16384 per side; default twice the texture's.
    block : int, default 48
        Patch side B, 8..min(H, W).
    overlap : int, default 12
        Width of the L-shaped neighbourhood, 2..B/2; patches step by B - overlap.
    sigma_d : float, optional
        sigma of W_d (eq. 1), in pixels, 0.1..256; default overlap / 2.
    sigma_s : float, default 0.35
        sigma of W_s (eq. 2), in intensity units (0..1 scale), 0.01..10. Smaller = features
        (pixels far from the L-shape's dominant colour) count more against the rest.
        (Eqs. 1-2 share one symbol sigma in the paper; here each W has its own.)
    tol : int, default 2
        Pick uniformly among the ``tol`` most similar source positions, 1..64 (1 = the paper's best).
    repair : bool, default True
        Steps 4-7: find mismatched pixels around each minimum-error cut and re-synthesize them.
    band : int, default 2
        Repair band: pixels within this distance of the cut (each side), 1..16.
    threshold : float, default 0.1
        Mismatch threshold: RMS colour difference (0..1 intensities) between the two overlapping
        patches at a band pixel, 0..1 (0 = repair the whole band).
    n : odd int, default 5
        Window side for re-synthesizing a pixel, 3..15.
    smooth : bool, default False
        Step 7: replace re-synthesized pixels by a Gaussian filtering (sigma 0.8 px) of the result.
    mask : bool array (H, W), optional
        Where the texture is valid (a rectification's coverage): patches and repairs only copy from
        there.
    rng : None, int or Generator
        Same seed, same pixels.
    progress, cancel
        Progress callback, once per patch row (preview: the partial result) and once for the repair;
        cancel token, checked before every patch row and 16 times during the repair.
    return_details : bool, default False
        Return a :class:`~weft.core.nfpt.synthesis.Synthesis` (image, patches, repaired pixel count, source
        positions, repaired mask) instead of the image.

    Returns
    -------
    float32 array (height, width[, 3]) with the texture's channels, or a Synthesis.

    Notes
    -----
    Eqs. 1-3 and steps 1-7 of §2; the choices where the paper is silent are listed in
    :mod:`weft.core.nfpt.synthesis` (luminance P_diff, units and sigmas, ``|P - M|``, the tol rule, the
    mismatch test, coherent repair candidates).
    """
    params = NfptParams(
        size=size,
        block=block,
        overlap=overlap,
        sigma_d=sigma_d,
        sigma_s=sigma_s,
        tol=tol,
        repair=repair,
        band=band,
        threshold=threshold,
        n=n,
        smooth=smooth,
    )
    tex = validate_image(texture, "texture")
    syn = _synthesize(tex, params, mask=mask, rng=rng, progress=progress, cancel=cancel)
    return syn if return_details else syn.image


#: Seconds per source position per patch besides the DFTs (tol choice, cut, repair); ~1 ns on the
#: 2-core machine (fitted to ``python -m benchmarks.estimates``).
SELECT_SECONDS_PER_POSITION = 1e-9


def estimate_seconds(texture_shape: tuple[int, ...], out_size: tuple[int, int], block: int, overlap: int) -> float:
    """Estimated running time of the patch synthesis on the 2-core reference machine (:mod:`weft.core.limits`).

    Every patch but the first costs three DFTs of the padded source luminance (eqs. 1-3 for all
    positions at once: two spectra of the weighted template and the inverse) and a choice over every
    source position; within 0.4..1.6x of real runs (``python -m benchmarks.estimates``).
    """
    from ..grid import block_grid
    from ..limits import dft_seconds

    h, w = texture_shape[:2]
    width, height = out_size
    patches = len(block_grid(height, block, overlap, False)[0]) * len(block_grid(width, block, overlap, False)[0])
    positions = max(1, h - block + 1) * max(1, w - block + 1)
    return patches * (3 * dft_seconds(h, w) + SELECT_SECONDS_PER_POSITION * positions)


def _check_limits(tex: np.ndarray, size: tuple[int, int], params: NfptParams) -> None:
    """Refuse up front an output over the pixel limit or one that would take too long."""
    from ..limits import check_duration, check_output_size

    width, height = size
    check_output_size(width, height)
    h, w = tex.shape[:2]
    seconds = estimate_seconds(tex.shape, size, params.block, params.overlap)
    check_duration(
        seconds,
        f"NFPT synthesis of {width}x{height} from a {w}x{h} texture with {params.block} px patches",
        "use a larger block, a smaller size or a smaller part of the texture",
    )


def _synthesize(tex: np.ndarray, params: NfptParams, *, mask=None, rng=None, progress=None, cancel=None) -> Synthesis:
    h, w = tex.shape[:2]
    size = params.size if params.size is not None else (2 * w, 2 * h)
    _check_limits(tex, size, params)
    sigma_d = params.sigma_d if params.sigma_d is not None else params.overlap / 2.0
    return synthesize_patches(
        tex,
        size,
        block=params.block,
        overlap=params.overlap,
        sigma_d=sigma_d,
        sigma_s=params.sigma_s,
        tol=params.tol,
        repair=params.repair,
        band=params.band,
        threshold=params.threshold,
        n=params.n,
        smooth=params.smooth,
        mask=mask,
        rng=rng,
        progress=progress,
        cancel=cancel,
    )


@dataclass(frozen=True)
class NfptResult:
    """The pipeline's products: ``image`` (the output: the synthesized texture, or it in the view or
    the photo), ``rectified`` (I_r, or the photo when no lines were given), ``synthesized`` (I_s),
    ``homography`` (frontal -> photo, or None) and ``figures``."""

    image: np.ndarray
    rectified: np.ndarray
    synthesized: np.ndarray
    homography: np.ndarray | None
    figures: Mapping[str, Any] = field(default_factory=dict)


def nfpt(
    photo: np.ndarray,
    lines=None,
    *,
    view=None,
    into_photo: bool = False,
    warp: str = "homography",
    a: float = 1.0,
    b: float = 2.0,
    p: float = 0.5,
    rng: None | int | np.random.Generator = None,
    progress: Callable[[Progress], None] | None = None,
    cancel: CancelToken | None = None,
    **synthesis: Any,
) -> NfptResult:
    """Rectify, synthesize and re-project a non-frontal-parallel texture (Yan, Lee & Lin, Fig. 2).

    Parameters
    ----------
    photo : float32 (H, W) or (H, W, 3) in [0, 1]
        I_0, the texture photographed at an angle.
    lines : FeatureLines, str or None
        Feature lines (:class:`weft.core.rectify.FeatureLines`, or a JSON file name / JSON text). None:
        the photo is frontal already and is synthesized as it is.
    view : View, str or None
        Put the synthesized texture into this view (:mod:`weft.core.rectify.view`: a quad or line pairs,
        in the synthesized texture's pixel coordinates); the output has the view's size (default
        the photo's), black where the texture does not reach.
    into_photo : bool, default False
        Put the synthesized texture back into the photo over the rectified plane, centred on the
        frontal frame, so a larger texture extends the plane (needs ``lines``).
    warp, a, b, p
        Rectification (and re-projection) warp; see :func:`weft.core.rectify.rectify`.
    rng, progress, cancel
        As :func:`synthesize`; progress stages "rectify", "nfpt synthesis", "re-project".
    **synthesis
        Any parameter of :func:`synthesize` (size, block, overlap, sigma_d, sigma_s, tol, repair,
        band, threshold, n, smooth).

    Returns
    -------
    NfptResult

    Raises
    ------
    GeometryError
        Bad feature lines or view (see :func:`weft.core.rectify.rectify`); ``into_photo`` without lines.
    """
    params = NfptParams(warp=warp, a=a, b=b, p=p, into_photo=into_photo, **synthesis)
    return _nfpt(photo, lines, view, params, rng=rng, progress=progress, cancel=cancel)


def _nfpt(photo, lines, view, params: NfptParams, *, rng=None, progress=None, cancel=None) -> NfptResult:
    import cv2

    from .. import rectify as rf
    from ..jobs import ProgressReporter
    from ..rectify import view as rv

    photo = validate_image(photo, "photo")
    ph, pw = photo.shape[:2]
    figures: dict[str, Any] = {}
    if lines is not None:
        lines = FeatureLines.coerce(lines)
    if view is not None:
        view = View.coerce(view)
    if params.into_photo and lines is None:
        raise GeometryError("--into-photo needs the feature lines (--lines) that rectified the photo")
    if cancel is not None:
        cancel.raise_if_cancelled()
    homography = None
    if lines is not None:
        rep = ProgressReporter(progress, "rectify", 1)
        rect = rf.Rectifier(photo).rectify(
            lines.image_lines,
            lines.frontal_lines,
            lines.frontal_size,
            warp=params.warp,
            a=params.a,
            b=params.b,
            p=params.p,
        )
        rep.update(1, preview=rect.image)
        source, homography = rect.image, rect.homography
        mask = cv2.erode(
            rect.mask.astype(np.uint8),
            np.ones((2 * _MASK_ERODE + 1,) * 2, np.uint8),
            borderType=cv2.BORDER_CONSTANT,
            borderValue=1,
        ).astype(bool)
        figures.update({f"rectify_{k}": v for k, v in rect.figures.items()})
        if mask.all():
            mask = None
    else:
        source, mask, rect = photo, None, None
    syn = _synthesize(source, params, mask=mask, rng=rng, progress=progress, cancel=cancel)
    figures.update(syn.figures())
    out = syn.image
    th, tw = out.shape[:2]
    if view is not None or params.into_photo:
        if cancel is not None:
            cancel.raise_if_cancelled()
        rep = ProgressReporter(progress, "re-project", 1)
        if view is not None:
            plan = rv.view_plan(view, (tw, th), (pw, ph), warp=params.warp, a=params.a, b=params.b, p=params.p)
            out, cover = plan.apply(syn.image, supersample=rv.SUPERSAMPLE, alpha=True)
            figures["view_coverage"] = round(float(cover.mean()), 4)
        else:
            plan = rv.into_photo_plan(
                rect.plan,
                lines.image_lines,
                lines.frontal_lines,
                lines.frontal_size,
                (pw, ph),
                (tw, th),
                warp=params.warp,
                a=params.a,
                b=params.b,
                p=params.p,
            )
            # warped is premultiplied (black outside, edge pixels scaled by their coverage): "over"
            warped, alpha = plan.apply(syn.image, supersample=rv.SUPERSAMPLE, alpha=True)
            if warped.ndim == 3:
                alpha = alpha[..., None]
            out = np.clip(photo * (1.0 - alpha) + warped, 0.0, 1.0).astype(np.float32)
            figures["photo_replaced_fraction"] = round(float(alpha.mean()), 4)
        rep.update(1, preview=out)
    return NfptResult(out, source, syn.image, homography, figures)


def _run(inputs: Mapping[str, np.ndarray], params: NfptParams, *, rng=None, progress=None, cancel=None) -> Result:
    from .. import rectify as rf

    res = _nfpt(inputs["photo"], params.lines, params.view, params, rng=rng, progress=progress, cancel=cancel)
    figures = dict(res.figures)
    if res.homography is not None:
        figures["homography"] = rf.homography_figure(res.homography)
    return Result(res.image, figures)


def warm_up() -> None:
    """Load (or compile) every kernel a run can use, on a tiny input: template, selection, repair,
    seams, and the Beier-Neely field morph of ``--warp lines``/``morph`` (``weft.core.rectify``'s)."""
    from .. import rectify

    rectify.warm_up()
    rng = np.random.default_rng(0)
    tex = rng.random((20, 20), dtype=np.float32)
    synthesize(tex, size=(24, 24), block=8, overlap=3, threshold=0.0, rng=0)
    synthesize(np.repeat(tex[..., None], 3, axis=2), size=(24, 24), block=8, overlap=3, threshold=0.0, rng=0)


METHOD = Method(
    name="nfpt",
    summary="NFPT (Yan, Lee & Lin): rectify a texture photo from feature lines, synthesize it patch by patch "
    "with feature-weighted matching and seam repair, put it back into a view",
    params=NfptParams,
    inputs=(InputSpec("photo", "the photo of the texture (or a frontal texture, without --lines)", min_side=8),),
    run=_run,
    warm_up=warm_up,
    studio=Studio(
        title="Non-frontal textures (Yan, Lee & Lin)",
        canvas="photo",
        geometry=(
            Geometry(
                LINES,
                on=("photo",),
                param="lines",
                help="drag to draw feature lines; drag an end to move it; click a line + Delete to remove it",
                suggest=suggest_for_studio,
                # (a run without lines takes the photo as frontal: of a perspective photo,
                # a collage with hard seams)
                needed="draw feature lines on the photo (or press Suggest lines, or Quad…: click "
                "the plane's four corners)",
            ),
        ),
        preview_params=("size",),
        compare=("photo",),
        examples={"photo": "perspective"},
        auto=lambda params, shapes: {"sigma_d": params.overlap / 2.0},
        rank=3,
        limits=lambda params, shapes: {"overlap": (2, params.block // 2)},
        # the warp's a, b, p shape the line-based warps only; the repair's settings need the repair
        idle=lambda params, shapes: (
            ({"a", "b", "p"} if params.warp == "homography" else set())
            | (set() if params.repair else {"band", "threshold", "n", "smooth"})
        ),
        figures={
            **{
                f"rectify_{k}": f.prefixed("rectification") if f.unit == "px" else f for k, f in RECTIFY_FIGURES.items()
            },
            "patches": Figure("patches"),
            "repaired_pixels": Figure("repaired pixels"),
            "repaired_fraction": Figure("repaired", "%", digits=2),
            "view_coverage": Figure("view coverage", "%"),
            "photo_replaced_fraction": Figure("photo replaced", "%"),
        },
    ),
)
