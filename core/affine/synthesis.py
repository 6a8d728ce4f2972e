"""Synthesis with the affine prototype model (Smith & Bhalerao §3): analysis and rendering.

:func:`analyse` models a texture as one prototype patch and, for every target patch, the affine
transform (linear part, translation) and intensity factor that best map the prototype onto it
(§2); :func:`render` draws a model with its prototype or with another one (a prototype swap, §4).
Keeping the two apart is what makes a live re-render possible when the user drags the prototype
rectangle with "reuse transforms" on: :func:`render` only warps, windows and sums.

Geometry. Target patches are B x B, B even, on a grid of step B/2 that starts B/2 above and left
of the image, so patches extend by B/2 outside it (zero padding, §3). Every image pixel is covered
by exactly two patches per axis and the cos² windows sum to one there (§3.1). The canvas (padded
image) has ``(n + 1) B/2`` rows for ``n = ceil(2H/B) + 1`` patch rows; the image occupies canvas
rows ``B/2 .. B/2 + H``.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Callable

import cv2
import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from ..errors import ImageError, InvalidParameter
from ..image import PcaBasis, from_pca, luminance, rgb_to_yiq, to_pca, validate_image, yiq_to_rgb
from ..jobs import CancelToken, Progress, ProgressReporter
from .centroids import centroids, cos2_window
from .params import COLOURS, LOWPASS, Rect, check_rect, default_rect, parse_rect
from .transforms import _clamp_scale, candidate_transforms, correlate_indexed, sampling_matrices

# ----------------------------------------------------------------------------------------------
# grey / chroma decomposition and the lowpass (§3.3, §3.4)


def lowpass(image: np.ndarray, block: int) -> np.ndarray:
    """The subsampled lowpass of §3.3, brought back to full size (float32, same shape).

    Ambiguity resolved here (the paper gives no cutoff): a Gaussian of σ = B/4 (variations slower
    than about one patch), kept at 1/(B/8) of the resolution (area-averaged, the "subsampled
    lowpass image") and enlarged again bilinearly. Mirrored at the borders.
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
        grey = Y, chroma = I and Q of YIQ (weft's YUV-family space, as in ``core.image``). Grey
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
        raise InvalidParameter(f"parameter 'colour' = {colour!r} is not one of {', '.join(COLOURS)}",
                               name="colour", value=colour)
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
    return Decomposition(grey=grey.astype(np.float32, copy=False), luminance=luminance(image), low=low,
                         high=(grey - low).astype(np.float32),
                         chroma_low=chroma_low, colour=colour, basis=basis, offset=offset)


def _recombine(dec: Decomposition, grey: np.ndarray) -> np.ndarray:
    """Grey channel + the decomposition's chroma -> RGB (or grey for grey images), clipped."""
    if dec.chroma_low is None:
        return np.clip(grey, 0.0, 1.0).astype(np.float32, copy=False)
    if dec.colour == "yuv":
        return yiq_to_rgb(np.concatenate([grey[..., None], dec.chroma_low], axis=2))
    comps = np.concatenate([(grey - dec.offset)[..., None], dec.chroma_low], axis=2)
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


def make_prototype(image: np.ndarray, rect: Rect | str | None = None, *, block: int = 32, colour: str = "pca",
                   decomposition: Decomposition | None = None, what: str = "prototype image") -> Prototype:
    """Cut a prototype square out of an image (§3.3, §3.4).

    Parameters
    ----------
    image : float32 (H, W) or (H, W, 3) in [0, 1]
        The image it is taken from (the texture, or another picture for a transfer, §4).
    rect : (x, y, s) or "X,Y,S", optional
        The square; default :func:`~core.affine.params.default_rect` (a 2B square in the middle).
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
    rect = default_rect(image.shape, block) if rect is None else parse_rect(rect)
    check_rect(rect, image.shape, what)
    dec = decomposition or decompose(image, block, colour, need_chroma=False)
    x, y, s = rect
    sl = (slice(y, y + s), slice(x, x + s))
    col = np.ascontiguousarray(image[sl]) if image.ndim == 3 else None
    return Prototype(highpass=np.ascontiguousarray(dec.high[sl]), grey=np.ascontiguousarray(luminance(image[sl])),
                     colour=col, rect=rect)


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
        r, c = np.mgrid[:self.rows, :self.cols]
        return (np.stack([r.ravel(), c.ravel()], axis=1) * self.step).astype(np.int64)

    def pad(self, img: np.ndarray) -> np.ndarray:
        """Zero-pad an (H, W[, C]) image onto the canvas (§3)."""
        hc, wc = self.canvas
        out = np.zeros((hc, wc) + img.shape[2:], np.float32)
        out[self.step:self.step + self.height, self.step:self.step + self.width] = img
        return out

    def crop(self, canvas: np.ndarray) -> np.ndarray:
        return canvas[self.step:self.step + self.height, self.step:self.step + self.width]

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

    def with_shifts(self, shifts: np.ndarray) -> "AffineModel":
        return replace(self, shifts=np.ascontiguousarray(shifts, dtype=np.int64))


def _patches(canvas: np.ndarray, grid: Grid) -> np.ndarray:
    B, h = grid.block, grid.step
    view = sliding_window_view(canvas, (B, B))[::h, ::h][:grid.rows, :grid.cols]
    return np.ascontiguousarray(view).reshape(-1, B, B)


def analyse(
    texture: np.ndarray,
    *,
    prototype: Rect | str | Prototype | None = None,
    prototype_image: np.ndarray | None = None,
    block: int = 32,
    segments: int = 32,
    lowpass: str = "add",
    colour: str = "pca",
    propagate: bool = True,
    refine: int = 2,
    progress: Callable[[Progress], None] | None = None,
    cancel: CancelToken | None = None,
) -> AffineModel:
    """Model a texture by a prototype patch and per-patch affine transforms (§2, §3).

    For every B x B target patch (B/2 apart, extending B/2 past the image, zero padded): the
    centroid pairs of the windowed highpass target and prototype (§2.1) give eight candidate linear
    transforms (§2.2); the unwindowed prototype warped by each is correlated with the windowed
    target for the translation (eq. 23, ``|t| <= B/4``, §2.3); each is windowed, normalised and
    compared (§2.4) and the lowest RMS error wins.

    Parameters
    ----------
    texture : float32 (H, W) or (H, W, 3) in [0, 1]
        The image to model (a texture, or any picture for a transfer onto it, §4).
    prototype : (x, y, s), "X,Y,S" or Prototype, optional
        The prototype square in ``prototype_image`` (or in the texture); default a 2B square in
        the middle (:func:`~core.affine.params.default_rect`). A :class:`Prototype` is used as is.
    prototype_image : float32 image, optional
        Another picture to take the prototype from: texture transfer with transforms computed for
        the new prototype (§4).
    block : even int, 8..256, default 32
        B, the target patch side.
    segments : even int, 4..128, default 32
        N, angular segments for the centroids (§2.1).
    lowpass : {"add", "absorb"}, default "add"
        §3.3: ``add`` models the highpass and keeps the image's subsampled lowpass (and chroma,
        §3.4 first way) to add back; ``absorb`` estimates the transforms on the highpass but
        chooses them and computes intensity factors on the unfiltered image (its luminance),
        and renders the unfiltered (colour) prototype (§3.4 second way): the lowpass is absorbed
        in the factors.
    colour : {"pca", "yuv"}, default "pca"
        Grey channel of colour images: the first principal component of the colours (§3.4, the
        paper's recommendation) or luma Y (of YIQ, weft's YUV-family space).
    progress, cancel
        Progress per patch row (stage "affine analysis", with a preview of the rows done);
        the cancel token is checked once per patch row.

    Returns
    -------
    AffineModel

    Notes
    -----
    Choices where the paper is silent: the correlation of §2.3 uses the cos²-windowed target
    (the part of the patch the rendering keeps); α is the ratio of windowed RMS values
    ``||W t|| / ||W p'||``, which for the zero-mean highpass of ``add`` is σ_t/σ_p' (§3.2) and in
    ``absorb`` includes the mean (how low-frequency intensity is "subsumed into the intensity
    normalization factor"); α and the RMS error of §2.4 count only the patch's pixels inside the
    image. The prototype is sampled bilinearly and mirrored beyond its square.
    """
    texture = validate_image(texture, "texture")
    if lowpass not in LOWPASS:
        raise InvalidParameter(f"parameter 'lowpass' = {lowpass!r} is not one of {', '.join(LOWPASS)}",
                               name="lowpass", value=lowpass)
    _check_geometry(texture.shape, block, segments)
    dec = decompose(texture, block, colour, need_chroma=lowpass == "add")
    if isinstance(prototype, Prototype):
        proto = prototype
    elif prototype_image is not None:
        proto = make_prototype(prototype_image, prototype, block=block, colour=colour)
    else:
        proto = make_prototype(texture, prototype, block=block, colour=colour, decomposition=dec, what="texture")

    ctx = _Context.build(dec, proto, block, lowpass)
    grid = ctx.grid
    K, B = grid.count, block
    # The prototype's centroids come from its central B x B block, windowed like the targets:
    # magnitude-spectrum centroids depend on the window, and identical content must give identical
    # centroids (then the identity is among the candidates).
    mu_p = centroids(_central(proto.highpass, B), segments=segments, lowcut=1.0 / B).mu[0]
    mu_t = centroids(ctx.targets_hp, segments=segments, lowcut=1.0 / B).mu
    T = candidate_transforms(mu_p, mu_t)  # (K, 8, 2, 2)
    M = sampling_matrices(T)
    state = _State.empty(K)
    rows = grid.rows
    stages = rows * (2 if propagate else 1)
    report = ProgressReporter(progress, "affine analysis", stages)
    done = [0]

    def preview() -> np.ndarray:
        return render(state.model(ctx, lowpass, proto, dec))

    def step() -> None:
        done[0] += 1
        report.update(done[0], preview=preview)

    # Top-down pass: the paper's eight candidates (§2.2-2.4), plus, with `propagate`, the chosen
    # transforms of the three patches above (§6: "take into account the surrounding patches'
    # transformations"); the winner is refined before the next row sees it.
    for r in range(rows):
        if cancel is not None:
            cancel.raise_if_cancelled()
        sl = slice(r * grid.cols, (r + 1) * grid.cols)
        sh, al, er = ctx.evaluate(M[sl], symmetric=True, rows=sl)
        best = np.argmin(er, axis=1)
        idx = np.arange(len(best))
        state.set(sl, M[sl][idx, best], sh[idx, best], al[idx, best], er[idx, best], best)
        if propagate and r > 0:
            ctx.try_row(state, r, r - 1, base=8)
        if refine:
            ctx.refine(state, sl, refine)
        step()
    if propagate:  # bottom-up pass: the three patches below
        for r in range(rows - 2, -1, -1):
            if cancel is not None:
                cancel.raise_if_cancelled()
            sl = slice(r * grid.cols, (r + 1) * grid.cols)
            changed = ctx.try_row(state, r, r + 1, base=11)
            if refine and changed.any():
                ctx.refine(state, sl, refine, only=changed)
            step()
        step()
    return state.model(ctx, lowpass, proto, dec, T_all=None)


@dataclass
class _State:
    """The chosen transform of every patch while the analysis runs."""

    mats: np.ndarray  # (K, 2, 2) sampling
    shifts: np.ndarray  # (K, 2) float64
    alpha: np.ndarray  # (K,)
    err: np.ndarray  # (K,)
    choice: np.ndarray  # (K,) int8

    @classmethod
    def empty(cls, K: int) -> "_State":
        return cls(np.tile(np.eye(2), (K, 1, 1)), np.zeros((K, 2)), np.zeros(K), np.full(K, np.inf),
                   np.full(K, -1, np.int8))

    def set(self, rows, mats, shifts, alpha, err, choice) -> None:
        self.mats[rows] = mats
        self.shifts[rows] = shifts
        self.alpha[rows] = alpha
        self.err[rows] = err
        self.choice[rows] = choice

    def model(self, ctx: "_Context", lowpass, proto, dec, T_all=None) -> AffineModel:
        return AffineModel(
            grid=ctx.grid,
            transforms=np.linalg.inv(self.mats),
            sampling=self.mats.copy(),
            shifts=self.shifts.copy(),
            alpha=self.alpha.copy(),
            choice=self.choice.copy(),
            rms=self.err.astype(np.float32),
            lowpass=lowpass,
            prototype=proto,
            decomposition=dec,
        )


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


@dataclass
class _Context:
    """What evaluating candidates needs: prototypes, target patches, weights, sizes."""

    grid: Grid
    hp: np.ndarray  # (3S, 3S) float32 padded highpass prototype
    cmp: np.ndarray  # (3S, 3S) float32 padded prototype the choice and factors use
    centre: float  # the prototype's centre in the padded arrays
    add: bool  # lowpass 'add': choice and factors on the highpass (scores from the frames)
    targets_hp: np.ndarray  # (K, B, B)
    targets_w: np.ndarray  # (K, B, B) windowed highpass targets (correlation, §2.3)
    targets_cmp: np.ndarray  # (K, B, B)
    weights: np.ndarray  # (K, B, B) window x inside
    grad: tuple | None = None  # the prototype's derivatives, for refinement

    @classmethod
    def build(cls, dec: Decomposition, proto: Prototype, block: int, lowpass: str) -> "_Context":
        H, W = dec.grey.shape
        grid = Grid(H, W, block)
        win = cos2_window(block)
        targets_hp = _patches(grid.pad(dec.high), grid)
        weights = (_patches(grid.inside(), grid) * win).astype(np.float32)
        if lowpass == "add":
            targets_cmp, cmp = targets_hp, proto.highpass
        else:
            targets_cmp, cmp = _patches(grid.pad(dec.luminance), grid), proto.grey
        hp, c = padded(proto.highpass)
        return cls(grid, hp, padded(cmp)[0], c, lowpass == "add", targets_hp, targets_hp * win, targets_cmp,
                   weights)

    def evaluate(self, mats: np.ndarray, *, symmetric: bool, rows) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Translations (§2.3), factors and RMS errors (§2.4) of candidate sampling matrices
        ``mats`` (n, J, 2, 2) for the patches ``rows``. ``symmetric``: candidates j + J/2 are
        candidates j turned by 180° (eq. 21's negations), whose frames are the turned frames."""
        n, J = mats.shape[:2]
        h = J // 2 if symmetric else J
        index = np.arange(n * h).reshape(n, h)
        flip = np.zeros((n, h), bool)
        if symmetric:
            index = np.concatenate([index, index], axis=1)
            flip = np.concatenate([flip, ~flip], axis=1)
        return self.evaluate_shared(np.ascontiguousarray(mats[:, :h]).reshape(-1, 2, 2), index, flip, rows,
                                    np.ascontiguousarray(mats))

    def evaluate_shared(self, frame_mats: np.ndarray, index: np.ndarray, flip: np.ndarray, rows,
                        mats: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`evaluate` for candidates sharing frames: candidate j of patch i is the
        prototype warped by ``frame_mats[index[i, j]]``, turned by 180° where ``flip[i, j]``."""
        from .._kernels import affine as _k

        R = self.grid.radius
        L = self.grid.block + 2 * R
        c = self.centre
        frames = np.empty((len(frame_mats), L, L), np.float32)
        _k.warp_frames(self.hp, c, c, np.ascontiguousarray(frame_mats), frames)
        sh, _ = correlate_indexed(frames, index, flip, self.targets_w[rows], R)
        n, J = index.shape
        alpha = np.zeros((n, J))
        err = np.zeros((n, J))
        if self.add:  # the frames are the highpass prototype: score by slicing them
            _k.score_frames(frames, index, flip, sh, R, self.targets_cmp[rows], self.weights[rows], alpha, err)
        else:
            if mats is None:
                mats = np.where(flip[..., None, None], -1.0, 1.0) * frame_mats[index]
            _k.score_candidates(self.cmp, c, c, np.ascontiguousarray(mats), sh.astype(np.float64),
                                self.targets_cmp[rows], self.weights[rows], alpha, err)
        return sh.astype(np.float64), alpha, err

    def try_row(self, state: _State, row: int, other: int, base: int) -> np.ndarray:
        """Try, for every patch of ``row``, the chosen transforms of the patches of row ``other``
        diagonally before, straight across and diagonally after it; keep those that beat the
        current choice (choice code ``base`` + 0, 1, 2). Returns the mask of patches changed."""
        cols = self.grid.cols
        sl = slice(row * cols, (row + 1) * cols)
        frame_mats = state.mats[other * cols:(other + 1) * cols]
        c = np.arange(cols)
        index = np.stack([np.maximum(c - 1, 0), c, np.minimum(c + 1, cols - 1)], axis=1)
        sh, al, er = self.evaluate_shared(frame_mats, index, np.zeros(index.shape, bool), sl)
        best = np.argmin(er, axis=1)
        better = er[c, best] < state.err[sl]
        if better.any():
            b = best[better]
            i = c[better]
            state.set(i + sl.start, frame_mats[index[i, b]], sh[i, b], al[i, b], er[i, b], base + b)
        return better

    def refine(self, state: _State, rows: slice, iterations: int, only: np.ndarray | None = None) -> None:
        from .._kernels import affine as _k

        c = self.centre
        if self.grad is None:
            gy, gx = np.gradient(self.hp.astype(np.float64))
            self.grad = (np.ascontiguousarray(gy, dtype=np.float32), np.ascontiguousarray(gx, dtype=np.float32))
        sel = np.arange(rows.start, rows.stop) if only is None else np.flatnonzero(only) + rows.start
        mats = np.ascontiguousarray(state.mats[sel])
        offsets = -np.einsum("kij,kj->ki", mats, state.shifts[sel])  # o = -M t
        params = np.concatenate([mats.reshape(-1, 4), offsets, np.ones((len(sel), 1))], axis=1)
        params = levenberg_marquardt(self.hp, self.grad, c, params, self.targets_hp[sel], self.weights[sel],
                                     iterations)
        mats = np.ascontiguousarray(params[:, :4].reshape(-1, 2, 2))
        offsets = params[:, 4:6]
        # scales within [1/4, 4] (for M as for T = M^-1): also never singular
        mats = np.ascontiguousarray(_clamp_scale(mats))
        R = float(self.grid.radius)
        sh = np.ascontiguousarray(np.clip(-np.einsum("kij,kj->ki", np.linalg.inv(mats), offsets), -R, R))
        alpha = np.zeros((len(mats), 1))
        err = np.zeros((len(mats), 1))
        _k.score_candidates(self.cmp, c, c, mats[:, None].copy(), sh[:, None].copy(), self.targets_cmp[sel],
                            self.weights[sel], alpha, err)
        better = err[:, 0] <= state.err[sel]
        idx = sel[better]
        state.set(idx, mats[better], sh[better], alpha[better, 0], err[better, 0], state.choice[idx])


def levenberg_marquardt(proto: np.ndarray, grad: tuple, centre: float, params: np.ndarray, targets: np.ndarray,
                        weights: np.ndarray, iterations: int) -> np.ndarray:
    """Refine affine maps by damped Gauss-Newton steps (an addition to the paper).

    Minimises, per patch, ``Σ_y (w(y) (g P(c + M y + o) - s_t(y)))²`` over ``params`` =
    (M00, M01, M10, M11, o_y, o_x, g) (n, 7), from the chosen candidate (``o = -M t``, gain
    ``g = 1``). A step that does not lower a patch's error is refused and its damping multiplied
    by 10 (accepted: divided by 3.3), so no patch gets worse; a patch stops when its error falls by
    less than 1e-7 of itself or its damping passes 1e6. ``proto`` and ``grad`` = (∂y, ∂x) are
    padded alike (see :func:`padded`).
    """
    from .._kernels import affine as _k

    n = len(params)
    params = np.ascontiguousarray(params, dtype=np.float64)
    JtJ = np.zeros((n, 7, 7))
    Jtr = np.zeros((n, 7))
    err = np.zeros(n)
    _k.lk_systems(proto, grad[0], grad[1], centre, centre, params, targets, weights, JtJ, Jtr, err)
    lam = np.full(n, 1e-3)
    active = np.ones(n, bool)
    eye = np.eye(7)
    for _ in range(iterations):
        idx = np.flatnonzero(active)
        if len(idx) == 0:
            break
        diag = np.einsum("kii->ki", JtJ[idx])
        A = JtJ[idx] + (lam[idx, None] * diag + 1e-12)[:, :, None] * eye
        try:
            step = np.linalg.solve(A, -Jtr[idx][..., None])[..., 0]
        except np.linalg.LinAlgError:  # a singular system (a flat patch): leave those as they are
            ok = np.linalg.cond(A) < 1e12
            step = np.zeros((len(idx), 7))
            if ok.any():
                step[ok] = np.linalg.solve(A[ok], -Jtr[idx][ok][..., None])[..., 0]
        trial = np.ascontiguousarray(params[idx] + step)
        J2 = np.zeros((len(idx), 7, 7))
        r2 = np.zeros((len(idx), 7))
        e2 = np.zeros(len(idx))
        _k.lk_systems(proto, grad[0], grad[1], centre, centre, trial, targets[idx], weights[idx], J2, r2, e2)
        better = e2 < err[idx]
        tiny = better & (e2 > err[idx] * (1.0 - 1e-7))
        acc = idx[better]
        params[acc] = trial[better]
        JtJ[acc] = J2[better]
        Jtr[acc] = r2[better]
        err[acc] = e2[better]
        lam[acc] = np.maximum(lam[acc] * 0.3, 1e-7)
        lam[idx[~better]] *= 10.0
        active[idx[tiny]] = False
        active[lam > 1e6] = False
    return params


def _central(patch: np.ndarray, B: int) -> np.ndarray:
    """The central B x B block of a square patch (the whole patch, zero-padded, if it is smaller)."""
    s = patch.shape[0]
    if s >= B:
        o = (s - B) // 2
        return patch[o:o + B, o:o + B]
    out = np.zeros((B, B), np.float32)
    o = (B - s) // 2
    out[o:o + s, o:o + s] = patch
    return out


def _check_geometry(shape, block: int, segments: int) -> None:
    if isinstance(block, bool) or not isinstance(block, (int, np.integer)) or block < 8 or block > 256 or block % 2:
        raise InvalidParameter(f"parameter 'block' = {block!r} must be an even integer in 8..256", name="block",
                               value=block)
    if isinstance(segments, bool) or not isinstance(segments, (int, np.integer)) or segments < 4 or segments % 2:
        raise InvalidParameter(f"parameter 'segments' = {segments!r} must be an even integer >= 4",
                               name="segments", value=segments)
    h, w = shape[:2]
    if min(h, w) < 8:
        raise ImageError(f"the texture is {w}x{h}; the affine model needs at least 8x8 pixels")
    if block > min(h, w):
        raise InvalidParameter(f"parameter 'block' = {block} is outside 8..{max(8, min(h, w))} (the patch must "
                               f"fit in the {w}x{h} image)", name="block", value=block)


def _as_prototype(model: AffineModel, prototype) -> Prototype:
    if prototype is None:
        return model.prototype
    if isinstance(prototype, Prototype):
        return prototype
    colour = model.decomposition.colour if model.decomposition is not None else "pca"
    return prototype_from_patch(prototype, block=model.block, colour=colour)


def render_signal(model: AffineModel, proto: Prototype) -> np.ndarray:
    """The prototype channel(s) a model renders: highpass grey (``add``), else the unfiltered
    colour patch if there is one, else the unfiltered grey; float32 (S, S, C)."""
    if model.lowpass == "add":
        sig = proto.highpass
    elif proto.colour is not None:
        sig = proto.colour
    else:
        sig = proto.grey
    sig = np.asarray(sig, dtype=np.float32)
    return np.ascontiguousarray(sig if sig.ndim == 3 else sig[..., None])


def render_canvas(model: AffineModel, proto: Prototype, index: np.ndarray | None = None) -> np.ndarray:
    """Sum of the windowed, normalised, warped prototypes on the padded canvas, (Hc, Wc, C) float32."""
    from .._kernels import affine as _k

    sig, c = padded(render_signal(model, proto))
    hc, wc = model.grid.canvas
    out = np.zeros((hc, wc, sig.shape[2]), np.float32)
    idx = np.arange(model.grid.count, dtype=np.int64) if index is None else np.asarray(index, dtype=np.int64)
    _k.render(sig, c, c, model.sampling, model.shifts.astype(np.float64), model.alpha, model.grid.origins(),
              cos2_window(model.block), idx, out)
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


def render(model: AffineModel, prototype: Prototype | np.ndarray | None = None, *,
           index: np.ndarray | None = None) -> np.ndarray:
    """Draw a model with its own prototype or a swapped one (§3, §4 "re-synthesizing based on the
    existing transformations").

    Each patch k is the prototype sampled through ``T_k⁻¹`` and moved by its translation,
    multiplied by its intensity factor and the cos² window, and summed into the canvas, which is
    cropped to the image (§3). Cheap enough for a live preview (a 256² texture with B = 32 renders
    in a few milliseconds): only warping, windowing and summing.

    Parameters
    ----------
    model : AffineModel
        From :func:`analyse` (or :func:`~core.affine.fields.field_model`, or after boundary matching).
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
