"""The one Qt adapter over :class:`weft.core.jobs.JobRunner`: jobs run on its worker threads, their
results, progress and completions arrive on the GUI thread as queued signals.

Workers never touch widgets: every part of the studio that runs work in the background (renders,
Variations, rectification, line suggestions, opening files, autosave, a batch) submits it here and
connects to the signals.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from PySide6.QtCore import QObject, Signal
from weft.core.jobs import Job, JobRunner


class QtJobs(QObject):
    """A :class:`~weft.core.jobs.JobRunner` whose callbacks are Qt signals (queued to the thread this
    object lives in, the GUI thread).

    Signals: ``result(JobResult)`` a job that is still the latest of its slot finished (success or
    error; not a cancelled one); ``progressed(job_id, slot, Progress)`` the latest job of a slot
    reported progress; ``finished(job_id, slot)`` any job resolved (also cancelled or stale), after
    its ``result`` if it had one.
    """

    result = Signal(object)
    progressed = Signal(int, str, object)
    finished = Signal(int, str)

    def __init__(self, parent: QObject | None = None, *, max_workers: int = 1, progress: bool = False):
        super().__init__(parent)
        self.runner = JobRunner(
            max_workers=max_workers,
            on_result=self._emit_result,
            on_progress=self._emit_progress if progress else None,
        )

    def submit(self, slot: str, fn: Callable[..., Any], *args: Any, **kwargs: Any) -> Job:
        """Run ``fn(*args, progress=..., cancel=..., **kwargs)`` on a worker; a newer job of ``slot``
        cancels this one (see :meth:`JobRunner.submit <weft.core.jobs.JobRunner.submit>`)."""
        job = self.runner.submit(slot, fn, *args, **kwargs)
        job.future.add_done_callback(lambda _f, jid=job.id, slot=slot: self._emit("finished", jid, slot))
        return job

    def cancel(self, slot: str | None = None) -> None:
        """Cancel the latest job of ``slot``, or every unfinished job."""
        self.runner.cancel(slot)

    def busy(self, slot: str | None = None) -> bool:
        return self.runner.busy(slot)

    def latest(self, slot: str) -> Job | None:
        return self.runner.latest(slot)

    def shutdown(self, wait: bool = True, cancel: bool = True) -> None:
        """Refuse new jobs, cancel unfinished ones (``cancel``) and join the workers (``wait``)."""
        self.runner.shutdown(wait=wait, cancel=cancel)

    def _emit_result(self, result) -> None:
        self._emit("result", result)

    def _emit_progress(self, job_id: int, slot: str, progress) -> None:
        self._emit("progressed", job_id, slot, progress)

    def _emit(self, name: str, *args) -> None:
        try:
            getattr(self, name).emit(*args)
        except RuntimeError:  # this object was deleted (its window closed) while the job ran: nobody to tell
            pass
