"""Benchmark cases of fast texture transfer (``weft.core.fast``)."""

from __future__ import annotations

from weft.core.examples import example
from weft.core.image import load_image, resize
from weft.core.metrics import psnr_db

from .base import Case, Input


def _superres_figures(inputs, out):
    """PSNR of the x4 result and of plain cubic magnification against the full-size original."""
    original = load_image(example("clouds")).image
    cubic = resize(inputs["texture"], original.shape[1::-1], interpolation="cubic")
    return {"psnr_db": psnr_db(original, out), "psnr_cubic_db": psnr_db(original, cubic)}


CASES: list[Case] = [
    Case(
        name="fast-transfer-640x500",
        method="fast",
        inputs={"texture": Input("gravel", crop=(0, 0, 192, 192)), "target": Input("astronaut", resize=(640, 500))},
        params={"n": 5},
        process=True,
        parallel=True,
        note="the live case: 640x500 target, 192 px source, 5x5, one pass; whole process and 2 threads too",
    ),
    Case(
        name="fast-preview-256",
        method="fast",
        inputs={"texture": Input("gravel", crop=(0, 0, 128, 128)), "target": Input("camera")},
        params={"n": 5},
        note="the size of a live preview while a slider moves",
    ),
    Case(
        name="fast-quality-camera-gravel",
        method="fast",
        inputs={"texture": Input("gravel", crop=(0, 0, 128, 128)), "target": Input("camera")},
        params={"metric": "target", "p": 0.05},
        metrics=("fidelity", "coherence"),
        note="camera 256² rendered in gravel 128², --metric target --p 0.05",
    ),
    Case(
        name="fast-artistic-640x500",
        method="fast",
        inputs={"texture": Input("wood-grain"), "target": Input("astronaut", resize=(640, 500))},
        params={"metric": "artistic", "w": 1.0},
        metrics=("fidelity",),
        note="artistic metric, result initialised with the target",
    ),
    Case(
        name="fast-superres-x4",
        method="fast",
        inputs={"texture": Input("clouds", resize=(64, 64))},
        params={"magnify": 4},
        figures=_superres_figures,
        note="clouds 256² shrunk to 64² and magnified x4 (p = 0, p_l = 0.03): PSNR against the original",
    ),
]
