"""Peak memory of large jobs run through the `weft` command (the goal: under 2 GiB).

    python -m benchmarks.memory [--repeat N] [--json FILE]

Runs each job as its own process and reads the child's peak resident set size from ``wait4`` -- the
figure ``/usr/bin/time -v`` prints as "Maximum resident set size" -- the median of ``--repeat`` runs
(default 3). Inputs are made in a temporary folder: the astronaut example (colour) resized to 2048²
and 4096² (cubic) as targets, the gravel example (256x256) as the texture, and a mask of a 40 px
square in the middle of the 4096² picture for the fill.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

LIMIT = 2 * 2**30


def _inputs(folder: Path) -> dict[str, str]:
    import cv2
    from weft.core.examples import example

    picture = cv2.imread(str(example("astronaut")), cv2.IMREAD_COLOR)
    out = {"texture": str(example("gravel"))}
    for side in (2048, 4096):
        path = folder / f"astronaut{side}.png"
        cv2.imwrite(str(path), cv2.resize(picture, (side, side), interpolation=cv2.INTER_CUBIC))
        out[f"target{side}"] = str(path)
    mask = np.zeros((4096, 4096), np.uint8)
    mask[2000:2040, 2000:2040] = 255  # a 40 px hole (a bolt, a signature) in the 4096² picture
    out["mask4096"] = str(folder / "mask4096.png")
    cv2.imwrite(out["mask4096"], mask)
    return out


def _jobs(files: dict[str, str]) -> list[tuple[str, list[str]]]:
    tex = files["texture"]
    return [
        ("fast transfer 4096x4096", ["fast", tex, "--target", files["target4096"]]),
        ("quilt synthesis 2048x2048", ["quilt", tex, "--size", "2048x2048"]),
        ("quilt transfer 2048x2048", ["quilt", tex, "--target", files["target2048"]]),
        ("fill a 40 px hole in 4096x4096", ["fill", files["target4096"], "--mask", files["mask4096"]]),
    ]


def peak_rss(argv: list[str]) -> tuple[int, float, int]:
    """Run ``argv``; return (peak RSS in bytes, wall seconds, exit status)."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    seconds = time.perf_counter() - t0
    if proc.returncode:
        sys.stderr.write(proc.stderr.read().decode(errors="replace"))
    proc.stderr.close()
    return usage.ru_maxrss * 1024, seconds, proc.returncode  # ru_maxrss is in KiB on Linux


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--json", help="where to write the results (default benchmarks/results/memory.json)")
    args = parser.parse_args(argv)
    rows = []
    with tempfile.TemporaryDirectory(prefix="weft-memory-") as tmp:
        files = _inputs(Path(tmp))
        out = str(Path(tmp) / "out.png")
        print("| job | peak RSS (median) | runs | wall s (median) | under 2 GiB |")
        print("|---|---:|---|---:|---|")
        jobs = _jobs(files)
        for name, cmd in jobs:
            full = [sys.executable, "-m", "weft.app.cli", *cmd, "-o", out, "-q", "--seed", "1"]
            runs = [peak_rss(full) for _ in range(args.repeat)]
            if any(code for _, _, code in runs):
                print(f"| {name} | failed | | | |")
                continue
            peak = statistics.median(r[0] for r in runs)
            wall = statistics.median(r[1] for r in runs)
            each = ", ".join(f"{r[0] / 2**20:.0f}" for r in runs)
            print(
                f"| {name} | {peak / 2**20:.0f} MiB | {each} | {wall:.1f} | {'yes' if peak < LIMIT else 'NO'} |",
                flush=True,
            )
            rows.append(
                {
                    "job": name,
                    "peak_bytes": peak,
                    "peak_mib": round(peak / 2**20),
                    "runs_bytes": [r[0] for r in runs],
                    "seconds": wall,
                    "under_2_gib": peak < LIMIT,
                }
            )
    from .record import command, write_results

    write_results(
        "memory",
        rows,
        command=command("benchmarks.memory", argv),
        path=args.json,
        note=f"peak resident set size of the whole weft process, median of {args.repeat} runs",
    )
    return 0 if all(r["peak_bytes"] < LIMIT for r in rows) and len(rows) == len(jobs) else 1


if __name__ == "__main__":
    raise SystemExit(main())
