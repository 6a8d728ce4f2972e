"""``weft affine``: the method as the CLI and the GUI run it, and the one-call Python API."""

from __future__ import annotations

import hashlib
import threading
from collections import OrderedDict
from collections.abc import Callable, Mapping

import numpy as np

from ..errors import ImageError
from ..geometry import Square
from ..image import luminance, validate_image
from ..jobs import CancelToken, Progress
from ..limits import check_output_size
from ..metrics import snr_db
from ..registry import InputSpec, Method, Result
from ..studio import SQUARE, Figure, Geometry, Studio
from .analysis import analyse
from .boundary import BoundaryReport, match_boundaries
from .fields import field_model
from .model import AffineModel, _recombine, make_prototype
from .params import MIN_SIDE, AffineParams, check_rect, default_rect
from .synthesis import render


def synthesize(
    texture: np.ndarray,
    *,
    prototype: tuple[int, int, int] | str | None = None,
    prototype_image: np.ndarray | None = None,
    block: int = 32,
    segments: int = 32,
    lowpass: str = "add",
    colour: str = "pca",
    propagate: bool = True,
    refine: int = 2,
    reuse_transforms: bool = False,
    analysis_prototype: tuple[int, int, int] | str | None = None,
    boundary: str = "auto",
    iterations: int = 20,
    per_radius: int = 5,
    shaker_start: str = "partial",
    field: str = "none",
    field_strength: float = 1.0,
    size: tuple[int, int] | None = None,
    rng: None | int | np.random.Generator = None,
    progress: Callable[[Progress], None] | None = None,
    cancel: CancelToken | None = None,
) -> np.ndarray:
    """Synthesis and texture transfer with the affine prototype model (Smith & Bhalerao).

    One call = :func:`~weft.core.affine.analyse` (or a parametric field), optional boundary matching
    (:func:`~weft.core.affine.match_boundaries`) and :func:`~weft.core.affine.render`. Parameters are those
    of :class:`~weft.core.affine.AffineParams` (same names, ranges and defaults as ``weft affine``).

    Parameters
    ----------
    texture : float32 (H, W) or (H, W, 3) in [0, 1]
        The image modelled (synthesis reproduces it; a transfer renders it in another texture).
    prototype : (x, y, s) or "X,Y,S", optional
        The prototype square (in ``prototype_image`` when given, else in the texture); default
        a 2B square in the middle. The side must be even.
    prototype_image : float32 image, optional
        Texture transfer (§4): the prototype comes from this picture.
    block : even int, 8..256, default 32
        B, the target patch side (patches overlap by B/2).
    segments : even int, 4..128, default 32
        N, angular segments of the centroid estimation (§2.1).
    lowpass : {"add", "absorb"}, default "add"
        §3.3 and §3.4 (see :func:`~weft.core.affine.analyse`).
    colour : {"pca", "yuv"}, default "pca"
        Grey channel of colour images (§3.4).
    propagate : bool, default True
        Also try the neighbouring patches' transforms (§6's suggestion; not in the paper's
        pipeline). ``refine`` : int, 0..20, default 2 -- Levenberg-Marquardt steps on each chosen
        transform (not in the paper). ``propagate=False, refine=0`` is the paper's pipeline.
    reuse_transforms : bool, default False
        Compute the transforms with ``analysis_prototype`` (a square of the texture; default the
        default prototype) and render them with ``prototype`` (of ``prototype_image`` or the
        texture): a prototype swap into existing transforms (§4, Fig. 5 top).
    boundary : {"auto", "none", "partial", "shaker"}, default "auto"
        Boundary matching (§4); auto = shaker with a field, none otherwise.
    iterations, per_radius, shaker_start
        Shaker box schedule (see :func:`~weft.core.affine.match_boundaries`).
    field : {"none", "swirl", "zoom", "rotate"}, default "none"
        Synthesize from a parametric transform field instead (Fig. 6); ``field_strength`` 0..2
        scales it; ``size`` (width, height) is the output size (default the texture's).
    rng, progress, cancel
        Seed of the shaker box's visiting order; progress callback; cancel token.

    Returns
    -------
    float32 (H, W) or (H, W, 3) in [0, 1]
    """
    params = AffineParams(
        prototype=None if prototype is None else Square.coerce(prototype, "prototype"),
        block=block,
        segments=segments,
        lowpass=lowpass,
        colour=colour,
        propagate=propagate,
        refine=refine,
        reuse_transforms=reuse_transforms,
        analysis_prototype=(
            None if analysis_prototype is None else Square.coerce(analysis_prototype, "analysis_prototype")
        ),
        boundary=boundary,
        iterations=iterations,
        per_radius=per_radius,
        shaker_start=shaker_start,
        field=field,
        field_strength=field_strength,
        size=size,
    )
    inputs = {"texture": texture}
    if prototype_image is not None:
        inputs["prototype_image"] = prototype_image
    return _run(inputs, params, rng=rng, progress=progress, cancel=cancel).image


