"""NFPT: patch-based synthesis for non-frontal-parallel textures (Yan, Lee & Lin).

The pipeline of Fig. 2: a photo of a texture seen at an angle (I_0) is rectified from feature lines
(:mod:`weft.core.rectify`, §3) into a frontal texture I_r; a larger texture I_s is synthesized from it
patch by patch with the feature-weighted similarity and seam repair of §2
(:mod:`weft.core.nfpt.synthesis`); optionally I_s is put back into a chosen view (a quad or feature
lines, Fig. 2b) or into the photo itself, replacing the textured plane with a larger one.

Python API: :func:`synthesize` (§2 alone, any frontal texture), :func:`nfpt` (the whole pipeline).
Command line: ``weft nfpt PHOTO --lines L.json --size WxH -o OUT [--view V.json] [--into-photo]``;
without ``--lines`` the photo is taken as frontal already (plain §2 synthesis, the "without
view-warping" column of Figs. 3-4).
"""

from .method import DEFAULT_BLOCK as DEFAULT_BLOCK
from .method import DEFAULT_OVERLAP as DEFAULT_OVERLAP
from .method import METHOD, NfptParams, NfptResult, nfpt, synthesize
from .method import SELECT_SECONDS_PER_POSITION as SELECT_SECONDS_PER_POSITION
from .method import estimate_seconds as estimate_seconds
from .method import warm_up as warm_up
from .synthesis import Synthesis, distance_weights

__all__ = ["NfptParams", "NfptResult", "Synthesis", "distance_weights", "nfpt", "synthesize", "METHOD"]
