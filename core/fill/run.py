"""One fill, step by step: :func:`fill_image` reads the image, the masks and the margins, grows the
canvas, resolves ``auto``, finds where to copy from and the patch, runs the engine on the part of the
canvas it fills, puts that part back with the blend band, and reports what ran. An uncrop of a
picture that also has interior holes fills those first (:func:`_by_region`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ..errors import InvalidParameter, WeftError
from ..geometry import Margins
from ..limits import check_output_size
from .band import blend_band
from .choose import _largest_square, _resolve_auto, _run_patch, engine_text
from .common import neighbourhood, whole_patches
from .engines import TABLE
from .inputs import _as_like, _error, _interior, _margins, _mask_bits, _split_alpha
from .params import FillParams

__all__ = ["fill_image"]


@dataclass(frozen=True)
class _Canvas:
    """The picture a fill works on: ``colour`` (H, W) or (H, W, 3) float32, its ``alpha`` or None, the
    ``hole`` and the ``transparent`` pixels (bool (H, W)); once grown, the image with the margins
    around it, their pixels part of the hole. ``named``: what made the hole, for messages (``"mask"``,
    ``"alpha"`` or None); ``margins``: what an uncrop adds, or None; ``w``, ``h``: the image's size."""

    colour: np.ndarray
    alpha: np.ndarray | None
    hole: np.ndarray
    transparent: np.ndarray
    named: str | None
    margins: Margins | None
    w: int
    h: int


@dataclass(frozen=True)
class _Source:
    """Where blocks are copied from: ``region`` (bool, on the texture when there is one), the
    ``texture`` in the image's channels or None, and the ``name`` and ``input`` messages give it."""

    region: np.ndarray
    texture: np.ndarray | None
    name: str
    input: str


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

    References
    ----------
    Efros & Freeman, "Image Quilting for Texture Synthesis and Transfer" (2001), §2 applied to a
    hole; Barnes et al., "PatchMatch" (2009); Wexler, Shechtman & Irani, "Space-time completion of
    video" (2007).
    """
    canvas = _read(image, mask, params)
    inner = _interior(canvas.hole) if canvas.hole.any() else None
    if canvas.margins is not None and inner is not None and inner.any():
        return _by_region(image, canvas.hole, inner, params, source_mask, texture, rng, progress, cancel)
    _check_something_to_fill(canvas)
    canvas = _grow(canvas, params)
    params, pending = _resolve_auto(params, canvas.colour, canvas.hole, canvas.transparent, texture is not None)
    patch = _canvas_patch(params, canvas)
    _check_structure(params, texture)
    structure = params.continues_edges(texture is not None)
    source = _source(canvas, source_mask, texture, patch)
    patch = _source_patch(params, patch, source)
    work, work_hole, work_src = _engine_canvas(canvas, source, patch)
    filled, cut, continued, refined = _run_engine(
        params, canvas, work, work_hole, work_src, patch, structure, pending, rng, progress, cancel
    )
    out = _put_back(canvas, filled, cut, refined, params.band)
    return out, _figures(params, canvas, source, patch, continued if structure else None)


def _read(image, mask, params: FillParams) -> _Canvas:
    """The image's colour and alpha, the hole (the mask's white, else the transparent pixels) and the
    margins, as given (not grown yet)."""
    colour, alpha = _split_alpha(image, "image")
    h, w = colour.shape[:2]
    hole = np.zeros((h, w), dtype=bool)
    named = None
    if mask is not None:
        hole = _mask_bits(mask, (h, w), "mask", "image")
        named = "mask"
    transparent = alpha < 0.5 if alpha is not None else np.zeros((h, w), dtype=bool)
    if mask is None and alpha is not None:
        hole = transparent.copy()
        named = "alpha"
    return _Canvas(colour, alpha, hole, transparent, named, _margins(params, w, h), w, h)


def _check_something_to_fill(c: _Canvas) -> None:
    """Refuse a fill with no hole and no margins, naming what was given."""
    if c.margins is None and c.named is None:
        raise WeftError(
            "nothing to fill: give a mask (--mask MASK), margins (--extend L,T,R,B) or a canvas size "
            "(--size WxH), or an image with transparent pixels"
        )
    if c.margins is None and not c.hole.any():
        if c.named == "mask":
            raise _error(WeftError, "nothing to fill: the mask has no white pixel", "mask")
        raise _error(
            WeftError,
            "nothing to fill: the image has no transparent pixel and no mask, --extend or --size was given",
            "image",
        )


def _grow(c: _Canvas, params: FillParams) -> _Canvas:
    """The canvas grown by the margins (within the output limits): their pixels are part of the hole,
    opaque and not transparent."""
    if not c.margins:
        return c
    m = c.margins
    cw, ch = m.grown(c.w, c.h)
    check_output_size(cw, ch, "parameter 'size'" if params.size is not None else "parameter 'extend'")
    pad = ((m.top, m.bottom), (m.left, m.right))
    return replace(
        c,
        colour=np.pad(c.colour, pad + (((0, 0),) if c.colour.ndim == 3 else ())),
        hole=np.pad(c.hole, pad, constant_values=True),
        transparent=np.pad(c.transparent, pad, constant_values=False),
        alpha=None if c.alpha is None else np.pad(c.alpha, pad, constant_values=1.0),
    )


def _canvas_patch(params: FillParams, c: _Canvas) -> int:
    """The patch side the engine takes on this canvas (:func:`_run_patch`), refused when larger than it."""
    ch, cw = c.hole.shape
    patch = _run_patch(params, ch, cw, hole=c.hole)
    if patch > min(ch, cw):
        grown = f", {cw}x{ch} once extended" if c.margins else ""
        raise _error(
            InvalidParameter,
            f"parameter 'patch' = {patch} is outside 3..{max(3, min(ch, cw))} (the image is {c.w}x{c.h}{grown})",
            "image",
            name="patch",
            value=patch,
        )
    return patch


def _check_structure(params: FillParams, texture) -> None:
    """Refuse ``structure`` = yes with a second texture: the edges it continues are the picture's own."""
    if params.structure == "yes" and texture is not None:
        raise _error(
            InvalidParameter,
            "parameter 'structure' = yes continues the picture's own edges across the "
            "hole: it cannot copy from a second texture",
            "texture",
            name="structure",
            value="yes",
        )


