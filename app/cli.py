"""The ``weft`` command.

``weft`` with no arguments opens the desktop studio (``weft IMAGE [TARGET]``: on those images);
``weft METHOD INPUT... -o OUT [options]`` runs a method headless; ``weft run RECIPE -o OUT`` reproduces
a recipe (a ``.json`` file, or a PNG exported by weft, which carries its recipe);
``weft batch RECIPE --over INPUT FILES -o PATTERN`` applies it to many files
(:mod:`weft.app.batch_cli`). Method options are generated from the method's ``Params`` specs, so the
CLI and the GUI share one definition of every parameter and its range.

Contract: any bad input (a file, a parameter, a geometry) prints exactly one line on stderr and exits
with status 2, with no traceback and no output file. ``--report`` prints exactly one JSON line on
stdout: ``{"method", "seconds", "size", "seed", ...method figures}`` where ``seconds`` is the compute
time only (no imports, no image I/O).
"""

from __future__ import annotations

import os
import signal
import sys
import threading


def _interrupted_while_starting(signum, frame) -> None:
    """Ctrl-C while the modules below load (before ``main`` can catch it): one line, no traceback."""
    sys.stderr.write("weft: cancelled\n")
    sys.stderr.flush()
    os._exit(130)


if (
    signal.getsignal(signal.SIGINT) is signal.default_int_handler
    and threading.current_thread() is threading.main_thread()
):
    signal.signal(signal.SIGINT, _interrupted_while_starting)


#: The least address space (``ulimit -v``) weft runs its methods in: below it, loading the numerical
#: libraries fails in many ways, and SciPy's OpenBLAS can retry a failing allocation forever.
MIN_ADDRESS_SPACE = 768 * 2**20


from weft.core.limits import address_space_limit as _address_space_limit  # noqa: E402 (stdlib only)

if _address_space_limit() is not None:
    # Under ulimit -v every thread's stack and every BLAS thread's buffers take address space: the
    # numerical libraries get one thread each (set before numpy loads), or they fail to start theirs.
    for _name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(_name, "1")

import argparse  # noqa: E402 (after the start-up Ctrl-C handler)
import dataclasses  # noqa: E402
import json  # noqa: E402
import secrets  # noqa: E402
from collections.abc import Sequence  # noqa: E402
from pathlib import Path  # noqa: E402

from weft.core import __version__  # noqa: E402 (after the start-up Ctrl-C handler)
from weft.core.errors import Cancelled, WeftError  # noqa: E402
from weft.core.params import Params, specs  # noqa: E402

from .options import parse_bit_depth as _parse_bit_depth  # noqa: E402
from .options import parse_int as _parse_int  # noqa: E402
from .terminal import PreparingLine, TerminalProgress  # noqa: E402
from .warm_up_cli import warm_up_all  # noqa: E402

SAVE_EXTENSIONS = (".png", ".jpg", ".jpeg", ".tif", ".tiff")


class UsageError(WeftError):
    """Bad command-line syntax (argparse's complaints, as one line)."""


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # argparse would print usage + message and exit itself
        raise UsageError(f"{self.prog}: {message} (see '{self.prog} --help')")


