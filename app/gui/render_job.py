"""A studio render as a value: the document's render request, captured on the GUI thread, and the job
that runs it on a worker with what its result carries for the studio.

:func:`render_request` takes references to the document's inputs and parameters (immutable values)
and builds a :class:`~weft.core.request.RenderRequest`; everything slow (a painted mask's image, the
crop to the source region, a preview's reduction, a stroke's crop) happens when the request runs,
on its worker. A preview around a stroke gets only the part of the stroke's mask its crop can reach
(:func:`stroke_part`, cut on the GUI thread: a few hundred pixels, never the whole mask).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from weft.core.geometry import MaskStroke
from weft.core.jobs import Progress
from weft.core.params import Recipe
from weft.core.preview import around_region
from weft.core.request import FULL, AroundStroke, Full, Mode, RenderRequest, RenderResult

PARTIAL_INTERVAL = 0.25


class _Partial:
    """A progress callback that asks algorithms for a partial image at most every PARTIAL_INTERVAL s."""

    preview_interval = PARTIAL_INTERVAL

    def __init__(self, forward):
        self.forward = forward

    def __call__(self, p: Progress) -> None:
        self.forward(p)


def stroke_part(doc, box) -> tuple[np.ndarray, tuple[int, int]] | None:
    """The part of the document's stroke being painted (``Document.live``: the mask tool's
    ``MaskStroke``) that a preview around ``box`` reads (``around_region``), copied now, with its
    place; None when the live geometry is not the previewed mask painted on the open image (a job
    then reads the document's live masks whole)."""
    g = doc.mask_geometry(doc.studio.preview_around) if doc.studio.preview_around else None
    live = doc.live
    if g is None or live is None or live.param or live.key != g.key or not isinstance(live.value, MaskStroke):
        return None
    on = doc.image(g.input_for(doc.inputs))
    h, w = live.value.shape
    if on is None or on.shape[:2] != (h, w):
        return None
    x0, y0, x1, y1 = around_region(box, w, h)
    return live.value.cut(x0, y0, x1, y1), (x0, y0)


def render_request(doc, mode: Mode = FULL) -> RenderRequest | None:
    """A render of the document's current method now, in ``mode``, or None when inputs are missing.

    Takes references only: the inputs (painted masks as images, the crop to the source region) are
    built when the request runs. Around a stroke (:class:`~weft.core.request.AroundStroke` without a
    ``mask_part``), the stroke's part is cut here and the whole live mask is not built."""
    if doc.missing_inputs():
        return None
    if isinstance(mode, AroundStroke) and mode.mask_part is None:
        part = stroke_part(doc, mode.box)
        if part is not None:
            mode = AroundStroke(mode.box, part)
    whole_live = not (isinstance(mode, AroundStroke) and mode.mask_part is not None)
    build = doc.deferred_inputs(live=whole_live)  # (a mask being painted, whole: Geometry.live)
    return RenderRequest(doc.current, doc.run_params(), build, doc.seed, doc.region(), mode, warm_up=True)


@dataclass(frozen=True)
class StudioJob:
    """A studio render job: the request, and what its result carries for the studio, captured when
    it was submitted: the ``recipe`` that reproduces it and the ``masks`` export writes beside it
    (final renders), the input Compare shows beside it (``before``), and for a stroke's first
    preview the image (``base``) to copy on the worker, its crops being pasted into the copy."""

    request: RenderRequest
    recipe: Recipe | None = None
    before: np.ndarray | None = None
    masks: dict | None = None
    base: np.ndarray | None = None

    @property
    def final(self) -> bool:
        return isinstance(self.request.mode, Full)

    def __call__(self, *, progress=None, cancel=None) -> Rendered | None:
        """Run on a worker. Previews report nothing; a final render's partial images are built at
        most every PARTIAL_INTERVAL seconds (a fast render never pays for one)."""
        report = None if not self.final or progress is None else _Partial(progress)
        out = self.request.run(progress=report, cancel=cancel, announce=report)
        if out is None:
            return None  # nothing painted near the stroke: the release renders
        copied = None if self.base is None or out.fitted is None else self.base.copy()
        return Rendered(self, out, copied)


@dataclass(frozen=True)
class Rendered:
    """A studio job's result: the job, the render's :class:`~weft.core.request.RenderResult`, and for
    a stroke's first preview the copy of the job's ``base`` its crop is pasted into."""

    job: StudioJob
    out: RenderResult
    copied: np.ndarray | None = None

    @property
    def final(self) -> bool:
        return self.job.final

    @property
    def method(self) -> str:
        return self.job.request.method.name
