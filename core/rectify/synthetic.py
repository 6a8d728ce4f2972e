"""A synthetic rectification case with known geometry, for the tests and the benchmarks.

:func:`perspective_case` photographs a frontal texture with a pinhole camera turned about the
texture's axes: the photo is the frontal image warped by a known homography (3x3 supersampled,
area-averaged, so it is a faithful photo rather than a resampling), over a grey gradient, plus
Gaussian noise; the feature lines are a grid of lines in the frontal frame and their images in the
photo with their end points perturbed by Gaussian noise (a user's clicks are not exact).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .homography import apply_homography

__all__ = ["SyntheticCase", "camera_homography", "perspective_case", "render_photo"]


@dataclass(frozen=True)
class SyntheticCase:
    """``photo``; ``frontal`` (ground truth); ``homography`` frontal -> photo; the lines (N, 4)."""

    photo: np.ndarray
    frontal: np.ndarray
    homography: np.ndarray
    image_lines: np.ndarray
    frontal_lines: np.ndarray

    @property
    def frontal_size(self) -> tuple[int, int]:
        return self.frontal.shape[1], self.frontal.shape[0]

    def lines_dict(self) -> dict:
        """The feature-lines JSON object (DESIGN.md), plus the true ``homography``."""
        return {"image_lines": self.image_lines.round(3).tolist(), "frontal_lines": self.frontal_lines.round(3).tolist(),
                "frontal_size": list(self.frontal_size), "homography": self.homography.tolist()}


def camera_homography(frontal_size: tuple[int, int], photo_size: tuple[int, int], *, yaw: float = 35.0,
                      pitch: float = -12.0, roll: float = 3.0, margin: float = 0.06) -> np.ndarray:
    """Frontal -> photo homography of a pinhole camera turned by ``yaw``, ``pitch``, ``roll`` degrees.

    The texture is the plane z = 0, centred on the origin; the camera looks at it from a distance of
    twice its width, rotated, and the projection is then scaled and shifted so that the texture fills
    the photo with ``margin`` (fraction of the photo's size) on its tightest side.
    """
    fw, fh = frontal_size
    pw, ph = photo_size
    y, p, r = (math.radians(v) for v in (yaw, pitch, roll))
    ry = np.array([[math.cos(y), 0, math.sin(y)], [0, 1, 0], [-math.sin(y), 0, math.cos(y)]])
    rx = np.array([[1, 0, 0], [0, math.cos(p), -math.sin(p)], [0, math.sin(p), math.cos(p)]])
    rz = np.array([[math.cos(r), -math.sin(r), 0], [math.sin(r), math.cos(r), 0], [0, 0, 1]])
    rot = rz @ rx @ ry
    dist = 2.0 * fw
    # plane point (X, Y, 0) -> camera coordinates rot @ (X - cx, Y - cy, 0) + (0, 0, dist)
    centre = np.array([[1, 0, -(fw - 1) / 2], [0, 1, -(fh - 1) / 2], [0, 0, 1]])
    h = np.column_stack([rot[:, 0], rot[:, 1], np.array([0.0, 0.0, dist])]) @ centre
    corners = np.array([[-0.5, -0.5], [fw - 0.5, -0.5], [fw - 0.5, fh - 0.5], [-0.5, fh - 0.5]])
    proj = apply_homography(h, corners)
    lo, hi = proj.min(axis=0), proj.max(axis=0)
    s = min((1 - 2 * margin) * pw / (hi[0] - lo[0]), (1 - 2 * margin) * ph / (hi[1] - lo[1]))
    off = np.array([pw, ph]) / 2 - s * (lo + hi) / 2 - 0.5
    fit = np.array([[s, 0, off[0]], [0, s, off[1]], [0, 0, 1]])
    out = fit @ h
    return out / out[2, 2]


def render_photo(frontal: np.ndarray, h: np.ndarray, photo_size: tuple[int, int], *, supersample: int = 3,
                 background: np.ndarray | None = None) -> np.ndarray:
    """The frontal image seen through ``h`` (frontal -> photo), supersampled and area-averaged."""
    import cv2

    pw, ph = photo_size
    s = supersample
    # photo sample (u, v) on the fine grid -> frontal point H^-1 (u, v)
    fine = np.array([[1.0 / s, 0, (1.0 / s - 1) / 2], [0, 1.0 / s, (1.0 / s - 1) / 2], [0, 0, 1]])
    inv = np.linalg.inv(h) @ fine
    warped = cv2.warpPerspective(frontal, inv, (pw * s, ph * s), flags=cv2.INTER_CUBIC | cv2.WARP_INVERSE_MAP,
                                 borderMode=cv2.BORDER_CONSTANT, borderValue=0)
    inside = cv2.warpPerspective(np.ones(frontal.shape[:2], np.float32), inv, (pw * s, ph * s),
                                 flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP, borderMode=cv2.BORDER_CONSTANT,
                                 borderValue=0)
    warped = np.clip(warped, 0, 1)
    cov = cv2.resize(inside, (pw, ph), interpolation=cv2.INTER_AREA)
    img = cv2.resize(warped, (pw, ph), interpolation=cv2.INTER_AREA)
    if background is None:
        g = np.linspace(0.75, 0.45, ph, dtype=np.float32)[:, None] * np.ones((1, pw), np.float32)
        background = g if frontal.ndim == 2 else np.repeat(g[..., None], 3, axis=2) * np.array([0.85, 0.9, 1.0],
                                                                                                np.float32)
    if img.ndim == 3:
        cov = cov[..., None]
    # the area average already holds cov x texture; add the background for the rest
    return np.clip(img + (1 - np.clip(cov, 0, 1)) * background, 0, 1).astype(np.float32)


def grid_lines(frontal_size: tuple[int, int], divisions: int = 4) -> np.ndarray:
    """``divisions + 1`` vertical and as many horizontal lines across the frontal frame (pixel centres)."""
    fw, fh = frontal_size
    out = []
    for k in range(divisions + 1):
        x = k * (fw - 1) / divisions
        out.append([x, 0.0, x, fh - 1.0])
    for k in range(divisions + 1):
        y = k * (fh - 1) / divisions
        out.append([0.0, y, fw - 1.0, y])
    return np.array(out, dtype=np.float64)


def perspective_case(frontal: np.ndarray, *, photo_size: tuple[int, int] = (640, 480), yaw: float = 35.0,
                     pitch: float = -12.0, roll: float = 3.0, noise: float = 0.01, line_noise: float = 0.3,
                     divisions: int = 4, seed: int = 0) -> SyntheticCase:
    """The frontal texture photographed at an angle, with noise, and grid feature lines.

    Parameters
    ----------
    frontal : float32 (h, w[, 3])
        The ground truth.
    photo_size : (width, height), default 640x480
    yaw, pitch, roll : float, degrees
        The camera's turn (see :func:`camera_homography`).
    noise : float, default 0.01
        Standard deviation of the Gaussian noise added to the photo (intensities in [0, 1]).
    line_noise : float, default 0.3
        Standard deviation in photo pixels of the noise on each line end point.
    divisions : int, default 4
        The grid: ``divisions + 1`` vertical and horizontal lines (10 lines for 4).
    seed : int
    """
    rng = np.random.default_rng(seed)
    fsize = (frontal.shape[1], frontal.shape[0])
    h = camera_homography(fsize, photo_size, yaw=yaw, pitch=pitch, roll=roll)
    photo = render_photo(frontal, h, photo_size)
    if noise > 0:
        photo = np.clip(photo + rng.normal(0.0, noise, photo.shape).astype(np.float32), 0, 1).astype(np.float32)
    fl = grid_lines(fsize, divisions)
    il = np.column_stack([apply_homography(h, fl[:, :2]), apply_homography(h, fl[:, 2:])])
    il = il + rng.normal(0.0, line_noise, il.shape)
    return SyntheticCase(photo, frontal.astype(np.float32), h, il, fl)


def _look(yaw: float, pitch: float) -> np.ndarray:
    y, p = math.radians(yaw), math.radians(pitch)
    ry = np.array([[math.cos(y), 0, math.sin(y)], [0, 1, 0], [-math.sin(y), 0, math.cos(y)]])
    rx = np.array([[1, 0, 0], [0, math.cos(p), -math.sin(p)], [0, math.sin(p), math.cos(p)]])
    return rx @ ry


def folded_case(texture: np.ndarray, *, size: tuple[int, int] = (480, 360), fold: float = 35.0,
                yaw: float = 25.0, pitch: float = -10.0, divisions: int = 4, seed: int = 0,
                noise: float = 0.005) -> SyntheticCase:
    """A texture folded along its vertical centre line (two planes), seen by two cameras.

    The non-planar scene ``--warp morph`` is for: the "frontal" image is the view of a camera facing
    the left half squarely, the photo a view from a camera turned by ``yaw``/``pitch``; the right half
    is folded away by ``fold`` degrees. The feature lines are, on each half separately, ``divisions``
    + 1 horizontal segments and the vertical segments of a grid (the fold line among them), so that
    every crossing of two segments is a real point of the surface. ``homography`` is None-like (the
    identity): no single homography relates the two views.
    """
    import cv2

    th, tw = texture.shape[:2]
    w, h = size
    half = (tw - 1) / 2.0
    a = math.radians(fold)

    def surface(x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Texture pixel (x, y) -> 3-D point; the texture is centred on the origin, 1 unit per pixel."""
        xx = np.where(x <= half, x - half, (x - half) * math.cos(a))
        zz = np.where(x <= half, 0.0, (x - half) * math.sin(a))
        return np.stack([xx, y - (th - 1) / 2.0, zz], axis=-1)

    dist = 1.6 * tw
    focal = 0.9 * w * dist / tw

    def camera(rot: np.ndarray):
        centre = -rot.T @ np.array([0.0, 0.0, dist])  # the camera looks at the origin from dist

        def project(pts: np.ndarray) -> np.ndarray:
            c = (pts - centre) @ rot.T
            return np.stack([focal * c[..., 0] / c[..., 2] + (w - 1) / 2, focal * c[..., 1] / c[..., 2] + (h - 1) / 2],
                            axis=-1)
        return project

    views = [camera(_look(yaw, pitch)), camera(np.eye(3))]
    images = []
    for project in views:
        # plane homographies texture -> image for each half, from 4 points each
        out = np.zeros((h, w) + texture.shape[2:], np.float32)
        for lo, hi in ((0.0, half), (half, tw - 1.0)):
            src = np.array([[lo, 0], [hi, 0], [hi, th - 1], [lo, th - 1]], np.float64)
            dst = project(surface(src[:, 0], src[:, 1]))
            hm = cv2.getPerspectiveTransform(src.astype(np.float32), dst.astype(np.float32)).astype(np.float64)
            part = render_photo(texture, hm, (w, h), background=np.zeros_like(out))
            m = np.zeros((th, tw), np.float32)
            m[:, int(math.floor(lo)):int(math.ceil(hi)) + 1] = 1.0
            cover = render_photo(m, hm, (w, h), background=np.zeros((h, w), np.float32))
            if out.ndim == 3:
                cover = cover[..., None]
            out = out * (1 - cover) + part * cover
        images.append(out.astype(np.float32))
    rng = np.random.default_rng(seed)
    photo = np.clip(images[0] + rng.normal(0, noise, images[0].shape), 0, 1).astype(np.float32)
    segs = []
    for k in range(divisions + 1):
        y = k * (th - 1) / divisions
        segs.append([0.0, y, half, y])
        segs.append([half, y, tw - 1.0, y])
    for k in range(2 * divisions + 1):
        x = k * (tw - 1) / (2 * divisions)
        segs.append([x, 0.0, x, th - 1.0])
    segs = np.array(segs)

    def lines_in(project):
        p = project(surface(segs[:, 0], segs[:, 1]))
        q = project(surface(segs[:, 2], segs[:, 3]))
        return np.column_stack([p, q])

    return SyntheticCase(photo, images[1], np.eye(3), lines_in(views[0]), lines_in(views[1]))
