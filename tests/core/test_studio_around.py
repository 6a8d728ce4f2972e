"""core.preview.crop_around (the preview around a mask stroke) and sessions' masks and margins (Qt-free)."""

import json
from dataclasses import dataclass

import numpy as np
import pytest
from weft.core import registry
from weft.core.errors import WeftError
from weft.core.geometry import Margins, Mask
from weft.core.params import Params, param
from weft.core.preview import AROUND_SIDE, crop_around
from weft.core.registry import InputSpec, Method, Result
from weft.core.session import mask_file, read_session
from weft.core.studio import MARGINS, MASK, Geometry, Studio


@dataclass(frozen=True)
class HoleParams(Params):
    grow: Margins = param(None, kind="geometry", type=Margins, optional=True, help="margins")


STUDIO = Studio(
    title="t",
    canvas="picture",
    preview_around="hole",
    masks_of={"source": ("texture", "picture")},
    geometry=(Geometry(MASK, on=("picture",), input="hole"), Geometry(MARGINS, on=("picture",), param="grow")),
)


def _inputs(h=300, w=400, hole=None):
    rng = np.random.default_rng(0)
    picture = rng.random((h, w, 3)).astype(np.float32)
    other = rng.random((50, 60, 3)).astype(np.float32)
    mask = np.zeros((h, w), np.float32) if hole is None else hole
    return {"picture": picture, "hole": mask, "texture": other}


def test_the_crop_is_the_painted_region_near_the_stroke_with_context_around_it():
    hole = np.zeros((300, 400), np.float32)
    hole[100:120, 200:230] = 1.0  # painted near the stroke
    hole[10:20, 10:20] = 1.0  # painted far away: not in this preview
    inputs = _inputs(hole=hole)
    around = crop_around(STUDIO, inputs, HoleParams(), (205, 105, 215, 115))
    x0, y0, x1, y1 = around.box
    assert x0 < 200 and y0 < 100 and x1 > 230 and y1 > 120  # the whole painted blob, and room around it
    assert x0 > 20 and y0 > 20  # not the far one
    assert max(x1 - x0, y1 - y0) <= AROUND_SIDE
    assert np.array_equal(around.inputs["picture"], inputs["picture"][y0:y1, x0:x1])
    assert np.array_equal(around.inputs["hole"], hole[y0:y1, x0:x1])
    assert around.inputs["texture"] is inputs["texture"]  # another image's size: kept whole
    assert around.offset == (0, 0)


def test_a_large_crop_is_scaled_to_the_side_and_pasted_back_at_full_size():
    hole = np.zeros((300, 400), np.float32)
    hole[20:280, 30:370] = 1.0
    inputs = _inputs(hole=hole)
    around = crop_around(STUDIO, inputs, HoleParams(), (100, 100, 110, 110), side=64)
    x0, y0, x1, y1 = around.box
    small = around.inputs["picture"]
    assert max(small.shape[:2]) == 64 and small.shape[:2] != (y1 - y0, x1 - x0)
    assert set(np.unique(around.inputs["hole"])) <= {0.0, 1.0}  # the mask stays a mask
    base = np.zeros((300, 400, 3), np.float32)
    pasted = around.paste(base, np.ones_like(small))
    assert pasted[y0:y1, x0:x1].min() == pytest.approx(1.0) and pasted.sum() == pytest.approx((y1 - y0) * (x1 - x0) * 3)
    assert base.sum() == 0  # the base is not changed


def test_margins_are_off_in_the_crop_and_offset_the_paste():
    hole = np.zeros((300, 400), np.float32)
    hole[150:160, 150:160] = 1.0
    around = crop_around(STUDIO, _inputs(hole=hole), HoleParams(grow=Margins(7, 5, 0, 0)), (150, 150, 160, 160))
    assert around.params.grow is None and around.offset == (7, 5)
    x0, y0, x1, y1 = around.box
    grown = np.zeros((305, 407, 3), np.float32)
    part = np.ones((y1 - y0, x1 - x0, 3), np.float32)
    pasted = around.paste(grown, part)
    assert pasted[y0 + 5 : y1 + 5, x0 + 7 : x1 + 7].min() == 1.0 and pasted.sum() == part.sum()
    assert around.paste(np.zeros((10, 10, 3), np.float32), part) is None  # does not fit: nothing


