"""What a batch is and what can be checked before any work: its items (:func:`plan`), their
memory (:func:`check_memory`, in :mod:`.memory`), and the records of outcomes and progress (in
:mod:`.items`; see :mod:`weft.core.batch`). Every name of the two is importable from here too."""

from __future__ import annotations

import glob
import json
import os
import re
import secrets
import string
from collections.abc import Mapping, Sequence
from pathlib import Path

from ..errors import WeftError
from ..readfile import file_key, kind_of, open_regular, shown
from .items import BatchProgress, Item, Outcome, Plan, Summary
from .memory import _header_shape, check_memory, item_memory, too_large_alone, workers_that_fit

__all__ = [
    "IMAGE_EXTENSIONS",
    "SAVE_EXTENSIONS",
    "BatchProgress",
    "Item",
    "Outcome",
    "Plan",
    "Summary",
    "check_memory",
    "expand_over",
    "item_memory",
    "plan",
    "too_large_alone",
    "workers_that_fit",
    "_header_shape",
]

#: File extensions a folder given to ``--over`` contributes (what :func:`weft.core.image.load_image` reads).
IMAGE_EXTENSIONS = (".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp", ".webp", ".gif")
#: Output extensions (what :func:`weft.core.image.save_image` writes).
SAVE_EXTENSIONS = (".png", ".jpg", ".jpeg", ".tif", ".tiff")


def _natural_key(path: str):
    return [int(t) if t.isdigit() else t.lower() for t in re.split(r"(\d+)", os.path.basename(path))] + [path]


def expand_over(name: str, where: str) -> list[str]:
    """The files of one ``--over``, in natural order (``frame_2`` before ``frame_10``).

    Parameters
    ----------
    name : str
        The recipe input it replaces, for messages.
    where : str
        A folder (its image files), a glob (its matches) or one file.

    Returns
    -------
    list of str

    Raises
    ------
    WeftError
        Nothing matches.
    """
    if os.path.isdir(where):
        files = [
            str(Path(where) / f)
            for f in os.listdir(where)
            if not f.startswith(".") and f.lower().endswith(IMAGE_EXTENSIONS) and (Path(where) / f).is_file()
        ]
        if not files:
            raise WeftError(f"--over {name} {where}: the folder holds no image files ({', '.join(IMAGE_EXTENSIONS)})")
    elif glob.has_magic(where):
        files = [f for f in glob.glob(where) if os.path.isfile(f)]
        if not files:
            raise WeftError(f"--over {name} {where}: matches no files")
    elif os.path.isfile(where):
        files = [where]
    else:
        raise WeftError(f"--over {name} {where}: no such file or folder")
    return sorted(files, key=_natural_key)


def _pattern_fields(pattern: str) -> list[str]:
    try:
        return [f for _, f, _, _ in string.Formatter().parse(pattern) if f is not None]
    except ValueError as e:
        raise WeftError(f"pattern {pattern!r}: {e}") from None


def _format(pattern: str, values: dict) -> str:
    try:
        return pattern.format(**values)
    except (ValueError, TypeError, IndexError, KeyError, AttributeError) as e:
        raise WeftError(f"pattern {pattern!r}: {' '.join(str(e).split())}") from None


def _png_bit_depth(path: str) -> int | None:
    with open_regular(path, "PNG file") as f:
        head = f.read(26)
    return head[24] if len(head) == 26 and head[12:16] == b"IHDR" else None


def _item_bit_depth(method, inputs: Mapping[str, str], output: str, asked: int | None) -> int:
    """An item's output bit depth: ``asked``, else what ``weft METHOD`` writes without ``--bit-depth``
    (the depth of the input the method keeps it from, ``Method.depth_from``; else 8; JPEG 8)."""
    from ..image import file_bit_depth

    if asked is not None:
        return asked
    source = inputs.get(method.depth_from) if method.depth_from else None
    if source is None or output.lower().endswith((".jpg", ".jpeg")):
        return 8
    return file_bit_depth(source) or 8


def _done_already(item: Item) -> bool:
    """The output exists, is a whole PNG (every chunk's CRC checked, up to its end: an interrupted copy
    is not done) of the item's bit depth and carries exactly the item's recipe."""
    from ..image import read_recipe
    from ..image.files import png_is_whole

    if not item.output.lower().endswith(".png") or not os.path.isfile(item.output):
        return False
    try:
        return (
            read_recipe(item.output) == item.recipe
            and _png_bit_depth(item.output) == item.bit_depth
            and png_is_whole(item.output)
        )
    except (WeftError, OSError):
        return False


def _existing_seed(outputs: Sequence[tuple[int, str]], method: str) -> tuple[int, int] | None:
    """(index, seed) of the first existing output carrying a recipe of ``method`` (a resumed batch
    whose recipe has no seed keeps the seed its first run drew)."""
    from ..image import read_recipe

    for index, out in outputs:
        if out.lower().endswith(".png") and os.path.isfile(out):
            try:
                data = json.loads(read_recipe(out) or "null")
            except (WeftError, OSError, ValueError):
                continue
            if isinstance(data, dict) and data.get("method") == method and isinstance(data.get("seed"), int):
                return index, data["seed"]
    return None


