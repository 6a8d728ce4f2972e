"""Running a planned batch: :func:`run` hands its items to a pool (the local process pool of
:mod:`.local_pool`, or the Dask pool of :mod:`.dask_pool`), a few per worker at a time, counts what
comes back, and runs an item again when the worker running it died (see :mod:`weft.core.batch`).

The pools' classes and the worker's functions are re-exported here for callers that import them
from this module."""

from __future__ import annotations

import asyncio
import collections
import concurrent.futures as cf
import os
import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

from ..errors import WeftError
from ..limits import LimitError, _bytes
from .dask_pool import DaskPool, scheduler_address
from .local_pool import LocalPool, default_workers
from .prepare import (
    BatchProgress,
    Item,
    Outcome,
    Plan,
    Summary,
    check_memory,
    item_memory,
    too_large_alone,
    workers_that_fit,
)
from .worker import WorkerDied, _one_line, run_item, set_threads, warm_up

__all__ = [
    "IN_FLIGHT_PER_WORKER",
    "MAX_ATTEMPTS",
    "DaskPool",
    "LocalPool",
    "WorkerDied",
    "default_workers",
    "run",
    "run_item",
    "scheduler_address",
    "set_threads",
    "warm_up",
]

#: Times an item is started before a worker dying under it fails the item (Dask's default too).
MAX_ATTEMPTS = 3
#: Items in flight per worker (one running, one queued behind it so the worker never waits for us).
IN_FLIGHT_PER_WORKER = 2
#: The reason given for an item whose worker died on every attempt.
_DIED = "the worker running it died each time it was tried (killed, or out of memory)"


def run(
    plan_: Plan,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: Callable[[BatchProgress], None] | None = None,
    on_outcome: Callable[[Outcome], None] | None = None,
    cancel=None,
    pool=None,
) -> Summary:
    """Run a planned batch; returns its :class:`Summary` once every item is done (or cancelled).

    Parameters
    ----------
    plan_ : Plan
        The batch, as :func:`~weft.core.batch.plan` made it (items to do and items skipped).
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

    Returns
    -------
    Summary
        What was written, skipped and failed (with reasons), whether it was cancelled, and how long
        it took.

    Raises
    ------
    LimitError
        The batch needs more memory than the workers have (nothing was run).
    """
    from ..image.temporaries import remove_stale_temporaries

    summary = Summary(total=len(plan_.items))
    batch = _Batch(plan_, summary, on_outcome, progress)
    remove_stale_temporaries(item.output for item in plan_.items)  # a killed earlier run's half-written files
    for item in plan_.skipped:
        summary.skipped += 1
        if on_outcome is not None:
            on_outcome(Outcome(item.index, item.label, item.output, "skipped"))
    batch.todo.extend(plan_.todo)
    t0 = time.monotonic()
    if batch.todo and pool is None and not scheduler:
        batch.refuse_too_large()
    if not batch.todo:
        return summary
    own = pool is None
    if pool is None:
        pool = _open_pool(plan_.method, batch.todo, workers, scheduler)
    try:
        if isinstance(pool, DaskPool):
            _check_dask_memory(pool, batch.todo)
        batch.run(pool, cancel)
    except KeyboardInterrupt:
        if isinstance(pool, LocalPool):
            pool.terminate()
        else:
            pool.cancel(batch.inflight)
        raise
    finally:
        summary.seconds = time.monotonic() - t0
        if own:
            _close(pool)
    return summary


def _open_pool(method: str, todo: collections.deque[Item], workers: int | None, scheduler: str | None):
    """The pool the batch runs on: Dask's when given a scheduler, else local processes (as many as
    asked for, or as fit in memory, and never more than the items to do)."""
    if scheduler:
        return DaskPool(scheduler, method)
    n = min(workers or default_workers(), len(todo))
    if workers is None:  # not asked for: as many as fit in memory
        n = workers_that_fit(todo, n)
    check_memory(todo, n)
    return LocalPool(n, method)


def _check_dask_memory(pool: DaskPool, todo: collections.deque[Item]) -> None:
    """Refuse the batch (``LimitError``) if a Dask worker's memory limit cannot hold the items its
    threads run at once."""
    need, label = item_memory(todo)
    for addr, info in pool.workers().items():
        limit, threads = info.get("memory_limit") or 0, info.get("nthreads", 1)
        if need and limit and need * threads > limit:
            raise LimitError(
                f"batch: one item ({label}) needs about {_bytes(need)} of memory; the Dask worker "
                f"{addr} runs {threads} at once with a limit of {_bytes(limit)}: start workers "
                f"with fewer threads (--nthreads) or more memory (--memory-limit)"
            )


def _close(pool) -> None:
    """Close a pool the batch opened, ending its workers at once on a Ctrl-C meanwhile."""
    try:
        pool.close()
    except KeyboardInterrupt:  # Ctrl-C while waiting for the workers to end (one still starting)
        if isinstance(pool, LocalPool):
            pool.terminate()
        raise
    except Exception:  # noqa: BLE001 - (after terminate(): nothing left to wait for)
        pass


