"""The synthesis of fast texture transfer: a result grown pixel by pixel in scan-line order, in bands of
rows (the kernel ``weft.core._kernels.fast.coherent_rows``); see the package docstring for the choices
where the paper is silent.
"""

from __future__ import annotations

from collections.abc import Callable

import cv2
import numpy as np

from ..errors import ImageError
from ..image import luminance, resize, validate_image
from ..jobs import CancelToken, Progress, ProgressReporter
from ..params import as_rng, out_of_range
from .checks import _check_limits
from .params import METRICS, FastParams

#: Rows per call of the kernel: progress, previews and cancelling go by bands of this many rows.
_ROWS_PER_BAND = 16


def _offsets(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(causal L, square without centre, complementary half with centre) offsets as (k, 2) int32."""
    h = n // 2
    causal: list[tuple[int, int]] = []
    square: list[tuple[int, int]] = []
    rest: list[tuple[int, int]] = []
    for dy in range(-h, h + 1):
        for dx in range(-h, h + 1):
            is_causal = dy < 0 or (dy == 0 and dx < 0)
            (causal if is_causal else rest).append((dy, dx))
            if (dy, dx) != (0, 0):
                square.append((dy, dx))
    c, s, r = (np.array(o, dtype=np.int32).reshape(-1, 2) for o in (causal, square, rest))
    return c, s, r


def _valid_region(source_shape: tuple[int, int], n: int, mask: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """The candidate mask (uint8) and the list of allowed positions (K, 2)."""
    hs, ws = source_shape
    h = n // 2
    if hs < n or ws < n:
        raise out_of_range(
            "n", n, 3, min(hs, ws), f"the neighbourhood must fit in the source, {ws}x{hs}", input="texture"
        )
    allowed = np.zeros((hs, ws), dtype=np.uint8)
    allowed[h : hs - h, h : ws - h] = 1
    if mask is not None:
        if mask.shape[:2] != (hs, ws):
            raise ImageError(f"source mask is {mask.shape[1]}x{mask.shape[0]}, the texture {ws}x{hs}: they must match")
        allowed &= (luminance(mask) > 0.5).astype(np.uint8)
    ys, xs = np.nonzero(allowed)
    if len(ys) == 0:
        raise ImageError("source mask leaves no usable position (white = allowed, away from the border by n/2)")
    return allowed, np.stack([ys, xs], axis=1).astype(np.int32)


def transfer(
    texture: np.ndarray,
    target: np.ndarray | None = None,
    *,
    mode: str = "auto",
    metric: str = "full",
    n: int = 5,
    p: float | None = None,
    p_l: float | None = None,
    magnify: int = 1,
    w: float = 1.0,
    target_weight: float = 1.0,
    iterations: int = 1,
    remap: bool = True,
    colour: str = "auto",
    size: tuple[int, int] | None = None,
    mask: np.ndarray | None = None,
    rng: None | int | np.random.Generator = None,
    progress: Callable[[Progress], None] | None = None,
    cancel: CancelToken | None = None,
) -> np.ndarray:
    """Fast texture transfer, coherent synthesis, super-resolution and novel styles (Ashikhmin 2003).

    Parameters
    ----------
    texture : float32 (Hs, Ws) or (Hs, Ws, 3) in [0, 1]
        The source texture (for ``superres`` and ``novel``: the picture itself).
    target : float32 (H, W) or (H, W, 3), optional
        The picture to render in the texture (``transfer`` mode).
    mode : {"auto", "transfer", "synthesis", "superres", "novel"}
        ``synthesis``: the 2001 coherent synthesis of ``size``; ``superres``: target = texture
        magnified ``magnify`` times by a cubic filter, source = texture, p = 0 and p_l = 0.03 by
        default (section "Super resolution"); ``novel``: the same set-up with the target's colour
        kept, for artistic styles without an extra sample (Fig. 2). ``auto`` picks transfer with a
        target, superres when ``magnify > 1``, else synthesis.
    metric : {"full", "target", "artistic"}
        ``full``: eq. 1, L-shaped result part + ``target_weight`` x target part; ``target``: the
        target part only; ``artistic``: w (mean N_s - mean N_t)^2 + (1/n)^2 D^2 of the mean-removed
        L-shapes, with the result initialised to a copy of the target.
    n : odd int, 3..15, default 5
        Neighbourhood side.
    p, p_l : float in [0, 1], optional
        Probabilities of the random and the location-specific extra candidate (defaults above).
    magnify : int, 1..16, default 1
        m: magnification for superres/novel, and the scale of the location-specific candidate
        (x/m, y/m).
    w : float, 0..100, default 1
        Weight of the average term of the artistic metric.
    target_weight : float, 0..100, default 1
        Relative weight of the target part in the full metric.
    iterations : int, 1..20, default 1
        Synthesis passes (later passes use the whole square; see the module docstring).
    remap : bool, default True
        Match against the source luminance mapped to the target's mean and standard deviation
        (module docstring); no effect without a target.
    colour : {"auto", "target", "source"}
        Output colour (module docstring). The output has 3 channels when the colour comes from an
        RGB image, else 1.
    size : (width, height), optional
        Output size for synthesis (default twice the texture).
    mask : float32 (Hs, Ws) or (Hs, Ws, 3), optional
        Source mask: candidates only come from where it is white (> 0.5).
    rng, progress, cancel
        Seed or Generator (same seed, same pixels); progress callback (per band of 16 rows, with a
        preview); cancel token (checked per band).

    Returns
    -------
    float32 array (H, W) or (H, W, 3).
    """
    params = FastParams(
        mode=mode,
        metric=metric,
        n=n,
        p=p,
        p_l=p_l,
        magnify=magnify,
        w=w,
        target_weight=target_weight,
        iterations=iterations,
        remap=remap,
        colour=colour,
        size=size,
    )
    out, _, _ = _transfer(texture, target, params, mask=mask, rng=rng, progress=progress, cancel=cancel)
    return out


def _transfer(texture, target, params: FastParams, *, mask=None, rng=None, progress=None, cancel=None):
    from .._kernels import fast as _k

    texture = validate_image(texture, "texture")
    if target is not None:
        target = validate_image(target, "target")
    if mask is not None:
        mask = validate_image(mask, "source mask")
    params = params.resolved(target is not None)
    rng = as_rng(rng)
    mode, m = params.mode, params.magnify
    _check_limits(texture, target, params)

    if mode in ("superres", "novel"):
        hs, ws = texture.shape[:2]
        target = resize(texture, (ws * m, hs * m), interpolation="cubic")
    src_y = luminance(texture)
    hs, ws = src_y.shape
    cand_mask, allowed = _valid_region((hs, ws), params.n, mask)

    tgt_y, match_y, width, height = _matching(src_y, target, params)
    h = params.n // 2
    metric = METRICS[params.metric]
    tgt_pad, src_mean, tgt_mean, res = _metric_planes(match_y, tgt_y, width, height, params)
    pos = np.zeros((height, width), np.int32)  # flat source index y * ws + x
    state = np.array([rng.integers(1, 2**63, dtype=np.uint64)], dtype=np.uint64)
    causal, square, rest = _offsets(params.n)

    bands = -(-height // _ROWS_PER_BAND)
    report = ProgressReporter(progress, "fast transfer", bands * params.iterations)
    done = 0
    for it in range(params.iterations):
        res_offs = causal if it == 0 else square
        for y0 in range(0, height, _ROWS_PER_BAND):
            if cancel is not None:
                cancel.raise_if_cancelled()
            y1 = min(height, y0 + _ROWS_PER_BAND)
            _k.coherent_rows(
                match_y,
                src_mean,
                tgt_pad,
                tgt_mean,
                res,
                pos,
                allowed,
                cand_mask,
                res_offs,
                rest,
                y0,
                y1,
                h,
                metric,
                tgt_y is not None,
                params.target_weight,
                params.w,
                params.p,
                params.p_l,
                m,
                state,
            )
            done += 1
            report.update(done, preview=lambda: _colourize(pos, src_y, texture, target, tgt_y, params.colour))
    return _colourize(pos, src_y, texture, target, tgt_y, params.colour), pos, params


def _matching(
    src_y: np.ndarray, target: np.ndarray | None, params: FastParams
) -> tuple[np.ndarray | None, np.ndarray, int, int]:
    """The target's luminance (None without a target), the source luminance the neighbourhoods are
    matched on (remapped to the target's mean and spread with ``remap``), and the output size."""
    hs, ws = src_y.shape
    match_y = src_y
    if target is not None:
        tgt_y = luminance(target)
        height, width = tgt_y.shape
        sd = float(src_y.std())
        if params.remap and sd > 1e-6:
            match_y = ((src_y - src_y.mean()) * (float(tgt_y.std()) / sd) + float(tgt_y.mean())).astype(np.float32)
    else:
        width, height = params.size if params.size is not None else (2 * ws, 2 * hs)
        tgt_y = None
    return tgt_y, match_y, width, height


def _metric_planes(
    match_y: np.ndarray, tgt_y: np.ndarray | None, width: int, height: int, params: FastParams
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """What the kernel's metric reads besides the source: the target padded by n/2, the local means
    of source and target (artistic metric), and the result it starts from."""
    h = params.n // 2
    if tgt_y is not None:
        tgt_pad = cv2.copyMakeBorder(tgt_y, h, h, h, h, cv2.BORDER_REPLICATE)
    else:
        tgt_pad = np.zeros((1, 1), np.float32)
    if params.metric == "artistic":
        ksize = (params.n, params.n)
        assert tgt_y is not None  # FastParams refuses the artistic metric without a target
        src_mean = cv2.blur(match_y, ksize, borderType=cv2.BORDER_REFLECT)
        tgt_mean = cv2.blur(tgt_y, ksize, borderType=cv2.BORDER_REFLECT)
        res = tgt_y.copy()  # the paper: "I initialize the result by copying the target image into it"
    else:
        src_mean = tgt_mean = np.zeros((1, 1), np.float32)
        res = np.zeros((height, width), np.float32)
    return tgt_pad, src_mean, tgt_mean, res


def _colourize(pos, src_y, texture, target, tgt_y, colour) -> np.ndarray:
    """The output image from the chosen source positions (flat indices; see ``colour``).

    Keeping the target's chroma means replacing Y in YIQ and converting back; YIQ -> RGB is linear
    and its Y column is (1, 1, 1), so that is ``target + (Y_new - Y_target)`` on every channel,
    then clipped to [0, 1] -- the same pixels as going through YIQ, at a fraction of the cost.
    """
    if colour == "source" and texture.ndim == 3:
        return texture.reshape(-1, 3)[pos]
    lum = src_y.ravel()[pos]
    if colour == "source" or target is None or target.ndim == 2:
        return lum
    out = target + (lum - tgt_y)[..., None]
    return np.clip(out, 0.0, 1.0, out=out)