def _source(c: _Canvas, source_mask, texture, patch: int) -> _Source:
    """Where blocks are copied from: the texture's opaque pixels, or the canvas's known ones; in
    either, only the source mask's white. Refused when nothing is left to copy from."""
    if texture is not None:
        tex, talpha = _split_alpha(texture, "texture")
        tex = _as_like(tex, c.colour.ndim == 3)
        region = np.ones(tex.shape[:2], dtype=bool) if talpha is None else talpha >= 0.5
        if source_mask is not None:
            region &= _mask_bits(source_mask, tex.shape[:2], "source_mask", "texture")
        return _Source(region, tex, f"texture ({tex.shape[1]}x{tex.shape[0]})", "texture")
    region = ~c.hole & ~c.transparent
    if source_mask is not None:
        bits = _mask_bits(source_mask, (c.h, c.w), "source_mask", "image")
        if c.margins:
            bits = np.pad(bits, ((c.margins.top, c.margins.bottom), (c.margins.left, c.margins.right)))
        region &= bits
    if not region.any():
        if source_mask is not None:
            raise _error(
                WeftError,
                "the source mask has no white pixel outside the hole: nothing to copy from",
                "source_mask",
            )
        raise _error(
            WeftError,
            f"the {'mask' if c.named == 'mask' else 'hole'} covers the whole image: nothing is "
            f"left to copy from (needs at least one whole {patch}x{patch} patch of known pixels)",
            "mask" if c.named == "mask" else "image",
        )
    return _Source(region, None, f"{c.w}x{c.h} image", "image")


def _source_patch(params: FillParams, patch: int, source: _Source) -> int:
    """``patch``, or for a default patch the largest square the source holds when it holds none of
    that side; refused when the source holds no whole patch."""
    if params.patch is None and not whole_patches(source.region, patch).any():
        side = _largest_square(source.region)  # a default patch shrinks to the largest the source holds
        if side >= 3:
            patch = side
    if not whole_patches(source.region, patch).any():
        side = _largest_square(source.region)
        raise _error(
            WeftError,
            f"too little to copy from: the {engine_text(params)} needs at least one whole "
            f"{patch}x{patch} patch of known pixels in the {source.name}, whose largest is {side}x{side} "
            f"(a smaller --patch, a smaller hole or a larger source)",
            source.input,
        )
    return patch


