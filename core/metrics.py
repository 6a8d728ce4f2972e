"""Quality figures every method reports: coherence, completeness, fidelity and SNR.

* :func:`coherence` -- does every patch of the output look like some patch of the source?
  (low is good; 0 means the output is made only of source patches).
* :func:`completeness` -- is every patch of the source represented somewhere in the output?
  (low is good; a tiny crop of the source is coherent but not complete).
* :func:`fidelity` -- does the output follow the target's large-scale luminance (texture transfer)?
  (Pearson correlation of blurred luminances, 1 is perfect).
* :func:`snr_db` -- signal-to-noise ratio of a reconstruction against its original, in decibels.
* :func:`fill_coherence`, :func:`fill_detail`, :func:`fill_seam` -- how a filled hole (or an uncropped
  border) reads against the known rest of its image: does it look like its surroundings, is it as
  detailed (not smeared), is its edge invisible.
* :func:`verbatim_fraction` -- the largest region of an output copied verbatim from its sample
  (connected pixels sharing one source offset, from the method's record of where each pixel came
  from), as a fraction of the sample's area (low is good: a large region is a visible strip).

Coherence and completeness are the two halves of the bidirectional similarity of Simakov et al.
(CVPR 2008), measured on 7x7 luminance patches with exact nearest neighbours. The search is a
chunked float32 BLAS product (``|a|^2 + |b|^2 - 2 a.b``) that picks the neighbour, followed by an
exact float64 recomputation of the chosen neighbour's distance, so a perfect match scores ~0.

Images are float32 in [0, 1], shape (H, W) or (H, W, 3); colour images are reduced to Rec. 601
luminance for the patch and fidelity measures.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from .errors import ImageError, InvalidParameter
from .image import luminance, validate_image

__all__ = [
    "coherence",
    "completeness",
    "fidelity",
    "fill_coherence",
    "fill_detail",
    "fill_seam",
    "psnr_db",
    "snr_db",
    "verbatim_fraction",
    "verbatim_region",
]

MIN_SIDE = 7
# Upper bound on the float32 distance block held at once by the nearest-neighbour search (small
# enough that the add/argmin passes stay close to the cache).
_BLOCK_BYTES = 16 * 1024 * 1024


# --------------------------------------------------------------------------------------------
# validation


def _check_image(image, what: str, min_side: int = MIN_SIDE) -> np.ndarray:
    """``image`` as float32 in [0, 1] (uint8/uint16 are rescaled) after checking its shape and size."""
    arr = validate_image(image, what)
    h, w = arr.shape[:2]
    if h < min_side or w < min_side:
        raise ImageError(f"{what} is {w}x{h}; it must be at least {min_side}x{min_side} pixels")
    return arr


def _check_int(name: str, value, lo: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise InvalidParameter(f"parameter '{name}' = {value!r} must be an integer", name=name, value=value)
    if value < lo:
        raise InvalidParameter(f"parameter '{name}' = {value} is outside {lo}..inf", name=name, value=value)
    return int(value)


# --------------------------------------------------------------------------------------------
# patches and exact nearest neighbours


def _patches(lum: np.ndarray, patch: int, stride: int) -> np.ndarray:
    """All ``patch`` x ``patch`` windows of ``lum`` on a ``stride`` grid, as float32 rows (N, patch²)."""
    windows = sliding_window_view(lum, (patch, patch))[::stride, ::stride]
    return np.ascontiguousarray(windows, dtype=np.float32).reshape(-1, patch * patch)


def _nearest_distances(queries: np.ndarray, database: np.ndarray, *, block_bytes: int = _BLOCK_BYTES) -> np.ndarray:
    """Euclidean distance from every query row to its nearest database row.

    Parameters
    ----------
    queries : ndarray, shape (N, D)
    database : ndarray, shape (M, D), M >= 1
    block_bytes : int
        Memory bound for the float32 distance block computed at once.

    Returns
    -------
    ndarray of float64, shape (N,)
        ``min_j ||queries[i] - database[j]||``. The neighbour is chosen with float32 BLAS
        (``|b|^2 - 2 a.b``, on data centred on the database mean to limit cancellation); its
        distance is then recomputed exactly in float64, so identical rows give exactly 0.
    """
    queries = np.asarray(queries)
    database = np.asarray(database)
    n, m = len(queries), len(database)
    if n == 0:
        return np.zeros(0, dtype=np.float64)
    centre = database.mean(axis=0, dtype=np.float64).astype(np.float32)
    q32 = np.subtract(queries, centre, dtype=np.float32)
    d32 = np.subtract(database, centre, dtype=np.float32)
    dnorm = np.einsum("ij,ij->i", d32, d32, dtype=np.float32)

    elems = max(1, block_bytes // 4)
    rows = int(min(n, max(64, elems // m)))
    cols = int(min(m, max(1, elems // rows)))
    buffer = np.empty(rows * cols, dtype=np.float32)
    best = np.empty(n, dtype=np.intp)

    for r0 in range(0, n, rows):
        qc = q32[r0 : r0 + rows]
        r = len(qc)
        best_val = np.full(r, np.inf, dtype=np.float32)
        best_idx = np.zeros(r, dtype=np.intp)
        for c0 in range(0, m, cols):
            dc = d32[c0 : c0 + cols]
            c = len(dc)
            block = buffer[: r * c].reshape(r, c)
            np.matmul(qc, dc.T, out=block)
            block *= -2.0
            block += dnorm[c0 : c0 + c]
            idx = np.argmin(block, axis=1)
            val = block[np.arange(r), idx]
            better = val < best_val
            best_val[better] = val[better]
            best_idx[better] = idx[better] + c0
        best[r0 : r0 + r] = best_idx

    out = np.empty(n, dtype=np.float64)
    step = 65536
    for r0 in range(0, n, step):
        diff = queries[r0 : r0 + step].astype(np.float64) - database[best[r0 : r0 + step]].astype(np.float64)
        out[r0 : r0 + step] = np.sqrt(np.einsum("ij,ij->i", diff, diff))
    return out


def _patch_score(queries_img, database_img, patch, stride, q_what, d_what) -> float:
    patch = _check_int("patch", patch, 1)
    stride = _check_int("stride", stride, 1)
    min_side = max(MIN_SIDE, patch)
    q = luminance(_check_image(queries_img, q_what, min_side).astype(np.float32, copy=False))
    d = luminance(_check_image(database_img, d_what, min_side).astype(np.float32, copy=False))
    dist = _nearest_distances(_patches(q, patch, stride), _patches(d, patch, 1))
    return float(dist.mean())


# --------------------------------------------------------------------------------------------
# public figures


def coherence(out, source, *, patch: int = 7, stride: int = 2) -> float:
    """Mean distance from the output's patches to their nearest source patch (lower is better).

    Every ``patch`` x ``patch`` luminance window of ``out`` on a ``stride`` grid (all valid
    positions) is matched to its exact nearest window of ``source`` among all positions
    (stride 1). The distance is Euclidean over the window's pixels, intensities in [0, 1]: the
    square root of the sum of squared differences (for 7x7 windows it lies in 0..7). This is the
    "coherence" half of Simakov et al.'s bidirectional similarity: an output assembled only from
    verbatim source patches scores ~0; blur, seams and invented structure raise it.

    Parameters
    ----------
    out : ndarray, float32 in [0, 1], shape (H, W) or (H, W, 3)
        The synthesized image; colour is reduced to Rec. 601 luminance.
    source : ndarray, float32 in [0, 1], shape (H', W') or (H', W', 3)
        The example texture.
    patch : int, default 7
        Window side in pixels, >= 1.
    stride : int, default 2
        Step between the windows of ``out``, >= 1.

    Returns
    -------
    float
        Mean nearest-neighbour distance, >= 0.

    Raises
    ------
    ImageError
        If an image is not (H, W) or (H, W, 3), or is smaller than max(7, patch) on a side.
    InvalidParameter
        If ``patch`` or ``stride`` is not an integer >= 1.
    """
    return _patch_score(out, source, patch, stride, "output image", "source image")


def completeness(out, source, *, patch: int = 7, stride: int = 2) -> float:
    """Mean distance from the source's patches to their nearest output patch (lower is better).

    The roles of :func:`coherence` swapped: every ``patch`` x ``patch`` luminance window of
    ``source`` on a ``stride`` grid is matched to its exact nearest window of ``out`` among all
    positions. An output that omits part of the source's appearance (e.g. a small crop of it)
    scores high even when it is perfectly coherent.

    Parameters
    ----------
    out : ndarray, float32 in [0, 1], shape (H, W) or (H, W, 3)
        The synthesized image; colour is reduced to Rec. 601 luminance.
    source : ndarray, float32 in [0, 1], shape (H', W') or (H', W', 3)
        The example texture.
    patch : int, default 7
        Window side in pixels, >= 1.
    stride : int, default 2
        Step between the windows of ``source``, >= 1.

    Returns
    -------
    float
        Mean nearest-neighbour distance, >= 0 (0..7 for 7x7 windows).

    Raises
    ------
    ImageError
        If an image is not (H, W) or (H, W, 3), or is smaller than max(7, patch) on a side.
    InvalidParameter
        If ``patch`` or ``stride`` is not an integer >= 1.
    """
    return _patch_score(source, out, patch, stride, "source image", "output image")


def fidelity(out, target, *, sigma: float = 3.0) -> float:
    """How well the output follows the target's large-scale luminance (texture transfer).

    Pearson correlation between the Rec. 601 luminances of ``out`` and ``target`` after a
    Gaussian blur of standard deviation ``sigma`` (OpenCV, reflected borders), which keeps the
    shading the transfer should reproduce and discards the texture's own detail.

    Parameters
    ----------
    out : ndarray, float32 in [0, 1], shape (H, W) or (H, W, 3)
    target : ndarray, float32 in [0, 1], shape (H, W) or (H, W, 3)
        Same height and width as ``out``; grey and colour may be mixed since only luminance is
        compared.
    sigma : float, default 3.0
        Blur in pixels, >= 0 (0 compares the unblurred luminances).

    Returns
    -------
    float
        Correlation in [-1, 1]: 1 for identical luminance, -1 for inverted. If either blurred
        luminance is constant (zero variance) the correlation is undefined and 0.0 is returned
        rather than NaN.

    Raises
    ------
    ImageError
        If an image is not (H, W) or (H, W, 3), is smaller than 7x7, or the sizes differ.
    InvalidParameter
        If ``sigma`` is not a finite number >= 0.
    """
    import cv2

    out = _check_image(out, "output image")
    target = _check_image(target, "target image")
    if out.shape[:2] != target.shape[:2]:
        raise ImageError(
            f"output image is {out.shape[1]}x{out.shape[0]} but target image is "
            f"{target.shape[1]}x{target.shape[0]}; they must be the same size"
        )
    if isinstance(sigma, bool) or not isinstance(sigma, (int, float, np.integer, np.floating)):
        raise InvalidParameter(f"parameter 'sigma' = {sigma!r} must be a number", name="sigma", value=sigma)
    if not (math.isfinite(sigma) and sigma >= 0):
        raise InvalidParameter(f"parameter 'sigma' = {sigma} is outside 0..inf", name="sigma", value=sigma)

    def blurred(img):
        lum = luminance(img.astype(np.float32, copy=False))
        if sigma > 0:
            lum = cv2.GaussianBlur(lum, (0, 0), sigmaX=float(sigma), sigmaY=float(sigma))
        lum = lum.astype(np.float64)
        return lum - lum.mean()

    a, b = blurred(out), blurred(target)
    var_a, var_b = float(np.mean(a * a)), float(np.mean(b * b))
    # A standard deviation below 1e-6 (intensities in [0, 1]) is float32 rounding, not signal.
    if var_a < 1e-12 or var_b < 1e-12:
        return 0.0
    r = float(np.mean(a * b)) / math.sqrt(var_a * var_b)
    return float(min(1.0, max(-1.0, r)))


def snr_db(orig, synth) -> float:
    """Signal-to-noise ratio of ``synth`` against ``orig`` in decibels.

    ``10 log10(var(orig) / mean((orig - synth)^2))`` over all pixels and channels as given
    (no luminance conversion), computed in float64.

    Parameters
    ----------
    orig : ndarray, float32 in [0, 1], shape (H, W) or (H, W, 3)
        The reference image.
    synth : ndarray, same shape as ``orig``
        The reconstruction.

    Returns
    -------
    float
        The SNR in dB. ``inf`` when the arrays are identical (also when ``orig`` is constant);
        ``-inf`` when ``orig`` is constant (zero variance) and ``synth`` differs from it. No
        floating-point warnings are emitted in either case.

    Raises
    ------
    ImageError
        If an array is not (H, W) or (H, W, 3), is smaller than 7x7, or the shapes differ.
    """
    orig = _check_image(orig, "original image")
    synth = _check_image(synth, "synthesized image")
    if orig.shape != synth.shape:
        raise ImageError(f"original image has shape {orig.shape} but synthesized image has {synth.shape}")
    o = orig.astype(np.float64)
    s = synth.astype(np.float64)
    mse = float(np.mean((o - s) ** 2))
    var = float(np.var(o))
    if mse == 0.0:
        return math.inf
    if var == 0.0:
        return -math.inf
    return 10.0 * math.log10(var / mse)


def psnr_db(orig, synth) -> float:
    """Peak signal-to-noise ratio of ``synth`` against ``orig`` in decibels, peak 1.

    ``10 log10(1 / mean((orig - synth)^2))`` over all pixels and channels, float64.

    Parameters
    ----------
    orig, synth : array_like, (H, W) or (H, W, 3), at least 7x7
        The reference and the result, in [0, 1], the same shape.

    Returns
    -------
    float
        The PSNR in dB; ``inf`` when the arrays are identical.

    Raises
    ------
    ImageError
        As :func:`snr_db`.
    """
    orig = _check_image(orig, "original image")
    synth = _check_image(synth, "synthesized image")
    if orig.shape != synth.shape:
        raise ImageError(f"original image has shape {orig.shape} but synthesized image has {synth.shape}")
    mse = float(np.mean((orig.astype(np.float64) - synth.astype(np.float64)) ** 2))
    return math.inf if mse == 0.0 else -10.0 * math.log10(mse)


def verbatim_region(sources) -> int:
    """Pixels of the largest region of an output copied verbatim from its sample.

    A verbatim region is a 4-connected set of copied pixels sharing one offset ``(sy - y, sx - x)``:
    a piece of the sample pasted as it is, whatever the blocks it was pasted in.

    Parameters
    ----------
    sources : ndarray, integer (H, W, 2)
        For every output pixel (y, x), the sample pixel (sy, sx) it was copied from, or a negative
        value where the pixel is not a copy (not made yet, blended).

    Returns
    -------
    int
        The region's pixel count (0 when nothing is a copy).

    Raises
    ------
    ImageError
        If ``sources`` is not an (H, W, 2) integer array.
    """
    import cv2

    src = np.asarray(sources)
    if src.ndim != 3 or src.shape[2] != 2 or not np.issubdtype(src.dtype, np.integer):
        raise ImageError(f"source map has shape {src.shape} and type {src.dtype}; it must be (H, W, 2) integers")
    h, w = src.shape[:2]
    if h == 0 or w == 0:
        return 0
    valid = (src[..., 0] >= 0) & (src[..., 1] >= 0)
    if not valid.any():
        return 0
    yy, xx = np.mgrid[0:h, 0:w]
    dy = src[..., 0].astype(np.int64) - yy
    dx = src[..., 1].astype(np.int64) - xx
    # The graph drawn at twice the resolution: pixel (y, x) at (2y, 2x), the edge to its right
    # neighbour at (2y, 2x + 1), to the one below at (2y + 1, 2x); an edge pixel is set where both
    # neighbours are copies with the same offset. The 4-connected components of that image are the
    # graph's (a node meets another only through an edge pixel), found by cv2 (importing
    # scipy.sparse's csgraph would slow every quilting process's start).
    grid = np.zeros((2 * h - 1, 2 * w - 1), dtype=np.uint8)
    grid[::2, ::2] = valid
    grid[::2, 1::2] = valid[:, :-1] & valid[:, 1:] & (dy[:, :-1] == dy[:, 1:]) & (dx[:, :-1] == dx[:, 1:])
    grid[1::2, ::2] = valid[:-1] & valid[1:] & (dy[:-1] == dy[1:]) & (dx[:-1] == dx[1:])
    _, labels = cv2.connectedComponents(grid, connectivity=4, ltype=cv2.CV_32S)
    counts = np.bincount(labels[::2, ::2][valid])
    return int(counts.max())


def verbatim_fraction(sources, sample_shape) -> float:
    """The largest verbatim region of an output (:func:`verbatim_region`) as a fraction of the sample.

    Quilting copies blocks, so every output has verbatim regions of about a block; a fraction near
    the block's share of the sample is the floor. When a method keeps choosing the continuation of
    its neighbour's source position, one region grows across blocks into a strip of the sample
    (1.0: as large as the whole sample). Lower is better.

    Parameters
    ----------
    sources : ndarray, integer (H, W, 2)
        As in :func:`verbatim_region`.
    sample_shape : tuple of int
        The sample's shape (H, W[, C]).

    Returns
    -------
    float
        The region's pixels over ``sample_shape[0] * sample_shape[1]``.

    Raises
    ------
    ImageError
        If ``sources`` is not an (H, W, 2) integer array or ``sample_shape`` has no area.
    """
    sh, sw = int(sample_shape[0]), int(sample_shape[1])
    if sh <= 0 or sw <= 0:
        raise ImageError(f"sample shape {tuple(sample_shape)} has no area")
    return verbatim_region(sources) / float(sh * sw)


# --------------------------------------------------------------------------------------------
# fill figures (a hole, or the new border of an uncrop, against the known rest of the image)


def _check_hole(hole, shape, what: str = "hole mask") -> np.ndarray:
    arr = np.asarray(hole)
    if arr.ndim != 2 or arr.shape != tuple(shape[:2]):
        raise ImageError(f"{what} has shape {arr.shape}; it must be the image's (H, W) = {tuple(shape[:2])}")
    return arr.astype(bool, copy=False)


def _gradient_magnitude(image: np.ndarray) -> np.ndarray:
    lum = luminance(image).astype(np.float64)
    gy, gx = np.gradient(lum)
    return np.hypot(gx, gy)


def fill_coherence(out, hole, reference=None, *, patch: int = 7, stride: int = 2, db_stride: int = 1) -> float:
    """How much a filled region looks like the known rest of its image (lower is better).

    The mean, over the ``patch`` x ``patch`` luminance windows of ``out`` that touch the hole (their
    top-left corners on a ``stride`` grid), of the distance to the nearest window lying wholly in the
    known region of ``reference``. The distance is the RMS difference per pixel in 8-bit levels
    (0..255): a fill made only of known patches scores about 0; blur between structures, seams and
    invented colours raise it. Diffusion fills score deceptively well on it: read it with
    :func:`fill_detail`.

    Parameters
    ----------
    out : array_like, (H, W) or (H, W, 3)
        The filled image.
    hole : array_like, bool (H, W)
        True where the image was filled.
    reference : array_like, optional
        The image the known windows come from (default ``out``; pass the input image so that a fill
        which changes known pixels is judged against what was there).
    patch : int, default 7
        The window side.
    stride : int, default 2
        The grid of the windows touching the hole.
    db_stride : int, default 1
        Thins the known windows (1 = all; 2 is quicker and slightly pessimistic).

    Returns
    -------
    float

    Raises
    ------
    ImageError
        The shapes disagree, the known region holds no whole window, or the hole is empty.
    InvalidParameter
        A bad ``patch`` or ``stride``.

    References
    ----------
    Simakov et al., "Summarizing visual data using bidirectional similarity" (CVPR 2008): the
    coherence half, restricted to the hole's windows against the known region.
    """
    patch = _check_int("patch", patch, 1)
    stride = _check_int("stride", stride, 1)
    db_stride = _check_int("db_stride", db_stride, 1)
    img = _check_image(out, "output image", max(MIN_SIDE, patch))
    ref = img if reference is None else _check_image(reference, "reference image", max(MIN_SIDE, patch))
    if ref.shape[:2] != img.shape[:2]:
        raise ImageError(
            f"reference image is {ref.shape[1]}x{ref.shape[0]} but the output is {img.shape[1]}x{img.shape[0]}"
        )
    mask = _check_hole(hole, img.shape)
    if not mask.any():
        raise ImageError("hole mask is empty: there is no filled region to judge")
    touches = sliding_window_view(mask, (patch, patch)).any(axis=(-1, -2))
    known = ~touches  # a window that does not touch the hole lies wholly in the known region
    q_pos = np.zeros_like(touches)
    q_pos[::stride, ::stride] = True
    d_pos = np.zeros_like(known)
    d_pos[::db_stride, ::db_stride] = True
    q_sel = (touches & q_pos).ravel()
    d_sel = (known & d_pos).ravel()
    if not d_sel.any():
        raise ImageError(f"the known region holds no whole {patch}x{patch} window to compare the fill with")
    q = _patches(luminance(img), patch, 1)[q_sel]
    d = _patches(luminance(ref), patch, 1)[d_sel]
    dist = _nearest_distances(q, d)  # Euclidean over patch² values in [0, 1]
    return float(dist.mean() / patch * 255.0)


def _known_gradient(grad: np.ndarray, mask: np.ndarray, margin: int) -> float:
    from scipy.ndimage import binary_dilation

    far = ~binary_dilation(mask, iterations=margin) if margin > 0 else ~mask
    if not far.any():
        far = ~mask
    if not far.any():
        raise ImageError("hole mask covers the whole image: there is no known region to compare with")
    value = float(grad[far].mean())
    return value


def fill_detail(out, hole) -> float:
    """How detailed a fill is against its surroundings.

    The mean gradient magnitude (of luminance, central differences) inside the hole, beyond 2 px from
    its edge, divided by that of the known region beyond 2 px from the hole. About the ground truth's
    value is right; much lower is a smeared fill, much higher is noise. A hole thinner than 5 px is
    measured whole.

    Parameters
    ----------
    out : array_like, (H, W) or (H, W, 3)
        The filled image.
    hole : array_like, bool (H, W)
        True where the image was filled.

    Returns
    -------
    float
        0 when the known region is flat and the fill is too; ``inf`` when only the known region is flat.

    Raises
    ------
    ImageError
        The shapes disagree or the hole is empty.
    """
    from scipy.ndimage import binary_erosion

    img = _check_image(out, "output image", 1)
    mask = _check_hole(hole, img.shape)
    if not mask.any():
        raise ImageError("hole mask is empty: there is no filled region to judge")
    grad = _gradient_magnitude(img)
    inner = binary_erosion(mask, iterations=2, border_value=1)
    if not inner.any():
        inner = mask
    known = _known_gradient(grad, mask, 2)
    fill = float(grad[inner].mean())
    if known == 0.0:
        return 0.0 if fill == 0.0 else math.inf
    return fill / known


def fill_seam(out, hole) -> float:
    """How visible a fill's edge is.

    The mean gradient magnitude on the 2-px ring around the hole's edge (the pixels within 1 px of it
    on either side) divided by that of the known region beyond 2 px from the hole. About the ground
    truth's value is right; above it is a visible edge. The image's own border is not an edge of the
    hole (an uncrop's ring lies where new meets old).

    Parameters
    ----------
    out : array_like, (H, W) or (H, W, 3)
        The filled image.
    hole : array_like, bool (H, W)
        True where the image was filled.

    Returns
    -------
    float

    Raises
    ------
    ImageError
        The shapes disagree or the hole is empty.
    """
    from scipy.ndimage import binary_dilation, binary_erosion

    img = _check_image(out, "output image", 1)
    mask = _check_hole(hole, img.shape)
    if not mask.any():
        raise ImageError("hole mask is empty: there is no filled region to judge")
    grad = _gradient_magnitude(img)
    known = _known_gradient(grad, mask, 2)
    ring = binary_dilation(mask, iterations=1) & ~binary_erosion(mask, iterations=1, border_value=1)
    edge = float(grad[ring].mean())
    if known == 0.0:
        return 0.0 if edge == 0.0 else math.inf
    return edge / known
