"""Running a batch's items: one item on a worker (:func:`run_item`), the local process pool and the
Dask pool behind one interface, and :func:`run` (see :mod:`weft.core.batch`)."""

from __future__ import annotations

import asyncio
import collections
import concurrent.futures as cf
import contextlib
import multiprocessing
import os
import secrets
import tempfile
import threading
import time
from collections.abc import Callable, Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any

from ..errors import Cancelled, WeftError
from ..jobs import CancelToken
from ..limits import LimitError, _bytes
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

#: Times an item is started before a worker dying under it fails the item (Dask's default too).
MAX_ATTEMPTS = 3
#: Items in flight per worker (one running, one queued behind it so the worker never waits for us).
IN_FLIGHT_PER_WORKER = 2
#: Environment variable naming a Dask scheduler when none is given.
SCHEDULER_ENV = "DASK_SCHEDULER_ADDRESS"
#: How long to try reaching a Dask scheduler before giving up.
CONNECT_TIMEOUT = "10s"
#: Environment variable: seconds to wait for a Dask scheduler to have a worker.
WORKER_TIMEOUT_ENV = "WEFT_DASK_WORKER_TIMEOUT"


def _worker_timeout() -> float:
    try:
        value = float(os.environ.get(WORKER_TIMEOUT_ENV, ""))
    except ValueError:
        return 30.0
    return value if value > 0 else 30.0


#: Seconds to wait for a Dask scheduler to have at least one worker (``WEFT_DASK_WORKER_TIMEOUT``).
WORKER_TIMEOUT = _worker_timeout()

# --------------------------------------------------------------------------------------------------
# One item, on a worker

_cancel_event = None  # set in local pool workers by _init_local_worker


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
    from .. import registry

    registry.warm_up(method_name)


def _one_line(e: BaseException) -> str:
    return " ".join(str(e).split()) or type(e).__name__


