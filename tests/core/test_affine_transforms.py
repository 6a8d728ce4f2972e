"""Affine model §2.2-2.4: the eight candidate transforms, translations by correlation, the choice."""

import cv2
import numpy as np
import pytest
from weft.core.affine import analyse, candidate_transforms, correlate_shifts, regularise_pairs
from weft.core.affine.transforms import MAX_SCALE, MIN_SCALE, PAIRINGS, singular_values


def _rotation_scale(deg, scale):
    """T in (y, x) coordinates, y down: a counter-clockwise turn on screen by ``deg``, then ``scale``."""
    a = np.deg2rad(deg)
    return scale * np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])


def _pattern(n):
    """Two gratings 75° apart, one with a harmonic that makes it asymmetric (no 180° symmetry)."""
    y, x = np.mgrid[:n, :n].astype(np.float64)
    t1 = 2 * np.pi * (0.03 * y + 0.13 * x)
    t2 = 2 * np.pi * (0.12 * y - 0.03 * x) + 0.7
    s = np.cos(t1) + 0.5 * np.sin(2 * t1) + 0.8 * np.cos(t2)
    return ((s - s.min()) / (s.max() - s.min())).astype(np.float32)


def _warp_about_centre(img, T):
    """target(y) = img(c + T⁻¹ (y - c)): ``img`` deformed by T about the image centre."""
    n = img.shape[0]
    c = (n - 1) / 2
    Ti = np.linalg.inv(T)
    Mxy = np.array([[Ti[1, 1], Ti[1, 0]], [Ti[0, 1], Ti[0, 0]]])  # OpenCV wants (x, y)
    off = np.array([c, c]) - Mxy @ np.array([c, c])
    A = np.hstack([Mxy, off[:, None]])
    return cv2.warpAffine(img, A, (n, n), flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP, borderMode=cv2.BORDER_REFLECT)


@pytest.fixture(scope="module")
def rotated_case():
    B = 32
    n = 5 * B
    proto_img = _pattern(n)
    T = _rotation_scale(30, 1.2)
    target = _warp_about_centre(proto_img, T)
    rect = ((n - 2 * B) // 2, (n - 2 * B) // 2, 2 * B)  # the prototype around the same centre
    return proto_img, target, T, rect, B


def _centre_patch(model):
    g = model.grid
    centres = g.origins() - g.step + (g.block - 1) / 2
    c = (g.height - 1) / 2
    return int(np.argmin(np.abs(centres - c).sum(axis=1)))


def test_rotation_by_30_scale_by_1_2_is_among_the_candidates_and_chosen(rotated_case):
    from weft.core.affine.analysis import _central
    from weft.core.affine.model import decompose, make_prototype
    from weft.core.affine.spectral import centroids

    proto_img, target, T, rect, B = rotated_case
    # §2.2: the eight candidates from the centroid pairs contain T (within the centroids' bias)
    proto = make_prototype(proto_img, rect, block=B)
    mu_p = centroids(_central(proto.highpass, B), lowcut=1 / B).mu[0]
    n = target.shape[0]
    o = (n - B) // 2
    mu_t = centroids(decompose(target, B).high[o : o + B, o : o + B], lowcut=1 / B).mu[0]
    cands = candidate_transforms(mu_p, mu_t)
    rel = np.linalg.norm(cands - T, axis=(1, 2)) / np.linalg.norm(T)
    assert rel.min() < 0.15
    j = int(np.argmin(rel))
    # §2.3-2.4 (the paper's pipeline only): that candidate is chosen, with no translation
    model = analyse(target, prototype=rect, prototype_image=proto_img, block=B, propagate=False, refine=0)
    k = _centre_patch(model)
    assert model.choice[k] == j
    np.testing.assert_allclose(model.transforms[k], cands[j])
    assert np.abs(model.shifts[k]).max() <= 1


def test_refinement_recovers_the_transform_exactly(rotated_case):
    proto_img, target, T, rect, B = rotated_case
    model = analyse(target, prototype=rect, prototype_image=proto_img, block=B)  # defaults: refine on
    k = _centre_patch(model)
    assert np.linalg.norm(model.transforms[k] - T) / np.linalg.norm(T) < 0.02
    assert np.abs(model.shifts[k]).max() < 0.3


def test_candidates_are_the_eight_pairings_and_their_negations():
    mu_p = np.array([[0.1, 0.02], [0.03, -0.12]])
    mu_t = np.array([[0.05, 0.11], [0.12, 0.01]])
    T = candidate_transforms(mu_p, mu_t)
    assert T.shape == (8, 2, 2) and len(PAIRINGS) == 8
    np.testing.assert_allclose(T[4:], -T[:4])  # -C_p gives -A, and T = (A^T)^-1
    # candidate 0 maps the pair as given: A mu_p = mu_t with T = (A^T)^-1
    A = np.linalg.inv(T[0]).T
    np.testing.assert_allclose(A @ mu_p, mu_t, atol=1e-12)
    # the eight are distinct
    flat = T.reshape(8, -1)
    assert len({tuple(np.round(r, 9)) for r in flat}) == 8


@pytest.mark.parametrize(
    "mu",
    [
        np.array([[0.1, 0.1], [0.05, 0.05]]),  # parallel centroids (singular pair)
        np.array([[0.1, 0.1000001], [0.05, 0.05]]),  # nearly parallel
        np.array([[0.1, -0.1], [0.05, -0.05]]),  # opposite
        np.zeros((2, 2)),  # empty spectrum
        np.array([[1e-12, 0.0], [0.0, 0.0]]),
    ],
)
def test_degenerate_centroid_pairs_give_no_nan(mu):
    good = np.array([[0.1, 0.02], [0.03, -0.12]])
    for p, t in ((mu, good), (good, mu), (mu, mu)):
        T = candidate_transforms(p, t)
        assert np.all(np.isfinite(T))
        sv = singular_values(T)
        assert np.all(sv <= MAX_SCALE + 1e-9) and np.all(sv >= MIN_SCALE - 1e-9)
    fixed = regularise_pairs(mu)
    assert abs(np.linalg.det(fixed)) > 0


def test_flat_target_maps_by_the_identity_frame():
    T = candidate_transforms(np.zeros((2, 2)), np.zeros((2, 2)))
    np.testing.assert_allclose(T[0], np.eye(2))


def test_correlation_finds_a_known_shift():
    rng = np.random.default_rng(5)
    B, R = 32, 8
    L = B + 2 * R
    frame = cv2.GaussianBlur(rng.random((L, L)).astype(np.float32), (0, 0), 1.5)
    for ty, tx in [(0, 0), (3, -2), (-8, 8), (5, 7)]:
        # the target is the frame moved by t: target[a] = frame[R + a - t]
        target = frame[R - ty : R - ty + B, R - tx : R - tx + B]
        shifts, peak = correlate_shifts(frame[None, None], (target - target.mean())[None], R)
        # the raw correlation of eq. 23 is not normalised: check it on a zero-mean frame too
        f0 = frame - frame.mean()
        t0 = f0[R - ty : R - ty + B, R - tx : R - tx + B]
        s0, _ = correlate_shifts(f0[None, None], t0[None], R)
        assert tuple(s0[0, 0]) == (ty, tx)
    # turned candidates: a frame turned by 180° is found as the turned candidate
    turned = frame[::-1, ::-1]
    target = (turned - turned.mean())[R : R + B, R : R + B]
    s, p = correlate_shifts((frame - frame.mean())[None, None], target[None], R, turned=True)
    assert s.shape == (1, 2, 2) and tuple(s[0, 1]) == (0, 0) and p[0, 1] > p[0, 0]
