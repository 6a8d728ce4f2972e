"""A transparent hole over a cat's face is not filled with copies of the nose beside it."""

import cv2
import numpy as np
import pytest
from skimage import data
from weft.core.fill import fill


def _nose_coloured(rgb: np.ndarray) -> np.ndarray:
    """The pixels of the nose's saturated red-pink (fur, eyes and whiskers are not)."""
    hsv = cv2.cvtColor(np.clip(np.rint(rgb * 255), 0, 255).astype(np.uint8), cv2.COLOR_RGB2HSV)
    h, s, v = hsv[..., 0].astype(int), hsv[..., 1] / 255.0, hsv[..., 2] / 255.0
    return ((h <= 10) | (h >= 170)) & (s > 0.45) & (v > 0.35)


@pytest.fixture(scope="module")
def cat_face():
    """scikit-image's chelsea, 300x260 around the face, RGBA with a transparent 110x100 rectangle over
    an eye's corner and the bridge and top of the nose (no mask: the alpha is the hole)."""
    rgb = data.chelsea()[40:300, 100:400].astype(np.float32) / 255.0
    alpha = np.ones(rgb.shape[:2], np.float32)
    alpha[95:195, 135:245] = 0.0
    return rgb, alpha


def test_no_stacked_noses(cat_face):
    """Over seeds 0-4 the median count of nose-coloured pixels in the hole stays near the truth's
    (the top of the real nose lies in the hole); copies of the nose beside the hole took it to about
    twice the truth's."""
    rgb, alpha = cat_face
    hole = alpha < 0.5
    truth = int(_nose_coloured(rgb)[hole].sum())
    counts = []
    for seed in range(5):
        out = fill(np.dstack([rgb, alpha]), seed=seed)
        assert out.shape == (260, 300, 4) and np.all(out[..., 3] == 1.0)
        counts.append(int(_nose_coloured(out[..., :3])[hole].sum()))
    assert float(np.median(counts)) <= 1.5 * truth, (counts, truth)
