"""The ``patchmatch`` fill engine (``weft.core.fill.patchmatch.fill_patchmatch``): known pixels untouched,
seeds deterministic, the issue's fill metrics on small cases, the source region respected, uncrop-like
holes at the border, cancelling, and one-line errors for bad inputs."""

import cv2
import numpy as np
import pytest
from weft.core.errors import Cancelled, ImageError, InvalidParameter, WeftError
from weft.core.examples import example
from weft.core.fill.patchmatch import fill_patchmatch
from weft.core.image import load_image
from weft.core.jobs import CancelToken
from weft.core.metrics import fill_coherence, fill_detail, fill_seam


def _image(name, h, w, y=0, x=0):
    return np.ascontiguousarray(load_image(example(name)).image[y : y + h, x : x + w]).astype(np.float32)


def _square_hole(h, w, y, x, side):
    hole = np.zeros((h, w), bool)
    hole[y : y + side, x : x + side] = True
    return hole


def _garbled(img, hole):
    """The image as a caller may pass it: anything (here NaN) inside the hole."""
    out = img.copy()
    out[hole] = np.nan
    return out


@pytest.fixture(scope="module")
def gravel():
    """96 px of scikit-image's gravel (small stones: a stochastic texture a 24 px hole cannot guess)."""
    from skimage import data

    return np.ascontiguousarray(data.gravel()[100:196, 100:196], dtype=np.float32) / 255


@pytest.mark.parametrize("channels", [0, 3, 4])
def test_known_pixels_are_returned_bit_for_bit_and_the_hole_is_filled(channels):
    base = _image("chelsea", 64, 72)
    if base.ndim == 3:
        base = cv2.cvtColor(base, cv2.COLOR_RGB2GRAY) if channels == 0 else base
    if channels == 4:
        alpha = np.linspace(0.2, 1.0, base.shape[1], dtype=np.float32)[None, :].repeat(base.shape[0], 0)
        base = np.dstack([base, alpha])
    hole = _square_hole(64, 72, 20, 25, 16)
    out = fill_patchmatch(_garbled(base, hole), hole, rng=3)
    assert out.dtype == np.float32 and out.shape == base.shape
    assert np.array_equal(out[~hole], base[~hole])
    assert np.isfinite(out).all()
    assert out[hole].min() >= base[~hole].min() - 1e-6 and out[hole].max() <= base[~hole].max() + 1e-6
    if channels == 4:  # alpha is filled like any channel: from the alpha values around the hole
        a = out[..., 3][hole]
        assert a.min() >= alpha[hole].min() - 0.15 and a.max() <= alpha[hole].max() + 0.15


def test_same_seed_same_pixels_other_seed_other_pixels(gravel):
    hole = _square_hole(96, 96, 36, 36, 24)
    img = _garbled(gravel, hole)
    a = fill_patchmatch(img, hole, rng=7)
    b = fill_patchmatch(img, hole, rng=np.random.default_rng(7))
    c = fill_patchmatch(img, hole, rng=8)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)


def test_a_gravel_hole_is_detailed_like_the_ground_truth_and_as_coherent(gravel):
    from weft.core.fill.band import band_region

    hole = _square_hole(96, 96, 36, 36, 24)
    # as the method runs it: the default 2 px blend band may change (without one the seam is about
    # +0.16 of the truth's here: the known edge is fixed, the copies meet it as they are)
    band = band_region(hole, 2) & ~hole
    out = fill_patchmatch(_garbled(gravel, hole), hole, rng=1, cuttable=band)
    assert np.array_equal(out[~(hole | band)], gravel[~(hole | band)])
    truth_detail = fill_detail(gravel, hole)
    assert 0.7 <= fill_detail(out, hole) / truth_detail <= 1.3
    assert abs(fill_seam(out, hole) - fill_seam(gravel, hole)) <= 0.15
    ours = fill_coherence(out, hole)
    assert ours <= fill_coherence(gravel, hole)  # as made of known patches as the real gravel is
    white = gravel.copy()
    white[hole] = 1.0
    assert ours < 0.5 * fill_coherence(white, hole)
    # diffusion (Telea) is coherent on this metric (a smooth patch is near many), but smeared: the
    # detail bound above is the one it fails
    u8 = (gravel * 255 + 0.5).astype(np.uint8)
    telea = cv2.inpaint(u8, hole.astype(np.uint8), 3, cv2.INPAINT_TELEA).astype(np.float32) / 255
    assert fill_detail(telea, hole) < 0.7 * truth_detail


