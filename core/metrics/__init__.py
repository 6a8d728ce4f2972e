"""Quality figures every method reports: coherence, completeness, fidelity and SNR.

* :func:`coherence` -- does every patch of the output look like some patch of the source?
  (low is good; 0 means the output is made only of source patches).
* :func:`completeness` -- is every patch of the source represented somewhere in the output?
  (low is good; a tiny crop of the source is coherent but not complete).
* :func:`fidelity` -- does the output follow the target's large-scale luminance (texture transfer)?
  (Pearson correlation of blurred luminances, 1 is perfect).
* :func:`snr_db` -- signal-to-noise ratio of a reconstruction against its original, in decibels.
* :func:`fill_coherence`, :func:`fill_detail`, :func:`fill_seam` -- how a filled hole (or an uncropped
  border) reads against the known rest of its image: does it look like its surroundings, is it as
  detailed (not smeared), is its edge invisible.
* :func:`verbatim_fraction` -- the largest region of an output copied verbatim from its sample
  (connected pixels sharing one source offset, from the method's record of where each pixel came
  from), as a fraction of the sample's area (low is good: a large region is a visible strip).

Coherence and completeness are the two halves of the bidirectional similarity of Simakov et al.
(CVPR 2008), measured on 7x7 luminance patches with exact nearest neighbours. The search is a
chunked float32 BLAS product (``|a|^2 + |b|^2 - 2 a.b``) that picks the neighbour, followed by an
exact float64 recomputation of the chosen neighbour's distance, so a perfect match scores ~0.

Images are float32 in [0, 1], shape (H, W) or (H, W, 3); colour images are reduced to Rec. 601
luminance for the patch and fidelity measures.
"""

from .comparison import fidelity, psnr_db, snr_db
from .fill import fill_coherence, fill_detail, fill_seam
from .patches import _nearest_distances, coherence, completeness  # noqa: F401 (a test checks the search)
from .verbatim import verbatim_fraction, verbatim_region

__all__ = [
    "coherence",
    "completeness",
    "fidelity",
    "fill_coherence",
    "fill_detail",
    "fill_seam",
    "psnr_db",
    "snr_db",
    "verbatim_fraction",
    "verbatim_region",
]
