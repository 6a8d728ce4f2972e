"""
Non-frontal textures: rectify, synthesize, put back
===================================================

Yan, Lee & Lin synthesize a texture photographed at an angle: rectify it from feature lines,
synthesize it patch by patch, and put it back into a view. Every panel is computed with a
fixed seed; the printed figures are those in the captions.
"""

from __future__ import annotations

import cv2
import numpy as np
from weft.core.examples import RESOURCES, example
from weft.core.image import load_image, resize, save_image
from weft.core.metrics import coherence
from weft.core.nfpt import nfpt, synthesize
from weft.core.rectify import load_feature_lines, rectify, rectify_feature_lines

from benchmarks.fixtures.synthetic import folded_case, perspective_case

LINES = RESOURCES / "perspective-lines.json"
WALL = (125, 117, 248, 194)  # the largest upright rectangle inside the wall of perspective.png
SEED = 7


def _rgb(img: np.ndarray) -> np.ndarray:
    return np.repeat(img[..., None], 3, axis=2) if img.ndim == 2 else img


def _fit(img: np.ndarray, h: int) -> np.ndarray:
    """``img`` scaled to height ``h`` (area-averaged when shrinking)."""
    w = max(1, round(img.shape[1] * h / img.shape[0]))
    interp = "area" if h < img.shape[0] else "cubic"
    return _rgb(resize(img, (w, h), interpolation=interp))


def _label(img: np.ndarray, *lines: str) -> np.ndarray:
    img = _rgb(img)
    strip = np.full((8 + 18 * len(lines), img.shape[1], 3), 255, np.uint8)
    for k, text in enumerate(lines):
        cv2.putText(strip, text, (6, 19 + 18 * k), cv2.FONT_HERSHEY_SIMPLEX, 0.45, (20, 20, 20), 1, cv2.LINE_AA)
    return np.concatenate([img, strip.astype(np.float32) / 255.0], axis=0)


def _row(panels: list[np.ndarray], gap: int = 6) -> np.ndarray:
    h = max(p.shape[0] for p in panels)
    parts = []
    for i, p in enumerate(panels):
        pad = np.ones((h, p.shape[1], 3), np.float32)
        pad[: p.shape[0]] = p
        parts.append(pad)
        if i < len(panels) - 1:
            parts.append(np.ones((h, gap, 3), np.float32))
    return np.concatenate(parts, axis=1)


def _stack(rows: list[np.ndarray], gap: int = 10) -> np.ndarray:
    w = max(r.shape[1] for r in rows)
    parts = []
    for i, r in enumerate(rows):
        pad = np.ones((r.shape[0], w, 3), np.float32)
        pad[:, : r.shape[1]] = r
        parts.append(pad)
        if i < len(rows) - 1:
            parts.append(np.ones((gap, w, 3), np.float32))
    return np.concatenate(parts, axis=0)


def _draw_lines(img: np.ndarray, lines: np.ndarray, colour=(255, 220, 0)) -> np.ndarray:
    u8 = (np.clip(_rgb(img), 0, 1) * 255).astype(np.uint8).copy()
    for x1, y1, x2, y2 in lines:
        cv2.line(
            u8,
            (int(round(x1 * 4)), int(round(y1 * 4))),
            (int(round(x2 * 4)), int(round(y2 * 4))),
            colour,
            1,
            cv2.LINE_AA,
            shift=2,
        )
    return u8.astype(np.float32) / 255.0


