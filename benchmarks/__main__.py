"""``python -m benchmarks [--quick] [--repeats N] [--json PATH] [--list] [--tools NAME,...] [CASE...]``.

A CASE may be a shell-style pattern: ``python -m benchmarks 'fill-*'`` runs the fill cases
(``benchmarks/fill.py``: weft's fill against its peers, each tool a process of its own)."""

from __future__ import annotations

import argparse
import fnmatch
import os
import platform
import sys
from pathlib import Path

from . import fill
from .cases import CASES, by_name
from .harness import markdown_table, run_case
from .record import command, write_results


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks", description=__doc__)
    ap.add_argument("cases", nargs="*", metavar="CASE", help="case names (default: all)")
    ap.add_argument("--quick", action="store_true", help="smaller inputs, one timed run: a smoke test")
    ap.add_argument("--repeats", type=int, default=None, help="timed runs per case (default 5, quick 1)")
    ap.add_argument(
        "--json", type=Path, default=None, help="where to write the results (default benchmarks/results/methods.json)"
    )
    ap.add_argument("--list", action="store_true", help="list the cases and exit")
    ap.add_argument(
        "--tools",
        default=None,
        help="fill cases: only the tools whose names start with these (comma-separated, e.g. weft,G'MIC)",
    )
    ap.add_argument("--keep", type=Path, default=None, help="fill cases: copy every tool's output into this folder")
    args = ap.parse_args(argv)
    known = {**by_name(), **fill.by_name()}
    if args.list:
        for c in [*CASES, *fill.CASES]:
            print(f"{c.name:28} {c.method:8} {c.note}")
        return 0
    picked: list[str] = []
    for pattern in args.cases:
        names = [n for n in known if fnmatch.fnmatchcase(n, pattern)]
        if not names:
            print(f"benchmarks: unknown case {pattern} (known: {', '.join(known)})", file=sys.stderr)
            return 2
        picked += [n for n in names if n not in picked]
    cases = [known[n] for n in picked] if picked else [*CASES, *fill.CASES]
    try:
        tools = fill.tools_named(args.tools.split(",")) if args.tools else None
    except ValueError as e:
        print(f"benchmarks: {e}", file=sys.stderr)
        return 2
    repeats = args.repeats or (1 if args.quick else 5)
    rows, fill_rows = [], []
    for case in cases:
        print(f"running {case.name} ...", file=sys.stderr, flush=True)
        if isinstance(case, fill.FillCase):
            fill_rows += fill.run_fill_case(case, repeats=repeats, quick=args.quick, tools=tools, keep=args.keep)
        else:
            rows.append(run_case(case, repeats=repeats, quick=args.quick))
    written = write_results(
        "methods",
        rows + fill_rows,
        command=command("benchmarks", argv),
        quick=args.quick,
        path=args.json,
        note="compute seconds of one run (inputs decoded), median of the runs",
    )
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(
        f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}"
        f", load average {load:.1f}{', quick' if args.quick else ''}"
    )
    if rows:
        print(markdown_table(rows))
    if fill_rows:
        print(fill.markdown_table(fill_rows))
    print(f"(written to {written})", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
