"""Rectification of a non-frontal-parallel texture photo from feature lines (Yan, Lee & Lin, §3).

The user draws lines on the photo and gives where they lie in the frontal (rectified) frame
(feature-lines JSON of DESIGN.md); intersections of line pairs become point correspondences
(near-parallel pairs and intersections far outside a frame are ignored), and one of three warps
maps the photo onto the frontal frame:

* ``homography`` (default) -- least squares + robust refinement from the points and the lines;
  exact for a planar texture (:mod:`weft.core.rectify.homography`).
* ``morph`` -- the paper's view-morphing route: fundamental matrix (>= 8 points), pre-warp to
  parallel views, Beier-Neely morph, post-warp. **Degenerate when all the points lie on one plane**
  (the usual case for a texture photo): that is detected and reported instead of producing garbage.
* ``lines`` -- Beier-Neely's field morph straight from the line pairs (weights a, b, p), for
  textures on gently curved surfaces.

Python API
----------
``rectify(photo, image_lines, frontal_lines, frontal_size, warp=...)`` -> :class:`Rectified`
(frontal image, validity mask, homography, figures). For a live preview that follows a dragged line
end point, build a :class:`Rectifier` once per photo and call ``.rectify(...)`` per drag event (the
photo is validated once), or ``.warp(homography, frontal_size)`` when the homography is known.
:func:`load_feature_lines` reads the JSON. Re-projection into a view or back into the photo lives
in :mod:`weft.core.rectify.view` and is driven by :mod:`weft.core.nfpt`.

Without drawn lines, :func:`suggest_lines` proposes them from two families of straight lines in
the photo (:mod:`weft.core.rectify.detect`).

``weft rectify PHOTO --lines L.json -o OUT`` (or ``--auto``) is the command line of it.
"""

from .detect import REFUSAL, Suggestion, suggest_lines
from .homography import HomographyFit, apply_homography, fit_homography
from .lines import FeatureLines, line_correspondences, load_feature_lines, parse_feature_lines
from .method import FIGURES as FIGURES
from .method import INTERPOLATIONS as INTERPOLATIONS
from .method import METHOD, Rectified, Rectifier, RectifyParams, WarpParams, rectify, rectify_feature_lines, scale_lines
from .method import homography_figure as homography_figure
from .method import warm_up as warm_up
from .view import View, load_view
from .warps import PLANAR_TOL_PX as PLANAR_TOL_PX
from .warps import WARPS, WarpPlan, plan_warp
from .warps import homography_plan as homography_plan

__all__ = [
    "FeatureLines",
    "HomographyFit",
    "REFUSAL",
    "Suggestion",
    "suggest_lines",
    "Rectified",
    "Rectifier",
    "RectifyParams",
    "View",
    "WARPS",
    "WarpParams",
    "WarpPlan",
    "apply_homography",
    "fit_homography",
    "line_correspondences",
    "load_feature_lines",
    "load_view",
    "parse_feature_lines",
    "plan_warp",
    "rectify",
    "rectify_feature_lines",
    "scale_lines",
    "METHOD",
]
