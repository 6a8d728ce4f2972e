"""Affine model §2.1 and §3.1: cos² windows, spectral centroids by Kruger's partial sums."""

import numpy as np
import pytest
from weft.core.affine import centroid_pairs, centroids, cos2_window, segment_sums
from weft.core.errors import InvalidParameter


@pytest.mark.parametrize("B", [8, 16, 32, 64])
def test_cos2_windows_overlapping_by_half_sum_to_one(B):
    win = cos2_window(B)
    assert win.shape == (B, B) and win.dtype == np.float32
    h = B // 2
    total = np.zeros((4 * B, 4 * B))
    for y in range(0, 3 * B + 1, h):
        for x in range(0, 3 * B + 1, h):
            total[y : y + B, x : x + B] += win
    # Everywhere covered by the full two-by-two overlap the windows sum to one (§3.1).
    np.testing.assert_allclose(total[h : 3 * B + h, h : 3 * B + h], 1.0, atol=1e-6)
    assert win.max() <= 1.0 and win.min() > 0.0  # sin²(π(a+½)/B): no exact zero on the grid


def _sinusoid(n, f, phase=0.0):
    y, x = np.mgrid[:n, :n]
    return np.cos(2 * np.pi * (f[0] * y + f[1] * x) + phase).astype(np.float32)


@pytest.mark.parametrize("angle", [0, 30, 75, 120, 160])
def test_oriented_sinusoid_gives_its_frequency_direction(angle):
    a = np.deg2rad(angle)
    f = 0.15 * np.array([np.sin(a), np.cos(a)])  # (y, x), cycles/pixel
    c = centroids(_sinusoid(32, f))
    # One energy cluster (spread by the window): the best split either cuts it in two or sets a
    # tight, nearly empty run beside it; either way the mass-weighted mean of the pair -- the
    # half-plane's centroid -- is the sinusoid's frequency (±f).
    mu1, mu2 = c.mu[0, :, 0], c.mu[0, :, 1]
    if mu1 @ mu2 < 0:  # the two runs' half-plane may straddle the angle π: align their signs
        mu2 = -mu2
    mu = (c.masses[0, 0] * mu1 + c.masses[0, 1] * mu2) / c.masses[0].sum()
    cos = abs(mu @ f) / (np.linalg.norm(mu) * np.linalg.norm(f))
    assert cos > np.cos(np.deg2rad(3)), (angle, mu)
    assert 0.9 < np.linalg.norm(mu) / np.linalg.norm(f) < 1.1
    assert not c.degenerate[0]


def test_two_sinusoids_give_the_two_frequencies():
    f1 = np.array([0.02, 0.16])
    f2 = np.array([0.15, -0.05])
    patch = _sinusoid(64, f1) + 0.8 * _sinusoid(64, f2, 0.4)
    mu = centroids(patch).mu[0]
    found = [mu[:, 0], mu[:, 1]]
    for f in (f1, f2):
        d = min(min(np.linalg.norm(m - f), np.linalg.norm(m + f)) for m in found)
        assert d < 0.12 * np.linalg.norm(f)


def _brute_force(patch, segments):
    """Eqs. 3-6 directly: every split (k, l) of every half-plane, variances from the bins."""
    from weft.core.affine.spectral import _bins

    n = patch.shape[0]
    bins = _bins(n, segments, 1.0 / n)
    win = cos2_window(n)
    p = (patch - patch.mean()) * win
    mag = np.abs(np.fft.rfft2(p)).ravel()[bins.flat]
    omega = bins.omega
    ang = np.mod(np.arctan2(omega[:, 0], omega[:, 1]), np.pi)
    # the full plane: every bin and its mirror
    full_w = np.concatenate([omega, -omega])
    full_m = np.concatenate([mag, mag])
    full_a = np.concatenate([ang, ang + np.pi])
    seg = np.floor(full_a / (2 * np.pi / segments)).astype(int) % segments
    half = segments // 2
    best = (np.inf, None)
    for k in range(segments):
        for l in range(k + 1, k + half):  # noqa: E741 (the paper's segment indices k, l)
            total = 0.0
            mus = []
            for a, b in ((k, l), (l, k + half)):
                sel = np.isin(seg, np.arange(a, b) % segments)
                m = full_m[sel].sum()
                if m <= 0:
                    total = np.inf
                    break
                mu = (full_m[sel, None] * full_w[sel]).sum(0) / m
                total += (full_m[sel] * ((full_w[sel] - mu) ** 2).sum(1)).sum() / m  # eq. 4
                mus.append(mu)
            if total < best[0]:
                best = (total, mus)
    return best


def test_partial_sums_equal_the_brute_force_minimum():
    rng = np.random.default_rng(3)
    patch = rng.random((16, 16)).astype(np.float32) + _sinusoid(16, (0.1, 0.2))
    c = centroids(patch, segments=16)
    total, mus = _brute_force(patch, 16)
    assert c.variance[0] == pytest.approx(total, rel=1e-6)  # float32 spectra in the code
    got = np.array(sorted([tuple(c.mu[0, :, 0]), tuple(c.mu[0, :, 1])]))
    want = np.array(sorted([tuple(m) for m in mus]))
    neg = np.array(sorted([tuple(-m) for m in mus]))  # the mirrored half-plane's pair
    assert np.allclose(got, want, atol=1e-6) or np.allclose(got, neg, atol=1e-6)


def test_half_plane_sums_carry_the_symmetry():
    patch = np.random.default_rng(0).random((32, 32)).astype(np.float32)
    M, f1, f2 = segment_sums(patch, segments=32)
    assert M.shape == (16,) and f1.shape == (16,) and f2.shape == (16, 2)
    assert np.all(M >= 0) and np.all(f1 >= 0)


def test_flat_and_empty_spectra_do_not_crash():
    flat = np.full((32, 32), 0.4, np.float32)
    c = centroids(np.stack([flat, np.zeros((32, 32), np.float32)]))
    assert np.all(np.isfinite(c.mu)) and c.degenerate.all() and np.all(c.mass == 0)
    # one bright pixel: energy everywhere, nothing degenerate, nothing NaN
    spike = np.zeros((32, 32), np.float32)
    spike[10, 12] = 1
    assert np.all(np.isfinite(centroids(spike).mu))


def test_degenerate_spectrum_in_one_segment():
    # a direct batch of sums with all energy in one segment: no valid split -> flagged, finite
    M = np.zeros((1, 8))
    f1 = np.zeros((1, 8))
    f2 = np.zeros((1, 8, 2))
    M[0, 3] = 2.0
    f1[0, 3] = 0.08
    f2[0, 3] = [0.2, 0.1]
    c = centroid_pairs(M, f1, f2)
    assert c.degenerate[0] and np.all(np.isfinite(c.mu))
    np.testing.assert_allclose(c.mu[0, :, 0], [0.1, 0.05])
    assert abs(c.mu[0, :, 0] @ c.mu[0, :, 1]) < 1e-12  # μ2 = μ1 turned by 90°


@pytest.mark.parametrize("segments", [7, 2, 0])
def test_segments_must_be_even_and_at_least_four(segments):
    with pytest.raises(InvalidParameter, match="segments"):
        centroids(np.zeros((16, 16), np.float32), segments=segments)
