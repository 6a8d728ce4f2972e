"""Generate the bad-input corpus (files weft must refuse cleanly or read correctly).

Nothing here is committed as data: :func:`make_corpus` writes the files into a folder (a pytest
``tmp_path``) each time. Run as a script to write them into a folder of your choice::

    python tests/data/make_corpus.py /tmp/corpus
"""

from __future__ import annotations

import io
import struct
import sys
import zlib
from pathlib import Path

import cv2
import numpy as np
from PIL import Image

#: Files no loader may accept: each must give one line naming the file, and no output.
BROKEN = ("empty", "text_as_png", "truncated_png", "truncated_jpeg", "bomb", "directory")
#: Valid but unusual images: each must either work or be refused with one line naming the file.
ODD = (
    "tiny_1x1",
    "thin_2x3000",
    "deep_16bit",
    "rgba",
    "palette",
    "grey_alpha",
    "cmyk_jpeg",
    "animated_gif",
    "non_ascii",
)


def _pattern(h: int, w: int, channels: int = 3, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:h, 0:w]
    base = (np.sin(xx / 3.0) * np.cos(yy / 5.0) + 1) * 100
    img = np.stack([base + rng.integers(0, 50, (h, w)) for _ in range(channels)], axis=-1)
    return np.clip(img, 0, 255).astype(np.uint8)


def _png_bytes(image: Image.Image) -> bytes:
    buf = io.BytesIO()
    image.save(buf, format="PNG")
    return buf.getvalue()


def _chunk(kind: bytes, body: bytes) -> bytes:
    return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))


def bomb_png(width: int = 60000, height: int = 60000) -> bytes:
    """A valid PNG header claiming ``width`` x ``height`` RGB pixels, with a tiny (deflated) IDAT.

    Decoding it would need ``width * height * 3`` bytes (10.8 GB for the default); a loader must
    refuse it from the header alone.
    """
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    row = b"\0" + b"\0" * (width * 3)
    idat = zlib.compress(row * 4, 9)  # only the first rows: still a bomb by its header
    return b"\x89PNG\r\n\x1a\n" + _chunk(b"IHDR", ihdr) + _chunk(b"IDAT", idat) + _chunk(b"IEND", b"")


def make_corpus(folder: str | Path) -> dict[str, Path]:
    """Write every corpus item into ``folder`` and return ``{name: path}``.

    Parameters
    ----------
    folder : str or Path
        An existing (normally empty) folder.

    Returns
    -------
    dict of str to Path
        Keys are the names in :data:`BROKEN` and :data:`ODD`. The "unreadable file" of the issue
        is not a file here: the tests simulate it by making ``open`` raise ``PermissionError``
        (the suite may run as root, for whom ``chmod 000`` changes nothing).
    """
    folder = Path(folder)
    out: dict[str, Path] = {}

    def put(name: str, filename: str, data: bytes) -> None:
        path = folder / filename
        path.write_bytes(data)
        out[name] = path

    good_png = _png_bytes(Image.fromarray(_pattern(48, 48)))
    buf = io.BytesIO()
    Image.fromarray(_pattern(48, 48)).save(buf, format="JPEG", quality=90)
    good_jpeg = buf.getvalue()

    # broken
    put("empty", "empty.png", b"")
    put("text_as_png", "notes.png", b"this is a text file, not a picture\n" * 4)
    put("truncated_png", "truncated.png", good_png[: len(good_png) // 2])
    put("truncated_jpeg", "truncated.jpg", good_jpeg[: len(good_jpeg) // 2])
    put("bomb", "bomb.png", bomb_png())
    (folder / "folder.png").mkdir()
    out["directory"] = folder / "folder.png"

    # valid but odd
    put("tiny_1x1", "tiny.png", _png_bytes(Image.fromarray(_pattern(1, 1))))
    put("thin_2x3000", "thin.png", _png_bytes(Image.fromarray(_pattern(3000, 2))))
    deep = _pattern(40, 40).astype(np.uint16) * 257  # 16-bit RGB: Pillow cannot write it, OpenCV can
    put("deep_16bit", "deep16.png", cv2.imencode(".png", deep)[1].tobytes())
    rgba = np.concatenate([_pattern(40, 40), np.full((40, 40, 1), 128, np.uint8)], axis=-1)
    put("rgba", "rgba.png", _png_bytes(Image.fromarray(rgba, mode="RGBA")))
    put("palette", "palette.png", _png_bytes(Image.fromarray(_pattern(40, 40)).convert("P", palette=Image.ADAPTIVE)))
    la = np.stack([_pattern(40, 40, 1)[..., 0], np.full((40, 40), 200, np.uint8)], axis=-1)
    put("grey_alpha", "grey_alpha.png", _png_bytes(Image.fromarray(la, mode="LA")))
    buf = io.BytesIO()
    Image.fromarray(_pattern(40, 40)).convert("CMYK").save(buf, format="JPEG", quality=90)
    put("cmyk_jpeg", "cmyk.jpg", buf.getvalue())
    frames = [Image.fromarray(_pattern(40, 40, seed=i)).convert("P", palette=Image.ADAPTIVE) for i in range(3)]
    buf = io.BytesIO()
    frames[0].save(buf, format="GIF", save_all=True, append_images=frames[1:], duration=100, loop=0)
    put("animated_gif", "animated.gif", buf.getvalue())
    put("non_ascii", "tëxtüre ü.png", _png_bytes(Image.fromarray(_pattern(40, 40, seed=3))))
    return out


if __name__ == "__main__":
    target = Path(sys.argv[1] if len(sys.argv) > 1 else "corpus")
    target.mkdir(parents=True, exist_ok=True)
    for key, p in make_corpus(target).items():
        print(f"{key:14s} {p}")
