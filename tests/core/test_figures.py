"""Every figure a studio method reports has a human reading (label, unit) in its studio description;
the report JSON keeps the keys."""

import json
import re

import numpy as np
import pytest
from weft.core import registry
from weft.core.examples import RESOURCES, example
from weft.core.geometry import FeatureLines
from weft.core.image import load_image, resize
from weft.core.studio import Figure, describe_figures

SNAKE = re.compile(r"\b[a-z0-9]+(?:_[a-z0-9]+)+\b")


def _hole(side: int) -> np.ndarray:
    """A mask with a white square in the middle (what to fill)."""
    mask = np.zeros((side, side), np.float32)
    mask[side // 3 : side // 2, side // 3 : side // 2] = 1.0
    return mask


def _small(name: str, side: int) -> np.ndarray:
    img = load_image(example(name)).image
    h, w = img.shape[:2]
    k = side / max(h, w)
    return resize(img, (max(8, round(w * k)), max(8, round(h * k))), interpolation="area")


def _lines() -> FeatureLines:
    data = json.loads((RESOURCES / "perspective-lines.json").read_text())
    return FeatureLines(data["image_lines"], data["frontal_lines"], data["frontal_size"])


# (method, inputs, params): together they make every figure each studio method can report
CASES = [
    ("fast", lambda: {"texture": _small("wood-grain", 48), "target": _small("astronaut", 40)}, {}),
    ("fast", lambda: {"texture": _small("wood-grain", 48)}, {"size": (40, 40)}),
    ("quilt", lambda: {"texture": _small("brick", 64)}, {"size": (64, 64), "mode": "mincut"}),
    ("quilt", lambda: {"texture": _small("brick", 64), "target": _small("astronaut", 48)}, {}),
    ("affine", lambda: {"texture": _small("cat-fur", 96)}, {"block": 16, "boundary": "shaker"}),
    ("fill", lambda: {"image": _small("brick", 64), "mask": _hole(64)}, {}),
    (
        "nfpt",
        lambda: {"photo": load_image(example("perspective")).image},
        {"lines": _lines(), "size": (64, 64), "block": 32, "overlap": 8, "into_photo": True},
    ),
]


@pytest.mark.parametrize("name,inputs,params", CASES, ids=[f"{c[0]}-{i}" for i, c in enumerate(CASES)])
def test_every_scalar_figure_of_a_studio_method_has_a_human_reading(name, inputs, params):
    method = registry.get(name)
    result = method.run(inputs(), method.params(**params), rng=0)
    scalars = {k for k, v in result.figures.items() if v is not None and not isinstance(v, (list, tuple, dict))}
    assert scalars, result.figures
    missing = scalars - set(method.studio.figures)
    assert not missing, f"{name} reports {sorted(missing)} with no Figure in its studio description"
    words = method.studio.describe(result.figures)
    assert len(words) == len(scalars)
    for text in words:
        assert not SNAKE.search(text), text
    json.dumps(dict(result.figures))  # the report keeps keys and values as they are


def test_every_studio_method_has_a_case_above():
    untested = set(registry.studio_methods()) - {c[0] for c in CASES}
    assert not untested, f"add a case to CASES for {sorted(untested)}: every figure it reports needs a Figure"


def test_a_figure_renders_its_value_in_words_and_units():
    assert (
        Figure("largest verbatim copy", "%", "of the sample", digits=2).render(0.0532)
        == "largest verbatim copy 5.3 % of the sample"
    )
    assert Figure("coherent pixels", "%", digits=2).render(0.83) == "coherent pixels 83 %"
    assert Figure("error", "px", digits=2).prefixed("rectification").render(1.2) == "rectification error 1.2 px"
    assert Figure("blocks").render(np.int64(36)) == "blocks 36"
    assert Figure("repair").render(True) == "repair yes" and Figure("repair").render(np.False_) == "repair no"
    assert Figure("warp").render("homography") == "warp homography"
    # lists and missing values are left to the report; a key no table names reads as its words
    assert describe_figures({"homography": [[1, 0], [0, 1]], "prototype": None, "odd_count": 3}, {}) == ["odd count 3"]
