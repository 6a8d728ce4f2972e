"""Strict JSON for weft's recipes, sessions and geometry files: parse, and read a file with limits."""

from __future__ import annotations

import json
import os
from typing import Any

from .errors import WeftError

MAX_FILE_BYTES = 10 * 1024 * 1024
"""The largest recipe or session weft reads (real ones are a few kB): a larger file is refused unread."""


def parse_json(text: str) -> Any:
    """Parse ``text`` as strict JSON, the only format of weft's recipes and sessions.

    Stricter than :func:`json.loads`: ``NaN`` and ``Infinity`` (not JSON) are refused, and every
    failure (bad syntax, nesting too deep for the parser, a number with thousands of digits) is a
    :class:`~weft.core.errors.WeftError` saying so in one line. Nothing is evaluated.
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
    """Read a weft JSON file (``what``: "recipe", "weft session"); one-line ``WeftError`` naming the
    file if it is missing, a folder, larger than :data:`MAX_FILE_BYTES`, not UTF-8 text or not JSON."""
    name = os.fsdecode(path)
    limit = f"the limit is {MAX_FILE_BYTES // 2**20} MB"
    try:
        with open(name, "rb") as f:
            size = os.fstat(f.fileno()).st_size
            raw = f.read(MAX_FILE_BYTES + 1) if size <= MAX_FILE_BYTES else b""
    except FileNotFoundError:
        raise WeftError(f"{name}: no such {what} file") from None
    except IsADirectoryError:
        raise WeftError(f"{name}: is a directory, not a {what} file") from None
    except (OSError, ValueError) as e:  # ValueError: a NUL in the name
        raise WeftError(f"{name}: cannot read {what} ({getattr(e, 'strerror', None) or e})") from None
    if size > MAX_FILE_BYTES:
        raise WeftError(f"{name}: {size / 2**20:.1f} MB is too large for a {what} file ({limit}); not read")
    if len(raw) > MAX_FILE_BYTES:  # grew since, or a device without a size
        raise WeftError(f"{name}: too large for a {what} file ({limit}); not read")
    try:
        text = raw.decode("utf-8-sig")  # a byte-order mark (Windows editors) is not an error
    except UnicodeDecodeError as e:
        raise WeftError(f"{name}: not a {what} file (not UTF-8 JSON text: byte {e.start} is 0x{raw[e.start]:02x})") from None
    try:
        return parse_json(text)
    except WeftError as e:
        raise WeftError(f"{name}: not a {what} file ({e})") from None
