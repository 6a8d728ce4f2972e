"""Re-projection (Yan, Lee & Lin, Fig. 2b): a frontal texture put into a chosen view or into the photo.

A view file (``--view V.json``) gives the view in one of two ways, in the synthesized texture's
pixel coordinates (origin top-left, pixel centres at integers):

* a quad -- where the texture's four corners land, top-left, top-right, bottom-right, bottom-left::

      {"quad": [[x, y], [x, y], [x, y], [x, y]], "size": [w, h]}

* feature lines -- lines in the view and the matching lines in the texture (like the feature-lines
  JSON, with the texture in the role of the frontal frame)::

      {"image_lines": [[x1, y1, x2, y2], ...], "frontal_lines": [[x1, y1, x2, y2], ...], "size": [w, h]}

``size`` is the view's width and height; without it the view has the photo's size. Pixels of the
view that the texture does not cover are black (0).
"""

from __future__ import annotations

import json
import math
import numbers
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import GeometryError
from ..geometry import as_lines as _as_lines
from ..geometry import as_size as _as_size
from ..geometry import read_json_or_file as read_json
from ..geometry.reading import _short
from ..params import MAX_SIDE
from .homography import apply_homography
from .lines import check_lines
from .warps import WarpPlan, homography_plan, plan_warp

__all__ = ["View", "load_view", "parse_view", "quad_homography", "view_plan", "into_photo_plan", "SUPERSAMPLE"]

SUPERSAMPLE = 3  # samples per side per output pixel when a texture is put into a (receding) view


@dataclass(frozen=True, eq=False)
class View:
    """A view: its ``size`` (or None: the photo's) and either a ``quad`` (4, 2) or line pairs.

    ``view_lines`` are in the view, ``texture_lines`` the matching lines in the texture frame.
    """

    size: tuple[int, int] | None
    quad: np.ndarray | None = None
    view_lines: np.ndarray | None = None
    texture_lines: np.ndarray | None = None

    def with_size(self, default: tuple[int, int]) -> tuple[int, int]:
        return self.size if self.size is not None else (default[0], default[1])

    # A typed geometry parameter (weft.core.geometry): parsed at the edges, written once.
    METAVAR = "VIEW"

    def to_json(self) -> dict[str, Any]:
        out: dict[str, Any] = {}
        if self.quad is not None:
            out["quad"] = np.asarray(self.quad).tolist()
        else:
            out["image_lines"] = np.asarray(self.view_lines).tolist()
            out["frontal_lines"] = np.asarray(self.texture_lines).tolist()
        if self.size is not None:
            out["size"] = list(self.size)
        return out

    def __eq__(self, other) -> bool:
        return isinstance(other, View) and self.to_json() == other.to_json()

    def __hash__(self) -> int:
        return hash(json.dumps(self.to_json()))

    @classmethod
    def parse(cls, text: str | Path, name: str = "view") -> View:
        """Command-line text: the JSON object itself (starts with ``{``) or a JSON file's name."""
        return load_view(text)

    @classmethod
    def coerce(cls, value: Any, name: str = "view") -> View:
        if isinstance(value, View):
            return value
        if isinstance(value, dict):
            return parse_view(value)
        if isinstance(value, (str, Path)):
            return load_view(value)
        raise GeometryError(f"parameter '{name}' = {_short(repr(value))} must be a view (a quad or line pairs)")

    @classmethod
    def from_json(cls, data: Any, name: str = "view", base=None) -> View:
        from ..geometry.reading import _from_json_or_path

        return _from_json_or_path(cls, data, name, base, "view")


