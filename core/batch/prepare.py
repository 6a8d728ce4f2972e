"""What a batch is and what can be checked before any work: its items (:func:`plan`), their
memory (:func:`check_memory`), and the records of outcomes and progress (see :mod:`weft.core.batch`)."""

from __future__ import annotations

import glob
import json
import os
import re
import secrets
import string
import time
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import WeftError
from ..limits import LimitError, _bytes, available_memory
from ..readfile import file_key, kind_of, open_regular, shown

#: File extensions a folder given to ``--over`` contributes (what :func:`weft.core.image.load_image` reads).
IMAGE_EXTENSIONS = (".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp", ".webp", ".gif")
#: Output extensions (what :func:`weft.core.image.save_image` writes).
SAVE_EXTENSIONS = (".png", ".jpg", ".jpeg", ".tif", ".tiff")


# --------------------------------------------------------------------------------------------------
# Items and outcomes (what crosses to a worker and back: plain, picklable values)


@dataclass(frozen=True)
class Item:
    """One output of a batch: everything a worker needs, with absolute paths.

    ``inputs`` are the files to read (``shipped`` holds their bytes when the client sends them);
    ``recipe`` is the JSON text the output carries (paths relative to the output's folder, as
    ``weft run`` writes it); ``write`` says whether the worker writes ``output`` itself or returns the
    encoded bytes for the client to write.
    """

    index: int
    label: str
    method: str
    params: Mapping[str, Any]
    inputs: Mapping[str, str]
    seed: int
    region: tuple[int, int, int] | None
    output: str
    recipe: str
    bit_depth: int = 8
    write: bool = True
    shipped: Mapping[str, bytes] | None = None
    #: OpenCV threads in the worker process (local pool: the cores shared out among the workers, so
    #: two workers on two cores do not each start two threads); None leaves OpenCV's default. The
    #: pixels do not depend on it (checked for every method: 1 and 2 threads give the same bytes).
    threads: int | None = None


@dataclass(frozen=True)
class Outcome:
    """What became of one item: ``status`` is ``"written"``, ``"skipped"`` (its output already
    exists with this recipe) or ``"failed"`` (``error`` says why, in one line)."""

    index: int
    label: str
    output: str
    status: str
    error: str | None = None
    seconds: float = 0.0
    figures: Mapping[str, Any] = field(default_factory=dict)
    worker: str = ""
    data: bytes | None = None
    #: The item's whole time on its worker: reading, running, encoding, writing (``seconds`` is the
    #: method's compute alone, as ``weft run --report`` gives it), and the CPU time its process used
    #: meanwhile (all its threads).
    elapsed: float = 0.0
    cpu: float = 0.0

    def report(self) -> dict:
        """The item's ``--report`` line (without the encoded bytes)."""
        line = {"index": self.index, "input": self.label, "output": self.output, "status": self.status}
        if self.error is not None:
            line["error"] = self.error
        if self.status == "written":
            line["seconds"] = round(self.seconds, 6)
            line["elapsed"] = round(self.elapsed, 6)
            line["cpu"] = round(self.cpu, 6)
            line["worker"] = self.worker
            line.update(self.figures)
        return line


@dataclass(frozen=True)
class Plan:
    """A checked batch: every item in order, and which of them are already done."""

    items: tuple[Item, ...]
    skipped: tuple[Item, ...]
    method: str
    seed: int
    ship_inputs: bool = False  # read each item's inputs here and send their bytes (just before it is submitted)

    @property
    def todo(self) -> tuple[Item, ...]:
        done = {i.index for i in self.skipped}
        return tuple(i for i in self.items if i.index not in done)


@dataclass
class Summary:
    """The end of a batch: counts, failures (index, label, reason) in item order, wall time."""

    total: int
    written: int = 0
    skipped: int = 0
    failed: list[tuple[int, str, str]] = field(default_factory=list)
    cancelled: bool = False
    seconds: float = 0.0

    @property
    def done(self) -> int:
        return self.written + self.skipped + len(self.failed)

    def line(self, most: int = 3) -> str:
        """``898 written, 2 failed: frame_0312.png: truncated PNG …``"""
        parts = [f"{self.written} written"]
        if self.skipped:
            parts.append(f"{self.skipped} already done")
        if self.cancelled:
            parts.append(f"{self.total - self.done} not done (cancelled)")
        text = ", ".join(parts)
        if self.failed:
            reasons = "; ".join(f"{label}: {reason}" for _, label, reason in self.failed[:most])
            more = f"; and {len(self.failed) - most} more" if len(self.failed) > most else ""
            text += f", {len(self.failed)} failed: {reasons}{more}"
        return text

    def report(self) -> dict:
        """The summary ``--report`` line."""
        return {
            "summary": True,
            "total": self.total,
            "written": self.written,
            "skipped": self.skipped,
            "failed": len(self.failed),
            "cancelled": self.cancelled,
            "seconds": round(self.seconds, 3),
            "items_per_second": round(self.written / self.seconds, 4) if self.seconds > 0 else None,
        }


