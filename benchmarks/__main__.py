"""``python -m benchmarks [--quick] [--repeats N] [--json PATH] [--list] [CASE...]``."""

from __future__ import annotations

import argparse
import os
import platform
import sys
from pathlib import Path

from .cases import CASES, by_name
from .harness import markdown_table, run_case, write_json


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks", description=__doc__)
    ap.add_argument("cases", nargs="*", metavar="CASE", help="case names (default: all)")
    ap.add_argument("--quick", action="store_true", help="smaller inputs, one timed run: a smoke test")
    ap.add_argument("--repeats", type=int, default=None, help="timed runs per case (default 5, quick 1)")
    ap.add_argument("--json", type=Path, default=Path("benchmarks/results/latest.json"), help="where to write the rows")
    ap.add_argument("--list", action="store_true", help="list the cases and exit")
    args = ap.parse_args(argv)
    known = by_name()
    if args.list:
        for c in CASES:
            print(f"{c.name:28} {c.method:8} {c.note}")
        return 0
    unknown = [n for n in args.cases if n not in known]
    if unknown:
        print(f"benchmarks: unknown case {', '.join(unknown)} (known: {', '.join(known)})", file=sys.stderr)
        return 2
    cases = [known[n] for n in args.cases] if args.cases else CASES
    repeats = args.repeats or (1 if args.quick else 5)
    rows = []
    for case in cases:
        print(f"running {case.name} ...", file=sys.stderr, flush=True)
        rows.append(run_case(case, repeats=repeats, quick=args.quick))
    print(f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}"
          f"{', quick' if args.quick else ''}")
    print(markdown_table(rows))
    write_json(rows, args.json)
    print(f"(written to {args.json})", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