def test_no_crop_without_anything_painted_near_the_stroke_or_without_the_field():
    hole = np.zeros((300, 400), np.float32)
    hole[10:20, 10:20] = 1.0
    assert crop_around(STUDIO, _inputs(hole=hole), HoleParams(), (200, 200, 210, 210)) is None
    plain = Studio(title="t", canvas="picture", geometry=STUDIO.geometry)
    assert crop_around(plain, _inputs(hole=hole), HoleParams(), (10, 10, 20, 20)) is None
    inputs = _inputs(hole=hole)
    del inputs["hole"]
    assert crop_around(STUDIO, inputs, HoleParams(), (10, 10, 20, 20)) is None


HOLE = Method(
    name="hole-test",
    summary="t",
    params=HoleParams,
    inputs=(InputSpec("picture", "p"), InputSpec("hole", "h", required=False)),
    run=lambda inputs, params, **kw: Result(inputs["picture"]),
    studio=STUDIO,
)


@pytest.fixture
def hole_method():
    registry.register(HOLE)
    yield HOLE
    registry.unregister(HOLE.name)


def test_a_session_reads_its_mask_png_and_margins(hole_method, tmp_path):
    session = tmp_path / "s.weft.json"
    png = mask_file(session, HOLE.name, "hole")
    assert png == tmp_path / "s.weft.hole-test.hole.png"
    mask = Mask.empty(40, 30).painted_line((5, 5), (30, 20), 3)
    mask.save(png)
    session.write_text(
        json.dumps(
            {"weft_session": 1, "method": HOLE.name, "geometry": {HOLE.name: {"hole": png.name, "grow": [1, 2, 3, 4]}}}
        )
    )
    data = read_session(session)
    assert data.geometry[HOLE.name] == {"hole": mask, "grow": Margins(1, 2, 3, 4)}


def test_a_session_naming_a_missing_mask_or_bad_margins_says_which(hole_method, tmp_path):
    session = tmp_path / "s.weft.json"
    session.write_text(
        json.dumps({"weft_session": 1, "method": HOLE.name, "geometry": {HOLE.name: {"hole": "gone.png"}}})
    )
    with pytest.raises(WeftError, match=r"s\.weft\.json: hole-test: .*gone\.png"):
        read_session(session)
    session.write_text(
        json.dumps({"weft_session": 1, "method": HOLE.name, "geometry": {HOLE.name: {"grow": [1, -2, 3, 4]}}})
    )
    with pytest.raises(WeftError, match=r"s\.weft\.json: hole-test: parameter 'grow' = 1,-2,3,4: the top margin -2"):
        read_session(session)


def test_a_session_read_with_a_dropped_list_leaves_out_a_missing_mask_and_says_so(hole_method, tmp_path):
    session = tmp_path / "s.weft.json"
    session.write_text(
        json.dumps(
            {
                "weft_session": 1,
                "method": HOLE.name,
                "geometry": {HOLE.name: {"hole": "gone.png", "grow": [1, 2, 3, 4]}},
            }
        )
    )
    dropped = []
    data = read_session(session, dropped=dropped)
    assert data.geometry[HOLE.name] == {"grow": Margins(1, 2, 3, 4)}
    assert len(dropped) == 1 and dropped[0].startswith(f"{session}: hole-test: ") and "gone.png" in dropped[0]
    assert dropped[0].endswith("; dropped")
    session.write_text(
        json.dumps(
            {
                "weft_session": 1,
                "method": HOLE.name,  # not a file name: still refused
                "geometry": {HOLE.name: {"hole": 3}},
            }
        )
    )
    with pytest.raises(WeftError, match=r"s\.weft\.json: hole-test: hole = 3 must be the name of a mask PNG"):
        read_session(session, dropped=[])


