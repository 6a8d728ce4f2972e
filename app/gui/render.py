"""Rendering: turns the document into preview and final jobs on the worker pool, results into images.

* While a slider is held down, ``preview()`` submits a reduced-size job (slot ``"preview"``). At most
  one preview is computed at a time: changes that arrive meanwhile are coalesced into the next one,
  started as soon as the running one is done (cancelling a running preview at every slider step
  would starve the display while the slider moves). Release, and any other edit, asks for
  ``final()`` (slot ``"final"``, full size), which cancels any preview.
  Previews are reduced as the method's studio description says (its ``preview_inputs``, else its
  ``preview_params`` sizes, scaled so the longer side is ``PREVIEW_SIDE``); measured with
  ``python -m benchmarks.gui_latency``, full-size previews of a 640x500 fast transfer (~40 ms each)
  gave a median latency of ~100 ms, 400 px previews meet the 50 ms goal.
* Jobs carry ids; a result older than the one shown is dropped, so what is shown is always the last
  completed job. A result carries the recipe of its pixels (method, parameters, inputs, seed, region)
  and its "before" image, captured when the job was made: export and Compare use those, never the
  panel's state at the time of the export. Workers never touch widgets: results and progress arrive
  through queued signals.
* While a mask stroke is painted, ``preview_around(box)`` submits (in the same coalesced preview slot)
  a render of the region around the stroke only, when the method's studio description asks for it
  (``Studio.preview_around``; ``weft.core.studio.crop_around`` crops the inputs to at most
  ``AROUND_SIDE`` px): its result is pasted into the last full result and shown; the release renders
  full size. A preview around a stroke that fails says nothing (the release's render will). A dab
  while no preview runs starts one at once; dabs while one runs are coalesced into the next (the
  latest wins), started when it is done.
* A job captures the document's inputs and parameters when it is submitted and builds what it runs
  on (painted masks as images, the preview's reduction, the stroke's crop) on its worker: the GUI
  thread only takes references (``Document.deferred_inputs``). A preview around a stroke gets only
  the part of the stroke's mask its crop can reach (``weft.core.studio.around_region``, cut from the
  tool's ``MaskStroke`` on the GUI thread: a few hundred pixels, never the 4096² mask), its result
  comes back already scaled to the crop's box, and the stroke's first one also brings the copy of
  the full result its crops are pasted into (200 MB at 4096² in colour: 110 ms on the GUI thread
  before); later ones are pasted into that copy in place, and the result view redraws only the part.
  While a stroke is painted, no whole-image preview is made (a preview asked for with no stroke box
  left waits for the next box).
* A job running longer than ``PROGRESS_DELAY_MS`` shows its progress (with partial previews where the
  method gives them) and can be cancelled; after a cancel or an error the last good result stays.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from PySide6.QtCore import QObject, QTimer, Signal
from weft.core import registry
from weft.core.errors import WeftError
from weft.core.geometry import MaskStroke
from weft.core.jobs import JobResult, JobRunner, Progress
from weft.core.params import Params, Recipe
from weft.core.studio import around_region, crop_around, describe_figures, reduce_for_preview

PREVIEW_SIDE = 400
PROGRESS_DELAY_MS = 300
PARTIAL_INTERVAL = 0.25
WARM_UP_DELAY_MS = 3000  # no render at start: warm the kernels up after this long anyway
WARM_UP_AFTER_RESULT_MS = 1000  # the first result is in: warm the others up this long after it (not mid-stroke)
#: Python's GIL switch interval (s) in a process with a renderer: a worker running Python (a numpy fill,
#: a stroke's crop) hands the GIL over to a waiting GUI thread after at most this long, not the default
#: 5 ms, and a GUI event handler enters Python several times (the tool, the QGraphicsItems' paint and
#: boundingRect). Painting a 4096² mask, median of 3: longest stall 50.4 -> 30.1 ms, latency 70.5 ->
#: 51.7 ms (``python -m benchmarks.gui_latency --paint --side 4096``); a long C call holding the GIL
#: (an import, numba loading its typing tables) is not cut short by it.
GIL_SWITCH_INTERVAL = 0.001


class _Partial:
    """A progress callback that asks algorithms for a partial image at most every PARTIAL_INTERVAL s."""

    preview_interval = PARTIAL_INTERVAL

    def __init__(self, forward):
        self.forward = forward

    def __call__(self, p: Progress) -> None:
        self.forward(p)


@dataclass
class Shown:
    """What the result view shows: the image, which job made it and how long it took (``seconds``:
    the render alone; ``prepared``: loading the method's kernels first, the first time in this
    process; ``compiled``: they had to be compiled, a first run), the recipe that reproduces it
    (``weft run``) and the input Compare shows beside it."""

    image: np.ndarray
    job_id: int
    seconds: float
    figures: dict
    final: bool
    prepared: float = 0.0
    compiled: bool = False
    recipe: Recipe | None = None
    before: np.ndarray | None = None
    masks: dict | None = None  # the painted masks it was rendered with (input name -> Mask): export writes them
    method: str | None = None  # the method that rendered it (its figures are read with its words)
    # a preview around a stroke: (width, height) of the crop in the image and as rendered (its figures are the
    # crop's: only those of the whole image are stated, ``describe``)
    crop: tuple[int, int, int, int] | None = None
    # a preview around a stroke: (x0, y0, x1, y1) of ``image`` it changed: ``image`` equals ``over`` elsewhere,
    # ``over`` being the stroke's previous preview (the same array: pasted into in place) or, for its first
    # preview, the full result (or canvas input) it is a copy of; None: a new image
    changed: tuple[int, int, int, int] | None = None
    over: np.ndarray | None = None


def _render(method, inputs, params, seed, report, cancel, *, final: bool):
    """Run ``method`` for a render job: its kernels first if this process has not loaded them yet
    (``report`` then hears "loading the ... method", and the method's "preparing ... — first run
    only" words as soon as a compile starts, or at once if another thread is compiling, i.e. holds
    numba's lock), then the render, timed without any of that. Returns ``(result, render seconds,
    final, seconds spent on kernels, whether they compiled)``."""
    said = []

    def preparing() -> None:
        said.append(True)
        if report is not None and len(said) == 1:
            report(Progress.preparing_stage(registry.preparing_text(method.name)))

    prepared = 0.0
    with registry.watch_compiles(this_thread=True, on_start=preparing) as compiles:
        if not registry.is_warm(method.name):
            t0 = time.perf_counter()
            if report is not None:  # numba's import and the cache take a moment even when warm
                report(Progress.preparing_stage(registry.loading_text(method.name)))
            if registry.compiling():
                preparing()
            registry.warm_up(method.name)
            prepared = time.perf_counter() - t0
        before = compiles.seconds
        t0 = time.perf_counter()
        result = method.run(inputs, params, rng=seed, progress=report, cancel=cancel)
        during = compiles.seconds - before  # a kernel the warm-up did not cover
        seconds = time.perf_counter() - t0 - during
    return result, max(0.0, seconds), final, prepared + during, bool(said)


def stroke_part(doc, box) -> tuple[np.ndarray, tuple[int, int]] | None:
    """The part of the document's stroke being painted (``Document.live``: the mask tool's
    ``MaskStroke``) that a preview around ``box`` reads (``around_region``), copied now, with its
    place; None when the live geometry is not the previewed mask painted on the open image (a job
    then reads the document's live masks whole)."""
    g = doc.mask_geometry(doc.studio.preview_around) if doc.studio.preview_around else None
    live = doc.live
    if g is None or live is None or live[0] != g.key or not isinstance(live[1], MaskStroke):
        return None
    on = doc.image(g.input_for(doc.inputs))
    h, w = live[1].shape
    if on is None or on.shape[:2] != (h, w):
        return None
    x0, y0, x1, y1 = around_region(box, w, h)
    return live[1].cut(x0, y0, x1, y1), (x0, y0)


def preparation(doc, *, side: int | None = None, around_box=None) -> tuple[Callable[[], tuple | None], Params] | None:
    """What a job of the document's current method runs on, captured now on the GUI thread (the
    document's inputs and parameters: references to immutable values) and built by the returned
    call, on the job's worker: its painted masks as float images, a crop to the source region, a
    reduction to ``side`` px (``reduce_for_preview``: 48.5 ms at 4096² on the GUI thread before;
    a preview's, a variations grid's thumbnails) or a stroke's crop around ``around_box``
    (``crop_around``, with the whole image's mask: 0.15-0.57 s per preview at 4096² on the GUI
    thread before). The call gives ``(inputs, params, around)`` (``around``: the stroke's
    :class:`~weft.core.studio.Around`, or None), or None when there is nothing painted near the
    stroke. Returns ``(that call, the document's run parameters)``, or None when inputs are missing.
    A stroke's crop gets only the part of the stroke's mask it can reach (:func:`stroke_part`, cut
    here), never the whole mask as an image (64 MB at 4096², per preview)."""
    if doc.missing_inputs():
        return None
    studio = doc.studio
    part = None if around_box is None else stroke_part(doc, around_box)
    build = doc.deferred_inputs(live=part is None)  # (a mask being painted, whole: Geometry.live)
    params = doc.run_params()
    names = None if part is None else [i.name for i in doc.current.inputs if i.name != studio.preview_around]

    def prepare():
        if around_box is not None:
            around = crop_around(studio, build(names), params, around_box, mask_part=part)
            return None if around is None else (around.inputs, around.params, around)
        if side is not None:
            return (*reduce_for_preview(studio, build(), params, side), None)
        return build(), params, None

    return prepare, params


class Renderer(QObject):
    """Preview/final job logic for one document (see the module docstring).

    Signals: ``shown(Shown)`` a new result to display; ``partial(image)`` a partial image of a
    running job; ``progress(fraction, stage)``; ``busy(bool)`` a job over the progress delay is
    running (show the bar); ``failed(message)``; ``needs(words)`` nothing rendered: the method needs
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
    failed = Signal(str)
    needs = Signal(str)  # the method needs a geometry drawn before it renders: what to draw (no job runs)
    cancelled = Signal()
    _delivered = Signal(object)
    _progressed = Signal(int, str, object)
    _preview_finished = Signal(int)

    def __init__(self, doc, parent=None, *, workers: int = 2):
        super().__init__(parent)
        if sys.getswitchinterval() > GIL_SWITCH_INTERVAL:
            sys.setswitchinterval(GIL_SWITCH_INTERVAL)
        self.doc = doc
        self.runner = JobRunner(
            max_workers=workers,
            on_result=self._delivered.emit,
            on_progress=lambda jid, slot, p: self._progressed.emit(jid, slot, p),
        )
        self._delivered.connect(self._on_result)
        self._progressed.connect(self._on_progress)
        self._preview_finished.connect(self._on_preview_finished)
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
    def job_inputs(self, *, preview: bool) -> tuple[dict[str, np.ndarray], Params] | None:
        """Inputs and parameters of a render of the current method, or None if inputs are missing
        (built here and now; a render job builds them on its worker: :meth:`_preparation`)."""
        prepared = self._preparation(preview=preview)
        return None if prepared is None else prepared[0]()[:2]

    def _preparation(self, *, preview: bool, around_box=None) -> tuple[Callable[[], tuple | None], Params] | None:
        """:func:`preparation` of a render of the current method: a preview's reduction to
        ``PREVIEW_SIDE``, a stroke's crop around ``around_box``, else the full-size inputs."""
        return preparation(self.doc, side=PREVIEW_SIDE if preview else None, around_box=around_box)

    def _submit(self, slot: str, preview: bool) -> int | None:
        if not self.enabled:
            return None
        doc = self.doc
        box = None
        if slot == "preview" and self._around_box is not None:
            # a stroke's preview: only the crop around it is built (not the whole-image reduced
            # preview as well: 11.6 ms at 2048², 48.5 ms at 4096² per preview, thrown away)
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
        prepared = self._preparation(preview=preview, around_box=box)
        if prepared is None:
            return None
        prepare, params = prepared
        method, seed = doc.current, doc.seed
        recipe = None if preview else doc.recipe(params)
        masks = None if preview else doc.masks()
        before = doc.image(doc.studio.compare_input(doc.inputs))
        # a stroke's first preview copies the image its crops are pasted into, on the worker
        base = self._around_base() if box is not None and self._around_image is None else None

        def job(*, progress=None, cancel=None):
            # Previews report nothing; a final render's partial images are built at most every
            # PARTIAL_INTERVAL seconds (a fast render never pays for one).
            prepared = prepare()
            if prepared is None:
                return None  # nothing painted near the stroke: the release renders
            inputs, run_params, around = prepared
            report = None if preview or progress is None else _Partial(progress)
            out = _render(method, inputs, run_params, seed, report, cancel, final=not preview)
            fitted = copied = None
            if around is not None:  # (scaled back to its box here, not on the GUI thread)
                fitted = around.fitted(out[0].image)
                copied = None if base is None or fitted is None else base.copy()
            return (*out, recipe, before, masks, around, method.name, fitted, copied)

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
            handle.future.add_done_callback(lambda _f, jid=handle.id: self._preview_finished.emit(jid))
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

    def _on_preview_finished(self, job_id: int) -> None:
        if job_id != self._preview_running:
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
                self.failed.emit(f"{result.slot} failed: {result.error}")
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
                self.failed.emit(f"render failed: {result.error}")
            return
        if result.value is None:
            return  # a stroke's preview with nothing painted near it
        if self.last is not None and result.job_id < self.last.job_id:
            return  # older than what is shown: stale
        res, seconds, final, prepared, compiled, recipe, before, masks, crop, name, fitted, copied = result.value
        if crop is not None:
            self._show_around(res, crop, result.job_id, seconds, name, fitted, copied, base)
            return
        if final:
            self._around_image = None
        self.input_shown = False
        self.last = Shown(
            res.image,
            result.job_id,
            seconds,
            dict(res.figures),
            final,
            prepared,
            compiled,
            recipe,
            before,
            masks,
            method=name,
        )
        self.shown.emit(self.last)

    def _around_base(self) -> np.ndarray | None:
        """What a preview around a stroke is pasted into: the last full result of this method, else
        (none yet, e.g. it refused to run with nothing painted) its canvas input."""
        last = self._current_final()
        canvas = self.doc.studio.canvas
        return last.image if last is not None else self.doc.deferred_inputs()(names=(canvas,)).get(canvas)

    def _show_around(self, res, crop, job_id: int, seconds: float, method: str, fitted, copied, base) -> None:
        """Paste a preview around a stroke (``fitted``: its result scaled to its box) into the stroke's
        copy of the full result: ``copied``, the copy of ``base`` its job made, for the stroke's first."""
        if fitted is None:
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
        rh, rw = res.image.shape[:2]
        self.around_shown.emit(
            Shown(
                self._around_image,
                job_id,
                seconds,
                dict(res.figures),
                False,
                recipe=None,
                before=None if self.last is None else self.last.before,
                method=method,
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
        visible render wait: numba compiles under one process-wide lock, and a warm-up that went
        first held the first result back behind every other method's compile. Nor do they stall
        painting: loading them holds Python's GIL up to 40-66 ms at a time (imports, numba's typing
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


def describe(shown: Shown) -> str:
    """Status-bar text for a shown result, a preview, or a preview around a stroke: its figures in
    its method's words and units (``Studio.figures``), for a preview as for the full result. A
    stroke's preview renders a crop: it states only the figures its method marks as holding for the
    whole image (``Figure.whole``), and says the others come with the full result."""
    h, w = shown.image.shape[:2]
    kind = "result" if shown.final else "preview"
    figs = ", ".join(_figure_words(shown))
    if shown.crop is not None:
        cw, ch, rw, rh = shown.crop
        at = "" if (rw, rh) == (cw, ch) else f" (rendered at {rw}x{rh})"
        later = len(_figure_words(shown, crop=False)) > len(_figure_words(shown))
        return (
            f"preview around the stroke in {shown.seconds * 1000:.0f} ms — its {cw}x{ch} crop{at}"
            + (f": {figs}" if figs else "")
            + ("; the image's figures on release" if later else "")
        )
    prepared = ""
    if shown.compiled:
        prepared = f" (after preparing its kernels for {shown.prepared:.1f} s, first run only)"
    elif shown.prepared >= 0.05:
        prepared = f" (after loading its kernels for {shown.prepared:.1f} s)"
    return f"{kind} {w}x{h} in {shown.seconds * 1000:.0f} ms{prepared}" + (f" — {figs}" if figs else "")


def _figure_words(shown: Shown, *, crop: bool | None = None) -> list[str]:
    """The result's figures in words and units, as its method's studio description reads them
    (``crop``, default: whether ``shown`` is a crop's preview: then only those of the whole image)."""
    crop = shown.crop is not None if crop is None else crop
    studio = None
    name = shown.method or (shown.recipe.method if shown.recipe is not None else None)
    if name is not None:  # (a preview has no recipe: its method still names its figures)
        try:
            studio = registry.get(name).studio
        except WeftError:
            studio = None
    if studio is None:
        return describe_figures(shown.figures, {}, crop=crop)
    return studio.describe(shown.figures, crop=crop)
