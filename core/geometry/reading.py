"""Reading geometry at the edges: numbers, sizes and lines checked with a message naming the
bad entry, and the command-line rule for JSON (text starting with ``{`` is JSON, anything else a
JSON file's name).
"""

from __future__ import annotations

import json
import math
import numbers
import os
import re
from collections.abc import Mapping
from typing import Any

import numpy as np

from ..errors import GeometryError
from ..jsonio import MAX_FILE_BYTES
from ..readfile import read_regular, shown

MAX_SIDE = 16384


def _num(v: Any) -> bool:
    return isinstance(v, numbers.Real) and not isinstance(v, bool)


def _short(value: Any) -> str:
    text = json.dumps(value) if not isinstance(value, np.ndarray) else str(value.tolist())
    return text if len(text) <= 60 else text[:57] + "..."


def as_lines(value: Any, key: str) -> np.ndarray:
    """Feature lines as a float64 (N, 4) array.

    Parameters
    ----------
    value : object
        A sequence of ``[x1, y1, x2, y2]`` of finite numbers.
    key : str
        The JSON key, for the message.

    Returns
    -------
    ndarray, float64 (N, 4)

    Raises
    ------
    GeometryError
        Naming the first bad entry.
    """
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
    """``text`` as a whole number written in ASCII digits, with an optional sign.

    ``int`` alone would also take ``1_000`` and other scripts' digits.

    Parameters
    ----------
    text : str
        The text.

    Returns
    -------
    int

    Raises
    ------
    ValueError
        Anything else.
    """
    if not _WHOLE.fullmatch(text):
        raise ValueError(f"not a whole number: {text!r}")
    return int(text)


def as_size(value: Any, key: str) -> tuple[int, int]:
    """``[w, h]`` of whole pixels (``512.0`` is accepted as 512, ``512.5`` is not).

    Parameters
    ----------
    value : object
        A two-item list or tuple.
    key : str
        The JSON key, for the message.

    Returns
    -------
    (int, int)

    Raises
    ------
    GeometryError
        Not two whole numbers, or a side outside 2..MAX_SIDE.
    """
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

    Parameters
    ----------
    text_or_path : str or os.PathLike
        The option's value.
    what : str
        What the JSON is, for messages (``"feature lines"``, ``"view"``).

    Returns
    -------
    data : object
        The parsed JSON.
    source : str
        The file's name, or "inline JSON", for messages.

    Raises
    ------
    GeometryError
        A missing or unreadable file, a folder, or invalid JSON.
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
