"""NFPT (``weft.core.nfpt``): parameter fuzzing and degenerate geometry.

* ``synthesize`` (§2 alone) over block, overlap, weights, repair, smooth, size and source masks, on
  tiny textures of every awkward kind (flat patches, a lone dot, noise): a finite float32 image in
  [0, 1] of the asked size whose pixels all come from the valid part of the source, or a one-line
  ``WeftError`` naming the parameter, by an independent oracle.
* ``nfpt`` (the whole pipeline) with feature lines drawn from a small grid of points, so parallel,
  coincident, zero-length and crossing lines come up often, sometimes outside the photo, through
  every warp (homography, morph, lines), with views (quads: collinear, crossed, outside) and
  ``into_photo``: an image of the documented shape or a one-line ``WeftError``.
* Each degenerate case on its own, checking the message says what is wrong.

Every example runs with numpy's ``RuntimeWarning`` turned into an error: a stray "invalid value
encountered in divide" on stderr would break the CLI's one-line promise.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import event, given
from hypothesis import strategies as st
from weft.core.errors import GeometryError, WeftError
from weft.core.nfpt import nfpt, synthesize
from weft.core.rectify import FeatureLines, rectify
from weft.core.rectify.view import View

from tests.core.fuzzing import RUNTIME_WARNINGS_ARE_ERRORS, check_image, fuzz, one_line_naming

pytestmark = RUNTIME_WARNINGS_ARE_ERRORS

KINDS = ("flat", "black", "noise", "dot", "stripes")


def texture(kind: str, h: int, w: int, colour: bool, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    if kind == "flat":
        img = np.full((h, w), rng.random(), np.float32)
    elif kind == "black":
        img = np.zeros((h, w), np.float32)
    elif kind == "noise":
        img = rng.random((h, w), dtype=np.float32)
    elif kind == "dot":
        img = np.zeros((h, w), np.float32)
        img[rng.integers(h), rng.integers(w)] = 1.0
    else:
        img = np.tile((np.arange(w) % 4 < 2).astype(np.float32), (h, 1))
    if colour:
        img = img[..., None] * rng.uniform(0.2, 1.0, 3).astype(np.float32)
    return np.ascontiguousarray(img, dtype=np.float32)


# --- synthesis (§2) ----------------------------------------------------------------------------

_sides = st.sampled_from((8, 9, 12, 16, 20, 24) * 3 + (5, 7))


# each parameter: (values in range, values out of range); one example breaks at most one or two
_PARAMS = {
    "size": (st.sampled_from([None, None, (8, 8), (13, 24), (40, 13), (24, 40)]), st.sampled_from([(7, 16), (16, 0)])),
    "block": (st.sampled_from((8,) * 6 + (10, 12, 16)), st.sampled_from([7, 0, 600])),
    "overlap": (st.sampled_from([2, 3, 4]), st.sampled_from([1, 0, 5, 6])),
    "sigma_d": (st.sampled_from([None, None, 0.1, 1.0, 256.0]), st.sampled_from([0.0, -1.0, 300.0])),
    "sigma_s": (st.sampled_from([0.01, 0.35, 10.0]), st.sampled_from([0.0, 11.0])),
    "tol": (st.sampled_from([1, 2, 4]), st.just(0)),
    "band": (st.sampled_from([1, 2, 16]), st.sampled_from([0, 17])),
    "threshold": (st.sampled_from([0.0, 0.1, 1.0]), st.sampled_from([-0.1, 1.5])),
    "n": (st.sampled_from([3, 5, 7]), st.sampled_from([4, 1, 17])),
}


@fuzz(200)
@given(
    kind=st.sampled_from(KINDS),
    hs=_sides,
    ws=_sides,
    colour=st.booleans(),
    seed=st.integers(0, 2**16),
    repair=st.booleans(),
    smooth=st.booleans(),
    data=st.data(),
    broken=st.lists(st.sampled_from(sorted(_PARAMS)), max_size=2).map(set) | st.just(set()),
    mask_kind=st.sampled_from(["none", "none", "random", "all", "empty", "corner", "shape"]),
)
def test_synthesize_fuzz(kind, hs, ws, colour, seed, repair, smooth, data, broken, mask_kind):
    values = {name: data.draw(bad if name in broken else good, label=name) for name, (good, bad) in _PARAMS.items()}
    size, block, overlap, sigma_d, sigma_s, tol, band, threshold, n = (
        values[k] for k in ("size", "block", "overlap", "sigma_d", "sigma_s", "tol", "band", "threshold", "n")
    )
    tex = texture(kind, hs, ws, colour, seed)
    rng = np.random.default_rng(seed)
    mask = None
    if mask_kind == "random":
        mask = rng.random((hs, ws)) < 0.9
    elif mask_kind == "all":
        mask = np.ones((hs, ws), bool)
    elif mask_kind == "empty":
        mask = np.zeros((hs, ws), bool)
    elif mask_kind == "corner":  # only the top-left 8x8 is valid
        mask = np.zeros((hs, ws), bool)
        mask[:8, :8] = True
    elif mask_kind == "shape":
        mask = np.ones((hs + 1, ws), bool)
    out_w, out_h = size if size is not None else (2 * ws, 2 * hs)
    # the oracle: NfptParams' documented ranges
    problems = set()
    if size is not None and not all(8 <= v <= 16384 for v in size):
        problems.add("'size'")
    if not 8 <= block <= 512:
        problems.add("'block'")
    if not 2 <= overlap <= 256 or 2 * overlap > block:
        problems.add("'overlap'")
    if sigma_d is not None and not 0.1 <= sigma_d <= 256:
        problems.add("'sigma_d'")
    if not 0.01 <= sigma_s <= 10:
        problems.add("'sigma_s'")
    if not 1 <= tol <= 64:
        problems.add("'tol'")
    if not 1 <= band <= 16:
        problems.add("'band'")
    if not 0 <= threshold <= 1:
        problems.add("'threshold'")
    if not 3 <= n <= 15 or n % 2 == 0:
        problems.add("'n'")
    if not problems:  # the texture-dependent checks come after the parameters'
        if block > min(hs, ws):
            problems.add("'block'")
        elif mask_kind == "shape":
            problems.add("mask")
        elif mask is not None:
            if mask_kind == "empty" or (mask_kind == "corner" and block > 8):
                problems.add("block")  # "no BxB patch of the source lies wholly inside its valid part"
            elif mask_kind == "random":
                ok = any(
                    mask[y : y + block, x : x + block].all()
                    for y in range(hs - block + 1)
                    for x in range(ws - block + 1)
                )
                if not ok:
                    problems.add("block")
    try:
        syn = synthesize(
            tex,
            size=size,
            block=block,
            overlap=overlap,
            sigma_d=sigma_d,
            sigma_s=sigma_s,
            tol=tol,
            repair=repair,
            band=band,
            threshold=threshold,
            n=n,
            smooth=smooth,
            mask=mask,
            rng=seed,
            return_details=True,
        )
    except WeftError as e:
        event("refused")
        assert problems, f"valid call refused: {e}"
        one_line_naming(e, problems)
        return
    event("valid")
    assert not problems, f"accepted although {sorted(problems)} is wrong"
    out = syn.image
    check_image(out, (out_h, out_w), 3 if colour else 1)
    # every pixel was copied from the source's valid part (patches and repairs)
    assert syn.pos.shape == (out_h, out_w) and (syn.pos >= 0).all() and (syn.pos < hs * ws).all()
    if mask is not None:
        assert mask.ravel()[syn.pos].all()
    if kind in ("flat", "black") and not smooth:  # a flat source gives the same flat texture
        assert np.array_equal(
            np.unique(out.reshape(-1, out.shape[-1] if colour else 1), axis=0),
            np.unique(tex.reshape(-1, tex.shape[-1] if colour else 1), axis=0),
        )
    elif kind in ("flat", "black"):
        assert np.allclose(out, tex[0, 0], atol=1e-6)
    assert 0 <= syn.repaired <= out_h * out_w


# --- the pipeline with degenerate geometry -----------------------------------------------------

PHOTO_W, PHOTO_H = 32, 24
FRONTAL = (16, 12)
# a coarse grid (repeated points are likely), now and then a point outside the photo
_x = st.sampled_from([0.0, 6.0, 12.0, 20.0, 31.0] * 8 + [-4.0, 40.0])
_y = st.sampled_from([0.0, 5.0, 11.0, 17.0, 23.0] * 8 + [-4.0, 30.0])
_line = st.tuples(_x, _y, _x, _y).map(lambda ln: list(ln) if ln[:2] != ln[2:] else [*ln[:3], ln[3] + 5.0])
_fx, _fy = st.sampled_from([0.0, 4.0, 8.0, 15.0]), st.sampled_from([0.0, 4.0, 8.0, 11.0])
_frontal_line = st.tuples(_fx, _fy, _fx, _fy).map(lambda ln: list(ln) if ln[:2] != ln[2:] else [*ln[:3], 11.0 - ln[3]])
# a perspective view of the frontal grid: lines that do work, to mix with the degenerate ones
_GOOD_IMAGE = [
    [2, 2, 29, 4],
    [3, 21, 28, 19],
    [2, 2, 3, 21],
    [29, 4, 28, 19],
    [8, 3, 9, 20],
    [16, 3, 16, 20],
    [2, 11, 29, 11],
    [22, 4, 21, 20],
    [2, 7, 29, 8],
]
_GOOD_FRONTAL = [
    [0, 0, 15, 0],
    [0, 11, 15, 11],
    [0, 0, 0, 11],
    [15, 0, 15, 11],
    [4, 0, 4, 11],
    [8, 0, 8, 11],
    [0, 6, 15, 6],
    [12, 0, 12, 11],
    [0, 3, 15, 3],
]
_corner = st.tuples(st.sampled_from([-8.0, 0.0, 4.0, 15.0, 30.0]), st.sampled_from([-8.0, 0.0, 4.0, 12.0, 30.0]))


@st.composite
def feature_lines(draw):
    """Some good lines, then degenerate ones: random from a coarse grid (repeats likely), or copies."""
    good = draw(st.integers(0, len(_GOOD_IMAGE)))
    image = [list(map(float, ln)) for ln in _GOOD_IMAGE[:good]]
    frontal = [list(map(float, ln)) for ln in _GOOD_FRONTAL[:good]]
    for _ in range(draw(st.integers(0 if good >= 4 else 1, 3))):
        how = draw(st.sampled_from(["random", "copy", "parallel"] * 3 + ["zero"]))
        if how == "copy" and image:  # a coincident line
            i = draw(st.integers(0, len(image) - 1))
            image.append(list(image[i]))
            frontal.append(list(frontal[i]) if draw(st.booleans()) else draw(_frontal_line))
        elif how == "parallel" and image:  # parallel to a line, shifted by a pixel
            i = draw(st.integers(0, len(image) - 1))
            image.append([v + 1.0 for v in image[i]])
            frontal.append([v + (1.0 if k % 2 else 0.0) for k, v in enumerate(frontal[i])])
        elif how == "zero":
            x, y = draw(_x), draw(_y)
            image.append([x, y, x, y])
            frontal.append(draw(_frontal_line))
        else:
            image.append(draw(_line))
            frontal.append(draw(_frontal_line))
    return image, frontal


@fuzz(150)
@given(
    lines=feature_lines(),
    warp=st.sampled_from(["homography", "morph", "lines"]),
    kind=st.sampled_from(KINDS),
    colour=st.booleans(),
    target=st.sampled_from(["plain", "plain", "into_photo", "quad", "view_lines"]),
    data=st.data(),
    size=st.sampled_from([None, (16, 16), (24, 13)]),
    seed=st.integers(0, 999),
)
def test_nfpt_pipeline_with_degenerate_lines(lines, warp, kind, colour, target, data, size, seed):
    photo = texture(kind, PHOTO_H, PHOTO_W, colour, seed)
    image_lines, frontal_lines = lines
    view = None
    if target == "quad":
        quad = data.draw(st.lists(_corner, min_size=4, max_size=4) | st.just([(1, 1), (20, 3), (22, 20), (2, 18)]))
        view = View(data.draw(st.sampled_from([None, (20, 14)])), quad=np.array(quad, dtype=np.float64))
    elif target == "view_lines":
        vl, tl = data.draw(feature_lines())
        view = View(None, view_lines=np.array(vl), texture_lines=np.array(tl))
    try:
        fl = FeatureLines(image_lines, frontal_lines, FRONTAL)
        res = nfpt(
            photo, fl, view=view, into_photo=target == "into_photo", warp=warp, size=size, block=8, overlap=2, rng=seed
        )
    except WeftError as e:
        event(f"refused {warp}: {str(e)[:50]}")
        message = str(e)
        assert "\n" not in message and message.strip(), message
        return
    event(f"valid {warp} {target}")
    syn_hw = (size[1], size[0]) if size is not None else (2 * FRONTAL[1], 2 * FRONTAL[0])
    channels = 3 if colour else 1
    check_image(res.synthesized, syn_hw, channels)
    check_image(res.rectified, (FRONTAL[1], FRONTAL[0]), channels)
    if target in ("plain",):
        out_hw = syn_hw
    elif target == "into_photo":
        out_hw = (PHOTO_H, PHOTO_W)
    else:
        vs = view.size or (PHOTO_W, PHOTO_H)
        out_hw = (vs[1], vs[0])
    check_image(res.image, out_hw, channels)
    if res.homography is not None:
        assert res.homography.shape == (3, 3) and np.isfinite(res.homography).all()
    if kind in ("flat", "black"):  # flat patches: the constant, nothing invented, no ringing or dark seam
        c = photo[0, 0]
        if target in ("plain", "into_photo"):
            assert np.allclose(res.image, c, atol=1e-5), (res.image.min(), res.image.max())
        else:  # in a view: the constant times the coverage (black outside)
            ratio = res.image / np.where(c > 0, c, 1.0)
            assert ratio.max() <= 1.0 + 1e-5 and (np.isclose(ratio, 1.0, atol=1e-5) | (ratio < 1.0)).all()


@fuzz(120)
@given(
    image_lines=st.lists(_line, min_size=0, max_size=9),
    data=st.data(),
    warp=st.sampled_from(["morph", "morph", "lines", "homography"]),
)
def test_rectify_degenerate_lines_warn_nothing(image_lines, data, warp):
    """``test_fuzz_geometry`` again, for morph especially (>= 8 points needed), with warnings as errors."""
    frontal = data.draw(st.lists(_frontal_line, min_size=len(image_lines), max_size=len(image_lines)))
    photo = texture("noise", PHOTO_H, PHOTO_W, True, 0)
    try:
        out = rectify(photo, image_lines, frontal, FRONTAL, warp=warp)
    except WeftError as e:
        assert "\n" not in str(e)
        return
    check_image(out.image, (FRONTAL[1], FRONTAL[0]), 3)


# --- each degenerate case alone ----------------------------------------------------------------

WARPS = ("homography", "morph", "lines")
GOOD_I = np.array(_GOOD_IMAGE, dtype=np.float64)
GOOD_F = np.array(_GOOD_FRONTAL, dtype=np.float64)


def _refused(image_lines, frontal_lines, warp, *words, size=FRONTAL):
    photo = texture("noise", PHOTO_H, PHOTO_W, False, 1)
    with pytest.raises(GeometryError) as info:
        nfpt(photo, FeatureLines(image_lines, frontal_lines, size), warp=warp, size=(16, 16), block=8, overlap=2, rng=0)
    message = str(info.value)
    assert "\n" not in message
    assert all(w in message for w in words), message
    return message


@pytest.mark.parametrize("warp", WARPS)
def test_zero_length_line_is_named(warp):
    image = GOOD_I.copy()
    image[3] = [10, 10, 10, 10]
    _refused(image, GOOD_F, warp, "image line 3", "zero length")
    frontal = GOOD_F.copy()
    frontal[5] = [4, 4, 4.5, 4]  # under a pixel
    _refused(GOOD_I, frontal, warp, "frontal line 5", "length")


@pytest.mark.parametrize("warp", WARPS)
@pytest.mark.parametrize("end", [(-10.0, 5.0), (5.0, -10.0), (PHOTO_W + 5.0, 5.0), (5.0, PHOTO_H + 5.0)])
def test_line_outside_the_photo_is_named(warp, end):
    image = GOOD_I.copy()
    image[2, 2:] = end
    _refused(image, GOOD_F, warp, "image line 2", "outside the photo")
    frontal = GOOD_F.copy()
    frontal[4, :2] = end
    _refused(GOOD_I, frontal, warp, "frontal line 4", "outside the frontal frame")


@pytest.mark.parametrize("warp", ["homography", "morph"])
def test_parallel_lines_give_no_points(warp):
    image = np.array([[2, y, 29, y + 1] for y in (2, 6, 10, 14, 18)], dtype=np.float64)
    frontal = np.array([[0, y, 15, y] for y in (0, 3, 6, 9, 11)], dtype=np.float64)
    message = _refused(image, frontal, warp)
    assert "parallel" in message, message


@pytest.mark.parametrize("warp", ["homography", "morph"])
def test_coincident_lines_give_no_points(warp):
    image = np.repeat(GOOD_I[:2], 5, axis=0)
    frontal = np.repeat(GOOD_F[:2], 5, axis=0)
    _refused(image, frontal, warp)


def test_morph_with_many_lines_through_two_points_is_refused_without_warnings():
    """Found by the fuzzing: 8 crossings that are only 2 distinct points in the frontal frame made the
    planarity test's homography send them to infinity ("invalid value encountered in divide")."""
    image = [
        [25.66, 9.88, 3.63, 18.35],
        [1.52, 2.51, 8.34, 10.32],
        [2.0, 7.81, 7.27, 1.69],
        [12.26, 4.09, 5.87, 22.77],
        [3.6, 4.54, 17.27, 15.62],
        [3.66, 18.48, 24.08, 20.74],
        [1.33, 5.59, 16.01, 14.6],
    ]
    frontal = [[4, 4, 0, 8], [8, 4, 16, 12], [8, 4, 8, 0], [4, 4, 4, 8], [8, 0, 8, 8], [4, 12, 8, 8], [0, 4, 12, 4]]
    photo = texture("noise", PHOTO_H, PHOTO_W, True, 3)
    with pytest.raises(GeometryError) as info:
        rectify(photo, image, frontal, (16, 12), warp="morph")
    message = str(info.value)
    assert "\n" not in message and "distinct" in message and "frontal frame" in message, message


