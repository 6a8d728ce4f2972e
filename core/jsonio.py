"""Strict JSON for weft's recipes, sessions and geometry files: parse, and read a file with limits."""

from __future__ import annotations

import json
import os
from typing import Any

from .errors import WeftError
from .readfile import read_regular, shown

MAX_FILE_BYTES = 10 * 1024 * 1024
"""The largest recipe or session weft reads (real ones are a few kB): a larger file is refused unread."""


def parse_json(text: str) -> Any:
    """Parse ``text`` as strict JSON, the only format of weft's recipes and sessions.

    Stricter than :func:`json.loads`: ``NaN`` and ``Infinity`` (not JSON) are refused, and every
    failure (bad syntax, nesting too deep for the parser, a number with thousands of digits) is a
    :class:`~weft.core.errors.WeftError` saying so in one line. Nothing is evaluated.

    Parameters
    ----------
    text : str
        The JSON text, at most :data:`MAX_FILE_BYTES` long.

    Returns
    -------
    object
        The parsed value (dict, list, str, int, float, bool or None).

    Raises
    ------
    WeftError
        Not valid JSON, or too long; one line saying where.
    """

    def no_constant(name: str):
        raise WeftError(f"not valid JSON: {name} is not a JSON number")

    if len(text) > MAX_FILE_BYTES:
        raise WeftError(f"longer than the {MAX_FILE_BYTES // 2**20} MB limit")
    try:
        return json.loads(text, parse_constant=no_constant)
    except json.JSONDecodeError as e:
        raise WeftError(f"not valid JSON: {e.msg} at line {e.lineno} column {e.colno}") from None
    except RecursionError:
        raise WeftError("not valid JSON: nested too deeply") from None
    except WeftError:
        raise
    except ValueError as e:  # e.g. an integer longer than Python converts
        raise WeftError(f"not valid JSON: {' '.join(str(e).split(';')[0].split())}") from None


def read_json_file(path: str | os.PathLike, what: str) -> Any:
    """Read and parse a weft JSON file.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    what : str
        What the file is, for messages: ``"recipe"``, ``"weft session"``.

    Returns
    -------
    object
        The parsed value (see :func:`parse_json`).

    Raises
    ------
    WeftError
        One line naming the file if it is missing, a folder, a named pipe or a device (refused unread,
        without blocking), larger than :data:`MAX_FILE_BYTES`, not UTF-8 text or not JSON.
    """
    name = os.fsdecode(path)
    try:
        raw = read_regular(name, MAX_FILE_BYTES, f"{what} file")
    except FileNotFoundError:
        raise WeftError(f"{shown(name)}: no such {what} file") from None
    except IsADirectoryError:
        raise WeftError(f"{shown(name)}: is a directory, not a {what} file") from None
    except (OSError, ValueError) as e:  # ValueError: a NUL in the name
        if isinstance(e, WeftError):
            raise
        raise WeftError(f"{shown(name)}: cannot read {what} ({getattr(e, 'strerror', None) or e})") from None
    try:
        text = raw.decode("utf-8-sig")  # a byte-order mark (Windows editors) is not an error
    except UnicodeDecodeError as e:
        raise WeftError(
            f"{shown(name)}: not a {what} file (not UTF-8 JSON text: byte {e.start} is 0x{raw[e.start]:02x})"
        ) from None
    try:
        return parse_json(text)
    except WeftError as e:
        raise WeftError(f"{shown(name)}: not a {what} file ({e})") from None
