"""Image quilting (Efros & Freeman 2001): texture synthesis and transfer by stitching blocks.

Implements everything the two write-ups in ``papers/`` describe (Ngo's "Texture Synthesis and
Transfer" and the "Image Quilting ... Poisson Blending" write-up):

* :func:`synthesize` -- a larger texture from a sample, in three modes (E&F §2, Fig. 2):
  ``random`` blocks tiled side by side; ``overlap`` blocks overlapping their left and top
  neighbours, each chosen by the SSD over the overlap against *every* source position; ``mincut``
  as ``overlap`` plus the minimum-error boundary cut (:mod:`weft.core.seams`). Three rules pick among the
  positions: the ``tol`` best at random (Ngo), all within ``(1 + epsilon)`` times the best (E&F
  §2.1), or the best 10% of a random 10% (the Poisson write-up). Options: ``poisson`` blends a band
  around every seam by a Poisson solve (the Poisson write-up); ``tile`` makes the output wrap.
* :func:`transfer` -- the texture re-rendered to follow a target (E&F §3): the cost is
  ``alpha * overlap SSD + (1 - alpha) * correspondence SSD`` over blurred luminance (or raw
  luminance, or user-given maps), the first block the best correspondence, tol = 1; with
  ``iterations`` N > 1 the block and overlap shrink by a third per pass, alpha follows
  ``alpha_i = alpha + (0.9 - alpha)(i - 1)/(N - 1)`` (the papers' ``0.8 (i-1)/(N-1) + 0.1`` for the
  default alpha 0.1) and the cost adds ``alpha_i`` times the SSD to the previous pass's result.

How a block is chosen (the speed of it): the SSD of the block's template (the pixels already in
place, the target's correspondence map, the previous pass) against every source position is
``sum w F² - 2 sum w G F + sum w G²``. The first sum depends only on the template's weights and is
computed once per overlap shape (``cv2.filter2D`` of the squared source); the cross-correlation
is one FFT product with source spectra computed once per pass (``cv2.dft``); the per-block work
-- choosing, the dynamic-programming cut, pasting and the Poisson band -- is done by numba kernels
(``weft.core._kernels.quilting``; one per selection rule and a separate Poisson band, so that a run
compiles only what it uses). Source and templates are centred on the source's mean so the float32
FFT loses little to cancellation.
"""

from .checks import estimate_seconds as estimate_seconds
from .checks import memory_estimate as memory_estimate
from .engine import _K, RULES, _pad_to, _Pass, _quilt_pass  # noqa: F401 (tests compare _K to the kernel)
from .method import METHOD
from .method import warm_up as warm_up
from .params import CORR_SIGMA as CORR_SIGMA
from .params import CORRESPONDENCES as CORRESPONDENCES
from .params import ITERATIVE_BLOCK as ITERATIVE_BLOCK
from .params import MIN_BLOCK as MIN_BLOCK
from .params import MIN_OVERLAP as MIN_OVERLAP
from .params import MODES as MODES
from .params import SYNTH_BLOCK_MAX as SYNTH_BLOCK_MAX
from .params import SYNTH_TOL as SYNTH_TOL
from .params import TRANSFER_BLOCK as TRANSFER_BLOCK
from .params import QuiltParams, transfer_schedule
from .params import synth_block as synth_block
from .params import synth_tol as synth_tol
from .synthesis import synthesize
from .transfer import transfer

__all__ = ["QuiltParams", "synthesize", "transfer", "transfer_schedule", "METHOD"]
