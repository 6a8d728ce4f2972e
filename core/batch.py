"""Batches: one recipe applied to many images (the frames of an animation, a folder of photos).

A batch is a recipe plus one or more *over* inputs: lists of files that replace one input of the
recipe in turn (several lists zip together), and a *pattern* naming each output
(``out/{stem}.png``, ``frame_{index:04d}.png``). :func:`plan` turns that into :class:`Item` s, checking
everything that can be wrong about the batch as a whole before any work (exit status 2 on the
command line): the recipe, the lists, the pattern (unknown fields, two items with one output, an
output that would overwrite an input). :func:`run` then runs the items

* on a local process pool (``concurrent.futures.ProcessPoolExecutor``, spawned workers, each loading
  the method's kernels once) by default, or
* on a Dask distributed cluster when given a scheduler address (``pip install -e '.[cluster]'``),

through one code path: both pools run :func:`run_item` on each item and hand back an
:class:`Outcome`. An item runs exactly as ``weft run`` on its recipe (:mod:`weft.core.run`), so its output
is byte for byte the same, recipe chunk included. An item's failure (a corrupt frame) is that
item's: it becomes a failed outcome with a one-line reason and the batch goes on. Outputs are
written atomically; an item whose output already exists with the same recipe is skipped (a re-run
resumes an interrupted batch; ``force`` redoes it). A worker that dies mid-item (killed, out of
memory) has its items run again: Dask reschedules them itself; the local pool is restarted and
its unfinished items resubmitted, up to :data:`MAX_ATTEMPTS` times each.

Memory: before any work the largest item's estimate (``Method.memory``) times the number of
workers must fit in the memory available (:mod:`weft.core.limits`); a Dask worker's own memory limit
is checked against the estimate times its threads.

Importing this module imports neither Dask nor the method modules.
"""

from __future__ import annotations

import collections
import concurrent.futures as cf
import glob
import json
import multiprocessing
import os
import re
import secrets
import string
import tempfile
import threading
import time
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Callable, Iterable, Mapping, Sequence

from .errors import Cancelled, WeftError
from .limits import LimitError, _bytes, available_memory

#: File extensions a folder given to ``--over`` contributes (what :func:`weft.core.image.load_image` reads).
IMAGE_EXTENSIONS = (".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp", ".webp", ".gif")
#: Output extensions (what :func:`weft.core.image.save_image` writes).
SAVE_EXTENSIONS = (".png", ".jpg", ".jpeg", ".tif", ".tiff")
#: Times an item is started before a worker dying under it fails the item (Dask's default too).
MAX_ATTEMPTS = 3
#: Items in flight per worker (one running, one queued behind it so the worker never waits for us).
IN_FLIGHT_PER_WORKER = 2
#: Environment variable naming a Dask scheduler when none is given.
SCHEDULER_ENV = "DASK_SCHEDULER_ADDRESS"
#: How long to try reaching a Dask scheduler before giving up.
CONNECT_TIMEOUT = "10s"


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
        return {"summary": True, "total": self.total, "written": self.written, "skipped": self.skipped,
                "failed": len(self.failed), "cancelled": self.cancelled, "seconds": round(self.seconds, 3),
                "items_per_second": round(self.written / self.seconds, 4) if self.seconds > 0 else None}


class BatchProgress:
    """Progress of a running batch, handed to :func:`run`'s ``progress`` after each item."""

    __slots__ = ("total", "done", "failed", "started", "_timed", "_first")

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
        if self._timed < 2:
            return None
        rate = (self._timed - 1) / max(1e-9, time.monotonic() - self._first)
        return (self.total - self.done) / rate


# --------------------------------------------------------------------------------------------------
# Planning: everything that can be wrong about the batch as a whole, before any work

def _natural_key(path: str):
    return [int(t) if t.isdigit() else t.lower() for t in re.split(r"(\d+)", os.path.basename(path))] + [path]


def expand_over(name: str, where: str) -> list[str]:
    """The files of one ``--over``: a folder's image files, a glob's matches or one file, in natural
    order (``frame_2`` before ``frame_10``); ``WeftError`` if there are none."""
    if os.path.isdir(where):
        files = [str(Path(where) / f) for f in os.listdir(where)
                 if not f.startswith(".") and f.lower().endswith(IMAGE_EXTENSIONS) and (Path(where) / f).is_file()]
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
    with open(path, "rb") as f:
        head = f.read(26)
    return head[24] if len(head) == 26 and head[12:16] == b"IHDR" else None


