"""Saving images: encoding PNG, JPEG or TIFF (a PNG with its recipe) and writing the bytes atomically."""

from __future__ import annotations

import contextlib
import numbers
import os
import stat
import struct
import tempfile
import zlib
from pathlib import Path

import cv2
import numpy as np

from ..errors import ImageError, InvalidParameter
from ..readfile import shown
from .arrays import validate_image
from .decoding import _one_line
from .png_chunks import _RECIPE_KEY
from .temporaries import _writer_tag


def atomic_write_bytes(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` so that readers see the old file or the new one, never half of one.

    The bytes go to a temporary file in the same folder (``tempfile.mkstemp``), are flushed and
    fsync'ed, then ``os.replace`` puts them over ``path``. A replaced file keeps its permission bits;
    a new one gets ``0o666 & ~umask`` (not mkstemp's 0o600).

    Parameters
    ----------
    path : pathlib.Path
        The file to write.
    data : bytes
        Its new contents.

    Raises
    ------
    ImageError
        ``{path}: cannot write (reason)``; the temporary file is removed and an old ``path`` is intact.
    """
    path = Path(path)
    if not path.parent.is_dir():
        raise ImageError(f"{shown(path)}: cannot write (folder {path.parent} does not exist)", path=str(path))
    tmp = None
    try:
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=f".{_writer_tag()}.tmp")
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        try:
            mode = stat.S_IMODE(os.stat(path).st_mode)
        except OSError:
            umask = os.umask(0o022)  # read the umask (no portable getter)
            os.umask(umask)
            mode = 0o666 & ~umask
        os.chmod(tmp, mode)
        os.replace(tmp, path)
        tmp = None
    except OSError as e:
        raise ImageError(f"{shown(path)}: cannot write ({e.strerror or _one_line(e)})", path=str(path)) from e
    finally:
        if tmp is not None:
            with contextlib.suppress(OSError):
                os.unlink(tmp)


_SAVE_FORMATS = {".png": "PNG", ".jpg": "JPEG", ".jpeg": "JPEG", ".tif": "TIFF", ".tiff": "TIFF"}


def _png_chunk(kind: bytes, body: bytes) -> bytes:
    return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))


def save_image(
    path: str | os.PathLike, image: np.ndarray, *, recipe: str | None = None, bit_depth: int = 8, quality: int = 95
) -> None:
    """Save an image atomically (see :func:`atomic_write_bytes`) in the format of its extension.

    The bytes are :func:`encode_image`'s; this only adds the atomic write.

    Parameters
    ----------
    path : str or os.PathLike
        The output file; its extension picks the format.
    image : ndarray, float32 in [0, 1], (H, W), (H, W, 3) (or with alpha)
        The image.
    recipe : str, optional
        A recipe's JSON, stored in the PNG's ``weft-recipe`` chunk.
    bit_depth : {8, 16}, default 8
        Bits per sample (16: PNG and TIFF only).
    quality : int, default 95
        JPEG and WebP quality.

    Raises
    ------
    ImageError
        Unknown extension, 16-bit JPEG, invalid image, missing folder, write failure.
    """
    atomic_write_bytes(Path(path), encode_image(path, image, recipe=recipe, bit_depth=bit_depth, quality=quality))


def encode_image(
    path: str | os.PathLike, image: np.ndarray, *, recipe: str | None = None, bit_depth: int = 8, quality: int = 95
) -> bytes:
    """The bytes :func:`save_image` writes to ``path`` (format from its extension; nothing is written).

    Parameters
    ----------
    path : str or PathLike
        ``.png``, ``.jpg``/``.jpeg`` or ``.tif``/``.tiff`` (any case), in an existing folder.
    image : ndarray
        Anything :func:`validate_image` accepts; grey is saved grey. (H, W, 4) RGBA and (H, W, 2)
        grey+alpha keep their alpha (grey+alpha as RGBA: OpenCV writes no grey+alpha), except in a
        JPEG, which gets the colour alone.
    recipe : str, optional
        Text embedded in a PNG as a ``weft-recipe`` ``tEXt`` chunk (``iTXt``, UTF-8, when not
        Latin-1) right after IHDR, for :func:`read_recipe`. JPEG and TIFF files do not carry it.
    bit_depth : {8, 16}, default 8
        Samples are ``round(value * 255)`` or ``round(value * 65535)``; JPEG is 8-bit only.
    quality : int, default 95
        JPEG quality, 0..100 (unused for PNG and TIFF).

    Raises
    ------
    ImageError
        Unknown extension, 16-bit JPEG, invalid image, missing folder, write failure.
    """
    target = Path(path)
    ext, where = target.suffix.lower(), str(target)
    if ext not in _SAVE_FORMATS:
        raise ImageError(
            f"{target}: cannot save {ext or 'without an extension'} (allowed extensions: {', '.join(_SAVE_FORMATS)})",
            path=where,
        )
    if bit_depth not in (8, 16) or isinstance(bit_depth, bool):
        raise InvalidParameter(
            f"parameter 'bit_depth' = {bit_depth!r} must be 8 or 16", name="bit_depth", value=bit_depth
        )
    if _SAVE_FORMATS[ext] == "JPEG" and bit_depth == 16:
        raise ImageError(f"{target}: JPEG cannot store 16-bit samples (use bit_depth=8, or .png or .tif)", path=where)
    if isinstance(quality, bool) or not isinstance(quality, numbers.Integral) or not 0 <= quality <= 100:
        raise InvalidParameter(f"parameter 'quality' = {quality!r} is outside 0..100", name="quality", value=quality)
    if recipe is not None and (not isinstance(recipe, str) or "\0" in recipe):
        raise InvalidParameter("parameter 'recipe' must be text without NUL characters", name="recipe")
    top = 65535.0 if bit_depth == 16 else 255.0
    dtype = np.uint16 if bit_depth == 16 else np.uint8
    alpha = None
    shape = np.shape(image)
    if len(shape) == 3 and shape[2] in (2, 4):  # with alpha (load_image(..., alpha=True), weft fill)
        image = np.asarray(image)
        alpha = np.clip(np.rint(validate_image(np.ascontiguousarray(image[..., -1]), "alpha") * top), 0, top)
        image = np.ascontiguousarray(image[..., 0] if shape[2] == 2 else image[..., :3])
    arr = np.clip(np.rint(validate_image(image) * top), 0, top).astype(dtype)
    if arr.ndim == 3:
        arr = np.ascontiguousarray(arr[..., ::-1])  # RGB -> BGR for OpenCV
    if alpha is not None and _SAVE_FORMATS[ext] != "JPEG":  # JPEG has no alpha: the colour alone
        # OpenCV writes no grey+alpha: grey with alpha is written as RGBA with three equal channels
        colour = arr if arr.ndim == 3 else np.repeat(arr[..., None], 3, axis=2)
        arr = np.ascontiguousarray(np.concatenate([colour, alpha.astype(dtype)[..., None]], axis=2))
    try:
        params = [cv2.IMWRITE_JPEG_QUALITY, int(quality)] if _SAVE_FORMATS[ext] == "JPEG" else []
        ok, encoded = cv2.imencode(ext, arr, params)
        if not ok:
            raise cv2.error("the encoder failed")
    except cv2.error as e:
        raise ImageError(f"{target}: cannot encode {_SAVE_FORMATS[ext]} ({_one_line(e)})", path=where) from e
    data = encoded.tobytes()
    if _SAVE_FORMATS[ext] == "TIFF" and arr.ndim == 3 and arr.shape[2] == 4 and bit_depth == 16:
        # (not at 8 bits: OpenCV's 8-bit TIFF reader, libtiff's RGBA interface, then premultiplies
        # the colour by an unassociated alpha)
        data = _tiff_with_alpha(data)
    if recipe is not None and ext == ".png":
        try:
            chunk = _png_chunk(b"tEXt", _RECIPE_KEY + b"\0" + recipe.encode("latin-1"))
        except UnicodeEncodeError:  # iTXt: keyword, 0, no compression, method 0, no language/translation
            chunk = _png_chunk(b"iTXt", _RECIPE_KEY + b"\0\0\0\0\0" + recipe.encode("utf-8"))
        data = data[:33] + chunk + data[33:]  # OpenCV writes signature (8) + IHDR (25) first
    return data


def _tiff_with_alpha(data: bytes) -> bytes:
    """A 4-channel TIFF from OpenCV (one IFD, no ExtraSamples tag) with ExtraSamples = 2, unassociated
    alpha (TIFF 6.0, section 18), so that readers take the 4th channel as alpha, not a colour. The IFD
    is written again, with the tag in order, after the data; the header points at it."""
    order = {b"II": "<", b"MM": ">"}.get(data[:2])
    if order is None:
        return data
    (offset,) = struct.unpack(order + "I", data[4:8])
    (count,) = struct.unpack(order + "H", data[offset : offset + 2])
    entries = [data[offset + 2 + 12 * i : offset + 14 + 12 * i] for i in range(count)]
    tags = [struct.unpack(order + "H", e[:2])[0] for e in entries]
    if 338 in tags:
        return data
    extra = struct.pack(order + "HHI", 338, 3, 1) + struct.pack(order + "H", 2) + b"\0\0"
    entries.append(extra)
    entries.sort(key=lambda e: struct.unpack(order + "H", e[:2])[0])
    pad = b"\0" * (len(data) % 2)  # (an IFD starts on a word boundary)
    new_offset = len(data) + len(pad)
    ifd = struct.pack(order + "H", len(entries)) + b"".join(entries) + struct.pack(order + "I", 0)
    return data[:4] + struct.pack(order + "I", new_offset) + data[8:] + pad + ifd
