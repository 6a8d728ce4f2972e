"""Typed geometry: a square, feature lines, and how each is read and written at the edges.

A geometry value is parsed once where it enters weft -- command-line text (:meth:`parse`), the JSON
of a recipe or session (:meth:`from_json`), a Python caller's value (:meth:`coerce`) -- and is held
typed everywhere else: in a method's ``Params``, in the studio's document, in a result's recipe. It
is written once, by :meth:`to_json` (and :meth:`to_text` for a command line). Nothing is turned into
text and parsed again per render.

A ``Params`` field holds one with ``param(None, kind="geometry", type=Square)`` (see
:mod:`weft.core.params`); any class with these four methods can be such a type (:class:`weft.core.rectify.View`
is one more).

Command-line rule for lines and views (one rule, stated here and in ``--help``): text that starts with
``{`` is the JSON object itself; anything else is the name of a JSON file.
"""

from __future__ import annotations

import json
import math
import numbers
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping, NamedTuple

import numpy as np

from .errors import GeometryError, InvalidParameter
from .jsonio import MAX_FILE_BYTES

MAX_SIDE = 16384

__all__ = ["Square", "FeatureLines", "LineDraft", "read_json_or_file", "SQUARE", "LINES", "KINDS"]

#: The kinds of geometry the studio has a tool for (a method's studio description names them per input).
#: DESIGN.md's third kind, a mask painted with a brush, comes with the method that needs it (fill).
SQUARE, LINES = "square", "lines"
KINDS = (SQUARE, LINES)


class Square(NamedTuple):
    """A square of an image: top-left corner ``(x, y)`` and ``side``, in pixels.

    It is a tuple, so ``x, y, s = square`` works; ``Square.parse("32,16,64")`` is the one parser of
    the text form ``X,Y,S`` (``--region``, ``--prototype``), ``from_json([x, y, s])`` of the JSON form.
    """

    x: int
    y: int
    side: int

    MIN_SIDE = 2
    METAVAR = "X,Y,S"

    @classmethod
    def parse(cls, text: Any, name: str = "region") -> "Square":
        """Parse ``"X,Y,S"`` (spaces ignored) or a sequence of three whole numbers.

        The corner must not be negative and the side at least 2; what a method needs beyond that (the
        affine prototype's even side of at least 8) is :meth:`check_side`. Whether the square fits in
        an image is :meth:`crop`'s business. ``InvalidParameter`` names ``name`` and the value.
        """
        if isinstance(text, str):
            shown = text
            try:
                values = tuple(int(p) for p in text.replace(" ", "").split(","))
            except ValueError:
                values = ()
        else:
            try:
                if isinstance(text, (str, bytes)) or any(isinstance(v, (bool, np.bool_)) for v in text):
                    raise TypeError
                values = tuple(int(v) for v in text)
                if any(v != w for v, w in zip(values, text)):  # 8.5 is not a pixel count: no silent rounding
                    values = ()
            except (TypeError, ValueError, OverflowError):
                values = ()
            shown = ",".join(str(v) for v in text) if isinstance(text, (tuple, list)) else repr(text)
        if len(values) != 3:
            raise InvalidParameter(f"parameter '{name}' = {shown!r} must be X,Y,SIDE (top-left corner and side of "
                                   f"a square in pixels, e.g. 32,16,64)", name=name, value=text)
        x, y, s = values
        if x < 0 or y < 0:
            raise InvalidParameter(f"parameter '{name}' = {x},{y},{s}: the corner {x},{y} must not be negative",
                                   name=name, value=text)
        if s < cls.MIN_SIDE:
            raise InvalidParameter(f"parameter '{name}' = {x},{y},{s}: the side {s} must be at least {cls.MIN_SIDE}",
                                   name=name, value=text)
        return cls(x, y, s)

    @classmethod
    def coerce(cls, value: Any, name: str = "region") -> "Square":
        """A Python caller's square: a ``Square``, ``(x, y, s)`` or ``"X,Y,S"``."""
        return value if isinstance(value, Square) else cls.parse(value, name)

    @classmethod
    def from_json(cls, data: Any, name: str = "region", base: str | os.PathLike | None = None) -> "Square":
        """``[x, y, side]`` of a recipe or session (whole numbers only); older recipes' text ``"X,Y,S"``
        is read by :meth:`parse` too."""
        if isinstance(data, str):
            return cls.parse(data, name)
        if not isinstance(data, list):
            raise InvalidParameter(f"parameter '{name}' = {data!r} must be [x, y, side] in pixels",
                                   name=name, value=data)
        return cls.parse(data, name)

    def to_json(self) -> list[int]:
        return [int(self.x), int(self.y), int(self.side)]

    def to_text(self) -> str:
        return f"{self.x},{self.y},{self.side}"

    def check_side(self, name: str, *, minimum: int = 2, even: bool = False) -> "Square":
        """Raise ``InvalidParameter`` unless the side is at least ``minimum`` (and even, if asked)."""
        x, y, s = self
        if s < minimum or (even and s % 2):
            need = f"even and at least {minimum}" if even else f"at least {minimum}"
            raise InvalidParameter(f"parameter '{name}' = {x},{y},{s}: the side {s} must be {need}",
                                   name=name, value=self)
        return self

    def crop(self, image: np.ndarray, what: str = "texture", name: str = "region") -> np.ndarray:
        """The square's pixels of ``image``; ``InvalidParameter`` naming it if it leaves the image."""
        x, y, s = self
        h, w = image.shape[:2]
        if x < 0 or y < 0 or s < 1 or x + s > w or y + s > h:
            raise InvalidParameter(f"parameter '{name}' = {x},{y},{s} leaves the {what} ({w}x{h})",
                                   name=name, value=self)
        return np.ascontiguousarray(image[y:y + s, x:x + s])

    def scaled(self, k: float) -> "Square":
        """The square in an image scaled by ``k`` (corner rounded down, side at least 1)."""
        return Square(int(self.x * k), int(self.y * k), max(1, int(round(self.side * k))))


