"""Quilting texture transfer, E&F §3 and Ngo's iterative transfer: :func:`transfer`."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..errors import ImageError, InvalidParameter
from ..grid import block_grid
from ..image import luminance, validate_image
from ..jobs import CancelToken, Progress, ProgressReporter
from ..params import as_rng
from .checks import (
    _check_block_fits,
    _check_limits,
    _check_overlap,
    _check_texture,
    _check_tile_size,
    _finish,
    _transfer_passes,
)
from .engine import _Pass, _quilt_pass
from .params import CORR_SIGMA, QuiltParams

# --------------------------------------------------------------------------------------------
# transfer


def _remap(cs: np.ndarray, ct: np.ndarray) -> np.ndarray:
    """Hertzmann et al. (2001) luminance remapping: ``ct`` linearly mapped to ``cs``'s mean and deviation."""
    sd_t = float(ct.std())
    scale = float(cs.std()) / sd_t if sd_t > 1e-6 else 1.0
    return np.ascontiguousarray((ct - ct.mean()) * scale + cs.mean(), dtype=np.float32)


def _correspondence_maps(tex, target, kind, source_map, target_map):
    import cv2

    if (source_map is None) != (target_map is None):
        missing = "target_map" if target_map is None else "source_map"
        raise InvalidParameter(
            f"parameter '{missing}' is required when the other correspondence map is given", name=missing
        )
    if source_map is not None:
        sm = validate_image(source_map, "source map")
        tm = validate_image(target_map, "target map")
        for m, ref, what, of in ((sm, tex, "source map", "texture"), (tm, target, "target map", "target")):
            if m.shape[:2] != ref.shape[:2]:
                raise ImageError(
                    f"{what} is {m.shape[1]}x{m.shape[0]} but the {of} is "
                    f"{ref.shape[1]}x{ref.shape[0]}; they must be the same size"
                )
        cs = luminance(sm) if sm.ndim == 3 else sm
        ct = luminance(tm) if tm.ndim == 3 else tm
        return np.ascontiguousarray(cs, np.float32), np.ascontiguousarray(ct, np.float32)
    cs = luminance(tex[..., 0] if tex.shape[2] == 1 else tex)
    ct = luminance(target)
    if kind == "blur":
        cs = cv2.GaussianBlur(cs, (0, 0), CORR_SIGMA)
        ct = cv2.GaussianBlur(ct, (0, 0), CORR_SIGMA)
    return np.ascontiguousarray(cs, np.float32), np.ascontiguousarray(ct, np.float32)