def test_a_texture_the_size_of_the_painted_image_is_kept_whole_and_a_source_mask_goes_with_its_image():
    """Only what belongs to the painted image is cropped: a second texture of the same size is an
    image of its own (a preview with --texture must copy from all of it, not from a corner); a
    source mask of the image's size is cropped with the image, unless such a texture is open (then it
    is the texture's)."""
    hole = np.zeros((300, 400), np.float32)
    hole[100:120, 200:230] = 1.0
    inputs = _inputs(hole=hole)
    rng = np.random.default_rng(1)
    inputs["texture"] = rng.random((300, 400, 3)).astype(np.float32)  # the painted image's size
    source = np.zeros((300, 400), np.float32)
    source[:, :200] = 1.0
    inputs["source"] = source
    around = crop_around(STUDIO, inputs, HoleParams(), (205, 105, 215, 115))
    x0, y0, x1, y1 = around.box
    assert np.array_equal(around.inputs["picture"], inputs["picture"][y0:y1, x0:x1])
    assert np.array_equal(around.inputs["hole"], hole[y0:y1, x0:x1])
    assert around.inputs["texture"] is inputs["texture"]
    assert around.inputs["source"] is inputs["source"]  # goes with the texture
    del inputs["texture"]
    around = crop_around(STUDIO, inputs, HoleParams(), (205, 105, 215, 115))
    assert np.array_equal(around.inputs["source"], source[y0:y1, x0:x1])  # goes with the image


@pytest.mark.parametrize("stroke", [(205, 105, 215, 115), (0, 0, 6, 4), (380, 280, 399, 299), (150, 20, 260, 60)])
def test_a_part_of_the_mask_around_the_stroke_gives_the_crop_the_whole_mask_gives(stroke):
    """The studio cuts only ``around_region`` of a stroke's mask (not the whole mask, 64 MB as a
    float image at 4096²): the crop, its inputs and its box are those of the whole mask."""
    from weft.core.preview import around_region

    rng = np.random.default_rng(3)
    hole = np.zeros((300, 400), np.float32)
    hole[100:120, 200:230] = 1.0
    hole[0:10, 0:9] = 1.0
    hole[270:300, 370:400] = 1.0
    hole[30:50, 140:270] = rng.random((20, 130)) > 0.5
    inputs = _inputs(hole=hole)
    whole = crop_around(STUDIO, inputs, HoleParams(grow=Margins(3, 4, 0, 0)), stroke)
    x0, y0, x1, y1 = around_region(stroke, 400, 300)
    assert 0 <= x0 < x1 <= 400 and 0 <= y0 < y1 <= 300 and (x1 - x0) * (y1 - y0) < 400 * 300
    part = (hole[y0:y1, x0:x1] > 0.5).copy()
    without = {k: v for k, v in inputs.items() if k != "hole"}
    cut = crop_around(STUDIO, without, HoleParams(grow=Margins(3, 4, 0, 0)), stroke, mask_part=(part, (x0, y0)))
    assert whole is not None and cut is not None
    assert cut.box == whole.box and cut.offset == whole.offset == (3, 4) and cut.params == whole.params
    assert set(cut.inputs) == set(whole.inputs)
    for name in whole.inputs:
        assert cut.inputs[name].dtype == whole.inputs[name].dtype
        assert np.array_equal(cut.inputs[name], whole.inputs[name]), name
    # a part that does not cover the region is refused, not read past its edge
    with pytest.raises(ValueError, match="does not cover"):
        crop_around(STUDIO, without, HoleParams(), stroke, mask_part=(part[1:], (x0, y0 + 1)))


def test_a_part_with_nothing_painted_near_the_stroke_gives_no_crop():
    from weft.core.preview import around_region

    x0, y0, x1, y1 = around_region((100, 100, 110, 110), 400, 300)
    part = np.zeros((y1 - y0, x1 - x0), bool)
    inputs = {k: v for k, v in _inputs().items() if k != "hole"}
    assert crop_around(STUDIO, inputs, HoleParams(), (100, 100, 110, 110), mask_part=(part, (x0, y0))) is None