def plan(
    recipe_path: str,
    over: Sequence[tuple[str, str]],
    pattern: str,
    *,
    seed: int | None = None,
    seed_per_item: bool = False,
    force: bool = False,
    bit_depth: int | None = None,
    ship_inputs: bool = False,
    ship_outputs: bool = False,
    recipe=None,
) -> Plan:
    """Check a batch and list its items.

    Parameters
    ----------
    recipe_path : str
        A recipe ``.json`` or a PNG exported by weft (its relative paths resolve against its folder).
        With ``recipe`` (a :class:`~weft.core.params.Recipe` with absolute paths, e.g. the studio's), the
        path is only used in messages and as the folder file parameters resolve against.
    over : sequence of (input name, folder / glob / file)
        Each replaces that input of the recipe, file by file; several zip together (equal lengths).
    pattern : str
        Output path with ``{stem}`` and ``{name}`` (stem and name of the first ``over`` file),
        ``{index}`` (0-based position, e.g. ``{index:04d}``), and ``{INPUT}`` for each over input
        (the stem of its file, e.g. ``{target}``). Missing folders are created.
    seed : int, optional
        Instead of the recipe's seed. Without either, one is drawn (or taken from a previous run's
        outputs, so a resumed batch keeps its look).
    seed_per_item : bool
        Item ``i`` gets seed ``seed + i`` instead of every item the same seed.
    force : bool
        Redo items whose output already exists with the same recipe (otherwise they are skipped).
    bit_depth : {8, 16}, optional
        Bits per channel of every output. None (the default): as ``weft METHOD`` decides it, per item:
        the bit depth of the item's input the method keeps it from (``Method.depth_from``: fill's
        image, so a 16-bit image gives a 16-bit output), else 8; a JPEG output is 8.
    ship_inputs, ship_outputs : bool
        Send the inputs' bytes with each item (workers need not see the files) / have the workers
        return the encoded outputs for this process to write (workers need not see the output folder).

    Raises
    ------
    WeftError
        Anything wrong with the batch as a whole (one line); nothing has been run or written.
    """
    from ..run import load_recipe

    own_file = recipe is None  # the recipe is read from recipe_path: that file is an input too
    if recipe is None:
        recipe = load_recipe(recipe_path)
    base = Path(recipe_path).resolve().parent
    if not over:
        raise WeftError("no --over INPUT FILES given: name the input the files replace")
    method, names, params_dict = _checked_recipe(recipe, recipe_path, base, over)
    params = method.params.from_dict(params_dict)
    if bit_depth is not None and bit_depth not in (8, 16):
        raise WeftError(f"parameter 'bit-depth' = {bit_depth} must be 8 or 16")
    lists, n = _over_lists(over)
    _check_pattern(pattern, bit_depth, lists)
    rows = _outputs(method, recipe, recipe_path, own_file, pattern, names[0], lists, n)
    seed = _batch_seed(seed, recipe.seed, rows, method.name, seed_per_item)
    items = [
        _item(
            method,
            params,
            params_dict,
            recipe.region,
            row,
            (seed + row[0]) % 2**63 if seed_per_item else seed,
            bit_depth,
            ship_outputs,
        )
        for row in rows
    ]
    skipped = () if force else tuple(it for it in items if _done_already(it))
    return Plan(items=tuple(items), skipped=skipped, method=method.name, seed=seed, ship_inputs=ship_inputs)


def _checked_recipe(recipe, recipe_path: str, base: Path, over: Sequence[tuple[str, str]]):
    """The recipe's method, the names of the inputs ``over`` replaces, and the recipe's parameters
    checked (as ``weft run`` checks them, those inputs supplied by the batch)."""
    from .. import registry
    from ..run import check_recipe

    try:
        method = registry.get(recipe.method)
        takes = [i.name for i in method.inputs]
        names = [name for name, _ in over]
        for name in names:
            if name not in takes:
                raise WeftError(f"--over {name}: {method.name} has no input {name!r} (it takes {', '.join(takes)})")
        if len(set(names)) != len(names):
            raise WeftError(f"--over names the input {next(n for n in names if names.count(n) > 1)!r} twice")
        params_dict = check_recipe(recipe, base, supplied=tuple(names))
    except WeftError as e:
        raise WeftError(f"{recipe_path}: {e}") from None
    return method, names, params_dict


def _over_lists(over: Sequence[tuple[str, str]]) -> tuple[dict[str, list[str]], int]:
    """The files of every ``--over`` by input name, and their common count."""
    lists = {name: expand_over(name, where) for name, where in over}
    counts = {len(v) for v in lists.values()}
    if len(counts) > 1:
        raise WeftError(
            "the --over lists differ in length ("
            + ", ".join(f"{name}: {len(v)} files" for name, v in lists.items())
            + "); they are taken in step, file by file"
        )
    return lists, counts.pop()


