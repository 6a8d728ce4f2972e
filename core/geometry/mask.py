"""A mask: a region of an image, immutable, read and written as a 1-bit image."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..errors import GeometryError
from .raster import paint_line
from .reading import MAX_SIDE


class Mask:
    """A region of an image: ``bits`` is a bool (H, W) array, True = the region (to fill, to copy from).

    DESIGN.md: a mask is an image file the size of the image it belongs to; white (> 50 %) is the
    region, black is not. It enters weft as an *input image* (``--mask MASK``; a recipe names its
    PNG), is read with :meth:`from_image` and written with :meth:`to_image` / :meth:`save` (a 1-bit
    PNG). The studio paints one with :meth:`painted_line` and :meth:`painted_polygon` (Qt-free, so
    the brush's pixels are tested here). Immutable; equal when the bits are.
    """

    __slots__ = ("bits",)
    bits: np.ndarray

    def __init__(self, bits) -> None:
        arr = np.asarray(bits)
        if arr.ndim != 2 or arr.shape[0] < 1 or arr.shape[1] < 1:
            raise GeometryError(f"a mask must be a 2-D array of at least 1x1, not shape {arr.shape}")
        if max(arr.shape) > MAX_SIDE:
            raise GeometryError(f"a mask of {arr.shape[1]}x{arr.shape[0]} has a side over {MAX_SIDE}")
        arr = np.array(arr, dtype=bool)  # a private copy
        arr.flags.writeable = False
        object.__setattr__(self, "bits", arr)

    @classmethod
    def _own(cls, bits: np.ndarray) -> Mask:
        """A mask over ``bits``, a fresh bool array of this module's own making (no second copy)."""
        mask = cls.__new__(cls)
        bits.flags.writeable = False
        object.__setattr__(mask, "bits", bits)
        return mask

    def __setattr__(self, name, value):
        raise AttributeError("Mask is immutable")

    @classmethod
    def empty(cls, width: int, height: int) -> Mask:
        return cls(np.zeros((height, width), dtype=bool))

    @classmethod
    def from_image(cls, image, what: str = "mask") -> Mask:
        """White (> 0.5) pixels of a float image in [0, 1]: grey (H, W), colour (H, W, 3) by its mean,
        or with alpha (H, W, 2|4), where a transparent pixel is black."""
        arr = np.asarray(image, dtype=np.float32)
        if arr.ndim == 2:
            value = arr
        elif arr.ndim == 3 and arr.shape[2] in (1, 2, 3, 4):
            colour = arr[..., : 1 if arr.shape[2] <= 2 else 3].mean(axis=2)
            value = colour * arr[..., -1] if arr.shape[2] in (2, 4) else colour
        else:
            raise GeometryError(f"the {what} has shape {arr.shape}; a mask is a grey or colour image")
        return cls(value > 0.5)

    @classmethod
    def from_alpha(cls, alpha, threshold: float = 0.5) -> Mask:
        """The transparent pixels (alpha below ``threshold``) of an alpha channel in [0, 1]: the hole
        a fill closes when it is given no mask."""
        return cls(np.asarray(alpha, dtype=np.float32) < threshold)

    @property
    def shape(self) -> tuple[int, int]:
        return self.bits.shape

    @property
    def size(self) -> tuple[int, int]:
        """``(width, height)``."""
        return self.bits.shape[1], self.bits.shape[0]

    @property
    def area(self) -> int:
        """The region's pixel count."""
        return int(np.count_nonzero(self.bits))

    @property
    def fraction(self) -> float:
        return self.area / self.bits.size

    def __bool__(self) -> bool:
        return self.area > 0

    def bbox(self) -> tuple[int, int, int, int] | None:
        """``(x0, y0, x1, y1)`` (exclusive ends) of the region, or None when it is empty."""
        rows = np.flatnonzero(self.bits.any(axis=1))
        if not len(rows):
            return None
        cols = np.flatnonzero(self.bits.any(axis=0))
        return int(cols[0]), int(rows[0]), int(cols[-1]) + 1, int(rows[-1]) + 1

    def check_size(self, shape, what: str = "image", name: str = "mask") -> Mask:
        """Raise ``GeometryError`` naming both sizes unless the mask is the size of ``shape``'s image."""
        h, w = int(shape[0]), int(shape[1])
        if self.bits.shape != (h, w):
            raise GeometryError(
                f"the {name} is {self.size[0]}x{self.size[1]} but the {what} is {w}x{h}; "
                f"a {name} must be the size of its image"
            )
        return self

    def to_image(self) -> np.ndarray:
        """float32 (H, W): 1.0 in the region, 0.0 elsewhere (what a method is given as its input)."""
        return self.bits.astype(np.float32)

    def to_png(self) -> bytes:
        """A 1-bit PNG of the mask (white = the region)."""
        import io

        from PIL import Image

        buf = io.BytesIO()
        Image.fromarray(self.bits).convert("1").save(buf, format="PNG", optimize=True)
        return buf.getvalue()

    def save(self, path: str | os.PathLike) -> None:
        """Write :meth:`to_png` to ``path`` atomically (a temporary file renamed into place)."""
        target = Path(path)
        tmp = target.with_name(f".{target.name}.tmp")
        tmp.write_bytes(self.to_png())
        os.replace(tmp, target)

    @classmethod
    def read(cls, path: str | os.PathLike, what: str = "mask") -> Mask:
        """A mask image file (any format weft reads); errors are weft's one-line image errors."""
        from ..image import load_image

        return cls.from_image(load_image(path).image, what)

    def painted_line(self, p0, p1, radius: float, value: bool = True) -> Mask:
        """The mask with a round brush stroke from ``p0`` to ``p1`` (pixel coordinates ``(x, y)``,
        pixel centres at whole numbers) set to ``value`` (True paints, False erases): every pixel whose
        centre lies within ``radius`` of the segment. A zero-length stroke is a dot; radius 0 is a
        one-pixel-wide line. (:func:`paint_line` paints into an array in place: a stroke being drawn.)"""
        out = self.bits.copy()
        return self if paint_line(out, p0, p1, radius, value) is None else Mask._own(out)

    def painted_polygon(self, points, value: bool = True) -> Mask:
        """The mask with the polygon ``points`` [(x, y), ...] (a lasso, closed) set to ``value``."""
        import cv2

        pts = np.round(np.asarray(points, dtype=np.float64)).astype(np.int32).reshape(-1, 1, 2)
        if len(pts) < 3:
            return self
        layer = np.zeros(self.bits.shape, dtype=np.uint8)
        cv2.fillPoly(layer, [pts], 1, lineType=cv2.LINE_8)
        out = self.bits.copy()
        out[layer > 0] = value
        return Mask._own(out)

    def __eq__(self, other) -> bool:
        return (
            isinstance(other, Mask)
            and self.bits.shape == other.bits.shape
            and bool(np.array_equal(self.bits, other.bits))
        )

    def __hash__(self) -> int:
        return hash((self.bits.shape, np.packbits(self.bits).tobytes()))

    def __repr__(self) -> str:
        return f"Mask({self.size[0]}x{self.size[1]}, {self.area} px)"
