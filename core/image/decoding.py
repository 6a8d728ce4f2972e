"""The decoders under :func:`~weft.core.image.load_image`: Pillow's lazy header, the Pillow fallback
for what OpenCV cannot decode, EXIF orientation, alpha kept, and the one-line wording of their errors.
"""

from __future__ import annotations

import contextlib
import errno
import io
import struct
import threading
import warnings

import cv2
import numpy as np
from PIL import Image

from ..errors import ImageError
from ..readfile import open_regular, shown

# A corrupt file is reported once, by us, as one line: OpenCV's own warnings would add a second.
cv2.utils.logging.setLogLevel(cv2.utils.logging.LOG_LEVEL_SILENT)

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