def _add_common(p: argparse.ArgumentParser, region: bool = True) -> None:
    p.add_argument(
        "-o", "--output", required=True, metavar="OUT", help="output image (.png, .jpg, .tif); PNGs carry the recipe"
    )
    p.add_argument("--seed", metavar="N", help="random seed (default: a fresh one, recorded in the recipe)")
    p.add_argument(
        "--bit-depth",
        metavar="BITS",
        help="8 or 16 bits per channel (16: PNG, TIFF); default 8 (fill: the image's own)",
    )
    if region:
        p.add_argument(
            "--region",
            metavar="X,Y,S",
            help="use only this square of the texture (top-left corner and side, pixels) as the source",
        )
    p.add_argument("--report", action="store_true", help="print one JSON line with the compute time and figures")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar")


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """The ``weft`` parser; with ``only``, just that method's subcommand (and ``run``) is built, so
    only that method's module is imported."""
    from weft.core import registry

    parser = _Parser(
        prog="weft",
        description="Example-based texture synthesis and transfer. "
        "Without arguments, opens the desktop studio; 'weft IMAGE [TARGET]' opens it "
        "on those images.",
    )
    parser.add_argument("--version", action="version", version=f"weft {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    chosen = [registry.get(only)] if only is not None else list(registry.methods().values())
    for method in chosen:
        p = sub.add_parser(method.name, help=method.summary, description=method.summary)
        for inp in method.inputs:
            if inp.is_positional:
                p.add_argument(inp.name, metavar=inp.name.upper(), help=inp.help)
            else:
                p.add_argument(
                    "--" + inp.name.replace("_", "-"),
                    dest=inp.name,
                    metavar="IMAGE",
                    required=inp.required,
                    help=inp.help,
                )
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
            metavar = spec.type.METAVAR if spec.kind == "geometry" else spec.kind.upper()
            group.add_argument(
                spec.option, dest="param_" + spec.name, metavar=metavar, help="; ".join(bits).replace("%", "%%")
            )
        if _lines_spec(method) is not None:
            p.add_argument(
                "--auto",
                action="store_true",
                help="suggest the feature lines from two families of straight lines in the photo "
                "(the recipe records the suggested lines; --report adds the confidence and the "
                "angle between the two directions)",
            )
            p.add_argument(
                "--save-lines",
                metavar="F.json",
                help="also write the feature lines used (the suggestion, with --auto) to this JSON "
                "file: edit it and pass it back with --lines",
            )
        _add_common(p, region=method.takes_region)
        p.set_defaults(method=method.name)
    w = sub.add_parser(
        "warm-up",
        help="prepare every method's compiled kernels now (installers, render nodes, CI)",
        description="Compile (or load) every method's numba kernels ahead of time, in parallel "
        "processes (one per CPU), into numba's cache, so that no later run pays the compile. "
        "Prints one line per method on stdout.",
    )
    w.add_argument("methods", nargs="*", metavar="METHOD", help="only these methods (default: all)")
    w.add_argument("--jobs", metavar="N", help="processes at once (default: the number of CPUs)")
    w.add_argument("-q", "--quiet", action="store_true", help="print nothing (errors still print)")
    w.set_defaults(method=None)
    r = sub.add_parser(
        "run",
        help="reproduce a recipe (.json, or a PNG exported by weft)",
        description="Reproduce a recipe: the same method, parameters, inputs and seed.",
    )
    r.add_argument("recipe", metavar="RECIPE", help="recipe JSON file, or a PNG exported by weft")
    _add_common(r)
    r.set_defaults(method=None)
    from weft.app.batch_cli import add_batch_parser

    add_batch_parser(sub)
    return parser


def _lines_spec(method):
    """The method's feature-lines parameter (its spec), or None: such a method takes ``--auto``."""
    from weft.core.geometry import FeatureLines

    return next((sp for sp in specs(method.params) if sp.kind == "geometry" and sp.type is FeatureLines), None)


def _suggest(method, params: Params, inputs: dict[str, str], args: argparse.Namespace) -> tuple[Params, dict]:
    """``--auto``: the feature lines suggested for the method's first input, in ``params``; the
    suggestion's figures for ``--report``."""
    from weft.core.image import load_image
    from weft.core.rectify import suggest_lines

    spec = _lines_spec(method)
    if getattr(params, spec.name) is not None:
        raise UsageError(f"weft {method.name}: give --{spec.name} or --auto, not both")
    first = method.inputs[0].name
    if first not in inputs:
        raise UsageError(f"weft {method.name}: --auto needs the {first}")
    photo = load_image(inputs[first]).image
    try:
        suggestion = suggest_lines(photo)
    except WeftError as e:
        raise WeftError(f"{inputs[first]}: {e}") from None
    return params.replace(**{spec.name: suggestion.lines}), suggestion.report()


def _check_output(output: str, inputs: Sequence[str]) -> Path:
    """Everything about ``-o`` that can be checked before the work: its format, its folder, and that
    it is none of the files the run reads (compared by device and inode: another path to an input,
    through a link or a second mount of its folder, is the input)."""
    from weft.core.readfile import file_key, kind_of, shown

    out = Path(output)
    name = shown(output)
    if out.suffix.lower() not in SAVE_EXTENSIONS:
        raise WeftError(f"{name}: cannot save this format (use {', '.join(SAVE_EXTENSIONS)})")
    try:
        kind = kind_of(os.stat(out).st_mode)
    except FileNotFoundError:
        kind = None
    except OSError as e:  # a symbolic link loop, a folder in the path that is a file, no permission
        raise WeftError(f"{name}: cannot write there ({e.strerror or e})") from None
    if kind == "a directory":
        raise WeftError(f"{name}: is a directory")
    if kind is not None:
        raise WeftError(f"{name}: is {kind}, not an image file; not replaced")
    parent = out.parent if str(out.parent) else Path(".")
    if not parent.is_dir():
        raise WeftError(f"{name}: folder {shown(parent)} does not exist")
    key = file_key(out)
    for src in inputs:
        if file_key(src) == key:
            raise WeftError(f"{name}: refusing to overwrite the input file {shown(src)}")
    return out


def _execute(
    method_name: str,
    params_dict: dict,
    input_paths: dict[str, str],
    seed: int | None,
    args: argparse.Namespace,
    region: tuple[int, int, int] | None = None,
    extra: dict | None = None,
    read_too: Sequence[str] = (),
) -> int:
    from weft.core import registry
    from weft.core.geometry import Square
    from weft.core.image import save_image
    from weft.core.image.temporaries import remove_stale_temporaries
    from weft.core.request import RenderRequest
    from weft.core.run import output_recipe

    method = registry.get(method_name)
    # typed parameters (a method's own command line) or their JSON form (a recipe's, read at its edge)
    params = params_dict if isinstance(params_dict, Params) else method.params.from_dict(params_dict)
    bit_depth = _parse_bit_depth(args) if args.bit_depth is not None else None  # None: see below
    out = _check_output(args.output, [*input_paths.values(), *read_too])  # read_too: the recipe file
    save_lines = _check_lines_file(
        method, params, getattr(args, "save_lines", None), [*input_paths.values(), *read_too, out]
    )
    if bit_depth == 16 and out.suffix.lower() in (".jpg", ".jpeg"):
        raise WeftError(f"{args.output}: JPEG cannot hold 16 bits per channel (use .png or .tif)")
    if seed is None:
        seed = secrets.randbits(31)

    bar = TerminalProgress(not args.quiet)
    preparing = PreparingLine(method.name, bar)
    try:
        with registry.watch_compiles(on_start=preparing):  # a kernel compiling: say so on the terminal
            # Loading every kernel up front only keeps --report's "seconds" free of cache loads; without
            # --report a run loads (or, first time, compiles) just the kernels it uses.
            request = RenderRequest(
                method,
                params,
                input_paths,
                seed,
                None if region is None else Square(*region),
                warm_up=args.report and method.warm_up_in_cli,
            )
            rendered = request.run(progress=bar)
    finally:
        preparing.stop()
        bar.close()
    notice = registry.kernel_cache_notice()
    if notice is not None and not args.quiet:
        print(f"weft: {notice}", file=sys.stderr)
    for repair in registry.kernel_cache_repairs() if not args.quiet else ():
        print(f"weft: {repair}", file=sys.stderr)
    if bit_depth is None:  # not asked for: 8, or the bit depth of the input the method names (fill: the image)
        info = rendered.infos.get(method.depth_from) if method.depth_from else None
        jpeg = out.suffix.lower() in (".jpg", ".jpeg")
        bit_depth = info.bit_depth if info is not None and not jpeg else 8
    recipe = output_recipe(method, params, input_paths, seed, region, out)
    if args.bit_depth is not None:  # asked for (or a recipe's): recorded, so weft run writes it again
        recipe = dataclasses.replace(recipe, bit_depth=bit_depth)
    remove_stale_temporaries([out])  # a killed earlier run's half-written file beside it
    save_image(out, rendered.image, recipe=recipe.to_json(), bit_depth=bit_depth)
    if save_lines is not None:
        from weft.core.image import atomic_write_bytes

        atomic_write_bytes(save_lines[0], (save_lines[1].to_text() + "\n").encode("utf-8"))
    if args.report:
        h, w = rendered.image.shape[:2]
        line = {"method": method.name, "seconds": round(rendered.seconds, 6), "size": [w, h], "seed": seed}
        line.update(rendered.figures)
        line.update(extra or {})
        print(json.dumps(line), flush=True)
    return 0


def _check_lines_file(method, params: Params, path: str | None, others: Sequence) -> tuple[Path, object] | None:
    """``--save-lines F.json``: where to write which lines (checked before any work), or None."""
    if path is None:
        return None
    lines = getattr(params, _lines_spec(method).name)
    if lines is None:
        raise UsageError(f"weft {method.name}: --save-lines needs --lines or --auto (there are no lines to save)")
    target = Path(path)
    if target.suffix.lower() != ".json":
        raise WeftError(f"{path}: feature lines are saved as .json")
    parent = target.parent if str(target.parent) else Path(".")
    if target.is_dir() or not parent.is_dir():
        raise WeftError(f"{path}: " + ("is a directory" if target.is_dir() else f"folder {parent} does not exist"))
    from weft.core.readfile import file_key

    key = file_key(target)  # by device and inode: another path to an input is that input
    if any(file_key(o) == key for o in others):
        raise WeftError(f"{path}: refusing to overwrite an input or the output")
    return target, lines


def _dispatch(args: argparse.Namespace) -> int:
    from weft.core import registry
    from weft.core.geometry import Square

    if args.command == "batch":
        from weft.app.batch_cli import run_batch

        return run_batch(args)
    if args.command == "warm-up":
        return warm_up_all(args)
    if args.command == "run":
        from weft.core.run import check_recipe, load_recipe

        recipe = load_recipe(args.recipe)
        try:  # what the recipe itself gets wrong is said with the recipe's name in front
            params = check_recipe(recipe, Path(args.recipe).resolve().parent)
        except WeftError as e:
            raise WeftError(f"{args.recipe}: {e}") from None
        if args.seed is not None:
            seed = _parse_int(args.seed, "seed", 0, 2**63 - 1)
        else:
            seed = recipe.seed
        region = Square.parse(args.region) if args.region is not None else recipe.region
        if (
            args.bit_depth is None
            and recipe.bit_depth is not None
            and Path(args.output).suffix.lower() not in (".jpg", ".jpeg")
        ):
            args.bit_depth = str(recipe.bit_depth)  # the depth the recipe's output was written at
        return _execute(recipe.method, params, dict(recipe.inputs), seed, args, region, read_too=[args.recipe])

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
    region = Square.parse(args.region) if getattr(args, "region", None) is not None else None
    extra = None
    if getattr(args, "auto", False):
        _check_output(args.output, list(inputs.values()))  # a wrong output is said before the suggestion's work
        params, extra = _suggest(method, params, inputs, args)
    return _execute(method.name, params, inputs, seed, args, region, extra)


def _reuse_freed_memory() -> None:
    """glibc's allocator told to keep freed memory for the next allocation: blocks under 32 MiB come
    from the heap (``M_MMAP_THRESHOLD``), and the heap is given back only past 256 MiB free
    (``M_TRIM_THRESHOLD``). A ``weft fill`` allocates and frees thousands of small numpy
    temporaries; by default each gets fresh pages from the kernel, paying page faults and trims.
    (Setting the trim threshold alone would disable glibc's sliding mmap threshold.) Other C
    libraries: nothing is done."""
    if not sys.platform.startswith("linux"):
        return
    try:
        import ctypes

        libc = ctypes.CDLL("libc.so.6")
        libc.mallopt(-3, 32 << 20)  # M_MMAP_THRESHOLD
        libc.mallopt(-1, 256 << 20)  # M_TRIM_THRESHOLD
    except (OSError, AttributeError):  # not glibc (musl has no mallopt of its own)
        pass


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``weft`` console script; returns the exit status."""
    if argv is None:
        _reuse_freed_memory()
    argv = list(sys.argv[1:] if argv is None else argv)
    if not argv:
        from weft.app.gui import run_gui

        return run_gui()
    if len(argv) <= 2 and all(not a.startswith("-") and Path(a).is_file() for a in argv):
        # weft IMAGE [TARGET]: the studio on those images (the current method's first inputs)
        from weft.app.gui import run_gui

        return run_gui(images=argv)
    limit = _address_space_limit()
    if limit is not None and limit < MIN_ADDRESS_SPACE and not any(a in ("-h", "--help", "--version") for a in argv):
        print(
            f"weft: out of memory: the address-space limit (ulimit -v) of {limit / 2**20:.0f} MiB is below the "
            f"{MIN_ADDRESS_SPACE // 2**20} MiB weft needs to load its libraries (raise it with ulimit -v)",
            file=sys.stderr,
        )
        return 2
    try:
        from weft.core import registry

        parser = build_parser(only=argv[0] if argv[0] in registry.names() else None)
        args = parser.parse_args(argv)
        if args.command is None:
            raise UsageError("weft: no command given (see 'weft --help')")
        return _dispatch(args)
    except WeftError as e:
        from weft.core.readfile import one_line

        print(one_line(f"weft: {e}".replace("weft: weft", "weft")), file=sys.stderr)
        return 2
    except MemoryError:
        limit = _address_space_limit()
        under = f" under the address-space limit (ulimit -v) of {limit / 2**20:.0f} MiB" if limit is not None else ""
        print(f"weft: out of memory{under} (try a smaller size or a smaller input)", file=sys.stderr)
        return 2
    except (KeyboardInterrupt, Cancelled):
        print("weft: cancelled", file=sys.stderr)
        return 130
    except Exception as e:  # a bug in weft, not bad input: still one line unless asked for more
        if os.environ.get("WEFT_DEBUG"):
            raise
        limit = _address_space_limit()
        if limit is not None:  # libraries fail in many ways when an allocation or a load is refused
            from weft.core.readfile import one_line

            print(
                one_line(
                    f"weft: out of memory: the address-space limit (ulimit -v) of {limit / 2**20:.0f} MiB "
                    f"is too small for this job ({type(e).__name__}: {e})"
                )[:400],
                file=sys.stderr,
            )
            return 2
        from weft.core.readfile import one_line

        print(
            one_line(f"weft: internal error: {type(e).__name__}: {e} (set WEFT_DEBUG=1 for the traceback)"),
            file=sys.stderr,
        )
        return 1


if signal.getsignal(signal.SIGINT) is _interrupted_while_starting:
    signal.signal(signal.SIGINT, signal.default_int_handler)  # loaded: from here on main() catches Ctrl-C


if __name__ == "__main__":
    sys.exit(main())