@pytest.mark.parametrize("warp", WARPS)
def test_mismatched_line_counts_are_named(warp):
    with pytest.raises(GeometryError) as info:
        FeatureLines(GOOD_I, GOOD_F[:-1], FRONTAL)
    assert "image_lines" in str(info.value) and "frontal_lines" in str(info.value)


@pytest.mark.parametrize(
    "quad",
    [
        [[0, 0], [10, 0], [20, 0], [5, 10]],  # three corners on one line
        [[0, 0], [15, 0], [0, 12], [15, 12]],  # crossed (bow tie)
        [[0, 0], [0, 0], [15, 12], [0, 12]],  # two corners coincide
    ],
)
def test_degenerate_view_quad_is_named(quad):
    photo = texture("noise", PHOTO_H, PHOTO_W, False, 1)
    with pytest.raises(GeometryError) as info:
        nfpt(
            photo,
            None,
            view=View(None, quad=np.array(quad, dtype=np.float64)),
            size=(16, 16),
            block=8,
            overlap=2,
            rng=0,
        )
    assert "\n" not in str(info.value) and "quad" in str(info.value)


@pytest.mark.parametrize("warp", WARPS)
def test_flat_photo_stays_flat_through_every_warp(warp):
    """A constant photo (an empty spectrum, every patch equally good) rectifies and synthesizes to the
    constant: nothing invented, no NaN from the equal costs."""
    photo = np.full((PHOTO_H, PHOTO_W, 3), 0.25, np.float32)
    try:
        res = nfpt(photo, FeatureLines(GOOD_I, GOOD_F, FRONTAL), warp=warp, size=(20, 16), block=8, overlap=2, rng=0)
    except GeometryError as e:  # morph may find the good lines planar: that is its documented refusal
        assert warp == "morph" and "plane" in str(e), str(e)
        return
    check_image(res.image, (16, 20), 3)
    assert np.allclose(res.image, 0.25, atol=1e-5)


