"""How close the up-front running-time estimates (weft.core.limits) come to real runs.

    python -m benchmarks.estimates [--repeat N]

For a few quilting and NFPT jobs of different texture, block and output sizes, prints the estimate
of ``estimate_seconds`` next to the median measured time and their ratio. The estimates only have to
tell minutes from hours (they refuse jobs over ``WEFT_MAX_SECONDS``, 10 min by default), so a ratio
within 0.3..3 is good enough; the README's performance section records the table.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np


def _texture(side: int, seed: int = 0) -> np.ndarray:
    from weft.core.examples import example
    from weft.core.image import load_image

    base = load_image(example("gravel")).image
    reps = -(-side // base.shape[0])
    tiled = np.tile(base, (reps, reps) + (1,) * (base.ndim - 2))[:side, :side]
    return np.ascontiguousarray(tiled)


def _cases():
    from weft.core import nfpt, quilting

    def quilt_synth(tex_side, out_side, block):
        tex = _texture(tex_side)
        ov = -(-block // 6)

        def run():
            quilting.synthesize(tex, size=(out_side, out_side), block=block, overlap=ov, rng=1)

        est = quilting.estimate_seconds(tex.shape, (out_side, out_side), [(block, ov)])
        return f"quilt synth {tex_side}² -> {out_side}², block {block}", est, run

    def quilt_transfer(tex_side, out_side, iterations):
        tex = _texture(tex_side)
        target = _texture(out_side)[..., ::-1].copy()
        block = quilting.TRANSFER_BLOCK if iterations == 1 else quilting.ITERATIVE_BLOCK
        ov = max(1, round(block / 3)) if iterations == 1 else 21
        passes = [(b, o) for b, o, _ in quilting.transfer_schedule(iterations, block=block, overlap=ov)]

        def run():
            quilting.transfer(tex, target, iterations=iterations, rng=1)

        est = quilting.estimate_seconds(tex.shape, (out_side, out_side), passes)
        return f"quilt transfer {tex_side}² -> {out_side}², N={iterations}", est, run

    def nfpt_synth(tex_side, out_side, block):
        tex = _texture(tex_side)
        ov = nfpt.DEFAULT_OVERLAP

        def run():
            nfpt.synthesize(tex, size=(out_side, out_side), block=block, overlap=ov, rng=1)

        est = nfpt.estimate_seconds(tex.shape, (out_side, out_side), block, ov)
        return f"nfpt synth {tex_side}² -> {out_side}², block {block}", est, run

    return [
        quilt_synth(128, 512, 32),
        quilt_synth(256, 1024, 32),
        quilt_synth(512, 1024, 16),
        quilt_synth(1024, 1024, 64),
        quilt_transfer(128, 512, 1),
        quilt_transfer(128, 512, 5),
        quilt_transfer(256, 1024, 1),
        nfpt_synth(128, 512, 48),
        nfpt_synth(512, 1024, 48),
        nfpt_synth(256, 1024, 24),
    ]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="runs per case (median), default 3")
    args = parser.parse_args(argv)
    from weft.core import nfpt, quilting

    quilting.warm_up()
    nfpt.warm_up()
    print("| job | estimate s | measured s (median) | estimate / measured |")
    print("|---|---:|---:|---:|")
    for name, est, run in _cases():
        times = []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            run()
            times.append(time.perf_counter() - t0)
        real = statistics.median(times)
        print(f"| {name} | {est:.2f} | {real:.2f} | {est / real:.2f} |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
