"""Parameter fuzzing.

Every registered method's ``Params`` class, built from arbitrary values (in and out of range, wrong
types, None, non-finite numbers, odd text), either builds (and round-trips through to_dict/from_dict)
or raises ``WeftError`` whose one-line message names the parameter; never another exception. Then a
small bounded end-to-end fuzz of ``weft.core.fast.transfer`` (all modes) and ``weft.core.quilting.synthesize``
and ``transfer``.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from weft.core import registry
from weft.core.errors import InvalidParameter, WeftError
from weft.core.params import specs

from tests.core.fuzzing import RUNTIME_WARNINGS_ARE_ERRORS, fuzz

pytestmark = RUNTIME_WARNINGS_ARE_ERRORS

METHODS = registry.methods()

_junk = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(10**6), 10**6),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=12),
    st.lists(st.integers(-5, 5), max_size=3),
    st.dictionaries(st.text(max_size=3), st.integers(), max_size=2),
    st.just(b"bytes"),
    st.just(object()),
)


def _valid(spec) -> st.SearchStrategy:
    """Values of the spec's own type, mostly in range, sometimes just outside it."""
    if spec.kind == "int":
        lo, hi = int(spec.lo if spec.lo is not None else -1000), int(spec.hi if spec.hi is not None else 1000)
        return st.integers(lo - 2, min(hi, lo + 64) + 2) | st.integers(lo, hi)
    if spec.kind == "float":
        lo, hi = float(spec.lo if spec.lo is not None else -100), float(spec.hi if spec.hi is not None else 100)
        return st.floats(lo - 1, hi + 1, allow_nan=False) | st.floats(lo, hi)
    if spec.kind == "bool":
        return st.booleans()
    if spec.kind == "choice":
        return st.sampled_from(spec.choices) | st.sampled_from(
            [c.upper() for c in spec.choices if isinstance(c, str)] or [0]
        )
    if spec.kind == "size":
        side = st.integers(int(spec.lo or 1) - 1, min(int(spec.hi or 64), 96))
        return st.tuples(side, side) | st.builds(lambda w, h: f"{w}x{h}", side, side)
    if spec.kind == "geometry":  # typed geometry: Python callers' forms (a Square also takes "X,Y,S")
        lines = {
            "image_lines": [[1, 1, 9, 1], [1, 9, 9, 9]],
            "frontal_lines": [[0, 0, 8, 0], [0, 8, 8, 8]],
            "frontal_size": [8, 8],
        }
        return st.sampled_from(
            [
                "0,0,8",
                "1,2,16",
                "x",
                (1, 2, 16),
                (-1, 0, 8),
                [0, 0, 7],
                lines,
                {"quad": 1},
                "/nonexistent/lines.json",
                json.dumps(lines),
            ]
        ) | st.text(max_size=16)
    if spec.kind == "str":
        lines = json.dumps(
            {
                "image_lines": [[1, 1, 9, 1], [1, 9, 9, 9]],
                "frontal_lines": [[0, 0, 8, 0], [0, 8, 8, 8]],
                "frontal_size": [8, 8],
            }
        )
        return st.sampled_from(
            ["", "0,0,8", "1,2,16", "x", "{", "[]", lines, "/nonexistent/lines.json", "-1,0,8"]
        ) | st.text(max_size=16)
    raise AssertionError(f"unknown kind {spec.kind}")


@st.composite
def param_dicts(draw, cls):
    out = {}
    for spec in specs(cls):
        choice = draw(st.integers(0, 9))
        if choice < 4:
            continue  # keep the default
        out[spec.name] = draw(_valid(spec)) if choice < 8 else draw(_junk)
    return out


def _check(cls, values: dict) -> None:
    try:
        params = cls(**values)
    except WeftError as e:
        message = str(e)
        assert "\n" not in message
        names = [s.name for s in specs(cls)]
        assert any(f"'{n}'" in message or n in message for n in names), message
        if isinstance(e, InvalidParameter) and e.name is not None:
            assert e.name in message, message
        return
    again = cls.from_dict(json.loads(json.dumps(params.to_dict())))
    assert again == params


@pytest.mark.parametrize("method", list(METHODS))
@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_params_build_or_name_the_parameter(method, data):
    cls = METHODS[method].params
    _check(cls, data.draw(param_dicts(cls)))


@pytest.mark.parametrize("method", list(METHODS))
@settings(max_examples=60, deadline=None)
@given(key=st.text(min_size=1, max_size=8))
def test_unknown_parameter_is_named(method, key):
    cls = METHODS[method].params
    if key in {s.name for s in specs(cls)}:
        return
    with pytest.raises(WeftError) as info:
        cls.from_dict({key: 1})
    assert key in str(info.value)


@pytest.mark.parametrize("method", list(METHODS))
@settings(max_examples=60, deadline=None)
@given(data=st.data())
def test_cli_text_parses_or_names_the_parameter(method, data):
    """What the CLI does with each option's text: ``Spec.parse`` -> value or a named WeftError."""
    spec = data.draw(st.sampled_from(specs(METHODS[method].params)))
    text = data.draw(st.text(max_size=12) | st.sampled_from(["nan", "inf", "-0", "1e400", "3x", "x3", "none", "auto"]))
    try:
        spec.parse(text)
    except WeftError as e:
        assert spec.name in str(e)


# --- end to end ----------------------------------------------------------------------------------


def _image(seed: int, h: int, w: int, colour: bool) -> np.ndarray:
    rng = np.random.default_rng(seed)
    shape = (h, w, 3) if colour else (h, w)
    return rng.random(shape, dtype=np.float32)


