"""Fast texture transfer (Ashikhmin 2003) on top of coherent synthesis (Ashikhmin 2001).

The result is grown one pixel at a time in scan-line order. Each already synthesized pixel of the
causal L-shaped half of an n x n neighbourhood proposes the source pixel next to the one it was
copied from (its source position shifted forward by its offset); with probability ``p`` one
uniformly random source position is added, with probability ``p_l`` the location-specific one
(x/m, y/m); duplicates are removed, and the candidate whose neighbourhood matches best is copied.

Choices where the paper is silent (all documented here and in :func:`transfer`):

* Candidates whose n x n source neighbourhood would leave the source are **clamped** into the valid
  region (a clamped candidate is one more nearby choice, where dropping it leaves fewer). Candidates outside
  a user's source mask are dropped. A pixel left with no candidate (the first pixel, or all dropped)
  gets a random one. The location-specific candidate is clamped likewise.
* ``remap`` (default on, not in the paper, which found equalisation unnecessary): matching uses the
  source luminance linearly mapped to the target's mean and standard deviation, as in Hertzmann et
  al.'s image analogies (a target brighter or darker than the source is still followed); the output
  still copies the source's own pixels.
* The target part of eq. 1 is the complementary half of the square, centre included (Fig. 1b: "the
  bottom half from the target image"); the ``target`` metric uses only that part.
* ``n`` in the artistic metric is the number of L-shape pixels actually compared (fewer at borders).
* Passes after the first (``iterations > 1``) use the whole square minus its centre, from the
  previous pass's result where this pass has not reached yet, both to propose candidates and for the
  result part of the metric (as the 2001 paper's later passes); the target part stays as above.
* Synthesis runs on luminance. Colour ``target`` keeps the target's chroma (YIQ), as the paper does;
  ``source`` copies the chosen source pixels' colour. ``auto`` is ``target`` for transfer and novel
  styles, ``source`` for synthesis and super-resolution.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

import cv2
import numpy as np

from .errors import ImageError, InvalidParameter
from .image import luminance, resize, validate_image
from .jobs import CancelToken, Progress, ProgressReporter
from .params import Params, as_rng, out_of_range, param
from .registry import InputSpec, Method, Result
from .studio import SQUARE, Figure, Geometry, Studio

MODES = ("auto", "transfer", "synthesis", "superres", "novel")
# Metric codes of the kernel (weft.core._kernels.fast), which is imported on first use: importing numba
# costs a quarter of a second that `weft --help` or another method's run need not pay.
METRICS = {"full": 0, "target": 1, "artistic": 2}
_ROWS_PER_BAND = 16


@dataclass(frozen=True)
class FastParams(Params):
    """Parameters of fast texture transfer (Ashikhmin 2003)."""

    mode: str = param(
        "auto",
        choices=MODES,
        help="what is made: transfer = the target rendered in the texture; synthesis = more texture; "
        "superres = the picture magnified from itself; novel = the picture restyled from itself "
        "(Fig. 2); auto: transfer with a target, superres with --magnify > 1, else synthesis",
    )
    metric: str = param(
        "full",
        choices=tuple(METRICS),
        help="what a candidate must match: full = the result so far and the picture (eq. 1); target"
        " = the picture only (most faithful); artistic = tones and strokes, for drawings and "
        "paintings",
    )
    n: int = param(
        5,
        lo=3,
        hi=15,
        symbol="n",
        help="side of the neighbourhood compared (odd): small copies fine "
        "grain, large carries larger structures of the texture",
    )
    p: float | None = param(
        None,
        kind="float",
        lo=0.0,
        hi=1.0,
        optional=True,
        symbol="p",
        step=0.01,
        help="chance of a random candidate: 0 gives long coherent pieces of the texture, higher values"
        " follow the picture in smaller pieces; default 0.05 (super-resolution 0)",
    )
    p_l: float | None = param(
        None,
        kind="float",
        lo=0.0,
        hi=1.0,
        optional=True,
        symbol="p_l",
        step=0.01,
        help="chance of the candidate at the same place in the picture (x/m, y/m): higher keeps the "
        "original layout; default 0 (super-resolution 0.03)",
    )
    magnify: int = param(
        1,
        lo=1,
        hi=16,
        symbol="m",
        help="magnification: the result is the picture magnified m times (superres, novel); also "
        "the scale of the same-place candidate",
    )
    w: float = param(
        1.0,
        lo=0.0,
        hi=100.0,
        symbol="w",
        step=0.1,
        help="artistic metric: weight of the tones (neighbourhood averages) against the strokes; "
        "higher follows the picture's tones more closely",
    )
    target_weight: float = param(
        1.0,
        lo=0.0,
        hi=100.0,
        step=0.1,
        help="full metric: weight of matching the picture against matching the result so "
        "far; higher is more faithful, lower more coherent",
    )
    iterations: int = param(
        1, lo=1, hi=20, help="synthesis passes: later passes match every pixel again and smooth out early mistakes"
    )
    remap: bool = param(
        True,
        help="match against the texture's brightness remapped to the picture's mean and "
        "contrast (Hertzmann et al.), so a dark texture can render a bright picture; the"
        " output keeps the texture's own values",
    )
    colour: str = param(
        "auto",
        choices=("auto", "target", "source"),
        help="colour of the result: target keeps the picture's colours (YIQ chroma); source copies "
        "the texture's colours",
    )
    size: tuple[int, int] | None = param(
        None,
        kind="size",
        lo=8,
        hi=16384,
        optional=True,
        help="output size WIDTHxHEIGHT for synthesis; default twice the texture",
    )

    def check(self) -> None:
        if self.n % 2 == 0:
            raise InvalidParameter(f"parameter 'n' = {self.n} must be odd (3, 5, 7, ...)", name="n", value=self.n)

    def resolved(self, has_target: bool) -> FastParams:
        """The parameters with ``mode``, ``p``, ``p_l`` and ``colour`` made explicit."""
        mode = self.mode
        if mode == "auto":
            mode = "transfer" if has_target else ("superres" if self.magnify > 1 else "synthesis")
        if mode == "transfer" and not has_target:
            raise InvalidParameter("mode 'transfer' needs a target image (--target)", name="mode", value=mode)
        if mode != "transfer" and has_target:
            raise InvalidParameter(
                f"mode '{mode}' takes no target image; drop --target or use mode transfer", name="mode", value=mode
            )
        if self.metric in ("target", "artistic") and mode == "synthesis":
            raise InvalidParameter(
                f"metric '{self.metric}' needs a target; synthesis has none (use metric full)",
                name="metric",
                value=self.metric,
            )
        p = self.p if self.p is not None else (0.0 if mode == "superres" else 0.05)
        p_l = self.p_l if self.p_l is not None else (0.03 if mode == "superres" else 0.0)
        colour = self.colour
        if colour == "auto":
            colour = "target" if mode in ("transfer", "novel") else "source"
        return self.replace(mode=mode, p=p, p_l=p_l, colour=colour)


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
    from ._kernels import fast as _k

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
    match_y = src_y
    cand_mask, allowed = _valid_region((hs, ws), params.n, mask)

    if target is not None:
        tgt_y = luminance(target)
        height, width = tgt_y.shape
        sd = float(src_y.std())
        if params.remap and sd > 1e-6:
            match_y = ((src_y - src_y.mean()) * (float(tgt_y.std()) / sd) + float(tgt_y.mean())).astype(np.float32)
    else:
        width, height = params.size if params.size is not None else (2 * ws, 2 * hs)
        tgt_y = None
    h = params.n // 2
    metric = METRICS[params.metric]
    if tgt_y is not None:
        tgt_pad = cv2.copyMakeBorder(tgt_y, h, h, h, h, cv2.BORDER_REPLICATE)
    else:
        tgt_pad = np.zeros((1, 1), np.float32)
    if params.metric == "artistic":
        assert tgt_y is not None  # FastParams refuses the artistic metric without a target
        ksize = (params.n, params.n)
        src_mean = cv2.blur(match_y, ksize, borderType=cv2.BORDER_REFLECT)
        tgt_mean = cv2.blur(tgt_y, ksize, borderType=cv2.BORDER_REFLECT)
        res = tgt_y.copy()  # the paper: "I initialize the result by copying the target image into it"
    else:
        src_mean = tgt_mean = np.zeros((1, 1), np.float32)
        res = np.zeros((height, width), np.float32)
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


#: Peak memory per output pixel besides the inputs (result, positions, padded target, luminance and
#: colour copies, previews), fitted to the peak memory of ``weft fast`` transfers without the
#: libraries' share.
BYTES_PER_OUTPUT_PIXEL = 50


def _output_size(
    texture_shape: tuple[int, ...], target_shape: tuple[int, ...] | None, params: FastParams
) -> tuple[int, int, str]:
    """Width, height and what sets them (for messages) of a run on inputs of these shapes;
    ``params`` are resolved (:meth:`FastParams.resolved`)."""
    hs, ws = texture_shape[:2]
    if params.mode in ("superres", "novel"):
        return ws * params.magnify, hs * params.magnify, "parameter 'magnify'"
    if target_shape is not None:
        return target_shape[1], target_shape[0], "the target"
    width, height = params.size if params.size is not None else (2 * ws, 2 * hs)
    return width, height, "parameter 'size'"


def _check_limits(texture: np.ndarray, target: np.ndarray | None, params: FastParams) -> None:
    """Refuse up front an output over the pixel limit or beyond the memory available.

    No running-time limit: the method is linear in the output, so the pixel limit bounds a job to
    well under the ten minutes of :mod:`weft.core.limits`.
    """
    from .limits import check_memory, check_output_size

    width, height, source = _output_size(texture.shape, None if target is None else target.shape, params)
    check_output_size(width, height, source)
    check_memory(BYTES_PER_OUTPUT_PIXEL * width * height, f"fast transfer of {width}x{height}")


def memory_estimate(shapes: Mapping[str, tuple[int, ...]], params: FastParams) -> float:
    """Estimated peak bytes of one run on inputs of these shapes (what :func:`_check_limits` checks).

    Parameters
    ----------
    shapes : mapping of str to tuple of int
        Input name -> array shape.
    params : FastParams
        The run's parameters.

    Returns
    -------
    float
        Bytes.
    """
    target = shapes.get("target")
    width, height, _ = _output_size(shapes["texture"], target, params.resolved(target is not None))
    return BYTES_PER_OUTPUT_PIXEL * width * height


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


def _run(inputs: Mapping[str, np.ndarray], params: FastParams, *, rng=None, progress=None, cancel=None) -> Result:
    out, pos, resolved = _transfer(
        inputs["texture"],
        inputs.get("target"),
        params,
        mask=inputs.get("mask"),
        rng=rng,
        progress=progress,
        cancel=cancel,
    )
    # How often a pixel continues its left neighbour's patch (flat source index one further).
    cont = np.mean(pos[:, 1:] == pos[:, :-1] + 1) if pos.shape[1] > 1 else 0.0
    return Result(
        out,
        {
            "mode": resolved.mode,
            "metric": resolved.metric,
            "p": resolved.p,
            "p_l": resolved.p_l,
            "coherent_fraction": round(float(cont), 4),
        },
    )


def warm_up() -> None:
    """Load the compiled kernel for every metric (numba's cache) on a tiny input."""
    tiny = np.linspace(0.0, 1.0, 12 * 12, dtype=np.float32).reshape(12, 12)
    for metric in METRICS:
        transfer(tiny, tiny, metric=metric, n=3, rng=0)
    transfer(tiny, size=(8, 8), n=3, rng=0)


def _auto(params: FastParams, shapes: Mapping[str, tuple]) -> dict:
    """What "auto" resolves to with inputs of these shapes (the studio shows it beside the box)."""
    resolved = params.resolved("target" in shapes)
    return {name: getattr(resolved, name) for name in ("p", "p_l")}


def _limits(params: FastParams, shapes: Mapping[str, tuple]) -> dict:
    """The neighbourhood fits in the source texture (its source region)."""
    return {"n": (3, min(shapes["texture"][:2]))} if "texture" in shapes else {}


def _idle(params: FastParams, shapes: Mapping[str, tuple]) -> set:
    """Parameters that change nothing with these settings: each metric's own weight outside it."""
    idle = set()
    if params.metric != "artistic":
        idle.add("w")
    if params.metric != "full":
        idle.add("target_weight")
    return idle


METHOD = Method(
    name="fast",
    summary="fast texture transfer (Ashikhmin): live artistic styles, synthesis, super-resolution",
    params=FastParams,
    inputs=(
        InputSpec("texture", "the source texture (for superres and novel styles: the picture itself)", min_side=3),
        InputSpec("target", "the picture to render in the texture (transfer)", required=False),
        InputSpec("mask", "source mask: candidates come only from its white part", required=False),
    ),
    run=_run,
    warm_up=warm_up,
    memory=memory_estimate,
    studio=Studio(
        title="Fast texture transfer (Ashikhmin)",
        canvas="texture",
        geometry=(
            Geometry(SQUARE, on=("texture",), help="drag a square: the source region (the method copies only from it)"),
        ),
        preview_inputs=("target",),
        preview_params=("size",),
        auto=_auto,
        limits=_limits,
        idle=_idle,
        compare=("target", "texture"),
        examples={"texture": "wood-grain", "target": "astronaut"},
        rank=0,
        figures={
            "mode": Figure("mode"),
            "metric": Figure("metric"),
            "p": Figure("random candidates", "%", digits=2),
            "p_l": Figure("location candidates", "%", digits=2),
            "coherent_fraction": Figure("coherent pixels", "%", digits=2),
        },
    ),
)
