"""Suggested feature lines: two vanishing directions found in the photo, and the lines they imply.

A photo of a planar texture with straight structure (mortar joints, tiles, a weave, lines of text)
shows two families of lines, each converging to a vanishing point. :func:`suggest_lines` finds
them and turns them into feature-line pairs the user can edit like drawn ones:

1. line segments (OpenCV's LSD) on the photo reduced to 720 pixels (:mod:`.segments`); a second
   look at up to 1600 pixels when few segments show (fine structure, a weave); each segment then
   refitted on the photo's full resolution (the sub-pixel peaks of the gradient across it, away
   from its ends): on a steep view a segment is a few reduced pixels long, and its direction would
   otherwise be known to a few degrees only;
2. vanishing points (:mod:`.vanishing`): RANSAC over pairs of segments (a segment supports a point
   when its direction points at it within 1.5 degrees, or a pixel over its length), the best
   supported point first, then the best supported among the other segments on the first family's
   region (clutter beside the surface counts a tenth) that a camera can see as perpendicular; each
   refined on the angles between segments and point, then over whole lines (collinear segments
   chained: a mortar joint broken at every brick, a checkerboard's edge). Two families of
   comparable strength with a third nearly as strong (the edges of hexagonal cells) are refused:
   which two are perpendicular is open;
3. rectification (:mod:`.suggest`): the vanishing line sent to infinity (affine), then the two
   directions made perpendicular and of equal scale (metric) with a camera of square pixels whose
   principal point is the photo's centre; the two orthogonal vanishing points then fix the focal
   length. When they cannot (a vanishing point at infinity), the aspect is left to an assumed focal
   length of 1.2 times the photo's longer side, and the suggestion says so;
4. feature lines: two long, well separated segments of each family, extended across the textured
   region, paired with their axis-aligned images in the frontal frame: four pairs fix the
   homography exactly, so every end the user drags moves the frontal view (with more, the robust
   fit would outvote one moved line).

Where segments give no two families, segments joining the texture's own repeats (SIFT features on
the photo reduced to 400 pixels, matched within the photo) take their place: the line through a
feature and its repeat points at the vanishing point of the repeat's direction on the plane; every
translation of the lattice has its point on the horizon, and the best supported pair a camera sees
as perpendicular is taken.

When nothing gives two families it raises :class:`~weft.core.errors.GeometryError` with one line
(:data:`REFUSAL`); it never returns a guess it has no support for. A photo cropped off-centre breaks
the principal-point assumption: the aspect is then off by about the crop's offset (the bundled
example's principal point lies 31 pixels from its photo's centre: even its true vanishing points
give an aspect 4.4 % too wide).

References
----------
Yan, Lee & Lin, "Patch-based synthesis of non-frontal-parallel textures", §3 (the feature lines this
module proposes).
Hartley & Zisserman, *Multiple View Geometry*, 2nd ed., §2.7 (affine and metric rectification) and
§8.6-8.8 (vanishing points, the image of the absolute conic, focal length from two orthogonal
vanishing points).
Grompone von Gioi et al., "LSD: a fast line segment detector with a false detection control",
IPOL 2012.
Bharadwaj, Collins & Liu, "R-VPD: repeated-pattern vanishing point detection", 2024 (repeats as
evidence of vanishing directions).
"""

from .segments import LSD_SCALE, WORK_SIDE
from .suggest import (
    ASSUMED_FOCAL,
    MIN_CONFIDENCE,
    REFUSAL,
    Suggestion,
    suggest_for_studio,
    suggest_lines,
    suggestion_from_families,
)
from .vanishing import INLIER_DEG, MIN_FOCAL

__all__ = [
    "Suggestion",
    "suggest_lines",
    "suggest_for_studio",
    "suggestion_from_families",
    "REFUSAL",
    "WORK_SIDE",
    "LSD_SCALE",
    "INLIER_DEG",
    "ASSUMED_FOCAL",
    "MIN_CONFIDENCE",
    "MIN_FOCAL",
]
