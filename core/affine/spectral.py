"""Representative centroids of a patch's Fourier energy (Smith & Bhalerao §2.1, after Hsu and Kruger).

A patch is windowed (the cos² window of §3.1), its mean removed, and its magnitude spectrum taken
with the lowpass bins removed. The spectrum is cut into ``N`` angular segments of ``2π/N``; the
per-segment sums ``f1 = Σ|ŝ| ||ω||²``, ``f2 = Σ|ŝ| ω`` and ``M = Σ|ŝ|`` (eqs. 7–9) are computed on
one half-plane only and extended to the other by the spectrum's point symmetry (eqs. 14–16). The
cumulative sums (eqs. 11–13) give the variance of any run of segments in O(1) (eq. 10); the split
of a half-plane into two runs with the least total variance (eq. 17) gives the centroid pair
(eqs. 18–19).

Frequencies are in cycles per pixel, so patches of different sizes (a 64-pixel prototype and
32-pixel target patches) have comparable centroids. Vectors are ``(y, x)``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..errors import InvalidParameter


@lru_cache(maxsize=16)
def cos2_window(n: int) -> np.ndarray:
    """The separable cos² window of §3.1 on an ``n x n`` patch, float32 (read-only).

    ``w(a) = cos²(π (a - (n-1)/2) / n) = sin²(π (a + 1/2) / n)`` for ``a = 0..n-1``; the 2-D window
    is ``w(a) w(b)``. For even ``n``, copies shifted by ``n/2`` sum to exactly one (cos² + sin² = 1),
    which is what lets overlapping windowed patches be summed without blocking artefacts.

    Parameters
    ----------
    n : int, >= 2, even for the partition of unity
        Patch side B.

    Returns
    -------
    ndarray, float32, shape (n, n)
    """
    a = np.arange(n, dtype=np.float64)
    w1 = np.sin(np.pi * (a + 0.5) / n) ** 2
    w = np.outer(w1, w1).astype(np.float32)
    w.setflags(write=False)
    return w


@dataclass(frozen=True)
class _Bins:
    """The half-plane bins of an ``n x n`` spectrum in ``numpy.fft.rfft2`` layout."""

    flat: np.ndarray  # indices into the flattened rfft2 output
    omega: np.ndarray  # (nb, 2) their frequencies (y, x), cycles/pixel, on the half-plane [0, π)
    weights: np.ndarray  # (nb, 4 * half) design matrix: columns M | f1 | f2y | f2x per segment


@lru_cache(maxsize=32)
def _bins(n: int, segments: int, lowcut: float) -> _Bins:
    """Bins used for §2.1: one of every ``±ω`` pair (the half-plane of angles ``[0, π)``), no DC,
    no Nyquist row/column (they have no mirror), none with ``||ω|| <= lowcut`` (the lowpass)."""
    fy = np.fft.fftfreq(n)[:, None] * np.ones((1, n // 2 + 1))
    fx = np.fft.rfftfreq(n)[None, :] * np.ones((n, 1))
    ang = np.arctan2(fy, fx)  # rfft2 holds fx >= 0: angles in [-π/2, π/2]
    # Representative of the pair on the half-plane [0, π): angles in [-π/2, 0) are mirrored.
    mirror = ang < 0
    ry = np.where(mirror, -fy, fy)
    rx = np.where(mirror, -fx, fx)
    rang = np.where(mirror, ang + np.pi, ang)
    keep = np.ones_like(fy, dtype=bool)
    ky = np.fft.fftfreq(n) * n
    keep[np.isclose(np.abs(ky), n / 2), :] = False  # Nyquist row (no mirror)
    keep[:, -1] = n % 2 == 1  # Nyquist column for even n
    keep[ky < 0, 0] = False  # fx = 0: (fy, 0) and (-fy, 0) are both present, keep fy > 0
    keep &= np.hypot(fy, fx) > lowcut  # DC and the lowpass
    flat = np.flatnonzero(keep)
    omega = np.stack([ry.ravel()[flat], rx.ravel()[flat]], axis=1)
    half = segments // 2
    phi = 2 * np.pi / segments
    seg = np.minimum((rang.ravel()[flat] / phi).astype(np.int64), half - 1)
    nb = len(flat)
    wts = np.zeros((nb, 4 * half))
    rows = np.arange(nb)
    wts[rows, seg] = 1.0  # M (eq. 9)
    wts[rows, half + seg] = (omega**2).sum(axis=1)  # f1 (eq. 7)
    wts[rows, 2 * half + seg] = omega[:, 0]  # f2 (eq. 8), y
    wts[rows, 3 * half + seg] = omega[:, 1]  # f2, x
    for arr in (flat, omega, wts):
        arr.setflags(write=False)
    return _Bins(flat, omega, wts)


def segment_sums(
    patches: np.ndarray, *, segments: int = 32, lowcut: float | None = None, windowed: bool = False
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per-segment spectral sums of a batch of square patches (§2.1, eqs. 2 and 7–9).

    Parameters
    ----------
    patches : ndarray, (K, n, n) or (n, n)
        Grey patches (any real values).
    segments : int, even, >= 4, default 32
        N, the number of angular segments of the full plane (φ = 2π/N).
    lowcut : float, optional
        Bins with ``||ω|| <= lowcut`` (cycles/pixel) are removed ("the lowpass removed", §3.3);
        default ``1/n``, i.e. the DC bin and its eight neighbours.
    windowed : bool, default False
        The patches are already windowed; otherwise their mean is removed and the cos² window
        applied first ("the image patches used for centroid estimation must be windowed first").

    Returns
    -------
    M, f1, f2 : ndarrays (K, N/2), (K, N/2), (K, N/2, 2)
        The sums of eqs. 9, 7 and 8 for the segments of the half-plane ``[0, π)``; the other half
        follows by symmetry (eqs. 14–16).
    """
    _check_segments(segments)
    p = np.asarray(patches, dtype=np.float32)
    single = p.ndim == 2
    if single:
        p = p[None]
    n = p.shape[-1]
    if p.ndim != 3 or p.shape[1] != n:
        raise InvalidParameter(f"patches must be square, shape (K, n, n); got {np.shape(patches)}")
    # A flat patch has an empty spectrum; keep float32 round-off of the mean removal out of it.
    hi = p.max(axis=(1, 2))
    lo = p.min(axis=(1, 2))
    flat = (hi - lo) <= 1e-6 * (1.0 + np.maximum(np.abs(hi), np.abs(lo)))
    if not windowed:
        p = (p - p.mean(axis=(1, 2), keepdims=True, dtype=np.float64).astype(np.float32)) * cos2_window(n)
    lowcut = 1.0 / n if lowcut is None else float(lowcut)
    bins = _bins(n, segments, lowcut)
    import scipy.fft as sfft  # here, not at import: most weft processes never need it

    mag = np.abs(sfft.rfft2(p)).reshape(len(p), -1)[:, bins.flat]
    mag[flat] = 0.0
    sums = mag.astype(np.float64) @ bins.weights
    half = segments // 2
    M = sums[:, :half]
    f1 = sums[:, half : 2 * half]
    f2 = np.stack([sums[:, 2 * half : 3 * half], sums[:, 3 * half :]], axis=-1)
    if single:
        return M[0], f1[0], f2[0]
    return M, f1, f2


