"""Render the affine-model gallery of the README: ``.venv/bin/python docs/gallery_affine.py``.

* ``affine-synthesis.jpg``: originals (procedural scales and basket weave, brick) and their
  synthesis by the paper's pipeline (eight candidates) and by weft's default (with the
  neighbours' transforms and refinement), with the SNR of each (Fig. 4b);
* ``affine-boundary.jpg``: the same transforms with the analysis translations, new translations
  by partial correlation, and by the shaker box, with the total boundary error (Fig. 4b-d);
* ``affine-transfer.jpg``: a colour "snakeskin" prototype swapped into the scales' transforms
  (Fig. 5 top), the same prototype with recomputed transforms, and the scales (and a basket
  weave) transferred onto a photo keeping its lowpass and colour, without and with the shaker
  box (Fig. 5 middle and bottom);
* ``affine-fields.jpg``: textures synthesized from parametric transform fields with the shaker
  box providing the translations (Fig. 6).

Every panel is computed here by ``weft.core.affine`` with fixed seeds; labels are drawn with OpenCV.
"""

from __future__ import annotations

import sys
from pathlib import Path

import cv2
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from weft.core.affine import (analyse, field_model, make_prototype, match_boundaries,  # noqa: E402
                         render, synthesize)
from benchmarks.fixtures.procedural import cells, weave  # noqa: E402
from panels import grid, label  # noqa: E402 (docs/panels.py)
from weft.core.examples import example  # noqa: E402
from weft.core.image import load_image, save_image  # noqa: E402
from weft.core.metrics import snr_db  # noqa: E402

OUT = Path(__file__).resolve().parent / "images"


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
    crop = lambda img: img[:, 22:278]  # the photo is 300x200: show 256 columns of it
    x, y, s = proto_rect
    snake_proto = cv2.resize(snake[y:y + s, x:x + s], (256, 256), interpolation=cv2.INTER_NEAREST)
    panels = [
        label(scales, "scales (transforms analysed)"),
        label(snake_proto, "colour prototype 64x64|from another texture"),
        label(swapped, "swapped into the existing|transforms (reuse, absorb)"),
        label(recomputed, "transforms recomputed|for the new prototype"),
        label(crop(photo), "photo 300x200"),
        label(crop(plain), "scales onto the photo, its|lowpass and colour kept"),
        label(crop(shaken), "... with the shaker box"),
        label(crop(synthesize(photo, prototype_image=weave(512), prototype=(224, 224, 64), boundary="shaker",
                               rng=1)), "basket weave onto the photo,|shaker box"),
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


def main() -> int:
    OUT.mkdir(parents=True, exist_ok=True)
    for name, fn in (("synthesis", synthesis), ("boundary", boundary), ("transfer", transfer), ("fields", fields)):
        path = OUT / f"affine-{name}.jpg"
        save_image(path, fn())
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
