"""The bundled examples load, and the perspective example's feature lines match its homography."""

import json

import numpy as np
import pytest
from weft.core.errors import WeftError
from weft.core.examples import RESOURCES, example, examples
from weft.core.image import load_image


def test_every_example_loads_as_a_float_image():
    paths = examples()
    names = {p.stem for p in paths}
    assert {"brick", "gravel", "grass", "camera", "astronaut", "coffee", "chelsea", "perspective"} <= names
    for p in paths:
        img = load_image(p).image
        assert img.dtype == np.float32 and 0.0 <= img.min() and img.max() <= 1.0
        assert min(img.shape[:2]) >= 64


def test_example_lookup():
    assert example("brick") == example("brick.png") == RESOURCES / "brick.png"
    with pytest.raises(WeftError, match="no bundled example named 'nope'"):
        example("nope")


def _apply(h, x, y):
    p = h @ np.array([x, y, 1.0])
    return p[:2] / p[2]


def test_perspective_lines_follow_the_recorded_homography():
    data = json.loads((RESOURCES / "perspective-lines.json").read_text())
    h = np.array(data["homography"])
    assert len(data["image_lines"]) == len(data["frontal_lines"]) >= 4
    w, hgt = data["frontal_size"]
    photo = load_image(example("perspective")).image
    for img_line, fr_line in zip(data["image_lines"], data["frontal_lines"], strict=True):
        for (xi, yi), (xf, yf) in zip(np.reshape(img_line, (2, 2)), np.reshape(fr_line, (2, 2)), strict=True):
            assert 0 <= xf <= w and 0 <= yf <= hgt
            assert np.allclose(_apply(h, xf, yf), (xi, yi), atol=0.01)
            assert 0 <= xi < photo.shape[1] and 0 <= yi < photo.shape[0]
