"""Random-block quilting: shapes, determinism, that every block is a real copy, errors, jobs."""

import numpy as np
import pytest

from core.errors import Cancelled, InvalidParameter
from core.jobs import CancelToken
from core.quilting import QuiltParams, synthesize


@pytest.fixture
def texture():
    rng = np.random.default_rng(0)
    return rng.random((40, 50, 3), dtype=np.float32)


def test_shape_dtype_and_default_size(texture):
    out = synthesize(texture, block=8, rng=1)
    assert out.shape == (80, 100, 3) and out.dtype == np.float32
    out = synthesize(texture[..., 0], size=(33, 17), block=8, rng=1)
    assert out.shape == (17, 33)


def test_same_seed_same_pixels_other_seed_differs(texture):
    a = synthesize(texture, size=(64, 64), block=16, rng=5)
    b = synthesize(texture, size=(64, 64), block=16, rng=5)
    c = synthesize(texture, size=(64, 64), block=16, rng=6)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)


def test_every_block_is_a_copy_of_the_texture(texture):
    b = 10
    out = synthesize(texture, size=(45, 35), block=b, rng=2)
    h, w = texture.shape[:2]
    windows = np.lib.stride_tricks.sliding_window_view(texture, (b, b), axis=(0, 1))  # (h-b+1, w-b+1, 3, b, b)
    for y0 in range(0, 35, b):
        for x0 in range(0, 45, b):
            blk = out[y0:y0 + b, x0:x0 + b]
            bh, bw = blk.shape[:2]
            cand = windows[..., :bh, :bw].transpose(0, 1, 3, 4, 2)
            assert np.any(np.all(cand == blk, axis=(2, 3, 4))), (y0, x0)


def test_block_larger_than_texture_is_refused(texture):
    with pytest.raises(InvalidParameter, match=r"parameter 'block' = 64 is outside 2..40 \(must fit in the texture, 50x40\)"):
        synthesize(texture, block=64)


def test_params_validation():
    with pytest.raises(InvalidParameter, match="'mode' = 'nope' is not one of random"):
        QuiltParams(mode="nope")
    with pytest.raises(InvalidParameter, match="'block' = 1 is outside 2..1024"):
        QuiltParams(block=1)


def test_progress_previews_and_cancel(texture):
    seen = []
    out = synthesize(texture, size=(80, 80), block=8, rng=0, progress=seen.append)
    assert seen[-1].done == seen[-1].total == 10
    assert all(p.preview.shape == out.shape for p in seen)
    # The preview grows row by row: the first report has later rows still empty.
    assert np.all(seen[0].preview[8:] == 0) and np.array_equal(seen[-1].preview, out)

    token = CancelToken()
    token.cancel()
    with pytest.raises(Cancelled):
        synthesize(texture, size=(80, 80), block=8, rng=0, cancel=token)
