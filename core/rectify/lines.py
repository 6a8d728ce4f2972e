"""Feature lines: parsing, validation, and the point correspondences their intersections give.

The feature-lines JSON of DESIGN.md::

    {"image_lines":   [[x1, y1, x2, y2], ...],   # in the photo
     "frontal_lines": [[x1, y1, x2, y2], ...],   # in the frontal (rectified) frame
     "frontal_size":  [w, h]}

Line *i* of the photo corresponds to line *i* of the frontal frame; pixel coordinates, origin
top-left, OpenCV convention (pixel (x, y) has its centre at integer (x, y), so a frame of width w
spans x in [-0.5, w - 0.5]). Other keys (e.g. the ``"homography"`` of the bundled example) are
ignored.

Every problem is a one-line :class:`~weft.core.errors.GeometryError` naming the file (when there is
one), the key, the line index and the value.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import GeometryError
from ..geometry import FeatureLines

__all__ = [
    "FeatureLines",
    "Correspondences",
    "load_feature_lines",
    "parse_feature_lines",
    "check_lines",
    "line_correspondences",
    "MIN_LENGTH",
    "OUTSIDE_TOLERANCE",
    "MIN_ANGLE_DEG",
    "FAR_MARGIN",
]

MIN_LENGTH = 1.0  # pixels: a shorter line has no usable direction
OUTSIDE_TOLERANCE = 2.0  # pixels an end point may lie beyond the frame's edge (a drag just past it)
MIN_ANGLE_DEG = 2.0  # two lines closer to parallel than this (in either image) give no point
FAR_MARGIN = 0.5  # an intersection further than this many frame sizes outside the frame is dropped


def parse_feature_lines(data: Mapping[str, Any], *, source: str = "") -> FeatureLines:
    """Feature lines from the parsed JSON object of DESIGN.md (:meth:`FeatureLines.from_mapping`).

    Parameters
    ----------
    data : mapping
        ``{"image_lines": [...], "frontal_lines": [...], "frontal_size": [w, h]}``.
    source : str, optional
        A file name, put in front of error messages.

    Returns
    -------
    FeatureLines

    Raises
    ------
    GeometryError
        A malformed object; the message names the key and the value.
    """
    return FeatureLines.from_mapping(data, source=source)


def load_feature_lines(path_or_json: str | Path) -> FeatureLines:
    """Feature lines from a JSON file or from JSON text (:meth:`FeatureLines.parse`).

    Parameters
    ----------
    path_or_json : str or pathlib.Path
        A JSON file's name, or the JSON object itself as text (anything starting with ``{``).

    Returns
    -------
    FeatureLines

    Raises
    ------
    GeometryError
        A missing or unreadable file, invalid JSON or malformed lines; the message names the file.
    """
    return FeatureLines.parse(path_or_json)


def check_lines(
    lines: np.ndarray,
    size: tuple[int, int],
    *,
    key: str,
    frame: str,
    tolerance: float = OUTSIDE_TOLERANCE,
    input: str | None = None,
) -> None:
    """Raise GeometryError if a line is shorter than :data:`MIN_LENGTH` or leaves the frame.

    Parameters
    ----------
    lines : (N, 4) float array
    size : (width, height) of the frame the lines are drawn in.
    key : str
        Name of the lines in messages (``"image line"``, ``"frontal line"``).
    frame : str
        Name of the frame in messages (``"the photo"``).
    tolerance : float, default 2
        How far (pixels) an end point may lie beyond the frame's edge, ``[-0.5, w - 0.5]``.
    input : str, optional
        The method input that is the frame (``"photo"``): set as ``WeftError.input`` on an end
        point outside it, so that front ends name the image file (lines drawn for another photo).
    """
    w, h = size
    lo_x, hi_x = -0.5 - tolerance, w - 0.5 + tolerance
    lo_y, hi_y = -0.5 - tolerance, h - 0.5 + tolerance
    for i, (x1, y1, x2, y2) in enumerate(lines):
        length = math.hypot(x2 - x1, y2 - y1)
        if length < MIN_LENGTH:
            what = "zero length" if length == 0 else f"length {length:.2g} px (under {MIN_LENGTH:g} px)"
            raise GeometryError(f"{key} {i} has {what}: ({x1:g}, {y1:g}) to ({x2:g}, {y2:g})")
        for x, y in ((x1, y1), (x2, y2)):
            if not (lo_x <= x <= hi_x and lo_y <= y <= hi_y):
                error = GeometryError(f"{key} {i} end ({x:g}, {y:g}) is outside {frame} ({w}x{h})")
                error.input = input
                raise error


@dataclass(frozen=True)
class Correspondences:
    """Point correspondences from line intersections.

    ``dst`` and ``src`` are float64 (K, 2): the intersection of lines i and j in the destination
    frame and in the source frame; ``pairs`` (K, 2) int are the (i, j) of each point; ``skipped``
    counts pairs dropped as near-parallel or meeting far outside a frame.
    """

    dst: np.ndarray
    src: np.ndarray
    pairs: np.ndarray
    skipped_parallel: int
    skipped_far: int
    skipped_off_segment: int = 0

    def __len__(self) -> int:
        return len(self.dst)


def _homogeneous_lines(lines: np.ndarray) -> np.ndarray:
    """(N, 3) line coefficients (a, b, c), a x + b y + c = 0 with (a, b) of unit length."""
    p = np.column_stack([lines[:, 0], lines[:, 1], np.ones(len(lines))])
    q = np.column_stack([lines[:, 2], lines[:, 3], np.ones(len(lines))])
    ln = np.cross(p, q)
    return ln / np.hypot(ln[:, 0], ln[:, 1])[:, None]


def _on_segment(point: np.ndarray, line: np.ndarray, slack: float) -> bool:
    """Whether ``point`` projects onto the segment ``line`` extended by ``slack`` pixels at both ends."""
    p, q = line[:2], line[2:]
    d = q - p
    length = float(np.hypot(*d))
    t = float(np.dot(point - p, d)) / length
    return -slack <= t <= length + slack


def line_correspondences(
    dst_lines: np.ndarray,
    src_lines: np.ndarray,
    dst_size: tuple[int, int],
    src_size: tuple[int, int],
    *,
    min_angle: float = MIN_ANGLE_DEG,
    margin: float = FAR_MARGIN,
    segments_only: bool = False,
    segment_slack: float = 3.0,
) -> Correspondences:
    """Intersections of every pair of lines, as point correspondences between two frames.

    Parameters
    ----------
    dst_lines, src_lines : (N, 4) float arrays
        Corresponding lines ``[x1, y1, x2, y2]`` in the destination (e.g. frontal) and source
        (e.g. photo) frames.
    dst_size, src_size : (width, height)
        The frames, for the "far outside" test.
    min_angle : float, default 2 degrees
        A pair whose lines are closer to parallel than this **in either frame** is skipped (its
        intersection is ill-conditioned, or at infinity: a vanishing point).
    margin : float, default 0.5
        A pair whose intersection lies more than ``margin`` frame sizes outside either frame
        (outside ``[-margin w, (1 + margin) w] x [-margin h, (1 + margin) h]``) is skipped.
    segments_only : bool, default False
        Keep only pairs whose segments themselves cross (within ``segment_slack`` pixels of both
        segments' extents, in both frames). On a plane the extension of a line is still on the
        plane, so the default uses infinite lines; on a non-planar surface (``--warp morph``) two
        lines on different faces meet only where the segments do.
    segment_slack : float, default 3
        Pixels a crossing may lie beyond a segment's end and still count (``segments_only``).

    Returns
    -------
    Correspondences
        Section 3 of Yan, Lee & Lin: "We compute the intersections of these feature lines as
        feature points".
    """
    n = len(dst_lines)
    hd, hs = _homogeneous_lines(dst_lines), _homogeneous_lines(src_lines)
    sin_min = math.sin(math.radians(min_angle))
    dst_pts, src_pts, pairs = [], [], []
    parallel = far = off = 0
    (dw, dh), (sw, sh) = dst_size, src_size
    for i in range(n):
        for j in range(i + 1, n):
            ok = True
            pts = []
            for hl, (w, h) in ((hd, (dw, dh)), (hs, (sw, sh))):
                # |sin| of the angle between the unit normals = |a1 b2 - a2 b1|
                s = abs(hl[i, 0] * hl[j, 1] - hl[i, 1] * hl[j, 0])
                if s < sin_min:
                    ok = False
                    parallel += 1
                    break
                x = np.cross(hl[i], hl[j])
                if abs(x[2]) < 1e-12:  # parallel: they meet at infinity
                    ok = False
                    far += 1
                    break
                pt = x[:2] / x[2]
                if not (-margin * w <= pt[0] <= (1 + margin) * w and -margin * h <= pt[1] <= (1 + margin) * h):
                    ok = False
                    far += 1
                    break
                pts.append(pt)
            if not ok:
                continue
            if segments_only and not all(
                _on_segment(pt, lines[k], segment_slack)
                for pt, lines in ((pts[0], dst_lines), (pts[1], src_lines))
                for k in (i, j)
            ):
                off += 1
                continue
            dst_pts.append(pts[0])
            src_pts.append(pts[1])
            pairs.append((i, j))
    return Correspondences(
        np.array(dst_pts, dtype=np.float64).reshape(-1, 2),
        np.array(src_pts, dtype=np.float64).reshape(-1, 2),
        np.array(pairs, dtype=np.int64).reshape(-1, 2),
        parallel,
        far,
        off,
    )


def all_parallel(lines: Sequence[np.ndarray], min_angle: float = MIN_ANGLE_DEG) -> bool:
    """Whether every line of every given set is within ``min_angle`` of the first line's direction.

    Parameters
    ----------
    lines : sequence of ndarray, each (N, 4)
        Sets of lines ``x1, y1, x2, y2``.
    min_angle : float, default MIN_ANGLE_DEG
        Degrees.

    Returns
    -------
    bool
        True when they are all (nearly) parallel: they cannot fix a homography.
    """
    sin_min = math.sin(math.radians(min_angle))
    for ls in lines:
        hl = _homogeneous_lines(ls)
        s = np.abs(hl[0, 0] * hl[:, 1] - hl[0, 1] * hl[:, 0])
        if np.all(s < sin_min):
            return True
    return False
