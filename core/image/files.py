"""Loading, saving, validating and resizing images (OpenCV's BGR never leaves this module).

Loading reads the header with Pillow (lazy, no pixels) to check the pixel limit, then decodes with
OpenCV from bytes (non-ASCII paths work) and falls back to Pillow for what OpenCV cannot decode.
Every failure is an :class:`~weft.core.errors.ImageError` whose message is one line starting with the path.
"""

from __future__ import annotations

import contextlib
import errno
import io
import numbers
import os
import stat
import struct
import tempfile
import threading
import warnings
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

import cv2
import numpy as np
from PIL import Image, UnidentifiedImageError

from ..errors import ImageError, InvalidParameter, WeftError
from ..readfile import open_regular, shown
from .codec_output import _codec_output, _scan_damage
from .colour import _check_float_image, luminance
from .temporaries import _writer_tag

# A corrupt file is reported once, by us, as one line: OpenCV's own warnings would add a second.
cv2.utils.logging.setLogLevel(cv2.utils.logging.LOG_LEVEL_SILENT)

# --------------------------------------------------------------------------------------------------
# Validation and resizing


def validate_image(image: np.ndarray, what: str = "image") -> np.ndarray:
    """Check an image and return it as C-contiguous float32 in [0, 1] (the input itself if it is one).

    Parameters
    ----------
    image : ndarray
        (H, W) or (H, W, 3); float in [0, 1] without NaN/inf, or uint8 (/255) or uint16 (/65535).
    what : str, default "image"
        Name used in error messages ("texture", "target", ...).

    Raises
    ------
    ImageError
        Wrong shape, empty, unsupported dtype, non-finite or out-of-range values.
    """
    image = _check_float_image(image, what)
    if image.dtype in (np.uint8, np.uint16):
        return np.ascontiguousarray(image, dtype=np.float32) / np.float32(np.iinfo(image.dtype).max)
    if not np.issubdtype(image.dtype, np.floating):
        raise ImageError(f"{what} has unsupported dtype {image.dtype} (use float in [0, 1], uint8 or uint16)")
    image = np.ascontiguousarray(image, dtype=np.float32)
    if not np.isfinite(image).all():
        raise ImageError(f"{what} contains NaN or infinite values")
    low, high = float(image.min()), float(image.max())
    if low < 0.0 or high > 1.0:
        raise ImageError(f"{what} has values outside [0, 1] (min {low:.4g}, max {high:.4g})")
    return image


_INTERPOLATIONS = {
    "cubic": cv2.INTER_CUBIC,
    "linear": cv2.INTER_LINEAR,
    "area": cv2.INTER_AREA,
    "nearest": cv2.INTER_NEAREST_EXACT,
}


def resize(image: np.ndarray, size: tuple[int, int], interpolation: str = "cubic") -> np.ndarray:
    """Resize to ``size = (width, height)`` (each >= 1); float32, same channel count as the input.

    Parameters
    ----------
    image : ndarray
        Anything :func:`validate_image` accepts.
    size : (int, int)
        Output width and height.
    interpolation : {"cubic", "linear", "area", "nearest"}, default "cubic"
        OpenCV bicubic (result clipped to [0, 1]), bilinear, pixel-area (best for shrinking) or
        nearest neighbour (``INTER_NEAREST_EXACT``: pixel centres, as Pillow and scikit-image).
    """
    image = validate_image(image)
    if not (
        isinstance(size, (tuple, list))
        and len(size) == 2
        and all(isinstance(s, numbers.Integral) and not isinstance(s, bool) and s >= 1 for s in size)
    ):
        raise InvalidParameter(
            f"parameter 'size' = {size!r} must be (width, height), both >= 1", name="size", value=size
        )
    if interpolation not in _INTERPOLATIONS:
        raise InvalidParameter(
            f"parameter 'interpolation' = {interpolation!r} is not one of {', '.join(_INTERPOLATIONS)}",
            name="interpolation",
            value=interpolation,
        )
    out = cv2.resize(image, (int(size[0]), int(size[1])), interpolation=_INTERPOLATIONS[interpolation])
    return np.clip(out, 0.0, 1.0, out=out) if interpolation == "cubic" else out


# --------------------------------------------------------------------------------------------------
# Pixel limit

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


# --------------------------------------------------------------------------------------------------
# Loading


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