def _pipeline(
    inputs: Mapping[str, np.ndarray], params: AffineParams, *, rng=None, progress=None, cancel=None
) -> tuple[np.ndarray, AffineModel, BoundaryReport, dict]:
    texture = validate_image(inputs["texture"], "texture")
    other = inputs.get("prototype_image")
    if other is not None:
        other = validate_image(other, "prototype image")
    B = params.block
    source = other if other is not None else texture
    source_name = "prototype image" if other is not None else "texture"
    info: dict = {}
    if params.field != "none":
        h, w = texture.shape[:2]
        if params.size is not None:
            w, h = params.size
            check_output_size(w, h)
        if B > min(h, w):
            raise ImageError(f"the output is {w}x{h}; it must be at least the block, {B} pixels, on each side")
        rect = params.prototype or default_rect(source.shape, B, source_name)
        proto = make_prototype(
            source, check_rect(rect, source.shape, source_name), block=B, colour=params.colour, what=source_name
        )
        model = field_model((h, w), proto, params.field, strength=params.field_strength, block=B)
        render_proto = proto
    elif params.reuse_transforms:
        arect = params.analysis_prototype or default_rect(texture.shape, B, "texture")
        check_rect(arect, texture.shape, "texture", "analysis_prototype")
        model = _cached_analysis(texture, arect, params, progress, cancel)
        rect = params.prototype or default_rect(source.shape, B, source_name)
        dec = model.decomposition if other is None else None
        render_proto = make_prototype(
            source,
            check_rect(rect, source.shape, source_name),
            block=B,
            colour=params.colour,
            decomposition=dec,
            what=source_name,
        )
        info["analysis_prototype"] = list(arect)
    else:
        if params.prototype is not None:
            check_rect(params.prototype, source.shape, source_name)
        model = analyse(
            texture,
            prototype=params.prototype,
            prototype_image=other,
            block=B,
            segments=params.segments,
            lowpass=params.lowpass,
            colour=params.colour,
            propagate=params.propagate,
            refine=params.refine,
            progress=progress,
            cancel=cancel,
        )
        render_proto = model.prototype
    info["prototype"] = list(render_proto.rect) if render_proto.rect is not None else None
    model, report = match_boundaries(
        model,
        params.resolved_boundary(),
        prototype=render_proto,
        iterations=params.iterations,
        per_radius=params.per_radius,
        start=params.shaker_start,
        rng=rng,
        progress=progress,
        cancel=cancel,
    )
    out = render(model, render_proto)
    return out, model, report, info


# The last few analyses made for reused transforms: the studio re-runs the method for every move
# of the prototype square, and with "reuse transforms" only the rendering has to be redone.
_CACHE_SIZE = 2
_cache: OrderedDict = OrderedDict()
_cache_lock = threading.Lock()


def cached_analyses() -> int:
    """How many analyses are remembered for runs with reused transforms.

    Returns
    -------
    int
        At most two: an analysis is kept by the texture's content and the analysis parameters.
    """
    with _cache_lock:
        return len(_cache)


def forget_analyses() -> None:
    """Forget the remembered analyses: the next run with reused transforms analyses its texture again."""
    with _cache_lock:
        _cache.clear()


