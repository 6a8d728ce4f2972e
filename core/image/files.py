"""Loading images, and the pixel limit loading checks first (OpenCV's BGR never leaves this package).

Loading reads the header with Pillow (lazy, no pixels) to check the pixel limit, then decodes with
OpenCV from bytes (non-ASCII paths work) and falls back to Pillow for what OpenCV cannot decode
(:mod:`weft.core.image.decoding`). Every failure is an :class:`~weft.core.errors.ImageError` whose
message is one line starting with the path. Validating and resizing arrays are in
:mod:`weft.core.image.arrays`, saving in :mod:`weft.core.image.writing`, a PNG's chunks in
:mod:`weft.core.image.png_chunks`; their public names are importable from here too.
"""

from __future__ import annotations

import contextlib
import numbers
import os
from dataclasses import dataclass
from typing import NamedTuple

import cv2
import numpy as np
from PIL import UnidentifiedImageError

from ..errors import ImageError, InvalidParameter
from ..readfile import open_regular, shown
from .arrays import resize, validate_image
from .codec_output import _codec_output, _scan_damage
from .colour import luminance
from .decoding import (
    _ALPHA_MODES,
    _GREY_MODES,
    _SIGNATURES,
    _damaged,
    _decode_alpha,
    _decode_pillow,
    _exif_orientation,
    _one_line,
    _os_error,
    _pil_open,
    _tiff_size,
)
from .png_chunks import png_is_whole, read_recipe
from .writing import atomic_write_bytes, encode_image, save_image

__all__ = [
    "DEFAULT_MAX_PIXELS",
    "ImageInfo",
    "Loaded",
    "atomic_write_bytes",
    "encode_image",
    "file_bit_depth",
    "get_max_pixels",
    "load_image",
    "png_is_whole",
    "read_recipe",
    "resize",
    "save_image",
    "set_max_pixels",
    "validate_image",
    # the decoders' private names that other modules of weft.core read
    "_GREY_MODES",
    "_SIGNATURES",
    "_os_error",
    "_pil_open",
]

DEFAULT_MAX_PIXELS = 50_000_000
_max_pixels_override: int | None = None


def _check_limit(n: object) -> int:
    if isinstance(n, bool) or not isinstance(n, numbers.Integral) or n < 1:
        raise InvalidParameter(f"parameter 'max_pixels' = {n!r} must be a positive integer", name="max_pixels", value=n)
    return int(n)


def get_max_pixels() -> int:
    """The largest width x height :func:`load_image` accepts.

    :func:`set_max_pixels` wins if called; else ``WEFT_MAX_PIXELS`` when it holds a positive integer
    (``200_000_000`` works, invalid values are ignored); else :data:`DEFAULT_MAX_PIXELS` (50 Mpx,
    600 MB as float32 RGB).
    """
    if _max_pixels_override is not None:
        return _max_pixels_override
    with contextlib.suppress(ValueError):
        if (value := int(os.environ.get("WEFT_MAX_PIXELS", "").strip())) >= 1:
            return value
    return DEFAULT_MAX_PIXELS


def set_max_pixels(n: int | None) -> None:
    """Set the process-wide pixel limit of :func:`load_image` and the outputs.

    Parameters
    ----------
    n : int or None
        The limit, a positive integer; ``None`` restores ``WEFT_MAX_PIXELS`` or the default.

    Raises
    ------
    InvalidParameter
        ``n`` is not a positive integer.
    """
    global _max_pixels_override
    _max_pixels_override = None if n is None else _check_limit(n)


@dataclass(frozen=True)
class ImageInfo:
    """What :func:`load_image` found and did.

    ``format`` is Pillow's name ("PNG", "JPEG", "TIFF", "BMP", "WEBP", "GIF"); width, height and
    ``channels`` (1 or 3) describe the returned array; ``bit_depth`` is 8 or 16 (sources below 8 bits
    count as 8); ``orientation`` is the EXIF orientation applied (1 if none); ``notes`` lists conversions.
    """

    path: str
    format: str
    width: int
    height: int
    channels: int
    bit_depth: int
    had_alpha: bool
    orientation: int
    notes: tuple[str, ...]


