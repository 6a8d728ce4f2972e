"""Reading a PNG's chunks by hand: the recipe a weft PNG carries, and whether a PNG file is whole."""

from __future__ import annotations

import os
import struct
import zlib

from ..errors import ImageError, WeftError
from ..readfile import open_regular, shown
from .decoding import _os_error

_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
_RECIPE_KEY = b"weft-recipe"


def read_recipe(path: str | os.PathLike) -> str | None:
    """The ``weft-recipe`` text (tEXt, zTXt or iTXt chunk) of a PNG file, parsed by hand.

    Chunks with a bad CRC or that cannot be decoded are skipped; a compressed chunk is inflated only
    up to the size limit.

    Parameters
    ----------
    path : str or os.PathLike
        The file.

    Returns
    -------
    str or None
        The recipe's JSON text; None when the file is not a PNG or has no such chunk.

    Raises
    ------
    ImageError
        The file cannot be read, is not a regular file (a named pipe, a device: refused unread), or
        its recipe is larger than ``weft.core.jsonio.MAX_FILE_BYTES`` stored or inflated.
    """
    from ..jsonio import MAX_FILE_BYTES

    name = os.fsdecode(path)
    too_large = f"{shown(name)}: recipe is longer than the {MAX_FILE_BYTES // 2**20} MB limit"
    try:
        with open_regular(name, "PNG file", error=ImageError) as f:
            if f.read(8) != _PNG_SIGNATURE:
                return None
            while len(head := f.read(8)) == 8 and head[4:] != b"IEND":
                length, kind = struct.unpack(">I4s", head)
                if kind not in (b"tEXt", b"zTXt", b"iTXt"):
                    f.seek(length + 4, os.SEEK_CUR)
                    continue
                if length > MAX_FILE_BYTES + 100:
                    if f.read(len(_RECIPE_KEY) + 1) == _RECIPE_KEY + b"\0":
                        raise ImageError(too_large, path=name)
                    f.seek(length + 4 - len(_RECIPE_KEY) - 1, os.SEEK_CUR)
                    continue
                body, crc = f.read(length), f.read(4)
                key, _, rest = body.partition(b"\0")
                if key != _RECIPE_KEY or crc != struct.pack(">I", zlib.crc32(kind + body)):
                    continue
                try:
                    if kind == b"tEXt":
                        return rest.decode("latin-1")
                    if kind == b"zTXt":
                        return _inflate(rest[1:], MAX_FILE_BYTES, too_large, name).decode("latin-1")
                    text = rest[2:].split(b"\0", 2)[2]  # skip language tag and translated keyword
                    return (_inflate(text, MAX_FILE_BYTES, too_large, name) if rest[0] else text).decode("utf-8")
                except ImageError:
                    raise
                except (ValueError, IndexError, zlib.error):
                    continue
    except OSError as e:
        raise _os_error(name, e) from e
    return None


def png_is_whole(path: str | os.PathLike) -> bool:
    """Whether ``path`` is a whole PNG file.

    A regular file, the signature, every chunk with its stated length and a matching CRC, up to the
    IEND chunk. A file cut short (an interrupted copy) or with a flipped byte anywhere is not. Reads
    the file through once; never raises.

    Parameters
    ----------
    path : str or os.PathLike
        The file.

    Returns
    -------
    bool
    """
    try:
        with open_regular(path, "PNG file", error=ImageError) as f:
            if f.read(8) != _PNG_SIGNATURE:
                return False
            while len(head := f.read(8)) == 8:
                length, kind = struct.unpack(">I4s", head)
                crc = zlib.crc32(kind)
                left = length
                while left:
                    block = f.read(min(left, 1 << 20))
                    if not block:
                        return False
                    crc, left = zlib.crc32(block, crc), left - len(block)
                if f.read(4) != struct.pack(">I", crc):
                    return False
                if kind == b"IEND":
                    return True
    except (OSError, WeftError):
        return False
    return False


def _inflate(data: bytes, limit: int, too_large: str, name: str) -> bytes:
    """zlib-inflate ``data`` to at most ``limit`` bytes; ``ImageError(too_large)`` past that, so a
    small chunk that would inflate to gigabytes costs no more than ``limit`` of memory."""
    inflater = zlib.decompressobj()
    out = inflater.decompress(data, limit + 1)
    if len(out) > limit:
        raise ImageError(too_large, path=name)
    if not inflater.eof:
        raise zlib.error("incomplete compressed data")
    return out