def _check_segments(segments: int) -> None:
    if isinstance(segments, bool) or not isinstance(segments, (int, np.integer)) or segments < 4 or segments % 2:
        raise InvalidParameter(
            f"parameter 'segments' = {segments!r} must be an even integer >= 4", name="segments", value=segments
        )


@dataclass(frozen=True)
class Centroids:
    """Centroid pairs of a batch of patches (§2.1).

    Attributes
    ----------
    mu : (K, 2, 2) float64
        ``mu[i, :, 0]`` = μ1 and ``mu[i, :, 1]`` = μ2 as (y, x) column vectors, cycles/pixel
        (the matrix C of eq. 20).
    variance : (K,) float64
        The minimum total variance of eq. 17 (``inf`` when the spectrum is empty).
    split : (K, 2) int64
        The segments (k, l) of the minimum: Λ1 = segments k..l-1, Λ2 = l..k+N/2-1.
    mass : (K,) float64
        Total spectral magnitude on the half-plane (0 for a flat patch).
    masses : (K, 2) float64
        The magnitude in Λ1 and in Λ2 (eq. 5). Eq. 17 adds the two variances without weighting
        them by mass, so for a single energy cluster (one sinusoid) the best split can be a tight,
        nearly empty run beside the whole cluster: the heavier centroid is then the cluster's.
    degenerate : (K,) bool
        No split with both runs non-empty exists (a flat patch, or all energy in one segment):
        μ1 is then the half-plane centroid and μ2 = μ1 turned by 90° (see :func:`centroid_pairs`).
    """

    mu: np.ndarray
    variance: np.ndarray
    split: np.ndarray
    mass: np.ndarray
    masses: np.ndarray
    degenerate: np.ndarray


