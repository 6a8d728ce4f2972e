"""Background jobs: progress reports, cooperative cancellation and a "latest wins" runner.

The model (after napari's slicer and texture-synthesis's progress callback):

* A *job* is a callable plus everything it needs (frozen params, input arrays). It runs on any
  thread and touches no GUI object. The runner calls it as
  ``fn(*args, progress=callback, cancel=token, **kwargs)``.
* The algorithm reports with ``progress(Progress(stage, done, total, preview))``, usually through
  a :class:`ProgressReporter`, which only calls when the integer percentage changes and builds the
  (possibly costly) preview image only then.
* The algorithm calls ``cancel.raise_if_cancelled()`` at least once per block row / pixel row /
  iteration; that raises :class:`Cancelled`, which the runner turns into a cancelled result.
* :class:`JobRunner` runs jobs on a :class:`~concurrent.futures.ThreadPoolExecutor`. Jobs are
  grouped in *slots* (``"preview"``, ``"final"``): a new submit to a slot cancels the slot's
  previous job, a superseded job that has not started yet never runs, and only the latest,
  non-cancelled job of a slot reaches ``on_result`` and ``on_progress``. Every result carries its
  job id; every job's :class:`~concurrent.futures.Future` resolves to a :class:`JobResult`, also
  for stale, failed and cancelled jobs. Exceptions raised by a job are delivered, never swallowed.

Callbacks run on the worker thread, without the runner's lock held, so they may call
:meth:`JobRunner.submit` or :meth:`JobRunner.cancel`. ``on_result`` calls of one slot are
serialized (so the last delivery of a slot is always its newest successful job); an
``on_result`` callback must therefore not block waiting for another job of the same slot.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
from weft.core.errors import Cancelled

__all__ = ["Cancelled", "CancelToken", "Job", "JobResult", "JobRunner", "Progress", "ProgressReporter"]

log = logging.getLogger(__name__)

ProgressCallback = Callable[["Progress"], None]


class Progress(NamedTuple):
    """One progress report: ``stage`` (e.g. ``"transfer 2/3"``), ``done`` and ``total`` units of
    work (blocks, rows, iterations) and an optional ``preview``, the partly built image.

    ``preparing`` marks a stage whose length is unknown and that is not the work itself — a
    method's kernels compiling on a first run (:meth:`preparing_stage`): show its words, not a
    percentage."""

    stage: str
    done: int
    total: int
    preview: np.ndarray | None = None
    preparing: bool = False

    @classmethod
    def preparing_stage(cls, text: str) -> Progress:
        """A report that the job is preparing (``text`` says what), before any work is done."""
        return cls(text, 0, 0, None, True)

    @property
    def fraction(self) -> float:
        """Share of the work done, in [0, 1]; 0 when ``total <= 0``."""
        if self.total <= 0:
            return 0.0
        return min(1.0, max(0.0, self.done / self.total))


class CancelToken:
    """A thread-safe, one-way cancel flag shared by a job and whoever may cancel it."""

    __slots__ = ("_event",)

    def __init__(self, event=None) -> None:
        # any object with set()/is_set(): a multiprocessing.Event lets another process cancel (batches)
        self._event = threading.Event() if event is None else event

    def cancel(self) -> None:
        """Ask the job to stop. Idempotent; never blocks."""
        self._event.set()

    @property
    def cancelled(self) -> bool:
        """True once :meth:`cancel` was called."""
        return self._event.is_set()

    def raise_if_cancelled(self) -> None:
        """Raise :class:`Cancelled` if the token was cancelled; otherwise do nothing."""
        if self._event.is_set():
            raise Cancelled("job cancelled")


class ProgressReporter:
    """Throttle progress reports of one stage to one per integer percentage.

    Parameters
    ----------
    callback : callable or None
        The algorithm's ``progress`` argument; ``None`` makes every update a cheap no-op. A callback
        with an attribute ``wants_preview = False`` (a progress bar that only draws the fraction)
        gets ``preview=None`` and preview callables are never called for it. A callback with an
        attribute ``preview_interval`` (seconds) gets a built preview at most that often, the first
        one only after that long: a job faster than the interval never pays for building one.
    stage : str
        Stage name put into each :class:`Progress`.
    total : int
        Units of work of this stage.

    Examples
    --------
    >>> calls = []
    >>> report = ProgressReporter(calls.append, "rows", 1000)
    >>> for row in range(1, 1001):
    ...     _ = report.update(row, preview=lambda: None)
    >>> len(calls), calls[-1].fraction
    (101, 1.0)
    """

    __slots__ = ("callback", "stage", "total", "_last", "_previews", "_interval", "_next_preview")

    def __init__(self, callback: ProgressCallback | None, stage: str, total: int) -> None:
        self.callback = callback
        self.stage = stage
        self.total = int(total)
        self._last: int | None = None
        self._previews = bool(getattr(callback, "wants_preview", True))
        self._interval = float(getattr(callback, "preview_interval", 0.0))
        self._next_preview = time.monotonic() + self._interval

    def update(self, done: int, preview: np.ndarray | Callable[[], np.ndarray] | None = None) -> bool:
        """Report ``done`` units if the integer percentage changed or ``done == total``.

        Parameters
        ----------
        done : int
            Units of work finished so far.
        preview : numpy.ndarray, zero-argument callable or None, optional
            The partial image, or a callable producing it; the callable is only called when a
            report is actually sent, so algorithms need not copy images for nothing.

        Returns ``True`` if the callback was called.
        """
        if self.callback is None:
            return False
        percent = 100 * done // self.total if self.total > 0 else 100
        if percent == self._last and done != self.total:
            return False
        self._last = percent
        if not self._previews:
            preview = None
        elif self._interval > 0.0:
            now = time.monotonic()
            if now < self._next_preview:
                preview = None
            else:
                self._next_preview = now + self._interval
                preview = preview() if callable(preview) else preview
        elif callable(preview):
            preview = preview()
        self.callback(Progress(self.stage, int(done), self.total, preview))
        return True

    __call__ = update


@dataclass(frozen=True)
class JobResult:
    """What a finished job produced.

    ``value`` is ``fn``'s return value (kept even if the job counts as cancelled); ``error`` the
    exception ``fn`` raised, other than :class:`Cancelled`; ``cancelled`` is True if ``fn`` raised
    :class:`Cancelled`, never started, or its token was cancelled (explicitly or by a newer job of
    its slot) before the result was delivered; ``seconds`` is the wall time spent in ``fn``.
    """

    job_id: int
    slot: str
    value: Any = None
    error: BaseException | None = None
    cancelled: bool = False
    seconds: float = 0.0

    @property
    def ok(self) -> bool:
        """True if the job finished without error and was not cancelled."""
        return self.error is None and not self.cancelled


class Job:
    """Handle of a submitted job: ``id`` (increasing), ``slot``, ``token`` (passed to ``fn`` as
    ``cancel``) and ``future``, which always resolves to the :class:`JobResult` (also when failed,
    stale or cancelled). Use :meth:`cancel`, not ``future.cancel()`` (which returns False).
    """

    __slots__ = ("id", "slot", "token", "future")

    def __init__(self, job_id: int, slot: str) -> None:
        self.id = job_id
        self.slot = slot
        self.token = CancelToken()
        self.future: Future[JobResult] = Future()
        self.future.set_running_or_notify_cancel()  # only the runner resolves it

    def cancel(self) -> None:
        """Cancel the job: a queued job never runs ``fn``, a running one sees its token set."""
        self.token.cancel()

    def result(self, timeout: float | None = None) -> JobResult:
        """Wait for and return the :class:`JobResult` (``TimeoutError`` after ``timeout`` s)."""
        return self.future.result(timeout)

    def done(self) -> bool:
        """True once the job's result is available."""
        return self.future.done()


