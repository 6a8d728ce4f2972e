"""A render request (Qt-free): everything one render needs, captured, and the result it gives.

``weft METHOD``, ``weft run``, each item of a batch, the studio's previews and final renders and the
Variations grid's cells all build a :class:`RenderRequest` and call :meth:`RenderRequest.run` (on any
thread): it loads or builds the inputs, crops the region input to the source region, reduces them as
the request's mode says (:class:`Full`, :class:`Preview` at a size, :class:`AroundStroke` a box),
loads the method's kernels first if asked, runs the method and times the compute alone (kernels
compiled on the way are left out). The :class:`RenderResult` names what came out.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from .errors import ImageError, WeftError
from .geometry import Square
from .jobs import Progress, ProgressCallback
from .params import Params
from .preview import Around, crop_around, reduce_for_preview

if TYPE_CHECKING:
    from .jobs import CancelToken
    from .registry import Method, Result

__all__ = [
    "Full",
    "Preview",
    "AroundStroke",
    "Mode",
    "FULL",
    "RenderRequest",
    "RenderResult",
    "Prepared",
    "crop_region",
]


@dataclass(frozen=True)
class Full:
    """Render the whole output at full size."""


@dataclass(frozen=True)
class Preview:
    """Render reduced so the longer side of the inputs (or output size) the method's studio description
    names is ``side`` px (:func:`~weft.core.preview.reduce_for_preview`)."""

    side: int


@dataclass(frozen=True)
class AroundStroke:
    """Render only the region around a mask stroke: ``box`` = ``(x0, y0, x1, y1)`` of the stroke in the
    painted image's pixels; ``mask_part`` = ``(bits, (x, y))``, the part of the painted mask the crop can
    reach, when the inputs do not hold the painted mask (:func:`~weft.core.preview.crop_around`)."""

    box: tuple[float, float, float, float]
    mask_part: tuple[np.ndarray, tuple[int, int]] | None = None


Mode = Full | Preview | AroundStroke
FULL = Full()

#: The inputs of a request by input name: image files, images, or a call that builds the images when
#: the request runs (``names`` restricts it to some).
Inputs = Mapping[str, str | os.PathLike] | Mapping[str, np.ndarray] | Callable[..., dict[str, np.ndarray]]


def _is_images(inputs: Inputs) -> bool:
    return not callable(inputs) and any(isinstance(v, np.ndarray) for v in inputs.values())


def crop_region(method: Method, images: dict[str, np.ndarray], region: Square | None) -> dict[str, np.ndarray]:
    """``images`` with the method's first input (the one a source region crops) cropped to ``region``.

    Parameters
    ----------
    method : Method
        The method the images are for; its first input is the one the region belongs to.
    images : dict of str to ndarray
        The method's inputs by name (not changed).
    region : Square or None
        The source region; None gives ``images`` unchanged.

    Returns
    -------
    dict of str to ndarray
        The inputs with the first one cropped. ``InvalidParameter`` if the square leaves that image.
    """
    first = method.inputs[0].name
    if region is None or first not in images:
        return images
    out = dict(images)
    out[first] = region.crop(images[first], what=first.replace("_", " "))
    return out


@dataclass(frozen=True)
class Prepared:
    """What a request's method runs on: ``images`` and ``params`` (cropped, reduced), the stroke's
    ``around`` crop (:class:`AroundStroke`) and the input files' ``infos``."""

    images: dict[str, np.ndarray]
    params: Params
    around: Around | None = None
    infos: dict = field(default_factory=dict)


