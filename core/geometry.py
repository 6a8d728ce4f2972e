"""Typed geometry: a square, feature lines, a mask, margins, and how each is read and written at the edges.

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
import re
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from .errors import GeometryError, InvalidParameter
from .jsonio import MAX_FILE_BYTES
from .readfile import read_regular, shown

MAX_SIDE = 16384

__all__ = [
    "Square",
    "FeatureLines",
    "LineDraft",
    "Mask",
    "MaskStroke",
    "paint_line",
    "Margins",
    "read_json_or_file",
    "SQUARE",
    "LINES",
    "MASK",
    "MARGINS",
    "KINDS",
]

#: The kinds of geometry the studio has a tool for (a method's studio description names them per input):
#: a square (dragged), feature lines (drawn in pairs), a mask (painted with a brush, eraser or lasso)
#: and margins (the canvas's edges dragged outward: an uncrop).
SQUARE, LINES, MASK, MARGINS = "square", "lines", "mask", "margins"
KINDS = (SQUARE, LINES, MASK, MARGINS)


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
                # 8.5 is not a pixel count: no silent rounding (text may be any iterable: not strict)
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
        if not isinstance(line, (list, tuple, np.ndarray)) or len(line) != 4 or not all(_num(v) for v in line):
            raise GeometryError(f"{key}[{i}] = {_short(line)} must be [x1, y1, x2, y2] (four numbers)")
        if not all(math.isfinite(float(v)) for v in line):
            raise GeometryError(f"{key}[{i}] = {_short(line)} has a NaN or infinite coordinate")
    return np.array(value, dtype=np.float64).reshape(-1, 4)


_WHOLE = re.compile(r"[+-]?[0-9]+")


def whole_number(text: str) -> int:
    """``text`` as a whole number written in ASCII digits (an optional sign): ``int`` alone would also
    take ``1_000`` and other scripts' digits. ``ValueError`` otherwise."""
    if not _WHOLE.fullmatch(text):
        raise ValueError(f"not a whole number: {text!r}")
    return int(text)


def as_size(value: Any, key: str) -> tuple[int, int]:
    """``[w, h]`` of whole pixels (``512.0`` is accepted as 512, ``512.5`` is not)."""
    if (
        not isinstance(value, (list, tuple))
        or len(value) != 2
        or not all(_num(v) and math.isfinite(float(v)) and float(v) == int(v) for v in value)
    ):
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
        source = shown(text)
        try:
            raw = read_regular(text, MAX_FILE_BYTES, f"{what} file", error=GeometryError).decode("utf-8-sig")
        except FileNotFoundError:
            raise GeometryError(f"{source}: no such {what} file") from None
        except IsADirectoryError:
            raise GeometryError(f"{source}: is a directory, not a {what} file") from None
        except GeometryError:
            raise
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
            raise GeometryError(
                f"{len(img)} image_lines but {len(fro)} frontal_lines: line i of the photo "
                f"must match line i of the frontal frame"
            )
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
        return {
            "image_lines": self.image_lines.tolist(),
            "frontal_lines": self.frontal_lines.tolist(),
            "frontal_size": list(self.frontal_size),
        }

    def to_text(self) -> str:
        return json.dumps(self.to_json())

    @classmethod
    def from_mapping(cls, data: Any, *, source: str = "") -> FeatureLines:
        """From the parsed JSON object; GeometryError (prefixed with ``source``) naming the key."""
        prefix = f"{source}: " if source else ""
        try:
            if not isinstance(data, Mapping):
                raise GeometryError(f"feature lines must be a JSON object, not {type(data).__name__}")
            for key in ("image_lines", "frontal_lines", "frontal_size"):
                if key not in data:
                    what = "[width, height]" if key == "frontal_size" else "a list of [x1, y1, x2, y2]"
                    raise GeometryError(f'no "{key}" ({what})')
            return cls(
                as_lines(data["image_lines"], "image_lines"),
                as_lines(data["frontal_lines"], "frontal_lines"),
                as_size(data["frontal_size"], "frontal_size"),
            )
        except GeometryError as e:
            raise GeometryError(prefix + str(e)) from None

    @classmethod
    def parse(cls, text: str | os.PathLike, name: str = "lines") -> FeatureLines:
        """Command-line text: the JSON object itself (starts with ``{``) or a JSON file's name."""
        data, source = read_json_or_file(text, "feature-lines")
        return cls.from_mapping(data, source=source)

    @classmethod
    def coerce(cls, value: Any, name: str = "lines") -> FeatureLines:
        """A Python caller's lines: ``FeatureLines``, the JSON object (a mapping), or a file name /
        JSON text by the command-line rule."""
        if isinstance(value, FeatureLines):
            return value
        if isinstance(value, Mapping):
            return cls.from_mapping(value)
        if isinstance(value, (str, os.PathLike)):
            return cls.parse(value, name)
        raise GeometryError(
            f"parameter '{name}' = {_short(repr(value))} must be feature lines "
            f"{{image_lines, frontal_lines, frontal_size}}"
        )

    @classmethod
    def from_json(cls, data: Any, name: str = "lines", base: str | os.PathLike | None = None) -> FeatureLines:
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
        return {
            "image_lines": [list(x) for x in self.image_lines],
            "frontal_lines": [list(x) for x in self.frontal_lines],
            "frontal_size": list(self.frontal_size),
        }

    @classmethod
    def from_json(cls, data: Any, name: str = "lines") -> LineDraft:
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
    def of(cls, lines: FeatureLines) -> LineDraft:
        return cls(
            tuple(map(tuple, lines.image_lines.tolist())),
            tuple(map(tuple, lines.frontal_lines.tolist())),
            lines.frontal_size,
        )


