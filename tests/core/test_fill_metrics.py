"""The fill figures of core.metrics: coherence, detail and seam of a filled hole."""

import cv2
import numpy as np
import pytest
from skimage import data
from weft.core import metrics as M
from weft.core.errors import ImageError


@pytest.fixture(scope="module")
def gravel():
    return data.gravel()[0:128, 0:128].astype(np.float32) / 255


@pytest.fixture(scope="module")
def hole():
    h = np.zeros((128, 128), bool)
    h[40:80, 50:90] = True
    return h


def test_ground_truth_reads_as_its_surroundings(gravel, hole):
    # a natural image's own figures (the reference a fill is judged against) are near 1
    assert 0.8 < M.fill_detail(gravel, hole) < 1.25
    assert 0.6 < M.fill_seam(gravel, hole) < 1.4
    assert M.fill_coherence(gravel, hole) > 0


def test_a_verbatim_copy_of_known_pixels_is_perfectly_coherent(gravel, hole):
    out = gravel.copy()
    out[40:80, 50:90] = gravel[80:120, 0:40]  # a piece of the known region, pasted
    # every window wholly inside the pasted piece exists in the known region: those score 0
    inside = np.zeros_like(hole)
    inside[40:80, 50:90] = True
    assert M.fill_coherence(out, hole, gravel) < M.fill_coherence(gravel, hole)


def test_diffusion_is_smeared_and_flat_fill_is_incoherent(gravel, hole):
    u8 = (gravel * 255).astype(np.uint8)
    telea = cv2.inpaint(u8, hole.astype(np.uint8), 5, cv2.INPAINT_TELEA).astype(np.float32) / 255
    assert M.fill_detail(telea, hole) < 0.5
    flat = gravel.copy()
    flat[hole] = 1.0  # a white hole: a hard edge, nothing like the gravel
    assert M.fill_coherence(flat, hole, gravel) > 2 * M.fill_coherence(gravel, hole)
    assert M.fill_seam(flat, hole) > 1.5
    assert M.fill_detail(flat, hole) < 0.05


def test_noise_raises_detail(gravel, hole):
    noisy = gravel.copy()
    rng = np.random.default_rng(0)
    noisy[hole] = rng.random(int(hole.sum()), dtype=np.float32)
    assert M.fill_detail(noisy, hole) > 1.5


def test_colour_and_uncrop_border(gravel):
    rgb = np.dstack([gravel, gravel * 0.5, 1 - gravel])
    border = np.ones((128, 128), bool)
    border[16:112, 16:112] = False
    assert 0.8 < M.fill_detail(rgb, border) < 1.25
    assert 0.8 < M.fill_seam(rgb, border) < 1.25


def test_bad_holes_are_one_line_errors(gravel, hole):
    with pytest.raises(ImageError, match="hole mask is empty"):
        M.fill_coherence(gravel, np.zeros_like(hole))
    with pytest.raises(ImageError, match=r"hole mask has shape \(10, 10\)"):
        M.fill_detail(gravel, np.zeros((10, 10), bool))
    with pytest.raises(ImageError, match="no whole 7x7 window"):
        M.fill_coherence(gravel, np.ones_like(hole))
    with pytest.raises(ImageError, match="covers the whole image"):
        M.fill_seam(gravel, np.ones_like(hole))
    with pytest.raises(ImageError, match="reference image is 64x64"):
        M.fill_coherence(gravel, hole, gravel[:64, :64])
