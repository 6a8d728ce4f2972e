"""The up-front limits of fast texture transfer: output size and memory."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from .params import FastParams

# Peak memory per output pixel besides the inputs (documented where weft.core.fast re-exports it).
BYTES_PER_OUTPUT_PIXEL = 50


def _output_size(
    texture_shape: tuple[int, ...], target_shape: tuple[int, ...] | None, params: FastParams
) -> tuple[int, int, str]:
    """Width, height and what sets them (for messages) of a run on inputs of these shapes;
    ``params`` are resolved (:meth:`FastParams.resolved`)."""
    hs, ws = texture_shape[:2]
    if params.mode in ("superres", "novel"):
        return ws * params.magnify, hs * params.magnify, "parameter 'magnify'"
    if target_shape is not None:
        return target_shape[1], target_shape[0], "the target"
    width, height = params.size if params.size is not None else (2 * ws, 2 * hs)
    return width, height, "parameter 'size'"


def _check_limits(texture: np.ndarray, target: np.ndarray | None, params: FastParams) -> None:
    """Refuse up front an output over the pixel limit or beyond the memory available.

    No running-time limit: the method is linear in the output, so the pixel limit bounds a job to
    well under the ten minutes of :mod:`weft.core.limits`.
    """
    from ..limits import check_memory, check_output_size

    width, height, source = _output_size(texture.shape, None if target is None else target.shape, params)
    check_output_size(width, height, source)
    check_memory(BYTES_PER_OUTPUT_PIXEL * width * height, f"fast transfer of {width}x{height}")


def memory_estimate(shapes: Mapping[str, tuple[int, ...]], params: FastParams) -> float:
    """Estimated peak bytes of one run on inputs of these shapes (what :func:`_check_limits` checks).

    Parameters
    ----------
    shapes : mapping of str to tuple of int
        Input name -> array shape.
    params : FastParams
        The run's parameters.

    Returns
    -------
    float
        Bytes.
    """
    target = shapes.get("target")
    width, height, _ = _output_size(shapes["texture"], target, params.resolved(target is not None))
    return BYTES_PER_OUTPUT_PIXEL * width * height
