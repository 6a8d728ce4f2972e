"""Affine model §3 and §4 (transfer): synthesis quality, lowpass and colour handling, prototype
swaps, reusable models, bad input, progress, cancel."""

import threading

import numpy as np
import pytest
from weft.core import metrics
from weft.core.affine import (
    METHOD,
    AffineParams,
    analyse,
    decompose,
    make_prototype,
    prototype_from_patch,
    render,
    synthesize,
)
from weft.core.errors import Cancelled, GeometryError, ImageError, InvalidParameter
from weft.core.examples import example
from weft.core.image import load_image, resize
from weft.core.jobs import CancelToken

from benchmarks.fixtures.procedural import cells, weave


@pytest.fixture(scope="module")
def scales():
    return cells(192)


@pytest.fixture(scope="module")
def woven():
    return weave(192)


@pytest.fixture(scope="module")
def colour():
    return resize(load_image(example("astronaut")).image, (128, 128), interpolation="area")


def test_synthesis_reproduces_a_cell_texture(scales):
    out = synthesize(scales)
    assert out.shape == scales.shape and out.dtype == np.float32
    assert 0.0 <= out.min() and out.max() <= 1.0
    snr = metrics.snr_db(scales, out)
    assert snr > 15.0  # 16.3 dB measured here; 17.9 dB at 512² (the benchmark)
    # the paper's pipeline alone (eight candidates, no refinement) is far less accurate
    paper = metrics.snr_db(scales, synthesize(scales, propagate=False, refine=0))
    assert 3.0 < paper < snr - 5.0


def test_synthesis_reproduces_a_woven_texture(woven):
    assert metrics.snr_db(woven, synthesize(woven)) > 11.0


def test_the_lowpass_alone_explains_little(scales):
    dec = decompose(scales, 32)
    np.testing.assert_allclose(dec.low + dec.high, dec.grey, atol=1e-6)  # exact split (§3.3)
    assert metrics.snr_db(scales, np.clip(dec.low, 0, 1)) < 1.0


def test_flat_prototype_renders_flat_windows_sum_to_one(scales):
    # A constant prototype with every factor 1, rendered unfiltered: the cos² windows must add
    # up to exactly one over the whole image (§3.1), whatever the transforms and translations.
    model = analyse(scales, lowpass="absorb")
    from dataclasses import replace

    model = replace(model, alpha=np.ones_like(model.alpha))
    flat = np.full((64, 64), 0.3, np.float32)
    np.testing.assert_allclose(render(model, flat), 0.3, atol=1e-5)


def test_flat_texture_does_not_crash():
    flat = np.full((96, 96), 0.5, np.float32)
    out = synthesize(flat)
    assert np.all(np.isfinite(out)) and np.allclose(out, 0.5, atol=1e-4)
    out = synthesize(flat, lowpass="absorb", boundary="shaker", rng=0)
    assert np.all(np.isfinite(out))


@pytest.mark.parametrize("lowpass", ["add", "absorb"])
@pytest.mark.parametrize("colour_space", ["pca", "yuv"])
def test_colour_both_ways(colour, lowpass, colour_space):
    # a photo, not a texture: one 64-pixel prototype of it cannot reproduce it, but add keeps its
    # lowpass and chroma (recognisable, 6.8 dB measured) and absorb its intensities (3.5 dB)
    out = synthesize(colour, lowpass=lowpass, colour=colour_space)
    assert out.shape == colour.shape and np.all(np.isfinite(out))
    assert np.abs(out.mean(axis=(0, 1)) - colour.mean(axis=(0, 1))).max() < 0.08
    assert metrics.snr_db(colour, out) > (5.0 if lowpass == "add" else 2.5)


def test_pca_grey_carries_more_of_a_colour_texture_than_luma():
    # a texture whose structure is in a colour direction luma hardly sees (red against green)
    y, x = np.mgrid[:96, :96]
    s = 0.5 + 0.4 * np.sin(2 * np.pi * (0.11 * x + 0.05 * y))
    img = np.stack([s, 1.0 - s, np.full_like(s, 0.5)], axis=2).astype(np.float32) * 0.8 + 0.1
    pca = decompose(img, 32, "pca").high.std()
    yuv = decompose(img, 32, "yuv").high.std()
    assert pca > 2 * yuv


def test_reused_transforms_render_the_same_prototype_identically(scales):
    model = analyse(scales, prototype=(40, 50, 64))
    same = make_prototype(scales, (40, 50, 64), block=32, decomposition=model.decomposition)
    np.testing.assert_array_equal(render(model), render(model, same))
    moved = render(model, make_prototype(scales, (60, 50, 64), block=32))
    assert moved.shape == scales.shape and not np.array_equal(moved, render(model))


def test_prototype_swap_takes_the_new_prototypes_colour(scales):
    # Fig. 5 top: a recoloured prototype substituted into the existing transforms (absorb: the
    # colour and shading come from the prototype).
    model = analyse(scales, lowpass="absorb")
    grey = model.prototype.grey
    tinted = np.clip(np.stack([grey * 1.0, grey * 0.6, grey * 0.3], axis=2), 0, 1).astype(np.float32)
    out = render(model, prototype_from_patch(tinted))
    assert out.shape == scales.shape + (3,)
    r, g, b = out.reshape(-1, 3).mean(axis=0)
    assert r > g > b
    # the structure is the same as the grey synthesis
    assert np.corrcoef(out[..., 0].ravel(), render(model).ravel())[0, 1] > 0.95