class JobRunner:
    """Run jobs on a thread pool; per slot, the latest job wins.

    Parameters
    ----------
    max_workers : int, default 2
        Worker threads (named ``weft-job_N``).
    on_result : callable(JobResult), optional
        Called on the worker thread with the result of each job that is still the latest of its
        slot and not cancelled (successes and errors). Exceptions it raises are logged.
    on_progress : callable(job_id, slot, Progress), optional
        Called on the worker thread with the progress of the latest, non-cancelled job of a slot.
    """

    def __init__(
        self,
        max_workers: int = 2,
        *,
        on_result: Callable[[JobResult], None] | None = None,
        on_progress: Callable[[int, str, Progress], None] | None = None,
    ) -> None:
        self._on_result = on_result
        self._on_progress = on_progress
        self._executor = ThreadPoolExecutor(max_workers=max_workers, thread_name_prefix="weft-job")
        self._lock = threading.Lock()
        self._next_id = 1
        self._latest: dict[str, Job] = {}
        self._active: dict[int, Job] = {}
        self._deliver_locks: dict[str, threading.Lock] = {}
        self._closed = False

    def submit(self, slot: str, fn: Callable[..., Any], *args: Any, **kwargs: Any) -> Job:
        """Run ``fn(*args, progress=..., cancel=..., **kwargs)`` and cancel the slot's previous job.

        Raises
        ------
        RuntimeError
            If the runner was shut down.
        """
        with self._lock:
            if self._closed:
                raise RuntimeError("JobRunner is shut down")
            job = Job(self._next_id, slot)
            self._next_id += 1
            previous = self._latest.get(slot)
            if previous is not None:
                previous.cancel()
            self._latest[slot] = job
            self._active[job.id] = job
            self._deliver_locks.setdefault(slot, threading.Lock())
            self._executor.submit(self._run, job, fn, args, kwargs)
        return job

    def cancel(self, slot: str | None = None) -> None:
        """Cancel the latest job of ``slot``, or every unfinished job when ``slot`` is None."""
        with self._lock:
            jobs = list(self._active.values()) if slot is None else [self._latest.get(slot)]
        for job in jobs:
            if job is not None:
                job.cancel()

    def latest(self, slot: str) -> Job | None:
        """The most recently submitted job of ``slot`` (finished or not), or None."""
        with self._lock:
            return self._latest.get(slot)

    def busy(self, slot: str | None = None) -> bool:
        """True while some job (of ``slot``, or of any slot) has not resolved yet."""
        with self._lock:
            return any(slot is None or job.slot == slot for job in self._active.values())

    def shutdown(self, wait: bool = True, cancel: bool = True) -> None:
        """Refuse new jobs, optionally cancel unfinished ones, and (if ``wait``) join the workers.

        Every job's future still resolves; cancelled queued jobs resolve without running.
        """
        with self._lock:
            self._closed = True
            pending = list(self._active.values()) if cancel else []
        for job in pending:
            job.cancel()
        self._executor.shutdown(wait=wait)

    def __enter__(self) -> JobRunner:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.shutdown()

    # -- worker side -------------------------------------------------------------------------

    def _is_current(self, job: Job) -> bool:
        with self._lock:
            return self._latest.get(job.slot) is job and not job.token.cancelled

    def _progress_callback(self, job: Job) -> ProgressCallback | None:
        on_progress = self._on_progress
        if on_progress is None:
            return None

        def forward(progress: Progress) -> None:
            if not self._is_current(job):
                return
            try:
                on_progress(job.id, job.slot, progress)
            except Exception:
                log.exception("on_progress callback failed for job %d (%s)", job.id, job.slot)

        return forward

    def _run(self, job: Job, fn: Callable[..., Any], args: tuple, kwargs: dict) -> None:
        value: Any = None
        error: BaseException | None = None
        raised_cancel = False
        seconds = 0.0
        result = JobResult(job.id, job.slot, cancelled=True)
        try:
            if not job.token.cancelled:
                start = time.perf_counter()
                try:
                    value = fn(*args, progress=self._progress_callback(job), cancel=job.token, **kwargs)
                except Cancelled:
                    raised_cancel = True
                except BaseException as exc:  # delivered in the result, never raised in the worker
                    error = exc
                seconds = time.perf_counter() - start
            with self._deliver_locks[job.slot]:
                # Decide and deliver atomically per slot: a newer job of the slot has cancelled
                # this token under the runner lock, so stale results always count as cancelled.
                deliver = self._is_current(job)
                result = JobResult(job.id, job.slot, value, error, not deliver or raised_cancel, seconds)
                if deliver and not raised_cancel and self._on_result is not None:
                    try:
                        self._on_result(result)
                    except Exception:
                        log.exception("on_result callback failed for job %d (%s)", job.id, job.slot)
        finally:
            with self._lock:
                self._active.pop(job.id, None)
            job.future.set_result(result)
