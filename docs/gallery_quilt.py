"""Render the image-quilting gallery of the README into docs/images/quilt-*.png.

    .venv/bin/python docs/gallery_quilt.py

Every picture is made by the real code (``weft.core.quilting``, ``weft.core.blending``) on the bundled
examples, with fixed seeds, so re-running reproduces the files:

* ``quilt-modes.png``: the 128x128 brick sample, then 256x256 quilts with block 32 / overlap 6 in
  modes random, overlap, mincut and mincut + Poisson seams.
* ``quilt-tile.png``: a tileable 192x192 quilt repeated 2 x 2 (no seam where the copies meet).
* ``quilt-transfer.png``: the camera target, then the three passes of an iterative transfer of the
  128x128 gravel sample (block 9 / overlap 3, alpha 0.1 -> 0.5 -> 0.9).
* ``quilt-blend.png``: "face in toast": the transfer composited into plain gravel through an
  elliptic mask, by a 5-level Laplacian pyramid and by Poisson cloning.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from weft.core.blending import poisson_blend, pyramid_blend  # noqa: E402
from weft.core.examples import example  # noqa: E402
from weft.core.image import load_image, save_image  # noqa: E402
from weft.core.quilting import synthesize, transfer  # noqa: E402

OUT = ROOT / "docs" / "images"
GAP = 6


def row(images: list[np.ndarray]) -> np.ndarray:
    """Grey images side by side on white, bottom-aligned, GAP pixels apart."""
    h = max(i.shape[0] for i in images)
    parts = []
    for k, img in enumerate(images):
        pad = np.ones((h, img.shape[1]), dtype=np.float32)
        pad[h - img.shape[0]:] = img
        parts.append(pad)
        if k < len(images) - 1:
            parts.append(np.ones((h, GAP), dtype=np.float32))
    return np.concatenate(parts, axis=1)


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    brick = load_image(example("brick")).image[:128, :128].copy()
    common = dict(size=(256, 256), block=32, overlap=6, rng=7)
    modes = [synthesize(brick, mode="random", **common),
             synthesize(brick, mode="overlap", **common),
             synthesize(brick, mode="mincut", **common),
             synthesize(brick, mode="mincut", poisson=True, **common)]
    save_image(OUT / "quilt-modes.png", row([brick] + modes))

    tile = synthesize(brick, size=(192, 192), block=32, overlap=6, mode="mincut", tile=True, poisson=True, rng=3)
    save_image(OUT / "quilt-tile.png", np.tile(tile, (2, 2)))

    gravel = load_image(example("gravel")).image[:128, :128].copy()
    camera = load_image(example("camera")).image
    passes = transfer(gravel, camera, block=9, overlap=3, alpha=0.1, iterations=3, rng=1, return_all=True)
    save_image(OUT / "quilt-transfer.png", row([camera] + passes))

    toast = load_image(example("gravel")).image  # the plain texture the face goes into
    yy, xx = np.mgrid[0:256, 0:256]
    mask = ((((yy - 110) / 95.0) ** 2 + ((xx - 128) / 70.0) ** 2) <= 1).astype(np.float32)
    composite = pyramid_blend(passes[-1], toast, mask, levels=5)
    cloned = poisson_blend(toast, passes[-1], mask)
    save_image(OUT / "quilt-blend.png", row([toast, passes[-1], composite, cloned]))
    for name in ("modes", "tile", "transfer", "blend"):
        print(OUT / f"quilt-{name}.png")


if __name__ == "__main__":
    main()
