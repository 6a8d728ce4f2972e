"""What the result view shows (a result, a preview, a preview around a stroke) and its status-bar words."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from weft.core import registry
from weft.core.errors import WeftError
from weft.core.params import Recipe
from weft.core.studio import describe_figures


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
