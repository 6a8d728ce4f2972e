"""The document's values: an input picture (:class:`InputImage`, read by :func:`read_input`), a whole
document at once (:class:`DocumentState`) and an edit in progress (:class:`LiveEdit`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
from weft.core.params import Params


@dataclass(frozen=True)
class InputImage:
    """An input picture: where it came from, its pixels (float32, as ``weft.core.image.load_image``)
    and, when the file has an alpha channel, the pixels with it (``load_image(..., alpha=True)``:
    (H, W, 2) or (H, W, 4)). A method gets what ``weft run`` gives it: the pixels with alpha for an
    input whose ``InputSpec.alpha`` asks for them, the others without; "Fill transparent" paints a
    mask from :attr:`alpha`."""

    path: str | None
    image: np.ndarray
    with_alpha: np.ndarray | None = None
    opened_for: str | None = None  # the method that was current when it was opened (Studio.own_inputs)
    bit_depth: int = 8  # of the file (16 for a 16-bit PNG or TIFF): the pixel read-out counts in it

    @property
    def alpha(self) -> np.ndarray | None:
        """The alpha channel (H, W) in [0, 1], or None."""
        return None if self.with_alpha is None else self.with_alpha[..., -1]


def read_input(path: str | Path) -> InputImage:
    """Decode an image file as an input (its pixels as ``load_image`` gives them, and with its alpha
    when it has one). Slow for a large file: call it off the GUI thread. ``WeftError`` naming the file."""
    from weft.core.image import load_image

    loaded = load_image(path)
    with_alpha = None
    if loaded.info.had_alpha:
        kept = load_image(path, alpha=True).image
        if kept.ndim == 3 and kept.shape[2] in (2, 4) and kept.shape[:2] == loaded.image.shape[:2]:
            with_alpha = kept
    return InputImage(str(path), loaded.image, with_alpha, bit_depth=loaded.info.bit_depth)


class LiveEdit(NamedTuple):
    """An edit in progress, not an undo step yet: a geometry being dragged or painted (``value``: the
    square or margins so far, or the mask tool's ``MaskStroke``; ``box``: the region of a stroke's
    latest dab, in the painted image's pixels), or a parameter's slider held (``param``: its value is
    in the parameters already, as one merged undo step)."""

    key: str
    value: Any
    box: tuple | None = None
    param: bool = False


@dataclass(frozen=True)
class DocumentState:
    """A whole document at once, for :meth:`Document.restore` (sessions, crash recovery, the bundled
    examples, screenshots, benchmarks). ``geometry`` maps method -> geometry key -> typed value
    (:class:`~weft.core.geometry.Square`, :class:`~weft.core.geometry.LineDraft`, a
    :class:`~weft.core.geometry.Mask`, :class:`~weft.core.geometry.Margins`); what is not given is empty
    or default."""

    inputs: dict[str, InputImage] = field(default_factory=dict)
    method: str | None = None
    params: dict[str, Params] = field(default_factory=dict)
    geometry: dict[str, dict[str, Any]] = field(default_factory=dict)
    seed: int = 1