_PIL_LOCK = threading.Lock()
_GREY_MODES = {"1", "L", "LA", "La", "I", "I;16", "I;16L", "I;16B", "I;16N", "F"}
_ALPHA_MODES = {"RGBA", "RGBa", "LA", "La", "PA"}
_SIGNATURES = {
    b"\x89PNG": "PNG",
    b"\xff\xd8\xff": "JPEG",
    b"II*\0": "TIFF",
    b"MM\0*": "TIFF",
    b"BM": "BMP",
    b"GIF8": "GIF",
    b"RIFF": "WEBP",
}
# EXIF orientation -> transform showing the stored pixels upright, as Pillow's exif_transpose. OpenCV
# applies it itself (IMREAD_ANYCOLOR without IMREAD_IGNORE_ORIENTATION); this is for the Pillow fallback.
_ORIENT = {
    1: lambda a: a,
    2: lambda a: a[:, ::-1],
    3: lambda a: a[::-1, ::-1],
    4: lambda a: a[::-1],
    5: lambda a: a.swapaxes(0, 1),
    6: lambda a: a.swapaxes(0, 1)[:, ::-1],
    7: lambda a: a[::-1, ::-1].swapaxes(0, 1),
    8: lambda a: a.swapaxes(0, 1)[::-1],
}


def _one_line(err: BaseException) -> str:
    return " ".join(str(err).split()) or type(err).__name__


def _os_error(name: str, err: OSError) -> ImageError:
    problem = {
        FileNotFoundError: "no such file",
        IsADirectoryError: "is a directory",
        PermissionError: "permission denied",
    }.get(type(err), f"cannot read ({err.strerror or _one_line(err)})")
    if getattr(err, "errno", None) == errno.ELOOP:
        problem = "a symbolic link loop"
    return ImageError(f"{shown(name)}: {problem}", path=name)


def _pil_open(source) -> tuple[Image.Image, bool]:
    """Lazy ``Image.open`` (header only) and whether it is animated, with Pillow's own bomb check and
    warnings off (our check, with a clearer message, follows). The lock keeps the switch local."""
    with _PIL_LOCK, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        saved, Image.MAX_IMAGE_PIXELS = Image.MAX_IMAGE_PIXELS, None
        try:
            im = Image.open(source)
            try:
                return im, bool(getattr(im, "is_animated", False))  # GIF seeks a frame here
            except BaseException:
                im.close()
                raise
        finally:
            Image.MAX_IMAGE_PIXELS = saved


def _exif_orientation(im: Image.Image) -> int:
    """EXIF orientation 1..8 (1 if absent/invalid) from the EXIF block or TIFF tags, not XMP: as OpenCV."""
    with contextlib.suppress(Exception):
        if "exif" in im.info:
            exif = Image.Exif()
            exif.load(im.info["exif"])
            value = int(exif.get(0x0112, 1))
        else:
            value = int(getattr(im, "tag_v2", {}).get(0x0112, 1))
        return value if value in _ORIENT else 1
    return 1


def _decode_pillow(data: np.ndarray) -> np.ndarray:
    """Decode with Pillow: upright grey or RGB, uint8/uint16 (alpha dropped, palette expanded)."""
    with _pil_open(io.BytesIO(data.tobytes()))[0] as im:
        im.load()  # Pillow's TIFF loader applies the orientation itself and drops the tag
        if im.mode == "F" or im.mode.startswith("I"):
            arr = np.asarray(im)
            if arr.dtype.kind == "f" or arr.min() < 0 or arr.max() > 65535:
                raise ValueError(f"unsupported {arr.dtype} samples")
            arr = arr.astype(np.uint16)
        else:
            arr = np.asarray(im.convert("L" if im.mode in _GREY_MODES else "RGB"))
        return _ORIENT[_exif_orientation(im)](arr)


def _damaged(name: str, reason: str) -> str | None:
    """A header Pillow could not read: name the format when the file starts with a known signature."""
    with contextlib.suppress(OSError, ImageError), open_regular(name, error=ImageError) as f:
        head = f.read(4)
        for magic, fmt in _SIGNATURES.items():
            if head.startswith(magic):
                return f"truncated or corrupt {fmt} data ({reason})"
    return None