def _done_already(item: Item) -> bool:
    """The output exists, is a PNG of the item's bit depth and carries exactly the item's recipe."""
    from .image import read_recipe

    if not item.output.lower().endswith(".png") or not os.path.isfile(item.output):
        return False
    try:
        return read_recipe(item.output) == item.recipe and _png_bit_depth(item.output) == item.bit_depth
    except (WeftError, OSError):
        return False


def _existing_seed(outputs: Sequence[tuple[int, str]], method: str) -> tuple[int, int] | None:
    """(index, seed) of the first existing output carrying a recipe of ``method`` (a resumed batch
    whose recipe has no seed keeps the seed its first run drew)."""
    from .image import read_recipe

    for index, out in outputs:
        if out.lower().endswith(".png") and os.path.isfile(out):
            try:
                data = json.loads(read_recipe(out) or "null")
            except (WeftError, OSError, ValueError):
                continue
            if isinstance(data, dict) and data.get("method") == method and isinstance(data.get("seed"), int):
                return index, data["seed"]
    return None


def plan(recipe_path: str, over: Sequence[tuple[str, str]], pattern: str, *, seed: int | None = None,
         seed_per_item: bool = False, force: bool = False, bit_depth: int = 8, ship_inputs: bool = False,
         ship_outputs: bool = False, recipe=None) -> Plan:
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
    bit_depth : {8, 16}
    ship_inputs, ship_outputs : bool
        Send the inputs' bytes with each item (workers need not see the files) / have the workers
        return the encoded outputs for this process to write (workers need not see the output folder).

    Raises
    ------
    WeftError
        Anything wrong with the batch as a whole (one line); nothing has been run or written.
    """
    from . import registry
    from .run import check_recipe, load_recipe, output_recipe

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
    if bit_depth not in (8, 16):
        raise WeftError(f"parameter 'bit-depth' = {bit_depth} must be 8 or 16")

    lists = {name: expand_over(name, where) for name, where in over}
    counts = {len(v) for v in lists.values()}
    if len(counts) > 1:
        raise WeftError("the --over lists differ in length (" + ", ".join(
            f"{name}: {len(v)} files" for name, v in lists.items()) + "); they are taken in step, file by file")
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
            raise WeftError(f"pattern {pattern!r} uses {{{f}}}; it may use " + ", ".join("{" + a + "}" for a in allowed))

    first = names[0]
    fixed = {k: str(Path(v).resolve()) for k, v in recipe.inputs.items() if k not in lists}
    rows = []
    seen: dict[str, str] = {}
    all_inputs = set(os.path.realpath(p) for p in fixed.values())
    for files in lists.values():
        all_inputs.update(os.path.realpath(p) for p in files)
    for i in range(n):
        over_files = {name: lists[name][i] for name in lists}
        values = {"stem": Path(over_files[first]).stem, "name": Path(over_files[first]).name, "index": i,
                  **{name: Path(path).stem for name, path in over_files.items()}}
        out = os.path.abspath(_format(pattern, values))
        label = os.path.basename(over_files[first])
        if out in seen:
            raise WeftError(f"pattern {pattern!r} gives {out} for both {seen[out]} and {label}: "
                            "add {index} or {stem} so every item has its own output")
        seen[out] = label
        if os.path.realpath(out) in all_inputs:
            raise WeftError(f"pattern {pattern!r}: refusing to overwrite the input file {out}")
        if os.path.isdir(out):
            raise WeftError(f"pattern {pattern!r} gives {out}, which is a folder")
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
        items.append(Item(index=i, label=label, method=method.name, params=params_dict, inputs=inputs,
                          seed=item_seed, region=recipe.region, output=out, recipe=text, bit_depth=bit_depth,
                          write=not ship_outputs))
    skipped = () if force else tuple(it for it in items if _done_already(it))
    return Plan(items=tuple(items), skipped=skipped, method=method.name, seed=seed, ship_inputs=ship_inputs)


def _header_shape(path: str) -> tuple[int, ...] | None:
    """(H, W) or (H, W, 3) of an image file from its header, or None if it cannot be read."""
    from .image.files import _GREY_MODES, _pil_open

    try:
        im, _ = _pil_open(path)
        with im:
            w, h = im.size
            return (h, w) if im.mode in _GREY_MODES else (h, w, 3)
    except Exception:  # noqa: BLE001 - a bad file fails its own item, with its own message
        return None


def item_memory(items: Iterable[Item]) -> tuple[float, str]:
    """The largest estimated peak memory of one item (``Method.memory`` on the inputs' header sizes)
    and that item's label; ``(0, "")`` when the method gives no estimate."""
    from . import registry

    best, label = 0.0, ""
    items = list(items)
    if not items:
        return best, label
    method = registry.get(items[0].method)
    if method.memory is None:
        return best, label
    params = method.params.from_dict(items[0].params)
    for item in items:
        shapes = {name: _header_shape(path) for name, path in item.inputs.items()}
        if any(s is None for s in shapes.values()):
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


def check_memory(items: Iterable[Item], workers: int, *, available: int | None = None,
                 option: str = "--workers") -> None:
    """Refuse up front a batch whose largest item's estimate times ``workers`` exceeds ``available``
    memory (default: what the system has available now), saying how many workers would fit."""
    need, label = item_memory(items)
    available = available_memory() if available is None else available
    if not need or available is None or need * workers <= available:
        return
    fits = int(available // need)
    advice = (f"use {option} {fits}" if fits >= 1
              else "make the inputs smaller (even one item does not fit)")
    raise LimitError(f"batch: one item ({label}) needs about {_bytes(need)} of memory, {workers} workers at once "
                     f"{_bytes(need * workers)}, {_bytes(available)} is available: {advice}")


# --------------------------------------------------------------------------------------------------
# One item, on a worker

_warm_lock = threading.Lock()
_warm: set[str] = set()
_cancel_event = None  # set in local pool workers by _init_local_worker


class _EventToken:
    """A cancel token over a ``multiprocessing.Event`` shared with the client process."""

    def __init__(self, event):
        self.event = event

    @property
    def cancelled(self) -> bool:
        return self.event.is_set()

    def raise_if_cancelled(self) -> None:
        if self.event.is_set():
            raise Cancelled("batch cancelled")


def set_threads(n: int | None) -> None:
    """OpenCV's thread count in this process (a worker shares the cores with the others)."""
    if n is not None:
        import cv2

        if cv2.getNumThreads() != n:
            cv2.setNumThreads(n)


def _dask_threads(totals: Mapping[str, int], dask_worker=None) -> None:
    """On a Dask worker: OpenCV threads = the host's cores / the threads all workers there run."""
    host = dask_worker.address.rsplit(":", 1)[0]
    set_threads(max(1, (os.cpu_count() or 1) // max(1, totals.get(host, 1))))


def warm_up(method_name: str) -> None:
    """Load the method's kernels once per process (every worker calls it before its first item)."""
    from . import registry

    with _warm_lock:
        if method_name in _warm:
            return
        method = registry.get(method_name)
        if method.warm_up is not None:
            method.warm_up()
        _warm.add(method_name)


def _one_line(e: BaseException) -> str:
    return " ".join(str(e).split()) or type(e).__name__


def run_item(item: Item) -> Outcome:
    """Run one item as ``weft run`` runs its recipe and write (or return) its output.

    Never raises for the item's own problems (a bad input, a parameter its image does not suit, a
    full disk): they become a failed :class:`Outcome` with a one-line reason. Both pools call this.
    """
    from . import registry
    from .image import atomic_write_bytes, encode_image
    from .run import render

    worker = f"{os.uname().nodename}:{os.getpid()}" if hasattr(os, "uname") else str(os.getpid())
    t0, c0 = time.perf_counter(), time.process_time()
    tmpdir = None
    try:
        set_threads(item.threads)
        warm_up(item.method)
        method = registry.get(item.method)
        params = method.params.from_dict(item.params)
        paths = dict(item.inputs)
        if item.shipped is not None:  # the client sent the bytes: read them from a private copy
            tmpdir = tempfile.TemporaryDirectory(prefix="weft-batch-")
            for name, data in item.shipped.items():
                copy = Path(tmpdir.name) / name / Path(item.inputs[name]).name
                copy.parent.mkdir()
                copy.write_bytes(data)
                paths[name] = str(copy)
        cancel = _EventToken(_cancel_event) if _cancel_event is not None else None
        try:
            result, seconds = render(method, params, paths, item.seed, item.region, cancel=cancel,
                                     warm_up=False, shown_paths=item.inputs)
        except WeftError as e:
            message = _one_line(e)
            for name, path in paths.items():  # a shipped copy is named by the file it came from
                message = message.replace(path, item.inputs[name])
            raise WeftError(message) from None
        data = encode_image(item.output, result.image, recipe=item.recipe, bit_depth=item.bit_depth)
        if item.write:
            os.makedirs(os.path.dirname(item.output), exist_ok=True)
            atomic_write_bytes(Path(item.output), data)
            data = None
        return Outcome(item.index, item.label, item.output, "written", seconds=seconds,
                       figures=dict(result.figures), worker=worker, data=data, elapsed=time.perf_counter() - t0,
                       cpu=time.process_time() - c0)
    except Cancelled:
        return Outcome(item.index, item.label, item.output, "failed", error="cancelled", worker=worker)
    except WeftError as e:
        return Outcome(item.index, item.label, item.output, "failed", error=_one_line(e), worker=worker)
    except MemoryError:
        return Outcome(item.index, item.label, item.output, "failed", error="out of memory", worker=worker)
    except OSError as e:
        return Outcome(item.index, item.label, item.output, "failed",
                       error=f"{e.strerror or _one_line(e)}", worker=worker)
    finally:
        if tmpdir is not None:
            tmpdir.cleanup()


def _pid_after(seconds: float) -> int:
    time.sleep(seconds)
    return os.getpid()


def _exit_with_parent(parent: int) -> None:
    """A local worker's watch: if the client process is gone (killed), the worker ends too instead
    of waiting for items forever (an item it was writing is lost whole: writes are atomic)."""
    while True:
        time.sleep(0.5)
        if os.getppid() != parent:
            os._exit(1)


def _init_local_worker(method_name: str, cancel_event, parent: int | None = None) -> None:
    """Local pool worker start: Ctrl-C is the client's to handle; kernels are loaded once."""
    import signal

    global _cancel_event
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _cancel_event = cancel_event
    if parent is not None:
        threading.Thread(target=_exit_with_parent, args=(parent,), name="weft-batch-parent", daemon=True).start()
    warm_up(method_name)


# --------------------------------------------------------------------------------------------------
# Pools: the same items, the same function, local processes or a Dask cluster

class WorkerDied(Exception):
    """The process running an item died (killed, or out of memory)."""


class LocalPool:
    """A ``ProcessPoolExecutor`` of ``workers`` spawned processes (not forked: the client may have
    threads), restarted if a worker dies."""

    def __init__(self, workers: int, method: str):
        self.workers = workers
        self.method = method
        self.ctx = multiprocessing.get_context("spawn")
        self.cancel_event = self.ctx.Event()
        self.executor = None
        self.restarts = 0  # times a dead worker took the pool down and it was started again
        self.threads = max(1, default_workers() // workers)
        self._start()

    def _start(self) -> None:
        self.executor = cf.ProcessPoolExecutor(self.workers, mp_context=self.ctx, initializer=_init_local_worker,
                                               initargs=(self.method, self.cancel_event, os.getpid()))
        if self.workers > 1:
            # One worker loads the kernels before the others start: on a first run (no numba cache
            # yet) it compiles them once and the others load its cache, instead of every worker
            # compiling the same kernels at once (24 fast transfers on 2 workers with a fresh
            # NUMBA_CACHE_DIR, whole command: 7.2 -> 5.2 s; warm cache 4.45 -> 4.44 s, medians of 3 at load
            # ~4). The executor starts a process per submit.
            self.executor.submit(_pid_after, 0.0).result()

    @property
    def slots(self) -> int:
        return self.workers

    def ready(self) -> list[int]:
        """Start every worker now and wait until each has loaded its kernels; their process ids."""
        seen: set[int] = set()
        while len(seen) < self.workers:  # each worker takes at most one short task while others are free
            seen.update(f.result() for f in [self.executor.submit(_pid_after, 0.05) for _ in range(self.workers)])
        return sorted(seen)

    def submit(self, item: Item):
        return self.executor.submit(run_item, replace(item, threads=self.threads))

    def wait(self, futures, timeout: float):
        done, _ = cf.wait(futures, timeout=timeout, return_when=cf.FIRST_COMPLETED)
        return done

    def outcome(self, future) -> Outcome:
        try:
            return future.result()
        except cf.process.BrokenProcessPool:
            raise WorkerDied() from None

    def after_death(self) -> None:
        self.executor.shutdown(wait=True, cancel_futures=True)
        self.restarts += 1
        self._start()

    def cancel(self, futures) -> None:
        """Stop: queued items never start, running ones stop at their next cancel check."""
        self.cancel_event.set()
        for f in futures:
            f.cancel()
        cf.wait(futures)

    def close(self) -> None:
        self.executor.shutdown(wait=True, cancel_futures=True)


class DaskPool:
    """A Dask distributed client on ``address``: the items are ``client.submit(run_item, item)``."""

    def __init__(self, address: str, method: str):
        try:
            from distributed import Client
        except ImportError:
            raise WeftError("a scheduler address needs Dask: pip install -e '.[cluster]'") from None
        try:
            self.client = Client(address, timeout=CONNECT_TIMEOUT)
        except (OSError, TimeoutError, ValueError) as e:
            raise WeftError(f"cannot reach the Dask scheduler at {address} ({_one_line(e)})") from None
        self.method = method
        totals: dict[str, int] = collections.Counter()
        for addr, info in self.workers().items():
            totals[addr.rsplit(":", 1)[0]] += info.get("nthreads", 1)
        self.client.run(_dask_threads, dict(totals))

    def workers(self) -> dict:
        return self.client.scheduler_info(n_workers=-1)["workers"] if self._takes_n() else \
            self.client.scheduler_info()["workers"]

    def _takes_n(self) -> bool:
        import inspect

        return "n_workers" in inspect.signature(self.client.scheduler_info).parameters

    @property
    def slots(self) -> int:
        return max(1, sum(w.get("nthreads", 1) for w in self.workers().values()))

    def ready(self) -> list[int]:
        """Load the method's kernels on every worker now; their process ids."""
        self.client.run(warm_up, self.method)
        return list(self.client.run(os.getpid).values())

    def submit(self, item: Item):
        return self.client.submit(run_item, item, pure=False, key=f"weft-item-{item.index}-{secrets.token_hex(4)}")

    def wait(self, futures, timeout: float):
        from distributed import wait

        try:
            done, _ = wait(list(futures), timeout=timeout, return_when="FIRST_COMPLETED")
        except TimeoutError:
            return set()
        return done

    def outcome(self, future) -> Outcome:
        from distributed import KilledWorker

        try:
            return future.result()
        except KilledWorker:
            raise WorkerDied() from None

    def after_death(self) -> None:
        pass  # Dask has already retried the item on other workers

    def cancel(self, futures) -> None:
        self.client.cancel(list(futures))

    def close(self) -> None:
        self.client.close()


def scheduler_address(given: str | None) -> str | None:
    """The Dask scheduler to use: ``given``, else ``DASK_SCHEDULER_ADDRESS``, else None (local pool)."""
    return given or os.environ.get(SCHEDULER_ENV) or None


def default_workers() -> int:
    """Local workers by default: the cores this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:
        return max(1, os.cpu_count() or 1)


def run(plan_: Plan, *, workers: int | None = None, scheduler: str | None = None,
        progress: Callable[[BatchProgress], None] | None = None,
        on_outcome: Callable[[Outcome], None] | None = None, cancel=None, pool=None) -> Summary:
    """Run a planned batch; returns its :class:`Summary` once every item is done (or ``cancel``led).

    Parameters
    ----------
    workers : int, optional
        Local processes (default :func:`default_workers`), at most one per item to do.
    scheduler : str, optional
        A Dask scheduler address (``tcp://host:8786``): the items run there instead.
    progress : callable, optional
        Called with a :class:`BatchProgress` after every item (on the calling thread).
    on_outcome : callable, optional
        Called with each item's :class:`Outcome` (skipped ones first), in completion order.
    cancel : CancelToken, optional
        Checked between items; running local items stop at their next check, queued ones never start.
    pool : optional
        An already open pool (tests); it is not closed.

    Raises
    ------
    LimitError
        The batch needs more memory than the workers have (nothing was run).
    """
    summary = Summary(total=len(plan_.items))
    state = BatchProgress(summary.total, len(plan_.skipped))
    for item in plan_.skipped:
        summary.skipped += 1
        if on_outcome is not None:
            on_outcome(Outcome(item.index, item.label, item.output, "skipped"))
    todo = collections.deque(plan_.todo)
    t0 = time.monotonic()
    if not todo:
        return summary
    own = pool is None
    if pool is None:
        if scheduler:
            pool = DaskPool(scheduler, plan_.method)
        else:
            n = min(workers or default_workers(), len(todo))
            check_memory(todo, n)
            pool = LocalPool(n, plan_.method)
    try:
        if isinstance(pool, DaskPool):
            need, label = item_memory(todo)
            for addr, info in pool.workers().items():
                limit, threads = info.get("memory_limit") or 0, info.get("nthreads", 1)
                if need and limit and need * threads > limit:
                    raise LimitError(f"batch: one item ({label}) needs about {_bytes(need)} of memory; the Dask worker "
                                     f"{addr} runs {threads} at once with a limit of {_bytes(limit)}: start workers "
                                     f"with fewer threads (--nthreads) or more memory (--memory-limit)")
        attempts: dict[int, int] = collections.Counter()
        inflight: dict[Any, Item] = {}
        limit = IN_FLIGHT_PER_WORKER * pool.slots
        while todo or inflight:
            if cancel is not None and cancel.cancelled:
                summary.cancelled = True
                pool.cancel(inflight)
                for future, item in inflight.items():  # items that finished meanwhile still count
                    if future.done() and not future.cancelled():
                        try:
                            outcome = pool.outcome(future)
                        except Exception:  # noqa: BLE001 - a dead worker: not done
                            continue
                        if outcome.status == "written":
                            _finish(outcome, item, summary, state, on_outcome, progress)
                break
            while todo and len(inflight) < limit:
                item = todo.popleft()
                if plan_.ship_inputs:
                    try:
                        item = _ship(item)
                    except WeftError as e:
                        _finish(Outcome(item.index, item.label, item.output, "failed", error=str(e)),
                                item, summary, state, on_outcome, progress)
                        continue
                inflight[pool.submit(item)] = item
            died = []
            for future in pool.wait(inflight, timeout=0.2):
                item = inflight.pop(future)
                try:
                    outcome = pool.outcome(future)
                except WorkerDied:
                    died.append(item)
                    continue
                except cf.CancelledError:
                    continue
                except Exception as e:  # noqa: BLE001 - e.g. a Dask communication error: this item's
                    outcome = Outcome(item.index, item.label, item.output, "failed", error=_one_line(e))
                _finish(outcome, item, summary, state, on_outcome, progress)
            if died:
                if isinstance(pool, LocalPool):  # the whole local pool went down with it
                    died.extend(inflight.values())
                    inflight.clear()
                for item in sorted(died, key=lambda it: it.index, reverse=True):
                    attempts[item.index] += 1
                    # Dask has already tried it on MAX_ATTEMPTS workers (its allowed-failures).
                    if attempts[item.index] >= MAX_ATTEMPTS or not isinstance(pool, LocalPool):
                        outcome = Outcome(item.index, item.label, item.output, "failed",
                                          error="the worker running it died each time it was tried "
                                                "(killed, or out of memory)")
                        _finish(outcome, item, summary, state, on_outcome, progress)
                    else:
                        todo.appendleft(item)
                pool.after_death()
    except KeyboardInterrupt:
        pool.cancel(inflight)
        raise
    finally:
        summary.seconds = time.monotonic() - t0
        if own:
            pool.close()
    return summary


def _ship(item: Item) -> Item:
    """The item with its input files' bytes attached (read here, on the client)."""
    from .image.files import _os_error

    shipped = {}
    for name, path in item.inputs.items():
        try:
            with open(path, "rb") as f:
                shipped[name] = f.read()
        except OSError as e:
            raise _os_error(path, e) from None
    return replace(item, shipped=shipped)


def _finish(outcome: Outcome, item: Item, summary: Summary, state: BatchProgress,
            on_outcome, progress) -> None:
    """Count one finished item (writing its output here when the worker sent it back)."""
    if outcome.status == "written" and outcome.data is not None:
        from .image import atomic_write_bytes

        try:
            os.makedirs(os.path.dirname(item.output), exist_ok=True)
            atomic_write_bytes(Path(item.output), outcome.data)
            outcome = replace(outcome, data=None)
        except (WeftError, OSError) as e:
            outcome = Outcome(item.index, item.label, item.output, "failed", error=_one_line(e), worker=outcome.worker)
    if outcome.status == "written":
        summary.written += 1
    elif outcome.status == "failed":
        reason = outcome.error or "failed"
        for path in item.inputs.values():  # "frame_0312.png: truncated PNG ..." rather than its whole path
            if reason.startswith(path + ": "):
                summary.failed.append((item.index, os.path.basename(path), reason[len(path) + 2:]))
                break
        else:
            summary.failed.append((item.index, item.label, reason))
        summary.failed.sort()
    state._add(outcome)
    if on_outcome is not None:
        on_outcome(outcome)
    if progress is not None:
        progress(state)
