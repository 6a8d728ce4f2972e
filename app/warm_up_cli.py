"""``weft warm-up``: load (or compile) every method's kernels ahead of time, in fresh processes."""

from __future__ import annotations

import argparse
import os
import sys
import time

from .options import parse_int as _parse_int


def warm_up_all(args: argparse.Namespace) -> int:
    """``weft warm-up``: every method's ``warm_up`` in a pool of ``--jobs`` fresh processes."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed

    from weft.core import registry

    chosen = [registry.get(name) for name in args.methods] if args.methods else registry.methods().values()
    names = [m.name for m in chosen if m.warm_up is not None]
    if not names:
        return 0
    jobs = _parse_int(args.jobs, "jobs", 1, 1024) or os.cpu_count() or 1
    say = (lambda text: None) if args.quiet else (lambda text: print(text, flush=True))
    t0 = time.perf_counter()
    failed = []
    notices = set()
    say(
        f"weft: warming up {len(names)} method{'s' if len(names) != 1 else ''}, "
        f"{min(jobs, len(names))} process{'es' if min(jobs, len(names)) != 1 else ''} at once"
    )
    # "spawn": fresh interpreters (no inherited numba state or threads). Each worker warms several
    # methods in turn (quilting, the longest, first): a process per method paid Python's, numba's
    # and LLVM's start-up six times, 19.7 s of CPU against 12.2 s in one process on this machine.
    with ProcessPoolExecutor(
        max_workers=min(jobs, len(names)), mp_context=multiprocessing.get_context("spawn")
    ) as pool:
        futures = {pool.submit(registry.warm_up_report, name): name for name in names}
        for future in as_completed(futures):
            name = futures[future]
            try:
                r = future.result()
            except Exception as e:  # a broken kernel is a bug: say which method, keep warming the others
                failed.append(name)
                print(f"weft: warm-up of {name} failed: {type(e).__name__}: {e}", file=sys.stderr)
                continue
            if r["notice"]:
                notices.add(r["notice"])
            notices.update(r.get("repairs") or ())
            what = (
                f"compiled {r['compiled']} function{'s' if r['compiled'] != 1 else ''}"
                if r["compiled"]
                else "loaded from the cache"
            )
            say(f"{name:8} {what} in {r['seconds']:.1f} s")
    for notice in sorted(notices):
        print(f"weft: {notice}", file=sys.stderr)
    if failed:
        return 1
    say(f"weft: {len(names)} method{'s' if len(names) != 1 else ''} ready in {time.perf_counter() - t0:.1f} s")
    return 0
