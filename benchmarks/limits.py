"""Measured runs for the up-front memory and time models of ``weft.core.limits`` (fill, quilting).

    python -m benchmarks.limits [--repeat N] [--quick]

Each job runs in a fresh process (``python -c``); its peak resident set size comes from ``wait4``
(``ru_maxrss``) and its compute time from the process itself. The peak of the same process doing a
tiny job of the same method is subtracted, so the figure is what the job adds to a running weft --
what :func:`weft.core.limits.check_memory` compares with the memory available. From the runs it fits

* fill: bytes per canvas pixel of an uncrop (``--size``) and of a hole inside a picture, and seconds
  per filled pixel of an uncrop (least squares through the origin);
* quilting synthesis: seconds per block besides the DFT and position terms the model already has.

and writes everything, with the machine and the date, to ``benchmarks/results/limits.json``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

RESULTS = Path(__file__).resolve().parent / "results" / "limits.json"

_FILL = """
import sys, time, json, numpy as np
from weft.core.image import load_image
from weft.core.fill.method import fill_image
from weft.core.fill.params import FillParams
img = load_image(sys.argv[1]).image
kind, n = sys.argv[2], int(sys.argv[3])
mask = None
if kind == "hole":
    reps = (-(-n // img.shape[0]), -(-n // img.shape[1])) + (1,) * (img.ndim - 2)
    img = np.ascontiguousarray(np.tile(img, reps)[:n, :n])
    mask = np.zeros(img.shape[:2], bool)
    mask[n // 2 - 20:n // 2 + 20, n // 2 - 20:n // 2 + 20] = True
    params = FillParams()
else:
    img = np.ascontiguousarray(img[:96, :96])
    params = FillParams(size=(max(n, 129), max(n, 129)))
small = np.zeros((48, 48), bool)
small[20:28, 20:28] = True
fill_image(img[:24, :24] if kind == "uncrop" else img[:48, :48], None if mask is None else small,
           params=FillParams(size=(32, 32)) if kind == "uncrop" else FillParams(), rng=0)  # load kernels
t0 = time.perf_counter()
if n:
    out, figures = fill_image(img, mask, params=params, rng=0)
print(json.dumps({"seconds": time.perf_counter() - t0}))
"""

_QUILT = """
import sys, time, json
import numpy as np
from weft.core import quilting
from weft.core.image import load_image
tex = load_image(sys.argv[1]).image[:int(sys.argv[2]), :int(sys.argv[2])]
out, block = int(sys.argv[3]), int(sys.argv[4])
ov = -(-block // 6)
quilting.synthesize(tex[:32, :32], size=(40, 40), block=8, overlap=2, rng=0)  # load kernels
t0 = time.perf_counter()
quilting.synthesize(tex, size=(out, out), block=block, overlap=ov, rng=1)
seconds = time.perf_counter() - t0
from weft.core.quilting import checks
from weft.core.quilting.checks import _blocks
checks.SECONDS_PER_BLOCK = checks.SECONDS_PER_BLOCK_SIDE = 0.0  # the model without the terms fitted here
est = quilting.estimate_seconds(tex.shape, (out, out), [(block, ov)])
print(json.dumps({"seconds": seconds, "model_dft_and_positions": est, "blocks": _blocks(out, out, block, ov, False)}))
"""


def _run(code: str, args: list[str]) -> tuple[dict, int]:
    """(the job's JSON line, its process's peak RSS in bytes)."""
    proc = subprocess.Popen([sys.executable, "-c", code, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    out = proc.stdout.read()
    err = proc.stderr.read()
    _, status, usage = os.wait4(proc.pid, 0)
    if status != 0:
        raise RuntimeError(err.decode(errors="replace")[-500:])
    return json.loads(out.decode().strip().splitlines()[-1]), usage.ru_maxrss * 1024


def _median_run(code: str, args: list[str], repeat: int) -> dict:
    runs = [_run(code, args) for _ in range(repeat)]
    return {
        "seconds": statistics.median(r[0]["seconds"] for r in runs),
        "peak_bytes": int(statistics.median(r[1] for r in runs)),
        **{k: v for k, v in runs[0][0].items() if k != "seconds"},
    }


def _through_origin(x: list[float], y: list[float]) -> float:
    x, y = np.asarray(x, float), np.asarray(y, float)
    return float((x * y).sum() / (x * x).sum())


def _per_block_fit(quilt: list[dict]) -> dict:
    """Seconds per block besides the modelled DFTs and positions, as ``a + b * block`` (least squares)."""
    blocks = np.array([r["block"] for r in quilt], float)
    per = np.array([(r["seconds"] - r["model_dft_and_positions"]) / r["blocks"] for r in quilt])
    b, a = np.polyfit(blocks, per, 1)
    return {"seconds_per_block": float(a), "seconds_per_block_per_side": float(b)}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--quick", action="store_true", help="fewer, smaller cases")
    args = parser.parse_args(argv)
    from weft.core.examples import example

    gravel = str(example("gravel"))
    photo = str(example("astronaut")) if Path(str(example("astronaut"))).exists() else gravel
    results: dict = {
        "machine": {
            "platform": platform.platform(),
            "cpus": os.cpu_count(),
            "python": platform.python_version(),
            "note": "shared by other jobs",
        },
        "date": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        "repeat": args.repeat,
    }

    base = _median_run(_FILL, [photo, "uncrop", "0"], args.repeat)
    results["fill_baseline_peak_bytes"] = base["peak_bytes"]
    sides = [300, 450, 600] if args.quick else [300, 450, 600, 800, 1000]
    fill: dict = {}
    for label, source in (("colour", photo), ("grey", gravel)):
        uncrop = []
        for n in sides:
            r = _median_run(_FILL, [source, "uncrop", str(n)], args.repeat)
            r.update(side=n, added_bytes=r["peak_bytes"] - base["peak_bytes"])
            uncrop.append(r)
            print(
                f"fill uncrop {label} 96² -> {n}x{n}: {r['seconds']:.2f} s, +{r['added_bytes'] / 2**20:.0f} MiB",
                flush=True,
            )
        filled = [r["side"] ** 2 - 96**2 for r in uncrop]
        fill[f"uncrop_{label}"] = uncrop
        fill[f"uncrop_{label}_bytes_per_canvas_pixel"] = _through_origin(
            [r["side"] ** 2 for r in uncrop], [r["added_bytes"] for r in uncrop]
        )
        fill[f"uncrop_{label}_seconds_per_filled_pixel"] = _through_origin(filled, [r["seconds"] for r in uncrop])
    hole = []
    for n in [800, 1600] if args.quick else [1000, 2000]:
        r = _median_run(_FILL, [photo, "hole", str(n)], args.repeat)
        r.update(side=n, added_bytes=r["peak_bytes"] - base["peak_bytes"])
        hole.append(r)
        print(f"fill 40 px hole in {n}x{n}: {r['seconds']:.2f} s, +{r['added_bytes'] / 2**20:.0f} MiB", flush=True)
    fill["hole"] = hole
    fill["hole_bytes_per_canvas_pixel"] = _through_origin(
        [r["side"] ** 2 for r in hole], [r["added_bytes"] for r in hole]
    )
    results["fill"] = fill

    quilt = []
    for block in [4, 8, 16] if args.quick else [4, 6, 8, 12, 16, 24, 32]:
        r = _median_run(_QUILT, [gravel, "128", "300", str(block)], args.repeat)
        r.update(block=block, texture=128, out=300)
        quilt.append(r)
        print(
            f"quilt 128² -> 300², block {block}: {r['seconds']:.2f} s against {r['model_dft_and_positions']:.2f} s "
            f"modelled ({r['blocks']} blocks)",
            flush=True,
        )
    results["quilting"] = {"synthesis": quilt, **_per_block_fit(quilt)}
    per_block = results["quilting"]
    print(json.dumps({k: v for k, v in results["fill"].items() if not isinstance(v, list)}))
    print(
        f"quilting seconds per block: {per_block['seconds_per_block']:.3g} + "
        f"{per_block['seconds_per_block_per_side']:.3g} x block"
    )
    RESULTS.parent.mkdir(exist_ok=True)
    RESULTS.write_text(json.dumps(results, indent=1) + "\n")
    print(f"wrote {RESULTS}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
