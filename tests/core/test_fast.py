"""Fast texture transfer (Ashikhmin): every mode and metric, on pixels, with seeds and quality bounds."""

import threading

import numpy as np
import pytest
from weft.core import metrics
from weft.core.errors import Cancelled, ImageError, InvalidParameter
from weft.core.examples import example
from weft.core.fast import METHOD, FastParams, _transfer, transfer
from weft.core.image import load_image, resize, rgb_to_yiq
from weft.core.jobs import CancelToken


@pytest.fixture(scope="module")
def gravel():
    return load_image(example("gravel")).image[:64, :64]


@pytest.fixture(scope="module")
def camera():
    return resize(load_image(example("camera")).image, (128, 128), interpolation="area")


@pytest.fixture(scope="module")
def fur():
    return load_image(example("cat-fur")).image[:64, :64]


@pytest.fixture(scope="module")
def astronaut():
    return resize(load_image(example("astronaut")).image, (96, 96), interpolation="area")


def _rows_of(image):
    return {tuple(np.round(np.atleast_1d(v), 6)) for v in image.reshape(-1, image.shape[-1] if image.ndim == 3 else 1)}


def test_synthesis_copies_source_pixels_and_is_deterministic(fur):
    a = transfer(fur, size=(80, 60), rng=3)
    b = transfer(fur, size=(80, 60), rng=3)
    c = transfer(fur, size=(80, 60), rng=4)
    assert a.shape == (60, 80, 3) and a.dtype == np.float32
    assert np.array_equal(a, b) and not np.array_equal(a, c)
    # Colour comes from the source: every output pixel is one of the texture's pixels.
    assert _rows_of(a) <= _rows_of(fur)
    # Coherent synthesis grows patches: most pixels continue their left neighbour's patch.
    _, pos, _ = _transfer(fur, None, FastParams(size=(80, 60)), rng=3)  # flat source indices
    cont = np.mean(pos[:, 1:] == pos[:, :-1] + 1)
    assert cont > 0.6


def test_synthesis_quality_beats_shuffled_pixels(fur):
    out = transfer(fur, size=(96, 96), rng=1)
    shuffled = np.random.default_rng(0).permutation(out.reshape(-1, 3)).reshape(out.shape)
    assert metrics.coherence(out, fur) < 0.5 * metrics.coherence(shuffled, fur)


def test_target_metric_follows_the_target(gravel, camera):
    out = transfer(gravel, camera, metric="target", p=0.05, rng=1)
    assert out.shape == camera.shape
    assert metrics.fidelity(out, camera) > 0.85
    # Without the target part (full metric, weight 0) the picture is lost.
    ignored = transfer(gravel, camera, metric="full", target_weight=0.0, rng=1)
    assert metrics.fidelity(ignored, camera) < 0.5
    # Luminance values are the source's own (remapping only affects matching).
    assert set(np.unique(out)) <= set(np.unique(gravel))


def test_full_metric_trades_fidelity_for_coherence(gravel, camera):
    weak = transfer(gravel, camera, metric="full", target_weight=0.2, rng=2)
    strong = transfer(gravel, camera, metric="full", target_weight=5.0, rng=2)
    assert metrics.fidelity(strong, camera) > metrics.fidelity(weak, camera)


def test_random_candidates_shrink_patches(gravel, camera):
    def coherent_fraction(p):
        return METHOD.run({"texture": gravel, "target": camera}, FastParams(metric="target", p=p), rng=5).figures[
            "coherent_fraction"
        ]

    assert coherent_fraction(0.0) > coherent_fraction(0.5) > coherent_fraction(1.0)


def test_transfer_keeps_the_target_chroma(gravel, astronaut):
    out = transfer(gravel, astronaut, rng=1)
    assert out.shape == astronaut.shape
    yiq_out, yiq_t = rgb_to_yiq(out), rgb_to_yiq(astronaut)
    unclipped = np.all((out > 0.001) & (out < 0.999), axis=2)
    assert unclipped.mean() > 0.5
    assert np.allclose(yiq_out[unclipped][:, 1:], yiq_t[unclipped][:, 1:], atol=2e-3)
    # colour="source" copies the source pixels instead: a grey source gives a grey result.
    grey = transfer(gravel, astronaut, colour="source", rng=1)
    assert grey.ndim == 2


def test_artistic_metric_and_its_average_weight(gravel, camera):
    a = transfer(gravel, camera, metric="artistic", w=0.0, rng=1)
    b = transfer(gravel, camera, metric="artistic", w=50.0, rng=1)
    assert not np.array_equal(a, b)
    # The average term is what ties the result to the photograph's large-scale light.
    assert metrics.fidelity(b, camera) > metrics.fidelity(a, camera)
    assert metrics.fidelity(b, camera) > 0.8


def test_location_candidate_reproduces_the_picture(camera):
    """novel mode, m = 1, p_l = 1: the candidate at (x, y) matches exactly, so the picture comes back."""
    pic = camera[:48, :48]
    out = transfer(pic, mode="novel", magnify=1, p=0.0, p_l=1.0, metric="target", remap=False, rng=0)
    assert np.array_equal(out[2:-2, 2:-2], pic[2:-2, 2:-2])


def test_super_resolution_magnifies_with_source_pixels(fur):
    small = fur[:32, :32]
    out = transfer(small, magnify=3, rng=1)
    assert out.shape == (96, 96, 3)
    assert _rows_of(out) <= _rows_of(small)
    resolved = FastParams(magnify=3).resolved(has_target=False)
    assert (resolved.mode, resolved.p, resolved.p_l, resolved.colour) == ("superres", 0.0, 0.03, "source")