@dataclass(frozen=True)
class RenderResult:
    """What a render gave.

    Attributes
    ----------
    request : the request it answers.
    result : the method's :class:`~weft.core.registry.Result` (``image``, ``figures``).
    seconds : the compute alone (loading kernels and compiles on the way left out).
    kernel_seconds : time spent loading (or compiling) the method's kernels for this render.
    compiled : a kernel had to be compiled (a first run).
    around : for :class:`AroundStroke`, the crop rendered (:class:`~weft.core.preview.Around`).
    fitted : for :class:`AroundStroke`, the crop's image scaled back to its box (None if it cannot be).
    infos : each input file's :class:`~weft.core.image.ImageInfo` (file inputs only).
    """

    request: RenderRequest
    result: Result
    seconds: float
    kernel_seconds: float = 0.0
    compiled: bool = False
    around: Around | None = None
    fitted: np.ndarray | None = None
    infos: dict = field(default_factory=dict)

    @property
    def image(self) -> np.ndarray:
        return self.result.image

    @property
    def figures(self) -> dict:
        return dict(self.result.figures)


@dataclass(frozen=True)
class RenderRequest:
    """One render, captured: it runs on any thread and reads nothing else.

    Attributes
    ----------
    method : the :class:`~weft.core.registry.Method`.
    params : its validated :class:`~weft.core.params.Params` (geometry included).
    inputs : image files or images by input name, or a call that builds the images (``Inputs``).
    seed : the random seed (the same seed gives the same pixels).
    region : the source region the first input is cropped to, or None.
    mode : :data:`FULL`, :class:`Preview` or :class:`AroundStroke`.
    warm_up : load the method's kernels before the timed run (if this process has not yet).
    shown_paths : the file names to use in messages when the files read are copies (a batch's
        shipped inputs); default the paths themselves.
    """

    method: Method
    params: Params
    inputs: Inputs
    seed: int
    region: Square | None = None
    mode: Mode = FULL
    warm_up: bool = False
    shown_paths: Mapping[str, str] | None = None

    def run(
        self,
        *,
        progress: ProgressCallback | None = None,
        cancel: CancelToken | None = None,
        announce: ProgressCallback | None = None,
    ) -> RenderResult | None:
        """Load the inputs, reduce them as the mode says and run the method.

        Parameters
        ----------
        progress : callable(Progress), optional
            The method's progress reports.
        cancel : CancelToken, optional
            Checked by the method; ``Cancelled`` ends the run.
        announce : callable(Progress), optional
            Hears, as a preparing stage, that the method's kernels are loading, and that they compile
            (a first run) as soon as a compile starts.

        Returns
        -------
        RenderResult or None
            None for :class:`AroundStroke` when nothing is painted near the stroke. An error about
            one input file names that file (``WeftError``).
        """
        prepared = self.prepared()
        if prepared is None:
            return None
        try:
            result, seconds, kernels, compiled = timed_run(
                self.method,
                prepared.images,
                prepared.params,
                self.seed,
                progress,
                cancel,
                warm_up=self.warm_up,
                announce=announce,
            )
        except WeftError as e:
            shown = self._shown()
            if e.input in shown:  # about one image (a block that does not fit it): say which file
                named = type(e)(f"{shown[e.input]}: {e}")
                named.__dict__.update(e.__dict__)
                raise named from None
            raise
        around = prepared.around
        fitted = None if around is None else around.fitted(result.image)
        return RenderResult(self, result, seconds, kernels, compiled, around, fitted, prepared.infos)

    def prepared(self) -> Prepared | None:
        """What the method runs on: the inputs loaded or built, the first cropped to the region, reduced
        as the mode says (on the calling thread: a worker's). None for :class:`AroundStroke` when
        nothing is painted near the stroke."""
        infos: dict = {}
        images = self._images(infos)
        params: Params = self.params
        mode, studio = self.mode, self.method.studio
        if isinstance(mode, Preview):
            images, params = reduce_for_preview(studio, images, params, mode.side)
        elif isinstance(mode, AroundStroke):
            around = crop_around(studio, images, params, mode.box, mask_part=mode.mask_part)
            if around is None:
                return None
            return Prepared(around.inputs, around.params, around, infos)
        return Prepared(images, params, None, infos)

    def _shown(self) -> dict[str, str]:
        if callable(self.inputs) or _is_images(self.inputs):
            return {}
        return {k: str(v) for k, v in (self.shown_paths or self.inputs).items()}

    def _images(self, infos: dict) -> dict[str, np.ndarray]:
        """The inputs as images, the first cropped to the region; files checked against the sizes
        the method needs (naming the file)."""
        method, region = self.method, self.region
        if region is not None and not method.takes_region:
            raise WeftError(
                f"weft {method.name} takes no --region (it works on the whole {method.inputs[0].name}; "
                f"crop the image first)"
            )
        if callable(self.inputs):
            names = None
            if isinstance(self.mode, AroundStroke) and self.mode.mask_part is not None:
                painted = None if method.studio is None else method.studio.preview_around
                names = [i.name for i in method.inputs if i.name != painted]
            return crop_region(method, self.inputs(names), region)
        if _is_images(self.inputs):
            return crop_region(method, dict(cast(Mapping[str, np.ndarray], self.inputs)), region)
        from .image import load_image

        paths = cast(Mapping[str, str | os.PathLike], self.inputs)
        keep_alpha = {spec.name for spec in method.inputs if spec.alpha}
        loaded = {name: load_image(path, alpha=name in keep_alpha) for name, path in paths.items()}
        infos.update({name: item.info for name, item in loaded.items()})
        images = crop_region(method, {name: item.image for name, item in loaded.items()}, region)
        shown = self._shown()
        for spec in method.inputs:
            if spec.name in images and min(images[spec.name].shape[:2]) < spec.min_side:
                h, w = images[spec.name].shape[:2]
                cropped = " (the --region crop)" if region is not None and spec is method.inputs[0] else ""
                raise ImageError(
                    f"{shown[spec.name]}: the {spec.name} is {w}x{h}{cropped}; weft {method.name} "
                    f"needs at least {spec.min_side}x{spec.min_side} pixels",
                    path=shown[spec.name],
                )
        return images


