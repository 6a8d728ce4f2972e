"""Parameter dataclasses: validation messages, specs for the front ends, recipe round trips."""

from dataclasses import FrozenInstanceError, dataclass

import numpy as np
import pytest
from weft.core.errors import InvalidParameter, WeftError
from weft.core.params import Params, Recipe, Spec, as_rng, out_of_range, param, parse_size, specs


@dataclass(frozen=True)
class DemoParams(Params):
    block: int = param(32, lo=2, hi=512, symbol="B", help="block side")
    overlap: int = param(6, lo=1, hi=256, help="overlap")
    alpha: float = param(0.1, lo=0.0, hi=1.0, symbol="α")
    mode: str = param("mincut", choices=("random", "overlap", "mincut"))
    tile: bool = param(False)
    size: tuple = param(None, kind="size", optional=True)

    def check(self):
        if self.overlap >= self.block:
            raise out_of_range("overlap", self.overlap, 1, self.block - 1, f"must be smaller than block = {self.block}")


def test_defaults_and_frozen():
    p = DemoParams()
    assert (p.block, p.overlap, p.alpha, p.mode, p.tile, p.size) == (32, 6, 0.1, "mincut", False, None)
    with pytest.raises(FrozenInstanceError):
        p.block = 3


def test_cross_parameter_message_matches_design():
    with pytest.raises(InvalidParameter) as e:
        DemoParams(block=32, overlap=40)
    assert str(e.value) == "parameter 'overlap' = 40 is outside 1..31 (must be smaller than block = 32)"
    assert e.value.name == "overlap" and e.value.value == 40


@pytest.mark.parametrize(
    "kwargs, fragment",
    [
        ({"block": 1}, "parameter 'block' = 1 is outside 2..512"),
        ({"block": 2.5}, "parameter 'block' = 2.5 must be an integer"),
        ({"block": True}, "must be an integer"),
        ({"alpha": 1.5}, "parameter 'alpha' = 1.5 is outside 0..1"),
        ({"alpha": float("nan")}, "must be a finite number"),
        ({"alpha": "x"}, "must be a number"),
        ({"mode": "best"}, "parameter 'mode' = 'best' is not one of random, overlap, mincut"),
        ({"tile": 1}, "must be true or false"),
        ({"size": (0, 10)}, "parameter 'size' = 0x10 has a side outside 1..16384"),
        ({"size": "abc"}, "must be a size WIDTHxHEIGHT"),
    ],
)
def test_invalid_values_name_parameter_and_range(kwargs, fragment):
    with pytest.raises(InvalidParameter) as e:
        DemoParams(**kwargs)
    assert fragment in str(e.value)
    assert "\n" not in str(e.value)


def test_numpy_scalars_and_ints_are_canonicalised():
    p = DemoParams(block=np.int64(16), overlap=np.int32(4), alpha=1, size=[64, 32])
    assert type(p.block) is int and type(p.alpha) is float
    assert p.size == (64, 32)


def test_specs_describe_fields_for_front_ends():
    s = {sp.name: sp for sp in specs(DemoParams)}
    assert list(s) == ["block", "overlap", "alpha", "mode", "tile", "size"]
    assert s["block"] == Spec(name="block", kind="int", default=32, lo=2, hi=512, symbol="B", help="block side")
    assert s["alpha"].symbol == "α" and s["alpha"].kind == "float"
    assert s["mode"].choices == ("random", "overlap", "mincut")
    assert s["size"].option == "--size" and s["size"].optional
    assert s["block"].range_text() == "2..512"


def test_parse_from_command_line_text():
    s = {sp.name: sp for sp in specs(DemoParams)}
    assert s["block"].parse("17") == 17
    assert s["alpha"].parse("0.25") == 0.25
    assert s["tile"].parse("yes") is True
    assert s["size"].parse("640x480") == (640, 480)
    assert s["size"].parse("auto") is None
    with pytest.raises(InvalidParameter, match="'block' = 'seventeen' must be an integer"):
        s["block"].parse("seventeen")
    assert parse_size("256") == (256, 256)


def test_dict_round_trip_and_unknown_keys():
    p = DemoParams(block=20, overlap=5, size=(100, 50))
    d = p.to_dict()
    assert d["size"] == [100, 50]
    assert DemoParams.from_dict(d) == p
    with pytest.raises(InvalidParameter, match="unknown parameter bogus for DemoParams"):
        DemoParams.from_dict({"bogus": 1})
    assert p.replace(alpha=0.5).alpha == 0.5
    with pytest.raises(InvalidParameter, match="unknown parameter"):
        p.replace(nope=1)


def test_as_rng_determinism():
    a = as_rng(7).integers(0, 1000, 5)
    b = as_rng(7).integers(0, 1000, 5)
    assert (a == b).all()
    g = np.random.default_rng(1)
    assert as_rng(g) is g
    with pytest.raises(InvalidParameter, match="rng"):
        as_rng("seed")


def test_recipe_json_round_trip(tmp_path):
    r = Recipe(method="quilt", params={"block": 16}, inputs={"texture": "a.png"}, seed=7)
    path = tmp_path / "r.json"
    r.save(path)
    back = Recipe.load(path)
    assert back.method == "quilt" and back.params == {"block": 16} and back.seed == 7
    # Relative inputs resolve against the recipe's folder.
    assert back.inputs["texture"] == str(tmp_path.resolve() / "a.png")
    assert Recipe.from_json(r.to_json()) == r


@pytest.mark.parametrize(
    "text, fragment",
    [
        ("{not json", "not valid JSON"),
        ("[]", "must be a JSON object"),
        ('{"weft": 2, "method": "quilt"}', "version 1"),
        ('{"weft": 1}', 'no "method"'),
        ('{"weft": 1, "method": "quilt", "seed": -1}', "non-negative integer"),
        ('{"weft": 1, "method": "quilt", "inputs": {"texture": 3}}', "map input names to file paths"),
    ],
)
def test_bad_recipes(text, fragment):
    with pytest.raises(WeftError, match=fragment.replace("(", r"\(")):
        Recipe.from_json(text)


def test_missing_recipe_file(tmp_path):
    with pytest.raises(WeftError, match="no such recipe file"):
        Recipe.load(tmp_path / "nope.json")