def test_super_resolution_adds_detail_to_a_self_similar_image():
    """Clouds (fractal): the result follows the picture and restores fine detail that cubic blurs away."""
    original = load_image(example("clouds")).image[:128, :128]
    small = resize(original, (32, 32), interpolation="area")
    out = transfer(small, magnify=4, rng=1)
    cubic = resize(small, (128, 128), interpolation="cubic")
    assert metrics.fidelity(out, original) > 0.9

    def detail(img):  # energy of the finest scale
        return float(np.abs(img[1:, 1:] - img[:-1, 1:] - img[1:, :-1] + img[:-1, :-1]).mean())

    assert abs(detail(out) - detail(original)) < abs(detail(cubic) - detail(original))


def test_novel_style_keeps_the_picture_colour(astronaut):
    out = transfer(astronaut, mode="novel", magnify=2, p=0.2, rng=1)
    assert out.shape == (192, 192, 3)
    assert metrics.fidelity(out, resize(astronaut, (192, 192))) > 0.8


def test_iterations_change_and_stay_deterministic(gravel, camera):
    one = transfer(gravel, camera, metric="target", iterations=1, rng=9)
    two = transfer(gravel, camera, metric="target", iterations=2, rng=9)
    assert not np.array_equal(one, two)
    assert np.array_equal(two, transfer(gravel, camera, metric="target", iterations=2, rng=9))
    assert metrics.fidelity(two, camera) >= metrics.fidelity(one, camera) - 0.01


def test_source_mask_restricts_candidates(camera):
    src = np.zeros((40, 40), np.float32)
    src[:, 20:] = np.random.default_rng(1).uniform(0.5, 1.0, (40, 20))
    mask = np.zeros_like(src)
    mask[:, 20:] = 1.0
    out = transfer(src, camera[:50, :50], mask=mask, p=0.5, rng=1)
    assert out.min() >= 0.5  # nothing from the masked-out black half
    _, pos, _ = _transfer(src, camera[:50, :50], FastParams(p=0.5), mask=mask, rng=1)
    assert (pos % 40).min() >= 20  # every chosen source position (flat index) lies in the white half
    with pytest.raises(ImageError, match="source mask is 10x10, the texture 40x40"):
        transfer(src, camera, mask=np.ones((10, 10), np.float32))
    with pytest.raises(ImageError, match="leaves no usable position"):
        transfer(src, camera, mask=np.zeros_like(src))


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"n": 4}, "parameter 'n' = 4 must be odd"),
        ({"n": 17}, "parameter 'n' = 17 is outside 3..15"),
        ({"p": 1.5}, "parameter 'p' = 1.5 is outside 0..1"),
        ({"magnify": 0}, "parameter 'magnify' = 0 is outside 1..16"),
        ({"metric": "fancy"}, "parameter 'metric' = 'fancy' is not one of full, target, artistic"),
        ({"mode": "transfer"}, "mode 'transfer' needs a target image"),
        ({"metric": "target"}, "metric 'target' needs a target"),
    ],
)
def test_bad_parameters(fur, kwargs, message):
    with pytest.raises(InvalidParameter, match=message.replace("(", r"\(")):
        transfer(fur, **kwargs)


def test_target_with_a_targetless_mode_and_tiny_source(fur, camera):
    with pytest.raises(InvalidParameter, match="mode 'superres' takes no target"):
        transfer(fur, camera, mode="superres")
    with pytest.raises(InvalidParameter, match="must fit in the source, 4x4"):
        transfer(fur[:4, :4], camera)


def test_progress_and_cancel(gravel, camera):
    seen = []
    transfer(gravel, camera, rng=1, progress=seen.append)
    assert seen and seen[-1].done == seen[-1].total
    assert [p.done for p in seen] == sorted(p.done for p in seen)
    assert seen[0].preview.shape == camera.shape
    token = CancelToken()
    token.cancel()
    with pytest.raises(Cancelled):
        transfer(gravel, camera, rng=1, cancel=token)


def test_two_threads_give_the_same_pixels_as_one(gravel, camera):
    expected = [transfer(gravel, camera, rng=s) for s in (1, 2)]
    got = [None, None]

    def work(i):
        got[i] = transfer(gravel, camera, rng=i + 1)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=60)
    assert all(np.array_equal(g, e) for g, e in zip(got, expected, strict=True))


def test_metric_codes_match_the_kernel():
    from weft.core._kernels import fast as kernel
    from weft.core.fast import METRICS

    assert METRICS == {"full": kernel.METRIC_FULL, "target": kernel.METRIC_TARGET, "artistic": kernel.METRIC_ARTISTIC}


@pytest.mark.slow
def test_the_largest_neighbourhoods_stay_inside_the_kernels_buffers(tmp_path):
    """n = 13 and 15 (the top of the slider) in every metric, with numba's bounds checks on: an index
    past a buffer raises instead of silently corrupting memory."""
    import os
    import subprocess
    import sys

    script = (
        "import numpy as np\n"
        "from weft.core.examples import example\n"
        "from weft.core.fast import transfer\n"
        "from weft.core.image import load_image, resize\n"
        "src = load_image(example('gravel')).image[:96, :96]\n"
        "tgt = resize(load_image(example('camera')).image, (64, 64), interpolation='area')\n"
        "for n in (13, 15):\n"
        "    for metric in ('full', 'target', 'artistic'):\n"
        "        out = transfer(src, tgt, n=n, metric=metric, p=0.1, rng=3)\n"
        "        assert out.shape == tgt.shape and set(np.unique(out)) <= set(np.unique(src)), (n, metric)\n"
        "print('ok')\n"
    )
    env = {**os.environ, "NUMBA_BOUNDSCHECK": "1", "NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    done = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0 and done.stdout.strip() == "ok", done.stderr[-2000:]