# --- feature lines --------------------------------------------------------------------------------


def _num(v: Any) -> bool:
    return isinstance(v, numbers.Real) and not isinstance(v, bool)


def _short(value: Any) -> str:
    text = json.dumps(value) if not isinstance(value, np.ndarray) else str(value.tolist())
    return text if len(text) <= 60 else text[:57] + "..."


def as_lines(value: Any, key: str) -> np.ndarray:
    """``value`` as a float64 (N, 4) array, or a GeometryError naming the first bad entry."""
    if isinstance(value, np.ndarray):
        arr = value
        if arr.ndim != 2 or arr.shape[1] != 4 or not np.issubdtype(arr.dtype, np.number):
            raise GeometryError(f"{key} must be an (N, 4) array of [x1, y1, x2, y2], not shape {arr.shape}")
        arr = arr.astype(np.float64)
        bad = np.nonzero(~np.isfinite(arr).all(axis=1))[0]
        if len(bad):
            raise GeometryError(f"{key}[{bad[0]}] = {arr[bad[0]].tolist()} has a NaN or infinite coordinate")
        return np.ascontiguousarray(arr)
    if not isinstance(value, (list, tuple)):
        raise GeometryError(f"{key} must be a list of [x1, y1, x2, y2], not {type(value).__name__}")
    for i, line in enumerate(value):
        if (not isinstance(line, (list, tuple, np.ndarray)) or len(line) != 4 or not all(_num(v) for v in line)):
            raise GeometryError(f"{key}[{i}] = {_short(line)} must be [x1, y1, x2, y2] (four numbers)")
        if not all(math.isfinite(float(v)) for v in line):
            raise GeometryError(f"{key}[{i}] = {_short(line)} has a NaN or infinite coordinate")
    return np.array(value, dtype=np.float64).reshape(-1, 4)


def as_size(value: Any, key: str) -> tuple[int, int]:
    """``[w, h]`` of whole pixels (``512.0`` is accepted as 512, ``512.5`` is not)."""
    if (not isinstance(value, (list, tuple)) or len(value) != 2
            or not all(_num(v) and math.isfinite(float(v)) and float(v) == int(v) for v in value)):
        raise GeometryError(f"{key} = {_short(value)} must be [width, height] in whole pixels")
    w, h = int(value[0]), int(value[1])
    if not (2 <= w <= MAX_SIDE and 2 <= h <= MAX_SIDE):
        raise GeometryError(f"{key} = [{w}, {h}] has a side outside 2..{MAX_SIDE}")
    return w, h


