"""Quilting's default block and tol on samples other than T1's (issue 17: the block follows the sample).

    python -m benchmarks.quilt_samples [--seeds N] [--samples NAME,...]

For each sample, a synthesis twice its size with the old fixed defaults (block 32, tol 2) and with
the current ones (``QuiltParams()``: block 7/16 of the sample's shorter side, at most 56; tol 6 from
block 48 up): the median coherence and completeness over seeds 0..N-1 (``weft.core.metrics``) and
the largest verbatim region of any seed, as a fraction of the sample. Samples: the bundled examples,
whole or their top-left 128x128 (``@128``), and the peers' ``gravel_128`` (issue 17's T2 texture).
Prints a Markdown table (the README's quilting section records it).
"""

from __future__ import annotations

import argparse
import statistics

import numpy as np

SAMPLES = (
    "gravel_128",
    "wood-grain",
    "cat-fur",
    "grass@128",
    "clouds@128",
    "hatching@128",
    "brick@128",
    "gravel",
    "grass",
    "brick",
)


def sample(name: str) -> np.ndarray:
    """The sample called ``name`` (see the module docstring), float32."""
    from weft.core.examples import example
    from weft.core.image import load_image, resize

    if name == "gravel_128":
        from skimage import data

        img = np.asarray(data.gravel(), np.float32)[0:256, 0:256] / 255.0
        img = resize(img, (128, 128), interpolation="area")
    elif name.endswith("@128"):
        img = load_image(example(name[:-4])).image[:128, :128]
    else:
        img = load_image(example(name)).image
    return np.ascontiguousarray(img, dtype=np.float32)


def figures(tex: np.ndarray, seeds: int, **params) -> tuple[float, float, float]:
    """(median coherence, median completeness, largest verbatim region) of ``seeds`` syntheses."""
    from weft.core.metrics import coherence, completeness
    from weft.core.quilting import METHOD, QuiltParams

    h, w = tex.shape[:2]
    coh, comp, verb = [], [], []
    for seed in range(seeds):
        res = METHOD.run({"texture": tex}, QuiltParams(size=(2 * w, 2 * h), **params), rng=seed)
        coh.append(coherence(res.image, tex))
        comp.append(completeness(res.image, tex))
        verb.append(res.figures["verbatim_fraction"])
    return statistics.median(coh), statistics.median(comp), max(verb)


def main(argv=None) -> int:
    from weft.core.quilting import synth_block

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument("--samples", default=",".join(SAMPLES))
    args = parser.parse_args(argv)
    print("| sample | block | coherence | completeness | largest verbatim region |")
    print("| --- | --- | --- | --- | --- |")
    for name in args.samples.split(","):
        tex = sample(name)
        old = figures(tex, args.seeds, block=32, tol=2)
        new = figures(tex, args.seeds)
        h, w = tex.shape[:2]
        print(
            f"| {name} {w}x{h} | {synth_block(tex.shape)} | "
            + " | ".join(
                f"{a:.4f} → {b:.4f}" if i < 2 else f"{a:.3f} → {b:.3f}"
                for i, (a, b) in enumerate(zip(old, new, strict=True))
            )
            + " |",
            flush=True,
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
