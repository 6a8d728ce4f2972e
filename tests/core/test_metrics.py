"""Quality figures: coherence/completeness (exact patch nearest neighbours), fidelity, SNR."""

from __future__ import annotations

import math
import warnings

import cv2
import numpy as np
import pytest
from skimage import data
from weft.core.errors import ImageError, InvalidParameter, WeftError
from weft.core.metrics import _nearest_distances, coherence, completeness, fidelity, snr_db


@pytest.fixture(scope="module")
def brick():
    """A 256x256 grey natural texture in [0, 1]."""
    return data.brick()[:256, :256].astype(np.float32) / 255.0


@pytest.fixture(scope="module")
def tile(brick):
    return np.ascontiguousarray(brick[:64, :64])


def _naive(out, source, patch, stride):
    """Reference: double loop over out's stride grid, full scan of source, float64."""
    out = out.astype(np.float64)
    source = source.astype(np.float64)
    h, w = out.shape
    sh, sw = source.shape
    dists = []
    for y in range(0, h - patch + 1, stride):
        for x in range(0, w - patch + 1, stride):
            p = out[y : y + patch, x : x + patch]
            best = math.inf
            for v in range(sh - patch + 1):
                for u in range(sw - patch + 1):
                    d = np.sqrt(np.sum((p - source[v : v + patch, u : u + patch]) ** 2))
                    best = min(best, d)
            dists.append(best)
    return float(np.mean(dists))


# ---------------------------------------------------------------------------- coherence


def test_verbatim_copies_of_a_periodic_texture_score_zero(tile):
    source = np.tile(tile, (2, 2))  # holds every wrap-around window of the periodic texture
    out = np.roll(np.tile(tile, (4, 4)), (13, 29), axis=(0, 1))
    assert coherence(out, source) < 1e-3
    assert completeness(out, source) < 1e-3


def test_blur_scores_much_worse_than_copies(tile):
    source = np.tile(tile, (2, 2))
    out = np.tile(tile, (4, 4))
    good = coherence(out, source)
    blurred = coherence(cv2.GaussianBlur(out, (0, 0), 1.5), source)
    assert blurred > 0.1  # measured 0.148
    assert blurred > 10 * max(good, 1e-3)


def test_visible_seams_cost_coherence_but_less_than_noise(tile):
    seams = coherence(np.tile(tile, (4, 4)), tile)  # non-periodic crop: seams are new windows
    noise = coherence(np.random.default_rng(0).random((128, 128), dtype=np.float32), tile)
    assert 0.01 < seams < 0.2  # measured 0.041
    assert noise > 1.0  # measured ~1.9
    assert seams < noise / 10


def test_coherence_is_asymmetric_for_a_small_crop(brick):
    crop = brick[40:56, 100:116]
    assert coherence(crop, brick) < 1e-9
    assert completeness(crop, brick) > 0.1  # measured ~0.23 for a 16x16 crop
    assert completeness(brick, brick) < 1e-9


def test_completeness_improves_with_a_larger_crop(brick):
    small = completeness(brick[:16, :16], brick)
    large = completeness(brick[:128, :128], brick)
    assert large < small


def test_colour_is_compared_through_luminance(tile):
    rgb = np.repeat(tile[..., None], 3, axis=2)
    assert coherence(rgb, tile) == pytest.approx(coherence(tile, tile), abs=1e-6)
    assert coherence(rgb, rgb) < 1e-9


def test_returns_python_float(tile):
    assert type(coherence(tile, tile)) is float
    assert type(completeness(tile, tile)) is float


@pytest.mark.parametrize(
    "out_shape, src_shape, patch, stride",
    [((12, 10), (11, 13), 7, 2), ((9, 14), (10, 8), 3, 1), ((13, 11), (12, 12), 5, 3), ((8, 8), (7, 9), 7, 1)],
)
def test_matches_a_naive_double_loop(out_shape, src_shape, patch, stride):
    rng = np.random.default_rng(sum(out_shape) * 7 + patch)
    out = rng.random(out_shape, dtype=np.float32)
    source = rng.random(src_shape, dtype=np.float32)
    got = coherence(out, source, patch=patch, stride=stride)
    assert got == pytest.approx(_naive(out, source, patch, stride), rel=1e-6)
    got = completeness(out, source, patch=patch, stride=stride)
    assert got == pytest.approx(_naive(source, out, patch, stride), rel=1e-6)