def read_json_or_file(text_or_path: str | os.PathLike, what: str) -> tuple[Any, str]:
    """The command-line rule: text starting with ``{`` is JSON, anything else a JSON file's name.

    Returns ``(data, source)``; ``source`` names the file (or says "inline JSON") for messages.
    """
    text = os.fspath(text_or_path)
    if text.lstrip().startswith("{"):
        source, raw = f"{what} (inline JSON)", text
    else:
        source = text if text.isprintable() else repr(text)
        try:
            if os.path.getsize(text) > MAX_FILE_BYTES:
                raise GeometryError(f"{source}: too large for a {what} file (the limit is "
                                    f"{MAX_FILE_BYTES // 2**20} MB); not read")
            raw = Path(text).read_text(encoding="utf-8-sig")
        except FileNotFoundError:
            raise GeometryError(f"{source}: no such {what} file") from None
        except IsADirectoryError:
            raise GeometryError(f"{source}: is a directory, not a {what} file") from None
        except (OSError, UnicodeDecodeError, ValueError) as e:
            raise GeometryError(f"{source}: cannot read {what} ({getattr(e, 'strerror', None) or e})") from None
    try:  # NaN is let through here: the line checks then say which line has it
        return json.loads(raw), source
    except json.JSONDecodeError as e:
        raise GeometryError(f"{source}: not valid JSON ({e.msg} at line {e.lineno} column {e.colno})") from None
    except (RecursionError, ValueError) as e:
        raise GeometryError(f"{source}: not valid JSON ({type(e).__name__})") from None


def _from_json_or_path(cls, data: Any, name: str, base, what: str):
    """A recipe's value: the JSON object itself, or (older recipes) text by the command-line rule: JSON
    text (starts with ``{``) or a file name, relative to ``base``."""
    if isinstance(data, str):
        if data.lstrip().startswith("{"):
            return cls.parse(data, name)
        if not data or "\0" in data:
            raise GeometryError(f"parameter '{name}' = {data!r} is not a {what} file name")
        path = data if os.path.isabs(data) or base is None else os.path.join(os.fspath(base), data)
        if not os.path.exists(path):
            raise GeometryError(f"parameter '{name}' names {data}, but {path} does not exist")
        return cls.parse(path, name)
    if isinstance(data, Mapping):
        return cls.coerce(data, name)
    raise GeometryError(f"parameter '{name}' = {_short(data)} must be a {what} JSON object")


class FeatureLines:
    """Validated feature lines: ``image_lines`` and ``frontal_lines`` are float64 (N, 4) arrays.

    ``frontal_size`` is ``(width, height)`` of the frontal frame. Line *i* of the photo goes with line
    *i* of the frontal frame (DESIGN.md: ``{"image_lines": [...], "frontal_lines": [...],
    "frontal_size": [w, h]}``). Equal when their JSON is equal.
    """

    __slots__ = ("image_lines", "frontal_lines", "frontal_size")
    METAVAR = "LINES"

    def __init__(self, image_lines, frontal_lines, frontal_size) -> None:
        img = as_lines(image_lines, "image_lines")
        fro = as_lines(frontal_lines, "frontal_lines")
        if len(img) != len(fro):
            raise GeometryError(f"{len(img)} image_lines but {len(fro)} frontal_lines: line i of the photo "
                                f"must match line i of the frontal frame")
        size = as_size(frontal_size, "frontal_size")
        # (the arrays stay writeable: numba compiles a second signature of every kernel for read-only ones)
        object.__setattr__(self, "image_lines", img)
        object.__setattr__(self, "frontal_lines", fro)
        object.__setattr__(self, "frontal_size", size)

    def __setattr__(self, name, value):
        raise AttributeError("FeatureLines is immutable")

    def __len__(self) -> int:
        return len(self.image_lines)

    def __eq__(self, other) -> bool:
        return isinstance(other, FeatureLines) and self.to_json() == other.to_json()

    def __hash__(self) -> int:
        return hash(json.dumps(self.to_json()))

    def __repr__(self) -> str:
        return f"FeatureLines({len(self)} pairs, frontal_size={self.frontal_size})"

    def to_dict(self) -> dict[str, Any]:
        return self.to_json()

    def to_json(self) -> dict[str, Any]:
        return {"image_lines": self.image_lines.tolist(), "frontal_lines": self.frontal_lines.tolist(),
                "frontal_size": list(self.frontal_size)}

    def to_text(self) -> str:
        return json.dumps(self.to_json())

    @classmethod
    def from_mapping(cls, data: Any, *, source: str = "") -> "FeatureLines":
        """From the parsed JSON object; GeometryError (prefixed with ``source``) naming the key."""
        prefix = f"{source}: " if source else ""
        try:
            if not isinstance(data, Mapping):
                raise GeometryError(f"feature lines must be a JSON object, not {type(data).__name__}")
            for key in ("image_lines", "frontal_lines", "frontal_size"):
                if key not in data:
                    what = "[width, height]" if key == "frontal_size" else "a list of [x1, y1, x2, y2]"
                    raise GeometryError(f"no \"{key}\" ({what})")
            return cls(as_lines(data["image_lines"], "image_lines"), as_lines(data["frontal_lines"], "frontal_lines"),
                       as_size(data["frontal_size"], "frontal_size"))
        except GeometryError as e:
            raise GeometryError(prefix + str(e)) from None

    @classmethod
    def parse(cls, text: str | os.PathLike, name: str = "lines") -> "FeatureLines":
        """Command-line text: the JSON object itself (starts with ``{``) or a JSON file's name."""
        data, source = read_json_or_file(text, "feature-lines")
        return cls.from_mapping(data, source=source)

    @classmethod
    def coerce(cls, value: Any, name: str = "lines") -> "FeatureLines":
        """A Python caller's lines: ``FeatureLines``, the JSON object (a mapping), or a file name /
        JSON text by the command-line rule."""
        if isinstance(value, FeatureLines):
            return value
        if isinstance(value, Mapping):
            return cls.from_mapping(value)
        if isinstance(value, (str, os.PathLike)):
            return cls.parse(value, name)
        raise GeometryError(f"parameter '{name}' = {_short(repr(value))} must be feature lines "
                            f"{{image_lines, frontal_lines, frontal_size}}")

    @classmethod
    def from_json(cls, data: Any, name: str = "lines", base: str | os.PathLike | None = None) -> "FeatureLines":
        return _from_json_or_path(cls, data, name, base, "feature-lines")


