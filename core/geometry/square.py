"""A square of an image (``--region``, ``--prototype``)."""

from __future__ import annotations

import os
from typing import Any, NamedTuple

import numpy as np

from ..errors import InvalidParameter
from .reading import whole_number


class _SquareFields(NamedTuple):
    x: int
    y: int
    side: int


class Square(_SquareFields):
    """A square of an image: top-left corner ``(x, y)`` and ``side``, in pixels.

    It is a tuple, so ``x, y, s = square`` works; ``Square.parse("32,16,64")`` is the one parser of
    the text form ``X,Y,S`` (``--region``, ``--prototype``), ``from_json([x, y, s])`` of the JSON form.
    (The fields live on a base class so that the constants below are class attributes, not fields.)
    """

    __slots__ = ()

    MIN_SIDE = 2
    METAVAR = "X,Y,S"

    @classmethod
    def parse(cls, text: Any, name: str = "region") -> Square:
        """Parse ``"X,Y,S"`` (spaces ignored) or a sequence of three whole numbers.

        The corner must not be negative and the side at least 2; what a method needs beyond that (the
        affine prototype's even side of at least 8) is :meth:`check_side`. Whether the square fits in
        an image is :meth:`crop`'s business. ``InvalidParameter`` names ``name`` and the value.
        """
        if isinstance(text, str):
            shown = text
            try:
                values = tuple(whole_number(p) for p in text.replace(" ", "").split(","))
            except ValueError:
                values = ()
        else:
            try:
                if isinstance(text, (str, bytes)) or any(isinstance(v, (bool, np.bool_)) for v in text):
                    raise TypeError
                values = tuple(int(v) for v in text)
                # 8.5 is not a pixel count: no silent rounding
                if any(v != w for v, w in zip(values, text, strict=False)):
                    values = ()
            except (TypeError, ValueError, OverflowError):
                values = ()
            shown = ",".join(str(v) for v in text) if isinstance(text, (tuple, list)) else repr(text)
        if len(values) != 3:
            raise InvalidParameter(
                f"parameter '{name}' = {shown!r} must be X,Y,SIDE (top-left corner and side of "
                f"a square in pixels, e.g. 32,16,64)",
                name=name,
                value=text,
            )
        x, y, s = values
        if x < 0 or y < 0:
            raise InvalidParameter(
                f"parameter '{name}' = {x},{y},{s}: the corner {x},{y} must not be negative", name=name, value=text
            )
        if s < cls.MIN_SIDE:
            raise InvalidParameter(
                f"parameter '{name}' = {x},{y},{s}: the side {s} must be at least {cls.MIN_SIDE}", name=name, value=text
            )
        return cls(x, y, s)

    @classmethod
    def coerce(cls, value: Any, name: str = "region") -> Square:
        """A Python caller's square: a ``Square``, ``(x, y, s)`` or ``"X,Y,S"``."""
        return value if isinstance(value, Square) else cls.parse(value, name)

    @classmethod
    def from_json(cls, data: Any, name: str = "region", base: str | os.PathLike | None = None) -> Square:
        """``[x, y, side]`` of a recipe or session (whole numbers only); older recipes' text ``"X,Y,S"``
        is read by :meth:`parse` too."""
        if isinstance(data, str):
            return cls.parse(data, name)
        if not isinstance(data, list):
            raise InvalidParameter(
                f"parameter '{name}' = {data!r} must be [x, y, side] in pixels", name=name, value=data
            )
        return cls.parse(data, name)

    def to_json(self) -> list[int]:
        return [int(self.x), int(self.y), int(self.side)]

    def to_text(self) -> str:
        return f"{self.x},{self.y},{self.side}"

    def check_side(self, name: str, *, minimum: int = 2, even: bool = False) -> Square:
        """Raise ``InvalidParameter`` unless the side is at least ``minimum`` (and even, if asked)."""
        x, y, s = self
        if s < minimum or (even and s % 2):
            need = f"even and at least {minimum}" if even else f"at least {minimum}"
            raise InvalidParameter(
                f"parameter '{name}' = {x},{y},{s}: the side {s} must be {need}", name=name, value=self
            )
        return self

    def crop(self, image: np.ndarray, what: str = "texture", name: str = "region") -> np.ndarray:
        """The square's pixels of ``image``; ``InvalidParameter`` naming it if it leaves the image."""
        x, y, s = self
        h, w = image.shape[:2]
        if x < 0 or y < 0 or s < 1 or x + s > w or y + s > h:
            raise InvalidParameter(
                f"parameter '{name}' = {x},{y},{s} leaves the {what} ({w}x{h})", name=name, value=self
            )
        return np.ascontiguousarray(image[y : y + s, x : x + s])

    def scaled(self, k: float) -> Square:
        """The square in an image scaled by ``k`` (corner rounded down, side at least 1)."""
        return Square(int(self.x * k), int(self.y * k), max(1, int(round(self.side * k))))