def _check_pattern(pattern: str, bit_depth: int | None, lists: Mapping[str, list[str]]) -> None:
    """The output pattern names a format weft saves (at this bit depth) and only fields it knows."""
    ext = os.path.splitext(pattern)[1].lower()
    if ext not in SAVE_EXTENSIONS:
        raise WeftError(f"pattern {pattern!r}: cannot save this format (end it with {', '.join(SAVE_EXTENSIONS)})")
    if bit_depth == 16 and ext in (".jpg", ".jpeg"):
        raise WeftError(f"pattern {pattern!r}: JPEG cannot hold 16 bits per channel (use .png or .tif)")
    allowed = ["stem", "name", "index", *lists]
    for f in _pattern_fields(pattern):
        key = re.split(r"[.\[]", f, maxsplit=1)[0]
        if key not in allowed:
            raise WeftError(
                f"pattern {pattern!r} uses {{{f}}}; it may use " + ", ".join("{" + a + "}" for a in allowed)
            )


def _outputs(
    method,
    recipe,
    recipe_path: str,
    own_file: bool,
    pattern: str,
    first: str,
    lists: Mapping[str, list[str]],
    n: int,
) -> list[tuple[int, str, dict[str, str], str]]:
    """``(index, label, inputs, output)`` of every item, refusing an output two items share, one that
    would overwrite an input or the recipe, and one that is not a file."""
    fixed = {k: str(Path(v).resolve()) for k, v in recipe.inputs.items() if k not in lists}
    rows = []
    seen: dict[str, str] = {}
    # Files are compared by identity (device and inode): an output path that reaches an input (or the
    # recipe file) through another mount of its folder or a link would overwrite it.
    read = {file_key(p): p for p in fixed.values()}
    for files in lists.values():
        read.update((file_key(p), p) for p in files)
    if own_file:
        read[file_key(recipe_path)] = recipe_path
    keys: dict[tuple, str] = {}
    for i in range(n):
        over_files = {name: lists[name][i] for name in lists}
        values = {
            "stem": Path(over_files[first]).stem,
            "name": Path(over_files[first]).name,
            "index": i,
            **{name: Path(path).stem for name, path in over_files.items()},
        }
        out = os.path.abspath(_format(pattern, values))
        label = os.path.basename(over_files[first])
        key = file_key(out)
        if out in seen or key in keys:
            raise WeftError(
                f"pattern {pattern!r} gives {shown(out)} for both {shown(seen.get(out) or keys[key])} "
                f"and {shown(label)}: add {{index}} or {{stem}} so every item has its own output"
            )
        seen[out] = keys[key] = label
        if key in read:
            what = "recipe" if own_file and read[key] == recipe_path else "input"
            raise WeftError(
                f"pattern {pattern!r}: refusing to overwrite the {what} file {shown(read[key])} (as {shown(out)})"
            )
        try:
            kind = kind_of(os.stat(out).st_mode)
        except FileNotFoundError:
            kind = None
        except OSError as e:
            raise WeftError(f"pattern {pattern!r} gives {shown(out)}: cannot write there ({e.strerror or e})") from None
        if kind is not None:
            raise WeftError(f"pattern {pattern!r} gives {shown(out)}, which is {kind}")
        inputs = {**fixed, **{k: str(Path(v).resolve()) for k, v in over_files.items()}}
        inputs = {spec.name: inputs[spec.name] for spec in method.inputs if spec.name in inputs}
        rows.append((i, label, inputs, out))
    return rows


def _batch_seed(
    seed: int | None, recipe_seed: int | None, rows: Sequence[tuple], method: str, seed_per_item: bool
) -> int:
    """The batch's seed: the one given, else the recipe's, else a previous run's (read from its
    outputs, so a resumed batch keeps its look), else a new one."""
    if seed is None:
        seed = recipe_seed
    if seed is None:
        found = _existing_seed([(i, out) for i, _, _, out in rows], method)
        if found is not None:
            seed = (found[1] - (found[0] if seed_per_item else 0)) % 2**63
        else:
            seed = secrets.randbits(31)
    return seed


def _item(
    method,
    params,
    params_dict: dict,
    region,
    row: tuple[int, str, dict[str, str], str],
    seed: int,
    bit_depth: int | None,
    ship_outputs: bool,
) -> Item:
    """One item of the batch, with the recipe its output carries."""
    from ..run import output_recipe

    i, label, inputs, out = row
    text = output_recipe(method, params, inputs, seed, region, out).to_json()
    return Item(
        index=i,
        label=label,
        method=method.name,
        params=params_dict,
        inputs=inputs,
        seed=seed,
        region=region,
        output=out,
        recipe=text,
        bit_depth=_item_bit_depth(method, inputs, out, bit_depth),
        write=not ship_outputs,
    )