@fuzz(20)
@given(
    seed=st.integers(0, 2**16),
    hs=st.integers(6, 16),
    ws=st.integers(6, 16),
    colour=st.booleans(),
    transfer=st.booleans(),
    n=st.sampled_from([3, 5]),
    p=st.floats(0, 1),
    p_l=st.floats(0, 1),
    metric=st.sampled_from(["full", "target", "artistic"]),
    iterations=st.integers(1, 2),
)
def test_fast_transfer_fuzz(seed, hs, ws, colour, transfer, n, p, p_l, metric, iterations):
    from weft.core.fast import transfer as fast_transfer

    n = min(n, hs, ws) | 1
    texture = _image(seed, hs, ws, colour)
    target = _image(seed + 1, 10, 12, colour) if transfer else None
    kwargs = dict(n=n, p=p, p_l=p_l, metric=metric, iterations=iterations, rng=seed)
    if not transfer:
        kwargs.update(size=(12, 10), metric="full")  # the other metrics need a target
    out = fast_transfer(texture, target, **kwargs)
    assert out.shape[:2] == (10, 12)
    assert out.ndim == (3 if colour else 2)
    assert out.dtype == np.float32 and np.isfinite(out).all()
    assert out.min() >= 0.0 and out.max() <= 1.0


@fuzz(20)
@given(
    seed=st.integers(0, 2**16),
    hs=st.integers(6, 20),
    ws=st.integers(6, 20),
    colour=st.booleans(),
    mode=st.sampled_from(["random", "overlap", "mincut"]),
    rule=st.sampled_from(["tol", "epsilon", "sampled"]),
    tol=st.integers(1, 4),
    block=st.integers(2, 6),
    width=st.integers(1, 30),
    height=st.integers(1, 30),
    poisson=st.booleans(),
)
def test_quilting_synthesize_fuzz(seed, hs, ws, colour, mode, rule, tol, block, width, height, poisson):
    from weft.core.quilting import synthesize

    texture = _image(seed, hs, ws, colour)
    overlap = max(1, block // 3)
    try:
        out = synthesize(
            texture,
            size=(width, height),
            block=block,
            overlap=overlap,
            mode=mode,
            rule=rule,
            tol=tol,
            poisson=poisson,
            rng=seed,
        )
    except WeftError as e:  # a combination the method refuses must say which parameter
        assert any(k in str(e) for k in ("size", "block", "overlap", "tol", "poisson", "band")), str(e)
        return
    assert out.shape[:2] == (height, width)
    assert out.ndim == (3 if colour else 2)
    assert out.dtype == np.float32 and np.isfinite(out).all()
    assert out.min() >= 0.0 and out.max() <= 1.0


@fuzz(15)
@given(
    seed=st.integers(0, 2**16),
    hs=st.integers(6, 20),
    ws=st.integers(6, 20),
    colour=st.booleans(),
    th=st.integers(1, 24),
    tw=st.integers(1, 24),
    block=st.integers(2, 8),
    iterations=st.integers(1, 3),
    alpha=st.floats(0, 1),
    mode=st.sampled_from(["overlap", "mincut"]),
    correspondence=st.sampled_from(["blur", "luminance"]),
    remap=st.booleans(),
    poisson=st.booleans(),
)
def test_quilting_transfer_fuzz(
    seed, hs, ws, colour, th, tw, block, iterations, alpha, mode, correspondence, remap, poisson
):
    from weft.core.quilting import transfer

    texture = _image(seed, hs, ws, colour)
    target = _image(seed + 1, th, tw, colour)
    try:
        outs = transfer(
            texture,
            target,
            block=block,
            overlap=max(1, block // 3),
            alpha=alpha,
            iterations=iterations,
            mode=mode,
            correspondence=correspondence,
            remap=remap,
            poisson=poisson,
            return_all=True,
            rng=seed,
        )
    except WeftError as e:
        assert "\n" not in str(e)
        assert any(k in str(e) for k in ("block", "overlap", "tile")), str(e)
        return
    assert len(outs) == iterations
    for out in outs:
        assert out.shape[:2] == (th, tw)
        assert out.ndim == (3 if colour else 2)
        assert out.dtype == np.float32 and np.isfinite(out).all()
        assert out.min() >= 0.0 and out.max() <= 1.0


@fuzz(15)
@given(
    seed=st.integers(0, 2**16),
    hs=st.integers(3, 12),
    ws=st.integers(3, 12),
    colour=st.booleans(),
    mode=st.sampled_from(["superres", "novel"]),
    magnify=st.integers(1, 4),
    p_l=st.floats(0, 1),
    iterations=st.integers(1, 2),
)
def test_fast_superres_and_novel_fuzz(seed, hs, ws, colour, mode, magnify, p_l, iterations):
    from weft.core.fast import transfer as fast_transfer

    texture = _image(seed, hs, ws, colour)
    n = 3
    try:
        out = fast_transfer(texture, None, mode=mode, magnify=magnify, n=n, p_l=p_l, iterations=iterations, rng=seed)
    except WeftError as e:
        assert "\n" not in str(e) and "parameter '" in str(e), str(e)
        return
    assert out.shape[:2] == (hs * magnify, ws * magnify)
    assert out.ndim == (3 if colour else 2)
    assert out.dtype == np.float32 and np.isfinite(out).all()
    assert out.min() >= 0.0 and out.max() <= 1.0