@dataclass(frozen=True)
class LineDraft:
    """Feature lines being drawn: the photo may have one line more than the frontal frame (its
    partner not drawn yet). :meth:`complete` gives the :class:`FeatureLines` of the finished pairs."""

    image_lines: tuple[tuple[float, float, float, float], ...] = ()
    frontal_lines: tuple[tuple[float, float, float, float], ...] = ()
    frontal_size: tuple[int, int] = (512, 512)

    def __post_init__(self) -> None:
        for key in ("image_lines", "frontal_lines"):
            lines = as_lines(list(map(list, getattr(self, key))), key) if len(getattr(self, key)) else np.zeros((0, 4))
            object.__setattr__(self, key, tuple(tuple(float(v) for v in ln) for ln in lines.tolist()))
        object.__setattr__(self, "frontal_size", as_size(self.frontal_size, "frontal_size"))

    @property
    def pairs(self) -> int:
        return min(len(self.image_lines), len(self.frontal_lines))

    def complete(self) -> FeatureLines | None:
        """The finished pairs as :class:`FeatureLines`, or None if there are none."""
        n = self.pairs
        if n == 0:
            return None
        return FeatureLines(list(self.image_lines[:n]), list(self.frontal_lines[:n]), self.frontal_size)

    def to_json(self) -> dict[str, Any]:
        return {"image_lines": [list(x) for x in self.image_lines],
                "frontal_lines": [list(x) for x in self.frontal_lines], "frontal_size": list(self.frontal_size)}

    @classmethod
    def from_json(cls, data: Any, name: str = "lines") -> "LineDraft":
        """From a session's ``{image_lines, frontal_lines, frontal_size}`` (pairs may be unfinished;
        ``frontal_size`` defaults to 512x512); the line and size checks are :class:`FeatureLines`'."""
        if not isinstance(data, Mapping):
            raise GeometryError(f"{name} must be an object {{image_lines, frontal_lines, frontal_size}}")
        drafts = []
        for key in ("image_lines", "frontal_lines"):
            value = data.get(key, [])
            drafts.append(tuple(map(tuple, as_lines(value, key).tolist())) if len(value) else ())
        return cls(drafts[0], drafts[1], as_size(data.get("frontal_size", [512, 512]), "frontal_size"))

    @classmethod
    def of(cls, lines: FeatureLines) -> "LineDraft":
        return cls(tuple(map(tuple, lines.image_lines.tolist())), tuple(map(tuple, lines.frontal_lines.tolist())),
                   lines.frontal_size)
