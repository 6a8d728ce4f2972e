"""Fill figures: how a filled hole (or the new border of an uncrop) reads against the known rest of its
image -- like its surroundings, as detailed, with an invisible edge.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from ..errors import ImageError
from ..image import luminance
from .checks import MIN_SIDE, _check_image, _check_int
from .patches import _nearest_distances, _patches


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
