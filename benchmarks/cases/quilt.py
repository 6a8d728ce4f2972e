"""Benchmark cases of image quilting (``core.quilting``)."""

from .base import Case, Input

CASES: list[Case] = [
    Case(
        name="quilt-random-512",
        method="quilt",
        inputs={"texture": Input("brick", crop=(0, 0, 128, 128))},
        params={"mode": "random", "block": 32, "size": (512, 512)},
        metrics=("coherence", "completeness"),
        gmic=("syntexturize_matchpatch", "512,512"),
        quick={"size": (256, 256)},
        note="random block tiling (no overlap); G'MIC runs its patch-matching synthesis on the same input",
    ),
]
