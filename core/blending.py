"""Blending images: Poisson (gradient-domain) blending and Laplacian-pyramid compositing.

* :func:`poisson_blend` -- Pérez, Gangnet & Blake's seamless cloning on an arbitrary mask: inside
  the mask the result has the source's gradients, on the mask's border it meets the target. The
  quilting write-up (``image-quilting-poisson-blending.txt``, "Poisson Blending") runs it on a
  band of at most 5 pixels around every seam; ``weft.core.quilting`` does that block by block with the
  same solver (``weft.core._kernels.poisson.poisson_cg``).
* :func:`pyramid_blend` -- Burt & Adelson's multiresolution spline: the Laplacian pyramids of the
  two images are mixed level by level with a Gaussian pyramid of the mask and collapsed, the
  "face in toast" compositing step of Ngo's write-up.

``weft blend FOREGROUND BACKGROUND --mask MASK -o OUT --levels k`` runs either from the command
line (:data:`METHOD`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from .errors import ImageError, InvalidParameter
from .image import luminance, validate_image
from .params import Params, out_of_range, param
from .registry import InputSpec, Method, Result

__all__ = ["BlendParams", "max_levels", "poisson_blend", "pyramid_blend", "METHOD"]


# --------------------------------------------------------------------------------------------
# shared checks


def _as_colour_pair(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Grey + colour -> both colour (the grey one repeated), so the pair can be mixed."""
    if a.ndim == 3 and b.ndim == 2:
        b = np.repeat(b[..., None], 3, axis=2)
    elif a.ndim == 2 and b.ndim == 3:
        a = np.repeat(a[..., None], 3, axis=2)
    return a, b


def _check_pair(first: np.ndarray, second: np.ndarray, names: tuple[str, str]) -> tuple[np.ndarray, np.ndarray]:
    a = validate_image(first, names[0])
    b = validate_image(second, names[1])
    if a.shape[:2] != b.shape[:2]:
        raise ImageError(
            f"{names[0]} is {a.shape[1]}x{a.shape[0]} but {names[1]} is {b.shape[1]}x{b.shape[0]}; "
            "they must be the same size"
        )
    return _as_colour_pair(a, b)


def _check_mask(mask, shape: tuple[int, int], what: str = "mask") -> np.ndarray:
    m = np.asarray(mask)
    if m.dtype == bool:
        m = m.astype(np.float32)
    if m.ndim == 3 and m.shape[2] == 1:
        m = m[..., 0]
    if m.ndim not in (2, 3) or (m.ndim == 3 and m.shape[2] != 3):
        raise ImageError(f"{what} must be (H, W) or (H, W, 3), not shape {m.shape}")
    if m.shape[:2] != tuple(shape):
        raise ImageError(
            f"{what} is {m.shape[1]}x{m.shape[0]} but the images are {shape[1]}x{shape[0]}; they must be the same size"
        )
    m = validate_image(m, what)
    return luminance(m) if m.ndim == 3 else m


# --------------------------------------------------------------------------------------------
# Poisson blending


