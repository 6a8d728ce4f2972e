"""The table of fill engines: what each is, its default patch, and how the method runs it.

Every engine is a function ``fill_x(image, hole, source=None, *, patch, rng, progress, cancel,
**extra)`` that returns the image with the hole filled and every other pixel unchanged (but the
known pixels of ``cuttable``, the blend band, when it takes them). ``progress`` gets
:class:`weft.core.jobs.Progress` reports (stage ``"fill"``) like every method's; ``cancel`` is
checked at least once per block, pixel row or EM iteration.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from importlib import import_module

import numpy as np


@dataclass(frozen=True)
class Engine:
    """One fill engine.

    ``name`` (``--engine``), ``summary`` (its help text), ``patch`` (default patch side),
    ``where`` (``"module:function"`` under :mod:`weft.core.fill`), ``cuttable`` (it takes the blend
    band's known pixels, ``cuttable=``), ``resynthesises_band(image, hole)`` (it re-synthesises that
    band itself, so the method runs no Poisson blend after it)."""

    name: str
    summary: str
    patch: int
    where: str
    cuttable: bool
    resynthesises_band: Callable[[np.ndarray, np.ndarray], bool]

    def function(self):
        module, _, function = self.where.partition(":")
        return getattr(import_module(f"{__package__}.{module}"), function)


def _quilt_refines(image: np.ndarray, hole: np.ndarray) -> bool:
    from .quilt import refines

    return refines(image, hole)


def _always(_image: np.ndarray, _hole: np.ndarray) -> bool:
    return True


#: The engines, by ``--engine`` name (``auto`` picks one of them: :func:`weft.core.fill.params.auto_engine`).
TABLE: dict[str, Engine] = {
    e.name: e
    for e in (
        Engine(
            "patchmatch",
            "multi-scale patch search with voting (Wexler et al., PatchMatch)",
            7,
            "patchmatch:fill_patchmatch",
            True,
            _always,
        ),
        Engine(
            "quilt",
            "blocks in fill-front order with min-cut seams (Efros & Freeman)",
            24,
            "quilt:fill_quilt",
            True,
            _quilt_refines,
        ),
        Engine(
            "hybrid",
            "quilt with 64-px blocks, then full-resolution patch search refines the seams",
            64,
            "hybrid:fill_hybrid",
            True,
            _always,
        ),
    )
}
