"""Analysis with the affine prototype model (Smith & Bhalerao §2, §3.2): for every target patch,
the affine transform and intensity factor that best map the prototype onto it.

:func:`analyse` runs the paper's per-patch search -- centroid pairs (§2.1), the eight candidate
transforms (§2.2), translations by correlation (§2.3), the choice by windowed RMS error with
intensity factors (§2.4, §3.2) -- and two additions, both on by default: the chosen transforms of
the neighbouring patches as further candidates (as §6 suggests: "take into account the surrounding
patches' transformations"), and a Levenberg-Marquardt refinement of the chosen transform and its
translation (:func:`levenberg_marquardt`). ``propagate=False, refine=0`` is the paper's pipeline.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from ..errors import ImageError, InvalidParameter
from ..image import validate_image
from ..jobs import CancelToken, Progress, ProgressReporter
from .model import AffineModel, Decomposition, Grid, Prototype, decompose, make_prototype, padded
from .params import LOWPASS, Rect
from .spectral import centroids, cos2_window
from .synthesis import render
from .transforms import _clamp_scale, candidate_transforms, correlate_indexed, sampling_matrices


def _patches(canvas: np.ndarray, grid: Grid) -> np.ndarray:
    B, h = grid.block, grid.step
    view = sliding_window_view(canvas, (B, B))[::h, ::h][: grid.rows, : grid.cols]
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
        the middle (:func:`~weft.core.affine.params.default_rect`). A :class:`Prototype` is used as is.
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
        raise InvalidParameter(
            f"parameter 'lowpass' = {lowpass!r} is not one of {', '.join(LOWPASS)}", name="lowpass", value=lowpass
        )
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
    return state.model(ctx, lowpass, proto, dec)


@dataclass
class _State:
    """The chosen transform of every patch while the analysis runs."""

    mats: np.ndarray  # (K, 2, 2) sampling
    shifts: np.ndarray  # (K, 2) float64
    alpha: np.ndarray  # (K,)
    err: np.ndarray  # (K,)
    choice: np.ndarray  # (K,) int8

    @classmethod
    def empty(cls, K: int) -> _State:
        return cls(
            np.tile(np.eye(2), (K, 1, 1)), np.zeros((K, 2)), np.zeros(K), np.full(K, np.inf), np.full(K, -1, np.int8)
        )

    def set(self, rows, mats, shifts, alpha, err, choice) -> None:
        self.mats[rows] = mats
        self.shifts[rows] = shifts
        self.alpha[rows] = alpha
        self.err[rows] = err
        self.choice[rows] = choice

    def model(self, ctx: _Context, lowpass, proto, dec) -> AffineModel:
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
    def build(cls, dec: Decomposition, proto: Prototype, block: int, lowpass: str) -> _Context:
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
        return cls(grid, hp, padded(cmp)[0], c, lowpass == "add", targets_hp, targets_hp * win, targets_cmp, weights)

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
        return self.evaluate_shared(
            np.ascontiguousarray(mats[:, :h]).reshape(-1, 2, 2), index, flip, rows, np.ascontiguousarray(mats)
        )

    def evaluate_shared(
        self, frame_mats: np.ndarray, index: np.ndarray, flip: np.ndarray, rows, mats: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
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
            _k.score_candidates(
                self.cmp,
                c,
                c,
                np.ascontiguousarray(mats),
                sh.astype(np.float64),
                self.targets_cmp[rows],
                self.weights[rows],
                alpha,
                err,
            )
        return sh.astype(np.float64), alpha, err

    def try_row(self, state: _State, row: int, other: int, base: int) -> np.ndarray:
        """Try, for every patch of ``row``, the chosen transforms of the patches of row ``other``
        diagonally before, straight across and diagonally after it; keep those that beat the
        current choice (choice code ``base`` + 0, 1, 2). Returns the mask of patches changed."""
        cols = self.grid.cols
        sl = slice(row * cols, (row + 1) * cols)
        frame_mats = state.mats[other * cols : (other + 1) * cols]
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
        params = levenberg_marquardt(self.hp, self.grad, c, params, self.targets_hp[sel], self.weights[sel], iterations)
        mats = np.ascontiguousarray(params[:, :4].reshape(-1, 2, 2))
        offsets = params[:, 4:6]
        # scales within [1/4, 4] (for M as for T = M^-1): also never singular
        mats = np.ascontiguousarray(_clamp_scale(mats))
        R = float(self.grid.radius)
        sh = np.ascontiguousarray(np.clip(-np.einsum("kij,kj->ki", np.linalg.inv(mats), offsets), -R, R))
        alpha = np.zeros((len(mats), 1))
        err = np.zeros((len(mats), 1))
        _k.score_candidates(
            self.cmp,
            c,
            c,
            mats[:, None].copy(),
            sh[:, None].copy(),
            self.targets_cmp[sel],
            self.weights[sel],
            alpha,
            err,
        )
        better = err[:, 0] <= state.err[sel]
        idx = sel[better]
        state.set(idx, mats[better], sh[better], alpha[better, 0], err[better, 0], state.choice[idx])


def levenberg_marquardt(
    proto: np.ndarray,
    grad: tuple,
    centre: float,
    params: np.ndarray,
    targets: np.ndarray,
    weights: np.ndarray,
    iterations: int,
) -> np.ndarray:
    """Refine affine maps by damped Gauss-Newton steps (an addition to the paper).

    Minimises, per patch, ``Σ_y (w(y) (g P(c + M y + o) - s_t(y)))²`` over ``params`` =
    (M00, M01, M10, M11, o_y, o_x, g) (n, 7), from the chosen candidate (``o = -M t``, gain
    ``g = 1``). A step that does not lower a patch's error is refused and its damping multiplied
    by 10 (accepted: divided by 3.3), so no patch gets worse; a patch stops when its error falls by
    less than 1e-7 of itself or its damping passes 1e6.

    Parameters
    ----------
    proto : ndarray
        The prototype's highpass grey, padded (see :func:`padded`).
    grad : (ndarray, ndarray)
        Its derivatives (∂y, ∂x), padded alike.
    centre : float
        The prototype's centre ``c`` in its padded coordinates.
    params : ndarray, float64 (n, 7)
        The start of each patch's map.
    targets : ndarray, (n, B, B)
        Each patch of the texture, ``s_t``.
    weights : ndarray, (n, B, B)
        Each patch's window ``w`` (the cosine-squared window of §3.1, 0 outside the image).
    iterations : int
        Most steps per patch.

    Returns
    -------
    ndarray, float64 (n, 7)
        The refined maps.

    References
    ----------
    Smith & Bhalerao, "Texture transfer using affine transformation groups and patch boundary
    matching", §2.4 (the minimum error transformation this polishes).
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
        return patch[o : o + B, o : o + B]
    out = np.zeros((B, B), np.float32)
    o = (B - s) // 2
    out[o : o + s, o : o + s] = patch
    return out


def _check_geometry(shape, block: int, segments: int) -> None:
    if isinstance(block, bool) or not isinstance(block, (int, np.integer)) or block < 8 or block > 256 or block % 2:
        raise InvalidParameter(
            f"parameter 'block' = {block!r} must be an even integer in 8..256", name="block", value=block
        )
    if isinstance(segments, bool) or not isinstance(segments, (int, np.integer)) or segments < 4 or segments % 2:
        raise InvalidParameter(
            f"parameter 'segments' = {segments!r} must be an even integer >= 4", name="segments", value=segments
        )
    h, w = shape[:2]
    if min(h, w) < 8:
        raise ImageError(f"the texture is {w}x{h}; the affine model needs at least 8x8 pixels")
    if block > min(h, w):
        raise InvalidParameter(
            f"parameter 'block' = {block} is outside 8..{max(8, min(h, w))} (the patch must fit in the {w}x{h} image)",
            name="block",
            value=block,
        )