class Loaded(NamedTuple):
    """The result of :func:`load_image`: the float32 image and its :class:`ImageInfo`."""

    image: np.ndarray
    info: ImageInfo


class _Header(NamedTuple):
    """What :func:`_read_header` found before any pixel is decoded, and the file's bytes."""

    fmt: str
    width: int
    height: int
    src_mode: str
    had_alpha: bool
    orientation: int
    animated: bool
    data: np.ndarray


def load_image(
    path: str | os.PathLike, *, max_pixels: int | None = None, mode: str | None = None, alpha: bool = False
) -> Loaded:
    """Load PNG, JPEG, TIFF, BMP, WebP or GIF (8 or 16 bits per sample) as float32 in [0, 1].

    Parameters
    ----------
    path : str or PathLike
        The file; non-ASCII paths work.
    max_pixels : int, optional
        Refuse more than this many pixels (default :func:`get_max_pixels`), checked from the header
        before any pixel is decoded, so decompression bombs fail in milliseconds.
    mode : {None, "rgb", "grey"}, default None
        None keeps grey (H, W) and colour (H, W, 3); "rgb" always gives (H, W, 3); "grey" gives the
        Rec. 601 :func:`luminance`.
    alpha : bool, default False
        Keep an alpha channel (``weft fill``: a transparent region is a hole): an image that has one
        comes back as (H, W, 2) grey+alpha or (H, W, 4) RGBA (a palette's transparency as RGBA), in
        the same bit depth; ``mode`` then applies to the colour channels. An image without alpha is
        returned as without this flag.

    Returns
    -------
    Loaded
        ``(image, info)``: C-contiguous float32 RGB (never BGR). Alpha is dropped without compositing;
        grey+alpha stays grey; palettes always become RGB (grey ones too); CMYK becomes RGB; the EXIF
        orientation is applied; an animation gives its first frame. ``info.notes`` lists each of these.

    Raises
    ------
    ImageError
        Missing, a directory, unreadable, empty, not an image, too large, truncated or corrupt.
    """
    name = os.fsdecode(path)
    if mode not in (None, "rgb", "grey"):
        raise InvalidParameter(
            f"parameter 'mode' = {mode!r} is not one of None, 'rgb', 'grey'", name="mode", value=mode
        )
    limit = get_max_pixels() if max_pixels is None else _check_limit(max_pixels)
    head = _read_header(name, limit)
    try:
        with_alpha, arr = _decode(name, head, alpha)
        if with_alpha:
            return _loaded_alpha(arr, name, head.fmt, head.orientation, head.src_mode, head.animated, mode)
        image = _as_float(name, head, arr)
    except MemoryError:
        raise ImageError(
            f"{shown(name)}: not enough memory to decode {head.width}x{head.height} pixels", path=name
        ) from None
    except ImageError:
        raise
    except Exception as e:  # noqa: BLE001 - never let a raw cv2/numpy error escape
        raise ImageError(f"{shown(name)}: cannot decode {head.fmt} data ({_one_line(e)})", path=name) from e
    return _loaded(image, arr, name, head, mode)


