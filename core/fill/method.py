"""``weft fill``: the method the registry, the command line and the studio run (see the package).

The run's steps are in :mod:`~weft.core.fill.run` (:func:`fill_image`); reading the inputs in
:mod:`~weft.core.fill.inputs`; the engine and patch chosen in :mod:`~weft.core.fill.choose`; the
estimates and limits in :mod:`~weft.core.fill.estimates`.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..geometry import MARGINS, MASK
from ..registry import InputSpec, Method, Result
from ..studio import Figure, Geometry, Studio
from .choose import _auto, engine_text
from .estimates import BYTES_PER_PIXEL, SECONDS_PER_FILLED_PIXEL, _memory, check_limits
from .params import ANCHORS, FillParams
from .run import fill_image


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

__all__ = [
    "ANCHORS",
    "BYTES_PER_PIXEL",
    "METHOD",
    "SECONDS_PER_FILLED_PIXEL",
    "STUDIO",
    "check_limits",
    "engine_text",
    "fill_image",
    "warm_up",
]
