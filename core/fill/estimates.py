"""What a fill costs before it runs: its peak memory and an uncrop's time, estimated from the inputs'
shapes, and the up-front refusal of a fill over the limits (:mod:`weft.core.limits`).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..limits import check_output_size
from .params import FillParams

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