def _read_header(name: str, limit: int) -> _Header:
    """Open ``name``, read its header (lazily, with Pillow), refuse more than ``limit`` pixels, and read
    the file's bytes; every failure an :class:`ImageError` naming the file."""
    try:
        with open_regular(name, "image file", error=ImageError) as f:
            if os.fstat(f.fileno()).st_size == 0:
                raise ImageError(f"{shown(name)}: empty file", path=name)
            try:
                im, animated = _pil_open(open(os.dup(f.fileno()), "rb"))  # Pillow closes what it is given
            except UnidentifiedImageError:
                f.seek(0)
                size = _tiff_size(f)  # a TIFF Pillow has no mode for (float RGB): OpenCV decodes it
                if size is None:
                    raise
                im, animated = None, False
                fmt, (width, height), src_mode, had_alpha, orientation = "TIFF", size, "RGB", False, 1
            if im is not None:
                with im:
                    fmt, (width, height), src_mode = im.format or "unknown", im.size, im.mode
                    had_alpha = src_mode in _ALPHA_MODES or "transparency" in im.info
                    orientation = _exif_orientation(im)
            if width * height > limit:
                raise ImageError(
                    f"{shown(name)}: {width}x{height} = {width * height / 1e6:.1f} megapixels exceeds the "
                    f"limit of {limit / 1e6:g} megapixels (set WEFT_MAX_PIXELS or max_pixels to raise it)",
                    path=name,
                )
            f.seek(0)
            data = np.fromfile(f, dtype=np.uint8)
    except ImageError:
        raise
    except Exception as e:  # noqa: BLE001 - Pillow raises many kinds on corrupt headers
        if isinstance(e, OSError) and e.errno is not None:  # real I/O errors; Pillow's own OSErrors have none
            raise _os_error(name, e) from e
        if isinstance(e, UnidentifiedImageError):
            problem = _damaged(name, "cannot read the header") or "not an image file (cannot identify format)"
        else:
            problem = _damaged(name, _one_line(e)) or f"corrupt image header ({_one_line(e)})"
        raise ImageError(f"{shown(name)}: {problem}", path=name) from e
    return _Header(fmt, width, height, src_mode, had_alpha, orientation, animated, data)


def _decode(name: str, head: _Header, alpha: bool) -> tuple[bool, np.ndarray]:
    """The decoded samples, uint8 or uint16, and whether they keep alpha (``alpha`` asked and the
    file has it: grey+alpha or RGBA); else RGB or grey (OpenCV, or Pillow where OpenCV cannot)."""
    said: list[str] = []
    kept = arr = None
    data, fmt = head.data, head.fmt
    with _codec_output(said):  # the codecs' own lines (libpng, libjpeg, libtiff) are ours to word
        if alpha and head.had_alpha:
            grey = head.src_mode in _GREY_MODES or (fmt == "PNG" and len(data) > 25 and data[25] == 4)
            kept = _decode_alpha(data, grey, head.orientation)
        if kept is None:
            with contextlib.suppress(cv2.error):
                arr = cv2.imdecode(data, cv2.IMREAD_ANYDEPTH | cv2.IMREAD_ANYCOLOR)  # applies EXIF orientation
            if arr is None:  # OpenCV could not: truncated, corrupt, or a variant only Pillow reads
                try:
                    arr = _decode_pillow(data)
                except Exception as e:  # noqa: BLE001
                    raise ImageError(
                        f"{shown(name)}: truncated or corrupt {fmt} data ({_one_line(e)})", path=name
                    ) from e
            elif arr.ndim == 3:
                arr = arr[..., 2::-1]  # BGR(A) -> RGB
    damage = _scan_damage(said) if fmt == "JPEG" else None
    if damage is not None:
        raise ImageError(f"{shown(name)}: truncated or corrupt JPEG data ({damage})", path=name)
    if kept is not None:
        return True, kept
    if arr is None:  # the Pillow fallback either decodes or raises
        raise ValueError("no decoder output")
    return False, arr


def _as_float(name: str, head: _Header, arr: np.ndarray) -> np.ndarray:
    """The decoded samples as float32 in [0, 1], grey where the file is grey."""
    data, fmt, src_mode = head.data, head.fmt, head.src_mode
    if not (arr.ndim == 2 or (arr.ndim == 3 and arr.shape[2] == 3)):
        raise ValueError(f"unexpected decoder output of shape {arr.shape}")
    if arr.dtype not in (np.uint8, np.uint16):
        raise ImageError(
            f"{shown(name)}: unsupported sample type {arr.dtype} (only 8- and 16-bit images are "
            "supported: save it with 8 or 16 bits per sample)",
            path=name,
        )
    # OpenCV expands grey+alpha to three equal channels; Pillow calls 16-bit grey+alpha PNG "RGBA",
    # so for PNG the IHDR colour type (0 grey, 4 grey+alpha) decides.
    if arr.ndim == 3 and (src_mode in _GREY_MODES or (fmt == "PNG" and len(data) > 25 and data[25] in (0, 4))):
        arr = arr[..., 0]
    return arr.astype(np.float32, order="C") / np.float32(np.iinfo(arr.dtype).max)