def centroid_pairs(M: np.ndarray, f1: np.ndarray, f2: np.ndarray) -> Centroids:
    """The representative centroid pair from per-segment sums (Kruger's partial sums, eqs. 10–19).

    Parameters
    ----------
    M, f1, f2 : ndarrays (K, N/2), (K, N/2), (K, N/2, 2)
        Half-plane segment sums from :func:`segment_sums`.

    Returns
    -------
    Centroids

    Notes
    -----
    Cumulative sums over the first half-plane (eqs. 11–13) are extended to ``l <= 3N/2`` with the
    symmetry of eqs. 14–16 (the second half-plane mirrors the first: same ``f1`` and ``M``, negated
    ``f2``). Eq. 17 is evaluated for every ``0 <= k < N`` and ``k < l < k + N/2``; a run of segments
    with no energy makes that split invalid (its variance is undefined). Ambiguity resolved here:
    when no split is valid (a flat patch, or one whose energy falls in a single segment), μ1 is the
    centroid of the whole half-plane and μ2 is μ1 turned by 90°, flagged ``degenerate`` (a zero
    vector for an empty spectrum); :func:`weft.core.affine.transforms.candidate_transforms` then
    treats the pair as a similarity frame.
    """
    M = np.atleast_2d(np.asarray(M, dtype=np.float64))
    f1 = np.atleast_2d(np.asarray(f1, dtype=np.float64))
    f2 = np.asarray(f2, dtype=np.float64)
    if f2.ndim == 2:
        f2 = f2[None]
    K, half = M.shape
    N = 2 * half
    # eqs. 11-13 on the first half-plane, then eqs. 14-16 and one more period for k + N/2 > N.
    cM = np.zeros((K, 3 * half + 1))
    c1 = np.zeros((K, 3 * half + 1))
    c2 = np.zeros((K, 3 * half + 1, 2))
    cM[:, 1 : half + 1] = np.cumsum(M, axis=1)
    c1[:, 1 : half + 1] = np.cumsum(f1, axis=1)
    c2[:, 1 : half + 1] = np.cumsum(f2, axis=1)
    for l in range(half + 1, 3 * half + 1):  # noqa: E741 (the paper's segment indices k, l)
        base = l - half if l <= N else l - N
        if l <= N:  # eqs. 14-16
            cM[:, l] = cM[:, half] + cM[:, base]
            c1[:, l] = c1[:, half] + c1[:, base]
            c2[:, l] = c2[:, half] - c2[:, base]
        else:  # a full turn further: S(l) = S(N) + S(l - N), with f2 summing to zero over a turn
            cM[:, l] = cM[:, N] + cM[:, base]
            c1[:, l] = c1[:, N] + c1[:, base]
            c2[:, l] = c2[:, N] + c2[:, base]
    # k and k + N/2 give the same two runs mirrored (same variances, negated centroids): the
    # first half-plane of starting segments is enough.
    pairs = [(k, end) for k in range(half) for end in range(k + 1, k + half)]
    ks = np.array([k for k, _ in pairs])
    ls = np.array([end for _, end in pairs])
    ends = ks + half
    mass = cM[:, half]
    tiny = 1e-9 * np.maximum(mass, 1e-300)[:, None]

    def run(a, b):
        m = cM[:, b] - cM[:, a]
        s1 = c1[:, b] - c1[:, a]
        s2 = c2[:, b] - c2[:, a]
        ok = m > tiny
        safe = np.where(ok, m, 1.0)
        mu = s2 / safe[..., None]
        var = s1 / safe - (mu**2).sum(axis=-1)  # eq. 10
        return np.where(ok, var, np.inf), mu, m

    v1, mu1, m1 = run(ks, ls)
    v2, mu2, m2 = run(ls, ends)
    total = v1 + v2  # eq. 17
    best = np.argmin(total, axis=1)
    rows = np.arange(K)
    variance = total[rows, best]
    degenerate = ~np.isfinite(variance)
    mu = np.stack([mu1[rows, best], mu2[rows, best]], axis=-1)  # eqs. 18-19, columns
    if degenerate.any():
        d = np.flatnonzero(degenerate)
        whole = np.where(mass[d, None] > 0, c2[d, half] / np.where(mass[d] > 0, mass[d], 1.0)[:, None], 0.0)
        mu[d, :, 0] = whole
        mu[d, :, 1] = np.stack([-whole[:, 1], whole[:, 0]], axis=1)
    split = np.stack([ks[best] % N, ls[best] % N], axis=1)
    masses = np.stack([m1[rows, best], m2[rows, best]], axis=1)
    return Centroids(mu=mu, variance=variance, split=split, mass=mass, masses=masses, degenerate=degenerate)


def centroids(patches: np.ndarray, *, segments: int = 32, lowcut: float | None = None) -> Centroids:
    """Representative centroid pairs of square grey patches (§2.1, eqs. 2–19).

    Parameters
    ----------
    patches : ndarray, (K, n, n) or (n, n)
        Grey patches; each is mean-removed and cos²-windowed first.
    segments : int, even, >= 4, default 32
        N, angular segments of the full plane.
    lowcut : float, optional
        Lowpass radius removed from the spectrum, cycles/pixel (default ``1/n``).

    Returns
    -------
    Centroids
        ``mu[i]`` is the 2x2 matrix ``(μ1 μ2)`` of column vectors (y, x) in cycles/pixel.

    Examples
    --------
    >>> import numpy as np
    >>> y, x = np.mgrid[:64, :64]
    >>> grid = np.cos(2 * np.pi * 0.125 * x) + np.cos(2 * np.pi * 0.25 * y)  # two gratings
    >>> mu = centroids(grid).mu[0]  # columns μ1, μ2 as (y, x), cycles/pixel
    >>> sorted((round(abs(float(mu[0, i])), 2), round(abs(float(mu[1, i])), 2)) for i in range(2))
    [(0.0, 0.13), (0.25, 0.0)]
    """
    M, f1, f2 = segment_sums(patches, segments=segments, lowcut=lowcut)
    return centroid_pairs(M, f1, f2)
