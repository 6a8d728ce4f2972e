"""Rendering with the affine prototype model (Smith & Bhalerao §3, §4).

:func:`~weft.core.affine.analysis.analyse` models a texture as one prototype patch and, for every
target patch, the affine transform (linear part, translation) and intensity factor that best map
the prototype onto it (§2); :func:`render` draws a model with its prototype or with another one
(a prototype swap, §4). Keeping the two apart is what makes a live re-render possible when the
user drags the prototype rectangle with "reuse transforms" on: :func:`render` only warps, windows
and sums.
"""

from __future__ import annotations

import numpy as np

from .model import AffineModel, Prototype, _recombine, padded, prototype_from_patch
from .spectral import cos2_window


def _as_prototype(model: AffineModel, prototype) -> Prototype:
    if prototype is None:
        return model.prototype
    if isinstance(prototype, Prototype):
        return prototype
    colour = model.decomposition.colour if model.decomposition is not None else "pca"
    return prototype_from_patch(prototype, block=model.block, colour=colour)


def render_signal(model: AffineModel, proto: Prototype) -> np.ndarray:
    """The prototype channel(s) a model renders.

    Parameters
    ----------
    model : AffineModel
        The model (its ``lowpass`` mode).
    proto : Prototype
        The prototype.

    Returns
    -------
    ndarray, float32 (S, S, C)
        The highpass grey (``add``), else the unfiltered colour patch if there is one, else the
        unfiltered grey.

    References
    ----------
    Smith & Bhalerao, "Texture transfer using affine transformation groups and patch boundary
    matching", §3.3-3.4.
    """
    if model.lowpass == "add":
        sig = proto.highpass
    elif proto.colour is not None:
        sig = proto.colour
    else:
        sig = proto.grey
    sig = np.asarray(sig, dtype=np.float32)
    return np.ascontiguousarray(sig if sig.ndim == 3 else sig[..., None])


def render_canvas(model: AffineModel, proto: Prototype, index: np.ndarray | None = None) -> np.ndarray:
    """Sum of the windowed, normalised, warped prototypes on the padded canvas.

    Parameters
    ----------
    model : AffineModel
        The transforms and the grid.
    proto : Prototype
        The prototype drawn.
    index : ndarray, optional
        The patches to draw (default all).

    Returns
    -------
    ndarray, float32 (Hc, Wc, C)

    References
    ----------
    Smith & Bhalerao, "Texture transfer using affine transformation groups and patch boundary
    matching", §3 (synthesis: §3.1 the cosine-squared window, §3.2 the intensity normalisation).
    """
    from .._kernels import affine as _k

    sig, c = padded(render_signal(model, proto))
    hc, wc = model.grid.canvas
    out = np.zeros((hc, wc, sig.shape[2]), np.float32)
    idx = np.arange(model.grid.count, dtype=np.int64) if index is None else np.asarray(index, dtype=np.int64)
    _k.render(
        sig,
        c,
        c,
        model.sampling,
        model.shifts.astype(np.float64),
        model.alpha,
        model.grid.origins(),
        cos2_window(model.block),
        idx,
        out,
    )
    return out


def compose(model: AffineModel, synth: np.ndarray) -> np.ndarray:
    """The output image from a synthesized signal (§3.3, §3.4).

    Parameters
    ----------
    model : AffineModel
    synth : float32 (H, W, C)
        The cropped sum of windowed patches (:func:`render_canvas` cropped to the image).

    Returns
    -------
    float32 (H, W) or (H, W, 3) in [0, 1]
        ``add``: synth + the retained lowpass, recombined with the retained chroma;
        ``absorb``: synth as it is. Clipped to [0, 1].
    """
    if model.lowpass == "add" and model.decomposition is not None:
        return _recombine(model.decomposition, synth[..., 0] + model.decomposition.low)
    out = synth[..., 0] if synth.shape[2] == 1 else synth
    return np.clip(out, 0.0, 1.0).astype(np.float32, copy=False)


def render(
    model: AffineModel, prototype: Prototype | np.ndarray | None = None, *, index: np.ndarray | None = None
) -> np.ndarray:
    """Draw a model with its own prototype or a swapped one (§3, §4 "re-synthesizing based on the
    existing transformations").

    Each patch k is the prototype sampled through ``T_k⁻¹`` and moved by its translation,
    multiplied by its intensity factor and the cos² window, and summed into the canvas, which is
    cropped to the image (§3). Cheap enough for a live preview: only warping, windowing and summing.

    Parameters
    ----------
    model : AffineModel
        From :func:`analyse` (or :func:`~weft.core.affine.fields.field_model`, or after boundary matching).
    prototype : Prototype, float32 (S, S) / (S, S, 3) patch, or None
        The prototype to draw; None = the model's. A bare patch is split into grey/highpass with
        its own lowpass (:func:`prototype_from_patch`); use :func:`make_prototype` to cut one out
        of an image with that image's lowpass. Any even side works; a side other than the model's
        prototype scales nothing (the transforms are in pixels) but changes how much texture is
        available around the centre.
    index : int array, optional
        Only these patches (used for previews of a partly analysed texture).

    Returns
    -------
    float32 (H, W) or (H, W, 3) in [0, 1]
        ``add``: the synthesized highpass + the image's lowpass, recombined with its chroma (the
        output has the modelled image's channels). ``absorb``: the prototype's own intensities and
        colour scaled by the factors (three channels for a colour prototype).
    """
    proto = _as_prototype(model, prototype)
    canvas = render_canvas(model, proto, index)
    return compose(model, model.grid.crop(canvas))
