"""Colour helpers every method shares: luminance (Rec. 601), RGB <-> YIQ (Ashikhmin keeps the
target's chroma in YIQ), and the principal-component grey of Smith & Bhalerao §3.4."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ImageError

# Rec. 601 luma weights, also the Y row of YIQ.
_LUMA = np.array([0.299, 0.587, 0.114], dtype=np.float32)
_RGB2YIQ = np.array(
    [[0.299, 0.587, 0.114], [0.595716, -0.274453, -0.321263], [0.211456, -0.522591, 0.311135]],
    dtype=np.float64,
)
_YIQ2RGB = np.linalg.inv(_RGB2YIQ)


def _check_float_image(image: np.ndarray, what: str = "image") -> np.ndarray:
    image = np.asarray(image)
    if image.ndim not in (2, 3) or (image.ndim == 3 and image.shape[2] != 3):
        raise ImageError(f"{what} must have shape (H, W) or (H, W, 3), not {image.shape}")
    if image.shape[0] < 1 or image.shape[1] < 1:
        raise ImageError(f"{what} is empty ({image.shape[1]}x{image.shape[0]})")
    return image


def luminance(image: np.ndarray) -> np.ndarray:
    """Rec. 601 luminance ``0.299 R + 0.587 G + 0.114 B``.

    Parameters
    ----------
    image : ndarray, (H, W) or (H, W, 3)
        RGB in [0, 1]; a grey image passes through.

    Returns
    -------
    ndarray, float32 (H, W)
    """
    image = _check_float_image(image)
    if image.ndim == 2:
        return image.astype(np.float32, copy=False)
    return (image.astype(np.float32, copy=False) @ _LUMA).astype(np.float32, copy=False)


def rgb_to_yiq(rgb: np.ndarray) -> np.ndarray:
    """RGB to YIQ (NTSC).

    Parameters
    ----------
    rgb : ndarray, (H, W, 3)
        RGB in [0, 1].

    Returns
    -------
    ndarray, float32 (H, W, 3)
        Y in [0, 1], I in ±0.596, Q in ±0.523.

    Raises
    ------
    ImageError
        ``rgb`` is not (H, W, 3).

    References
    ----------
    Ashikhmin, "Fast texture transfer" (2003), "Basic technique": the synthesis runs on Y and the
    target's chroma is kept.
    """
    rgb = _check_float_image(rgb, "RGB image")
    if rgb.ndim != 3:
        raise ImageError(f"RGB image must have shape (H, W, 3), not {rgb.shape}")
    return (rgb.astype(np.float32, copy=False) @ _RGB2YIQ.T.astype(np.float32)).astype(np.float32, copy=False)


def yiq_to_rgb(yiq: np.ndarray, *, clip: bool = True) -> np.ndarray:
    """YIQ to RGB, the inverse of :func:`rgb_to_yiq`.

    Parameters
    ----------
    yiq : ndarray, (H, W, 3)
        Y, I, Q.
    clip : bool, default True
        Clip the result to [0, 1].

    Returns
    -------
    ndarray, float32 (H, W, 3)

    Raises
    ------
    ImageError
        ``yiq`` is not (H, W, 3).
    """
    yiq = np.asarray(yiq)
    if yiq.ndim != 3 or yiq.shape[2] != 3:
        raise ImageError(f"YIQ image must have shape (H, W, 3), not {yiq.shape}")
    rgb = (yiq.astype(np.float32, copy=False) @ _YIQ2RGB.T.astype(np.float32)).astype(np.float32, copy=False)
    return np.clip(rgb, 0.0, 1.0, out=rgb) if clip else rgb


@dataclass(frozen=True)
class PcaBasis:
    """An orthonormal colour basis: ``components = (rgb - mean) @ axes.T``.

    ``axes`` rows are the principal directions, largest variance first; the first axis is signed so
    that it correlates positively with luminance (bright stays bright). ``variances`` are the
    eigenvalues in the same order.
    """

    mean: np.ndarray  # (3,)
    axes: np.ndarray  # (3, 3), rows
    variances: np.ndarray  # (3,)


def pca_basis(rgb: np.ndarray) -> PcaBasis:
    """The principal components of an RGB image's colours.

    Parameters
    ----------
    rgb : ndarray, (H, W, 3)
        RGB in [0, 1].

    Returns
    -------
    PcaBasis
        The colours' mean and the three axes, the direction of greatest variance first.

    Raises
    ------
    ImageError
        ``rgb`` is not (H, W, 3).

    References
    ----------
    Smith & Bhalerao, "Texture transfer using affine transformation groups and patch boundary
    matching", §3.4; Jolliffe, *Principal Component Analysis*.
    """
    rgb = _check_float_image(rgb, "RGB image")
    if rgb.ndim != 3:
        raise ImageError(f"RGB image must have shape (H, W, 3), not {rgb.shape}")
    pixels = rgb.reshape(-1, 3).astype(np.float64)
    mean = pixels.mean(axis=0)
    cov = np.cov((pixels - mean).T) if len(pixels) > 1 else np.zeros((3, 3))
    variances, vectors = np.linalg.eigh(cov)
    order = np.argsort(variances)[::-1]
    variances = np.maximum(variances[order], 0.0)
    axes = vectors[:, order].T.copy()
    if variances[0] <= 1e-18:
        # Flat colour: no preferred direction, use luminance so the grey still means brightness
        # (and two directions orthogonal to it, so the basis stays orthonormal).
        q, _ = np.linalg.qr(np.column_stack([_LUMA.astype(np.float64), np.eye(3)[:, :2]]))
        axes = q.T.copy()
    for i in range(3):
        ref = _LUMA if i == 0 else axes[i]
        if np.dot(axes[i], ref) < 0:
            axes[i] = -axes[i]
    return PcaBasis(mean=mean.astype(np.float32), axes=axes.astype(np.float32), variances=variances.astype(np.float32))


def to_pca(rgb: np.ndarray, basis: PcaBasis | None = None) -> tuple[np.ndarray, PcaBasis]:
    """Project RGB onto a PCA colour basis.

    Parameters
    ----------
    rgb : ndarray, (H, W, 3)
        RGB in [0, 1].
    basis : PcaBasis, optional
        The basis; default the image's own (:func:`pca_basis`).

    Returns
    -------
    components : ndarray, float32 (H, W, 3)
        The coordinates along the basis's axes, about its mean.
    basis : PcaBasis
        The basis used.

    References
    ----------
    Smith & Bhalerao, "Texture transfer using affine transformation groups and patch boundary matching", §3.4.
    """
    if basis is None:
        basis = pca_basis(rgb)
    comps = (np.asarray(rgb, dtype=np.float32) - basis.mean) @ basis.axes.T
    return comps.astype(np.float32, copy=False), basis


def from_pca(components: np.ndarray, basis: PcaBasis, *, clip: bool = True) -> np.ndarray:
    """Inverse of :func:`to_pca`.

    Parameters
    ----------
    components : ndarray, (H, W, 3)
        Coordinates along the basis's axes.
    basis : PcaBasis
        The basis they are in.
    clip : bool, default True
        Clip the result to [0, 1].

    Returns
    -------
    ndarray, float32 (H, W, 3)
        RGB.
    """
    rgb = (np.asarray(components, dtype=np.float32) @ basis.axes + basis.mean).astype(np.float32, copy=False)
    return np.clip(rgb, 0.0, 1.0, out=rgb) if clip else rgb


def pca_grey(rgb: np.ndarray) -> tuple[np.ndarray, PcaBasis]:
    """The principal-component grey of §3.4: the colour direction of greatest variance.

    Reconstruct with ``from_pca(stack([grey - offset, c1, c2]), basis)`` where
    ``offset = basis.mean @ basis.axes[0]``.

    Parameters
    ----------
    rgb : ndarray, (H, W, 3)
        RGB in [0, 1].

    Returns
    -------
    grey : ndarray, float32 (H, W)
        The first component offset by the mean's projection on that axis (so the values sit around
        the image's mean brightness rather than around zero).
    basis : PcaBasis

    References
    ----------
    Smith & Bhalerao, "Texture transfer using affine transformation groups and patch boundary matching", §3.4.
    """
    comps, basis = to_pca(rgb)
    offset = float(basis.mean @ basis.axes[0])
    return (comps[..., 0] + offset).astype(np.float32), basis
