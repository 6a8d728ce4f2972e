"""Fuzzing the shared building blocks: blending, seams, metrics, colour, square regions.

Hypothesis over ``weft.core.blending`` (Laplacian pyramid and Poisson blend: random, all-black and
all-white masks, sizes 1..16, grey/colour mixes, mismatched sizes), ``weft.core.seams`` (minimum cuts on
random and constant error surfaces, checked against a brute-force dynamic program), ``weft.core.metrics``
(identical, constant, tiny images: finite values in the documented ranges, the documented values for
the degenerate cases), ``weft.core.image`` colour helpers and ``Square.parse``/``Square.crop``. Valid
inputs give finite results of the documented shape and range; invalid ones a one-line
``WeftError`` naming the parameter or the image. Numpy ``RuntimeWarning``s are errors throughout.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from weft.core import metrics
from weft.core.blending import max_levels, poisson_blend, pyramid_blend
from weft.core.errors import ImageError, InvalidParameter, WeftError
from weft.core.geometry import Square
from weft.core.image import (
    from_pca,
    luminance,
    pca_basis,
    pca_grey,
    rgb_to_yiq,
    to_pca,
    yiq_to_rgb,
)
from weft.core.seams import min_cut_mask, min_error_path, overlap_error

from tests.core.fuzzing import RUNTIME_WARNINGS_ARE_ERRORS, check_image, fuzz, one_line_naming

pytestmark = RUNTIME_WARNINGS_ARE_ERRORS


def image(kind: str, h: int, w: int, colour: bool, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    shape = (h, w, 3) if colour else (h, w)
    if kind == "noise":
        return rng.random(shape, dtype=np.float32)
    if kind == "flat":
        return np.full(shape, rng.random(), np.float32)
    if kind == "black":
        return np.zeros(shape, np.float32)
    if kind == "white":
        return np.ones(shape, np.float32)
    ramp = np.linspace(0, 1, h * w, dtype=np.float32).reshape(h, w)  # "ramp"
    return np.repeat(ramp[..., None], 3, axis=2) if colour else ramp


KINDS = ("noise", "flat", "black", "white", "ramp")
_kind = st.sampled_from(KINDS)


# --- blending ----------------------------------------------------------------------------------


@st.composite
def masks(draw, h, w):
    how = draw(st.sampled_from(["random", "soft", "black", "white", "bool", "uint8", "colour", "one_pixel"]))
    rng = np.random.default_rng(draw(st.integers(0, 999)))
    if how == "random":
        return (rng.random((h, w)) > 0.5).astype(np.float32)
    if how == "soft":
        return rng.random((h, w), dtype=np.float32)
    if how == "black":
        return np.zeros((h, w), np.float32)
    if how == "white":
        return np.ones((h, w), np.float32)
    if how == "bool":
        return rng.random((h, w)) > 0.3
    if how == "uint8":
        return (rng.random((h, w)) * 255).astype(np.uint8)
    if how == "colour":
        return rng.random((h, w, 3), dtype=np.float32)
    m = np.zeros((h, w), np.float32)
    m[rng.integers(h), rng.integers(w)] = 1.0
    return m


def mask_values(mask) -> np.ndarray:
    """The mask as the blends read it: float in [0, 1], luminance of a colour mask."""
    m = np.asarray(mask)
    m = m / 255.0 if m.dtype == np.uint8 else m.astype(np.float64)
    return luminance(m.astype(np.float32)).astype(np.float64) if m.ndim == 3 else m


_side = st.integers(1, 16)


@fuzz(150)
@given(
    h=_side,
    w=_side,
    fg_kind=_kind,
    bg_kind=_kind,
    fg_colour=st.booleans(),
    bg_colour=st.booleans(),
    levels=st.integers(0, 6) | st.sampled_from([2.0, True, "3"]),
    data=st.data(),
    seed=st.integers(0, 999),
)
def test_pyramid_blend_fuzz(h, w, fg_kind, bg_kind, fg_colour, bg_colour, levels, data, seed):
    fg = image(fg_kind, h, w, fg_colour, seed)
    bg = image(bg_kind, h, w, bg_colour, seed + 1)
    mask = data.draw(masks(h, w))
    top = max_levels(h, w)
    assert top == math.floor(math.log2(min(h, w))) + 1
    if isinstance(levels, bool) or not isinstance(levels, int) or not 1 <= levels <= top:
        with pytest.raises(InvalidParameter) as info:
            pyramid_blend(fg, bg, mask, levels=levels)
        one_line_naming(info.value, ["'levels'"])
        return
    out = pyramid_blend(fg, bg, mask, levels=levels)
    colour = fg_colour or bg_colour
    check_image(out, (h, w), 3 if colour else 1)
    m = mask_values(mask)
    f3 = fg if fg.ndim == 3 or not colour else np.repeat(fg[..., None], 3, axis=2)
    b3 = bg if bg.ndim == 3 or not colour else np.repeat(bg[..., None], 3, axis=2)
    if (m == 1).all():  # documented: all ones gives the foreground, all zeros the background
        assert np.allclose(out, f3, atol=1e-5)
    elif (m == 0).all():
        assert np.allclose(out, b3, atol=1e-5)
    elif levels == 1:  # a plain per-pixel mix
        mk = m[..., None] if colour else m
        assert np.allclose(out, mk * f3 + (1 - mk) * b3, atol=1e-5)
    if fg_kind == bg_kind and fg_kind in ("black", "white"):  # the same constant on both sides: nothing to blend
        assert np.allclose(out, f3, atol=1e-5)


@fuzz(100)
@given(
    h=_side,
    w=_side,
    t_kind=_kind,
    s_kind=_kind,
    t_colour=st.booleans(),
    s_colour=st.booleans(),
    wrap=st.booleans(),
    data=st.data(),
    seed=st.integers(0, 999),
    tol=st.sampled_from([1e-6, 1e-3, 0.5, np.float32(1e-4), np.float64(1e-5)] * 2 + [0, 1, -1e-3, float("nan"), "x"]),
    max_iter=st.sampled_from([None, None, 1, 50, 5000] * 2 + [0, -3, 2.5, True, "x"]),
)
def test_poisson_blend_fuzz(h, w, t_kind, s_kind, t_colour, s_colour, wrap, data, seed, tol, max_iter):
    target = image(t_kind, h, w, t_colour, seed)
    source = image(s_kind, h, w, s_colour, seed + 1)
    mask = data.draw(masks(h, w))
    problems = set()
    if isinstance(tol, (bool, str)) or not 0 < float(tol) < 1:
        problems.add("'tol'")
    if max_iter is not None and (isinstance(max_iter, (bool, str, float)) or max_iter < 1):
        problems.add("'max_iter'")
    try:
        out = poisson_blend(target, source, mask, tol=tol, max_iter=max_iter, wrap=wrap)
    except WeftError as e:
        assert problems, f"valid call refused: {e}"
        one_line_naming(e, problems)
        return
    assert not problems, f"accepted although {sorted(problems)} is wrong"
    colour = t_colour or s_colour
    check_image(out, (h, w), 3 if colour else 1)
    t3 = target if target.ndim == 3 or not colour else np.repeat(target[..., None], 3, axis=2)
    outside = mask_values(mask) <= 0.5
    assert np.array_equal(out[outside], t3[outside])  # the target is kept outside the mask
    if t_kind == s_kind and t_colour == s_colour and t_kind != "noise":
        # the source's gradients are the target's: the target itself solves the equation
        assert np.allclose(out, t3, atol=1e-4 if max_iter is None or max_iter >= 50 else 1.0)


@pytest.mark.parametrize("which", ["foreground", "background", "mask"])
def test_blend_mismatched_sizes_name_which(which):
    imgs = {
        "foreground": np.zeros((8, 8), np.float32),
        "background": np.zeros((8, 8), np.float32),
        "mask": np.zeros((8, 8), np.float32),
    }
    imgs[which] = np.zeros((8, 9), np.float32)
    with pytest.raises(ImageError) as info:
        pyramid_blend(imgs["foreground"], imgs["background"], imgs["mask"], levels=2)
    one_line_naming(info.value, [which])
    assert "8x8" in str(info.value) and "9x8" in str(info.value)
    names = {"foreground": "source", "background": "target", "mask": "mask"}
    with pytest.raises(ImageError) as info:
        poisson_blend(imgs["background"], imgs["foreground"], imgs["mask"])
    one_line_naming(info.value, [names[which]])


@pytest.mark.parametrize(
    "bad",
    [
        np.full((4, 4), 1.5, np.float32),
        np.full((4, 4), np.nan, np.float32),
        np.zeros((4, 4, 2), np.float32),
        np.zeros((4,), np.float32),
    ],
)
def test_blend_bad_mask_is_named(bad):
    img = np.zeros((4, 4), np.float32)
    for blend in (lambda: pyramid_blend(img, img, bad, levels=1), lambda: poisson_blend(img, img, bad)):
        with pytest.raises(ImageError) as info:
            blend()
        one_line_naming(info.value, ["mask"])


# --- seams -------------------------------------------------------------------------------------


def _best_path_cost(err: np.ndarray) -> float:
    """Brute-force reference: least total error of an 8-connected top-to-bottom path."""
    acc = err[-1].astype(np.float64).copy()
    for y in range(len(err) - 2, -1, -1):
        nxt = np.full(len(acc) + 2, np.inf)
        nxt[1:-1] = acc
        acc = err[y] + np.minimum(np.minimum(nxt[:-2], nxt[1:-1]), nxt[2:])
    return float(acc.min())


_errors = st.builds(
    lambda kind, h, w, seed: {
        "random": lambda: np.random.default_rng(seed).random((h, w)),
        "constant": lambda: np.full((h, w), 0.25),
        "zero": lambda: np.zeros((h, w)),
        "integer": lambda: np.random.default_rng(seed).integers(0, 3, (h, w)),
    }[kind](),
    st.sampled_from(["random", "random", "constant", "zero", "integer"]),
    st.integers(1, 12),
    st.integers(1, 12),
    st.integers(0, 999),
)


@fuzz(150)
@given(err=_errors)
def test_min_error_path_is_optimal_and_connected(err):
    path = min_error_path(err)
    h, w = err.shape
    assert path.shape == (h,) and path.dtype == np.int64
    assert (path >= 0).all() and (path < w).all()
    assert (np.abs(np.diff(path)) <= 1).all()
    cost = float(err[np.arange(h), path].sum())
    assert cost == pytest.approx(_best_path_cost(err), abs=1e-9)


@fuzz(150)
@given(err=_errors, data=st.data())
def test_min_cut_mask_fuzz(err, data):
    h, w = err.shape
    sides = {
        k: data.draw(st.integers(0, lim) | st.sampled_from([-1, lim + 1, 2.0, True]), label=k)
        for k, lim in (("left", w), ("top", h), ("right", w), ("bottom", h))
    }
    bad = {
        k
        for k, v in sides.items()
        if isinstance(v, (bool, float)) or not 0 <= v <= (w if k in ("left", "right") else h)
    }
    try:
        mask = min_cut_mask(err, **sides)
    except WeftError as e:
        assert bad, f"valid call refused: {e}"
        one_line_naming(e, {f"'{k}'" for k in bad})
        return
    assert not bad
    assert mask.shape == (h, w) and mask.dtype == bool
    left, top, right, bottom = (sides[k] for k in ("left", "top", "right", "bottom"))
    # outside every overlap strip the new block shows
    assert mask[top : h - bottom, left : w - right].all()
    if not any(sides.values()):
        assert mask.all()
    if left and not (top or right or bottom):  # one vertical cut: old pixels left of it, new from it on
        assert (np.diff(mask.astype(np.int8), axis=1) >= 0).all()
        first_new = np.argmax(mask, axis=1)
        assert (np.abs(np.diff(first_new)) <= 1).all()


def test_seams_refuse_bad_error_surfaces():
    for bad, word in (
        (np.zeros((0, 3)), "shape"),
        (np.zeros(5), "shape"),
        (np.full((2, 2), np.nan), "NaN"),
        (np.array([["a", "b"]]), "real"),
        (np.ones((2, 2), complex), "real"),
    ):
        for call in (min_error_path, min_cut_mask):
            with pytest.raises(ImageError) as info:
                call(bad)
            one_line_naming(info.value, ["error"])
            assert word in str(info.value)
    with pytest.raises(ImageError) as info:
        overlap_error(np.zeros((3, 3)), np.zeros((3, 4)))
    assert "\n" not in str(info.value)


@given(h=_side, w=_side, colour=st.booleans(), seed=st.integers(0, 99))
@settings(max_examples=30, deadline=None)
def test_overlap_error(h, w, colour, seed):
    a, b = image("noise", h, w, colour, seed), image("noise", h, w, colour, seed + 1)
    e = overlap_error(a, b)
    assert e.shape == (h, w) and e.dtype == np.float64 and np.isfinite(e).all()
    assert e.min() >= 0 and e.max() <= (3 if colour else 1)
    assert (overlap_error(a, a) == 0).all()


# --- metrics -----------------------------------------------------------------------------------

_msides = st.sampled_from([7, 8, 9, 12, 16] * 3 + [1, 5, 6])


@fuzz(80)
@given(
    kind_a=_kind,
    kind_b=_kind,
    ha=_msides,
    wa=_msides,
    hb=_msides,
    wb=_msides,
    colour=st.booleans(),
    patch=st.sampled_from([1, 3, 7] * 3 + [0, 9, 17]),
    stride=st.sampled_from([1, 2, 5] * 3 + [0]),
    seed=st.integers(0, 999),
)
def test_patch_metrics_fuzz(kind_a, kind_b, ha, wa, hb, wb, colour, patch, stride, seed):
    a = image(kind_a, ha, wa, colour, seed)
    b = image(kind_b, hb, wb, colour, seed + 1)
    problems = set()
    if patch < 1:
        problems.add("'patch'")
    if stride < 1:
        problems.add("'stride'")
    if not problems:
        side = max(7, patch)
        if min(ha, wa) < side:
            problems.add("output image")
        if min(hb, wb) < side:
            problems.add("source image")
    for fn in (metrics.coherence, metrics.completeness):
        try:
            value = fn(a, b, patch=patch, stride=stride)
        except WeftError as e:
            assert problems, f"valid call refused: {e}"
            one_line_naming(e, problems)
            continue
        assert not problems
        # a Euclidean distance between patch x patch windows of [0, 1] intensities
        assert isinstance(value, float) and math.isfinite(value) and 0.0 <= value <= patch + 1e-6
        if kind_a in ("flat", "black", "white") and kind_b in ("flat", "black", "white"):
            diff = abs(float(luminance(a).flat[0]) - float(luminance(b).flat[0]))
            assert value == pytest.approx(patch * diff, abs=1e-5)  # every window is the constant
    if not problems:  # identical images: ~0. The neighbour is picked in float32 (|b|^2 - 2a.b, an error of
        # ~1e-7 on squared distances), so a twin patch up to ~sqrt(1e-7) = 3e-4 away may win over the patch
        # itself (noise, 1x1 patches: 1.3e-5); the reported distance is then exact
        assert 0.0 <= metrics.coherence(a, a, patch=patch, stride=stride) < 1e-3
        assert 0.0 <= metrics.completeness(b, b, patch=patch, stride=stride) < 1e-3


@fuzz(80)
@given(
    kind_a=_kind,
    kind_b=_kind,
    h=_msides,
    w=_msides,
    colour=st.booleans(),
    seed=st.integers(0, 999),
    sigma=st.sampled_from([0.0, 1.0, 3.0, 50.0] * 2 + [-1.0, float("nan"), float("inf"), "3"]),
)
def test_fidelity_snr_psnr_fuzz(kind_a, kind_b, h, w, colour, seed, sigma):
    a = image(kind_a, h, w, colour, seed)
    b = image(kind_b, h, w, colour, seed + 1)
    small = min(h, w) < 7
    bad_sigma = isinstance(sigma, str) or not (math.isfinite(sigma) and sigma >= 0)
    try:
        fid = metrics.fidelity(a, b, sigma=sigma)
    except WeftError as e:
        assert small or bad_sigma, str(e)
        one_line_naming(e, ({"output image"} if small else set()) | ({"'sigma'"} if bad_sigma else set()))
    else:
        assert not small and not bad_sigma
        assert math.isfinite(fid) and -1.0 <= fid <= 1.0

        def constant(img):
            return np.ptp(luminance(img)) == 0

        if constant(a) or constant(b):
            assert fid == 0.0  # documented: undefined correlation -> 0
        if kind_a == "ramp" and kind_a == kind_b and sigma <= 1.0:  # (a wide blur of a tiny ramp is flat: 0)
            assert fid == pytest.approx(1.0, abs=1e-6)
    for fn in (metrics.snr_db, metrics.psnr_db):
        try:
            value = fn(a, b)
        except WeftError as e:
            assert small
            one_line_naming(e, ["original image", "synthesized image"])
            continue
        assert not small
        assert fn(a, a) == math.inf  # documented: identical arrays give inf
        if np.array_equal(a, b):
            assert value == math.inf
        elif fn is metrics.psnr_db:
            assert math.isfinite(value) and value >= 0.0  # mse <= 1 for [0, 1] images
            if kind_a in ("black", "white") and kind_b in ("black", "white"):
                assert value == 0.0  # mse = 1: 0 dB
        elif np.var(a.astype(np.float64)) == 0:
            assert value == -math.inf  # documented: constant original, different synthesis
        else:
            assert math.isfinite(value)


def test_metrics_refuse_mismatched_shapes():
    a = np.zeros((8, 8), np.float32)
    for fn, names in (
        (metrics.snr_db, ("original image", "synthesized image")),
        (metrics.psnr_db, ("original image", "synthesized image")),
        (metrics.fidelity, ("output image", "target image")),
    ):
        with pytest.raises(ImageError) as info:
            fn(a, np.zeros((8, 9), np.float32))
        assert all(n in str(info.value) for n in names) and "\n" not in str(info.value)


# --- colour ------------------------------------------------------------------------------------


@fuzz(100)
@given(
    kind=_kind,
    h=st.integers(1, 9),
    w=st.integers(1, 9),
    seed=st.integers(0, 999),
    rank=st.sampled_from(["full", "grey", "tint"]),
)
def test_colour_helpers_fuzz(kind, h, w, seed, rank):
    rgb = image(kind, h, w, True, seed)
    if rank == "grey":  # rank-1 colours: all on the grey axis
        rgb = np.repeat(rgb[..., :1], 3, axis=2)
    elif rank == "tint":
        rgb = np.ascontiguousarray(rgb[..., :1] * np.array([1.0, 0.5, 0.2], np.float32))
    y = luminance(rgb)
    assert y.shape == (h, w) and y.dtype == np.float32 and np.isfinite(y).all()
    assert y.min() >= 0.0 and y.max() <= 1.0 + 1e-6
    yiq = rgb_to_yiq(rgb)
    assert yiq.shape == (h, w, 3) and np.isfinite(yiq).all()
    assert -1e-6 <= yiq[..., 0].min() and yiq[..., 0].max() <= 1 + 1e-6
    assert np.abs(yiq[..., 1]).max() <= 0.596 + 1e-5 and np.abs(yiq[..., 2]).max() <= 0.523 + 1e-5
    back = yiq_to_rgb(yiq)
    assert back.dtype == np.float32 and np.allclose(back, rgb, atol=1e-5)
    basis = pca_basis(rgb)
    for arr in (basis.mean, basis.axes, basis.variances):
        assert np.isfinite(arr).all()
    assert (basis.variances >= 0).all() and (np.diff(basis.variances) <= 1e-9).all()
    # documented: an orthonormal basis, the first axis signed to correlate with luminance
    assert np.allclose(basis.axes @ basis.axes.T, np.eye(3), atol=1e-5), basis.axes
    assert float(basis.axes[0] @ np.array([0.299, 0.587, 0.114])) > 0
    comps, b2 = to_pca(rgb)
    assert comps.shape == (h, w, 3) and np.isfinite(comps).all()
    assert np.allclose(from_pca(comps, b2), rgb, atol=1e-5)
    grey, _ = pca_grey(rgb)
    assert grey.shape == (h, w) and grey.dtype == np.float32 and np.isfinite(grey).all()
    if np.ptp(rgb) == 0:  # flat: the grey is the brightness of the colour along the luminance axis
        assert np.ptp(grey) <= 1e-6


@pytest.mark.parametrize("fn", [luminance, rgb_to_yiq, pca_basis])
@pytest.mark.parametrize("shape", [(4,), (4, 4, 2), (4, 4, 4), (0, 4, 3), (2, 2, 3, 1)])
def test_colour_helpers_refuse_wrong_shapes(fn, shape):
    with pytest.raises(ImageError) as info:
        fn(np.zeros(shape, np.float32))
    assert "\n" not in str(info.value) and "image" in str(info.value)


def test_rgb_only_helpers_refuse_grey():
    for fn in (rgb_to_yiq, pca_basis):
        with pytest.raises(ImageError) as info:
            fn(np.zeros((4, 4), np.float32))
        assert "RGB image" in str(info.value)
    with pytest.raises(ImageError) as info:
        yiq_to_rgb(np.zeros((4, 4), np.float32))
    assert "YIQ image" in str(info.value)


# --- square regions ----------------------------------------------------------------------------

_coord = st.integers(-5, 24)


@fuzz(300)
@given(
    text=st.one_of(
        st.tuples(_coord, _coord, st.integers(-2, 30)).map(lambda t: ",".join(map(str, t))),
        st.text(max_size=10),
        st.sampled_from(["1,2", "1,2,3,4", "1.5,2,8", " 3 , 4 , 8 ", "", ",,", "nan,0,8", "0,0,1e3", "0x1,0,8"]),
    ),
    h=st.integers(1, 20),
    w=st.integers(1, 20),
    name=st.sampled_from(["region", "prototype"]),
)
def test_parse_and_crop_square(text, h, w, name):
    img = image("noise", h, w, True, 0)
    try:
        square = Square.parse(text, name)
    except WeftError as e:
        one_line_naming(e, [f"'{name}'"])
        parts = text.replace(" ", "").split(",")
        try:
            x, y, s = (int(p) for p in parts)
        except ValueError:
            return
        assert x < 0 or y < 0 or s < 2, f"{text!r} refused: {e}"
        return
    x, y, s = square
    assert all(isinstance(v, int) for v in square) and x >= 0 and y >= 0 and s >= 2
    try:
        crop = square.crop(img, what="texture", name=name)
    except WeftError as e:
        one_line_naming(e, [f"'{name}'"])
        assert "texture" in str(e) and f"{w}x{h}" in str(e)
        assert x + s > w or y + s > h, f"{square} fits {w}x{h} yet: {e}"
        return
    assert x + s <= w and y + s <= h
    assert crop.shape == (s, s, 3) and np.array_equal(crop, img[y : y + s, x : x + s])


@given(x=st.integers(-8, 8), y=st.integers(-8, 8), s=st.integers(-3, 12))
@settings(max_examples=100, deadline=None)
def test_crop_square_alone_refuses_every_square_outside(x, y, s):
    """``Square.crop`` without ``Square.parse`` in front (the GUI and recipes call it directly)."""
    img = image("noise", 10, 10, False, 0)
    if x < 0 or y < 0 or s < 1 or x + s > 10 or y + s > 10:
        with pytest.raises(WeftError) as info:
            Square(x, y, s).crop(img)
        one_line_naming(info.value, ["'region'"])
    else:
        assert Square(x, y, s).crop(img).shape == (s, s)
