"""NFPT synthesis (Yan, Lee & Lin §2): eqs. 1-3, patch scan, repair, seeds, progress, cancel, errors."""

import numpy as np
import pytest
from weft.core import metrics
from weft.core.errors import Cancelled, GeometryError, ImageError, InvalidParameter
from weft.core.examples import example
from weft.core.image import load_image
from weft.core.jobs import CancelToken
from weft.core.nfpt import METHOD, NfptParams, distance_weights, nfpt, synthesize

LINES_JSON = str(example("perspective").parent / "perspective-lines.json")


@pytest.fixture(scope="module")
def gravel():
    return load_image(example("gravel")).image[:96, :96]


@pytest.fixture(scope="module")
def fur():
    return load_image(example("cat-fur")).image


@pytest.fixture(scope="module")
def photo():
    return load_image(example("perspective")).image


def _rows(img):
    return {tuple(np.round(np.atleast_1d(v), 6)) for v in img.reshape(-1, img.shape[-1] if img.ndim == 3 else 1)}


def test_shapes_seeds_and_source_pixels(fur):
    a = synthesize(fur, size=(100, 80), block=32, overlap=8, rng=3)
    b = synthesize(fur, size=(100, 80), block=32, overlap=8, rng=3)
    c = synthesize(fur, size=(100, 80), block=32, overlap=8, rng=4)
    assert a.shape == (80, 100, 3) and a.dtype == np.float32
    assert np.array_equal(a, b) and not np.array_equal(a, c)
    assert _rows(a) <= _rows(fur)  # patches and repairs copy source pixels (no smoothing)
    grey = synthesize(fur[..., 0], block=32, overlap=8, rng=1)
    assert grey.shape == (208, 208)  # default size: twice the texture


def test_quality_beats_random_patches_and_shuffled_pixels(gravel):
    out = synthesize(gravel, size=(128, 128), block=32, overlap=8, rng=1)
    shuffled = np.random.default_rng(0).permutation(out.ravel()).reshape(out.shape)
    coh = metrics.coherence(out, gravel)
    assert coh < 0.3 * metrics.coherence(shuffled, gravel)
    assert coh < 0.15


def test_distance_weight_is_eq_1_on_the_l_shape():
    wd = distance_weights(16, 4, 4, sigma_d=2.0)
    assert wd.shape == (16, 16) and (wd[4:, 4:] == 0).all()  # nothing on the new part
    assert wd[8, 3] == pytest.approx(np.exp(-0.25 / 8) / (np.sqrt(2 * np.pi) * 2))  # d = 0.5 next to it
    assert wd[8, 3] > wd[8, 2] > wd[8, 1] > wd[8, 0] > 0  # falls off away from the patch boundary
    assert wd[3, 3] == pytest.approx(wd[8, 3] ** 0 * np.exp(-0.5 / 8) / (np.sqrt(2 * np.pi) * 2))  # corner
    only_left = distance_weights(16, 0, 4, sigma_d=2.0)
    assert (only_left[:, 4:] == 0).all() and (only_left[:, :4] > 0).all()


def test_feature_weight_is_eq_2_and_3():
    from weft.core._kernels import nfpt as _k

    canvas = np.full((8, 8, 1), 0.5, np.float32)
    canvas[2, 0, 0] = 0.9  # one feature pixel on a background of 0.5
    wd = distance_weights(8, 0, 2, sigma_d=1.0)
    w = np.zeros((16, 16), np.float32)
    tw = np.zeros((16, 16), np.float32)
    const = _k.l_template(canvas[..., 0], canvas, 0, 0, 8, wd, 0.35, 32, 0.5, w, tw)

    def g(f):
        return np.exp(-((f - 1) ** 2) / (2 * 0.35**2)) / (np.sqrt(2 * np.pi) * 0.35)

    assert w[3, 0] == pytest.approx(wd[3, 0] + g(0.0), rel=1e-5)  # background: M = 0.5
    assert w[2, 0] == pytest.approx(wd[2, 0] + g(0.4), rel=1e-5)  # feature: |P - M| = 0.4
    assert w[2, 0] > w[3, 0] and (w[:, 2:] == 0).all()
    assert tw[2, 0] == pytest.approx(w[2, 0] * 0.4) and const == pytest.approx(w[2, 0] * 0.16, rel=1e-5)


def test_repair_counts_and_smooth(gravel):
    none = synthesize(gravel, size=(96, 96), block=32, overlap=8, repair=False, rng=2, return_details=True)
    some = synthesize(gravel, size=(96, 96), block=32, overlap=8, rng=2, return_details=True)
    band = synthesize(gravel, size=(96, 96), block=32, overlap=8, threshold=0.0, rng=2, return_details=True)
    off = synthesize(gravel, size=(96, 96), block=32, overlap=8, threshold=1.0, rng=2, return_details=True)
    assert none.repaired == 0 and off.repaired == 0 and np.array_equal(off.image, none.image)
    assert 0 < some.repaired < band.repaired == band.repaired_mask.sum()
    assert some.figures()["repaired_pixels"] == some.repaired
    # only pixels in the repair band differ from the unrepaired result
    assert not (some.image != none.image)[~some.repaired_mask].any()
    smooth = synthesize(gravel, size=(96, 96), block=32, overlap=8, smooth=True, rng=2, return_details=True)
    diff = smooth.image != some.image
    assert diff.any() and not diff[~some.repaired_mask].any()


