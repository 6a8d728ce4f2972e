"""The local process pool: spawned worker processes that each load the method's kernels once, run
:func:`~weft.core.batch.worker.run_item` on each item, and leave Ctrl-C to the client (see
:mod:`weft.core.batch`)."""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import multiprocessing
import os
import threading
import time
from dataclasses import replace

from .prepare import Item, Outcome
from .worker import WorkerDied, listen_for_cancel, run_item, warm_up


def default_workers() -> int:
    """Local workers by default: the cores this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:
        return max(1, os.cpu_count() or 1)


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

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})  # blocked by _interrupts_held; ignored now
    listen_for_cancel(cancel_event)
    if parent is not None:
        threading.Thread(target=_exit_with_parent, args=(parent,), name="weft-batch-parent", daemon=True).start()
    warm_up(method_name)


class LocalPool:
    """A ``ProcessPoolExecutor`` of ``workers`` spawned processes (not forked: the client may have
    threads), restarted if a worker dies."""

    def __init__(self, workers: int, method: str):
        self.workers = workers
        self.method = method
        self.ctx = multiprocessing.get_context("spawn")
        with _interrupts_held():  # (the first semaphore starts multiprocessing's resource tracker)
            self.cancel_event = self.ctx.Event()
        self.executor: cf.ProcessPoolExecutor  # started by _start()
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
