"""Small cases the fill tests share: 96x96 crops of the bundled gravel and brick (module-scoped
fixtures) and a rectangular hole."""

import numpy as np
import pytest
from weft.core.examples import example
from weft.core.image import load_image


@pytest.fixture(scope="module")
def gravel():
    return load_image(example("gravel")).image[:96, :96]


@pytest.fixture(scope="module")
def brick():
    return load_image(example("brick")).image[:96, :96]


def square_hole(shape, y0=32, y1=60, x0=30, x1=66):
    hole = np.zeros(shape[:2], dtype=bool)
    hole[y0:y1, x0:x1] = True
    return hole