# --- masks ----------------------------------------------------------------------------------------


class Mask:
    """A region of an image: ``bits`` is a bool (H, W) array, True = the region (to fill, to copy from).

    DESIGN.md: a mask is an image file the size of the image it belongs to; white (> 50 %) is the
    region, black is not. It enters weft as an *input image* (``--mask MASK``; a recipe names its
    PNG), is read with :meth:`from_image` and written with :meth:`to_image` / :meth:`save` (a 1-bit
    PNG). The studio paints one with :meth:`painted_line` and :meth:`painted_polygon` (Qt-free, so
    the brush's pixels are tested here). Immutable; equal when the bits are.
    """

    __slots__ = ("bits",)

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
        """A mask over ``bits``, a fresh bool array of this module's own making (no second copy: a
        brush dab on an 8192² mask copied it twice)."""
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
        from .image import load_image

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


def paint_line(bits: np.ndarray, p0, p1, radius: float, value: bool = True) -> tuple[int, int, int, int] | None:
    """Paint :meth:`Mask.painted_line`'s brush line into the bool array ``bits`` in place (only the
    line's box is read and written: a dab on a 4096² mask costs the dab, not a copy of the mask).
    Returns the box ``(x0, y0, x1, y1)`` (exclusive ends) whose pixels changed, None if none did."""
    h, w = bits.shape
    (x0, y0), (x1, y1) = (float(p0[0]), float(p0[1])), (float(p1[0]), float(p1[1]))
    r = max(0.0, float(radius)) + 0.5  # a pixel is hit when its centre is within radius (+ half a pixel)
    left, right = max(0, int(math.floor(min(x0, x1) - r))), min(w, int(math.ceil(max(x0, x1) + r)) + 1)
    top, bottom = max(0, int(math.floor(min(y0, y1) - r))), min(h, int(math.ceil(max(y0, y1) + r)) + 1)
    if left >= right or top >= bottom:
        return None  # the line misses the image
    yy, xx = np.mgrid[top:bottom, left:right].astype(np.float64)
    dx, dy = x1 - x0, y1 - y0
    length2 = dx * dx + dy * dy
    t = np.zeros_like(xx) if length2 == 0 else np.clip(((xx - x0) * dx + (yy - y0) * dy) / length2, 0.0, 1.0)
    hit = (xx - x0 - t * dx) ** 2 + (yy - y0 - t * dy) ** 2 < r * r
    part = bits[top:bottom, left:right]
    hit &= part != bool(value)  # the pixels this line changes
    rows, cols = np.flatnonzero(hit.any(axis=1)), np.flatnonzero(hit.any(axis=0))
    if not len(rows):
        return None
    part[hit] = bool(value)
    return left + int(cols[0]), top + int(rows[0]), left + int(cols[-1]) + 1, top + int(rows[-1]) + 1


class MaskStroke:
    """A mask being painted, dab by dab (the studio's brush and eraser): its bits change in place
    (:func:`paint_line`), so a dab costs the dab's pixels, where ``Mask.painted_line`` copies the
    whole mask (16 MB per dab at 4096²). Not a :class:`Mask` (which is immutable): read it with
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


# --- margins --------------------------------------------------------------------------------------


class Margins(NamedTuple):
    """Pixels added on each side of an image: ``left, top, right, bottom`` (an uncrop's new border).

    Text form ``L,T,R,B`` (``--extend``); JSON ``[l, t, r, b]``. Each is a whole number from 0 to
    :data:`MAX_SIDE`; whether the grown canvas is allowed is the pixel limit's business.
    """

    left: int
    top: int
    right: int
    bottom: int

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