def test_only_the_source_region_is_copied_from():
    rng = np.random.default_rng(0)
    img = np.zeros((80, 80, 3), np.float32)
    img[:, :40] = [0.9, 0.1, 0.1] + 0.05 * rng.random((80, 40, 3), dtype=np.float32)  # red left half
    img[:, 40:] = [0.1, 0.1, 0.9] + 0.05 * rng.random((80, 40, 3), dtype=np.float32)  # blue right half
    hole = _square_hole(80, 80, 30, 32, 16)  # straddles the two halves
    source = np.zeros((80, 80), bool)
    source[:, 50:] = True  # copy from the blue side only
    out = fill_patchmatch(_garbled(img, hole), hole, source, rng=2)
    filled = out[hole]
    assert (filled[:, 2] > 0.85).all() and (filled[:, 0] < 0.2).all()  # every filled pixel is blue
    default = fill_patchmatch(_garbled(img, hole), hole, rng=2)
    assert (default[hole][:, 0] > 0.85).any()  # without a source mask the red side is used too


def test_a_hole_along_the_border_is_an_uncrop():
    truth = _image("brick", 96, 96)
    hole = np.ones((96, 96), bool)
    hole[16:80, 16:80] = False  # the known 64 px in the middle, a 16 px border to grow
    out = fill_patchmatch(_garbled(truth, hole), hole, rng=4)
    assert np.array_equal(out[~hole], truth[~hole])
    assert 0.6 <= fill_detail(out, hole) / fill_detail(truth, hole) <= 1.4
    assert fill_coherence(out, hole) < 3 * fill_coherence(truth, hole) + 2


def test_levels_and_iterations_can_be_given(gravel):
    hole = _square_hole(96, 96, 36, 36, 24)
    one = fill_patchmatch(_garbled(gravel, hole), hole, rng=1, levels=1, iterations=1)
    assert np.array_equal(one[~hole], gravel[~hole]) and np.isfinite(one).all()
    assert not np.array_equal(one, fill_patchmatch(_garbled(gravel, hole), hole, rng=1))


def test_progress_reaches_the_end_and_cancel_raises(gravel):
    hole = _square_hole(96, 96, 36, 36, 24)
    reports = []
    fill_patchmatch(gravel, hole, rng=1, progress=reports.append)
    assert reports and reports[-1].done == reports[-1].total and reports[-1].stage == "fill"
    assert [r.done for r in reports] == sorted(r.done for r in reports)

    token = CancelToken()
    calls = []

    def cancel_on_first(report):
        calls.append(report)
        token.cancel()

    with pytest.raises(Cancelled):
        fill_patchmatch(gravel, hole, rng=1, progress=cancel_on_first, cancel=token)
    assert len(calls) == 1  # stopped at the next check, right after the first iteration


def test_an_empty_hole_returns_the_image_unchanged(gravel):
    out = fill_patchmatch(gravel, np.zeros((96, 96), bool))
    assert out is not gravel and np.array_equal(out, gravel)


@pytest.mark.parametrize(
    "kwargs, error, message",
    [
        ({"hole": np.zeros((90, 96), bool)}, ImageError, "hole mask is 96x90 but the image is 96x96"),
        ({"source": np.ones((96, 95), bool)}, ImageError, "source mask is 95x96 but the image is 96x96"),
        ({"patch": 2}, InvalidParameter, "parameter 'patch' = 2 must be an integer 3..63"),
        ({"patch": 7.0}, InvalidParameter, "parameter 'patch' = 7.0 must be an integer 3..63"),
        ({"levels": 0}, InvalidParameter, "parameter 'levels' = 0 must be an integer 1..64 or None"),
        ({"iterations": "3"}, InvalidParameter, "parameter 'iterations' = '3' must be an integer 1..64 or None"),
        (
            {"image": np.zeros((96, 96, 5), np.float32)},
            ImageError,
            "image must be (H, W) or (H, W, C) with C = 1..4 channels, got shape (96, 96, 5)",
        ),
        ({"image": np.zeros((96, 96), np.uint8)}, ImageError, "image must be float in [0, 1], got uint8"),
        (
            {"image": np.zeros((5, 96), np.float32), "hole": np.ones((5, 96), bool)},
            ImageError,
            "image is 96x5: smaller than the 7x7 patch",
        ),
    ],
)
def test_bad_inputs_are_one_line_errors(gravel, kwargs, error, message):
    args = {"image": gravel, "hole": _square_hole(96, 96, 36, 36, 24)}
    args.update(kwargs)
    image, hole = args.pop("image"), args.pop("hole")
    with pytest.raises(error) as info:
        fill_patchmatch(image, hole, **args)
    assert str(info.value) == message
    assert isinstance(info.value, WeftError) and "\n" not in str(info.value)