def _engine_canvas(c: _Canvas, source: _Source, patch: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(image, hole, source)`` the engine runs on: the canvas, or the canvas above the texture with a
    filled gap of a patch between them."""
    if source.texture is None:
        return c.colour, c.hole, source.region
    tex = source.texture
    ch, cw = c.hole.shape
    gap = patch
    th, tw = tex.shape[:2]
    cw2 = max(cw, tw)
    big = np.zeros((ch + gap + th, cw2) + c.colour.shape[2:], dtype=np.float32)
    big[:ch, :cw] = c.colour
    big[ch + gap :, :tw] = tex
    big_hole = np.zeros(big.shape[:2], dtype=bool)
    big_hole[:ch, :cw] = c.hole
    big_hole[ch : ch + gap] = True
    big_hole[:ch, cw : cw + gap] = True  # beside a narrower image: filled, so its edge has texture beside it
    big_src = np.zeros(big.shape[:2], dtype=bool)
    big_src[ch + gap :, :tw] = source.region
    return big, big_hole, big_src


def _run_engine(
    params: FillParams,
    c: _Canvas,
    work: np.ndarray,
    work_hole: np.ndarray,
    work_src: np.ndarray,
    patch: int,
    structure: bool,
    pending,
    rng,
    progress,
    cancel,
) -> tuple[np.ndarray, np.ndarray | None, int | None, bool]:
    """Run the engine on the part of its canvas it fills: ``(filled canvas, the band's known pixels it
    may change or None, edges continued or None, whether it re-synthesised the band)``."""
    engine = TABLE[params.engine]
    ch, cw = c.hole.shape
    extra = {}
    if engine.cuttable and params.band > 0:
        # the engine may change the band's known pixels (a quilting cut through them, or a refine that
        # re-synthesises them): the image's own band (never its transparent pixels), on the engine's
        # canvas (a band worked out there would also take the image's last rows beside a texture's gap)
        from .band import band_region

        cut = np.zeros(work_hole.shape, dtype=bool)
        cut[:ch, :cw] = band_region(c.hole, params.band, exclude=c.transparent) & ~c.hole
        extra = {"cuttable": cut}
    # a small hole in a large picture: the engine fills the hole's neighbourhood alone (of the canvas
    # itself; not when the engine's canvas has a texture below it)
    near = neighbourhood(work_hole, work_src, patch) if work is c.colour else None
    part = (slice(None), slice(None)) if near is None else near
    engine_kw: dict[str, Any] = {k: v[part] for k, v in extra.items()}
    continued = None
    if structure:  # the edges entering the hole, continued across it (None: none pair up)
        if pending is not None and pending[0] == part and work is c.colour:
            engine_kw["guide"], continued = pending[1], pending[2]
        else:
            from .structure import structure_guide

            engine_kw["guide"], continued = structure_guide(
                work[part], work_hole[part], ~work_hole[part] & ~c.transparent[part]
            )
    filled = engine.function()(
        work[part], work_hole[part], work_src[part], patch=patch, rng=rng, progress=progress, cancel=cancel, **engine_kw
    )
    if near is not None:
        whole = np.array(work, dtype=np.float32)
        whole[near] = filled
        filled = whole
    filled = np.asarray(filled, dtype=np.float32)[:ch, :cw]
    # (whether the engine re-synthesised the band is asked of the part it filled, as it asked itself)
    refined = engine.resynthesises_band(work[part], work_hole[part])
    return filled, (extra["cuttable"][:ch, :cw] if extra else None), continued, refined


def _put_back(c: _Canvas, filled: np.ndarray, cut: np.ndarray | None, refined: bool, band: int) -> np.ndarray:
    """The filled canvas with the blend band (unless the engine re-synthesised it) and the alpha
    (every filled pixel opaque), in the image's channels."""
    out3 = filled if filled.ndim == 3 else filled[..., None]
    if not refined:
        written = c.hole
        if cut is not None:  # the band's known pixels the quilting cut ran through: the seam lies beside them
            col3 = c.colour if c.colour.ndim == 3 else c.colour[..., None]
            written = c.hole.copy()
            written[cut] = (out3[cut] != col3[cut]).any(axis=1)
        out3 = blend_band(np.ascontiguousarray(out3), c.hole, band, exclude=c.transparent, written=written)
    out = out3 if c.colour.ndim == 3 else out3[..., 0]
    if c.alpha is not None:
        alpha = c.alpha.copy()
        alpha[c.hole] = 1.0  # filled pixels are opaque
        out = np.concatenate([out if out.ndim == 3 else out[..., None], alpha[..., None]], axis=2)
    return np.ascontiguousarray(out, dtype=np.float32)


def _figures(params: FillParams, c: _Canvas, source: _Source, patch: int, continued: int | None) -> dict:
    """What the run reports: the engine and patch that ran, the hole, the canvas, the source; the
    edges continued when the edge guide ran; the margins of an uncrop."""
    ch, cw = c.hole.shape
    figures = {
        "engine": params.engine,
        "patch": patch,
        "hole_pixels": int(c.hole.sum()),
        "hole_fraction": round(float(c.hole.mean()), 4),
        "canvas": [int(cw), int(ch)],
        "source_pixels": int(source.region.sum()),
    }
    if continued is not None:
        figures["edges_continued"] = continued
    if c.margins:
        figures["extend"] = c.margins.to_json()
    return figures


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
