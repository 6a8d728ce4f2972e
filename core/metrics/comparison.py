"""Whole-image figures: fidelity to a target (texture transfer), SNR and PSNR against an original."""

from __future__ import annotations

import math

import numpy as np

from ..errors import ImageError, InvalidParameter
from ..image import luminance
from .checks import _check_image


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
