"""Batch throughput: items per second of `weft batch` on 1 and 2 local workers and a local Dask cluster.

    python -m benchmarks.batch [--repeats N] [--frames N] [--only fast|quilt] [--json FILE]

24 frames of 640x480 (a slow pan over ``resources/perspective-frontal.png``, scaled to 800x600 and
cropped at a shifting window), written to a temporary folder, then two recipes over them, each in
one run of this script:

* ``fast``: fast texture transfer of the gravel example onto each frame (default parameters);
* ``quilt``: quilting transfer of a 128x128 crop of gravel onto each frame (block 9, overlap 3).

Each recipe runs on a local pool of 1 worker, a local pool of 2 workers, and a Dask
``LocalCluster`` of 2 worker processes with 1 thread each (loopback). The pools are started and their
kernels loaded before the clock starts (``ready()``); the time is that of :func:`weft.core.batch.run`
over all frames, outputs written as PNG with their recipe (``force``: every repeat redoes them),
median of ``--repeats`` (default 3), the configurations alternating run by run. The start-up of
each pool (spawning, imports, kernels; the Dask cluster's own start included) and the 1-minute
load average during the runs (the machine is shared: above ~0.5 the figures are not clean) are
printed too, with two figures that do not depend on how busy the machine is: the median time of
one item on its worker (read, run, encode, write: if two workers make it longer than one, they
compete for cores or memory bandwidth), the CPU time its process used for it (all threads: if that
grows with two workers, they slow each other down; if only the wall time grows, other programs took
the cores), and how busy the workers were (the items' times over wall time x workers: below 100 %
is time the pool left a worker idle). Goals:
2 workers >= 1.7x the items per second of 1, and Dask within 15 % of the local pool of 2.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path


def make_frames(folder: Path, n: int) -> list[Path]:
    import cv2
    from weft.core.examples import example

    src = cv2.imread(str(example("perspective-frontal")), cv2.IMREAD_COLOR)
    big = cv2.resize(src, (800, 600), interpolation=cv2.INTER_CUBIC)
    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    for i in range(n):
        x, y = (6 * i) % 160, (4 * i) % 120
        p = folder / f"frame_{i:04d}.png"
        cv2.imwrite(str(p), big[y : y + 480, x : x + 640])
        paths.append(p)
    return paths


def make_recipes(folder: Path, first_frame: Path) -> dict[str, Path]:
    import cv2
    from weft.core.examples import example

    gravel = cv2.imread(str(example("gravel")), cv2.IMREAD_GRAYSCALE)
    cv2.imwrite(str(folder / "gravel128.png"), gravel[:128, :128])
    recipes = {
        "fast": {"method": "fast", "params": {}, "inputs": {"texture": str(example("gravel"))}},
        "quilt": {
            "method": "quilt",
            "params": {"block": 9, "overlap": 3},
            "inputs": {"texture": str(folder / "gravel128.png")},
        },
    }
    out = {}
    for name, r in recipes.items():
        path = folder / f"{name}.json"
        r["inputs"]["target"] = str(first_frame)
        path.write_text(json.dumps({"weft": 1, **r, "seed": 1}))
        out[name] = path
    return out


def time_batch(plan_factory, pool, slots: int) -> tuple[float, float, float, float]:
    """One batch: (wall seconds, busy fraction, seconds per item on its worker, CPU seconds per item).
    Busy = the items' whole times on their workers / (wall x workers): how well the pool keeps its
    workers fed."""
    from weft.core import batch

    plan = plan_factory()
    done = []
    t0 = time.perf_counter()
    summary = batch.run(plan, pool=pool, on_outcome=done.append)
    wall = time.perf_counter() - t0
    if summary.written != len(plan.items):
        raise SystemExit(f"batch failed: {summary.line()}")
    return (
        wall,
        sum(o.elapsed for o in done) / (wall * slots),
        statistics.median(o.elapsed for o in done),
        statistics.median(o.cpu for o in done),
    )


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.batch", description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--frames", type=int, default=24)
    ap.add_argument("--only", choices=("fast", "quilt"))
    ap.add_argument("--no-dask", action="store_true", help="local pools only")
    ap.add_argument("--json", type=Path, help="where to write the results (default benchmarks/results/batch.json)")
    args = ap.parse_args(argv)

    from weft.core import batch

    rows = []
    with tempfile.TemporaryDirectory(prefix="weft-bench-batch-") as tmp:
        tmp = Path(tmp)
        frames = make_frames(tmp / "frames", args.frames)
        recipes = make_recipes(tmp, frames[0])
        names = [args.only] if args.only else list(recipes)
        configs = [("local, 1 worker", 1), ("local, 2 workers", 2)] + (
            [] if args.no_dask else [("Dask, 2 workers", "dask")]
        )
        cluster = None
        if not args.no_dask:
            from distributed import LocalCluster

            t0 = time.perf_counter()
            cluster = LocalCluster(
                processes=True,
                n_workers=2,
                threads_per_worker=1,
                host="127.0.0.1",
                dashboard_address=None,
                silence_logs=50,
            )
            cluster_start = time.perf_counter() - t0
        for name in names:
            method = json.loads(recipes[name].read_text())["method"]
            pools, startup = {}, {}
            for label, kind in configs:  # every pool started and warm before any clock runs
                t0 = time.perf_counter()
                pools[label] = (
                    batch.DaskPool(cluster.scheduler_address, method)
                    if kind == "dask"
                    else batch.LocalPool(kind, method)
                )
                pools[label].ready()
                startup[label] = time.perf_counter() - t0 + (cluster_start if kind == "dask" else 0.0)

            def factory(name=name):
                return batch.plan(
                    str(recipes[name]),
                    [("target", str(tmp / "frames"))],
                    str(tmp / "out" / name / "{stem}.png"),
                    force=True,
                )

            times = {label: [] for label, _ in configs}
            busy = {label: [] for label, _ in configs}
            per_item = {label: [] for label, _ in configs}
            cpu = {label: [] for label, _ in configs}
            loads = []
            try:
                for r in range(args.repeats):  # configurations alternate, so a busier minute hits them all
                    for label, _ in configs:
                        print(f"{name}: {label}, run {r + 1}/{args.repeats} ...", file=sys.stderr, flush=True)
                        loads.append(os.getloadavg()[0])
                        wall, b, e, c = time_batch(factory, pools[label], pools[label].slots)
                        cpu[label].append(c)
                        times[label].append(wall)
                        busy[label].append(b)
                        per_item[label].append(e)
            finally:
                for pool in pools.values():
                    pool.close()
            for label, _ in configs:
                med = statistics.median(times[label])
                rows.append(
                    {
                        "recipe": name,
                        "pool": label,
                        "items": args.frames,
                        "median_s": round(med, 3),
                        "runs_s": [round(t, 3) for t in times[label]],
                        "items_per_s": round(args.frames / med, 2),
                        "startup_s": round(startup[label], 2),
                        "load_avg": round(statistics.median(loads), 2),
                        "busy": round(statistics.median(busy[label]), 3),
                        "item_s": round(statistics.median(per_item[label]), 3),
                        "item_cpu_s": round(statistics.median(cpu[label]), 3),
                    }
                )
        if cluster is not None:
            cluster.close()

    print(
        f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}, "
        f"{args.frames} frames of 640x480, median of {args.repeats}"
    )
    print(
        "| recipe | pool | items/s | median s | runs s | vs 1 worker | s per item on its worker | CPU s per item "
        "| workers busy | pool start s | load avg |"
    )
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for r in rows:
        one = next(x for x in rows if x["recipe"] == r["recipe"] and x["pool"] == "local, 1 worker")
        print(
            f"| {r['recipe']} | {r['pool']} | {r['items_per_s']} | {r['median_s']} | "
            f"{' / '.join(str(t) for t in r['runs_s'])} | {r['items_per_s'] / one['items_per_s']:.2f}x | "
            f"{r['item_s']} | {r['item_cpu_s']} | {r['busy'] * 100:.0f} % | {r['startup_s']} | {r['load_avg']} |"
        )
    for name in {r["recipe"] for r in rows}:
        by = {r["pool"]: r["items_per_s"] for r in rows if r["recipe"] == name}
        two, one, dask = by.get("local, 2 workers"), by.get("local, 1 worker"), by.get("Dask, 2 workers")
        line = f"{name}: 2 workers {two / one:.2f}x of 1 (goal >= 1.7x)"
        if dask:
            line += f"; Dask {dask / two:.2f} of the local pool of 2 (goal >= 0.85)"
        print(line)
    for r in rows:
        one = next(x for x in rows if x["recipe"] == r["recipe"] and x["pool"] == "local, 1 worker")
        r["vs_one_worker"] = round(r["items_per_s"] / one["items_per_s"], 2)
    from .record import command, write_results

    write_results(
        "batch",
        rows,
        command=command("benchmarks.batch", argv),
        path=args.json,
        note=f"{args.frames} frames of 640x480; median of {args.repeats} runs, the pools alternating",
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