def transfer(
    texture: np.ndarray,
    target: np.ndarray,
    *,
    block: int | None = None,
    overlap: int | None = None,
    alpha: float = 0.1,
    iterations: int = 1,
    mode: str = "mincut",
    correspondence: str = "blur",
    source_map: np.ndarray | None = None,
    target_map: np.ndarray | None = None,
    tol: int | None = None,
    rule: str = "tol",
    epsilon: float = 0.1,
    remap: bool = True,
    tile: bool = False,
    poisson: bool = False,
    band: int = 4,
    return_all: bool = False,
    rng: None | int | np.random.Generator = None,
    progress: Callable[[Progress], None] | None = None,
    cancel: CancelToken | None = None,
) -> np.ndarray | list[np.ndarray]:
    """Texture transfer: re-render ``target`` with blocks of ``texture`` (E&F §3).

    Parameters
    ----------
    texture : float32 array (h, w) or (h, w, 3) in [0, 1]
        The texture the result is made of.
    target : float32 array (H, W) or (H, W, 3)
        The picture the result follows; the result has its size and the texture's channels.
    block : int, optional
        Block side, 2..min(h, w). Default 9 for one pass (Ngo), 31 for ``iterations`` > 1 (Ngo's
        31 / 21 down to 9 / 3). With iterations it is the first pass's block.
    overlap : int, optional
        Overlap, 1..block-1. Default round(block / 3) for one pass (9 -> 3), round(2 block / 3)
        for iterative transfer (31 -> 21).
    alpha : float, default 0.1
        Weight of the overlap error, 0..1; the correspondence error gets 1 - alpha (E&F §3).
    iterations : int, default 1
        Passes N, 1..10; see :func:`transfer_schedule` for the block, overlap and alpha of each.
        Passes after the first add ``alpha_i`` times the SSD between the candidate and the previous
        pass's result over the whole block, as the Poisson write-up's
        ``error = alpha (overlap + previous) + (1 - alpha) correspondence``.
    mode : {"overlap", "mincut"}, default "mincut"
        As in :func:`synthesize`; the cut uses the overlap error only (the correspondence decides
        which block, the seam goes where the two blocks agree).
    correspondence : {"blur", "luminance"}, default "blur"
        Correspondence maps of texture and target: their Rec. 601 luminance blurred by a Gaussian
        of sigma 2 pixels (E&F: "blurred luminance") or unblurred.
    source_map, target_map : arrays, optional
        User-given correspondence maps (both or neither), the texture's and the target's size;
        colour maps are reduced to luminance. They replace ``correspondence``.
    remap : bool, default True
        Map the target's correspondence map linearly to the texture map's mean and standard
        deviation first (Hertzmann et al. 2001's luminance remapping; not in E&F). Without it a
        target brighter or darker than most of the texture is rendered from the texture's few
        extreme spots, repeated (a bright sky becomes one bright stone tiled). ``False`` is the
        papers' behaviour.
    tol, rule, epsilon
        Position rule as in :func:`synthesize`; transfer takes the best (tol None means 1, Ngo), the
        first block being the best correspondence.
    tile, poisson, band
        As in :func:`synthesize` (a tileable transfer wraps the texture seamlessly; the target is
        not periodic, so its picture may not continue across the wrap).
    return_all : bool, default False
        Return the list of every pass's result instead of the last one.
    rng, progress, cancel
        As in :func:`synthesize`; the progress stage is ``"transfer i/N"``, once per block row.

    Returns
    -------
    float32 array (H, W[, 3]) with the texture's channels, or a list of them (``return_all``).
    """
    params = QuiltParams(
        mode=mode,
        block=block,
        overlap=overlap,
        tol=tol,
        rule=rule,
        epsilon=epsilon,
        tile=tile,
        poisson=poisson,
        band=band,
        iterations=iterations,
        alpha=alpha,
        correspondence=correspondence,
        remap=remap,
    )
    return _transfer(
        texture,
        target,
        params,
        source_map=source_map,
        target_map=target_map,
        return_all=return_all,
        rng=rng,
        progress=progress,
        cancel=cancel,
    )


def _transfer(
    texture: np.ndarray,
    target: np.ndarray,
    params: QuiltParams,
    *,
    source_map=None,
    target_map=None,
    return_all: bool = False,
    rng=None,
    progress=None,
    cancel=None,
) -> np.ndarray | list[np.ndarray]:
    """:func:`transfer` with its options in ``params`` (``None`` tol: the transfer default, 1)."""
    if params.tol is None:
        params = params.replace(tol=1)
    if params.mode == "random":
        raise InvalidParameter(
            "parameter 'mode' = 'random' is not one of overlap, mincut (transfer matches blocks on their overlap)",
            name="mode",
            value="random",
        )
    tex = _check_texture(texture)
    tgt = validate_image(target, "target")
    H, W = tgt.shape[:2]
    n = params.iterations
    schedule = _transfer_passes(params)
    b, ov = schedule[0][:2]
    _check_block_fits(b, tex)
    if params.overlap is not None:
        _check_overlap(b, params.overlap)
    if params.tile:
        _check_tile_size(b, W, H)
    _check_limits(tex, W, H, [(bi, oi) for bi, oi, _ in schedule], tile=params.tile, transfer=True)
    cs, ct = _correspondence_maps(tex, tgt, params.correspondence, source_map, target_map)
    if params.remap:
        ct = _remap(cs, ct)
    rng = as_rng(rng)
    results = []
    prev = None
    for i, (bi, oi, ai) in enumerate(schedule):
        p = _Pass(
            params.mode,
            bi,
            oi,
            params.rule,
            params.tol or 1,
            params.epsilon,
            params.tile,
            params.poisson,
            params.band,
            w_overlap=ai,
            w_prev=ai if i > 0 else 0.0,
            w_corr=1.0 - ai,
        )
        rows = len(block_grid(H, bi, oi, params.tile)[0])
        report = ProgressReporter(progress, f"transfer {i + 1}/{n}", rows)
        img, _ = _quilt_pass(
            tex, H, W, p, rng, prev=prev, corr=(cs, ct), report=report, cancel=cancel, channels_out=tex.shape[2]
        )
        prev = np.ascontiguousarray(img)
        results.append(_finish(img, tex.shape[2]))
    return results if return_all else results[-1]
