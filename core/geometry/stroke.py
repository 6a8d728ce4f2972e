"""A mask being painted, dab by dab, in place."""

from __future__ import annotations

import numpy as np

from ..errors import GeometryError
from .mask import Mask
from .raster import paint_line


class MaskStroke:
    """A mask being painted, dab by dab (the studio's brush and eraser): its bits change in place
    (:func:`paint_line`), so a dab costs the dab's pixels, where ``Mask.painted_line`` copies the
    whole mask. Not a :class:`Mask` (which is immutable): read it with
    :meth:`cut` (a copy of a part, what a preview around the stroke needs), :attr:`bits` (a read-only
    view that changes as the stroke goes on) or :meth:`snapshot`; :meth:`mask` ends the stroke.

    ``changed``: whether any pixel differs from the mask the stroke began on."""

    __slots__ = ("_bits", "changed", "_ended")

    def __init__(self, base: Mask | None, width: int | None = None, height: int | None = None) -> None:
        if base is None:
            if not width or not height or width < 1 or height < 1:
                raise GeometryError(f"a stroke needs a mask or a size, not {width}x{height}")
            self._bits = np.zeros((height, width), dtype=bool)  # (calloc: pages are made as painted)
        else:
            self._bits = base.bits.copy()
        self.changed = False
        self._ended = False

    @property
    def shape(self) -> tuple[int, int]:
        return self._bits.shape

    @property
    def bits(self) -> np.ndarray:
        """The bits so far (a read-only view: it changes with the next dab)."""
        view = self._bits.view()
        view.flags.writeable = False
        return view

    def line(self, p0, p1, radius: float, value: bool = True) -> tuple[int, int, int, int] | None:
        """Paint a brush line (as :meth:`Mask.painted_line`); the box of the pixels it changed, or None."""
        if self._ended:
            raise GeometryError("this stroke has ended: it paints no more")
        box = paint_line(self._bits, p0, p1, radius, value)
        self.changed = self.changed or box is not None
        return box

    def cut(self, x0: int, y0: int, x1: int, y1: int) -> np.ndarray:
        """A copy of the bits in ``[y0:y1, x0:x1]`` (clipped to the mask)."""
        h, w = self._bits.shape
        return self._bits[max(0, y0) : min(h, y1), max(0, x0) : min(w, x1)].copy()

    def snapshot(self) -> Mask:
        """The mask so far (a copy: the stroke goes on)."""
        return Mask(self._bits)

    def mask(self) -> Mask:
        """The mask painted, ending the stroke: the bits are handed over, not copied."""
        self._ended = True
        return Mask._own(self._bits)

    def __repr__(self) -> str:
        h, w = self._bits.shape
        return f"MaskStroke({w}x{h}, changed={self.changed})"