def _comparison_row(photo, image_lines, crop_box, rectified, truth, size, title):
    x, y, w, h = crop_box
    crop = photo[y : y + h, x : x + w]
    without = synthesize(crop, size=size, rng=SEED)
    with_ = synthesize(rectified, size=size, rng=SEED)
    figs = {
        "without": (coherence(without, crop, stride=6), coherence(without, truth, stride=6)),
        "with": (coherence(with_, rectified, stride=6), coherence(with_, truth, stride=6)),
    }
    print(title, {k: tuple(round(v, 4) for v in f) for k, f in figs.items()})
    hh = 250
    return _row(
        [
            _label(_fit(_draw_lines(photo, image_lines), hh), f"(a) {title}", "feature lines in yellow"),
            _label(
                _fit(without, hh),
                "(b) synthesis without rectification",
                f"coherence {figs['without'][0]:.3f} own source, {figs['without'][1]:.3f} true",
            ),
            _label(_fit(rectified, hh), "(c) rectified (homography from the lines)", ""),
            _label(
                _fit(with_, hh),
                "(d) synthesis with rectification",
                f"coherence {figs['with'][0]:.3f} own source, {figs['with'][1]:.3f} true",
            ),
        ]
    )


def comparison() -> np.ndarray:
    photo = load_image(example("perspective")).image
    lines = load_feature_lines(LINES)
    rectified = rectify_feature_lines(photo, lines).image
    truth = load_image(example("perspective-frontal")).image
    top = _comparison_row(photo, lines.image_lines, WALL, rectified, truth, (384, 384), "brick wall photo")

    gravel = resize(load_image(example("gravel")).image, (400, 300), interpolation="cubic")
    case = perspective_case(gravel, yaw=50.0, pitch=-25.0, roll=5.0, seed=1)
    rect = rectify(case.photo, case.image_lines, case.frontal_lines, case.frontal_size).image
    mask = np.zeros(case.photo.shape[:2], np.uint8)
    corners = np.array([[-0.5, -0.5], [399.5, -0.5], [399.5, 299.5], [-0.5, 299.5]])
    from weft.core.rectify import apply_homography

    cv2.fillConvexPoly(mask, np.round(apply_homography(case.homography, corners)).astype(np.int32), 1)
    box = _largest_rectangle(cv2.erode(mask, np.ones((5, 5), np.uint8)))
    bottom = _comparison_row(
        case.photo, case.image_lines, box, rect, case.frontal, (320, 320), "gravel at 50° (synthetic)"
    )
    return _stack([top, bottom])


def _largest_rectangle(mask: np.ndarray) -> tuple[int, int, int, int]:
    """The largest upright rectangle of ones in ``mask``, as (x, y, w, h) (histogram method)."""
    best, box = 0, (0, 0, 1, 1)
    heights = np.zeros(mask.shape[1], int)
    for y in range(mask.shape[0]):
        heights = np.where(mask[y] > 0, heights + 1, 0)
        stack: list[tuple[int, int]] = []
        for x in range(mask.shape[1] + 1):
            cur = heights[x] if x < mask.shape[1] else 0
            start = x
            while stack and stack[-1][1] >= cur:
                s, hh = stack.pop()
                if hh * (x - s) > best:
                    best, box = hh * (x - s), (s, y - hh + 1, x - s, hh)
                start = s
            stack.append((start, cur))
    return tuple(int(v) for v in box)


def views() -> np.ndarray:
    photo = load_image(example("perspective")).image
    into = nfpt(photo, str(LINES), size=(768, 576), into_photo=True, rng=SEED)
    quad = '{"quad": [[40, 150], [440, 120], [470, 330], [10, 340]], "size": [480, 360]}'
    floor = nfpt(photo, str(LINES), size=(768, 576), view=quad, rng=SEED)
    hh = 300
    return _row(
        [
            _label(_fit(photo, hh), "the photo"),
            _label(_fit(into.image, hh), "--into-photo: the wall replaced by a", "768x576 synthesis (2.25x its area)"),
            _label(_fit(floor.image, hh), "--view quad.json: the synthesis laid", "as a floor"),
        ]
    )


