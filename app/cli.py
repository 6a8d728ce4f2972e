"""The ``weft`` command.

``weft`` with no arguments opens the desktop studio; ``weft METHOD INPUT... -o OUT [options]`` runs a
method headless; ``weft run RECIPE -o OUT`` reproduces a recipe (a ``.json`` file, or a PNG exported
by weft, which carries its recipe); ``weft batch RECIPE --over INPUT FILES -o PATTERN`` applies it to
many files (:mod:`app.batch_cli`). Method options are generated from the method's ``Params`` specs,
so the CLI and the GUI share one definition of every parameter and its range.

Contract: any bad input (a file, a parameter, a geometry) prints exactly one line on stderr and exits
with status 2, with no traceback and no output file. ``--report`` prints exactly one JSON line on
stdout: ``{"method", "seconds", "size", "seed", ...method figures}`` where ``seconds`` is the compute
time only (no imports, no image I/O).
"""

from __future__ import annotations

import argparse
import json
import os
import secrets
import sys
from pathlib import Path
from typing import Sequence

from core import __version__
from core.errors import Cancelled, WeftError
from core.params import specs

SAVE_EXTENSIONS = (".png", ".jpg", ".jpeg", ".tif", ".tiff")


class UsageError(WeftError):
    """Bad command-line syntax (argparse's complaints, as one line)."""


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # argparse would print usage + message and exit itself
        raise UsageError(f"{self.prog}: {message} (see '{self.prog} --help')")


class _TerminalProgress:
    """A one-line progress bar on stderr, drawn only when stderr is a terminal."""

    wants_preview = False  # it draws the fraction only: algorithms need not build partial images

    def __init__(self, enabled: bool):
        self.enabled = enabled and sys.stderr.isatty()
        self.drawn = False

    def __call__(self, p) -> None:
        if not self.enabled:
            return
        width = 30
        filled = int(round(p.fraction * width))
        sys.stderr.write(f"\r{p.stage:<14} [{'#' * filled}{' ' * (width - filled)}] {p.fraction * 100:3.0f}%")
        sys.stderr.flush()
        self.drawn = True

    def close(self) -> None:
        if self.drawn:
            sys.stderr.write("\n")
            sys.stderr.flush()
            self.drawn = False