def poisson_blend(
    target: np.ndarray,
    source: np.ndarray,
    mask: np.ndarray,
    *,
    tol: float = 1e-6,
    max_iter: int | None = None,
    wrap: bool = False,
) -> np.ndarray:
    """Seamless cloning: inside ``mask`` the result has ``source``'s gradients and meets ``target``.

    Solves the discrete Poisson equation of Pérez et al. (2003), eq. 7, on the pixels of the mask:
    for every masked pixel p with 4-neighbours N(p) inside the image,
    ``|N(p)| f_p - sum_{q in N(p), masked} f_q = sum_{q in N(p)} (s_p - s_q) + sum_{q in N(p), unmasked} t_q``,
    i.e. the Laplacian of the result equals the source's Laplacian and the result equals the target
    on the mask's border (Dirichlet). Image borders are Neumann (no neighbour, no term), unless
    ``wrap``. The quilting write-up applies exactly this with the existing pixels as the source of
    gradients and the quilt after pasting as the target, on a band of at most 5 pixels around each
    seam (``weft.core.quilting``, ``--poisson``).

    Parameters
    ----------
    target : ndarray, float32 in [0, 1], (H, W) or (H, W, 3)
        The image outside the mask (and the initial guess inside it).
    source : ndarray, same height and width
        The image whose gradients fill the mask. Grey and colour may be mixed (grey is repeated).
    mask : ndarray (H, W), bool or [0, 1]
        The region to solve; values > 0.5 count as inside.
    tol : float, default 1e-6
        Conjugate-gradient stop: residual norm <= tol * norm of the right-hand side (0 < tol < 1).
    max_iter : int >= 1, optional
        Iteration limit per channel; default 20 * sqrt(masked pixels) + 200.
    wrap : bool, default False
        Neighbours wrap around the image borders (for tileable images).

    Returns
    -------
    ndarray, float32, clipped to [0, 1]; colour if either image is colour.

    Notes
    -----
    The system is symmetric positive definite when every connected part of the mask touches an
    unmasked pixel; it is solved by (matrix-free) conjugate gradient, channel by channel. A part that
    touches none (e.g. a mask covering the whole image) is only defined up to a constant: CG then
    keeps the target's mean there.
    """
    t, s = _check_pair(target, source, ("target", "source"))
    h, w = t.shape[:2]
    m = _check_mask(mask, (h, w)) > 0.5
    if isinstance(tol, bool) or not isinstance(tol, (int, float, np.integer, np.floating)) or not 0 < tol < 1:
        raise InvalidParameter(f"parameter 'tol' = {tol!r} is outside 0..1", name="tol", value=tol)
    if max_iter is not None and (
        isinstance(max_iter, bool) or not isinstance(max_iter, (int, np.integer)) or max_iter < 1
    ):
        raise InvalidParameter(
            f"parameter 'max_iter' = {max_iter!r} must be an integer >= 1 (or None: the default)",
            name="max_iter",
            value=max_iter,
        )
    t3 = t.reshape(h, w, -1).astype(np.float64)
    s3 = s.reshape(h, w, -1).astype(np.float64)
    n = int(m.sum())
    if n == 0:
        return t.copy()
    if max_iter is None:
        max_iter = int(20 * np.sqrt(n)) + 200
    index = np.full((h, w), -1, dtype=np.int64)
    ys, xs = np.nonzero(m)
    index[ys, xs] = np.arange(n)
    nbr = np.full((n, 4), -1, dtype=np.int64)
    ndeg = np.zeros(n)
    rhs = np.zeros((n, t3.shape[2]))
    for k, (dy, dx) in enumerate(((1, 0), (-1, 0), (0, 1), (0, -1))):
        qy, qx = ys + dy, xs + dx
        if wrap:
            qy %= h
            qx %= w
            valid = np.ones(n, dtype=bool)
        else:
            valid = (qy >= 0) & (qy < h) & (qx >= 0) & (qx < w)
        i = np.nonzero(valid)[0]
        qy, qx = qy[valid], qx[valid]
        ndeg[i] += 1
        rhs[i] += s3[ys[i], xs[i]] - s3[qy, qx]
        j = index[qy, qx]
        inside = j >= 0
        nbr[i[inside], k] = j[inside]
        rhs[i[~inside]] += t3[qy[~inside], qx[~inside]]
    x = t3[ys, xs].copy()
    from ._kernels import poisson as _k  # numba loads on first use

    _k.poisson_cg(nbr, ndeg, rhs, x, float(tol), int(max_iter))
    out = t3.copy()
    out[ys, xs] = x
    out = np.clip(out, 0.0, 1.0).astype(np.float32)
    return out.reshape(t.shape)


# --------------------------------------------------------------------------------------------
# Laplacian-pyramid blending


def max_levels(height: int, width: int) -> int:
    """Most pyramid levels an image of this size allows (the coarsest level at least 1 pixel).

    Parameters
    ----------
    height, width : int
        The image's size in pixels.

    Returns
    -------
    int
        ``floor(log2(min(height, width))) + 1`` (1 for an image of one pixel).

    References
    ----------
    Burt & Adelson, "A multiresolution spline with application to image mosaics" (1983), as used in
    Ngo's quilting write-up ("Bells and Whistles": Laplacian blending).
    """
    return int(np.floor(np.log2(max(1, min(height, width))))) + 1


