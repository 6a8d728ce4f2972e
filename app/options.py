"""Command-line values shared by ``weft`` (app/cli.py) and ``weft batch`` (app/batch_cli.py)."""

from __future__ import annotations

import argparse

from weft.core.errors import WeftError


def parse_int(text: str | None, name: str, lo: int, hi: int) -> int | None:
    """``text`` as an integer in ``lo..hi`` (None stays None); ``WeftError`` naming the option."""
    if text is None:
        return None
    from weft.core.geometry import whole_number
    from weft.core.params import out_of_range

    try:
        value = whole_number(text.strip())
    except ValueError:
        raise WeftError(f"parameter '{name}' = {text!r} must be an integer") from None
    if not lo <= value <= hi:
        raise out_of_range(name, value, lo, hi)
    return value


def parse_bit_depth(args: argparse.Namespace) -> int:
    """``--bit-depth``: 8 or 16."""
    bit_depth = parse_int(args.bit_depth, "bit-depth", 8, 16)
    if bit_depth not in (8, 16):
        raise WeftError(f"parameter 'bit-depth' = {bit_depth} must be 8 or 16")
    return bit_depth