def _add_common(p: argparse.ArgumentParser) -> None:
    p.add_argument("-o", "--output", required=True, metavar="OUT",
                   help="output image (.png, .jpg, .tif); PNGs carry the recipe")
    p.add_argument("--seed", metavar="N", help="random seed (default: a fresh one, recorded in the recipe)")
    p.add_argument("--bit-depth", metavar="BITS", default="8", help="8 or 16 bits per channel (16: PNG, TIFF)")
    p.add_argument("--region", metavar="X,Y,S",
                   help="use only this square of the texture (top-left corner and side, pixels) as the source")
    p.add_argument("--report", action="store_true", help="print one JSON line with the compute time and figures")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar")


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """The ``weft`` parser; with ``only``, just that method's subcommand (and ``run``) is built, so
    only that method's module is imported."""
    from core import registry

    parser = _Parser(prog="weft", description="Example-based texture synthesis and transfer. "
                     "Without arguments, opens the desktop studio.")
    parser.add_argument("--version", action="version", version=f"weft {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    chosen = [registry.get(only)] if only is not None else list(registry.methods().values())
    for method in chosen:
        p = sub.add_parser(method.name, help=method.summary, description=method.summary)
        for inp in method.inputs:
            if inp.is_positional:
                p.add_argument(inp.name, metavar=inp.name.upper(), help=inp.help)
            else:
                p.add_argument("--" + inp.name.replace("_", "-"), dest=inp.name, metavar="IMAGE",
                               required=inp.required, help=inp.help)
        group = p.add_argument_group("method parameters")

        for spec in specs(method.params):
            bits = [spec.help or spec.name]
            if spec.symbol:
                bits.append(f"paper: {spec.symbol}")
            rng = spec.range_text()
            if rng:
                bits.append(("one of " if spec.kind == "choice" else "range ") + rng)
            if spec.default is not None:
                d = spec.default
                bits.append("default " + (f"{d[0]}x{d[1]}" if isinstance(d, tuple) else str(d)))
            group.add_argument(spec.option, dest="param_" + spec.name, metavar=spec.kind.upper(),
                               help="; ".join(bits).replace("%", "%%"))
        _add_common(p)
        p.set_defaults(method=method.name)
    r = sub.add_parser("run", help="reproduce a recipe (.json, or a PNG exported by weft)",
                       description="Reproduce a recipe: the same method, parameters, inputs and seed.")
    r.add_argument("recipe", metavar="RECIPE", help="recipe JSON file, or a PNG exported by weft")
    _add_common(r)
    r.set_defaults(method=None)
    from app.batch_cli import add_batch_parser

    add_batch_parser(sub)
    return parser


def _check_output(output: str, inputs: Sequence[str]) -> Path:
    out = Path(output)
    if out.suffix.lower() not in SAVE_EXTENSIONS:
        raise WeftError(f"{output}: cannot save this format (use {', '.join(SAVE_EXTENSIONS)})")
    if out.is_dir():
        raise WeftError(f"{output}: is a directory")
    parent = out.parent if str(out.parent) else Path(".")
    if not parent.is_dir():
        raise WeftError(f"{output}: folder {parent} does not exist")
    real_out = os.path.realpath(out)
    for src in inputs:
        if os.path.realpath(src) == real_out:
            raise WeftError(f"{output}: refusing to overwrite the input file {src}")
    return out


def _parse_int(text: str | None, name: str, lo: int, hi: int) -> int | None:
    if text is None:
        return None
    from core.params import out_of_range

    try:
        value = int(text)
    except ValueError:
        raise WeftError(f"parameter '{name}' = {text!r} must be an integer") from None
    if not lo <= value <= hi:
        raise out_of_range(name, value, lo, hi)
    return value


def _parse_bit_depth(args: argparse.Namespace) -> int:
    bit_depth = _parse_int(args.bit_depth, "bit-depth", 8, 16)
    if bit_depth not in (8, 16):
        raise WeftError(f"parameter 'bit-depth' = {bit_depth} must be 8 or 16")
    return bit_depth


def _execute(method_name: str, params_dict: dict, input_paths: dict[str, str], seed: int | None,
             args: argparse.Namespace, region: tuple[int, int, int] | None = None) -> int:
    from core import registry
    from core.image import save_image
    from core.run import output_recipe, render

    method = registry.get(method_name)
    params = method.params.from_dict(params_dict)
    bit_depth = _parse_bit_depth(args)
    out = _check_output(args.output, list(input_paths.values()))
    if bit_depth == 16 and out.suffix.lower() in (".jpg", ".jpeg"):
        raise WeftError(f"{args.output}: JPEG cannot hold 16 bits per channel (use .png or .tif)")
    if seed is None:
        seed = secrets.randbits(31)

    bar = _TerminalProgress(not args.quiet)
    try:
        result, seconds = render(method, params, input_paths, seed, region, progress=bar)
    finally:
        bar.close()
    recipe = output_recipe(method, params, input_paths, seed, region, out)
    save_image(out, result.image, recipe=recipe.to_json(), bit_depth=bit_depth)
    if args.report:
        h, w = result.image.shape[:2]
        line = {"method": method.name, "seconds": round(seconds, 6), "size": [w, h], "seed": seed}
        line.update(result.figures)
        print(json.dumps(line), flush=True)
    return 0


def _dispatch(args: argparse.Namespace) -> int:
    from core import registry
    from core.image import parse_square

    if args.command == "batch":
        from app.batch_cli import run_batch

        return run_batch(args)
    if args.command == "run":
        from core.run import check_recipe, load_recipe

        recipe = load_recipe(args.recipe)
        try:  # what the recipe itself gets wrong is said with the recipe's name in front
            params = check_recipe(recipe, Path(args.recipe).resolve().parent)
        except WeftError as e:
            raise WeftError(f"{args.recipe}: {e}") from None
        if args.seed is not None:
            seed = _parse_int(args.seed, "seed", 0, 2**63 - 1)
        else:
            seed = recipe.seed
        region = parse_square(args.region) if args.region is not None else recipe.region
        return _execute(recipe.method, params, dict(recipe.inputs), seed, args, region)

    method = registry.get(args.method)

    values = {}
    for spec in specs(method.params):
        text = getattr(args, "param_" + spec.name)
        if text is not None:
            values[spec.name] = spec.parse(text)
    params = method.params(**values)  # validates cross-parameter rules before any image is read
    inputs = {}
    for inp in method.inputs:
        value = getattr(args, inp.name, None)
        if value is not None:
            inputs[inp.name] = value
    seed = _parse_int(args.seed, "seed", 0, 2**63 - 1)
    region = parse_square(args.region) if args.region is not None else None
    return _execute(method.name, params.to_dict(), inputs, seed, args, region)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``weft`` console script; returns the exit status."""
    argv = list(sys.argv[1:] if argv is None else argv)
    if not argv:
        from app.gui import run_gui

        return run_gui()
    try:
        from core import registry

        parser = build_parser(only=argv[0] if argv[0] in registry.names() else None)
        args = parser.parse_args(argv)
        if args.command is None:
            raise UsageError("weft: no command given (see 'weft --help')")
        return _dispatch(args)
    except WeftError as e:
        print(f"weft: {e}".replace("weft: weft", "weft"), file=sys.stderr)
        return 2
    except MemoryError:
        print("weft: out of memory (try a smaller size or a smaller input)", file=sys.stderr)
        return 2
    except (KeyboardInterrupt, Cancelled):
        print("weft: cancelled", file=sys.stderr)
        return 130
    except Exception as e:  # a bug in weft, not bad input: still one line unless asked for more
        if os.environ.get("WEFT_DEBUG"):
            raise
        print(f"weft: internal error: {type(e).__name__}: {e} (set WEFT_DEBUG=1 for the traceback)", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
