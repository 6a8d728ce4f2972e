"""Make weft's bundled example images from scikit-image's sample data.

Run once from the repository root (the outputs are committed; re-running reproduces them
byte for byte, the noise is seeded)::

    .venv/bin/python resources/make_examples.py

Every source image ships with scikit-image (``skimage.data``, no download); its licence is
recorded in ``resources/README.md``. Outputs:

* textures (grey): ``brick.png``, ``gravel.png``, ``grass.png`` -- 256x256 crops;
* textures (colour): ``wood-grain.png`` (coffee table top), ``cat-fur.png`` (Chelsea's forehead);
* a fractal (self-similar) image for super-resolution: ``clouds.png``; a pen-hatching style
  sample: ``hatching.png``;
* targets: ``camera.png``, ``astronaut.png`` (256x256), ``coffee.png``, ``chelsea.png`` (300x200);
* a perspective photo of a texture for the non-frontal-parallel method (``nfpt``):
  ``perspective-frontal.png`` (the frontal brick wall, ground truth), ``perspective.png`` (that wall
  warped by a known homography onto a gradient background with mild noise) and
  ``perspective-lines.json`` (feature lines in DESIGN.md's format plus the true homography).

Coordinates follow OpenCV: pixel (x, y) has its centre at integer (x, y), origin top-left.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import cv2
import numpy as np
from scipy.ndimage import gaussian_filter1d
from skimage import data

HERE = Path(__file__).resolve().parent
SEED = 20240607

# perspective example
FRONTAL_SIZE = (512, 384)  # (w, h) of the rectified brick wall: 12 courses of 32 px
COURSE = 32
PHOTO_SIZE = (480, 360)
SUPERSAMPLE = 3  # warp at 3x and area-average down, so the receding bricks do not alias
NOISE_SIGMA = 0.012


def _save(name: str, image: np.ndarray) -> Path:
    """Save float [0, 1] (H, W) or (H, W, 3) RGB as PNG, via weft.core.image.save_image when available."""
    path = HERE / name
    image = np.clip(np.asarray(image, dtype=np.float32), 0.0, 1.0)
    if str(HERE.parent) not in sys.path:
        sys.path.insert(0, str(HERE.parent))
    try:
        from weft.core.image import save_image
    except ImportError:
        save_image = None
    if save_image is not None:
        save_image(path, image)
    else:
        arr = np.rint(image * 255).astype(np.uint8)
        if arr.ndim == 3:
            arr = cv2.cvtColor(arr, cv2.COLOR_RGB2BGR)
        if not cv2.imwrite(str(path), arr):
            raise OSError(f"cannot write {path}")
    return path


def _f32(img: np.ndarray) -> np.ndarray:
    return img.astype(np.float32) / 255.0


def _resize_area(img: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    return cv2.resize(img, size, interpolation=cv2.INTER_AREA)


# ------------------------------------------------------------------------------------------
# the frontal brick wall


# ``data.brick()`` is itself a perspective view (its mortar lines converge). Rotated by 90 degrees
# its bed joints run left-right; these are rough (slope, intercept) of 13 consecutive bed joints,
# y = slope * x + intercept in the rotated 512x512 image, found by tracking the bright mortar
# rows. ``_refine_joint`` re-measures each to sub-pixel accuracy.
_ROUGH_JOINTS = [
    (-0.169, 88.3),
    (-0.143, 116.4),
    (-0.118, 145.2),
    (-0.094, 172.6),
    (-0.070, 201.9),
    (-0.044, 230.3),
    (-0.024, 262.5),
    (-0.001, 291.8),
    (0.026, 320.9),
    (0.049, 351.1),
    (0.074, 381.2),
    (0.100, 411.1),
    (0.126, 440.5),
]


def _refine_joint(img: np.ndarray, rough: tuple[float, float]) -> tuple[float, float]:
    """Least-squares line through the sub-pixel brightness peaks of a mortar joint near ``rough``."""
    slope, icpt = rough
    h, w = img.shape
    xs, ys = [], []
    for x0 in range(0, w - 12, 6):
        xc = x0 + 5.5
        prof = gaussian_filter1d(img[:, x0 : x0 + 12].mean(axis=1), 1.5)
        guess = int(round(slope * xc + icpt))
        lo, hi = max(1, guess - 4), min(h - 2, guess + 4)
        p = lo + int(np.argmax(prof[lo : hi + 1]))
        if p in (lo, hi):
            continue
        a, c, e = prof[p - 1], prof[p], prof[p + 1]
        den = a - 2 * c + e
        xs.append(xc)
        ys.append(p + (0.5 * (a - e) / den if den < 0 else 0.0))
    coef = np.polyfit(np.array(xs), np.array(ys), 1)
    return float(coef[0]), float(coef[1])


def frontal_brick_wall() -> tuple[np.ndarray, list[tuple[float, float]]]:
    """Rectify ``data.brick()`` into a frontal wall; return it (grey float32) and the joint rows.

    The quadrilateral between the first and last tracked bed joints and the image's left and
    right borders is mapped to a FRONTAL_SIZE rectangle, which makes all bed joints horizontal and
    evenly spaced. Returns the wall and, for each bed joint, its y at the left (x = 0) and right
    (x = w - 1) borders of the frontal frame (the joints are straight; residual tilt <= ~1.5 px).
    """
    rot = np.ascontiguousarray(np.rot90(data.brick())).astype(np.float32)
    joints = [_refine_joint(rot, r) for r in _ROUGH_JOINTS]
    w_in = rot.shape[1] - 1
    (s0, c0), (s1, c1) = joints[0], joints[-1]
    quad = np.float32([[0, c0], [w_in, s0 * w_in + c0], [w_in, s1 * w_in + c1], [0, c1]])
    fw, fh = FRONTAL_SIZE
    rect = np.float32([[0, 0], [fw - 1, 0], [fw - 1, fh - 1], [0, fh - 1]])
    rectify = cv2.getPerspectiveTransform(quad, rect)
    wall = cv2.warpPerspective(
        rot / 255.0, rectify, FRONTAL_SIZE, flags=cv2.INTER_CUBIC, borderMode=cv2.BORDER_REPLICATE
    )
    rows = []
    for s, c in joints:
        pts = np.float64([[[0, c], [w_in, s * w_in + c]]])
        mapped = cv2.perspectiveTransform(pts, rectify.astype(np.float64))[0]
        rows.append((float(mapped[0, 1]), float(mapped[1, 1])))
    return np.clip(wall, 0, 1).astype(np.float32), rows


def colourize_bricks(grey: np.ndarray) -> np.ndarray:
    """Terracotta bricks, light grey mortar: a tint that fades to neutral on bright pixels."""
    t = np.clip((grey - 0.42) / (0.68 - 0.42), 0.0, 1.0)
    t = t * t * (3 - 2 * t)  # smoothstep
    brick = np.array([1.45, 0.86, 0.66], np.float32)
    mortar = np.array([1.02, 1.0, 0.96], np.float32)
    tint = brick * (1 - t[..., None]) + mortar * t[..., None]
    return np.clip(grey[..., None] * tint, 0.0, 1.0).astype(np.float32)


# ------------------------------------------------------------------------------------------
# the perspective photo


def _rotation(yaw: float, pitch: float, roll: float) -> np.ndarray:
    y, p, r = np.radians([yaw, pitch, roll])
    ry = np.array([[np.cos(y), 0, np.sin(y)], [0, 1, 0], [-np.sin(y), 0, np.cos(y)]])
    rx = np.array([[1, 0, 0], [0, np.cos(p), -np.sin(p)], [0, np.sin(p), np.cos(p)]])
    rz = np.array([[np.cos(r), -np.sin(r), 0], [np.sin(r), np.cos(r), 0], [0, 0, 1]])
    return rz @ rx @ ry


def photo_homography(margin: float = 22.0) -> np.ndarray:
    """Frontal -> photo homography of a pinhole camera looking at the wall at an angle.

    The wall (1 frontal pixel = 1/256 m, centred on the origin of the plane Z = 0) is seen by a
    camera rotated 42 deg about the vertical, -15 deg about the horizontal and rolled 4 deg, 2.6 m
    away; the image is then scaled and shifted (a change of focal length and principal point) so
    that the wall fills PHOTO_SIZE with ``margin`` pixels to spare.
    """
    fw, fh = FRONTAL_SIZE
    k = 1 / 256
    plane = np.array([[k, 0, -(fw - 1) / 2 * k], [0, k, -(fh - 1) / 2 * k], [0, 0, 1]])
    r = _rotation(42, -15, 4)
    cam = np.c_[r[:, 0], r[:, 1], [0.0, 0.0, 2.6]]
    g = cam @ plane
    corners = np.array([[0, 0, 1], [fw - 1, 0, 1], [fw - 1, fh - 1, 1], [0, fh - 1, 1]], float).T
    p = g @ corners
    p = p[:2] / p[2]
    lo, hi = p.min(axis=1), p.max(axis=1)
    pw, ph = PHOTO_SIZE
    s = min((pw - 1 - 2 * margin) / (hi[0] - lo[0]), (ph - 1 - 2 * margin) / (hi[1] - lo[1]))
    centre = (lo + hi) / 2
    fit = np.array([[s, 0, (pw - 1) / 2 - s * centre[0]], [0, s, (ph - 1) / 2 - s * centre[1]], [0, 0, 1]])
    h = fit @ g
    return h / h[2, 2]


def background() -> np.ndarray:
    """A soft vertical gradient (pale blue-grey above, warm grey below) with a faint vignette."""
    pw, ph = PHOTO_SIZE
    yy, xx = np.mgrid[0:ph, 0:pw].astype(np.float32)
    t = (yy / (ph - 1))[..., None]
    top = np.array([0.78, 0.82, 0.86], np.float32)
    bottom = np.array([0.52, 0.48, 0.43], np.float32)
    bg = top * (1 - t) + bottom * t
    r2 = ((xx - pw / 2) / pw) ** 2 + ((yy - ph / 2) / ph) ** 2
    bg *= (1 - 0.25 * r2)[..., None]
    return bg.astype(np.float32)


def perspective_photo(frontal_rgb: np.ndarray, h: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Warp the frontal wall by ``h`` onto the background, anti-aliased, plus mild sensor noise."""
    pw, ph = PHOTO_SIZE
    n = SUPERSAMPLE
    # photo pixel x has its centre at supersampled x * n + (n - 1) / 2 under INTER_AREA
    up = np.array([[n, 0, (n - 1) / 2], [0, n, (n - 1) / 2], [0, 0, 1]]) @ h
    big = (pw * n, ph * n)
    tex = cv2.warpPerspective(frontal_rgb, up, big, flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
    fw, fh = FRONTAL_SIZE
    # coverage: the wall spans frontal pixel centres 0..w-1 plus half a pixel on each side
    mask = np.zeros((fh + 2, fw + 2), np.float32)
    mask[1:-1, 1:-1] = 1.0
    shift = np.array([[1, 0, -1], [0, 1, -1], [0, 0, 1]], float)  # mask pixel i+1 = frontal pixel i
    mask_big = cv2.warpPerspective(mask, up @ shift, big, flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT)
    tex = _resize_area(tex, PHOTO_SIZE)
    cover = _resize_area(mask_big, PHOTO_SIZE)[..., None]
    photo = background() * (1 - cover) + tex * cover
    photo += rng.normal(0.0, NOISE_SIGMA, photo.shape).astype(np.float32)
    return np.clip(photo, 0, 1).astype(np.float32)


def _apply(h: np.ndarray, line: list[float]) -> list[float]:
    pts = np.array([[line[0], line[1], 1.0], [line[2], line[3], 1.0]]).T
    q = h @ pts
    q = q[:2] / q[2]
    return [round(float(v), 3) for v in (q[0, 0], q[1, 0], q[0, 1], q[1, 1])]


def feature_lines(h: np.ndarray, joint_rows: list[tuple[float, float]]) -> dict:
    """The wall's four borders and two mortar bed joints, in the frontal frame and in the photo."""
    fw, fh = FRONTAL_SIZE
    x1, y1 = fw - 1, fh - 1
    frontal = [
        [0, 0, x1, 0],  # top border
        [x1, 0, x1, y1],  # right border
        [x1, y1, 0, y1],  # bottom border
        [0, y1, 0, 0],  # left border
    ]
    for j in (4, 8):  # two interior bed joints: the visible mortar lines themselves
        y_left, y_right = joint_rows[j]
        frontal.append([0, round(y_left, 3), x1, round(y_right, 3)])
    return {
        "image_lines": [_apply(h, line) for line in frontal],
        "frontal_lines": [[float(v) for v in line] for line in frontal],
        "frontal_size": [fw, fh],
        # extra key (not part of the feature-lines format): frontal (x, y, 1) -> photo, up to scale
        "homography": [[float(v) for v in row] for row in h],
    }


def _dump_json(doc: dict) -> str:
    """JSON with one line (or matrix row) per row: readable and diff-friendly."""
    parts = []
    for key, value in doc.items():
        if isinstance(value, list) and value and isinstance(value[0], list):
            rows = ",\n".join("    " + json.dumps(row) for row in value)
            parts.append(f"  {json.dumps(key)}: [\n{rows}\n  ]")
        else:
            parts.append(f"  {json.dumps(key)}: {json.dumps(value)}")
    text = "{\n" + ",\n".join(parts) + "\n}\n"
    assert json.loads(text) == doc
    return text


# ------------------------------------------------------------------------------------------


def fractal_clouds(size: int = 256, beta: float = 2.5, seed: int = SEED + 1) -> np.ndarray:
    """Fractional Brownian "clouds": random phases under a 1/f^(beta/2) amplitude spectrum.

    Statistically self-similar across scales by construction, so it is the kind of image Ashikhmin's
    super-resolution is meant for (his Fig. 6 uses an aerial photograph of a fractal terrain).
    """
    rng = np.random.default_rng(seed)
    fy = np.fft.fftfreq(size)[:, None]
    fx = np.fft.fftfreq(size)[None, :]
    f = np.hypot(fx, fy)
    f[0, 0] = 1.0
    spectrum = (rng.normal(size=(size, size)) + 1j * rng.normal(size=(size, size))) / f ** (beta / 2)
    spectrum[0, 0] = 0.0
    img = np.real(np.fft.ifft2(spectrum))
    return ((img - img.min()) / (img.max() - img.min())).astype(np.float32)


def hatching(size: int = 256, seed: int = SEED + 2) -> np.ndarray:
    """A pen-hatching "drawing" to use as an artistic style sample (cf. Ashikhmin Fig. 3b).

    A smooth random tone field is rendered with layers of short anti-aliased strokes: one direction
    where the tone is below 0.7, a crossing one below 0.45, a third below 0.25, so the sample holds
    every tone from paper white to dense cross-hatching.
    """
    rng = np.random.default_rng(seed)
    tone = cv2.GaussianBlur(rng.random((size, size)).astype(np.float32), (0, 0), size / 10)
    tone = (tone - tone.min()) / (tone.max() - tone.min())
    canvas = np.full((size * 2, size * 2), 255, np.uint8)  # drawn at 2x, shrunk: finer strokes
    for angle, threshold in ((np.pi / 4, 0.7), (-np.pi / 4, 0.45), (0.0, 0.25)):
        dx, dy = np.cos(angle), np.sin(angle)
        for _ in range(int(size * size * 0.09)):
            x, y = rng.uniform(0, size, 2)
            if tone[int(y), int(x)] > threshold:
                continue
            length = rng.uniform(6, 14)
            p0 = (int(2 * (x - dx * length / 2)), int(2 * (y - dy * length / 2)))
            p1 = (int(2 * (x + dx * length / 2)), int(2 * (y + dy * length / 2)))
            cv2.line(canvas, p0, p1, int(rng.uniform(20, 90)), 1, cv2.LINE_AA)
    return _resize_area(canvas, (size, size)).astype(np.float32) / 255.0


def main() -> None:
    rng = np.random.default_rng(SEED)
    made = []
    # grey textures
    made.append(_save("brick.png", _f32(data.brick()[:256, :256])))
    made.append(_save("gravel.png", _f32(data.gravel()[:256, :256])))
    made.append(_save("grass.png", _f32(data.grass()[:256, :256])))
    # colour textures
    made.append(_save("wood-grain.png", _f32(data.coffee()[272:400, 488:600])))
    made.append(_save("cat-fur.png", _f32(data.chelsea()[0:104, 202:306])))
    # targets
    made.append(_save("camera.png", _f32(_resize_area(data.camera(), (256, 256)))))
    made.append(_save("astronaut.png", _f32(_resize_area(data.astronaut(), (256, 256)))))
    made.append(_save("coffee.png", _f32(_resize_area(data.coffee(), (300, 200)))))
    made.append(_save("chelsea.png", _f32(_resize_area(data.chelsea(), (300, 200)))))
    # perspective photo
    wall, rows = frontal_brick_wall()
    wall_rgb = colourize_bricks(wall)
    h = photo_homography()
    made.append(_save("perspective-frontal.png", wall_rgb))
    made.append(_save("perspective.png", perspective_photo(wall_rgb, h, rng)))
    # a self-similar (fractal) image for super-resolution, and an artistic style sample
    made.append(_save("clouds.png", fractal_clouds()))
    made.append(_save("hatching.png", hatching()))
    lines_path = HERE / "perspective-lines.json"
    lines_path.write_text(_dump_json(feature_lines(h, rows)), encoding="utf-8")
    made.append(lines_path)
    total = 0
    for p in made:
        size = p.stat().st_size
        total += size
        print(f"{p.name:24s} {size / 1024:7.1f} KiB")
    print(f"{'total':24s} {total / 1024:7.1f} KiB")


if __name__ == "__main__":
    main()