def test_transfer_onto_a_photo_keeps_its_lowpass(scales):
    # Fig. 5 middle: the transforms are computed for a prototype from another image, the
    # photo's lowpass (and colour) are kept.
    photo = resize(load_image(example("chelsea")).image, (144, 96), interpolation="area")
    out = synthesize(photo, prototype_image=scales, prototype=(64, 64, 64))
    assert out.shape == photo.shape
    low = decompose(photo, 32).low
    got = decompose(out, 32).low
    assert np.corrcoef(low.ravel(), got.ravel())[0, 1] > 0.95
    # and the texture is the prototype's: its highpass energy is of the scales' order
    assert decompose(out, 32).high.std() > 0.5 * decompose(scales, 32).high.std()


def test_model_is_reusable_and_cheap_to_render(scales):
    model = analyse(scales)
    a = render(model)
    b = render(model)
    np.testing.assert_array_equal(a, b)
    assert model.sampling.shape == (model.grid.count, 2, 2)
    np.testing.assert_allclose(
        model.transforms @ model.sampling, np.broadcast_to(np.eye(2), model.sampling.shape), atol=1e-9
    )
    assert np.all(np.abs(model.shifts) <= model.grid.radius)


@pytest.mark.parametrize(
    "rect, error, fragment",
    [
        ((150, 10, 64), GeometryError, "outside the 192x192 texture"),
        ((-1, 0, 64), InvalidParameter, "must not be negative"),
        ((0, 0, 200), GeometryError, "larger than the texture (192x192)"),
        ((0, 0, 63), InvalidParameter, "must be even"),
        ((0, 0, 6), InvalidParameter, "at least 8"),
        ("1,2", InvalidParameter, "must be X,Y,S"),
    ],
)
def test_bad_prototypes_give_one_clear_error(scales, rect, error, fragment):
    with pytest.raises(error) as info:
        synthesize(scales, prototype=rect)
    msg = str(info.value)
    assert fragment in msg and "\n" not in msg and "prototype" in msg


def test_bad_parameters_and_images(scales):
    with pytest.raises(InvalidParameter, match="'block' = 31 must be even"):
        AffineParams(block=31)
    with pytest.raises(InvalidParameter, match="'block' = 31 must be even"):
        synthesize(scales, block=31)
    with pytest.raises(InvalidParameter, match="'block' = 128 is outside 8..96"):
        synthesize(scales[:96, :96], block=128)
    with pytest.raises(InvalidParameter, match="'segments' = 9 must be even"):
        AffineParams(segments=9)
    with pytest.raises(InvalidParameter, match="analysis_prototype"):
        AffineParams(analysis_prototype="0,0,64")
    with pytest.raises(InvalidParameter, match="size"):
        AffineParams(size=(64, 64))
    with pytest.raises(ImageError, match="NaN"):
        synthesize(np.full((64, 64), np.nan, np.float32))
    with pytest.raises(GeometryError, match="prototype image"):
        synthesize(scales, prototype_image=scales[:40, :40], prototype=(0, 0, 64))


def test_progress_and_preview_per_patch_row(scales):
    calls = []
    synthesize(scales, boundary="shaker", rng=1, progress=calls.append)
    stages = {c.stage for c in calls}
    assert {"affine analysis", "boundary matching"} <= stages
    analysis = [c for c in calls if c.stage == "affine analysis"]
    assert analysis[-1].done == analysis[-1].total
    assert analysis[0].preview is not None and analysis[0].preview.shape == scales.shape
    shaker = [c for c in calls if c.stage == "boundary matching"]
    assert shaker[-1].preview.shape == scales.shape


def test_cancel_stops_the_job(scales):
    token = CancelToken()
    token.cancel()
    with pytest.raises(Cancelled):
        synthesize(scales, cancel=token)
    # cancelled while running, from the progress callback of another thread's token
    token = CancelToken()

    def cancel_soon(p):
        if p.done >= 2:
            token.cancel()

    with pytest.raises(Cancelled):
        synthesize(scales, boundary="shaker", progress=cancel_soon, cancel=token)


def test_two_jobs_in_two_threads_give_the_same_pixels(scales):
    ref = synthesize(scales, boundary="shaker", rng=3)
    outs = [None, None]

    def job(i):
        outs[i] = synthesize(scales, boundary="shaker", rng=3)

    threads = [threading.Thread(target=job, args=(i,)) for i in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for o in outs:
        np.testing.assert_array_equal(o, ref)


def test_method_is_registered_with_its_inputs():
    from weft.core import registry

    m = registry.get("affine")
    assert m is METHOD
    assert [i.name for i in m.inputs] == ["texture", "prototype_image"]
    assert not m.inputs[1].required
    AffineParams()  # defaults validate (the GUI builds its panel from them)


def test_reused_transforms_are_cached_between_runs(scales):
    """The studio re-runs the method for every move of the prototype square: with reused
    transforms the analysis is remembered (by content and parameters) and only the render redone."""
    from weft.core.affine import method

    method.forget_analyses()
    params = AffineParams(reuse_transforms=True, prototype="40,40,64")
    first = METHOD.run({"texture": scales}, params, rng=0).image
    assert method.cached_analyses() == 1
    moved = METHOD.run({"texture": scales}, params.replace(prototype="60,50,64"), rng=0).image
    assert method.cached_analyses() == 1  # the same analysis served the move
    method.forget_analyses()
    fresh = METHOD.run({"texture": scales}, params.replace(prototype="60,50,64"), rng=0).image
    np.testing.assert_array_equal(moved, fresh)
    assert not np.array_equal(first, moved)
    other = scales[::-1].copy()  # other content: another analysis
    METHOD.run({"texture": other}, params, rng=0)
    METHOD.run({"texture": scales}, params.replace(block=16), rng=0)  # other parameters: another one
    assert method.cached_analyses() == 2  # at most two are kept
