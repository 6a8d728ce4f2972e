"""Each connected region of a hole is filled with what suits it: an uncrop beside an interior hole
leaves the interior fill as it is without the uncrop."""

import cv2
import numpy as np
import pytest
from weft.core.examples import example
from weft.core.fill import FillParams, fill
from weft.core.fill.method import fill_image
from weft.core.image import load_image


@pytest.fixture(scope="module")
def coffee_spoon():
    """The bundled coffee photo (300x200) with its spoon lassoed loosely: an interior hole over the
    saucer's rim."""
    image = load_image(example("coffee")).image
    m = np.zeros(image.shape[:2], np.uint8)
    cv2.ellipse(m, (182, 140), (22, 25), 0, 0, 360, 1, thickness=-1)
    cv2.polylines(m, [np.array([(206, 36), (197, 80), (189, 119)], np.int32)], False, 1, thickness=7)
    hole = cv2.dilate(m, np.ones((5, 5), np.uint8)).astype(bool)
    return image, hole


def test_margins_do_not_change_an_interior_hole(coffee_spoon):
    image, hole = coffee_spoon
    alone, fig_alone = fill_image(image, hole, params=FillParams(), rng=1)
    grown, fig_grown = fill_image(image, hole, params=FillParams(extend=(0, 0, 64, 0)), rng=1)
    assert grown.shape == (200, 364, 3)
    assert np.array_equal(grown[:, :300][hole], alone[hole])  # the spoon's hole: the same pixels
    assert fig_alone["engine"] in fig_grown["engine"]  # and the same engine inside
    assert fig_grown["hole_pixels"] == int(hole.sum()) + 64 * 200
    # the margin is filled too, and the known pixels beyond the band are the input's
    assert grown[:, 300:].std() > 0.02
    far = ~cv2.dilate(hole.astype(np.uint8), np.ones((5, 5), np.uint8)).astype(bool)
    far[:, 297:] = False
    assert np.array_equal(grown[:, :300][far], image[far])


def test_the_api_splits_too(coffee_spoon):
    image, hole = coffee_spoon
    a = fill(image, hole, seed=2)
    b = fill(image, hole, extend="0,10,0,10", seed=2)
    assert np.array_equal(b[10:210][hole], a[hole])
