"""``weft batch``: one recipe over many files (the command-line face of :mod:`weft.core.batch`).

Exit status: 0 when every item was written (or was already done), 1 when any item failed (the
others are written; the last line on stderr says which failed and why), 2 for a bad recipe, list or
pattern (before any work), 130 when interrupted (finished items stay; a re-run resumes).
"""

from __future__ import annotations

import argparse
import json
import sys
import time

BATCH_HELP = "apply a recipe to many files: every frame of an animation, every photo of a folder"
BATCH_DESCRIPTION = (
    "Apply a recipe (.json, or a PNG exported by weft) to many files: each --over list replaces one input of "
    "the recipe file by file (several lists zip together). Runs on local processes, or on a Dask cluster "
    "with --scheduler. Items whose output already exists with the same recipe are skipped, so a re-run "
    "resumes an interrupted batch."
)


def add_batch_parser(sub) -> None:
    b = sub.add_parser("batch", help=BATCH_HELP, description=BATCH_DESCRIPTION)
    b.add_argument("recipe", metavar="RECIPE", help="recipe JSON file, or a PNG exported by weft")
    b.add_argument(
        "--over",
        nargs=2,
        action="append",
        metavar=("INPUT", "FILES"),
        required=True,
        help="the recipe input the files replace (e.g. target), and a folder, a glob ('frames/*.png', "
        "quoted) or a file; repeat to zip several lists",
    )
    b.add_argument(
        "-o",
        "--output",
        required=True,
        metavar="PATTERN",
        help="output path per item: {stem} and {name} of the (first) --over file, {index} (from 0, "
        "e.g. {index:04d}), {INPUT} the stem of that input's file; .png outputs carry their recipe",
    )
    b.add_argument("--workers", metavar="N", help="local worker processes (default: the number of cores)")
    b.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="run on this Dask scheduler (tcp://HOST:8786; default: $DASK_SCHEDULER_ADDRESS, else local)",
    )
    b.add_argument(
        "--ship-inputs",
        action="store_true",
        help="read the input files here and send their bytes to the workers (no shared folder needed)",
    )
    b.add_argument(
        "--ship-outputs",
        action="store_true",
        help="workers send each encoded output back and this process writes it (by default the "
        "workers write the output paths themselves, which they must then share)",
    )
    b.add_argument("--seed", metavar="N", help="instead of the recipe's seed")
    b.add_argument(
        "--seed-per-item",
        action="store_true",
        help="item i gets seed + i (default: every item the same seed, a consistent look across frames)",
    )
    b.add_argument("--force", action="store_true", help="redo items whose output already exists with the same recipe")
    b.add_argument(
        "--bit-depth",
        metavar="BITS",
        help="8 or 16 bits per channel (16: PNG, TIFF); default 8 (fill: each item's image's own)",
    )
    b.add_argument("--report", action="store_true", help="print one JSON line per item and a summary line on stdout")
    b.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    b.set_defaults(method=None)


def _duration(seconds: float) -> str:
    seconds = int(round(seconds))
    if seconds < 60:
        return f"{seconds} s"
    if seconds < 3600:
        return f"{seconds // 60} min {seconds % 60:02d} s"
    return f"{seconds // 3600} h {seconds % 3600 // 60:02d} min"


class _BatchBar:
    """``batch [#####     ] 312/900, 2 failed, 3 min 10 s left`` on stderr, only when it is a terminal."""

    def __init__(self, enabled: bool):
        self.enabled = enabled and sys.stderr.isatty()
        self.drawn = False

    def __call__(self, state) -> None:
        if not self.enabled:
            return
        width = 30
        filled = int(round(width * state.done / max(1, state.total)))
        left = state.seconds_left
        bits = [f"{state.done}/{state.total}"]
        if state.failed:
            bits.append(f"{state.failed} failed")
        if left is not None and state.done < state.total:
            bits.append(f"{_duration(left)} left")
        sys.stderr.write(f"\rbatch [{'#' * filled}{' ' * (width - filled)}] {', '.join(bits)}\033[K")
        sys.stderr.flush()
        self.drawn = True

    def say(self, line: str) -> None:
        """A line above the bar."""
        if self.drawn:
            sys.stderr.write("\r\033[K")
        print(line, file=sys.stderr, flush=True)

    def close(self) -> None:
        if self.drawn:
            sys.stderr.write("\n")
            sys.stderr.flush()
            self.drawn = False


def run_batch(args: argparse.Namespace) -> int:
    from weft.app.options import parse_bit_depth as _parse_bit_depth
    from weft.app.options import parse_int as _parse_int
    from weft.core import batch
    from weft.core.errors import WeftError
    from weft.core.readfile import one_line

    bit_depth = _parse_bit_depth(args) if args.bit_depth is not None else None  # None: per item, as `weft METHOD`
    seed = _parse_int(args.seed, "seed", 0, 2**63 - 1)
    workers = _parse_int(args.workers, "workers", 1, 1024)
    scheduler = batch.scheduler_address(args.scheduler)
    if scheduler and workers is not None:
        raise WeftError("--workers sets local processes; with a Dask scheduler the cluster's workers run the items")
    plan = batch.plan(
        args.recipe,
        [tuple(o) for o in args.over],
        args.output,
        seed=seed,
        seed_per_item=args.seed_per_item,
        force=args.force,
        bit_depth=bit_depth,
        ship_inputs=args.ship_inputs,
        ship_outputs=args.ship_outputs,
    )
    bar = _BatchBar(not args.quiet)

    def on_outcome(outcome) -> None:
        if args.report:
            print(json.dumps(outcome.report()), flush=True)
        if outcome.status == "failed":
            bar.say(
                one_line(
                    f"weft: {outcome.label}: {outcome.error}"
                    if not outcome.error.startswith("/")
                    else f"weft: {outcome.error}"
                )
            )

    t0 = time.monotonic()
    try:
        summary = batch.run(plan, workers=workers, scheduler=scheduler, progress=bar, on_outcome=on_outcome)
    finally:
        bar.close()
    summary.seconds = time.monotonic() - t0
    if args.report:
        print(json.dumps(summary.report()), flush=True)
    print(one_line(summary.line()), file=sys.stderr, flush=True)
    return 1 if summary.failed else 0
