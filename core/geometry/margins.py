"""Margins: pixels added on each side of an image (an uncrop)."""

from __future__ import annotations

import os
from typing import Any, NamedTuple

import numpy as np

from ..errors import InvalidParameter
from .reading import MAX_SIDE, whole_number


class _MarginsFields(NamedTuple):
    left: int
    top: int
    right: int
    bottom: int


class Margins(_MarginsFields):
    """Pixels added on each side of an image: ``left, top, right, bottom`` (an uncrop's new border).

    Text form ``L,T,R,B`` (``--extend``); JSON ``[l, t, r, b]``. Each is a whole number from 0 to
    :data:`MAX_SIDE`; whether the grown canvas is allowed is the pixel limit's business.
    (The fields live on a base class so that ``METAVAR`` is a class attribute, not a field.)
    """

    __slots__ = ()

    METAVAR = "L,T,R,B"

    @classmethod
    def parse(cls, text: Any, name: str = "extend") -> Margins:
        shown = (
            text
            if isinstance(text, str)
            else ",".join(map(str, text))
            if isinstance(text, (list, tuple))
            else repr(text)
        )
        values: tuple = ()
        try:
            if isinstance(text, str):
                values = tuple(whole_number(p) for p in text.replace(" ", "").split(","))
            elif not any(isinstance(v, (bool, np.bool_)) for v in text):
                values = tuple(int(v) for v in text)
                if any(v != w for v, w in zip(values, text, strict=False)):
                    values = ()
        except (TypeError, ValueError, OverflowError):
            values = ()
        if len(values) != 4:
            raise InvalidParameter(
                f"parameter '{name}' = {shown!r} must be L,T,R,B (pixels added on the left, "
                f"top, right and bottom, e.g. 0,0,128,0)",
                name=name,
                value=text,
            )
        for side, v in zip(("left", "top", "right", "bottom"), values, strict=True):
            if not 0 <= v <= MAX_SIDE:
                raise InvalidParameter(
                    f"parameter '{name}' = {shown}: the {side} margin {v} is outside 0..{MAX_SIDE}",
                    name=name,
                    value=text,
                )
        return cls(*values)

    @classmethod
    def coerce(cls, value: Any, name: str = "extend") -> Margins:
        return value if isinstance(value, Margins) else cls.parse(value, name)

    @classmethod
    def from_json(cls, data: Any, name: str = "extend", base: str | os.PathLike | None = None) -> Margins:
        if not isinstance(data, (list, str)):
            raise InvalidParameter(
                f"parameter '{name}' = {data!r} must be [left, top, right, bottom] in pixels", name=name, value=data
            )
        return cls.parse(data, name)

    def to_json(self) -> list[int]:
        return [int(v) for v in self]

    def to_text(self) -> str:
        return ",".join(str(int(v)) for v in self)

    def __bool__(self) -> bool:
        return any(self)

    def grown(self, width: int, height: int) -> tuple[int, int]:
        """The canvas size ``(width, height)`` once the margins are added."""
        return width + self.left + self.right, height + self.top + self.bottom