def test_nearest_distances_chunked_matches_brute_force():
    rng = np.random.default_rng(3)
    queries = rng.random((300, 49), dtype=np.float32)
    database = rng.random((500, 49), dtype=np.float32)
    database[17] = queries[5]  # an exact match must come out exactly 0
    full = np.sqrt(((queries[:, None, :].astype(np.float64) - database[None].astype(np.float64)) ** 2).sum(-1))
    expect = full.min(axis=1)
    # tiny block budget: many row chunks and many column chunks
    got = _nearest_distances(queries, database, block_bytes=4 * 64 * 37)
    np.testing.assert_allclose(got, expect, rtol=1e-6)
    assert got[5] == 0.0
    np.testing.assert_allclose(_nearest_distances(queries, database), expect, rtol=1e-6)


def test_perfect_match_is_zero_not_rounding_noise():
    rng = np.random.default_rng(5)
    source = 0.3 + 0.4 * rng.random((40, 40), dtype=np.float32)  # offset values stress cancellation
    assert coherence(source[5:25, 11:31], source) == 0.0


# ---------------------------------------------------------------------------- fidelity


def test_fidelity_of_identical_and_inverted_images(brick):
    assert fidelity(brick, brick) == pytest.approx(1.0, abs=1e-9)
    assert fidelity(brick, 1.0 - brick) == pytest.approx(-1.0, abs=1e-6)


def test_fidelity_of_unrelated_noise_is_near_zero():
    rng = np.random.default_rng(11)
    a = rng.random((256, 256), dtype=np.float32)
    b = rng.random((256, 256), dtype=np.float32)
    assert abs(fidelity(a, b)) < 0.1


def test_fidelity_follows_large_scale_shading_not_detail(brick):
    yy, xx = np.mgrid[0:128, 0:128].astype(np.float32)
    gradient = xx / 127.0
    textured = np.clip(0.8 * gradient + 0.4 * (brick[:128, :128] - brick[:128, :128].mean()), 0, 1)
    assert fidelity(textured, gradient) > 0.9
    assert fidelity(textured, gradient, sigma=0) < fidelity(textured, gradient)


def test_fidelity_mixes_grey_and_colour(brick):
    rgb = np.repeat(brick[..., None], 3, axis=2)
    assert fidelity(rgb, brick) == pytest.approx(1.0, abs=1e-6)


def test_fidelity_of_a_constant_image_is_zero_not_nan(brick):
    flat = np.full((64, 64), 0.5, dtype=np.float32)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert fidelity(flat, brick[:64, :64]) == 0.0
        assert fidelity(brick[:64, :64], flat) == 0.0
        assert fidelity(flat, flat) == 0.0


# ---------------------------------------------------------------------------- SNR


def test_snr_of_a_constant_offset_is_known():
    rng = np.random.default_rng(2)
    orig = (0.9 * rng.random((32, 48, 3))).astype(np.float32)  # room for the offset inside [0, 1]
    c = 0.05
    synth = orig + np.float32(c)
    expect = 10 * math.log10(float(np.var(orig.astype(np.float64))) / c**2)
    assert snr_db(orig, synth) == pytest.approx(expect, abs=1e-4)


def test_snr_of_a_constructed_signal_and_noise():
    # orig alternates 0/1: variance 0.25; error ±0.05 everywhere: mse 0.0025 -> 20 dB
    orig = np.indices((16, 16)).sum(axis=0) % 2
    orig = orig.astype(np.float32)
    synth = orig + np.where(orig > 0, -0.05, 0.05).astype(np.float32)
    assert snr_db(orig, synth) == pytest.approx(20.0, abs=1e-4)


def test_snr_identical_and_constant_cases_without_warnings():
    rng = np.random.default_rng(4)
    img = rng.random((20, 20), dtype=np.float32)
    flat = np.full((20, 20), 0.25, dtype=np.float32)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert snr_db(img, img) == math.inf
        assert snr_db(flat, flat) == math.inf
        assert snr_db(flat, img) == -math.inf


# ---------------------------------------------------------------------------- errors


BAD_SHAPES = [np.zeros((8, 8, 4), np.float32), np.zeros((8, 8, 3, 1), np.float32), np.zeros(64, np.float32)]


@pytest.mark.parametrize("bad", BAD_SHAPES, ids=["4ch", "4d", "1d"])
@pytest.mark.parametrize("fn", [coherence, completeness, fidelity, snr_db])
def test_wrong_shapes_raise_image_error(fn, bad):
    good = np.zeros(bad.shape[:2] if bad.ndim > 1 else (8, 8), np.float32)
    for args in ((bad, good), (good, bad)):
        with pytest.raises(ImageError, match=r"shape \(H, W\) or \(H, W, 3\)") as info:
            fn(*args)
        assert "\n" not in str(info.value)


