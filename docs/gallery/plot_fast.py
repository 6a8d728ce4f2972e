"""
Fast texture transfer: styles, transfers, super-resolution
==========================================================

Ashikhmin's fast texture transfer grows the result pixel by pixel; the pixels already made
propose where to copy from next. Every panel is made by ``weft.core.fast.transfer`` with a fixed
seed.
"""

from __future__ import annotations

import numpy as np
from panels import grid, label  # docs/gallery/panels.py
from weft.core.examples import example
from weft.core.fast import transfer
from weft.core.image import load_image, resize, save_image


def styles() -> np.ndarray:
    photo = load_image(example("chelsea")).image
    tile = (photo.shape[1], photo.shape[0])
    settings = [(1, 0.1, 0.0), (2, 0.0, 0.03), (4, 1.0, 0.1), (8, 0.5, 0.01), (2, 0.2, 0.0)]
    panels = [label(photo, "original")]
    for m, p, p_l in settings:
        out = transfer(photo, mode="novel", magnify=m, p=p, p_l=p_l, rng=7)
        # Show the same region at the photo's scale x2: the middle of the magnified result.
        h, w = out.shape[:2]
        crop = out[h // 4 : h // 4 + h // 2, w // 4 : w // 4 + w // 2] if m > 1 else out
        panels.append(label(resize(crop, tile, interpolation="area"), f"m={m}  p={p}  p_l={p_l}"))
    return grid(panels, 3)


def transfers() -> np.ndarray:
    cat = load_image(example("chelsea")).image
    astro = resize(load_image(example("astronaut")).image, (300, 300), interpolation="area")
    camera = resize(load_image(example("camera")).image, (300, 300), interpolation="area")
    hatch = load_image(example("hatching")).image
    wood = load_image(example("wood-grain")).image
    gravel = load_image(example("gravel")).image[:128, :128]
    size = (300, 300)
    panels = [
        label(resize(hatch[:171], (300, 200)), "hatching sample"),
        label(transfer(hatch, cat, metric="artistic", p=0.2, colour="source", rng=1), "artistic metric, p=0.2"),
        label(resize(wood, size, interpolation="linear"), "wood grain sample"),
        label(transfer(wood, astro, metric="full", rng=1), "full metric (eq. 1), p=0.05"),
        label(resize(gravel, size, interpolation="linear"), "gravel sample"),
        label(transfer(gravel, camera, metric="target", p=0.05, rng=1), "target metric, p=0.05"),
    ]
    return grid(panels, 2)


def superres() -> np.ndarray:
    original = load_image(example("clouds")).image
    small = resize(original, (64, 64), interpolation="area")
    cubic = resize(small, (256, 256), interpolation="cubic")
    fast = transfer(small, magnify=4, rng=1)
    panels = [
        label(resize(small, (256, 256), interpolation="nearest"), "input 64x64"),
        label(cubic, "cubic x4"),
        label(fast, "texture transfer x4 (p=0, p_l=0.03)"),
        label(original, "original 256x256"),
    ]
    return grid(panels, 4)


# %%
# Novel styles from one photo
# ---------------------------
# No extra sample: the photo is its own source, magnified by ``m`` with ``p`` random and ``p_l``
# location candidates (a grid like Ashikhmin's Fig. 2).

save_image("fast-styles.jpg", styles(), quality=88)


# %%
# Style and texture transfer
# --------------------------
# A hatching drawing with the ``artistic`` metric, wood grain with the ``full`` metric (eq. 1) and
# gravel with the ``target`` metric.

save_image("fast-transfer.jpg", transfers(), quality=88)


# %%
# Super-resolution
# ----------------
# A fractal image shrunk to 64x64 and magnified x4 from itself, next to cubic magnification.

save_image("fast-superres.jpg", superres(), quality=88)