def pyramid_blend(foreground: np.ndarray, background: np.ndarray, mask: np.ndarray, *, levels: int = 5) -> np.ndarray:
    """Composite ``foreground`` over ``background`` with a Laplacian-pyramid (multiresolution) blend.

    Burt & Adelson (1983), as used for the "face in toast" in Ngo's quilting write-up: build the
    Laplacian pyramids of both images and the Gaussian pyramid of the mask, mix every level as
    ``G_mask * L_fg + (1 - G_mask) * L_bg``, and collapse. Low frequencies are thus mixed over a wide
    transition and fine detail over a narrow one, so the seam disappears without ghosting.

    Parameters
    ----------
    foreground, background : ndarray, float32 in [0, 1], (H, W) or (H, W, 3), same height and width
        Grey and colour may be mixed (the grey one is repeated into three channels).
    mask : ndarray (H, W) (or (H, W, 3), reduced to luminance), in [0, 1] or bool
        1 where the foreground shows, 0 where the background does; soft values mix.
    levels : int, default 5
        Pyramid levels, 1..max_levels(H, W) (the coarsest level at least one pixel). 1 is a plain
        per-pixel mix by the mask.

    Returns
    -------
    ndarray, float32, clipped to [0, 1]. A mask of all ones gives the foreground, all zeros the
    background (up to float rounding).

    Notes
    -----
    Pyramids use OpenCV's 5-tap binomial ``pyrDown``/``pyrUp`` (reflected borders); odd sizes are
    handled by giving ``pyrUp`` the finer level's exact size, so the collapse reconstructs each
    image exactly.
    """
    import cv2

    fg, bg = _check_pair(foreground, background, ("foreground", "background"))
    h, w = fg.shape[:2]
    m = _check_mask(mask, (h, w))
    top = max_levels(h, w)
    if isinstance(levels, bool) or not isinstance(levels, (int, np.integer)):
        raise InvalidParameter(f"parameter 'levels' = {levels!r} must be an integer", name="levels", value=levels)
    if not 1 <= levels <= top:
        raise out_of_range(
            "levels", int(levels), 1, top, f"a {w}x{h} image has at most {top} pyramid levels", input="foreground"
        )
    fg = fg.astype(np.float32)
    bg = bg.astype(np.float32)
    gm: list[np.ndarray] = [m.astype(np.float32)]
    gf: list[np.ndarray] = [fg]
    gb: list[np.ndarray] = [bg]
    for _ in range(levels - 1):
        gf.append(cv2.pyrDown(gf[-1]))
        gb.append(cv2.pyrDown(gb[-1]))
        gm.append(cv2.pyrDown(gm[-1]))
    out: np.ndarray | None = None
    for lev in range(levels - 1, -1, -1):
        mk = gm[lev] if fg.ndim == 2 else gm[lev][..., None]
        if lev == levels - 1:
            lf, lb = gf[lev], gb[lev]
        else:
            size = (gf[lev].shape[1], gf[lev].shape[0])
            lf = gf[lev] - cv2.pyrUp(gf[lev + 1], dstsize=size)
            lb = gb[lev] - cv2.pyrUp(gb[lev + 1], dstsize=size)
        mixed = mk * lf + (1.0 - mk) * lb
        if out is None:
            out = mixed
        else:
            out = mixed + cv2.pyrUp(out, dstsize=(mixed.shape[1], mixed.shape[0]))
    assert out is not None  # levels >= 1, so the loop ran
    return np.clip(out, 0.0, 1.0).astype(np.float32)


# --------------------------------------------------------------------------------------------
# the `weft blend` command


@dataclass(frozen=True)
class BlendParams(Params):
    """Parameters of ``weft blend``."""

    mode: str = param(
        "pyramid",
        choices=("pyramid", "poisson"),
        help="how the pictures meet: pyramid = a soft Laplacian-pyramid blend that keeps each "
        "picture's colours; poisson = seamless cloning, the foreground takes on the background's"
        " colours at its edge",
    )
    levels: int = param(
        5,
        lo=1,
        hi=16,
        symbol="k",
        help="pyramid levels (pyramid mode): more levels give a wider, softer transition; at most "
        "log2 of the image's smaller side + 1",
    )


def _run(inputs: Mapping[str, np.ndarray], params: BlendParams, *, rng=None, progress=None, cancel=None) -> Result:
    fg, bg, mask = inputs["foreground"], inputs["background"], inputs["mask"]
    if cancel is not None:
        cancel.raise_if_cancelled()
    if params.mode == "pyramid":
        image = pyramid_blend(fg, bg, mask, levels=params.levels)
        figures = {"levels": params.levels}
    else:
        image = poisson_blend(bg, fg, mask)
        figures = {"masked_pixels": int((_check_mask(mask, bg.shape[:2]) > 0.5).sum())}
    return Result(image, figures)


def warm_up() -> None:
    """Load (or compile) the numba Poisson solver on a tiny input (for the GUI's background start-up;
    ``METHOD.warm_up_in_cli`` is False so that ``weft blend`` in pyramid mode never loads numba)."""
    img = np.linspace(0, 1, 64, dtype=np.float32).reshape(8, 8)
    mask = np.zeros((8, 8), dtype=bool)
    mask[2:6, 2:6] = True
    poisson_blend(img, img[::-1], mask)


METHOD = Method(
    name="blend",
    summary="composite a foreground over a background through a mask (Laplacian pyramid or Poisson)",
    params=BlendParams,
    inputs=(
        InputSpec("foreground", "the image that shows where the mask is white"),
        InputSpec("background", "the image that shows where the mask is black"),
        InputSpec("mask", "grey image, white = foreground, same size as the images", positional=False),
    ),
    run=_run,
    warm_up=warm_up,
    warm_up_in_cli=False,
)
