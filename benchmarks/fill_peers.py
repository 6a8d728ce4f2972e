"""Run one peer hole filler on an image file: the other tools ``python -m benchmarks fill-*`` measures.

    PYTHON benchmarks/fill_peers.py PEER IMAGE MASK OUT

``MASK`` is white (non-zero) where ``IMAGE`` is to be filled; ``OUT`` is written as an 8-bit PNG of
the image's channel count. The script imports neither weft nor anything of this repository, so a
separate environment that holds a peer (``pypatchmatch``, ``resynthesizer``: never dependencies of
weft) runs it as a file, each peer in its own process so that its whole-process time and peak memory
are its own. Each peer runs with its defaults except where noted:

* ``telea``, ``ns``: ``cv2.inpaint`` (radius 3), OpenCV's diffusion fills (the smear reference);
* ``shiftmap``: ``cv2.xphoto.inpaint(..., INPAINT_SHIFTMAP)`` (He & Sun 2012) from opencv-contrib; its
  mask is the other way round (non-zero = known) and a colour image is passed in CIELab as its
  documentation asks;
* ``pypatchmatch``: ``patchmatch.patch_match.inpaint`` (PatchMatch, patch radius 15, its default);
  grey images are passed as three equal channels;
* ``resynthesizer``: the PyPI package's ``imageSynth`` engine (GIMP's Resynthesizer) with its
  defaults except ``isMakeSeamlesslyTileable*`` = 0, as GIMP's "Heal selection" runs it;
  grey images are passed as three equal channels.

G'MIC (``gmic ... inpaint_matchpatch``) is its own program and needs no runner.
"""

from __future__ import annotations

import sys

import numpy as np

PEERS = ("telea", "ns", "shiftmap", "pypatchmatch", "resynthesizer")


def _read(path: str) -> np.ndarray:
    from PIL import Image

    img = Image.open(path)
    if img.mode not in ("L", "RGB"):
        img = img.convert("RGB" if img.mode in ("RGBA", "P", "CMYK") else "L")
    return np.asarray(img).copy()


def _write(path: str, img: np.ndarray) -> None:
    from PIL import Image

    Image.fromarray(np.ascontiguousarray(img.astype(np.uint8))).save(path)


def _three(img: np.ndarray) -> np.ndarray:
    return np.repeat(img[..., None], 3, axis=2) if img.ndim == 2 else img


def _like(out: np.ndarray, img: np.ndarray) -> np.ndarray:
    """``out`` with the channel count of ``img`` (three equal channels back to one)."""
    if img.ndim == 2 and out.ndim == 3:
        return np.round(out.astype(np.float32).mean(axis=2)).astype(np.uint8)
    return out


def fill(peer: str, img: np.ndarray, hole: np.ndarray) -> np.ndarray:
    """``img`` (uint8 RGB or grey) with ``hole`` (bool) filled by ``peer``."""
    mask = hole.astype(np.uint8) * 255
    if peer in ("telea", "ns"):
        import cv2

        flag = cv2.INPAINT_TELEA if peer == "telea" else cv2.INPAINT_NS
        src = img if img.ndim == 2 else img[..., ::-1].copy()
        out = cv2.inpaint(src, mask, 3, flag)
        return out if img.ndim == 2 else out[..., ::-1]
    if peer == "shiftmap":
        import cv2

        src = img if img.ndim == 2 else cv2.cvtColor(img, cv2.COLOR_RGB2Lab)
        dst = np.zeros_like(src)
        cv2.xphoto.inpaint(src, (~hole).astype(np.uint8) * 255, dst, cv2.xphoto.INPAINT_SHIFTMAP)
        return dst if img.ndim == 2 else cv2.cvtColor(dst, cv2.COLOR_Lab2RGB)
    if peer == "pypatchmatch":
        from patchmatch import patch_match

        return _like(patch_match.inpaint(_three(img), mask), img)
    if peer == "resynthesizer":
        from PIL import Image
        from resynthesizer import getDefaultParams, resynthesize

        params = getDefaultParams()
        params.isMakeSeamlesslyTileableHorizontally = 0
        params.isMakeSeamlesslyTileableVertically = 0
        out = resynthesize(Image.fromarray(_three(img)), Image.fromarray(mask), params)
        return _like(np.asarray(out), img)
    raise SystemExit(f"fill_peers: unknown peer {peer!r} (known: {', '.join(PEERS)})")


def main(argv: list[str]) -> int:
    if len(argv) != 4:
        print(__doc__.splitlines()[2].strip(), file=sys.stderr)
        return 2
    peer, image, mask, out = argv
    img = _read(image)
    hole = _read(mask)
    hole = (hole if hole.ndim == 2 else hole.max(axis=2)) > 127
    _write(out, fill(peer, img, hole))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