class BatchProgress:
    """Progress of a running batch, handed to :func:`run`'s ``progress`` after each item."""

    __slots__ = ("total", "done", "failed", "started", "_timed", "_first")
    _first: float | None

    def __init__(self, total: int, skipped: int):
        self.total, self.done, self.failed = total, skipped, 0
        self.started = time.monotonic()
        self._timed, self._first = 0, None

    def _add(self, outcome: Outcome) -> None:
        self.done += 1
        self.failed += outcome.status == "failed"
        if outcome.status != "skipped":
            self._timed += 1
            if self._first is None:
                self._first = time.monotonic()

    @property
    def seconds_left(self) -> float | None:
        """Time left at the rate items have completed since the first one (so the workers' start-up
        does not count); None before two are done."""
        if self._timed < 2 or self._first is None:
            return None
        rate = (self._timed - 1) / max(1e-9, time.monotonic() - self._first)
        return (self.total - self.done) / rate


# --------------------------------------------------------------------------------------------------
# Planning: everything that can be wrong about the batch as a whole, before any work


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
    from .. import registry
    from ..run import check_recipe, load_recipe, output_recipe

    own_file = recipe is None  # the recipe is read from recipe_path: that file is an input too
    if recipe is None:
        recipe = load_recipe(recipe_path)
    base = Path(recipe_path).resolve().parent
    if not over:
        raise WeftError("no --over INPUT FILES given: name the input the files replace")
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
    params = method.params.from_dict(params_dict)
    if bit_depth is not None and bit_depth not in (8, 16):
        raise WeftError(f"parameter 'bit-depth' = {bit_depth} must be 8 or 16")

    lists = {name: expand_over(name, where) for name, where in over}
    counts = {len(v) for v in lists.values()}
    if len(counts) > 1:
        raise WeftError(
            "the --over lists differ in length ("
            + ", ".join(f"{name}: {len(v)} files" for name, v in lists.items())
            + "); they are taken in step, file by file"
        )
    n = counts.pop()

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

    first = names[0]
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

    if seed is None:
        seed = recipe.seed
    if seed is None:
        found = _existing_seed([(i, out) for i, _, _, out in rows], method.name)
        if found is not None:
            seed = (found[1] - (found[0] if seed_per_item else 0)) % 2**63
        else:
            seed = secrets.randbits(31)

    items = []
    for i, label, inputs, out in rows:
        item_seed = (seed + i) % 2**63 if seed_per_item else seed
        text = output_recipe(method, params, inputs, item_seed, recipe.region, out).to_json()
        items.append(
            Item(
                index=i,
                label=label,
                method=method.name,
                params=params_dict,
                inputs=inputs,
                seed=item_seed,
                region=recipe.region,
                output=out,
                recipe=text,
                bit_depth=_item_bit_depth(method, inputs, out, bit_depth),
                write=not ship_outputs,
            )
        )
    skipped = () if force else tuple(it for it in items if _done_already(it))
    return Plan(items=tuple(items), skipped=skipped, method=method.name, seed=seed, ship_inputs=ship_inputs)


def _header_shape(path: str) -> tuple[int, ...] | None:
    """(H, W) or (H, W, 3) of an image file from its header, or None if it cannot be read."""
    from ..image.files import _GREY_MODES, _pil_open

    try:
        with open_regular(path, "image file") as f:
            im, _ = _pil_open(open(os.dup(f.fileno()), "rb"))
        with im:
            w, h = im.size
            return (h, w) if im.mode in _GREY_MODES else (h, w, 3)
    except Exception:  # noqa: BLE001 - a bad file fails its own item, with its own message
        return None


