"""Benchmark cases of rectification (``weft.core.rectify``) and NFPT synthesis (``weft.core.nfpt``).

The figures of the rectification case come from the synthetic known-geometry case of
:func:`benchmarks.fixtures.synthetic.perspective_case` (gravel enlarged to 400x300, photographed at
35°/-12°/3° into 640x480, noise 0.01, a 5 x 5 grid of lines with 0.3 px noise on every end point):
PSNR of the fitted rectification against the ground truth on the interior, with the same for the
exact homography and for one shifted by 0.5 px as the scale of the criterion.
"""

from __future__ import annotations

import json
import statistics
import time
from functools import lru_cache

import numpy as np
from weft.core.examples import RESOURCES, example
from weft.core.image import load_image, resize
from weft.core.metrics import coherence, completeness, psnr_db

from .base import Case, Input

LINES = RESOURCES / "perspective-lines.json"
WALL = (125, 117, 248, 194)  # the largest upright rectangle inside the wall of perspective.png


def _scaled_lines(factor: float) -> str:
    """The bundled feature lines for perspective.png scaled by ``factor`` (inline JSON)."""
    data = json.loads(LINES.read_text())
    image = (np.array(data["image_lines"]) + 0.5) * factor - 0.5
    return json.dumps(
        {
            "image_lines": image.round(4).tolist(),
            "frontal_lines": data["frontal_lines"],
            "frontal_size": data["frontal_size"],
        }
    )


def _interior(img: np.ndarray, frac: float = 0.05) -> np.ndarray:
    h, w = img.shape[:2]
    m = int(frac * min(h, w))
    return img[m : h - m, m : w - m]


@lru_cache(maxsize=1)
def synthetic_accuracy() -> dict[str, float]:
    """Accuracy (and the time of the fit + warp alone) on the synthetic known-geometry case."""
    from weft.core.rectify import Rectifier, apply_homography

    from benchmarks.fixtures.synthetic import perspective_case

    frontal = resize(load_image(example("gravel")).image, (400, 300), interpolation="cubic")
    case = perspective_case(frontal, seed=1)
    rect = Rectifier(case.photo)
    fs = case.frontal_size
    out = rect.rectify(case.image_lines, case.frontal_lines, fs)
    times = []
    for _ in range(15):
        t0 = time.perf_counter()
        rect.rectify(case.image_lines, case.frontal_lines, fs)
        times.append(time.perf_counter() - t0)
    exact = rect.warp(case.homography, fs).image
    shifted = rect.warp(case.homography @ np.array([[1, 0, 0.5], [0, 1, 0], [0, 0, 1.0]]), fs).image
    xs, ys = np.meshgrid(np.linspace(0, fs[0] - 1, 21), np.linspace(0, fs[1] - 1, 16))
    pts = np.column_stack([xs.ravel(), ys.ravel()])
    err = apply_homography(np.linalg.inv(case.homography) @ out.homography, pts) - pts
    truth = _interior(case.frontal)
    return {
        "psnr_db": psnr_db(truth, _interior(out.image)),
        "psnr_exact_db": psnr_db(truth, _interior(exact)),
        "psnr_half_px_db": psnr_db(truth, _interior(shifted)),
        "max_err_px": float(np.sqrt((err**2).sum(axis=1)).max()),
        "synthetic_rectify_ms": 1000 * statistics.median(times),
    }


def _rectify_figures(inputs, out):
    return synthetic_accuracy()


@lru_cache(maxsize=1)
def _rectified_wall() -> np.ndarray:
    from weft.core.rectify import rectify_feature_lines

    return rectify_feature_lines(load_image(example("perspective")).image, str(LINES)).image


def _truth() -> np.ndarray:
    return load_image(example("perspective-frontal")).image


def _with_rectification(inputs, out):
    """Coherence against the rectified wall (the source) and against the true frontal wall."""
    src = _rectified_wall()
    return {
        "coherence": coherence(out, src),
        "completeness": completeness(out, src),
        "coherence_vs_truth": coherence(out, _truth()),
    }


def _without_rectification(inputs, out):
    """Coherence against the photo crop (the source) and against the true frontal wall."""
    src = inputs["photo"]
    return {
        "coherence": coherence(out, src),
        "completeness": completeness(out, src),
        "coherence_vs_truth": coherence(out, _truth()),
    }


CASES: list[Case] = [
    Case(
        name="rectify-640x480",
        method="rectify",
        inputs={"photo": Input("perspective", resize=(640, 480))},
        params={"lines": _scaled_lines(640 / 480), "size": (640, 480)},
        figures=_rectify_figures,
        process=True,
        note="the live case: a 640x480 photo rectified to 640x480 (fit + cubic warp); figures: synthetic "
        "known-geometry case (PSNR fitted / exact / 0.5 px off, max geometric error)",
    ),
    Case(
        name="nfpt-512",
        method="nfpt",
        inputs={"photo": Input("perspective")},
        params={"lines": str(LINES), "size": (512, 512)},
        figures=_with_rectification,
        note="perspective.png rectified (512x384) and synthesized to 512x512 with the defaults (48/12, repair)",
    ),
    Case(
        name="nfpt-512-no-rectify",
        method="nfpt",
        inputs={"photo": Input("perspective", crop=WALL)},
        params={"size": (512, 512)},
        figures=_without_rectification,
        note="the paper's Fig. 3b: the same wall synthesized straight from the photo (its largest upright "
        "rectangle, 248x194), no rectification",
    ),
    Case(
        name="nfpt-into-photo",
        method="nfpt",
        inputs={"photo": Input("perspective")},
        params={"lines": str(LINES), "size": (1024, 768), "into_photo": True},
        note="rectify, synthesize 1024x768 (4x the wall), put it back into the photo (3x3 supersampled)",
    ),
]