def test_source_mask_limits_where_patches_come_from(gravel):
    mask = np.zeros(gravel.shape, bool)
    mask[:, :60] = True
    syn = synthesize(gravel, size=(64, 64), block=24, overlap=6, mask=mask, rng=5, return_details=True)
    assert (syn.pos % gravel.shape[1] < 60).all()
    with pytest.raises(ImageError, match="no 40x40 patch"):
        synthesize(gravel, block=40, overlap=8, mask=mask[:, :] & (np.arange(96) < 30), rng=1)


def test_progress_per_patch_row_with_preview_and_cancel(gravel):
    calls = []
    synthesize(gravel, size=(96, 96), block=32, overlap=8, rng=1, progress=calls.append)
    rows = 4  # patches at 0, 24, 48, 72
    assert calls[-1].done == calls[-1].total == rows + 1 and calls[0].stage == "nfpt synthesis"
    assert calls[0].preview is not None and calls[0].preview.shape == (96, 96)
    token = CancelToken()

    def cancel_after_first(p):
        token.cancel()

    with pytest.raises(Cancelled):
        synthesize(gravel, size=(96, 96), block=32, overlap=8, rng=1, progress=cancel_after_first, cancel=token)


@pytest.mark.parametrize(
    "kwargs, fragment",
    [
        (dict(overlap=20, block=32), "parameter 'overlap' = 20 is outside 2..16"),
        (dict(n=4), "parameter 'n' = 4 must be odd"),
        (dict(block=200), "parameter 'block' = 200 is outside 8..96 \\(must fit in the source texture, 96x96\\)"),
        (dict(sigma_s=0.0), "parameter 'sigma_s' = 0 is outside 0.01..10"),
        (dict(size=(4, 4)), "parameter 'size' = 4x4 has a side outside 8..16384"),
    ],
)
def test_bad_parameters(gravel, kwargs, fragment):
    with pytest.raises(InvalidParameter, match=fragment):
        synthesize(gravel, **kwargs)


def test_pipeline_rectifies_synthesizes_and_reprojects(photo):
    res = nfpt(photo, LINES_JSON, size=(160, 128), block=32, overlap=8, rng=1)
    assert res.rectified.shape == (384, 512, 3) and res.image.shape == (128, 160, 3)
    assert res.homography is not None and res.figures["rectify_points"] == 8
    assert res.figures["patches"] == 7 * 5  # patches step by 24: 7 columns cover 160, 5 rows 128
    back = nfpt(photo, LINES_JSON, size=(768, 576), block=32, overlap=8, into_photo=True, rng=1)
    assert back.image.shape == photo.shape
    assert back.figures["photo_replaced_fraction"] > 0.6  # the wall grew beyond its borders
    # far from the wall (sky, top left corner), the photo is untouched
    assert np.allclose(back.image[:15, :15], photo[:15, :15], atol=1e-6)
    quad = '{"quad": [[20, 30], [300, 10], [310, 230], [10, 220]], "size": [320, 240]}'
    view = nfpt(photo, LINES_JSON, size=(160, 128), block=32, overlap=8, view=quad, rng=1)
    assert view.image.shape == (240, 320, 3) and 0.7 < view.figures["view_coverage"] < 0.9
    assert view.image[0, 319].max() == 0  # outside the quad: black


def test_pipeline_without_lines_takes_the_photo_as_frontal(gravel):
    res = nfpt(gravel, size=(64, 64), block=24, overlap=6, rng=1)
    assert res.homography is None and res.rectified is not None and res.image.shape == (64, 64)
    with pytest.raises(GeometryError, match="--into-photo needs the feature lines"):
        nfpt(gravel, into_photo=True, block=24, overlap=6)


def test_method_runs_with_params_and_reports_figures(photo):
    params = NfptParams(lines=LINES_JSON, size=(96, 96), block=32, overlap=8)
    result = METHOD.run({"photo": photo}, params, rng=1)
    assert result.image.shape == (96, 96, 3)
    assert {"patches", "repaired_pixels", "repaired_fraction", "rectify_rms_lines_px", "homography"} <= set(
        result.figures
    )
    assert NfptParams().block == 48  # defaults construct (the studio builds them for every method)
    with pytest.raises(InvalidParameter, match="'view' and 'into_photo' exclude each other"):
        NfptParams(view={"quad": [[0, 0], [9, 0], [9, 9], [0, 9]]}, into_photo=True)


def test_fft_search_equals_the_direct_sum_of_eq_3(fur):
    from weft.core.image import luminance
    from weft.core.nfpt.synthesis import _Search

    rng = np.random.default_rng(0)
    src = fur[:40, :50]
    src_y = luminance(src)
    canvas = rng.random((30, 30, 3), dtype=np.float32)
    canvas_y = luminance(canvas)
    wd = distance_weights(16, 5, 5, sigma_d=2.5)
    search = _Search(src_y, float(src_y.mean()), 8, 0.35)
    cmap, const = search.cost(canvas_y, canvas, 7, 9, wd)
    w = search.w_buf[:16, :16].astype(np.float64)
    assert (w[wd == 0] == 0).all() and (w[wd > 0] > wd[wd > 0]).all()  # W_d + W_s on the L only
    t = canvas_y[7:23, 9:25].astype(np.float64)
    for py, px in [(0, 0), (10, 20), (24, 34), (3, 30)]:
        s = src_y[py : py + 16, px : px + 16].astype(np.float64)
        direct = (w * (t - s) ** 2).sum()
        assert cmap[py, px] + const == pytest.approx(direct, rel=1e-3, abs=1e-4)
