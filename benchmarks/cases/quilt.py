"""Benchmark cases of image quilting (``core.quilting``)."""

from .base import Case, Input

BRICK = Input("brick", crop=(0, 0, 128, 128))
GRAVEL = Input("gravel", crop=(0, 0, 128, 128))

CASES: list[Case] = [
    Case(
        name="quilt-random-512",
        method="quilt",
        inputs={"texture": BRICK},
        params={"mode": "random", "block": 32, "size": (512, 512)},
        metrics=("coherence", "completeness"),
        gmic=("syntexturize_matchpatch", "512,512"),
        quick={"size": (256, 256)},
        note="random block tiling (no overlap); G'MIC runs its patch-matching synthesis on the same input",
    ),
    Case(
        name="quilt-mincut-512",
        method="quilt",
        inputs={"texture": BRICK},
        params={"mode": "mincut", "block": 32, "overlap": 6, "size": (512, 512)},
        metrics=("coherence", "completeness"),
        gmic=("syntexturize_matchpatch", "512,512"),
        quick={"size": (256, 256)},
        note="min-cut synthesis, default tol 2; G'MIC's patch-matching synthesis on the same input",
    ),
    Case(
        name="quilt-transfer-512",
        method="quilt",
        inputs={"texture": GRAVEL, "target": Input("camera", resize=(512, 512))},
        params={"block": 9, "overlap": 3},
        metrics=("fidelity", "coherence"),
        quick={},
        note="one transfer pass of a 512x512 target (camera, upscaled), block 9 / overlap 3, alpha 0.1",
    ),
    Case(
        name="quilt-iterative-512",
        method="quilt",
        inputs={"texture": GRAVEL, "target": Input("camera", resize=(512, 512))},
        params={"iterations": 5},
        metrics=("fidelity", "coherence"),
        quick={"iterations": 2},
        note="iterative transfer N=5 on 512x512: blocks 31/21, 21/14, 14/9, 9/6, 9/4, alpha 0.1 -> 0.9",
    ),
    Case(
        name="quilt-transfer-quality",
        method="quilt",
        inputs={"texture": GRAVEL, "target": Input("camera")},
        params={"block": 9, "overlap": 3, "alpha": 0.1, "iterations": 3},
        metrics=("fidelity", "coherence"),
        note="camera 256x256 in gravel 128x128, block 9 / overlap 3, alpha 0.1, 3 iterations",
    ),
]
