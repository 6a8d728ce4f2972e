"""Fast texture transfer (Ashikhmin 2003) on top of coherent synthesis (Ashikhmin 2001).

The result is grown one pixel at a time in scan-line order. Each already synthesized pixel of the
causal L-shaped half of an n x n neighbourhood proposes the source pixel next to the one it was
copied from (its source position shifted forward by its offset); with probability ``p`` one
uniformly random source position is added, with probability ``p_l`` the location-specific one
(x/m, y/m); duplicates are removed, and the candidate whose neighbourhood matches best is copied.

Choices where the paper is silent (all documented here and in :func:`transfer`):

* Candidates whose n x n source neighbourhood would leave the source are **clamped** into the valid
  region (a clamped candidate is one more nearby choice, where dropping it leaves fewer). Candidates outside
  a user's source mask are dropped. A pixel left with no candidate (the first pixel, or all dropped)
  gets a random one. The location-specific candidate is clamped likewise.
* ``remap`` (default on, not in the paper, which found equalisation unnecessary): matching uses the
  source luminance linearly mapped to the target's mean and standard deviation, as in Hertzmann et
  al.'s image analogies (a target brighter or darker than the source is still followed); the output
  still copies the source's own pixels.
* The target part of eq. 1 is the complementary half of the square, centre included (Fig. 1b: "the
  bottom half from the target image"); the ``target`` metric uses only that part.
* ``n`` in the artistic metric is the number of L-shape pixels actually compared (fewer at borders).
* Passes after the first (``iterations > 1``) use the whole square minus its centre, from the
  previous pass's result where this pass has not reached yet, both to propose candidates and for the
  result part of the metric (as the 2001 paper's later passes); the target part stays as above.
* Synthesis runs on luminance. Colour ``target`` keeps the target's chroma (YIQ), as the paper does;
  ``source`` copies the chosen source pixels' colour. ``auto`` is ``target`` for transfer and novel
  styles, ``source`` for synthesis and super-resolution.
"""

from . import checks as _checks
from .checks import memory_estimate
from .method import METHOD, warm_up
from .params import METRICS, MODES, FastParams
from .transfer import _transfer, transfer  # noqa: F401 (_transfer: the tests run it for its positions)

#: Peak memory per output pixel besides the inputs (result, positions, padded target, luminance and
#: colour copies, previews), fitted to the peak memory of ``weft fast`` transfers without the
#: libraries' share.
BYTES_PER_OUTPUT_PIXEL = _checks.BYTES_PER_OUTPUT_PIXEL

__all__ = [
    "BYTES_PER_OUTPUT_PIXEL",
    "FastParams",
    "METHOD",
    "METRICS",
    "MODES",
    "memory_estimate",
    "transfer",
    "warm_up",
]
