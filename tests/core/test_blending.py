"""Poisson blending solves the Poisson equation; pyramid blending mixes and reconstructs exactly."""

import numpy as np
import pytest
import scipy.sparse
import scipy.sparse.linalg
from weft.core.blending import METHOD, BlendParams, max_levels, poisson_blend, pyramid_blend
from weft.core.errors import ImageError, InvalidParameter


def _laplacian(img: np.ndarray) -> np.ndarray:
    """4-neighbour Laplacian (sum of neighbours minus 4x centre) of the interior."""
    f = img.astype(np.float64)
    return f[:-2, 1:-1] + f[2:, 1:-1] + f[1:-1, :-2] + f[1:-1, 2:] - 4 * f[1:-1, 1:-1]


@pytest.fixture
def pair():
    rng = np.random.default_rng(1)
    y, x = np.mgrid[0:40, 0:48] / 48.0
    target = (0.2 + 0.5 * x + 0.05 * rng.random((40, 48))).astype(np.float32)
    source = (0.4 + 0.2 * np.sin(6 * y) * np.cos(5 * x) + 0.05 * rng.random((40, 48))).astype(np.float32)
    mask = np.zeros((40, 48), dtype=bool)
    mask[8:30, 10:40] = True
    mask[12:20, 5:12] = True
    return target, source, mask


def test_poisson_result_has_the_source_laplacian_inside_and_the_target_outside(pair):
    target, source, mask = pair
    out = poisson_blend(target, source, mask, tol=1e-10)
    assert out.dtype == np.float32 and out.shape == target.shape
    assert np.array_equal(out[~mask], target[~mask])
    inner = mask[1:-1, 1:-1]
    lap_out, lap_src = _laplacian(out)[inner], _laplacian(source)[inner]
    assert np.abs(lap_out - lap_src).max() < 1e-5  # float32 output rounding
    # and it is not the source pasted: the border meets the target
    assert np.abs(out[mask] - source[mask]).mean() > 0.05


def test_poisson_matches_a_direct_sparse_solve(pair):
    target, source, mask = pair
    h, w = mask.shape
    idx = -np.ones((h, w), dtype=int)
    ys, xs = np.nonzero(mask)
    idx[ys, xs] = np.arange(len(ys))
    rows, cols, vals = [], [], []
    b = np.zeros(len(ys))
    for i, (y, x) in enumerate(zip(ys, xs, strict=True)):
        deg = 0
        for dy, dx in ((1, 0), (-1, 0), (0, 1), (0, -1)):
            qy, qx = y + dy, x + dx
            if not (0 <= qy < h and 0 <= qx < w):
                continue
            deg += 1
            b[i] += float(source[y, x]) - float(source[qy, qx])
            if mask[qy, qx]:
                rows.append(i), cols.append(idx[qy, qx]), vals.append(-1.0)
            else:
                b[i] += float(target[qy, qx])
        rows.append(i), cols.append(i), vals.append(float(deg))
    a = scipy.sparse.csr_matrix((vals, (rows, cols)), shape=(len(ys), len(ys)))
    exact = scipy.sparse.linalg.spsolve(a, b)
    out = poisson_blend(target, source, mask, tol=1e-10)
    assert np.abs(out[ys, xs] - np.clip(exact, 0, 1)).max() < 1e-5


def test_poisson_edge_cases():
    img = np.linspace(0, 1, 100, dtype=np.float32).reshape(10, 10)
    assert np.array_equal(poisson_blend(img, img[::-1], np.zeros((10, 10))), img)
    colour = np.stack([img] * 3, axis=2)
    assert poisson_blend(img, colour, np.ones((10, 10)) * 0.0).shape == (10, 10, 3)
    with pytest.raises(ImageError, match="mask is 9x10 but the images are 10x10"):
        poisson_blend(img, img, np.zeros((10, 9)))
    with pytest.raises(ImageError, match="same size"):
        poisson_blend(img, img[:5], np.zeros((10, 10)))


def test_pyramid_mask_ones_gives_foreground_zeros_background():
    rng = np.random.default_rng(2)
    fg = rng.random((37, 50, 3), dtype=np.float32)
    bg = rng.random((37, 50, 3), dtype=np.float32)
    assert np.abs(pyramid_blend(fg, bg, np.ones((37, 50)), levels=5) - fg).max() < 1e-5
    assert np.abs(pyramid_blend(fg, bg, np.zeros((37, 50)), levels=5) - bg).max() < 1e-5
    # one level is a plain per-pixel mix
    half = np.full((37, 50), 0.5, dtype=np.float32)
    assert np.allclose(pyramid_blend(fg, bg, half, levels=1), 0.5 * (fg + bg), atol=1e-6)


def test_pyramid_blend_transition_is_smooth_and_levels_validated():
    fg = np.ones((64, 64), dtype=np.float32)
    bg = np.zeros((64, 64), dtype=np.float32)
    mask = np.zeros((64, 64), dtype=np.float32)
    mask[:, 32:] = 1
    out = pyramid_blend(fg, bg, mask, levels=4)
    row = out[32]
    assert row[0] < 0.01 and row[-1] > 0.99
    assert np.all(np.diff(row) >= -1e-6)  # monotone ramp, no ringing
    assert 3 < np.count_nonzero((row > 0.02) & (row < 0.98)) < 40  # spread over several pixels
    assert max_levels(64, 64) == 7
    with pytest.raises(InvalidParameter, match=r"'levels' = 8 is outside 1..7 \(a 64x64 image has at most 7"):
        pyramid_blend(fg, bg, mask, levels=8)
    with pytest.raises(InvalidParameter, match=r"'levels' = 0 is outside 1..7"):
        pyramid_blend(fg, bg, mask, levels=0)
    with pytest.raises(ImageError, match="mask must be"):
        pyramid_blend(fg, bg, np.zeros((64, 64, 2)))
    with pytest.raises(ImageError, match="mask is 32x64"):
        pyramid_blend(fg, bg, np.zeros((64, 32)))


def test_blend_method_runs_both_modes():
    rng = np.random.default_rng(3)
    fg = rng.random((20, 24), dtype=np.float32)
    bg = rng.random((20, 24, 3), dtype=np.float32)
    mask = np.zeros((20, 24), dtype=np.float32)
    mask[5:15, 6:18] = 1
    res = METHOD.run({"foreground": fg, "background": bg, "mask": mask}, BlendParams(levels=3))
    assert res.image.shape == (20, 24, 3) and res.figures == {"levels": 3}
    res = METHOD.run({"foreground": fg, "background": bg, "mask": mask}, BlendParams(mode="poisson"))
    assert res.image.shape == (20, 24, 3) and res.figures["masked_pixels"] == 120
