"""The patch-search core every fill engine shares: PatchMatch and EM voting, in numpy.

Barnes et al., "PatchMatch" (SIGGRAPH 2009): nearest-neighbour fields found by propagation and random
search, vectorised here (every target patch at once; propagation by jump flooding instead of a scan
order). Wexler, Shechtman & Irani, "Space-Time Completion of Video" (PAMI 2007): each EM iteration
searches the patches touching the hole (E) and writes each hole pixel from its covering patches'
matches (M). The vote is a weighted *mode* of offsets, not Wexler's weighted mean, so copies keep
their grain and a fill never blurs. numpy and OpenCV only: a fill loads no numba.

- :mod:`~weft.core.fill.search.patches`: the inputs' checks and :class:`Flat`, an image as its target
  and source patches;
- :mod:`~weft.core.fill.search.em`: the EM iterations (:func:`em`) and their PatchMatch steps;
- :mod:`~weft.core.fill.search.vote`: the vote (:func:`vote_mode`);
- :mod:`~weft.core.fill.search.refine`: :func:`refine_patchmatch`, the iterations at full resolution
  from a given fill, and :func:`refine_band`, a finished fill's hole and band re-synthesised.

:mod:`weft.core.fill.patchmatch` runs the iterations on every level of a pyramid.
"""

from .em import STEPS_FIRST, em
from .patches import MAX_PATCH, MIN_PATCH, Flat, box_sum, check_inputs
from .refine import REFINE_ITERATIONS, refine_band, refine_patchmatch
from .vote import VOTE_STRIDE, vote_mode

__all__ = [
    "MAX_PATCH",
    "MIN_PATCH",
    "REFINE_ITERATIONS",
    "STEPS_FIRST",
    "VOTE_STRIDE",
    "Flat",
    "box_sum",
    "check_inputs",
    "em",
    "refine_band",
    "refine_patchmatch",
    "vote_mode",
]
