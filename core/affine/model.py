"""The affine model's data: the image split for it (§3.3, §3.4), prototypes, the patch grid (§3)
and the model itself.

Geometry. Target patches are B x B, B even, on a grid of step B/2 that starts B/2 above and left
of the image, so patches extend by B/2 outside it (zero padding, §3). Every image pixel is covered
by exactly two patches per axis and the cos² windows sum to one there (§3.1). The canvas (padded
image) has ``(n + 1) B/2`` rows for ``n = ceil(2H/B) + 1`` patch rows; the image occupies canvas
rows ``B/2 .. B/2 + H``.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import cv2
import numpy as np

from ..errors import ImageError, InvalidParameter
from ..geometry import Square
from ..image import PcaBasis, from_pca, luminance, rgb_to_yiq, to_pca, validate_image, yiq_to_rgb
from .params import COLOURS, MIN_SIDE, Rect, check_rect, default_rect

# ----------------------------------------------------------------------------------------------
# grey / chroma decomposition and the lowpass (§3.3, §3.4)


def lowpass(image: np.ndarray, block: int) -> np.ndarray:
    """The subsampled lowpass of §3.3, brought back to full size (float32, same shape).

    Ambiguity resolved here (the paper gives no cutoff): a Gaussian of σ = B/4 (variations slower
    than about one patch), kept at 1/(B/8) of the resolution (area-averaged, the "subsampled
    lowpass image") and enlarged again bilinearly. Mirrored at the borders.

    Parameters
    ----------
    image : ndarray, float32 (H, W) or (H, W, C)
        The image.
    block : int
        The patch side B.

    Returns
    -------
    ndarray, float32, the shape of ``image``

    References
    ----------
    Smith & Bhalerao, "Texture transfer using affine transformation groups and patch boundary matching", §3.3.
    """
    img = np.ascontiguousarray(image, dtype=np.float32)
    h, w = img.shape[:2]
    sigma = block / 4.0
    blurred = cv2.GaussianBlur(img, (0, 0), sigma, borderType=cv2.BORDER_REFLECT)
    f = max(1, block // 8)
    small = cv2.resize(blurred, (max(1, -(-w // f)), max(1, -(-h // f))), interpolation=cv2.INTER_AREA)
    up = cv2.resize(small, (w, h), interpolation=cv2.INTER_LINEAR)
    return up.reshape(img.shape).astype(np.float32, copy=False)


@dataclass(frozen=True, eq=False)
class Decomposition:
    """An image split for the model: the grey channel the transforms are estimated on, its
    lowpass and highpass (``grey = low + high`` exactly), and, for colour images, the two chroma
    channels (lowpassed: the "subsampled" chroma of §3.4) with what is needed to recombine."""

    grey: np.ndarray  # (H, W) float32
    luminance: np.ndarray  # (H, W) float32, Rec. 601 (the intensity factors of 'absorb')
    low: np.ndarray  # (H, W) float32
    high: np.ndarray  # (H, W) float32
    chroma_low: np.ndarray | None  # (H, W, 2) float32, colour images only
    colour: str  # "pca" or "yuv"
    basis: PcaBasis | None  # pca only
    offset: float  # pca: the mean's projection on the first axis (grey = c0 + offset)


def decompose(image: np.ndarray, block: int, colour: str = "pca", *, need_chroma: bool = True) -> Decomposition:
    """Split an image into the grey channel the model works on, its lowpass/highpass and chroma
    (§3.3, §3.4).

    Parameters
    ----------
    image : float32 (H, W) or (H, W, 3) in [0, 1]
    block : int
        B; sets the lowpass (see :func:`lowpass`).
    colour : {"pca", "yuv"}, default "pca"
        ``pca``: grey = the first principal component of the image's colours (offset by the mean's
        projection, so it reads as brightness), chroma = the other two components; ``yuv``:
        grey = Y, chroma = I and Q of YIQ (weft's YUV-family space, as in ``weft.core.image``). Grey
        images pass through.
    need_chroma : bool, default True
        Compute the lowpassed chroma (``add`` keeps it; ``absorb`` does not need it).

    Returns
    -------
    Decomposition
        ``grey = low + high`` exactly; ``chroma_low`` is the "subsampled" chroma of §3.4's first
        way (the same lowpass as the grey's).
    """
    if colour not in COLOURS:
        raise InvalidParameter(
            f"parameter 'colour' = {colour!r} is not one of {', '.join(COLOURS)}", name="colour", value=colour
        )
    basis, offset, chroma = None, 0.0, None
    if image.ndim == 2:
        grey = image
    elif colour == "yuv":
        yiq = rgb_to_yiq(image)
        grey = np.ascontiguousarray(yiq[..., 0])
        chroma = yiq[..., 1:]
    else:
        comps, basis = to_pca(image)
        offset = float(basis.mean @ basis.axes[0])
        grey = np.ascontiguousarray(comps[..., 0] + offset)
        chroma = comps[..., 1:]
    low = lowpass(grey, block)
    chroma_low = lowpass(chroma, block) if chroma is not None and need_chroma else None
    return Decomposition(
        grey=grey.astype(np.float32, copy=False),
        luminance=luminance(image),
        low=low,
        high=(grey - low).astype(np.float32),
        chroma_low=chroma_low,
        colour=colour,
        basis=basis,
        offset=offset,
    )


def _recombine(dec: Decomposition, grey: np.ndarray) -> np.ndarray:
    """Grey channel + the decomposition's chroma -> RGB (or grey for grey images), clipped."""
    if dec.chroma_low is None:
        return np.clip(grey, 0.0, 1.0).astype(np.float32, copy=False)
    if dec.colour == "yuv":
        return yiq_to_rgb(np.concatenate([grey[..., None], dec.chroma_low], axis=2))
    comps = np.concatenate([(grey - dec.offset)[..., None], dec.chroma_low], axis=2)
    assert dec.basis is not None  # a pca decomposition with chroma carries its basis
    return from_pca(comps, dec.basis)


# ----------------------------------------------------------------------------------------------
# prototypes


@dataclass(frozen=True, eq=False)
class Prototype:
    """A prototype patch in the forms the model needs (§3.3, §3.4).

    Attributes
    ----------
    highpass : (S, S) float32
        Grey highpass: spectra and translations are always estimated on it; rendered in ``add``.
    grey : (S, S) float32
        Unfiltered luminance (Rec. 601): intensity factors and the choice of transform in
        ``absorb`` (§3.3). Luminance rather than the PCA grey, so that a factor found between
        greys scales the rendered colour prototype to the target's brightness whichever image
        the prototype comes from (the first principal component of two images has two scales).
    colour : (S, S, 3) float32 or None
        The unfiltered colour patch, rendered in ``absorb`` (§3.4's colour prototype).
    rect : (x, y, s) or None
        Where it was taken from.
    """

    highpass: np.ndarray
    grey: np.ndarray
    colour: np.ndarray | None
    rect: Rect | None = None

    @property
    def side(self) -> int:
        return self.highpass.shape[0]


def make_prototype(
    image: np.ndarray,
    rect: Rect | tuple[int, int, int] | str | None = None,
    *,
    block: int = 32,
    colour: str = "pca",
    decomposition: Decomposition | None = None,
    what: str = "prototype image",
) -> Prototype:
    """Cut a prototype square out of an image (§3.3, §3.4).

    Parameters
    ----------
    image : float32 (H, W) or (H, W, 3) in [0, 1]
        The image it is taken from (the texture, or another picture for a transfer, §4).
    rect : (x, y, s) or "X,Y,S", optional
        The square; default :func:`~weft.core.affine.params.default_rect` (a 2B square in the middle).
    block : int, default 32
        B, which sets the lowpass (σ = B/4) the highpass is taken against.
    colour : {"pca", "yuv"}
        Grey channel: the image's own first principal component or luma Y.
    decomposition : Decomposition, optional
        The image's decomposition when already computed (saves the work).

    Returns
    -------
    Prototype

    Raises
    ------
    GeometryError
        The square does not fit in the image.
    """
    image = validate_image(image, what)
    rect = (
        default_rect(image.shape, block, what)
        if rect is None
        else Square.coerce(rect, "prototype").check_side("prototype", minimum=MIN_SIDE, even=True)
    )
    check_rect(rect, image.shape, what)
    dec = decomposition or decompose(image, block, colour, need_chroma=False)
    x, y, s = rect
    sl = (slice(y, y + s), slice(x, x + s))
    col = np.ascontiguousarray(image[sl]) if image.ndim == 3 else None
    return Prototype(
        highpass=np.ascontiguousarray(dec.high[sl]),
        grey=np.ascontiguousarray(luminance(image[sl])),
        colour=col,
        rect=rect,
    )


def prototype_from_patch(patch: np.ndarray, *, block: int = 32, colour: str = "pca") -> Prototype:
    """A prototype from a bare square patch (e.g. a swapped-in sample, §4).

    Parameters
    ----------
    patch : float32 (S, S) or (S, S, 3) in [0, 1]
        S even, >= 8.
    block, colour
        As for :func:`make_prototype`; the highpass is taken against the patch's own lowpass
        (mirrored at its borders), since no surrounding image is known.

    Returns
    -------
    Prototype

    Raises
    ------
    ImageError
        The patch is not a square with an even side of at least 8.
    """
    patch = validate_image(patch, "prototype patch")
    h, w = patch.shape[:2]
    if h != w or h < 8 or h % 2:
        raise ImageError(f"prototype patch is {w}x{h}; it must be a square with an even side >= 8")
    return make_prototype(patch, (0, 0, h), block=block, colour=colour, what="prototype patch")


# ----------------------------------------------------------------------------------------------
# the model


@dataclass(frozen=True)
class Grid:
    """The patch grid of an ``H x W`` image with B x B patches at a B/2 step (module docstring)."""

    height: int
    width: int
    block: int

    @property
    def step(self) -> int:
        return self.block // 2

    @property
    def rows(self) -> int:
        return -(-self.height // self.step) + 1

    @property
    def cols(self) -> int:
        return -(-self.width // self.step) + 1

    @property
    def count(self) -> int:
        return self.rows * self.cols

    @property
    def canvas(self) -> tuple[int, int]:
        return (self.rows + 1) * self.step, (self.cols + 1) * self.step

    @property
    def radius(self) -> int:
        """Largest translation per axis, B/4 (§2.3)."""
        return self.block // 4

    def origins(self) -> np.ndarray:
        r, c = np.mgrid[: self.rows, : self.cols]
        return (np.stack([r.ravel(), c.ravel()], axis=1) * self.step).astype(np.int64)

    def pad(self, img: np.ndarray) -> np.ndarray:
        """Zero-pad an (H, W[, C]) image onto the canvas (§3)."""
        hc, wc = self.canvas
        out = np.zeros((hc, wc) + img.shape[2:], np.float32)
        out[self.step : self.step + self.height, self.step : self.step + self.width] = img
        return out

    def crop(self, canvas: np.ndarray) -> np.ndarray:
        return canvas[self.step : self.step + self.height, self.step : self.step + self.width]

    def inside(self) -> np.ndarray:
        """1 on the image, 0 on the padding (canvas shape, float32)."""
        return self.pad(np.ones((self.height, self.width), np.float32))


@dataclass(frozen=True, eq=False)
class AffineModel:
    """A texture as a prototype and one affine transform + intensity factor per target patch.

    Attributes
    ----------
    grid : Grid
        Image size and patch geometry.
    transforms : (K, 2, 2) float64
        T_k (eq. 22): prototype -> target coordinates, ``(y, x)``.
    sampling : (K, 2, 2) float64
        ``T_k⁻¹``, what rendering samples the prototype through.
    shifts : (K, 2) int64
        Translations ``(ty, tx)`` in target pixels, ``|t| <= B/4`` (§2.3, or from §4's matching).
    alpha : (K,) float64
        Intensity factors (§3.2).
    choice : (K,) int8
        Which of the eight candidates (eq. 21 order) was chosen; -1 for a parametric field.
    rms : (K,) float32
        RMS error of the chosen candidate against its target patch (§2.4); NaN for a field.
    lowpass : {"add", "absorb"}
    prototype : Prototype
        The prototype the transforms were computed for.
    decomposition : Decomposition or None
        The modelled image's grey/lowpass/chroma; ``add`` adds its lowpass (and chroma) back.
    """

    grid: Grid
    transforms: np.ndarray
    sampling: np.ndarray
    shifts: np.ndarray
    alpha: np.ndarray
    choice: np.ndarray
    rms: np.ndarray
    lowpass: str
    prototype: Prototype
    decomposition: Decomposition | None = None
    extra: dict = field(default_factory=dict)

    @property
    def block(self) -> int:
        return self.grid.block

    @property
    def shape(self) -> tuple[int, int]:
        return self.grid.height, self.grid.width

    def with_shifts(self, shifts: np.ndarray) -> AffineModel:
        return replace(self, shifts=np.ascontiguousarray(shifts, dtype=np.int64))


def padded(patch: np.ndarray) -> tuple[np.ndarray, float]:
    """The prototype as the kernels sample it.

    Parameters
    ----------
    patch : (S, S) or (S, S, C) array

    Returns
    -------
    (ndarray (3S, 3S[, C]) float32, float)
        The patch mirrored (reflect-101) by its own side on every side, and the patch's centre
        ``S + (S - 1)/2`` in it. Choice where the paper is silent: a transformed prototype that
        reaches past its square (a shrinking or turned transform near the patch corners) sees the
        mirrored prototype, not zeros.
    """
    s = patch.shape[0]
    pad = ((s, s), (s, s)) + ((0, 0),) * (patch.ndim - 2)
    return np.ascontiguousarray(np.pad(patch.astype(np.float32), pad, mode="reflect")), s + (s - 1) / 2.0
