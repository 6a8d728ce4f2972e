"""Rendering: turns the document into preview and final render requests on the worker pool, and
their results into images.

* The renderer alone decides what a change of the document renders: its ``policy``
  (:class:`~weft.app.gui.render_policy.RenderPolicy`) listens to the document and asks for a
  preview, a preview around a stroke, or the full size.
* While a slider is held down, ``preview()`` submits a reduced-size job (slot ``"preview"``,
  :class:`~weft.core.request.Preview` at ``PREVIEW_SIDE``, reduced as the method's studio description
  says). At most one preview is computed at a time: changes that arrive meanwhile are coalesced into
  the next one, started as soon as the running one is done (cancelling a running preview at every
  slider step would starve the display while the slider moves). Release, and any other edit, asks
  for ``final()`` (slot ``"final"``, full size), which cancels any preview.
* A job is a :class:`~weft.app.gui.render_job.StudioJob`: the document's
  :class:`~weft.core.request.RenderRequest`, captured on the GUI thread by reference and built on
  its worker, with the recipe of its pixels and its "before" image. Its result is a
  :class:`~weft.app.gui.render_job.Rendered`, read by name. Export and Compare use the result's
  recipe and "before", never the panel's state at the time of the export.
* Jobs carry ids; a result older than the one shown is dropped, so what is shown is always the last
  completed job. Workers never touch widgets: results and progress arrive through
  :class:`~weft.app.gui.qjobs.QtJobs`' queued signals.
* While a mask stroke is painted, ``preview_around(box)`` submits (in the same coalesced preview slot)
  a render of the region around the stroke only (:class:`~weft.core.request.AroundStroke`), when the
  method's studio description asks for it (``Studio.preview_around``): its result comes back scaled
  to the crop's box and is pasted into a copy of the last full result (the stroke's first preview
  makes the copy on its worker; later ones paste into it in place, and the result view redraws only
  the part). The release renders full size. A preview around a stroke that fails says nothing (the
  release's render will). While a stroke is painted, no whole-image preview is made.
* A job running longer than ``PROGRESS_DELAY_MS`` shows its progress (with partial previews where the
  method gives them) and can be cancelled; after a cancel or an error the last good result stays.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from enum import Enum, auto

import numpy as np
from PySide6.QtCore import QObject, QTimer, Signal
from weft.core import registry
from weft.core.jobs import JobResult, Progress
from weft.core.request import FULL, AroundStroke, Preview

from .qjobs import QtJobs
from .render_job import Rendered, StudioJob, render_request
from .render_policy import RenderPolicy
from .shown import Shown, describe

__all__ = ["Renderer", "Shown", "describe", "PREVIEW_SIDE", "PROGRESS_DELAY_MS"]

PREVIEW_SIDE = 400
PROGRESS_DELAY_MS = 300
WARM_UP_DELAY_MS = 3000  # no render at start: warm the kernels up after this long anyway
WARM_UP_AFTER_RESULT_MS = 1000  # the first result is in: warm the others up this long after it (not mid-stroke)
#: Python's GIL switch interval (s) in a process with a renderer: a worker running Python (a numpy fill,
#: a stroke's crop) hands the GIL over to a waiting GUI thread after at most this long, not the default
#: 5 ms, and a GUI event handler enters Python several times (the tool, the QGraphicsItems' paint and
#: boundingRect); a long C call holding the GIL (an import, numba loading its typing tables) is not cut
#: short by it.
GIL_SWITCH_INTERVAL = 0.001


class FailureKind(Enum):
    """What failed: a render of the document (the result shown is out of date), or a job in the
    background (the kernels' warm-up: the result shown is not affected)."""

    RENDER = auto()
    BACKGROUND = auto()


@dataclass(frozen=True)
class RenderFailure:
    """A failure the renderer reports (``Renderer.failed``): its kind and one line of words."""

    kind: FailureKind
    message: str

    def __str__(self) -> str:
        return self.message


class Renderer(QObject):
    """Preview/final job logic for one document (see the module docstring).

    Signals: ``shown(Shown)`` a new result to display; ``partial(image)`` a partial image of a
    running job; ``progress(fraction, stage)``; ``busy(bool)`` a job over the progress delay is
    running (show the bar); ``failed(RenderFailure)``; ``withdrawn()`` an edit in progress was
    dropped: show again what was shown before its previews (``shown`` has the last result again
    when it was on screen); ``needs(words)`` nothing rendered: the method needs
    something drawn first (``Geometry.needed``); ``cancelled()``; ``preparing(words)`` the running
    final render is waiting for its method's kernels to compile (a first run), in words for the
    result view (then ``progress`` takes over again); ``submitted(job_id, slot)`` a job was handed
    to the workers (for measurements).
    """

    submitted = Signal(int, str)
    around_shown = Signal(object)  # a preview around a stroke, pasted into the last full result

    shown = Signal(object)
    partial = Signal(object)
    progress = Signal(float, str)
    preparing = Signal(str)
    busy = Signal(bool)
    failed = Signal(object)  # a RenderFailure
    withdrawn = Signal()
    needs = Signal(str)  # the method needs a geometry drawn before it renders: what to draw (no job runs)
    cancelled = Signal()

    def __init__(self, doc, parent=None, *, workers: int = 2):
        super().__init__(parent)
        if sys.getswitchinterval() > GIL_SWITCH_INTERVAL:
            sys.setswitchinterval(GIL_SWITCH_INTERVAL)
        self.doc = doc
        self.runner = QtJobs(self, max_workers=workers, progress=True)
        self.runner.result.connect(self._on_result)
        self.runner.progressed.connect(self._on_progress)
        self.runner.finished.connect(self._on_finished)
        self._preview_running: int | None = None
        self._preview_dirty = False
        self._around_box: tuple[float, float, float, float] | None = None  # stroke region not previewed yet
        self._around_jobs: set[int] = set()
        self._around_image: np.ndarray | None = None  # the last full result with the stroke's previews pasted
        self._around_bases: dict[int, np.ndarray] = {}  # a job copying the base -> that base (the array copied)
        self._stroking = False  # a stroke's previews are asked for: no whole-image preview meanwhile
        self.last: Shown | None = None
        # The window shows the canvas input instead of ``last`` (the method had nothing to do, e.g.
        # nothing painted): ``last`` is older than the document, no base for a stroke's previews.
        self.input_shown = False
        self.latest_final: int | None = None
        self._final_running = False  # the latest final job has not delivered yet
        self._preview_timer = QTimer(self, singleShot=True, interval=16)
        self._preview_timer.timeout.connect(self._submit_preview)
        self._final_timer = QTimer(self, singleShot=True, interval=60)
        self._final_timer.timeout.connect(self._submit_final)
        self._busy_timer = QTimer(self, singleShot=True, interval=PROGRESS_DELAY_MS)
        self._busy_timer.timeout.connect(self._maybe_busy)
        self.enabled = True
        self._warm_up_timer = QTimer(self, singleShot=True)
        self._warm_up_timer.timeout.connect(self._warm_up_due)
        self._warm_up_started = False
        self._warm_up_wanted = False
        self.policy = RenderPolicy(doc, self)  # what a change of the document renders

    # --- requests ------------------------------------------------------------------------------
    def preview(self) -> None:
        """Ask for a reduced-size render soon (coalesced to one per frame)."""
        if not self._preview_timer.isActive():
            self._preview_timer.start()

    def preview_around(self, box) -> bool:
        """A mask stroke is being painted (``box`` the region of its latest dab, in the painted image's
        pixels): preview the region around it at once when no preview is running (no frame's wait:
        the stroke's crop is small), else as soon as the running one is done, coalesced with the dabs
        that follow (the latest wins). False if the method previews no stroke that way."""
        if self.doc.studio.preview_around is None:
            return False
        self._stroking = True
        if self._around_box is None:
            self._around_box = tuple(box)
        else:
            a = self._around_box
            self._around_box = (min(a[0], box[0]), min(a[1], box[1]), max(a[2], box[2]), max(a[3], box[3]))
        self._submit_preview()
        return True

    def stroke_cancelled(self) -> bool:
        """The stroke was cancelled: drop its previews and show the last full result again if it is
        one of the current method and was on screen (True); else the caller shows what was there."""
        self._preview_timer.stop()
        self._around_box = None
        self._around_image = None
        self._stroking = False
        self._around_bases.clear()  # (a cancelled job delivers nothing)
        self.runner.cancel("preview")
        self._preview_running, self._preview_dirty = None, False
        if self._current_final() is not None:
            self.shown.emit(self.last)
            return True
        return False

    def _current_final(self) -> Shown | None:
        """The last result if it is a full-size result of the current method on screen, else None."""
        last = self.last
        if self.input_shown or last is None or not last.final or last.recipe is None:
            return None
        return last if last.recipe.method == self.doc.method else None

    def final(self, *, now: bool = False) -> None:
        """Ask for the full-size render (coalesced; ``now`` skips the short delay). A stroke being
        previewed has ended (released, or the document changed under it)."""
        self._preview_timer.stop()
        self._stroking = False
        if now:
            self._final_timer.stop()
            self._submit_final()
        else:
            self._final_timer.start()

    def cancel(self) -> None:
        """Cancel running renders; the last good result stays shown."""
        self._preview_timer.stop()
        self._final_timer.stop()
        self._preview_running, self._preview_dirty = None, False
        self._final_running = False
        self._around_bases.clear()
        self.runner.cancel("preview")
        self.runner.cancel("final")
        self._busy_timer.stop()
        self.busy.emit(False)
        self.cancelled.emit()

    def running(self) -> bool:
        """A preview or final render is running or about to start."""
        return (
            self._final_running
            or self._preview_running is not None
            or self._final_timer.isActive()
            or self._preview_timer.isActive()
        )

    def shutdown(self) -> None:
        self._warm_up_timer.stop()
        self._warm_up_wanted = False  # a result still queued must not start it on a closed runner
        self._preview_timer.stop()
        self._final_timer.stop()
        self._busy_timer.stop()
        self.runner.shutdown(wait=True, cancel=True)

    # --- job construction ----------------------------------------------------------------------
    def _submit(self, slot: str, preview: bool) -> int | None:
        if not self.enabled:
            return None
        doc = self.doc
        box = None
        if slot == "preview" and self._around_box is not None:
            # a stroke's preview: only the crop around it is built (not the whole-image reduced
            # preview as well, which would be thrown away)
            if doc.missing_inputs():
                return None
            box, self._around_box = self._around_box, None
            self._preview_timer.stop()  # (asked for by the dabs this job covers)
        elif slot == "preview" and self._stroking:
            return None  # a stroke is painted: its next dab asks for its preview (no whole image meanwhile)
        needed = doc.nothing_drawn()
        if needed is not None:
            if slot == "final":
                self.runner.cancel("final")
                self._final_running = False
                self._busy_timer.stop()
                self.busy.emit(False)
                self.needs.emit(needed)
            return None
        mode = AroundStroke(box) if box is not None else Preview(PREVIEW_SIDE) if preview else FULL
        request = render_request(doc, mode)
        if request is None:
            return None
        # a stroke's first preview copies the image its crops are pasted into, on the worker
        base = self._around_base() if box is not None and self._around_image is None else None
        job = StudioJob(
            request,
            recipe=None if preview else doc.recipe(request.params),
            before=doc.image(doc.studio.compare_input(doc.inputs)),
            masks=None if preview else doc.masks(),
            base=base,
        )
        if slot == "final":
            self.runner.cancel("preview")
            self._preview_running, self._preview_dirty = None, False
            self._around_box = None
            self._around_bases.clear()
        handle = self.runner.submit(slot, job)
        if box is not None:
            self._around_jobs.add(handle.id)
            if base is not None:
                self._around_bases[handle.id] = base
        if slot == "preview":
            self._preview_running = handle.id
        if slot == "final":
            self.latest_final = handle.id
            self._final_running = True
            self._busy_timer.start()
        self.submitted.emit(handle.id, slot)
        return handle.id

    def _submit_preview(self) -> None:
        if self._preview_running is not None:
            self._preview_dirty = True  # started when the running preview is done
            return
        self._submit("preview", preview=True)

    def _on_finished(self, job_id: int, slot: str) -> None:
        if slot != "preview" or job_id != self._preview_running:
            return
        self._preview_running = None
        if self._preview_dirty:
            self._preview_dirty = False
            self._submit("preview", preview=True)

    def _submit_final(self) -> None:
        self._submit("final", preview=False)

    # --- results -------------------------------------------------------------------------------
    def _on_result(self, result: JobResult) -> None:
        if result.slot not in ("preview", "final"):  # e.g. the kernels' warm-up
            if result.error is not None:
                self.failed.emit(RenderFailure(FailureKind.BACKGROUND, f"{result.slot} failed: {result.error}"))
            return
        if result.slot == "final" and result.job_id == self.latest_final:
            self._final_running = False
            self._busy_timer.stop()
            self.busy.emit(False)
            self._warm_up_after_result()  # the first result (or error) is in: the other methods' turn
        around = result.job_id in self._around_jobs
        self._around_jobs.discard(result.job_id)
        base = self._around_bases.pop(result.job_id, None)
        if result.error is not None:
            if not around and (self.last is None or result.job_id > self.last.job_id):
                self.failed.emit(RenderFailure(FailureKind.RENDER, f"render failed: {result.error}"))
            return
        if result.value is None:
            return  # a stroke's preview with nothing painted near it
        if self.last is not None and result.job_id < self.last.job_id:
            return  # older than what is shown: stale
        rendered: Rendered = result.value
        out, job = rendered.out, rendered.job
        if out.around is not None:
            self._show_around(rendered, result.job_id, base)
            return
        if rendered.final:
            self._around_image = None
        self.input_shown = False
        self.last = Shown(
            out.image,
            result.job_id,
            out.seconds,
            out.figures,
            rendered.final,
            prepared=out.kernel_seconds,
            compiled=out.compiled,
            recipe=job.recipe,
            before=job.before,
            masks=job.masks,
            method=rendered.method,
        )
        self.shown.emit(self.last)

    def _around_base(self) -> np.ndarray | None:
        """What a preview around a stroke is pasted into: the last full result of this method, else
        (none yet, e.g. it refused to run with nothing painted) its canvas input."""
        last = self._current_final()
        canvas = self.doc.studio.canvas
        return last.image if last is not None else self.doc.deferred_inputs()(names=(canvas,)).get(canvas)

    def _show_around(self, rendered: Rendered, job_id: int, base) -> None:
        """Paste a preview around a stroke (its result scaled to its box) into the stroke's copy of the
        full result: the copy of ``base`` its job made, for the stroke's first."""
        out, copied = rendered.out, rendered.copied
        crop, fitted = out.around, out.fitted
        if crop is None or fitted is None:
            return  # the crop's result does not fit the full one (another size): the release renders
        over = self._around_image
        if over is None:
            current = self._around_base()
            if not self._stroking or current is None:
                return  # the stroke has ended (its full render is on its way), or nothing to paste into
            if copied is None or base is not current:
                # no copy, or one of what is no longer the base (a full result came meanwhile): the next
                # job copies the base again and covers this crop too
                self.preview_around(crop.box)
                return
            self._around_image, over = copied, base
        if crop.paste(self._around_image, fitted, copy=False) is None:
            if over is base:
                self._around_image = None
            return
        x0, y0, x1, y1 = crop.box
        dx, dy = crop.offset
        rh, rw = out.image.shape[:2]
        self.around_shown.emit(
            Shown(
                self._around_image,
                job_id,
                out.seconds,
                out.figures,
                False,
                recipe=None,
                before=None if self.last is None else self.last.before,
                method=rendered.method,
                crop=(x1 - x0, y1 - y0, rw, rh),
                changed=(x0 + dx, y0 + dy, x1 + dx, y1 + dy),
                over=over,
            )
        )

    def _on_progress(self, job_id: int, slot: str, p: Progress) -> None:
        if slot != "final" or job_id != self.latest_final:
            return
        if p.preparing:
            self.preparing.emit(p.stage)
            return
        self.progress.emit(p.fraction, p.stage)
        if p.preview is not None:
            self.partial.emit(p.preview)

    def _maybe_busy(self) -> None:
        if self._final_running:
            self.busy.emit(True)

    # --- kernels warm-up -----------------------------------------------------------------------
    def warm_up_soon(self, delay_ms: int = WARM_UP_DELAY_MS) -> None:
        """Load (or compile) the other methods' kernels in the background — a moment
        (``WARM_UP_AFTER_RESULT_MS``) after the first full result is shown, or after ``delay_ms`` if no
        render is running then, and never while a stroke is previewed — so that they never make the
        visible render wait: numba compiles under one process-wide lock, so a warm-up that went
        first would hold the first result back behind every other method's compile. Nor do they stall
        painting: loading them holds Python's GIL for several frames at a time (imports, numba's typing
        tables), and an artist often starts a stroke as soon as the picture is there."""
        self._warm_up_wanted = True
        self._warm_up_timer.start(delay_ms)

    def _warm_up_after_result(self) -> None:
        if self._warm_up_wanted and not self._warm_up_started:
            self._warm_up_timer.start(WARM_UP_AFTER_RESULT_MS)

    def _warm_up_due(self) -> None:
        if self._final_running or self._stroking:
            self._warm_up_timer.start()  # that render's result (or the next timeout) starts it
        else:
            self._start_warm_up()

    def _start_warm_up(self) -> None:
        if self._warm_up_started or not self._warm_up_wanted:
            return  # already started, or never asked for (warm_up_soon not called)
        self._warm_up_started = True
        self._warm_up_timer.stop()
        current = self.doc.method

        def warm_up_others(*, progress=None, cancel=None):
            return registry.warm_up_all(first=current, cancel=cancel)

        self.runner.submit("warm-up", warm_up_others)