def test_a_source_without_a_whole_patch_is_refused(gravel):
    hole = _square_hole(96, 96, 36, 36, 24)
    source = np.zeros((96, 96), bool)
    source[::2, ::2] = True  # plenty of pixels, but no 7x7 square of them
    message = (
        "the source region holds no whole 7x7 patch: leave at least a 7x7 square of known pixels "
        "to copy from (or use a smaller patch)"
    )
    with pytest.raises(ImageError, match=r"^the source region holds no whole 7x7 patch"):
        fill_patchmatch(gravel, hole, source)
    everything = np.ones((96, 96), bool)
    with pytest.raises(ImageError) as info:
        fill_patchmatch(gravel, everything)  # nothing known at all
    assert str(info.value) == message
    source[:, :6] = True  # a 6 px strip: still too narrow for 7x7, fine for 5x5
    with pytest.raises(ImageError):
        fill_patchmatch(gravel, hole, source)
    out = fill_patchmatch(gravel, hole, source, patch=5)
    assert np.array_equal(out[~hole], gravel[~hole])


@pytest.mark.parametrize("bias, takes_neighbours_offset", [(0.0, False), (1.0, True)])
def test_a_coherence_bias_lets_propagation_take_a_neighbours_offset_within_the_margin(bias, takes_neighbours_offset):
    from weft.core.fill.search import Flat as _Flat
    from weft.core.fill.search.em import _try

    p = 3
    img = np.random.default_rng(5).random((20, 20, 1)).astype(np.float32)
    hole = np.zeros((20, 20), bool)
    hole[10:13, 10:14] = True
    source = ~hole
    fl = _Flat(img, hole, source, p)
    target = fl.gather(np.array([10]), np.array([11]))  # the patch at (10, 11), as its pixels
    k = np.array([0])  # its candidate (2, 3), its current match (2, 2)
    d_cand = fl.dist(target, k, np.array([2]), np.array([3]))[0]
    # the current match is 1.5x closer than the candidate the neighbour's offset proposes: only a
    # bias above 0.5 takes the neighbour's offset
    sy, sx, dist = np.array([2]), np.array([2]), np.array([d_cand / 1.5])
    _try(fl, target, k, sy, sx, dist, np.array([2]), np.array([3]), np.array([True]), bias=bias)
    if takes_neighbours_offset:
        assert (sy[0], sx[0]) == (2, 3) and dist[0] == d_cand
    else:
        assert (sy[0], sx[0]) == (2, 2) and dist[0] == d_cand / 1.5


@pytest.mark.slow
def test_a_patchmatch_fill_loads_no_numba():
    """The engine is numpy only: a ``weft fill --engine patchmatch`` process pays no numba import
    or kernel cache loads (0.4-0.5 s of its whole-process time when it had them)."""
    import subprocess
    import sys

    script = (
        "import sys, numpy as np\n"
        "from weft.core.fill.patchmatch import fill_patchmatch\n"
        "img = np.random.default_rng(0).random((64, 64, 3), dtype=np.float32)\n"
        "hole = np.zeros((64, 64), bool); hole[20:40, 20:40] = True\n"
        "out = fill_patchmatch(img, hole, rng=1)\n"
        "assert np.array_equal(out[~hole], img[~hole])\n"
        "print(sorted(m for m in sys.modules if m == 'numba' or m.startswith('scipy.ndimage')))\n"
    )
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert proc.stdout.strip().splitlines()[-1] == "[]"


def test_stable_argsort_is_numpys_stable_argsort():
    """The refine's principal-axis candidates sort ~80k projections with a key sort that must order
    ties (and -0.0 against 0.0, and infinities) exactly as np.argsort(kind="stable")."""
    from weft.core.fill.search.refine import _stable_argsort

    rng = np.random.default_rng(3)
    for _ in range(50):
        n = int(rng.integers(1, 3000))
        a = (rng.integers(-20, 20, n) * rng.choice([0.5, 1e-3, 1e30], n)).astype(np.float32)
        a[rng.random(n) < 0.05] = -0.0
        a[rng.random(n) < 0.02] = np.inf
        a[rng.random(n) < 0.02] = -np.inf
        assert np.array_equal(_stable_argsort(a), np.argsort(a, kind="stable"))
