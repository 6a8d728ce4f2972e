"""``weft fill``: the method the registry, the command line and the studio run (see the package)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import cv2
import numpy as np

from ..errors import ImageError, InvalidParameter, WeftError
from ..geometry import MARGINS, MASK, Margins, Mask
from ..image import validate_image
from ..limits import check_output_size
from ..registry import InputSpec, Method, Result
from ..studio import Figure, Geometry, Studio
from .band import blend_band
from .common import neighbourhood, touches_border, whole_patches
from .engines import TABLE
from .params import ANCHORS, BORDER_BLOCK, DEFAULT_PATCH, FillParams, auto_engine
from .quilt import is_colour


def _error(cls, message: str, input: str | None = None, **kw):
    e = cls(message, **kw)
    e.input = input  # the CLI puts that input's file name in front
    return e


def _split_alpha(image: np.ndarray, what: str) -> tuple[np.ndarray, np.ndarray | None]:
    """``(colour (H, W) or (H, W, 3) float32, alpha (H, W) or None)`` of a validated image."""
    arr = np.asarray(image)
    if arr.ndim == 3 and arr.shape[2] in (2, 4):
        alpha = validate_image(np.ascontiguousarray(arr[..., -1]), f"{what}'s alpha")
        colour = validate_image(np.ascontiguousarray(arr[..., 0] if arr.shape[2] == 2 else arr[..., :3]), what)
        return colour, alpha
    if arr.ndim == 3 and arr.shape[2] == 1:
        arr = arr[..., 0]
    return validate_image(arr, what), None


def _mask_bits(mask, shape: tuple[int, int], what: str, against: str) -> np.ndarray:
    m = np.asarray(mask)
    if m.dtype != bool and not (m.ndim == 3 and m.shape[2] in (2, 4)):  # (with alpha: Mask.from_image reads it)
        m = np.asarray(validate_image(m, what))
    if m.shape[:2] != tuple(shape):
        raise _error(
            ImageError,
            f"the {what.replace('_', ' ')} is {m.shape[1]}x{m.shape[0]} but the {against} is "
            f"{shape[1]}x{shape[0]}; they must be the same size",
            what,
        )
    if m.dtype == bool:
        return m
    _black_and_white(m, what)
    return Mask.from_image(m.astype(np.float32), what).bits


#: A mask is refused when more than this share of its pixels is neither nearly black nor nearly white
#: (or is coloured): a photo given as the mask, not a painted mask with soft edges.
MAX_GREY_SHARE = 0.25


def _black_and_white(m: np.ndarray, what: str) -> None:
    """Refuse a mask that is not nearly black and white (a photo passed by mistake)."""
    arr = np.asarray(m, dtype=np.float32)
    if arr.ndim == 3 and arr.shape[2] in (2, 4):  # a transparent pixel reads as black
        arr = arr[..., :-1] * arr[..., -1:]
    grey = arr if arr.ndim == 2 else arr.mean(axis=2)
    odd = (grey > 0.1) & (grey < 0.9)
    if arr.ndim == 3 and arr.shape[2] >= 3:
        odd |= (arr.max(axis=2) - arr.min(axis=2)) > 0.1
    share = float(odd.mean())
    if share > MAX_GREY_SHARE:
        raise _error(
            ImageError,
            f"the {what.replace('_', ' ')} is not black and white: {share:.0%} of its pixels are "
            "grey or coloured (white = fill, black = keep; was a photo given as the mask?)",
            what,
        )


def _margins(params: FillParams, w: int, h: int) -> Margins | None:
    """The margins to add, or None when nothing grows the canvas (no --extend/--size, or a --size
    equal to the image's)."""
    if params.extend:
        return params.extend
    if params.size is None:
        return None
    sw, sh = params.size
    if sw < w or sh < h:
        raise _error(
            InvalidParameter,
            f"parameter 'size' = {sw}x{sh} is smaller than the {w}x{h} image (an uncrop only grows the canvas)",
            None,
            name="size",
            value=params.size,
        )
    dx, dy = sw - w, sh - h
    col = {"left": 0, "right": 2}.get(params.anchor.split("-")[-1], 1)
    row = {"top": 0, "bottom": 2}.get(params.anchor.split("-")[0], 1)
    left = (0, dx // 2, dx)[col]
    top = (0, dy // 2, dy)[row]
    return Margins(left, top, dx - left, dy - top) if dx or dy else None


def _run_patch(
    params: FillParams, ch: int, cw: int, *, hole: np.ndarray | None = None, margins: Margins | None = None
) -> int:
    """The patch side a run of ``params.engine`` (not ``auto``) uses on a ``cw`` x ``ch`` canvas: the
    one given, or the engine's default fitted to a small canvas; the quilt's :data:`BORDER_BLOCK`
    (at most a third of the canvas) for a hole along the border deeper than its 24-px block
    (:func:`_deep_border`, of the canvas's ``hole``, or of the ``margins`` when only shapes are known)."""
    patch = params.resolved_patch()
    if params.patch is None and params.engine == "quilt" and _deep_border(hole, margins):
        patch = max(patch, min(BORDER_BLOCK, min(ch, cw) // 3))
    if params.patch is None and patch > min(ch, cw) // 2:  # a default patch fits a small image
        patch = max(3, min(ch, cw) // 2)
    if params.patch is None and params.engine == "hybrid":  # its 48-px block: at most a third of a small image
        patch = min(patch, max(3, min(ch, cw) // 3))
    return patch


def _deep_border(hole: np.ndarray | None, margins: Margins | None) -> bool:
    """Whether the hole runs along the canvas border and reaches more than the quilt's default block
    (24 px) from the known pixels: an uncrop or an extended canvas, whose quilt takes
    :data:`BORDER_BLOCK`; a small hole that touches the border keeps 24. Of ``hole`` when given (a
    chessboard distance, so that margins of L, T, R, B reach their largest), else of ``margins``."""
    if hole is None:
        return margins is not None and max(margins) > DEFAULT_PATCH["quilt"]
    if not touches_border(hole):
        return False
    d = cv2.distanceTransform(hole.astype(np.uint8), cv2.DIST_C, 3)
    return float(d.max()) > DEFAULT_PATCH["quilt"]


def _largest_square(region: np.ndarray) -> int:
    """The side of the largest square inside ``region`` (0 if empty), from a chessboard distance."""
    if not region.any():
        return 0
    d = cv2.distanceTransform(np.pad(region, 1).astype(np.uint8), cv2.DIST_C, 3)
    r = int(d.max())
    return 2 * r if whole_patches(region, 2 * r).any() else 2 * r - 1


def _as_like(image: np.ndarray, colour: bool) -> np.ndarray:
    if colour and image.ndim == 2:
        return np.repeat(image[..., None], 3, axis=2)
    if not colour and image.ndim == 3:
        from ..image import luminance

        return luminance(image)
    return image


def fill_image(
    image, mask=None, *, params: FillParams, source_mask=None, texture=None, rng=0, progress=None, cancel=None
) -> tuple[np.ndarray, dict]:
    """The whole fill method (see :func:`weft.core.fill.fill`).

    Parameters
    ----------
    image : ndarray, float32 (H, W), (H, W, 3) or with alpha
        The picture; a transparent region is a hole.
    mask : ndarray, optional
        White (> 0.5) = the hole.
    params : FillParams
        The method's parameters.
    source_mask : ndarray, optional
        Where to copy from.
    texture : ndarray, optional
        A second picture to copy from.
    rng, progress, cancel
        Seed; progress callback; cancel token.

    Returns
    -------
    image : ndarray, float32
        The filled picture; pixels outside the hole (and the band) unchanged.
    figures : dict
        What the run reports.

    Raises
    ------
    WeftError
        Nothing to fill, masks of the wrong size, no source to copy from, an output over the limits.
    """
    colour, alpha = _split_alpha(image, "image")
    h, w = colour.shape[:2]
    hole = np.zeros((h, w), dtype=bool)
    named = None  # what made the hole, for messages
    if mask is not None:
        hole = _mask_bits(mask, (h, w), "mask", "image")
        named = "mask"
    transparent = alpha < 0.5 if alpha is not None else np.zeros((h, w), dtype=bool)
    if mask is None and alpha is not None:
        hole = transparent.copy()
        named = "alpha"
    margins = _margins(params, w, h)
    inner = _interior(hole) if hole.any() else None
    if margins is not None and inner is not None and inner.any():
        return _by_region(image, hole, inner, params, source_mask, texture, rng, progress, cancel)
    if margins is None and named is None:
        raise WeftError(
            "nothing to fill: give a mask (--mask MASK), margins (--extend L,T,R,B) or a canvas size "
            "(--size WxH), or an image with transparent pixels"
        )
    if margins is None and not hole.any():
        if named == "mask":
            raise _error(WeftError, "nothing to fill: the mask has no white pixel", "mask")
        raise _error(
            WeftError,
            "nothing to fill: the image has no transparent pixel and no mask, --extend or --size was given",
            "image",
        )
    # the canvas: the image, grown by the margins (their pixels are part of the hole)
    if margins:
        cw, ch = margins.grown(w, h)
        check_output_size(cw, ch, "parameter 'size'" if params.size is not None else "parameter 'extend'")
        pad = ((margins.top, margins.bottom), (margins.left, margins.right))
        colour = np.pad(colour, pad + (((0, 0),) if colour.ndim == 3 else ()))
        hole = np.pad(hole, pad, constant_values=True)
        transparent = np.pad(transparent, pad, constant_values=False)
        if alpha is not None:
            alpha = np.pad(alpha, pad, constant_values=1.0)
    ch, cw = hole.shape
    pending = None  # auto's edge guide: (part, guide, edges continued)
    if params.engine == "auto":  # the figures and messages name the engine that runs
        # decided on the hole's neighbourhood, the part the engine fills when the hole is small in a
        # large picture (a colour corner far from a hole in a grey region does not make it a photo)
        known = ~hole & ~transparent
        near: tuple[slice, slice] | None  # (None later: no neighbourhood, the engine fills the whole)
        near = neighbourhood(hole, known, DEFAULT_PATCH["quilt"]) or (slice(None), slice(None))
        picture = colour.ndim == 3 and is_colour(colour[near], known[near])
        on_border = touches_border(hole)
        edges = None
        if (
            texture is None
            and params.structure == "auto"
            and auto_engine(picture, on_border, params.patch, params.structure, True) == "patchmatch"
        ):
            # whether the edge guide finds edges to continue decides; on the part patchmatch would
            # fill, so that its run takes this guide
            found = _edge_guide(colour, hole, transparent, params.replace(engine="patchmatch"), ch, cw)
            edges = found[2] > 0
            pending = found
        params = params.replace(engine=auto_engine(picture, on_border, params.patch, params.structure, edges))
    patch = _run_patch(params, ch, cw, hole=hole)
    if patch > min(ch, cw):
        grown = f", {cw}x{ch} once extended" if margins else ""
        raise _error(
            InvalidParameter,
            f"parameter 'patch' = {patch} is outside 3..{max(3, min(ch, cw))} (the image is {w}x{h}{grown})",
            "image",
            name="patch",
            value=patch,
        )
    if params.structure == "yes" and texture is not None:
        raise _error(
            InvalidParameter,
            "parameter 'structure' = yes continues the picture's own edges across the "
            "hole: it cannot copy from a second texture",
            "texture",
            name="structure",
            value="yes",
        )
    structure = params.continues_edges(texture is not None)
    # the source: where blocks are copied from
    if texture is not None:
        tex, _talpha = _split_alpha(texture, "texture")
        tex = _as_like(tex, colour.ndim == 3)
        src_region = np.ones(tex.shape[:2], dtype=bool) if _talpha is None else _talpha >= 0.5
        if source_mask is not None:
            src_region &= _mask_bits(source_mask, tex.shape[:2], "source_mask", "texture")
        src_name, src_input = f"texture ({tex.shape[1]}x{tex.shape[0]})", "texture"
    else:
        src_region = ~hole & ~transparent
        if source_mask is not None:
            src_region &= (
                _mask_bits(source_mask, (h, w), "source_mask", "image")
                if not margins
                else np.pad(
                    _mask_bits(source_mask, (h, w), "source_mask", "image"),
                    ((margins.top, margins.bottom), (margins.left, margins.right)),
                )
            )
        src_name, src_input = f"{w}x{h} image", "image"
        if not src_region.any():
            if source_mask is not None:
                raise _error(
                    WeftError,
                    "the source mask has no white pixel outside the hole: nothing to copy from",
                    "source_mask",
                )
            raise _error(
                WeftError,
                f"the {'mask' if named == 'mask' else 'hole'} covers the whole image: nothing is "
                f"left to copy from (needs at least one whole {patch}x{patch} patch of known pixels)",
                "mask" if named == "mask" else "image",
            )
    if params.patch is None and not whole_patches(src_region, patch).any():
        side = _largest_square(src_region)  # a default patch shrinks to the largest the source holds
        if side >= 3:
            patch = side
    if not whole_patches(src_region, patch).any():
        side = _largest_square(src_region)
        raise _error(
            WeftError,
            f"too little to copy from: the {engine_text(params)} needs at least one whole "
            f"{patch}x{patch} patch of known pixels in the {src_name}, whose largest is {side}x{side} "
            f"(a smaller --patch, a smaller hole or a larger source)",
            src_input,
        )
    # the engine's canvas: the image, or the image above the texture with a filled gap between them
    if texture is not None:
        gap = patch
        th, tw = tex.shape[:2]
        cw2 = max(cw, tw)
        big = np.zeros((ch + gap + th, cw2) + colour.shape[2:], dtype=np.float32)
        big[:ch, :cw] = colour
        big[ch + gap :, :tw] = tex
        big_hole = np.zeros(big.shape[:2], dtype=bool)
        big_hole[:ch, :cw] = hole
        big_hole[ch : ch + gap] = True
        big_hole[:ch, cw : cw + gap] = True  # beside a narrower image: filled, so its edge has texture beside it
        big_src = np.zeros(big.shape[:2], dtype=bool)
        big_src[ch + gap :, :tw] = src_region
        work, work_hole, work_src = big, big_hole, big_src
    else:
        work, work_hole, work_src = colour, hole, src_region
    extra = {}
    engine = TABLE[params.engine]
    if engine.cuttable and params.band > 0:
        # the engine may change the band's known pixels (a quilting cut through them, or a refine that
        # re-synthesises them): the image's own band (never its transparent pixels), on the engine's
        # canvas (a band worked out there would also take the image's last rows beside a texture's gap)
        from .band import band_region

        cut = np.zeros(work_hole.shape, dtype=bool)
        cut[:ch, :cw] = band_region(hole, params.band, exclude=transparent) & ~hole
        extra = {"cuttable": cut}
    # a small hole in a large picture: the engine fills the hole's neighbourhood alone
    near = neighbourhood(work_hole, work_src, patch) if texture is None else None
    part = (slice(None), slice(None)) if near is None else near
    engine_kw: dict[str, Any] = {k: v[part] for k, v in extra.items()}
    if structure:  # the edges entering the hole, continued across it (None: none pair up)
        if pending is not None and pending[0] == part and work is colour:
            engine_kw["guide"], continued = pending[1], pending[2]
        else:
            from .structure import structure_guide

            engine_kw["guide"], continued = structure_guide(
                work[part], work_hole[part], ~work_hole[part] & ~transparent[part]
            )
    filled = engine.function()(
        work[part], work_hole[part], work_src[part], patch=patch, rng=rng, progress=progress, cancel=cancel, **engine_kw
    )
    if near is not None:
        whole = np.array(work, dtype=np.float32)
        whole[near] = filled
        filled = whole
    filled = np.asarray(filled, dtype=np.float32)[:ch, :cw]
    out3 = filled if filled.ndim == 3 else filled[..., None]
    # (whether the engine re-synthesised the band is asked of the part it filled, as it asked itself)
    refined = engine.resynthesises_band(work[part], work_hole[part])
    if not refined:
        written = hole
        if extra:  # the band's known pixels the quilting cut ran through: the seam lies beside them
            col3 = colour if colour.ndim == 3 else colour[..., None]
            cut = extra["cuttable"][:ch, :cw]
            written = hole.copy()
            written[cut] = (out3[cut] != col3[cut]).any(axis=1)
        out3 = blend_band(np.ascontiguousarray(out3), hole, params.band, exclude=transparent, written=written)
    out = out3 if colour.ndim == 3 else out3[..., 0]
    if alpha is not None:
        alpha = alpha.copy()
        alpha[hole] = 1.0  # filled pixels are opaque
        out = np.concatenate([out if out.ndim == 3 else out[..., None], alpha[..., None]], axis=2)
    figures = {
        "engine": params.engine,
        "patch": patch,
        "hole_pixels": int(hole.sum()),
        "hole_fraction": round(float(hole.mean()), 4),
        "canvas": [int(cw), int(ch)],
        "source_pixels": int(src_region.sum()),
    }
    if structure:
        figures["edges_continued"] = continued
    if margins:
        figures["extend"] = margins.to_json()
    return np.ascontiguousarray(out, dtype=np.float32), figures


def _edge_guide(
    colour: np.ndarray, hole: np.ndarray, transparent: np.ndarray, params: FillParams, ch: int, cw: int
) -> tuple[tuple[slice, slice], np.ndarray | None, int]:
    """``(part, guide, edges continued)``: the structure guide of ``hole`` on the part of the canvas a
    run of ``params.engine`` fills (:func:`neighbourhood` of its patch; the whole canvas when that is
    most of it), from the known pixels that are not transparent."""
    from .structure import structure_guide

    known = ~hole & ~transparent
    near = neighbourhood(hole, known, _run_patch(params, ch, cw, hole=hole))
    part = (slice(None), slice(None)) if near is None else near
    guide, n = structure_guide(colour[part], hole[part], known[part])
    return part, guide, n


def _interior(hole: np.ndarray) -> np.ndarray:
    """The connected regions of ``hole`` (8-connected) that do not touch the picture's border."""
    n, labels = cv2.connectedComponents(hole.astype(np.uint8), connectivity=8)
    touches = np.zeros(n, bool)
    touches[np.concatenate([labels[0], labels[-1], labels[:, 0], labels[:, -1]])] = True
    return hole & ~touches[labels]


def _by_region(image, hole, inner, params, source_mask, texture, rng, progress, cancel) -> tuple[np.ndarray, dict]:
    """Fill the hole's interior regions first, on the picture as given (no margins), then its regions
    along the border and the margins: growing the canvas does not change the engine or the pixels
    inside an interior hole."""
    first_params = params.replace(extend=None, size=None)
    inside, fig1 = fill_image(
        image,
        inner,
        params=first_params,
        source_mask=source_mask,
        texture=texture,
        rng=rng,
        progress=_scaled(progress, 0, 2),
        cancel=cancel,
    )
    rest = hole & ~inner
    if not rest.any() and _margins(params, hole.shape[1], hole.shape[0]) is None:
        return inside, fig1
    out, fig2 = fill_image(
        inside,
        rest,
        params=params,
        source_mask=source_mask,
        texture=texture,
        rng=rng,
        progress=_scaled(progress, 1, 2),
        cancel=cancel,
    )
    figures = dict(fig2)
    if fig1["engine"] != fig2["engine"]:
        figures["engine"] = f"{fig1['engine']} inside, {fig2['engine']} along the border"
    figures["hole_pixels"] = fig1["hole_pixels"] + fig2["hole_pixels"]
    figures["hole_fraction"] = round(figures["hole_pixels"] / float(np.prod(out.shape[:2])), 4)
    if "edges_continued" in fig1:
        figures["edges_continued"] = fig1["edges_continued"] + fig2.get("edges_continued", 0)
    return out, figures


def _scaled(progress, part: int, parts: int):
    """A progress callback that reports a pass's fraction as part ``part`` of ``parts`` equal passes."""
    if progress is None:
        return None
    from ..jobs import Progress

    def report(p: Progress) -> None:
        total = max(1, p.total)
        progress(p._replace(done=part * total + p.done, total=parts * total))

    for attr in ("wants_preview", "preview_interval"):
        if hasattr(progress, attr):
            setattr(report, attr, getattr(progress, attr))
    return report


def engine_text(params: FillParams) -> str:
    """The words naming the engine a fill runs with.

    Parameters
    ----------
    params : FillParams
        The fill's parameters.

    Returns
    -------
    str
    """
    return f"{params.engine} engine"


def _run(inputs: Mapping[str, np.ndarray], params: FillParams, *, rng=None, progress=None, cancel=None) -> Result:
    check_limits(inputs, params)
    image, figures = fill_image(
        inputs["image"],
        inputs.get("mask"),
        params=params,
        source_mask=inputs.get("source_mask"),
        texture=inputs.get("texture"),
        rng=rng,
        progress=progress,
        cancel=cancel,
    )
    return Result(image, figures)


def warm_up() -> None:
    """A tiny default fill, grey and colour, so that a first run loads nothing more: every engine runs
    in numpy and OpenCV (no numba kernel to compile)."""
    rng = np.random.default_rng(0)
    img = rng.random((24, 24), dtype=np.float32)
    hole = np.zeros((24, 24), dtype=bool)
    hole[8:16, 8:16] = True
    for image in (img, np.repeat(img[..., None], 3, axis=2)):
        fill_image(image, hole, params=FillParams(patch=5), rng=0)


#: Peak bytes a fill adds per canvas pixel, by case, fitted to measured runs (``python -m
#: benchmarks.limits``, ``benchmarks/results/limits.json``) with a quarter added as a margin: an uncrop
#: of a colour picture (the engines' per-pixel candidates and costs over the whole new canvas), of a
#: grey one, and a hole inside a picture.
BYTES_PER_PIXEL = {"uncrop colour": 2400, "uncrop grey": 60, "hole": 50}
#: Seconds per filled pixel of an uncrop on the 2-core reference machine (same benchmark).
SECONDS_PER_FILLED_PIXEL = {"uncrop colour": 4e-5, "uncrop grey": 8e-6}


def _canvas(shapes: Mapping[str, tuple[int, ...]], params: FillParams) -> tuple[int, int, bool]:
    """(width, height, extended) of the canvas a fill works on for inputs of these shapes."""
    h, w = shapes["image"][:2]
    if params.extend:
        return (*params.extend.grown(w, h), True)
    if params.size is not None:
        return max(w, params.size[0]), max(h, params.size[1]), (params.size[0] > w or params.size[1] > h)
    return w, h, False


def _case(shapes: Mapping[str, tuple[int, ...]], params: FillParams) -> str:
    w, h, extended = _canvas(shapes, params)
    shape = shapes["image"]
    colour = len(shape) == 3 and shape[2] >= 3
    return ("uncrop colour" if colour else "uncrop grey") if extended else "hole"


def _memory(shapes: Mapping[str, tuple[int, ...]], params: FillParams) -> float:
    """Estimated peak bytes a fill adds, from the canvas it works on (see :data:`BYTES_PER_PIXEL`)."""
    w, h, _ = _canvas(shapes, params)
    if "texture" in shapes:
        th, tw = shapes["texture"][:2]
        h, w = h + th + 64, max(w, tw)
    return float(h * w * BYTES_PER_PIXEL[_case(shapes, params)])


def _seconds(shapes: Mapping[str, tuple[int, ...]], params: FillParams) -> float:
    """Estimated running time of an uncrop (the pixels added to the canvas); 0 for a hole."""
    case = _case(shapes, params)
    if case not in SECONDS_PER_FILLED_PIXEL:
        return 0.0
    w, h, _ = _canvas(shapes, params)
    ih, iw = shapes["image"][:2]
    return (w * h - iw * ih) * SECONDS_PER_FILLED_PIXEL[case]


def check_limits(inputs: Mapping[str, np.ndarray], params: FillParams) -> None:
    """Refuse up front, before any work, a fill over the limits (:mod:`weft.core.limits`).

    Parameters
    ----------
    inputs : mapping of str to ndarray
        The method's inputs.
    params : FillParams
        Its parameters.

    Raises
    ------
    LimitError
        The grown canvas is over the pixel limit, or the estimated memory or time is over its limit.
    """
    from ..limits import check_duration, check_memory

    shapes = {name: np.shape(image) for name, image in inputs.items() if image is not None}
    w, h, extended = _canvas(shapes, params)
    if extended:  # the pixel limit first: it names the parameter that set the canvas
        check_output_size(w, h, "parameter 'size'" if params.size is not None else "parameter 'extend'")
    what = f"fill of a {w}x{h} canvas" + (" (uncrop)" if extended else "")
    check_memory(_memory(shapes, params), what, "make the canvas smaller, or extend it in steps")
    check_duration(_seconds(shapes, params), what, "make the canvas smaller, or extend it in steps")


def _auto(params: FillParams, shapes: Mapping[str, tuple]) -> dict:
    """What an unset ``patch`` resolves to with inputs of these shapes (the studio shows it beside its
    box, and the variations grid centres its range on it): the patch the run takes (the engine's
    default, fitted to a small canvas; the quilt's border block for margins over 24 px). Nothing when
    the run decides it from the pixels, which a shape does not tell: ``auto``'s engine on a colour
    picture with a painted hole (:func:`auto_engine`: patchmatch where the edge guide pairs edges
    across it); the result's figures then say what ran. Nothing before an image is open."""
    shape = shapes.get("image")
    if params.patch is not None or shape is None:
        return {}
    h, w = shape[:2]
    try:
        margins = _margins(params, w, h)
    except WeftError:
        return {}
    if margins is not None:
        h, w = h + margins.top + margins.bottom, w + margins.left + margins.right
    if params.engine == "auto":
        colour = len(shape) == 3 and shape[2] >= 3
        painted = shapes.get("mask") is not None or (len(shape) == 3 and shape[2] in (2, 4))
        if params.structure == "auto" and colour and painted:
            return {}  # patchmatch or hybrid, as the edge guide finds edges in the hole or not
        params = params.replace(engine=auto_engine(colour, margins is not None, None, params.structure))
    return {"patch": _run_patch(params, h, w, margins=margins)}


def _always(params) -> bool:
    """A sampling area previews the whole fill while it is painted, whatever the parameters."""
    return True


#: The studio's description of fill, as the studio shows it (``METHOD.studio``): painting
#: the mask previews the region around the stroke (``preview_around``); the optional ``texture`` is
#: fill's own (``own_inputs``: the texture the studio has open for quilt and fast is not a source).
STUDIO = Studio(
    title="Fill and extend",
    canvas="image",
    geometry=(
        Geometry(MASK, on=("image",), input="mask", help="paint what to fill ([ and ] size the brush)", label="hole"),
        Geometry(MARGINS, on=("image",), param="extend", help="drag an edge outward to extend the canvas"),
        Geometry(
            MASK,
            on=("image",),
            input="source_mask",
            label="sampling area",
            empty_is_all=True,
            live=_always,
            help="the sampling area (optional): where fill copies from",
        ),
    ),
    preview_inputs=("image", "mask", "source_mask", "texture"),
    examples={"image": "brick"},
    rank=7,
    preview_around="mask",
    own_inputs=("texture",),
    auto=_auto,
    figures={
        "engine": Figure("engine"),
        "patch": Figure("patch", "px"),
        "hole_pixels": Figure("filled", "px"),
        "hole_fraction": Figure("filled", "%", "of the image", digits=2),
        "source_pixels": Figure("copied from", "px"),
        "edges_continued": Figure("edges continued"),
    },
)


METHOD = Method(
    name="fill",
    summary="fill a hole (the white of --mask, or transparent pixels) or extend the canvas (--extend, --size) "
    "with texture from the rest of the image",
    params=FillParams,
    inputs=(
        InputSpec(
            "image",
            "the image to fill (a transparent region is the hole when no mask is given)",
            alpha=True,
            min_side=3,
        ),
        InputSpec(
            "mask",
            "white = the pixels to fill; the image's size (a transparent pixel is black)",
            required=False,
            alpha=True,
        ),
        InputSpec(
            "source_mask",
            "white = the only pixels to copy from (the image's size, or the texture's; a transparent pixel is black)",
            required=False,
            alpha=True,
        ),
        InputSpec("texture", "copy from this image instead of the rest of the image", required=False),
    ),
    takes_region=False,
    run=_run,
    warm_up=warm_up,
    memory=_memory,
    depth_from="image",
    studio=STUDIO,
)

__all__ = ["ANCHORS", "METHOD", "STUDIO", "fill_image", "warm_up"]
