"""Rectification under random, degenerate feature lines.

Lines drawn from a small grid of points (so coincident, parallel, zero-length and crossing lines come
up often), sometimes outside the photo: ``rectify`` gives a finite image in [0, 1] of the frontal size,
or raises ``WeftError`` in one line; never another exception, never NaN.
"""

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from weft.core.errors import WeftError
from weft.core.rectify import rectify

from tests.core.fuzzing import RUNTIME_WARNINGS_ARE_ERRORS, fuzz

pytestmark = RUNTIME_WARNINGS_ARE_ERRORS

PHOTO = np.random.default_rng(3).random((24, 32, 3), dtype=np.float32)
# mostly inside the 32x24 photo (a point outside now and then), few values: repeats are likely
_x = st.sampled_from([0.0, 5.0, 10.0, 16.0, 31.0] * 4 + [-3.0, 40.0])
_y = st.sampled_from([0.0, 5.0, 10.0, 16.0, 23.0] * 4 + [-3.0, 30.0])
_line = st.tuples(_x, _y, _x, _y).map(list)
_fx, _fy = st.sampled_from([0.0, 4.0, 8.0, 15.0]), st.sampled_from([0.0, 4.0, 8.0, 11.0])
_frontal_line = st.tuples(_fx, _fy, _fx, _fy).map(list)


@fuzz(80)
@given(
    image_lines=st.lists(_line, min_size=0, max_size=6),
    data=st.data(),
    warp=st.sampled_from(["homography", "morph", "lines"]),
)
def test_rectify_with_degenerate_lines(image_lines, data, warp):
    frontal_size = (16, 12)
    frontal = data.draw(st.lists(_frontal_line, min_size=len(image_lines), max_size=len(image_lines)))
    try:
        out = rectify(PHOTO, image_lines, frontal, frontal_size, warp=warp)
    except WeftError as e:
        assert "\n" not in str(e)
        return
    image = out.image
    assert image.shape == (12, 16, 3)
    assert np.isfinite(image).all() and image.min() >= 0.0 and image.max() <= 1.0
