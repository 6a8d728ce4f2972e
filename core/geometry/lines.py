"""Feature lines: pairs of lines in a photo and in its frontal frame, finished or being drawn."""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import GeometryError
from .reading import _from_json_or_path, _short, as_lines, as_size, read_json_or_file


class FeatureLines:
    """Validated feature lines: ``image_lines`` and ``frontal_lines`` are float64 (N, 4) arrays.

    ``frontal_size`` is ``(width, height)`` of the frontal frame. Line *i* of the photo goes with line
    *i* of the frontal frame (DESIGN.md: ``{"image_lines": [...], "frontal_lines": [...],
    "frontal_size": [w, h]}``). Equal when their JSON is equal.
    """

    __slots__ = ("image_lines", "frontal_lines", "frontal_size")
    METAVAR = "LINES"
    image_lines: np.ndarray
    frontal_lines: np.ndarray
    frontal_size: tuple[int, int]

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