def timed_run(
    method: Method,
    images: Mapping[str, np.ndarray],
    params: Params,
    seed: Any,
    progress: ProgressCallback | None,
    cancel: CancelToken | None,
    *,
    warm_up: bool,
    announce: ProgressCallback | None = None,
) -> tuple[Result, float, float, bool]:
    """Run ``method`` on ``images``: its kernels first if ``warm_up`` and this process has not loaded
    them yet, then the run, timed without the kernels' loading and without any compile on the way.

    Parameters
    ----------
    method, images, params, seed, progress, cancel
        As ``Method.run`` takes them (``seed`` is its ``rng``).
    warm_up : bool
        Load the method's kernels before the timed run.
    announce : callable(Progress), optional
        Hears "loading the ... method" before the kernels load, and the method's "preparing ... —
        first run only" words when a compile starts (at once if another thread is compiling: it
        holds numba's lock).

    Returns
    -------
    (Result, seconds, kernel_seconds, compiled)
        The method's result, the compute time, the time on kernels (loading, and compiles during the
        run), and whether a kernel compiled.
    """
    from . import registry

    said: list[bool] = []

    def preparing() -> None:
        said.append(True)
        if announce is not None and len(said) == 1:
            announce(Progress.preparing_stage(registry.preparing_text(method.name)))

    prepared = 0.0
    with registry.watch_compiles(this_thread=True, on_start=preparing) as compiles:
        if warm_up and not registry.is_warm(method.name):
            t0 = time.perf_counter()
            if announce is not None:  # numba's import and the cache take a moment even when warm
                announce(Progress.preparing_stage(registry.loading_text(method.name)))
            if registry.compiling():
                preparing()
            registry.warm_up(method.name)
            prepared = time.perf_counter() - t0
        before = compiles.seconds
        t0 = time.perf_counter()
        result = method.run(images, params, rng=seed, progress=progress, cancel=cancel)
        during = compiles.seconds - before  # a kernel the warm-up did not cover
        seconds = time.perf_counter() - t0 - during
    return result, max(0.0, seconds), prepared + during, bool(said)