def parse_view(data: Any, *, source: str = "") -> View:
    """A :class:`View` from the parsed JSON (see the module docstring).

    Parameters
    ----------
    data : object
        The parsed JSON: ``{"quad": [...]}`` or ``{"image_lines": [...], "frontal_lines": [...]}``,
        with an optional ``"size"``.
    source : str, optional
        A file name, put in front of error messages.

    Returns
    -------
    View

    Raises
    ------
    GeometryError
        Not an object, a malformed quad or lines, or lines that do not pair up.
    """
    prefix = f"{source}: " if source else ""
    try:
        if not isinstance(data, dict):
            raise GeometryError(f"a view must be a JSON object, not {type(data).__name__}")
        size = _as_size(data["size"], "size") if "size" in data else None
        if "quad" in data:
            q = data["quad"]
            if (
                not isinstance(q, list)
                or len(q) != 4
                or not all(
                    isinstance(c, list)
                    and len(c) == 2
                    and all(isinstance(v, numbers.Real) and not isinstance(v, bool) for v in c)
                    for c in q
                )
            ):
                raise GeometryError(
                    f"quad = {_short(q)} must be four corners [[x, y], ...] (top-left, top-right, "
                    f"bottom-right, bottom-left)"
                )
            quad = np.array(q, dtype=np.float64)
            if not np.all(np.isfinite(quad)):
                raise GeometryError(f"quad = {_short(q)} has a NaN or infinite coordinate")
            return View(size, quad=quad)
        if "image_lines" in data or "frontal_lines" in data:
            for key in ("image_lines", "frontal_lines"):
                if key not in data:
                    raise GeometryError(
                        f'no "{key}" (a view by lines needs image_lines in the view and the '
                        f"matching frontal_lines in the texture)"
                    )
            vl = _as_lines(data["image_lines"], "image_lines")
            tl = _as_lines(data["frontal_lines"], "frontal_lines")
            if len(vl) != len(tl):
                raise GeometryError(f"{len(vl)} image_lines but {len(tl)} frontal_lines: they must pair up")
            return View(size, view_lines=vl, texture_lines=tl)
        raise GeometryError('a view needs a "quad" (4 corners) or "image_lines" + "frontal_lines"')
    except GeometryError as e:
        raise GeometryError(prefix + str(e)) from None


def load_view(path_or_json: str | Path) -> View:
    """Read a view from a JSON file or inline JSON text (see the module docstring).

    Parameters
    ----------
    path_or_json : str or pathlib.Path
        A JSON file's name, or the JSON object itself as text.

    Returns
    -------
    View

    Raises
    ------
    GeometryError
        A missing file, invalid JSON, a malformed quad or lines; the message names the file.
    """
    data, source = read_json(path_or_json, "view")
    return parse_view(data, source=source)


def quad_homography(quad: np.ndarray, texture_size: tuple[int, int]) -> np.ndarray:
    """The homography view -> texture that sends the quad's corners to the texture's corners.

    The corners are those of the texture's pixel area, ``(-0.5, -0.5)`` to ``(w - 0.5, h - 0.5)``.

    Parameters
    ----------
    quad : ndarray, (4, 2)
        Where the texture's corners land in the view: top-left, top-right, bottom-right, bottom-left.
    texture_size : (int, int)
        The texture's width and height.

    Returns
    -------
    ndarray, float64 (3, 3)

    Raises
    ------
    GeometryError
        The quad is degenerate (three corners on a line) or not convex.

    References
    ----------
    Yan, Lee & Lin, "Patch-based synthesis for non-frontal-parallel textures", §3 (putting the
    synthesized texture back into a view).
    """
    q = np.asarray(quad, dtype=np.float64).reshape(4, 2)
    for i in range(4):
        a, b, c = q[i], q[(i + 1) % 4], q[(i + 2) % 4]
        cross = (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0])
        if abs(cross) < 1e-6 * max(1.0, float(np.ptp(q)) ** 2):
            raise GeometryError(f"quad corners {i}, {(i + 1) % 4}, {(i + 2) % 4} lie on one line: {_short(q.tolist())}")
    signs = []
    for i in range(4):
        a, b, c = q[i], q[(i + 1) % 4], q[(i + 2) % 4]
        signs.append(np.sign((b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0])))
    if len(set(signs)) != 1:
        raise GeometryError(
            f"quad {_short(q.tolist())} is not convex (corners must go round: top-left, top-right, "
            f"bottom-right, bottom-left)"
        )
    w, h = texture_size
    rect = np.array([[-0.5, -0.5], [w - 0.5, -0.5], [w - 0.5, h - 0.5], [-0.5, h - 0.5]])
    import cv2

    return cv2.getPerspectiveTransform(q.astype(np.float32), rect.astype(np.float32)).astype(np.float64)