def _loaded(image: np.ndarray, arr: np.ndarray, name: str, head: _Header, mode: str | None) -> Loaded:
    """The image in the ``mode`` asked for, with its :class:`ImageInfo` (what was converted)."""
    orientation, had_alpha, src_mode = head.orientation, head.had_alpha, head.src_mode
    notes = [
        text
        for cond, text in [
            (orientation != 1, f"EXIF orientation {orientation} applied"),
            (had_alpha, "alpha channel dropped"),
            (src_mode in ("P", "PA"), "palette expanded to RGB"),
            (src_mode == "CMYK", "CMYK converted to RGB"),
            (head.animated, "first frame of an animation used"),
        ]
        if cond
    ]
    if mode == "rgb" and image.ndim == 2:
        image = np.repeat(image[..., None], 3, axis=2)
        notes.append("grey expanded to RGB")
    elif mode == "grey" and image.ndim == 3:
        image = np.ascontiguousarray(luminance(image))
        notes.append("converted to grey (Rec. 601 luminance)")
    info = ImageInfo(
        path=name,
        format=head.fmt,
        width=image.shape[1],
        height=image.shape[0],
        channels=1 if image.ndim == 2 else 3,
        bit_depth=8 * arr.itemsize,
        had_alpha=had_alpha,
        orientation=orientation,
        notes=tuple(notes),
    )
    return Loaded(image, info)


def file_bit_depth(path: str | os.PathLike) -> int | None:
    """The bits per sample :func:`load_image` gives for an image file, from its header alone.

    What an output keeps when the method keeps its input's depth (``Method.depth_from``) and no bit
    depth was asked for.

    Parameters
    ----------
    path : str or os.PathLike
        The image file.

    Returns
    -------
    int or None
        16 for a 16-bit PNG or TIFF, 8 for anything else it reads; None when the header cannot be read
        (loading the file says why).
    """
    name = os.fsdecode(path)
    try:
        with open_regular(name, error=ImageError) as f:
            head = f.read(26)
            if head[:8] == b"\x89PNG\r\n\x1a\n" and head[12:16] == b"IHDR":
                return 16 if head[24] == 16 else 8
            f.seek(0)
            im, _ = _pil_open(open(os.dup(f.fileno()), "rb"))
        with im:
            if im.mode.startswith("I;16"):
                return 16
            bits = getattr(im, "tag_v2", {}).get(258) if im.format == "TIFF" else None
            bits = bits if isinstance(bits, tuple) else (bits,)
            return 16 if any(b == 16 for b in bits) else 8
    except Exception:  # noqa: BLE001 - an unreadable file fails where it is loaded, with its own message
        return None


def _loaded_alpha(
    arr: np.ndarray, name: str, fmt: str, orientation: int, src_mode: str, animated: bool, mode: str | None
) -> Loaded:
    image = arr.astype(np.float32, order="C") / np.float32(65535 if arr.dtype == np.uint16 else 255)
    notes = [
        text
        for cond, text in [
            (orientation != 1, f"EXIF orientation {orientation} applied"),
            (True, "alpha channel kept"),
            (src_mode in ("P", "PA"), "palette expanded to RGB"),
            (animated, "first frame of an animation used"),
        ]
        if cond
    ]
    if mode == "rgb" and image.shape[2] == 2:
        image = np.ascontiguousarray(image[..., [0, 0, 0, 1]])
        notes.append("grey expanded to RGB")
    elif mode == "grey" and image.shape[2] == 4:
        image = np.ascontiguousarray(np.stack([luminance(image[..., :3]), image[..., 3]], axis=2))
        notes.append("converted to grey (Rec. 601 luminance)")
    info = ImageInfo(
        path=name,
        format=fmt,
        width=image.shape[1],
        height=image.shape[0],
        channels=image.shape[2],
        bit_depth=8 * arr.itemsize,
        had_alpha=True,
        orientation=orientation,
        notes=tuple(notes),
    )
    return Loaded(image, info)