def _cached_analysis(texture: np.ndarray, arect, params: AffineParams, progress, cancel) -> AffineModel:
    """:func:`analyse` of the texture for ``arect``, remembered by content and parameters (models
    are never modified, so threads may share them)."""
    key = (
        hashlib.blake2b(texture.tobytes(), digest_size=16).digest(),
        texture.shape,
        tuple(arect),
        params.block,
        params.segments,
        params.lowpass,
        params.colour,
        params.propagate,
        params.refine,
    )
    with _cache_lock:
        model = _cache.get(key)
        if model is not None:
            _cache.move_to_end(key)
            return model
    model = analyse(
        texture,
        prototype=arect,
        block=params.block,
        segments=params.segments,
        lowpass=params.lowpass,
        colour=params.colour,
        propagate=params.propagate,
        refine=params.refine,
        progress=progress,
        cancel=cancel,
    )
    with _cache_lock:
        _cache[key] = model
        while len(_cache) > _CACHE_SIZE:
            _cache.popitem(last=False)
    return model


def _run(inputs: Mapping[str, np.ndarray], params: AffineParams, *, rng=None, progress=None, cancel=None) -> Result:
    out, model, report, info = _pipeline(inputs, params, rng=rng, progress=progress, cancel=cancel)
    texture = validate_image(inputs["texture"], "texture")
    figures: dict = {"patches": int(model.grid.count), **info}
    if out.shape[:2] == texture.shape[:2] and min(out.shape[:2]) >= 7:
        ref, cmp = texture, out
        if ref.ndim != cmp.ndim:  # a grey texture rendered in a colour prototype, or the reverse
            ref, cmp = luminance(ref), luminance(cmp)
        figures["snr_db"] = round(float(snr_db(ref, cmp)), 3)
        if model.lowpass == "add" and model.decomposition is not None and params.field == "none":
            # what the retained lowpass (and chroma) alone would score: the synthesis adds the rest
            base = _recombine(model.decomposition, model.decomposition.low)
            if base.ndim != ref.ndim:
                base = luminance(base)
            figures["snr_lowpass_db"] = round(float(snr_db(ref, base)), 3)
    if np.isfinite(model.rms).any():
        figures["rms_median"] = round(float(np.nanmedian(model.rms)), 5)
    figures.update(report.figures())
    return Result(out, figures)


def warm_up() -> None:
    """Load (or compile) every kernel on a tiny input: analysis, refinement, both boundary passes,
    colour rendering."""
    y, x = np.mgrid[:32, :32]
    tiny = (0.5 + 0.25 * np.sin(x * 0.9 + 0.3 * y) * np.cos(y * 0.7)).astype(np.float32)
    params = AffineParams(block=8, boundary="shaker", iterations=2, per_radius=1)
    _run({"texture": tiny}, params, rng=0)
    colour = np.stack([tiny, tiny[::-1], tiny.T], axis=2)
    _run({"texture": colour}, AffineParams(block=8, lowpass="absorb", boundary="partial"), rng=0)


METHOD = Method(
    name="affine",
    summary="affine prototype model (Smith & Bhalerao): synthesis, transfer by prototype swap, shaker box",
    params=AffineParams,
    inputs=(
        InputSpec("texture", "the texture to model (or the picture to transfer a texture onto)", min_side=MIN_SIDE),
        InputSpec(
            "prototype_image",
            "take the prototype from this picture instead (texture transfer, §4)",
            required=False,
            min_side=MIN_SIDE,
        ),
    ),
    run=_run,
    warm_up=warm_up,
    studio=Studio(
        title="Affine prototype model (Smith & Bhalerao)",
        canvas="texture",
        geometry=(
            Geometry(
                SQUARE,
                on=("prototype_image", "texture"),
                param="prototype",
                help="drag a square: the prototype patch (on the prototype image when one is open); "
                "with reuse transforms the result follows it live",
                live=lambda params: params.reuse_transforms,
            ),
        ),
        preview_params=("size",),
        compare=("texture",),
        examples={"texture": "wood-grain"},
        rank=2,
        figures={
            "patches": Figure("patches"),
            "snr_db": Figure("SNR against the texture", "dB"),
            "snr_lowpass_db": Figure("SNR of its lowpass alone", "dB"),
            "rms_median": Figure("median transform fit error"),
            "boundary": Figure("boundary matching"),
            "shaker_iterations": Figure("shaker iterations"),
        },
    ),
)
