"""How a render's inputs are reduced for a preview (Qt-free): to a size, or to the region around a stroke.

:func:`reduce_for_preview` scales the inputs (or the output size parameters) a method's studio
description names, so the longer side is a given size; :func:`crop_around` crops the inputs around a
mask stroke being painted, and :class:`Around` pastes the crop's result back into a full result.
A :class:`~weft.core.request.RenderRequest` in preview or around mode runs on what these give.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from .errors import WeftError
from .geometry import MARGINS, MASK

__all__ = ["reduce_for_preview", "crop_around", "around_region", "Around", "AROUND_SIDE"]


def reduce_for_preview(
    studio: Any, inputs: Mapping[str, np.ndarray], params, side: int
) -> tuple[dict[str, np.ndarray], Any]:
    """Inputs and parameters of a reduced render: the studio's ``preview_inputs`` that are open
    scaled so the longer side of the largest is ``side``; else its ``preview_params`` sizes scaled
    so; unchanged when already that small (or when the method refuses the smaller size)."""
    from .image import resize

    scaled = [n for n in studio.preview_inputs if n in inputs]
    if scaled:
        longest = max(max(inputs[n].shape[:2]) for n in scaled)
        if longest <= side:
            return dict(inputs), params
        k = side / longest
        small = dict(inputs)
        for n in scaled:
            h, w = inputs[n].shape[:2]
            small[n] = resize(inputs[n], (max(8, round(w * k)), max(8, round(h * k))), interpolation="area")
        return small, params
    changes = {}
    for name in studio.preview_params:
        size = getattr(params, name, None)
        if size is not None and max(size) > side:
            k = side / max(size)
            changes[name] = (max(8, round(size[0] * k)), max(8, round(size[1] * k)))
    if changes:
        try:
            return dict(inputs), params.replace(**changes)
        except WeftError:  # a size the method refuses at preview scale: render at full size
            pass
    return dict(inputs), params


#: The longest side of a preview around a stroke (:func:`crop_around`): larger crops are scaled down.
AROUND_SIDE = 160


@dataclass(frozen=True)
class Around:
    """A render of the region around a stroke (see :func:`crop_around`).

    Attributes
    ----------
    inputs, params : what the method runs on (cropped, perhaps scaled; margins parameters off).
    box : ``(x0, y0, x1, y1)`` of the crop in the painted image's pixels (exclusive ends).
    offset : ``(dx, dy)`` of the painted image in a full result (the left and top margins of an
        uncrop; (0, 0) without them).
    """

    inputs: dict
    params: Any
    box: tuple[int, int, int, int]
    offset: tuple[int, int]

    def fitted(self, part: np.ndarray) -> np.ndarray | None:
        """The crop's result ``part`` at the box's size (scaled back when it was rendered smaller), as
        :meth:`paste` pastes it; None when it cannot be (another channel layout or an empty result)."""
        from .image import resize

        x0, y0, x1, y1 = self.box
        w, h = x1 - x0, y1 - y0
        if part.shape[:2] == (h, w):
            return part
        if part.ndim not in (2, 3) or min(part.shape[:2]) < 1:
            return None
        return resize(part, (w, h), interpolation="linear")

    def paste(self, base: np.ndarray, part: np.ndarray, *, copy: bool = True) -> np.ndarray | None:
        """``base`` (a full result) with ``part`` (the crop's result, scaled back to the box) pasted
        at the box (into a copy, or with ``copy=False`` into ``base`` itself); None when they do not
        fit together (another size or channel count)."""
        x0, y0, x1, y1 = self.box
        dx, dy = self.offset
        fitted = self.fitted(part)
        if (
            fitted is None
            or fitted.ndim != base.ndim
            or (fitted.ndim == 3 and fitted.shape[2] != base.shape[2])
            or y0 + dy < 0
            or x0 + dx < 0
            or y1 + dy > base.shape[0]
            or x1 + dx > base.shape[1]
        ):
            return None
        out = base.copy() if copy else base
        out[y0 + dy : y1 + dy, x0 + dx : x1 + dx] = fitted
        return out


def around_region(
    stroke: tuple[float, float, float, float], width: int, height: int, *, context: int = 16
) -> tuple[int, int, int, int]:
    """The part ``(x0, y0, x1, y1)`` of a ``width`` x ``height`` painted mask that :func:`crop_around`
    reads for ``stroke`` (same ``context``): the stroke's box grown by ``context``, grown again by
    ``context`` and a quarter of that box's longer side (the crop never reaches farther), clipped to
    the mask. Cut that part and pass it as ``crop_around(..., mask_part=)``: a preview around a
    stroke then never needs the whole mask (64 MB as a float image at 4096²)."""
    wx0, wy0, wx1, wy1 = _stroke_window(stroke, context)
    grow = context + max(wx1 - wx0, wy1 - wy0) // 4 + 1
    return max(0, wx0 - grow), max(0, wy0 - grow), min(width, wx1 + grow), min(height, wy1 + grow)


def _stroke_window(stroke: tuple[float, float, float, float], context: int) -> tuple[int, int, int, int]:
    """The stroke's box in whole pixels grown by ``context`` (exclusive ends, not clipped): where
    :func:`crop_around` looks for painted pixels."""
    sx0, sy0, sx1, sy1 = stroke
    return (
        int(np.floor(sx0)) - context,
        int(np.floor(sy0)) - context,
        int(np.ceil(sx1)) + 1 + context,
        int(np.ceil(sy1)) + 1 + context,
    )


def crop_around(
    studio: Any,
    inputs: Mapping[str, np.ndarray],
    params,
    stroke: tuple[float, float, float, float],
    *,
    side: int = AROUND_SIDE,
    context: int = 16,
    mask_part: tuple[np.ndarray, tuple[int, int]] | None = None,
) -> Around | None:
    """What to render while a stroke paints the mask input ``studio.preview_around``: the inputs
    cropped around the painted region near the stroke, so the preview costs a fraction of a full
    render.

    ``stroke`` is the stroke's ``(x0, y0, x1, y1)`` in the painted image's pixels (brush radius
    included). The crop is the bounding box of the mask's pixels within the stroke's box grown by
    ``context`` px, grown again by ``context`` px and by a quarter of its side (known pixels around
    the hole to copy from), clipped to the image. Only what belongs to the painted image is cropped
    alike: the image, the masks painted on it, and the masks ``studio.masks_of`` gives to it (a
    source mask opened as a file, unless its texture is open); every other input (a second texture
    to copy from, even of the image's size) is kept whole. A crop longer than
    ``side`` is scaled down to it (``area``, a mask thresholded back to 0/1). Parameters filled by a
    margins geometry on that image are reset to their defaults (the crop is not uncropped) and their
    left/top margins give :attr:`Around.offset`. None when the studio previews no mask that way,
    the mask is not open, or there is nothing painted near the stroke (nothing to fill).

    ``mask_part`` = ``(bits, (x, y))``: the painted mask is not in ``inputs``; ``bits`` (bool or
    float) is its part at ``(x, y)``, covering at least :func:`around_region` of the stroke.
    """
    from .geometry import Margins
    from .image import resize
    from .params import specs

    name = studio.preview_around
    g = next((g for g in studio.geometry if g.kind == MASK and g.input == name), None)
    if g is None or (name not in inputs and mask_part is None):
        return None
    on = g.input_for(inputs)
    if on not in inputs:
        return None
    h, w = inputs[on].shape[:2]
    if mask_part is None:
        mask, (px, py) = np.asarray(inputs[name]), (0, 0)
        if mask.shape[:2] != (h, w):
            return None
    else:
        mask, (px, py) = np.asarray(mask_part[0]), mask_part[1]
        rx0, ry0, rx1, ry1 = around_region(stroke, w, h, context=context)
        if px > rx0 or py > ry0 or px + mask.shape[1] < rx1 or py + mask.shape[0] < ry1:
            raise ValueError(
                f"the mask's part {mask.shape[1]}x{mask.shape[0]} at ({px}, {py}) does not cover "
                f"the stroke's region {(rx0, ry0, rx1, ry1)}"
            )
    plane = mask if mask.ndim == 2 else mask[..., 0]
    wx0, wy0, wx1, wy1 = _stroke_window(stroke, context)
    wx0, wy0, wx1, wy1 = max(0, wx0), max(0, wy0), min(w, wx1), min(h, wy1)
    if wx0 >= wx1 or wy0 >= wy1:
        return None
    near = plane[wy0 - py : wy1 - py, wx0 - px : wx1 - px] > 0.5
    rows, cols = np.flatnonzero(near.any(axis=1)), np.flatnonzero(near.any(axis=0))
    if not len(rows):
        return None
    bx0, bx1 = wx0 + int(cols[0]), wx0 + int(cols[-1]) + 1
    by0, by1 = wy0 + int(rows[0]), wy0 + int(rows[-1]) + 1
    grow = context + max(bx1 - bx0, by1 - by0) // 4
    x0, y0, x1, y1 = max(0, bx0 - grow), max(0, by0 - grow), min(w, bx1 + grow), min(h, by1 + grow)
    k = min(1.0, side / max(x1 - x0, y1 - y0))
    size = (max(8, round((x1 - x0) * k)), max(8, round((y1 - y0) * k)))
    small = dict(inputs)
    crop = {on} | {m.input for m in studio.geometry if m.kind == MASK and m.input_for(inputs) == on}
    crop |= {n for n, of in studio.masks_of.items() if next((i for i in of if i in inputs), None) == on}
    for n in dict.fromkeys([*inputs, name] if mask_part is not None else inputs):  # (each input once)
        if n == name and mask_part is not None:  # (the painted mask's part, as a 0/1 image)
            part = (plane[y0 - py : y1 - py, x0 - px : x1 - px] > 0.5).astype(np.float32)
        elif n not in crop or inputs[n].shape[:2] != (h, w):  # a mask of another size: the method says so
            continue
        else:
            part = np.ascontiguousarray(inputs[n][y0:y1, x0:x1])
        if k < 1.0:
            part = resize(part, size, interpolation="area")
            if n != on:  # a mask stays a mask
                part = (part > 0.5).astype(np.float32)
        small[n] = part
    changes, offset = {}, (0, 0)
    defaults = {s.name: s.default for s in specs(type(params))}
    for m in studio.geometry:
        if m.kind == MARGINS and m.param is not None and m.input_for(inputs) == on:
            value = getattr(params, m.param, None)
            if value:
                margins = Margins.coerce(value, m.param)
                offset = (margins.left, margins.top)
                changes[m.param] = defaults.get(m.param)
    if changes:
        params = params.replace(**changes)
    return Around(small, params, (x0, y0, x1, y1), offset)