def run_item(item: Item) -> Outcome:
    """Run one item as ``weft run`` runs its recipe and write (or return) its output.

    Never raises for the item's own problems (a bad input, a parameter its image does not suit, a
    full disk): they become a failed :class:`Outcome` with a one-line reason. Both pools call this.
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
            data = None
        return Outcome(
            item.index,
            item.label,
            item.output,
            "written",
            seconds=rendered.seconds,
            figures=rendered.figures,
            worker=worker,
            data=data,
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


@contextlib.contextmanager
def _interrupts_held():
    """Ctrl-C held back while worker processes are started. SIGINT is blocked in this thread, so a
    spawned worker inherits it blocked and a Ctrl-C meant for the client (the terminal sends it to
    every process of the group) never interrupts the worker's start-up with a traceback (its
    initializer then ignores it); and the client's own handler only notes it (another thread may
    take the signal), to raise once the worker is launched, never half-way through launching it."""
    import signal

    if not hasattr(signal, "pthread_sigmask") or threading.current_thread() is not threading.main_thread():
        yield
        return
    pending = []
    handler = signal.signal(signal.SIGINT, lambda signum, frame: pending.append(signum))
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)
        signal.signal(signal.SIGINT, handler)
    if pending and callable(handler):
        handler(signal.SIGINT, None)


def _init_local_worker(method_name: str, cancel_event, parent: int | None = None) -> None:
    """Local pool worker start: Ctrl-C is the client's to handle; kernels are loaded once."""
    import signal

    global _cancel_event
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})  # blocked by _interrupts_held; ignored now
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
        with _interrupts_held():  # (the first semaphore starts multiprocessing's resource tracker)
            self.cancel_event = self.ctx.Event()
        self.executor = None
        self.restarts = 0  # times a dead worker took the pool down and it was started again
        self.threads = max(1, default_workers() // workers)
        self._start()

    def _start(self) -> None:
        self.executor = cf.ProcessPoolExecutor(
            self.workers,
            mp_context=self.ctx,
            initializer=_init_local_worker,
            initargs=(self.method, self.cancel_event, os.getpid()),
        )
        if self.workers > 1:  # (the executor starts a process per submit: each under _interrupts_held)
            try:
                self._first_worker()
            except BaseException:  # Ctrl-C while it starts: end it now, before the client goes
                self.terminate()
                raise

    def _first_worker(self) -> None:
        """One worker loads the kernels before the others start: on a first run (no numba cache yet)
        it compiles them once and the others load its cache, instead of every worker compiling the
        same kernels at once. The executor starts a process per submit."""
        with _interrupts_held():
            future = self.executor.submit(_pid_after, 0.0)
        future.result()

    @property
    def slots(self) -> int:
        return self.workers

    def ready(self) -> list[int]:
        """Start every worker now and wait until each has loaded its kernels; their process ids."""
        seen: set[int] = set()
        while len(seen) < self.workers:  # each worker takes at most one short task while others are free
            with _interrupts_held():
                futures = [self.executor.submit(_pid_after, 0.05) for _ in range(self.workers)]
            seen.update(f.result() for f in futures)
        return sorted(seen)

    def submit(self, item: Item):
        with _interrupts_held():
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

    def terminate(self) -> None:
        """Stop at once (Ctrl-C): every worker is ended (SIGTERM) where it is, a running item's output
        is lost whole (writes are atomic), and a worker still starting never prints a traceback."""
        processes = list((getattr(self.executor, "_processes", None) or {}).values())
        processes += [p for p in multiprocessing.active_children() if p not in processes]
        for p in processes:
            with contextlib.suppress(Exception):
                p.terminate()
        for p in processes:
            with contextlib.suppress(Exception):
                p.join(5)
        with contextlib.suppress(Exception):
            self.executor.shutdown(wait=False, cancel_futures=True)


class DaskPool:
    """A Dask distributed client on ``address``: the items are ``client.submit(run_item, item)``."""

    def __init__(self, address: str, method: str):
        try:
            from distributed import Client
        except ImportError:
            raise WeftError("a scheduler address needs Dask: pip install -e '.[cluster]'") from None
        import logging

        # distributed logs a lost connection with tracebacks; weft says what happened in one line
        for name in ("distributed", "tornado"):
            logging.getLogger(name).setLevel(logging.CRITICAL + 1)
        self.address = address
        try:
            self.client = Client(address, timeout=CONNECT_TIMEOUT)
        except Exception as e:  # noqa: BLE001 - OSError, TimeoutError; TypeError/ValueError for tls:// without
            # certificates; ImportError for ucx:// without ucx-py
            raise WeftError(
                f"cannot reach the Dask scheduler at {address} ({type(e).__name__}: {_one_line(e)})"
            ) from None
        try:
            self.client.wait_for_workers(1, timeout=WORKER_TIMEOUT)
        except Exception:  # noqa: BLE001 - (TimeoutError, or the scheduler went away meanwhile)
            self.close()
            raise WeftError(
                f"the Dask scheduler at {address} has no workers (waited {WORKER_TIMEOUT:g} s; "
                f"set {WORKER_TIMEOUT_ENV} to wait longer)"
            ) from None
        self.method = method
        totals: dict[str, int] = collections.Counter()
        for addr, info in self.workers().items():
            totals[addr.rsplit(":", 1)[0]] += info.get("nthreads", 1)
        self.client.run(_dask_threads, dict(totals))

    def workers(self) -> dict:
        return (
            self.client.scheduler_info(n_workers=-1)["workers"]
            if self._takes_n()
            else self.client.scheduler_info()["workers"]
        )

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
        except Exception:  # noqa: BLE001 - a timeout, or the connection lost (run() checks lost())
            return set()
        return done

    def outcome(self, future) -> Outcome:
        """The item's outcome. A finished item's result lives on its worker: if that worker died
        before we fetched it, Dask recomputes it and would wait for a worker forever, so wait in
        short steps and give up once the cluster is gone (``WeftError`` saying why)."""
        from distributed import KilledWorker

        while True:
            try:
                return future.result(timeout=1)
            except KilledWorker:
                raise WorkerDied() from None
            except TimeoutError:
                reason = self.gone()
                if reason:
                    raise WeftError(reason) from None

    def after_death(self) -> None:
        pass  # Dask has already retried the item on other workers

    def idle_without_workers(self) -> float:
        """Seconds since the cluster was last seen with a worker (checked at most every second)."""
        now = time.monotonic()
        if now - getattr(self, "_checked", 0.0) >= 1.0:
            self._checked = now
            try:
                has = bool(self.workers())
            except Exception:  # noqa: BLE001 - the scheduler gone: lost() says so
                has = True
            if has or not hasattr(self, "_seen"):
                self._seen = now
        return now - self._seen

    def lost(self) -> bool:
        """Whether the connection to the scheduler is gone (the scheduler was stopped or killed)."""
        return getattr(self.client, "status", "running") not in ("running", "connecting", "newly-created")

    def gone(self) -> str | None:
        """Why no item can finish any more (the scheduler lost, or no worker for ``WORKER_TIMEOUT``
        seconds), or None while the cluster can still run them."""
        if self.lost():
            return f"the Dask scheduler at {self.address} was lost before it was done"
        if self.idle_without_workers() > WORKER_TIMEOUT:
            return f"the Dask scheduler at {self.address} had no workers left for {WORKER_TIMEOUT:g} s"
        return None

    def cancel(self, futures) -> None:
        with contextlib.suppress(Exception):
            self.client.cancel(list(futures))

    def close(self) -> None:
        with contextlib.suppress(Exception):
            self.client.close(timeout=5)


def scheduler_address(given: str | None) -> str | None:
    """The Dask scheduler to use: ``given``, else ``DASK_SCHEDULER_ADDRESS``, else None (local pool)."""
    return given or os.environ.get(SCHEDULER_ENV) or None


def default_workers() -> int:
    """Local workers by default: the cores this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:
        return max(1, os.cpu_count() or 1)


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
    from ..image.temporaries import remove_stale_temporaries

    summary = Summary(total=len(plan_.items))
    state = BatchProgress(summary.total, len(plan_.skipped))
    remove_stale_temporaries(item.output for item in plan_.items)  # a killed earlier run's half-written files
    for item in plan_.skipped:
        summary.skipped += 1
        if on_outcome is not None:
            on_outcome(Outcome(item.index, item.label, item.output, "skipped"))
    todo = collections.deque(plan_.todo)
    t0 = time.monotonic()
    if todo and pool is None and not scheduler:  # an item too large even alone fails alone; the rest run
        alone = too_large_alone(todo)
        for item, reason in alone:
            _finish(
                Outcome(item.index, item.label, item.output, "failed", error=reason),
                item,
                summary,
                state,
                on_outcome,
                progress,
            )
        refused = {item.index for item, _ in alone}
        todo = collections.deque(item for item in todo if item.index not in refused)
    if not todo:
        return summary
    own = pool is None
    if pool is None:
        if scheduler:
            pool = DaskPool(scheduler, plan_.method)
        else:
            n = min(workers or default_workers(), len(todo))
            if workers is None:  # not asked for: as many as fit in memory
                n = workers_that_fit(todo, n)
            check_memory(todo, n)
            pool = LocalPool(n, plan_.method)
    try:
        if isinstance(pool, DaskPool):
            need, label = item_memory(todo)
            for addr, info in pool.workers().items():
                limit, threads = info.get("memory_limit") or 0, info.get("nthreads", 1)
                if need and limit and need * threads > limit:
                    raise LimitError(
                        f"batch: one item ({label}) needs about {_bytes(need)} of memory; the Dask worker "
                        f"{addr} runs {threads} at once with a limit of {_bytes(limit)}: start workers "
                        f"with fewer threads (--nthreads) or more memory (--memory-limit)"
                    )
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
                        _finish(
                            Outcome(item.index, item.label, item.output, "failed", error=str(e)),
                            item,
                            summary,
                            state,
                            on_outcome,
                            progress,
                        )
                        continue
                inflight[pool.submit(item)] = item
            reason = pool.gone() if isinstance(pool, DaskPool) else None
            if reason:  # every item not done fails
                pool.cancel(inflight)
                for item in [*inflight.values(), *todo]:
                    _finish(
                        Outcome(item.index, item.label, item.output, "failed", error=reason),
                        item,
                        summary,
                        state,
                        on_outcome,
                        progress,
                    )
                inflight.clear()
                todo.clear()
                break
            died = []
            for future in pool.wait(inflight, timeout=0.2):
                item = inflight.pop(future)
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
                _finish(outcome, item, summary, state, on_outcome, progress)
            if died:
                if isinstance(pool, LocalPool):  # the whole local pool went down with it
                    died.extend(inflight.values())
                    inflight.clear()
                for item in sorted(died, key=lambda it: it.index, reverse=True):
                    attempts[item.index] += 1
                    # Dask has already tried it on MAX_ATTEMPTS workers (its allowed-failures).
                    if attempts[item.index] >= MAX_ATTEMPTS or not isinstance(pool, LocalPool):
                        outcome = Outcome(
                            item.index,
                            item.label,
                            item.output,
                            "failed",
                            error="the worker running it died each time it was tried (killed, or out of memory)",
                        )
                        _finish(outcome, item, summary, state, on_outcome, progress)
                    else:
                        todo.appendleft(item)
                pool.after_death()
    except KeyboardInterrupt:
        if isinstance(pool, LocalPool):
            pool.terminate()
        else:
            pool.cancel(inflight)
        raise
    finally:
        summary.seconds = time.monotonic() - t0
        if own:
            try:
                pool.close()
            except KeyboardInterrupt:  # Ctrl-C while waiting for the workers to end (one still starting)
                if isinstance(pool, LocalPool):
                    pool.terminate()
                raise
            except Exception:  # noqa: BLE001 - (after terminate(): nothing left to wait for)
                pass
    return summary


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
