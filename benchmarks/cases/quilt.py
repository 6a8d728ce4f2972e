"""Benchmark cases of image quilting (``weft.core.quilting``).

The ``quilt-t1-*`` and ``quilt-t2-*`` cases use the peers' own inputs, rebuilt from
scikit-image's data: ``brick_128`` = ``brick()[0:256, 256:512]`` box-downscaled 2x, ``gravel_128``
= ``gravel()[0:256, 0:256]`` box-downscaled 2x, ``camera_256`` = ``camera()`` box-downscaled 2x.
T1 is a 512x512 synthesis from brick_128 with the defaults, measured over seeds 0-9; T2 renders
camera_256 in gravel_128 (one point of weft's quality front each, see ``docs/quality_front.py``).
"""

import statistics

from .base import Case, Input

BRICK = Input("brick", crop=(0, 0, 128, 128))
GRAVEL = Input("gravel", crop=(0, 0, 128, 128))
PEER_BRICK = Input("skimage:brick", crop=(256, 0, 256, 256), resize=(128, 128))
PEER_GRAVEL = Input("skimage:gravel", crop=(0, 0, 256, 256), resize=(128, 128))
PEER_CAMERA = Input("skimage:camera", resize=(256, 256))
T1_SEEDS = range(10)


def t1_over_seeds(inputs, out, seeds=T1_SEEDS, size=(512, 512), **params) -> dict[str, float]:
    """T1's figures over ``seeds``: the median and worst coherence and completeness, and the
    largest verbatim region (``weft.core.metrics.verbatim_fraction``) of any seed; ``params``: the
    quilting parameters other than the defaults."""
    from weft.core.metrics import coherence, completeness
    from weft.core.quilting import METHOD, QuiltParams

    tex = inputs["texture"]
    coh, comp, verb = [], [], []
    for s in seeds:
        res = METHOD.run({"texture": tex}, QuiltParams(size=size, **params), rng=s)
        coh.append(coherence(res.image, tex))
        comp.append(completeness(res.image, tex))
        verb.append(res.figures["verbatim_fraction"])
    return {
        "coherence_median": statistics.median(coh),
        "coherence_max": max(coh),
        "completeness_median": statistics.median(comp),
        "completeness_max": max(comp),
        "verbatim_max": max(verb),
    }


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
    Case(
        name="quilt-t1-brick",
        method="quilt",
        inputs={"texture": PEER_BRICK},
        params={"size": (512, 512)},
        metrics=("coherence", "completeness"),
        figures=t1_over_seeds,
        quick={"size": (256, 256)},
        note="T1: 512x512 from brick_128 with the defaults (block 56 = 7/16 of the sample, tol 6); figures of "
        "seed 1, and median/max over seeds 0-9 (peers: Texturize 0.027/0.015, G'MIC 0.037/0.021, numpy "
        "quilting 0.027/0.046)",
    ),
    Case(
        name="quilt-t2-block9",
        method="quilt",
        inputs={"texture": PEER_GRAVEL, "target": PEER_CAMERA},
        params={"block": 9, "overlap": 3, "alpha": 0.1, "iterations": 3},
        metrics=("fidelity", "coherence"),
        quick={"iterations": 1},
        note="T2: camera_256 in gravel_128, block 9 / overlap 3, alpha 0.1, 3 iterations",
    ),
    Case(
        name="quilt-t2-block4",
        method="quilt",
        inputs={"texture": PEER_GRAVEL, "target": PEER_CAMERA},
        params={"block": 4, "overlap": 2, "alpha": 0.1, "iterations": 3},
        metrics=("fidelity", "coherence"),
        quick={"iterations": 1},
        note="T2: camera_256 in gravel_128, block 4 / overlap 2, alpha 0.1, 3 iterations "
        "(the coherent end of the front: beats G'MIC stylize 0.54/0.35 and numpy quilting 0.984/0.41)",
    ),
    Case(
        name="quilt-t2-block4-luminance",
        method="quilt",
        inputs={"texture": PEER_GRAVEL, "target": PEER_CAMERA},
        params={"block": 4, "overlap": 2, "alpha": 0.1, "iterations": 3, "correspondence": "luminance"},
        metrics=("fidelity", "coherence"),
        quick={"iterations": 1},
        note="T2: the same with unblurred luminance correspondence (the faithful end: beats Resynthesizer "
        "0.996/0.54, numpy quilting 0.984/0.41, Ashikhmin 0.94/0.50)",
    ),
]