def test_into_photo_needs_lines():
    photo = texture("noise", PHOTO_H, PHOTO_W, False, 1)
    with pytest.raises(GeometryError) as info:
        nfpt(photo, None, into_photo=True, size=(16, 16), block=8, overlap=2, rng=0)
    assert "lines" in str(info.value) and "\n" not in str(info.value)


@pytest.mark.parametrize("warp", WARPS)
def test_frame_reaching_the_photo_edge_is_not_darkened(warp):
    """Found by the fuzzing: a frontal frame mapped right up to the photo's edge was resampled
    against a black frame, so cubic interpolation rang (values up to 10 % above a flat photo's, or
    darker) on pixels counted as inside, which NFPT then copied as texture."""
    photo = np.full((PHOTO_H, PHOTO_W), 0.7, np.float32)
    w, h = PHOTO_W - 1.0, PHOTO_H - 1.0
    image = [
        [0, 0, w, 0],
        [0, h, w, h],
        [0, 0, 0, h],
        [w, 0, w, h],
        [w / 2, 0, w / 2, h],
        [0, h / 2, w, h / 2],
        [0, 0, w, h],
        [w, 0, 0, h],
    ]
    fw, fh = 20.0, 15.0  # a scaled frame: every sample between pixels, a half pixel past the corners
    frontal = [
        [-0.5, -0.5, fw - 0.5, -0.5],
        [-0.5, fh - 0.5, fw - 0.5, fh - 0.5],
        [-0.5, -0.5, -0.5, fh - 0.5],
        [fw - 0.5, -0.5, fw - 0.5, fh - 0.5],
        [fw / 2 - 0.5, -0.5, fw / 2 - 0.5, fh - 0.5],
        [-0.5, fh / 2 - 0.5, fw - 0.5, fh / 2 - 0.5],
        [-0.5, -0.5, fw - 0.5, fh - 0.5],
        [fw - 0.5, -0.5, -0.5, fh - 0.5],
    ]
    try:
        out = rectify(photo, image, frontal, (int(fw), int(fh)), warp=warp)
    except GeometryError as e:  # morph: the points of a plane
        assert warp == "morph" and "plane" in str(e), str(e)
        return
    inside = out.mask
    assert inside.mean() > 0.9
    assert np.allclose(out.image[inside], 0.7, atol=1e-5), (out.image[inside].min(), out.image[inside].max())
    assert (out.image[~inside] == 0).all()


@pytest.mark.parametrize("warp", ["homography", "lines"])
def test_into_photo_of_a_flat_photo_is_the_photo(warp):
    """Found by the fuzzing: the texture put back into the photo was composited with its coverage
    twice (a dark seam, down to 0.53 for 0.8) and rang against a black frame (up to 0.93)."""
    photo = np.full((PHOTO_H, PHOTO_W), 0.8, np.float32)
    res = nfpt(
        photo,
        FeatureLines(GOOD_I, GOOD_F, FRONTAL),
        into_photo=True,
        warp=warp,
        size=(20, 16),
        block=8,
        overlap=2,
        rng=0,
    )
    assert 0.3 < res.figures["photo_replaced_fraction"] < 1.0  # the plane's edge crosses the photo
    assert np.allclose(res.image, 0.8, atol=1e-5), (res.image.min(), res.image.max())
