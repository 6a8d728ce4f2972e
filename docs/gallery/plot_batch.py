"""
One look over the frames of a clip
==================================

``weft batch`` applies one recipe to many files: here ``docs/examples/look.json`` (a fast transfer
of gravel, the target metric) to four frames of a slow pan. Each item is what ``weft run`` would
make of the recipe with that frame as its target: the same parameters and seed, so the look holds
from frame to frame. This script does per frame what one worker of the batch does.
"""

from pathlib import Path

import numpy as np
from panels import grid, label
from weft.core import registry
from weft.core.image import load_image, save_image
from weft.core.request import RenderRequest
from weft.core.run import load_recipe

EXAMPLES = Path("../examples")  # docs/examples, seen from docs/gallery (or docs/images)

recipe = load_recipe(str(EXAMPLES / "look.json"))
method = registry.get(recipe.method)
params = method.params.from_dict(recipe.params)
frames = sorted((EXAMPLES / "frames").glob("frame_*.png"))

# %%
# The frames and their outputs
# ----------------------------
# Top: the frames as they come; bottom: each rendered with the recipe.

outputs = []
for frame in frames:
    request = RenderRequest(method, params, {**recipe.inputs, "target": str(frame)}, recipe.seed)
    outputs.append(request.run().image)
panels = [label(load_image(f).image, f.name) for f in frames]
panels += [
    label(np.repeat(o[..., None], 3, axis=2) if o.ndim == 2 else o, f"out/{Path(f).stem}.png")
    for f, o in zip(frames, outputs, strict=True)
]
save_image("batch-frames.png", grid(panels, len(frames)))
