"""
Affine prototype model: synthesis, boundaries, transfer, fields
===============================================================

Smith & Bhalerao model a texture as one prototype patch and an affine transform per patch.
Every panel is computed by ``weft.core.affine`` with fixed seeds.
"""

from __future__ import annotations

import cv2
import numpy as np
from panels import grid, label  # docs/gallery/panels.py
from weft.core.affine import analyse, field_model, make_prototype, match_boundaries, render, synthesize
from weft.core.examples import example
from weft.core.image import load_image, save_image
from weft.core.metrics import snr_db

from benchmarks.fixtures.procedural import cells, weave


def _textures() -> list[tuple[str, np.ndarray]]:
    return [("scales", cells(256)), ("basket weave", weave(256)), ("brick", load_image(example("brick")).image)]


def synthesis() -> np.ndarray:
    panels = []
    for name, tex in _textures():
        paper = synthesize(tex, propagate=False, refine=0)
        ours = synthesize(tex)
        panels += [
            label(tex, f"{name} 256x256 (prototype: the|middle 64x64)"),
            label(paper, f"paper's pipeline: 8 candidates|SNR {snr_db(tex, paper):.1f} dB"),
            label(ours, f"+ neighbours' transforms, refined|SNR {snr_db(tex, ours):.1f} dB"),
        ]
    return grid(panels, 3)


def boundary() -> np.ndarray:
    panels = []
    for name, tex in _textures()[::2]:
        model = analyse(tex)
        start, _ = match_boundaries(model, "partial")
        shaken, rep = match_boundaries(model, "shaker", rng=1)
        from weft.core.affine import total_boundary_error

        e0 = total_boundary_error(model.with_shifts(np.round(model.shifts)))
        panels += [
            label(render(model), f"{name}: analysis translations|boundary error {e0:.0f}"),
            label(render(start), f"new translations, partial|correlation: error {rep.errors[0]:.0f}"),
            label(render(shaken), f"shaker box, {rep.iterations} iterations|error {rep.errors[-1]:.0f}"),
        ]
    return grid(panels, 3)


def _snakeskin() -> np.ndarray:
    """A colour scale texture like the grey one (another seed, other lighting): green to yellow."""
    g = cells(256, seed=5, spacing=17.0, drift=0.3)
    g = (g - g.min()) / (g.max() - g.min())
    dark = np.array([0.10, 0.22, 0.08], np.float32)
    light = np.array([0.92, 0.84, 0.30], np.float32)
    return np.clip(dark + g[..., None] ** 1.2 * (light - dark), 0, 1).astype(np.float32)


def transfer() -> np.ndarray:
    scales = cells(256)
    snake = _snakeskin()
    proto_rect = (96, 96, 64)
    # Fig. 5 top: the colour prototype substituted into the scales' own transforms (absorb)
    model = analyse(scales, lowpass="absorb")
    swapped = render(model, make_prototype(snake, proto_rect, block=32))
    recomputed = synthesize(scales, prototype_image=snake, prototype=proto_rect, lowpass="absorb")
    # Fig. 5 middle: the scales' highpass onto a photo that keeps its lowpass and colour
    photo = load_image(example("chelsea")).image
    plain = synthesize(photo, prototype_image=scales, prototype=proto_rect)
    shaken = synthesize(photo, prototype_image=scales, prototype=proto_rect, boundary="shaker", rng=1)

    def crop(img):  # the photo is 300x200: show 256 columns of it
        return img[:, 22:278]

    x, y, s = proto_rect
    snake_proto = cv2.resize(snake[y : y + s, x : x + s], (256, 256), interpolation=cv2.INTER_NEAREST)
    panels = [
        label(scales, "scales (transforms analysed)"),
        label(snake_proto, "colour prototype 64x64|from another texture"),
        label(swapped, "swapped into the existing|transforms (reuse, absorb)"),
        label(recomputed, "transforms recomputed|for the new prototype"),
        label(crop(photo), "photo 300x200"),
        label(crop(plain), "scales onto the photo, its|lowpass and colour kept"),
        label(crop(shaken), "... with the shaker box"),
        label(
            crop(synthesize(photo, prototype_image=weave(512), prototype=(224, 224, 64), boundary="shaker", rng=1)),
            "basket weave onto the photo,|shaker box",
        ),
    ]
    return grid(panels, 4)


def fields() -> np.ndarray:
    # (a brick prototype of 64 pixels holds a brick and a half: too little structure for a field --
    # the shaker box then lines up its short joints into long lines)
    panels = []
    for name, tex in (("scales", cells(256)), ("basket weave", weave(256))):
        proto = make_prototype(tex, None, block=32)
        for field in ("swirl", "zoom", "rotate"):
            model = field_model((256, 256), proto, field, block=32)
            matched, rep = match_boundaries(model, "shaker", rng=1)
            panels.append(label(render(matched), f"{name}: {field} field|shaker box, {rep.iterations} iterations"))
    return grid(panels, 3)


# %%
# Synthesis
# ---------
# Procedural scales, a basket weave and brick, synthesized by the paper's pipeline (eight
# candidates) and by weft's default (with the neighbours' transforms and refinement), with the SNR
# of each against the original (Fig. 4b).

save_image("affine-synthesis.jpg", synthesis())


# %%
# Boundary matching
# -----------------
# The same transforms with the analysis translations, new translations by partial correlation,
# and by the shaker box, with the total boundary error (Fig. 4b-d).

save_image("affine-boundary.jpg", boundary())


# %%
# Transfer by swapping the prototype
# ----------------------------------
# A colour prototype swapped into the scales' transforms (Fig. 5 top), the same prototype with
# recomputed transforms, and textures transferred onto a photo that keeps its lowpass and colour,
# without and with the shaker box (Fig. 5 middle and bottom).

save_image("affine-transfer.jpg", transfer())


# %%
# Transform fields
# ----------------
# Textures synthesized from parametric transform fields (swirl, zoom, rotate), the shaker box
# providing the translations (Fig. 6).

save_image("affine-fields.jpg", fields())