@pytest.mark.parametrize("fn", [coherence, completeness, fidelity, snr_db])
def test_images_smaller_than_7x7_raise(fn):
    small = np.zeros((6, 20), np.float32)
    ok = np.zeros((6, 20), np.float32)
    with pytest.raises(ImageError, match="at least 7x7"):
        fn(small, ok)
    with pytest.raises(ImageError, match="at least 7x7"):
        fn(np.zeros((20, 20), np.float32), np.zeros((20, 5, 3), np.float32))


def test_patch_larger_than_image_raises(tile):
    with pytest.raises(ImageError, match="at least 9x9"):
        coherence(tile, tile[:8, :8], patch=9)


@pytest.mark.parametrize("kw", [{"patch": 0}, {"stride": 0}, {"patch": 2.5}, {"stride": True}])
def test_bad_patch_parameters_raise(tile, kw):
    with pytest.raises(InvalidParameter):
        coherence(tile, tile, **kw)
    with pytest.raises(InvalidParameter):
        completeness(tile, tile, **kw)


def test_size_mismatch_raises(tile):
    with pytest.raises(ImageError, match="same size"):
        fidelity(tile, tile[:32, :40])
    with pytest.raises(ImageError, match="shape"):
        snr_db(tile, tile[:32, :40])
    with pytest.raises(ImageError):
        snr_db(tile, np.repeat(tile[..., None], 3, axis=2))


@pytest.mark.parametrize("sigma", [-1.0, float("nan"), "3"])
def test_bad_sigma_raises(tile, sigma):
    with pytest.raises(InvalidParameter, match="sigma"):
        fidelity(tile, tile, sigma=sigma)


def test_errors_are_weft_errors(tile):
    with pytest.raises(WeftError):
        coherence(np.zeros((3, 3)), tile)
    with pytest.raises(ValueError):
        fidelity(np.array([["a"] * 8] * 8), tile[:8, :8])


def test_psnr_of_a_known_error():
    from weft.core.metrics import psnr_db

    orig = np.full((16, 16), 0.5, np.float32)
    synth = orig + np.float32(0.1)  # mse 0.01 -> 20 dB
    assert psnr_db(orig, synth) == pytest.approx(20.0, abs=1e-4)
    assert psnr_db(orig, orig) == math.inf
    with pytest.raises(ImageError, match="shape"):
        psnr_db(orig, orig[:8])


# --------------------------------------------------------------------------------------------
# verbatim regions


def _copy_map(h, w, dy, dx):
    yy, xx = np.mgrid[0:h, 0:w]
    return np.stack([yy + dy, xx + dx], axis=2).astype(np.int32)


def test_verbatim_region_of_one_offset_is_everything():
    from weft.core.metrics import verbatim_fraction, verbatim_region

    src = _copy_map(20, 30, 3, 5)
    assert verbatim_region(src) == 600
    assert verbatim_fraction(src, (40, 30)) == 0.5


def test_verbatim_regions_split_by_offset_and_by_connectivity():
    from weft.core.metrics import verbatim_region

    src = _copy_map(10, 10, 0, 0)
    src[:, 6:] = _copy_map(10, 10, 1, 0)[:, 6:]  # another offset on the right: 60 and 40 pixels
    assert verbatim_region(src) == 60
    src[:, 2] = -1  # a column that is not a copy cuts the left region into 20 and 30 pixels
    assert verbatim_region(src) == 40
    # the same offset in two places that do not touch is two regions
    src = _copy_map(10, 10, 0, 0)
    src[4:6] = _copy_map(10, 10, 2, 2)[4:6]
    assert verbatim_region(src) == 40
    # diagonal contact does not join (4-connectivity)
    src = np.full((4, 4, 2), -1, np.int32)
    src[0, 0] = (0, 0)
    src[1, 1] = (1, 1)
    assert verbatim_region(src) == 1


def test_verbatim_region_of_nothing_copied_and_bad_maps():
    from weft.core.metrics import verbatim_fraction, verbatim_region

    assert verbatim_region(np.full((5, 6, 2), -1, np.int32)) == 0
    with pytest.raises(
        ImageError, match=r"source map has shape \(5, 6\) and type int32; it must be \(H, W, 2\) integers"
    ):
        verbatim_region(np.zeros((5, 6), np.int32))
    with pytest.raises(ImageError, match="must be"):
        verbatim_region(np.zeros((5, 6, 2), np.float32))
    with pytest.raises(ImageError, match=r"sample shape \(0, 4\) has no area"):
        verbatim_fraction(np.zeros((5, 6, 2), np.int32), (0, 4))