def view_plan(
    view: View,
    texture_size: tuple[int, int],
    default_size: tuple[int, int],
    *,
    warp: str = "homography",
    a: float = 1.0,
    b: float = 2.0,
    p: float = 0.5,
) -> WarpPlan:
    """The warp that puts a texture of ``texture_size`` into ``view``.

    Parameters
    ----------
    view : View
    texture_size : (width, height) of the synthesized texture.
    default_size : (width, height)
        The view's size when the view file gives none (the photo's).
    warp, a, b, p
        As for rectification (:func:`~weft.core.rectify.warps.plan_warp`); a quad always uses its
        homography.
    """
    size = view.with_size(default_size)
    if not all(1 <= s <= MAX_SIDE for s in size):
        raise GeometryError(f"view size {size[0]}x{size[1]} has a side outside 1..{MAX_SIDE}")
    if view.quad is not None:
        h = quad_homography(view.quad, texture_size)
        # scale so that the third coordinate is positive inside the quad (at its centroid)
        plan = homography_plan(h, size, texture_size, positive_at=tuple(view.quad.mean(axis=0)))
        plan.figures = {"view": "quad"}
        return plan
    # the view lines must lie in the view; the texture lines may reach beyond the texture (the plane
    # goes on), they only must not be zero-length
    assert view.view_lines is not None and view.texture_lines is not None  # a view is a quad or two line sets
    check_lines(view.view_lines, size, key="view line", frame="the view")
    check_lines(view.texture_lines, texture_size, key="texture line", frame="the texture", tolerance=math.inf)
    return plan_warp(
        view.view_lines,
        view.texture_lines,
        size,
        texture_size,
        warp=warp,
        a=a,
        b=b,
        p=p,
        dst_name="the view",
        src_name="the texture",
        dst_key="view line",
        src_key="texture line",
        check=False,
    )


def into_photo_plan(
    rect_plan: WarpPlan,
    image_lines: np.ndarray,
    frontal_lines: np.ndarray,
    frontal_size: tuple[int, int],
    photo_size: tuple[int, int],
    texture_size: tuple[int, int],
    *,
    warp: str = "homography",
    a: float = 1.0,
    b: float = 2.0,
    p: float = 0.5,
) -> WarpPlan:
    """The warp that puts a synthesized texture into the photo, over the rectified plane.

    The texture (``texture_size``) is centred on the frontal frame (``frontal_size``): its pixel
    (x, y) is frontal point ``(x + ox, y + oy)`` with ``o = (frontal_size - texture_size) / 2``, so a
    larger texture extends the plane equally on every side. A homography rectification is simply
    inverted (the same fit, photo -> frontal, shifted by o); the other warps are fitted again with
    the photo as the destination.

    Parameters
    ----------
    rect_plan : WarpPlan
        The rectification's plan (photo -> frontal frame).
    image_lines, frontal_lines : ndarray, (N, 4)
        The feature lines in the photo and in the frontal frame.
    frontal_size, photo_size, texture_size : (int, int)
        Width and height of each frame.
    warp, a, b, p
        As in :func:`weft.core.rectify.rectify`.

    Returns
    -------
    WarpPlan
        Texture -> photo.

    References
    ----------
    Yan, Lee & Lin, "Patch-based synthesis for non-frontal-parallel textures", §3.
    """
    fw, fh = frontal_size
    tw, th = texture_size
    ox, oy = (fw - tw) / 2.0, (fh - th) / 2.0
    if warp == "homography" and rect_plan.homography is not None:
        shift = np.array([[1.0, 0.0, -ox], [0.0, 1.0, -oy], [0.0, 0.0, 1.0]])
        h = shift @ np.linalg.inv(rect_plan.homography)
        # positive third coordinate on the plane as the photo sees it: at the photo image of the frontal centre
        c = apply_homography(rect_plan.homography, np.array([[(fw - 1) / 2, (fh - 1) / 2]]))[0]
        return homography_plan(h, photo_size, texture_size, positive_at=(c[0], c[1]))
    shifted = frontal_lines - np.array([ox, oy, ox, oy])
    return plan_warp(image_lines, shifted, photo_size, texture_size, warp=warp, a=a, b=b, p=p, check=False)
