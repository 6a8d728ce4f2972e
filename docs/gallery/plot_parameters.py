"""
What each parameter changes
===========================

One strip per parameter: the same input and seed, the parameter stepped over its range, every
other parameter at its default. The pictures are small (128 px) so the strips stay quick to make;
the effect reads the same at full size.
"""

import numpy as np
from panels import grid, label
from weft.core import registry
from weft.core.examples import example
from weft.core.image import load_image, resize, save_image

brick = load_image(example("brick")).image[:96, :96].copy()
gravel = load_image(example("gravel")).image[:96, :96].copy()
camera = resize(load_image(example("camera")).image, (128, 128), interpolation="area")
coffee = load_image(example("coffee")).image


def strip(method: str, inputs: dict, name: str, values: list, **fixed) -> np.ndarray:
    """One result per value of parameter ``name`` (seed 1), captioned, side by side."""
    m = registry.get(method)
    panels = []
    for v in values:
        params = m.params.from_dict({**fixed, name: v})
        out = m.run(inputs, params, rng=1).image
        panels.append(label(out, f"{name} = {v}"))
    return grid(panels, len(panels))


# %%
# Quilting: block
# ---------------
# The side of the blocks copied from the sample. Small blocks break the bricks into pieces; large
# blocks keep whole bricks and their joints, and copy more of the sample at once.

save_image("param-quilt-block.png", strip("quilt", {"texture": brick}, "block", [8, 16, 32, 48], size=(128, 128)))

# %%
# Quilting: tol
# -------------
# How many of the best-matching positions a block is drawn from. 1 always takes the best match
# (seams vanish but the same spot repeats); larger values vary the result at the cost of
# visible seams.

save_image("param-quilt-tol.png", strip("quilt", {"texture": gravel}, "tol", [1, 2, 8, 64], size=(128, 128), block=24))

# %%
# Quilting transfer: alpha
# ------------------------
# In a transfer, how much a block must agree with its neighbours (alpha near 1: smooth texture)
# against how much it must follow the picture (alpha near 0: a faithful picture).

save_image(
    "param-quilt-alpha.png",
    strip("quilt", {"texture": gravel, "target": camera}, "alpha", [0.0, 0.3, 0.6, 0.9], block=9, overlap=3),
)

# %%
# Fast transfer: p
# ----------------
# The chance that a random position of the texture competes with the coherent candidates. 0 gives
# long coherent copies of the texture; higher values follow the picture more closely, in
# smaller pieces.

save_image(
    "param-fast-p.png",
    strip("fast", {"texture": gravel, "target": camera}, "p", [0.0, 0.05, 0.3, 1.0], metric="target"),
)

# %%
# Fast transfer: n
# ----------------
# The side of the neighbourhood compared. Small neighbourhoods copy fine grain; larger ones
# carry larger structures of the texture.

save_image(
    "param-fast-n.png", strip("fast", {"texture": gravel, "target": camera}, "n", [3, 5, 7, 11], metric="target")
)

# %%
# Fill: band
# ----------
# How far around the hole known pixels may change so the filled part meets them without a step.
# 0 keeps every known pixel exactly; a few pixels hide the seam.

hole = np.zeros(coffee.shape[:2], np.float32)
hole[60:120, 200:260] = 1
save_image("param-fill-band.png", strip("fill", {"image": coffee, "mask": hole}, "band", [0, 2, 8, 16]))
