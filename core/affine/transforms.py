"""Linear transforms, translations and the best affine transform of a prototype (§2.2–2.4).

Conventions (``(y, x)`` vectors, pixels):

* ``A`` maps prototype frequencies to target frequencies, ``μ_t = A μ_p`` (eq. 20).
* ``T = (Aᵀ)⁻¹`` (eq. 22) maps prototype coordinates to target coordinates: if the target patch
  is the prototype deformed by ``T`` about the patches' centres, then ``s_t(T x) = s_p(x)``.
* Warping samples the prototype through the inverse, the *sampling matrix* ``Aᵀ = T⁻¹`` ("the actual
  transformation is carried out using an inverse transformation to map coordinates in the target
  image to real number coordinates in the prototype image", §2), bilinearly.
* A translation ``t`` (target pixels, ``|t_y|, |t_x| <= B/4``) moves the warped prototype:
  ``s_p'(y) = s_p(c_p + Aᵀ (y - t))`` for ``y`` relative to the target patch's centre; the paper's
  offset ``d`` of eq. 1 is ``-Aᵀ t``.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

# Singular values of a candidate T are kept in this range: a stretch by more than 4 is never a
# plausible deformation of a texture patch and a near-singular pair would otherwise give inf.
MIN_SCALE = 0.25
MAX_SCALE = 4.0
# A centroid pair whose vectors are closer than this to parallel (|sin| of the angle between
# them) is "near-singular" (§2.2): it is replaced by a similarity frame.
MIN_SINE = 0.05

# The eight centroid pairings of eq. 21 and their negations: (which centroid first, sign of the
# first, sign of the second).
PAIRINGS = (
    (0, 1, 1),
    (1, 1, 1),
    (0, 1, -1),
    (1, 1, -1),
    (0, -1, -1),
    (1, -1, -1),
    (0, -1, 1),
    (1, -1, 1),
)


def regularise_pairs(mu: np.ndarray) -> np.ndarray:
    """Centroid pairs safe to invert: near-singular pairs become similarity frames.

    Parameters
    ----------
    mu : ndarray (..., 2, 2)
        Column pairs ``(μ1 μ2)``.

    Returns
    -------
    ndarray (..., 2, 2), float64
        ``mu`` where ``|sin(μ1, μ2)| >= 0.05``; otherwise ``(μ1, R90 μ1)`` (μ1 the longer vector,
        the pair's common direction kept, the orthogonal direction given the same frequency), and
        for an empty spectrum (both vectors ~0) the frame ``(e_y, e_x) / 8`` so that a flat patch
        maps to a flat patch by the identity. This is the choice made for the "degenerate
        (near-singular) centroid pairs" of §2.2, which the paper leaves open.
    """
    mu = np.array(mu, dtype=np.float64, copy=True)
    a = mu[..., :, 0]
    b = mu[..., :, 1]
    na = np.hypot(a[..., 0], a[..., 1])
    nb = np.hypot(b[..., 0], b[..., 1])
    det = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    sine = np.abs(det) / np.maximum(na * nb, 1e-300)
    bad = sine < MIN_SINE
    longer = np.where((na >= nb)[..., None], a, b)
    nl = np.maximum(na, nb)
    empty = nl < 1e-9
    turned = np.stack([-longer[..., 1], longer[..., 0]], axis=-1)
    fix_a = np.where(empty[..., None], np.array([0.125, 0.0]), longer)
    fix_b = np.where(empty[..., None], np.array([0.0, 0.125]), turned)
    mu[..., :, 0] = np.where(bad[..., None], fix_a, a)
    mu[..., :, 1] = np.where(bad[..., None], fix_b, b)
    return mu


def singular_values(T: np.ndarray) -> np.ndarray:
    """Singular values of a stack of 2x2 matrices in closed form.

    Parameters
    ----------
    T : ndarray (..., 2, 2)

    Returns
    -------
    ndarray (..., 2)
        Largest first: ``(|q| + |r|) / 2`` and ``||q| - |r|| / 2`` with ``q = (a + d, c - b)``
        and ``r = (a - d, c + b)`` (the rotation and reflection parts of ``[[a, b], [c, d]]``).
    """
    a, b, c, d = T[..., 0, 0], T[..., 0, 1], T[..., 1, 0], T[..., 1, 1]
    s1 = np.hypot(a + d, c - b)
    s2 = np.hypot(a - d, c + b)
    return np.stack([(s1 + s2) / 2, np.abs(s1 - s2) / 2], axis=-1)


def _clamp_scale(T: np.ndarray) -> np.ndarray:
    """T with its singular values clamped to [MIN_SCALE, MAX_SCALE] (SVD only where needed)."""
    sv = singular_values(T)
    bad = (sv[..., 0] > MAX_SCALE) | (sv[..., 1] < MIN_SCALE)
    if bad.any():
        T = T.copy()
        u, s, vt = np.linalg.svd(T[bad])
        s = np.clip(s, MIN_SCALE, MAX_SCALE)
        T[bad] = (u * s[..., None, :]) @ vt
    return T


def candidate_transforms(mu_p: np.ndarray, mu_t: np.ndarray) -> np.ndarray:
    """The eight linear transforms A₁…A₈ between a prototype and target patches, as spatial T_j (§2.2).

    Parameters
    ----------
    mu_p : ndarray (2, 2)
        The prototype's centroid pair ``(μ1 μ2)`` (columns, (y, x), cycles/pixel).
    mu_t : ndarray (K, 2, 2) or (2, 2)
        The target patches' centroid pairs.

    Returns
    -------
    ndarray (K, 8, 2, 2) (or (8, 2, 2)), float64
        ``T_j = (A_jᵀ)⁻¹`` (eq. 22) with ``A_j = C_t C_p,j⁻¹`` (eq. 20) for the four pairings
        ``(μ1 μ2), (μ2 μ1), (μ1 -μ2), (μ2 -μ1)`` of eq. 21 and their negations (candidates 4–7 are
        candidates 0–3 turned by 180°). Near-singular pairs are made invertible by
        :func:`regularise_pairs`, and singular values of T are clamped to [1/4, 4]: never NaN or inf.
    """
    mu_t = np.asarray(mu_t, dtype=np.float64)
    single = mu_t.ndim == 2
    ct = regularise_pairs(mu_t.reshape(-1, 2, 2))
    cp = regularise_pairs(np.asarray(mu_p, dtype=np.float64))
    cps = np.stack(
        [np.stack([s1 * cp[:, first], s2 * cp[:, 1 - first]], axis=1) for first, s1, s2 in PAIRINGS]
    )  # (8, 2, 2)
    # A_j = C_t C_pj^-1 and T_j = (A_j^T)^-1 = (C_pj^-T C_t^T)^-1 = C_t^-T C_pj^T
    ct_inv_t = np.linalg.inv(ct).transpose(0, 2, 1)  # (K, 2, 2)
    T = ct_inv_t[:, None] @ cps.transpose(0, 2, 1)[None]  # (K, 8, 2, 2)
    T = _clamp_scale(T)
    return T[0] if single else T


def sampling_matrices(T: np.ndarray) -> np.ndarray:
    """The sampling matrices ``T⁻¹ = Aᵀ`` of spatial transforms (§2, eq. 22).

    Parameters
    ----------
    T : ndarray (..., 2, 2)
        Prototype -> target transforms (non-singular; :func:`candidate_transforms` guarantees it).

    Returns
    -------
    ndarray (..., 2, 2) float64
        Offsets in a target patch -> offsets in the prototype: what warping samples through.
    """
    return np.linalg.inv(np.asarray(T, dtype=np.float64))


@lru_cache(maxsize=16)
def _pruned_inverse(L: int, radius: int) -> tuple[np.ndarray, np.ndarray]:
    """Matrices of the inverse real 2-D DFT restricted to shifts ``-radius..radius`` (rows in
    the order 0..R, -R..-1): ``rho = Ey @ X @ Ex.T`` for an rfft2 spectrum X (L, L//2 + 1)."""
    vals = np.r_[0 : radius + 1, -radius:0]
    ky = np.fft.fftfreq(L) * L
    ey = np.exp(2j * np.pi * np.outer(vals, ky) / L) / L
    kx = np.arange(L // 2 + 1)
    wx = np.full(L // 2 + 1, 2.0)
    wx[0] = 1.0
    if L % 2 == 0:
        wx[-1] = 1.0
    ex = wx[None, :] * np.exp(2j * np.pi * np.outer(vals, kx) / L) / L
    return ey.astype(np.complex64), np.ascontiguousarray(ex.T.astype(np.complex64))


@lru_cache(maxsize=16)
def _turn_phase(L: int) -> np.ndarray:
    """``phase`` with rfft2(x[::-1, ::-1]) = phase * conj(rfft2(x)) for real x (L x L)."""
    ky = np.fft.fftfreq(L) * L
    kx = np.arange(L // 2 + 1)
    return np.exp(2j * np.pi * (ky[:, None] + kx[None, :]) / L).astype(np.complex64)


def correlate_shifts(
    frames: np.ndarray, targets: np.ndarray, radius: int, *, turned: bool = False
) -> tuple[np.ndarray, np.ndarray]:
    """Translation of each warped prototype that best fits its target patch (§2.3, eq. 23).

    Parameters
    ----------
    frames : ndarray (n, J, L, L) float32
        Unwindowed warped prototypes on frames of side ``L = B + 2 radius`` around each patch.
    targets : ndarray (n, B, B) float32
        The target patches as they are to be matched (the caller windows them).
    radius : int
        Largest shift per axis, ``B/4`` in the paper ("only translations within a quarter block").
    turned : bool, default False
        Also evaluate every frame turned by 180° (the negated candidates of eq. 21): the result
        then has 2J candidates, the turned ones last. Their spectra are the frames' conjugates
        times a phase, so no extra FFT is needed.

    Returns
    -------
    shifts : ndarray (n, J or 2J, 2) int64
        ``t = (ty, tx)`` maximising ``ρ(t) = Σ_y s_t(y) s_p'(y - t)``: the peak of
        ``F⁻¹(ŝ_p' ŝ_t*)`` (eq. 23) restricted to ``|t_y|, |t_x| <= radius``.
    peak : ndarray (n, J or 2J) float32
        ``ρ`` at the chosen shift.

    Notes
    -----
    The target is zero-padded to the frame, so for shifts within the radius the FFT's circular
    correlation equals the linear one (no wrap-around); only the ``(2 radius + 1)²`` shifts
    wanted are transformed back (a pruned inverse DFT as two matrix products).
    """
    n, J, L, _ = frames.shape
    index = np.arange(n * J).reshape(n, J)
    flip = np.zeros((n, J), bool)
    if turned:
        index = np.concatenate([index, index], axis=1)
        flip = np.concatenate([flip, ~flip], axis=1)
    return correlate_indexed(frames.reshape(n * J, L, L), index, flip, targets, radius)


def correlate_indexed(
    frames: np.ndarray, index: np.ndarray, flip: np.ndarray, targets: np.ndarray, radius: int
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`correlate_shifts` for candidates that share frames (§2.3, eq. 23).

    Parameters
    ----------
    frames : ndarray (F, L, L) float32
        Warped prototypes (a frame depends on its matrix only, not on the patch).
    index : int ndarray (n, J)
        Candidate j of patch i is frame ``index[i, j]`` ...
    flip : bool ndarray (n, J)
        ... turned by 180° where ``flip[i, j]``.
    targets : ndarray (n, B, B) float32
        The (windowed) target patches.
    radius : int
        Largest shift per axis (B/4).

    Returns
    -------
    shifts, peak
        As :func:`correlate_shifts`. Each frame is Fourier-transformed once however many patches
        use it.
    """
    F_count, L, _ = frames.shape
    n, J = index.shape
    B = targets.shape[-1]
    R = radius
    g = np.zeros((n, L, L), np.float32)
    g[:, R : R + B, R : R + B] = targets
    import scipy.fft as sfft  # here, not at import: most weft processes never need it

    G = sfft.rfft2(g)[:, None]
    F = sfft.rfft2(frames)
    # rho[u] = sum g[v] f[v - u]: spectrum G conj(F); a turned frame has spectrum phase conj(F),
    # so its correlation has spectrum G F conj(phase)
    h = J // 2
    if (
        J % 2 == 0
        and F_count == n * h
        and np.array_equal(index[:, :h].ravel(), np.arange(n * h))
        and np.array_equal(index[:, h:], index[:, :h])
        and not flip[:, :h].any()
        and flip[:, h:].all()
    ):
        Fr = F.reshape(n, h, L, -1)  # own frames, then the same turned: no gathering needed
        spec = np.concatenate([G * np.conj(Fr), G * (Fr * np.conj(_turn_phase(L)))], axis=1)
    else:
        sel = np.conj(F)[index]  # (n, J, L, L//2+1)
        if flip.any():
            sel[flip] = F[index[flip]] * np.conj(_turn_phase(L))
        spec = G * sel
    ey, ext = _pruned_inverse(L, R)
    rho = (ey @ spec @ ext).real  # (n, J, 2R+1, 2R+1)
    win = rho.reshape(n, J, -1)
    best = np.argmax(win, axis=-1)
    side = 2 * R + 1
    vals = np.r_[0 : R + 1, -R:0]
    shifts = np.stack([vals[best // side], vals[best % side]], axis=-1).astype(np.int64)
    peak = np.take_along_axis(win, best[..., None], axis=-1)[..., 0].astype(np.float32)
    return shifts, peak
