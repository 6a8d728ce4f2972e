"""One batch item on a worker: :func:`run_item` runs its recipe as ``weft run`` does and writes (or
returns) its output; both pools call it (see :mod:`weft.core.batch`)."""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

from ..errors import Cancelled, WeftError
from ..jobs import CancelToken
from .prepare import Item, Outcome

_cancel_event = None  # a local pool's cancel event, in that pool's workers (listen_for_cancel)


class WorkerDied(Exception):
    """The process running an item died (killed, or out of memory)."""


def listen_for_cancel(event) -> None:
    """Make the items this process runs stop at their next cancel check once ``event`` is set.

    Parameters
    ----------
    event : multiprocessing.Event
        The local pool's cancel event, shared by all its workers.
    """
    global _cancel_event
    _cancel_event = event


def set_threads(n: int | None) -> None:
    """Set OpenCV's thread count in this process (a worker shares the cores with the others).

    Parameters
    ----------
    n : int or None
        Threads; None leaves OpenCV's default.
    """
    if n is not None:
        import cv2

        if cv2.getNumThreads() != n:
            cv2.setNumThreads(n)


def warm_up(method_name: str) -> None:
    """Load the method's kernels once per process (every worker calls it before its first item).

    Parameters
    ----------
    method_name : str
        The batch's method.
    """
    from .. import registry

    registry.warm_up(method_name)


def _one_line(e: BaseException) -> str:
    return " ".join(str(e).split()) or type(e).__name__


def run_item(item: Item) -> Outcome:
    """Run one item as ``weft run`` runs its recipe and write (or return) its output.

    Never raises for the item's own problems (a bad input, a parameter its image does not suit, a
    full disk): they become a failed :class:`Outcome` with a one-line reason. Both pools call this.

    Parameters
    ----------
    item : Item
        The item: its recipe, inputs, output path and seed.

    Returns
    -------
    Outcome
        ``written`` (with the encoded bytes when the item is not written here) or ``failed``.
    """
    from .. import registry
    from ..geometry import Square
    from ..image import atomic_write_bytes, encode_image
    from ..request import RenderRequest

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
        cancel = CancelToken(_cancel_event) if _cancel_event is not None else None
        try:
            region = None if item.region is None else Square._make(item.region)
            request = RenderRequest(method, params, paths, item.seed, region, shown_paths=item.inputs)
            rendered = request.run(cancel=cancel)
            assert rendered is not None  # (a full render always gives a result)
        except WeftError as e:
            message = _one_line(e)
            for name, path in paths.items():  # a shipped copy is named by the file it came from
                message = message.replace(path, item.inputs[name])
            raise WeftError(message) from None
        data = encode_image(item.output, rendered.image, recipe=item.recipe, bit_depth=item.bit_depth)
        if item.write:
            os.makedirs(os.path.dirname(item.output), exist_ok=True)
            atomic_write_bytes(Path(item.output), data)
        return Outcome(
            item.index,
            item.label,
            item.output,
            "written",
            seconds=rendered.seconds,
            figures=rendered.figures,
            worker=worker,
            data=None if item.write else data,  # a written item's bytes stay in the worker
            elapsed=time.perf_counter() - t0,
            cpu=time.process_time() - c0,
        )
    except Cancelled:
        return Outcome(item.index, item.label, item.output, "failed", error="cancelled", worker=worker)
    except WeftError as e:
        return Outcome(item.index, item.label, item.output, "failed", error=_one_line(e), worker=worker)
    except MemoryError:
        return Outcome(item.index, item.label, item.output, "failed", error="out of memory", worker=worker)
    except OSError as e:
        return Outcome(
            item.index, item.label, item.output, "failed", error=f"{e.strerror or _one_line(e)}", worker=worker
        )
    finally:
        if tmpdir is not None:
            tmpdir.cleanup()