def _tiff_size(f) -> tuple[int, int] | None:
    """(width, height) from a classic TIFF's first directory (tags 256 and 257), or None."""
    head = f.read(8)
    if len(head) < 8 or head[:4] not in (b"II*\0", b"MM\0*"):
        return None
    end = "<" if head[:2] == b"II" else ">"
    f.seek(struct.unpack(end + "I", head[4:])[0])
    raw = f.read(2)
    if len(raw) < 2:
        return None
    count = struct.unpack(end + "H", raw)[0]
    entries = f.read(12 * count)
    found = {}
    for i in range(len(entries) // 12):
        tag, kind, n = struct.unpack(end + "HHI", entries[12 * i : 12 * i + 8])
        if tag in (256, 257) and n == 1 and kind in (3, 4):
            value = entries[12 * i + 8 : 12 * i + 12]
            found[tag] = struct.unpack(end + ("H" if kind == 3 else "I"), value[: 2 if kind == 3 else 4])[0]
    return (found[256], found[257]) if 256 in found and 257 in found and min(found.values()) > 0 else None


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

    said: list[str] = []
    try:
        kept = arr = None
        with _codec_output(said):  # the codecs' own lines (libpng, libjpeg, libtiff) are ours to word
            if alpha and had_alpha:
                grey = src_mode in _GREY_MODES or (fmt == "PNG" and len(data) > 25 and data[25] == 4)
                kept = _decode_alpha(data, grey, orientation)
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
            return _loaded_alpha(kept, name, fmt, orientation, src_mode, animated, mode)
        assert arr is not None  # decoded by OpenCV or Pillow, or raised
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
        image = arr.astype(np.float32, order="C") / np.float32(65535 if arr.dtype == np.uint16 else 255)
    except MemoryError:
        raise ImageError(f"{shown(name)}: not enough memory to decode {width}x{height} pixels", path=name) from None
    except ImageError:
        raise
    except Exception as e:  # noqa: BLE001 - never let a raw cv2/numpy error escape
        raise ImageError(f"{shown(name)}: cannot decode {fmt} data ({_one_line(e)})", path=name) from e

    notes = [
        text
        for cond, text in [
            (orientation != 1, f"EXIF orientation {orientation} applied"),
            (had_alpha, "alpha channel dropped"),
            (src_mode in ("P", "PA"), "palette expanded to RGB"),
            (src_mode == "CMYK", "CMYK converted to RGB"),
            (animated, "first frame of an animation used"),
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
        format=fmt,
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


def _decode_alpha(data: np.ndarray, grey: bool, orientation: int) -> np.ndarray | None:
    """Decode keeping alpha: uint8/uint16 (H, W, 2) grey+alpha or (H, W, 4) RGBA, upright; None when
    the file turns out to have no alpha channel after all (a palette without transparency)."""
    arr = None
    with contextlib.suppress(cv2.error):
        arr = cv2.imdecode(data, cv2.IMREAD_UNCHANGED)  # unlike IMREAD_ANYCOLOR, no EXIF orientation: ours
    if arr is not None and arr.ndim == 3 and arr.shape[2] == 4 and arr.dtype in (np.uint8, np.uint16):
        rgba = arr[..., [2, 1, 0, 3]]
        out = np.stack([rgba[..., 0], rgba[..., 3]], axis=2) if grey else rgba
        return np.ascontiguousarray(_ORIENT[orientation](out))
    if arr is not None and arr.dtype == np.uint16 and (arr.ndim == 2 or arr.shape[2] == 3):
        keyed = _keyed_alpha(data, arr)
        if keyed is not None:
            return np.ascontiguousarray(_ORIENT[orientation](keyed))
    with _pil_open(io.BytesIO(data.tobytes()))[0] as im:  # palettes with transparency, odd layouts
        im.load()
        if not (im.mode in _ALPHA_MODES or "transparency" in im.info):
            return None
        out = np.asarray(im.convert("LA" if grey else "RGBA"))
        return np.ascontiguousarray(_ORIENT[_exif_orientation(im)](out))


def _keyed_alpha(data: np.ndarray, arr: np.ndarray) -> np.ndarray | None:
    """A 16-bit grey or RGB PNG whose transparency is a tRNS colour key (not an alpha channel), as
    decoded by OpenCV without alpha (``arr``: (H, W) grey or (H, W, 3) BGR): the pixels of the key's
    colour transparent, (H, W, 2) grey+alpha or (H, W, 4) RGBA uint16; None without such a key.
    (Pillow reads these as 16-bit grey "I;16" or 8-bit "RGB" and loses the key, or the depth.)"""
    with _pil_open(io.BytesIO(data.tobytes()))[0] as im:  # the header and the chunks before the pixels
        key = im.info.get("transparency") if im.format == "PNG" else None
    if arr.ndim == 2 and isinstance(key, int):
        return np.stack([arr, np.where(arr == key, 0, 65535).astype(np.uint16)], axis=2)
    if arr.ndim == 3 and isinstance(key, tuple) and len(key) == 3:
        rgb = arr[..., ::-1]
        hit = (rgb[..., 0] == key[0]) & (rgb[..., 1] == key[1]) & (rgb[..., 2] == key[2])
        return np.concatenate([rgb, np.where(hit, 0, 65535).astype(np.uint16)[..., None]], axis=2)
    return None


def _loaded_alpha(
    arr: np.ndarray, name: str, fmt: str, orientation: int, src_mode: str, animated: bool, mode: str | None
) -> Loaded:
    image = arr.astype(np.float32, order="C") / np.float32(np.iinfo(arr.dtype).max)
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


# --------------------------------------------------------------------------------------------------
# Saving


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


_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
_RECIPE_KEY = b"weft-recipe"
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
