"""
Image quilting: modes, tiles, transfer, blending
================================================

Image quilting (Efros & Freeman 2001) grows a texture by stitching square blocks of a sample.
Every picture here is made by ``weft.core.quilting`` and ``weft.core.blending`` on the bundled
examples with fixed seeds; running the script writes the same PNG files.
"""

from __future__ import annotations

import numpy as np
from weft.core.blending import poisson_blend, pyramid_blend
from weft.core.examples import example
from weft.core.image import load_image, save_image
from weft.core.quilting import synthesize, transfer

GAP = 6


def row(images: list[np.ndarray]) -> np.ndarray:
    """Grey images side by side on white, bottom-aligned, GAP pixels apart."""
    h = max(i.shape[0] for i in images)
    parts = []
    for k, img in enumerate(images):
        pad = np.ones((h, img.shape[1]), dtype=np.float32)
        pad[h - img.shape[0] :] = img
        parts.append(pad)
        if k < len(images) - 1:
            parts.append(np.ones((h, GAP), dtype=np.float32))
    return np.concatenate(parts, axis=1)


# %%
# Random, overlap, min-cut
# ------------------------
# The 128x128 brick sample, then 256x256 quilts with block 32 / overlap 6 in the modes ``random``
# (blocks side by side), ``overlap`` (each block matched on its overlap), ``mincut`` (plus the
# least-error cut through the overlap) and ``mincut`` with Poisson-blended seams.

brick = load_image(example("brick")).image[:128, :128].copy()
common = dict(size=(256, 256), block=32, overlap=6, rng=7)
modes = [
    synthesize(brick, mode="random", **common),
    synthesize(brick, mode="overlap", **common),
    synthesize(brick, mode="mincut", **common),
    synthesize(brick, mode="mincut", poisson=True, **common),
]
save_image("quilt-modes.png", row([brick] + modes))


# %%
# A tile that repeats without a seam
# ----------------------------------
# ``tile=True`` quilts on a torus: the output wraps left-right and top-bottom. Here a 192x192 tile
# repeated 2 x 2: no seam where the copies meet.

tile = synthesize(brick, size=(192, 192), block=32, overlap=6, mode="mincut", tile=True, poisson=True, rng=3)
save_image("quilt-tile.png", np.tile(tile, (2, 2)))


# %%
# Texture transfer, pass by pass
# ------------------------------
# The camera picture rendered in gravel: each block matches its neighbours on the overlap
# (weight ``alpha``) and the picture's blurred luminance (weight ``1 - alpha``). Three passes with
# smaller blocks each time and ``alpha`` rising 0.1 -> 0.5 -> 0.9.

gravel = load_image(example("gravel")).image[:128, :128].copy()
camera = load_image(example("camera")).image
passes = transfer(gravel, camera, block=9, overlap=3, alpha=0.1, iterations=3, rng=1, return_all=True)
save_image("quilt-transfer.png", row([camera] + passes))


# %%
# Blending it into another picture
# --------------------------------
# The transfer put into plain gravel through an elliptic mask ("face in toast"): a 5-level
# Laplacian-pyramid blend (``weft blend --mode pyramid``), then Poisson cloning (``--mode poisson``).

toast = load_image(example("gravel")).image  # the plain texture the face goes into
yy, xx = np.mgrid[0:256, 0:256]
mask = ((((yy - 110) / 95.0) ** 2 + ((xx - 128) / 70.0) ** 2) <= 1).astype(np.float32)
composite = pyramid_blend(passes[-1], toast, mask, levels=5)
cloned = poisson_blend(toast, passes[-1], mask)
save_image("quilt-blend.png", row([toast, passes[-1], composite, cloned]))