def item_memory(items: Iterable[Item]) -> tuple[float, str]:
    """The largest estimated peak memory of one item (``Method.memory`` on the inputs' header sizes).

    Parameters
    ----------
    items : iterable of Item
        The batch's items (one method).

    Returns
    -------
    bytes : float
        The largest estimate; 0 when the method gives none.
    label : str
        That item's label ("" with no estimate).
    """
    from .. import registry

    best, label = 0.0, ""
    items = list(items)
    if not items:
        return best, label
    method = registry.get(items[0].method)
    if method.memory is None:
        return best, label
    params = method.params.from_dict(items[0].params)
    for item in items:
        found = {name: _header_shape(path) for name, path in item.inputs.items()}
        shapes = {name: s for name, s in found.items() if s is not None}
        if len(shapes) < len(found):
            continue
        if item.region is not None:
            first = method.inputs[0].name
            side = item.region[2]
            shapes[first] = (side, side) + tuple(shapes[first][2:])
        try:
            need = float(method.memory(shapes, params))
        except (WeftError, KeyError, TypeError, ValueError):
            continue  # the item's own run refuses it with the precise reason
        if need > best:
            best, label = need, item.label
    return best, label


def too_large_alone(items: Iterable[Item], *, available: int | None = None) -> list[tuple[Item, str]]:
    """The items that cannot run even alone, each with its one-line reason.

    An input whose header claims more pixels than the pixel limit, or an estimated peak memory above
    ``available``. They fail by themselves; the rest of the batch runs.

    Parameters
    ----------
    items : iterable of Item
        The batch's items.
    available : int, optional
        Bytes of memory; default what the system has available now.

    Returns
    -------
    list of (Item, str)
    """
    from .. import registry
    from ..image import get_max_pixels

    items = list(items)
    if not items:
        return []
    method = registry.get(items[0].method)
    params = method.params.from_dict(items[0].params) if method.memory is not None else None
    available = available_memory() if available is None else available
    limit = get_max_pixels()
    alone = []
    for item in items:
        shapes = {name: _header_shape(path) for name, path in item.inputs.items()}
        big = next(((name, s) for name, s in shapes.items() if s is not None and s[0] * s[1] > limit), None)
        if big is not None:
            name, (h, w) = big[0], big[1][:2]
            alone.append(
                (
                    item,
                    f"{shown(item.inputs[name])}: {w}x{h} = {w * h / 1e6:.1f} megapixels exceeds the "
                    f"limit of {limit / 1e6:g} megapixels (set WEFT_MAX_PIXELS to raise it)",
                )
            )
            continue
        known = {name: s for name, s in shapes.items() if s is not None}
        if method.memory is None or params is None or available is None or len(known) < len(shapes):
            continue
        if item.region is not None:
            first = method.inputs[0].name
            known[first] = (item.region[2], item.region[2]) + tuple(known[first][2:])
        try:
            need = float(method.memory(known, params))
        except (WeftError, KeyError, TypeError, ValueError):
            continue
        if need > available:
            alone.append(
                (
                    item,
                    f"needs about {_bytes(need)} of memory, {_bytes(available)} is available: make its inputs smaller",
                )
            )
    return alone


def workers_that_fit(items: Iterable[Item], workers: int, *, available: int | None = None) -> int:
    """How many workers fit in memory at once by the largest item's estimate.

    Parameters
    ----------
    items : iterable of Item
        The batch's items.
    workers : int
        The most workers wanted.
    available : int, optional
        Bytes of memory; default what the system has available now.

    Returns
    -------
    int
        At most ``workers``, at least 1.
    """
    need, _ = item_memory(items)
    available = available_memory() if available is None else available
    if not need or available is None:
        return workers
    return max(1, min(workers, int(available // need)))


def check_memory(
    items: Iterable[Item], workers: int, *, available: int | None = None, option: str = "--workers"
) -> None:
    """Refuse up front a batch whose largest item's estimate times ``workers`` exceeds the memory.

    Parameters
    ----------
    items : iterable of Item
        The batch's items.
    workers : int
        The workers that would run at once.
    available : int, optional
        Bytes of memory; default what the system has available now.
    option : str, default "--workers"
        The option to name in the advice.

    Raises
    ------
    LimitError
        Saying how many workers would fit.
    """
    need, label = item_memory(items)
    available = available_memory() if available is None else available
    if not need or available is None or need * workers <= available:
        return
    fits = int(available // need)
    advice = f"use {option} {fits}" if fits >= 1 else "make the inputs smaller (even one item does not fit)"
    raise LimitError(
        f"batch: one item ({label}) needs about {_bytes(need)} of memory, {workers} workers at once "
        f"{_bytes(need * workers)}, {_bytes(available)} is available: {advice}"
    )