class _Batch:
    """A running batch's state: the items still to submit, those in flight on the pool, the tries
    of each, and the summary and progress that each finished item is counted into."""

    def __init__(self, plan_: Plan, summary: Summary, on_outcome, progress) -> None:
        self.plan = plan_
        self.summary = summary
        self.state = BatchProgress(summary.total, len(plan_.skipped))
        self.on_outcome = on_outcome
        self.progress = progress
        self.todo: collections.deque[Item] = collections.deque()
        self.inflight: dict[Any, Item] = {}
        self.attempts: dict[int, int] = collections.Counter()

    def finish(self, outcome: Outcome, item: Item) -> None:
        _finish(outcome, item, self.summary, self.state, self.on_outcome, self.progress)

    def fail(self, item: Item, reason: str) -> None:
        self.finish(Outcome(item.index, item.label, item.output, "failed", error=reason), item)

    def refuse_too_large(self) -> None:
        """An item too large even alone fails alone; the rest run."""
        alone = too_large_alone(self.todo)
        for item, reason in alone:
            self.fail(item, reason)
        refused = {item.index for item, _ in alone}
        self.todo = collections.deque(item for item in self.todo if item.index not in refused)

    def run(self, pool, cancel) -> None:
        """Keep the pool busy until every item is done, the batch is cancelled or the cluster is gone."""
        limit = IN_FLIGHT_PER_WORKER * pool.slots
        while self.todo or self.inflight:
            if cancel is not None and cancel.cancelled:
                self.cancel(pool)
                break
            self.submit(pool, limit)
            lost = pool.gone() if isinstance(pool, DaskPool) else None
            if lost:
                self.fail_all(pool, lost)
                break
            died = self.collect(pool)
            if died:
                self.retry(pool, died)

    def cancel(self, pool) -> None:
        """Stop the pool; the items that finished meanwhile still count."""
        self.summary.cancelled = True
        pool.cancel(self.inflight)
        for future, item in self.inflight.items():
            if future.done() and not future.cancelled():
                try:
                    outcome = pool.outcome(future)
                except Exception:  # noqa: BLE001 - a dead worker: not done
                    continue
                if outcome.status == "written":
                    self.finish(outcome, item)

    def submit(self, pool, limit: int) -> None:
        """Submit items until ``limit`` are in flight (an input that cannot be shipped fails its item)."""
        while self.todo and len(self.inflight) < limit:
            item = self.todo.popleft()
            if self.plan.ship_inputs:
                try:
                    item = _ship(item)
                except WeftError as e:
                    self.fail(item, str(e))
                    continue
            self.inflight[pool.submit(item)] = item

    def fail_all(self, pool, reason: str) -> None:
        """The cluster is gone: every item not done fails with ``reason``."""
        pool.cancel(self.inflight)
        for item in [*self.inflight.values(), *self.todo]:
            self.fail(item, reason)
        self.inflight.clear()
        self.todo.clear()

    def collect(self, pool) -> list[Item]:
        """Count the items that finished within a short wait; the items whose worker died."""
        died = []
        for future in pool.wait(self.inflight, timeout=0.2):
            item = self.inflight.pop(future)
            try:
                outcome = pool.outcome(future)
            except WorkerDied:
                died.append(item)
                continue
            except (cf.CancelledError, asyncio.CancelledError):
                if not (isinstance(pool, DaskPool) and pool.lost()):
                    continue
                outcome = Outcome(
                    item.index,
                    item.label,
                    item.output,
                    "failed",
                    error=f"the Dask scheduler at {pool.address} was lost before it was done",
                )
            except Exception as e:  # noqa: BLE001 - e.g. a Dask communication error: this item's
                outcome = Outcome(item.index, item.label, item.output, "failed", error=_one_line(e))
            self.finish(outcome, item)
        return died

    def retry(self, pool, died: list[Item]) -> None:
        """Put the items whose worker died back first in line, or fail those tried too often."""
        if isinstance(pool, LocalPool):  # the whole local pool went down with it
            died.extend(self.inflight.values())
            self.inflight.clear()
        for item in sorted(died, key=lambda it: it.index, reverse=True):
            self.attempts[item.index] += 1
            # Dask has already tried it on MAX_ATTEMPTS workers (its allowed-failures).
            if self.attempts[item.index] >= MAX_ATTEMPTS or not isinstance(pool, LocalPool):
                self.fail(item, _DIED)
            else:
                self.todo.appendleft(item)
        pool.after_death()


def _ship(item: Item) -> Item:
    """The item with its input files' bytes attached (read here, on the client)."""
    from ..errors import ImageError
    from ..image.files import _os_error
    from ..readfile import open_regular

    shipped = {}
    for name, path in item.inputs.items():
        try:
            with open_regular(path, "image file", error=ImageError) as f:
                shipped[name] = f.read()
        except OSError as e:
            raise _os_error(path, e) from None
    return replace(item, shipped=shipped)


def _finish(outcome: Outcome, item: Item, summary: Summary, state: BatchProgress, on_outcome, progress) -> None:
    """Count one finished item (writing its output here when the worker sent it back)."""
    if outcome.status == "written" and outcome.data is not None:
        from ..image import atomic_write_bytes

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
                summary.failed.append((item.index, os.path.basename(path), reason[len(path) + 2 :]))
                break
        else:
            summary.failed.append((item.index, item.label, reason))
        summary.failed.sort()
    state._add(outcome)
    if on_outcome is not None:
        on_outcome(outcome)
    if progress is not None:
        progress(state)
