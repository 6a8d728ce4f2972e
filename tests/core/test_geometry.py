"""Typed geometry (weft.core.geometry) and the studio descriptions (weft.core.studio), without Qt."""

import json

import numpy as np
import pytest
from weft.core import registry
from weft.core.errors import GeometryError, InvalidParameter
from weft.core.geometry import FeatureLines, LineDraft, Square
from weft.core.params import Recipe
from weft.core.preview import reduce_for_preview

LINES = {
    "image_lines": [[1, 1, 30, 2], [2, 20, 31, 22]],
    "frontal_lines": [[0, 0, 32, 0], [0, 20, 32, 20]],
    "frontal_size": [32, 24],
}


@pytest.mark.parametrize(
    "text, fragment",
    [
        ("a,b", "parameter 'region' = 'a,b' must be X,Y,SIDE"),
        ("1,2", "must be X,Y,S"),
        ("-1,0,8", "the corner -1,0 must not be negative"),
        ("0,0,1", "the side 1 must be at least 2"),
        ((1, 2, 8.5), "must be X,Y,SIDE"),
        ((True, 2, 8), "must be X,Y,SIDE"),
    ],
)
def test_one_square_parser_with_one_line_errors(text, fragment):
    with pytest.raises(InvalidParameter) as e:
        Square.parse(text)
    assert fragment in str(e.value) and "\n" not in str(e.value)


def test_a_square_parses_once_and_writes_once():
    sq = Square.parse(" 3 , 4 , 16 ")
    assert sq == (3, 4, 16) and sq.to_text() == "3,4,16" and sq.to_json() == [3, 4, 16]
    assert Square.from_json([3, 4, 16]) == sq and Square.from_json("3,4,16") == sq  # older recipes' text
    assert Square.coerce(sq) is sq
    with pytest.raises(InvalidParameter, match="the side 15 must be even and at least 8"):
        Square(0, 0, 15).check_side("prototype", minimum=8, even=True)
    img = np.arange(20 * 30, dtype=np.float32).reshape(20, 30) / 600
    assert np.array_equal(sq.crop(img), img[4:20, 3:19])


def test_feature_lines_are_values():
    a = FeatureLines.from_mapping(LINES)
    b = FeatureLines.coerce(json.dumps(LINES))  # JSON text by the command-line rule
    assert a == b and hash(a) == hash(b) and len(a) == 2 and a.to_json()["frontal_size"] == [32, 24]
    with pytest.raises(AttributeError):
        a.frontal_size = (1, 1)


def test_a_line_draft_completes_to_the_finished_pairs():
    draft = LineDraft(((0, 0, 5, 5), (1, 1, 9, 9)), ((0, 0, 4, 4),), (16, 16))
    done = draft.complete()
    assert draft.pairs == 1 and len(done) == 1 and done.frontal_size == (16, 16)
    assert LineDraft().complete() is None
    with pytest.raises(GeometryError, match=r"image_lines\[0\]"):
        LineDraft(((0, 0, 5),), (), (16, 16))


def test_params_hold_geometry_typed_and_round_trip_through_json(tmp_path):
    nfpt = registry.get("nfpt").params
    affine = registry.get("affine").params
    p = affine(prototype="8,8,32")
    assert isinstance(p.prototype, Square) and p.to_dict()["prototype"] == [8, 8, 32]
    assert affine.from_dict(json.loads(json.dumps(p.to_dict()))) == p
    q = nfpt(lines=LINES, size=(64, 64), block=16, overlap=4)
    assert isinstance(q.lines, FeatureLines)
    assert nfpt.from_dict(json.loads(json.dumps(q.to_dict()))) == q
    (tmp_path / "l.json").write_text(json.dumps(LINES))  # an older recipe's file name, beside the recipe
    assert nfpt.from_dict({"lines": "l.json"}, base=tmp_path).lines == q.lines
    r = Recipe("quilt", {}, {"texture": str(tmp_path / "t.png")}, 3, Square(1, 2, 8))
    data = json.loads(r.to_json(relative_to=tmp_path))
    assert data["region"] == [1, 2, 8] and data["inputs"] == {"texture": "t.png"}
    assert Recipe.from_json(r.to_json()).region == (1, 2, 8)


def test_previews_are_reduced_as_each_method_says():
    fast, nfpt, affine = (registry.get(n) for n in ("fast", "nfpt", "affine"))
    tex = np.zeros((50, 60, 3), np.float32)
    target = np.zeros((800, 600, 3), np.float32)
    inputs, params = reduce_for_preview(fast.studio, {"texture": tex, "target": target}, fast.params(), 400)
    assert inputs["target"].shape == (400, 300, 3) and inputs["texture"] is tex
    _, small = reduce_for_preview(nfpt.studio, {"photo": tex}, nfpt.params(size=(1000, 500)), 400)
    assert small.size == (400, 200)
    same_inputs, same = reduce_for_preview(affine.studio, {"texture": target}, affine.params(), 400)
    assert same_inputs["texture"] is target and same == affine.params()  # affine reduces nothing


def test_every_studio_method_describes_inputs_it_has():
    for name, method in registry.studio_methods().items():
        names = {i.name for i in method.inputs}
        studio = method.studio
        assert studio.canvas in names and studio.title, name
        for g in studio.geometry:
            assert set(g.on) <= names, name
        assert set(studio.preview_inputs) <= names and set(studio.compare) <= names, name
        assert set(studio.examples) <= names, name


def test_every_geometry_parameter_type_is_a_geometry_value():
    """The studio, the CLI and recipes read a geometry parameter only through the GeometryValue
    interface; every method's geometry types have it, and a value's JSON form reads back equal."""
    from weft.core.geometry import GeometryValue, Margins
    from weft.core.params import specs

    types = {spec.type for m in registry.methods().values() for spec in specs(m.params) if spec.kind == "geometry"}
    assert Square in types and FeatureLines in types
    for t in types:
        assert issubclass(t, GeometryValue), t
    for value in (Square(3, 4, 16), Margins(0, 8, 16, 0), FeatureLines.coerce(LINES)):
        assert isinstance(value, GeometryValue)
        assert type(value).from_json(value.to_json()) == value


def test_a_geometry_parameter_without_the_interface_is_refused():
    from weft.core.params import param

    class NoJson:
        @classmethod
        def parse(cls, text, name="x"):
            return cls()

        @classmethod
        def coerce(cls, value, name="x"):
            return cls()

    with pytest.raises(TypeError, match="type NoJson has no from_json, to_json"):
        param(None, kind="geometry", type=NoJson, optional=True)
