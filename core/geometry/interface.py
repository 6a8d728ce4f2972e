"""The kinds of geometry the studio has a tool for, and the interface a geometry value shares with
the others so that a ``Params`` field can hold it."""

from __future__ import annotations

import os
from typing import Any, Protocol, Self, runtime_checkable

# The kinds of geometry the studio has a tool for (documented where weft.core.geometry re-exports them).
SQUARE, LINES, MASK, MARGINS = "square", "lines", "mask", "margins"
KINDS = (SQUARE, LINES, MASK, MARGINS)


@runtime_checkable
class GeometryValue(Protocol):
    """A typed geometry value that a ``Params`` field can hold (``param(kind="geometry", type=...)``).

    It is parsed once where it enters weft and written once where it leaves: :meth:`parse` reads the
    command line's text, :meth:`from_json` a recipe's or session's JSON, :meth:`coerce` a Python
    caller's value (the value itself when it is already of the type), and :meth:`to_json` writes the
    JSON form that :meth:`from_json` reads back. :class:`~weft.core.geometry.Square`,
    :class:`~weft.core.geometry.FeatureLines`, :class:`~weft.core.geometry.Margins` and
    :class:`weft.core.rectify.View` are geometry values; a :class:`~weft.core.geometry.Mask` is not
    (it enters weft as an input image).

    Every method raises :class:`~weft.core.errors.WeftError` (``GeometryError`` or
    ``InvalidParameter``) with one line naming the parameter ``name`` and what is wrong.
    """

    @classmethod
    def parse(cls, text: Any, name: str = ...) -> Self:
        """The value written as command-line text, for the parameter ``name``."""
        ...

    @classmethod
    def coerce(cls, value: Any, name: str = ...) -> Self:
        """A Python caller's value (the value itself when it already has this type)."""
        ...

    @classmethod
    def from_json(cls, data: Any, name: str = ..., base: str | os.PathLike | None = None) -> Self:
        """The value read from its JSON form; file names in it are relative to ``base``."""
        ...

    def to_json(self) -> Any:
        """The JSON form, which :meth:`from_json` reads back to an equal value."""
        ...
