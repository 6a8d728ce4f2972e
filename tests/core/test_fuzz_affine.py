"""Parameter fuzzing and degenerate geometry for the affine prototype model (``weft.core.affine``).

Hypothesis over the public functions: ``synthesize`` end to end (analysis, reuse of transforms,
fields, boundary matching), ``analyse`` + ``render`` with swapped prototypes, the prototype
rectangle helpers, the spectral centroids and candidate transforms, ``match_boundaries``.

Inputs are tiny textures (8..24 pixels a side, near the model's 8x8 minimum) of every awkward kind:
flat (an empty spectrum: the Fourier energy centroids are undefined), a single grating (all energy
in one segment), noise, a lone bright pixel, a step, grey and colour. Prototype squares are placed
at every border, partly or fully outside, larger than the texture, with zero, negative or odd
sides. An independent oracle says which inputs are valid: valid ones give a finite float32 image in
[0, 1] of the documented shape; invalid ones a one-line ``WeftError`` naming the parameter. Every
example runs with numpy's ``RuntimeWarning`` turned into an error (a "divide by zero" printed on
stderr would break the CLI's one-line promise).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import event, given, settings
from hypothesis import strategies as st
from weft.core.affine import (
    AffineModel,
    Prototype,
    analyse,
    candidate_transforms,
    centroids,
    check_rect,
    cos2_window,
    default_rect,
    field_model,
    make_prototype,
    match_boundaries,
    prototype_from_patch,
    render,
    sampling_matrices,
    segment_sums,
    synthesize,
    total_boundary_error,
)
from weft.core.affine.transforms import MAX_SCALE, MIN_SCALE, singular_values
from weft.core.errors import WeftError
from weft.core.geometry import Square

from tests.core.fuzzing import RUNTIME_WARNINGS_ARE_ERRORS, check_image, fuzz, one_line_naming

pytestmark = RUNTIME_WARNINGS_ARE_ERRORS

KINDS = ("flat", "black", "white", "noise", "grating", "dot", "step", "nearly_flat", "checker")


def texture(kind: str, h: int, w: int, colour: bool, seed: int) -> np.ndarray:
    """A tiny test texture of the given kind, float32 in [0, 1]."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[:h, :w].astype(np.float32)
    if kind == "flat":
        img = np.full((h, w), rng.random(), np.float32)
    elif kind == "black":
        img = np.zeros((h, w), np.float32)
    elif kind == "white":
        img = np.ones((h, w), np.float32)
    elif kind == "noise":
        img = rng.random((h, w), dtype=np.float32)
    elif kind == "grating":  # one frequency: all the spectrum's energy in one segment
        f, a = rng.uniform(0.05, 0.5), rng.uniform(0, np.pi)
        img = 0.5 + 0.5 * np.cos(2 * np.pi * f * (np.cos(a) * x + np.sin(a) * y))
    elif kind == "dot":
        img = np.zeros((h, w), np.float32)
        img[rng.integers(h), rng.integers(w)] = 1.0
    elif kind == "step":
        img = (x >= rng.integers(1, max(w, 2))).astype(np.float32)
    elif kind == "nearly_flat":  # float32 round-off around a constant
        img = np.float32(0.5) + rng.normal(0, 1e-7, (h, w)).astype(np.float32)
    else:
        img = ((x // 2 + y // 2) % 2).astype(np.float32)
    img = np.clip(img, 0.0, 1.0).astype(np.float32)
    if colour:
        tint = rng.uniform(0.2, 1.0, 3).astype(np.float32)
        img = img[..., None] * tint if kind != "noise" else rng.random((h, w, 3), dtype=np.float32)
    return np.ascontiguousarray(img, dtype=np.float32)


_SIDES = (8, 9, 10, 12, 13, 16, 20, 24)


@st.composite
def textures(draw, small: bool = False):
    """8..24 pixels a side (with ``small``, now and then 5..7: below the model's minimum)."""
    sides = st.sampled_from(_SIDES * 3 + ((5, 6, 7) if small else ()))
    kind = draw(st.sampled_from(KINDS))
    return texture(kind, draw(sides), draw(sides), draw(st.booleans()), draw(st.integers(0, 2**16)))


# Prototype squares: anywhere around a <= 24 pixel image, sides from negative to larger than it.
_coord = st.integers(-10, 30)
_side = st.sampled_from([8, 10, 12, 16, 24]) | st.integers(-4, 32)
_rects = st.tuples(_coord, _coord, _side)


@st.composite
def rects_for(draw, shape):
    """None (the default), a square that fits ``shape`` (touching a border half of the time), or any."""
    how = draw(st.sampled_from(["none", "fit", "fit", "wild"]))
    h, w = shape[:2]
    if how == "none" or (how == "fit" and min(h, w) < 8):
        return None
    if how == "wild":
        return draw(_rects)
    s = draw(st.sampled_from(range(8, min(h, w) + 1, 2)))
    x = draw(st.sampled_from([0, w - s]) | st.integers(0, w - s))
    y = draw(st.sampled_from([0, h - s]) | st.integers(0, h - s))
    return x, y, s


def rect_problem(rect, shape) -> bool:
    """True when the square is not a usable prototype of an image of ``shape`` (the oracle)."""
    x, y, s = rect
    h, w = shape[:2]
    return x < 0 or y < 0 or s < 8 or s % 2 == 1 or x + s > w or y + s > h


# --- the prototype rectangle -------------------------------------------------------------------


@settings(max_examples=300, deadline=None)
@given(
    rect=st.one_of(
        _rects,
        st.tuples(_coord, _coord, _side).map(lambda r: f"{r[0]},{r[1]},{r[2]}"),
        st.text(max_size=10),
        st.lists(st.integers(-3, 20), max_size=4),
        st.tuples(st.floats(-2, 20), st.floats(-2, 20), st.floats(-2, 20)),
        st.none(),
        st.just(8),
    ),
    h=st.integers(1, 24),
    w=st.integers(1, 24),
    name=st.sampled_from(["prototype", "analysis_prototype"]),
)
def test_parse_and_check_rect(rect, h, w, name):
    """``Square.parse`` + ``check_rect``: a square inside the image, or an error naming the parameter."""
    values = None
    if isinstance(rect, (tuple, list)) and len(rect) == 3 and all(float(v) == int(v) for v in rect):
        values = tuple(int(v) for v in rect)
    elif isinstance(rect, str):
        try:
            values = tuple(int(p) for p in rect.replace(" ", "").split(","))  # Square.parse: spaces ignored
        except ValueError:
            values = None
        if values is not None and len(values) != 3:
            values = None
    try:
        parsed = Square.parse(rect, name).check_side(name, minimum=8, even=True)
        check_rect(parsed, (h, w), "texture", name)
    except WeftError as e:
        one_line_naming(e, [f"'{name}'"])
        assert values is None or rect_problem(values, (h, w)), f"{rect!r} fits {w}x{h} yet: {e}"
        return
    assert values is not None, f"{rect!r} accepted as {parsed}"
    assert parsed == values and not rect_problem(parsed, (h, w))


@given(
    x=st.integers(-20, -1) | st.integers(0, 8),
    y=st.integers(-20, -1) | st.integers(0, 8),
    s=st.sampled_from([8, 10, 16]),
)
@settings(max_examples=60, deadline=None)
def test_check_rect_refuses_a_corner_outside(x, y, s):
    """``check_rect`` alone (its callers may skip ``Square.parse``): a negative corner is outside too."""
    shape = (24, 24)
    if rect_problem((x, y, s), shape):
        with pytest.raises(WeftError) as info:
            check_rect((x, y, s), shape)
        one_line_naming(info.value, ["'prototype'"])
    else:
        assert check_rect((x, y, s), shape) == (x, y, s)


@given(h=st.integers(1, 40), w=st.integers(1, 40), block=st.sampled_from([8, 10, 16, 32]))
@settings(max_examples=80, deadline=None)
def test_default_rect(h, w, block):
    if min(h, w) < 8:
        with pytest.raises(WeftError) as info:
            default_rect((h, w), block)
        one_line_naming(info.value, ["prototype", f"{w}x{h}"])
        return
    x, y, s = default_rect((h, w), block)
    assert not rect_problem((x, y, s), (h, w)) and s <= 2 * block


# --- synthesize end to end ---------------------------------------------------------------------


@fuzz(300)
@given(
    tex=textures(small=True),
    data=st.data(),
    block=st.sampled_from([8] * 16 + [10, 12, 16] + [0, 7, 30]),
    segments=st.sampled_from([8] * 16 + [4, 6, 32] + [0, 2, 5]),
    lowpass=st.sampled_from(["add", "absorb"]),
    colour=st.sampled_from(["pca", "yuv"]),
    propagate=st.booleans(),
    refine=st.integers(0, 2),
    boundary=st.sampled_from(["auto", "none", "partial", "shaker"]),
    shaker_start=st.sampled_from(["partial", "analysis"]),
    mode=st.sampled_from(["analyse", "analyse", "reuse", "field"]),
    field=st.sampled_from(["swirl", "zoom", "rotate"]),
    strength=st.floats(0.0, 2.0),
    seed=st.integers(0, 2**16),
)
def test_synthesize_fuzz(
    tex, data, block, segments, lowpass, colour, propagate, refine, boundary, shaker_start, mode, field, strength, seed
):
    h, w = tex.shape[:2]
    problems: set[str] = set()
    if block < 8 or block > 256 or block % 2:
        problems.add("'block'")
    if segments < 4 or segments % 2:
        problems.add("'segments'")
    other = None
    if data.draw(st.booleans(), label="prototype_image"):
        other = data.draw(textures(small=True), label="other")
    source = other if other is not None else tex
    rect = data.draw(rects_for(source.shape), label="prototype")
    kwargs = {
        "prototype": rect,
        "prototype_image": other,
        "block": block,
        "segments": segments,
        "lowpass": lowpass,
        "colour": colour,
        "propagate": propagate,
        "refine": refine,
        "boundary": boundary,
        "iterations": 3,
        "per_radius": 1,
        "shaker_start": shaker_start,
        "rng": seed,
    }
    out_hw = (h, w)
    # the oracle: what is wrong with this call by the documented rules, as the words the error must use
    source_name = "prototype image" if other is not None else "texture"
    if rect is not None and rect_problem(rect, source.shape):
        problems.add("'prototype'")
    if rect is None and min(source.shape[:2]) < 8:  # no room for the default prototype
        problems.add(f"the {source_name} is")
    if mode == "field":
        size = data.draw(st.sampled_from([None, None, (20, 16), (16, 30), (30, 17), (14, 20), (24, 15)]), label="size")
        kwargs.update(field=field, field_strength=strength, size=size)
        if size is not None:
            out_hw = (size[1], size[0])
            if min(size) < 16:
                problems.add("'size'")
        if block > min(out_hw):
            problems.add("block")
        channels = 3 if source.ndim == 3 else 1  # a field renders the unfiltered prototype
    else:
        if min(h, w) < 8:
            problems.add("the texture is")
        elif block > min(h, w):
            problems.add("'block'")
        if mode == "reuse":
            arect = data.draw(rects_for(tex.shape), label="analysis_prototype")
            kwargs.update(reuse_transforms=True, analysis_prototype=arect)
            if arect is not None and rect_problem(arect, tex.shape):
                problems.add("'analysis_prototype'")
        # add: the modelled image's channels; absorb: the prototype's own
        channels = 3 if (tex if lowpass == "add" else source).ndim == 3 else 1
    try:
        out = synthesize(tex, **kwargs)
    except WeftError as e:
        event("refused")
        assert problems, f"valid call refused: {e}"
        one_line_naming(e, problems)
        return
    event(f"valid {mode}")
    assert not problems, f"accepted although {sorted(problems)} is wrong"
    check_image(out, out_hw, channels)
    if tex.ndim == 2 and np.ptp(tex) == 0 and other is None and mode == "analyse" and lowpass == "add":
        # a flat texture (empty spectrum) is reproduced flat
        assert np.allclose(out, tex[0, 0], atol=1e-4)


# --- analyse and render with swapped prototypes -------------------------------------------------


@fuzz(80)
@given(
    tex=textures(),
    block=st.sampled_from([8, 8, 10, 12]),
    lowpass=st.sampled_from(["add", "absorb"]),
    refine=st.integers(0, 3),
    data=st.data(),
)
def test_analyse_and_render_any_prototype(tex, block, lowpass, refine, data):
    h, w = tex.shape[:2]
    if block > min(h, w):
        block = 8
    model = analyse(tex, block=block, segments=8, lowpass=lowpass, refine=refine)
    assert isinstance(model, AffineModel)
    K = model.grid.count
    for name in ("transforms", "sampling", "shifts", "alpha"):
        arr = getattr(model, name)
        assert len(arr) == K and np.isfinite(arr).all(), name
    assert np.isfinite(model.rms).all() and (model.rms >= 0).all()
    sv = singular_values(model.sampling)
    assert (sv[:, 1] > 0).all()
    assert (np.abs(model.shifts) <= model.grid.radius + 1e-9).all()
    check_image(render(model), (h, w), None)
    # a swapped prototype: any square patch, even or odd side, cut anywhere, grey or colour
    side = data.draw(st.integers(1, 20), label="side")
    patch = texture(data.draw(st.sampled_from(KINDS)), side, side, data.draw(st.booleans()), 1)
    if side < 8 or side % 2:
        with pytest.raises(WeftError) as info:
            render(model, patch)
        one_line_naming(info.value, ["prototype patch"])
    else:
        check_image(render(model, patch), (h, w), None)
    # a patch that is not square
    with pytest.raises(WeftError) as info:
        prototype_from_patch(np.zeros((8, 10), np.float32))
    one_line_naming(info.value, ["prototype patch"])


@fuzz(40)
@given(tex=textures(), data=st.data())
def test_make_prototype_at_every_border(tex, data):
    """Squares touching each border fit; one pixel further they are refused, naming the parameter."""
    h, w = tex.shape[:2]
    s = data.draw(st.sampled_from([8, 10, 12, 16, 24, 26]))
    x = data.draw(st.sampled_from([0, w - s, w - s + 1, -1, w]))
    y = data.draw(st.sampled_from([0, h - s, h - s + 1, -1, h]))
    try:
        proto = make_prototype(tex, (x, y, s), block=8)
    except WeftError as e:
        assert rect_problem((x, y, s), tex.shape), f"{(x, y, s)} fits {w}x{h} yet: {e}"
        one_line_naming(e, ["'prototype'"])
        return
    assert not rect_problem((x, y, s), tex.shape)
    assert isinstance(proto, Prototype) and proto.side == s and proto.rect == (x, y, s)
    assert np.isfinite(proto.highpass).all() and np.isfinite(proto.grey).all()
    model = analyse(tex, prototype=proto, block=8, segments=8, refine=1)
    check_image(render(model), (h, w), None)


# --- spectra and candidate transforms ----------------------------------------------------------


@fuzz(80)
@given(
    kind=st.sampled_from(KINDS),
    n=st.sampled_from([4, 8, 9, 16]),
    k=st.integers(1, 3),
    segments=st.sampled_from([4, 8, 32]) | st.integers(-2, 7),
    seed=st.integers(0, 999),
)
def test_centroids_and_candidates_never_nan(kind, n, k, segments, seed):
    patches = np.stack([texture(kind, n, n, False, seed + i) for i in range(k)])
    if segments < 4 or segments % 2:
        with pytest.raises(WeftError) as info:
            centroids(patches, segments=segments)
        one_line_naming(info.value, ["'segments'"])
        return
    M, f1, f2 = segment_sums(patches, segments=segments)
    assert np.isfinite(M).all() and np.isfinite(f1).all() and np.isfinite(f2).all() and (M >= 0).all()
    c = centroids(patches, segments=segments)
    assert c.mu.shape == (k, 2, 2) and np.isfinite(c.mu).all()
    assert np.isfinite(c.mass).all() and np.isfinite(c.masses).all()
    flat = np.ptp(patches, axis=(1, 2)) == 0
    assert (c.mass[flat] == 0).all() and c.degenerate[flat].all()  # the empty spectrum
    T = candidate_transforms(c.mu[0], c.mu)
    assert T.shape == (k, 8, 2, 2) and np.isfinite(T).all()
    sv = singular_values(T)
    assert (sv >= MIN_SCALE - 1e-9).all() and (sv <= MAX_SCALE + 1e-9).all()
    S = sampling_matrices(T)
    assert np.isfinite(S).all()
    assert np.allclose(S @ T, np.eye(2), atol=1e-9)


@given(n=st.integers(2, 64))
@settings(max_examples=30, deadline=None)
def test_cos2_window(n):
    win = cos2_window(n)
    assert win.shape == (n, n) and win.dtype == np.float32 and np.isfinite(win).all()
    assert win.min() >= 0.0 and win.max() <= 1.0
    if n % 2 == 0:  # copies shifted by n/2 sum to one (§3.1)
        h = n // 2
        total = win[:h, :h] + win[h:, :h] + win[:h, h:] + win[h:, h:]
        assert np.allclose(total, 1.0, atol=1e-5)


# --- boundary matching and fields --------------------------------------------------------------


@fuzz(60)
@given(
    tex=textures(),
    mode=st.sampled_from(["none", "partial", "shaker", "bogus"]),
    start=st.sampled_from(["partial", "analysis", "x"]),
    iterations=st.integers(-1, 4),
    per_radius=st.integers(-1, 3),
    seed=st.integers(0, 99),
)
def test_match_boundaries_fuzz(tex, mode, start, iterations, per_radius, seed):
    model = analyse(tex, block=8, segments=8, refine=0, propagate=False)
    problems = set()
    if mode == "bogus":
        problems.add("'boundary'")
    if start == "x":
        problems.add("'shaker_start'")
    if iterations < 1:
        problems.add("'iterations'")
    if per_radius < 1:
        problems.add("'per_radius'")
    try:
        matched, report = match_boundaries(
            model, mode, iterations=iterations, per_radius=per_radius, start=start, rng=seed
        )
    except WeftError as e:
        assert problems, str(e)
        one_line_naming(e, problems)
        return
    assert not problems
    assert np.isfinite(matched.shifts).all() and (np.abs(matched.shifts) <= model.grid.radius).all()
    assert all(np.isfinite(report.errors)) and all(e >= -1e-6 for e in report.errors)
    if mode == "shaker" and len(report.errors) > 1:  # the shaker box never increases the error
        assert report.errors[-1] <= report.errors[0] + 1e-6 * (1 + abs(report.errors[0]))
    err = total_boundary_error(matched)
    assert np.isfinite(err) and err >= -1e-6
    check_image(render(matched), tex.shape[:2], None)


@fuzz(40)
@given(
    tex=textures(),
    field=st.sampled_from(["swirl", "zoom", "rotate", "none", "twirl"]),
    strength=st.floats(0.0, 2.0),
    oh=st.integers(8, 30),
    ow=st.integers(8, 30),
)
def test_field_model_fuzz(tex, field, strength, oh, ow):
    proto = make_prototype(tex, block=8)
    try:
        model = field_model((oh, ow), proto, field, strength=strength, block=8)
    except WeftError as e:
        assert field == "twirl"
        one_line_naming(e, ["'field'"])
        return
    assert field != "twirl"
    assert np.isfinite(model.transforms).all() and np.isfinite(model.sampling).all()
    check_image(render(model), (oh, ow), 3 if tex.ndim == 3 else 1)


@fuzz(60)
@given(
    block=st.sampled_from([8, 7, 9, 0, -8, 258, 8.0, True, "8", None]),
    segments=st.sampled_from([8, 3, 5, 0, -4, 8.0, True, "8", None]),
    lowpass=st.sampled_from(["add", "absorb", "ADD", "", None]),
    colour=st.sampled_from(["pca", "yuv", "rgb", None]),
)
def test_analyse_arguments_are_named(block, segments, lowpass, colour):
    """``analyse`` called directly (no Params class in front): wrong arguments are named."""
    tex = texture("noise", 16, 16, True, 0)
    problems = set()
    if not (type(block) is int and 8 <= block <= 16 and block % 2 == 0):
        problems.add("'block'")
    if not (type(segments) is int and segments >= 4 and segments % 2 == 0):
        problems.add("'segments'")
    if lowpass not in ("add", "absorb"):
        problems.add("'lowpass'")
    if colour not in ("pca", "yuv"):
        problems.add("'colour'")
    try:
        model = analyse(tex, block=block, segments=segments, lowpass=lowpass, colour=colour, refine=0)
    except WeftError as e:
        assert problems, str(e)
        one_line_naming(e, problems)
        return
    assert not problems
    check_image(render(model), (16, 16), None)