def warps() -> np.ndarray:
    gravel = resize(load_image(example("gravel")).image, (400, 300), interpolation="cubic")
    case = perspective_case(gravel, seed=1)
    r = rectify(case.photo, case.image_lines, case.frontal_lines, case.frontal_size)
    from weft.core.metrics import psnr_db

    m = 15
    psnr = psnr_db(case.frontal[m:-m, m:-m], r.image[m:-m, m:-m])
    diff = np.clip(np.abs(r.image - case.frontal) * 4, 0, 1)
    hh = 220
    top = _row(
        [
            _label(
                _fit(_draw_lines(case.photo, case.image_lines), hh),
                "photo 640x480 (noise 0.01),",
                "10 grid lines (0.3 px noise)",
            ),
            _label(_fit(r.image, hh), "--warp homography", f"PSNR {psnr:.1f} dB on the interior"),
            _label(_fit(case.frontal, hh), "ground truth", ""),
            _label(_fit(diff, hh), "|difference| x 4", ""),
        ]
    )
    tex = resize(load_image(example("gravel")).image, (400, 300), interpolation="cubic")
    fold = folded_case(tex)
    panels = [
        _label(_fit(_draw_lines(fold.photo, fold.image_lines), hh), "a texture folded 35° (two planes),", "19 segments")
    ]
    for warp in ("homography", "lines", "morph"):
        out = rectify(fold.photo, fold.image_lines, fold.frontal_lines, fold.frontal_size, warp=warp)
        sel = out.mask & (fold.frontal > 0)
        corr = np.corrcoef(fold.frontal[sel], out.image[sel])[0, 1]
        print("fold", warp, round(float(corr), 3))
        panels.append(_label(_fit(out.image, hh), f"--warp {warp}", f"correlation with the truth {corr:.2f}"))
    panels.append(_label(_fit(fold.frontal, hh), "ground truth (the other view)", ""))
    return _stack([top, _row(panels)])


def repair() -> np.ndarray:
    fur = load_image(example("cat-fur")).image
    kw = dict(size=(160, 160), block=32, overlap=8, rng=3, return_details=True)
    raw = synthesize(fur, repair=False, **kw)
    fixed = synthesize(fur, **kw)
    smooth = synthesize(fur, smooth=True, **kw)
    marked = raw.image.copy()
    marked[fixed.repaired_mask] = [0.1, 0.9, 0.2]

    def z(a):
        return cv2.resize(a[:96, :96], (288, 288), interpolation=cv2.INTER_NEAREST)

    print("repair", fixed.figures())
    return _row(
        [
            _label(z(raw.image), "min-cut seams, no repair"),
            _label(z(marked), f"mismatched pixels ({fixed.repaired} of 160x160)"),
            _label(z(fixed.image), "after pixel re-synthesis"),
            _label(z(smooth.image), "... and --smooth (step 7)"),
        ]
    )


# %%
# With and without rectification
# ------------------------------
# The paper's Figs. 3-4: a perspective texture synthesized straight from the photo and after
# rectification, with coherence figures. Top: the bundled brick wall photo; bottom: gravel
# photographed at an angle (synthetic, known geometry). Coherence is ``weft.core.metrics.coherence``
# over the output's 7x7 patches on a 6-pixel grid (lower is better), against the texture each was
# made from and against the true frontal texture.

save_image("nfpt-comparison.jpg", comparison(), quality=88)


# %%
# Into the photo and into another view
# ------------------------------------
# The wall put back into the photo, larger, and into a view given by a quad (Fig. 2b).

save_image("nfpt-views.jpg", views(), quality=88)


# %%
# The three warps
# ---------------
# Rectification of a synthetic photo against its ground truth (homography), and a folded texture
# where only the paper's view morph is right.

save_image("nfpt-warps.jpg", warps(), quality=88)


# %%
# Seam repair
# -----------
# Steps 4-7: the minimum-error cuts and the mismatched pixels (green) before repair, after repair,
# and after the optional Gaussian filtering.

save_image("nfpt-repair.jpg", repair(), quality=88)
