"""Affine prototype model (Smith & Bhalerao, "Texture transfer using affine transformation groups
and patch boundary matching"): synthesis, texture transfer by prototype swap, boundary matching.

A texture is modelled as one *prototype* patch and, for every B x B target patch (overlapping by
B/2), an affine transform and an intensity factor that map the prototype onto it. The pieces, one
per section of the paper:

==========================  =====================================================================
§2.1 centroids              :func:`centroids` (:mod:`weft.core.affine.spectral`)
§2.2 linear transforms      :func:`candidate_transforms` (:mod:`weft.core.affine.transforms`)
§2.3 translation            :func:`correlate_shifts`
§2.4 best transform         :func:`analyse` (:mod:`weft.core.affine.analysis`)
§3.1 cos² windows           :func:`cos2_window`
§3.2 intensity factors      :func:`analyse`
§3 synthesis                :func:`render` (:mod:`weft.core.affine.synthesis`), :class:`Grid`
§3.3 lowpass (add/absorb)   :func:`lowpass`, :func:`decompose` (:mod:`weft.core.affine.model`)
§3.4 colour (YUV/PCA)       :func:`decompose`, :func:`make_prototype`
§4 transfer                 ``analyse(prototype_image=...)``; :func:`render` with another prototype
§4 boundary matching        :func:`match_boundaries` (partial correlation, shaker box)
Fig. 6 parametric fields    :func:`field_model` (:mod:`weft.core.affine.fields`)
==========================  =====================================================================

:func:`synthesize` does it all in one call with the parameters of ``weft affine``
(:class:`AffineParams`). For a live preview while the user drags the prototype, analyse once and
call :func:`render` with each new prototype (``reuse transforms``).

Example
-------
>>> from weft.core.affine import analyse, render, make_prototype
>>> from weft.core.examples import example
>>> from weft.core.image import load_image
>>> tex = load_image(example("brick")).image[:128, :128]
>>> model = analyse(tex, prototype=(32, 32, 64), block=32)
>>> out = render(model)                                   # the synthesis
>>> moved = render(model, make_prototype(tex, (40, 30, 64), block=32))  # a prototype swap
>>> out.shape, moved.shape
((128, 128), (128, 128))
"""

from .analysis import analyse, levenberg_marquardt
from .boundary import BoundaryReport, match_boundaries, total_boundary_error
from .fields import field_model, field_transforms
from .method import METHOD, synthesize, warm_up
from .model import AffineModel, Decomposition, Grid, Prototype, decompose, lowpass, make_prototype, prototype_from_patch
from .params import AffineParams, check_rect, default_rect
from .spectral import Centroids, centroid_pairs, centroids, cos2_window, segment_sums
from .synthesis import compose, render
from .transforms import candidate_transforms, correlate_shifts, regularise_pairs, sampling_matrices

__all__ = [
    "METHOD",
    "AffineModel",
    "AffineParams",
    "BoundaryReport",
    "Centroids",
    "Decomposition",
    "Grid",
    "Prototype",
    "analyse",
    "candidate_transforms",
    "centroid_pairs",
    "centroids",
    "check_rect",
    "compose",
    "correlate_shifts",
    "cos2_window",
    "decompose",
    "default_rect",
    "field_model",
    "field_transforms",
    "levenberg_marquardt",
    "lowpass",
    "make_prototype",
    "match_boundaries",
    "prototype_from_patch",
    "regularise_pairs",
    "render",
    "sampling_matrices",
    "segment_sums",
    "synthesize",
    "total_boundary_error",
    "warm_up",
]
