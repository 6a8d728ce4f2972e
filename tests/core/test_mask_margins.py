"""The mask and margins geometry types: parse, paint, serialise, refuse."""

import numpy as np
import pytest
from weft.core.errors import GeometryError, InvalidParameter
from weft.core.geometry import MAX_SIDE, Margins, Mask
from weft.core.image import load_image
from weft.core.studio import MASK, Geometry


def test_from_image_thresholds_white_and_alpha():
    grey = np.array([[0.0, 0.49, 0.51, 1.0]], np.float32)
    assert Mask.from_image(grey).bits.tolist() == [[False, False, True, True]]
    rgba = np.ones((1, 2, 4), np.float32)
    rgba[0, 1, 3] = 0.0  # white but transparent: not the region
    assert Mask.from_image(rgba).bits.tolist() == [[True, False]]
    assert Mask.from_alpha(np.array([[0.0, 1.0]])).bits.tolist() == [[True, False]]
    with pytest.raises(GeometryError, match="shape"):
        Mask.from_image(np.zeros((2, 2, 5)))


def test_brush_eraser_and_lasso_pixels():
    m = Mask.empty(20, 10).painted_line((2, 5), (12, 5), radius=1)
    assert m.bits[5, 2:13].all() and m.bits[4, 7] and m.bits[6, 7] and not m.bits[2, 7]
    assert m.bbox() == (1, 4, 14, 7)  # radius 1 around the segment: one pixel beyond each end and side
    assert (
        Mask.empty(9, 9).painted_line((4, 4), (4, 4), radius=2).area == 21
    )  # a disc: centres within 2.5 px (d² in 0,1,2,4,5)
    erased = m.painted_line((7, 5), (7, 5), radius=1, value=False)  # a dot of the eraser
    assert not erased.bits[5, 7] and erased.bits[5, 2] and erased.area < m.area
    lasso = Mask.empty(20, 20).painted_polygon([(5, 5), (15, 5), (15, 15), (5, 15)])
    assert lasso.bits[10, 10] and not lasso.bits[2, 2] and lasso.area == 121
    assert Mask.empty(4, 4).painted_polygon([(1, 1), (2, 2)]).area == 0  # two points enclose nothing
    assert m == Mask(m.bits.copy()) and hash(m) == hash(Mask(m.bits.copy())) and m != erased


def test_png_round_trip_is_one_bit(tmp_path):
    m = Mask.empty(33, 17).painted_line((0, 0), (32, 16), radius=2)
    path = tmp_path / "m.png"
    m.save(path)
    from PIL import Image

    assert Image.open(path).mode == "1"
    assert Mask.read(path) == m
    assert Mask.from_image(load_image(path).image) == m


def test_size_check_names_both_sizes():
    with pytest.raises(
        GeometryError, match="the mask is 20x10 but the image is 64x48; a mask must be the size of its image"
    ):
        Mask.empty(20, 10).check_size((48, 64, 3))
    with pytest.raises(GeometryError, match=f"side over {MAX_SIDE}"):
        Mask(np.zeros((1, MAX_SIDE + 1), bool))
    with pytest.raises(AttributeError):
        Mask.empty(2, 2).bits = None
    assert not Mask.empty(3, 3).bits.flags.writeable


def test_margins_parse_and_refuse():
    assert Margins.parse("0, 8,128,0") == (0, 8, 128, 0)
    assert Margins.from_json([1, 2, 3, 4]).to_text() == "1,2,3,4"
    assert Margins.parse("0,0,64,32").grown(256, 256) == (320, 288)
    assert not Margins(0, 0, 0, 0) and Margins(0, 1, 0, 0)
    with pytest.raises(InvalidParameter, match=r"parameter 'extend' = '1,2,3' must be L,T,R,B"):
        Margins.parse("1,2,3")
    with pytest.raises(InvalidParameter, match="the left margin -5 is outside 0..16384"):
        Margins.parse("-5,0,0,0")
    with pytest.raises(InvalidParameter, match="the bottom margin 99999 is outside"):
        Margins.parse([0, 0, 0, 99999])
    with pytest.raises(InvalidParameter, match="must be L,T,R,B"):
        Margins.parse([0, 0, 0, 1.5])


def test_a_mask_geometry_is_an_input():
    g = Geometry(MASK, on=("image",), input="mask")
    assert g.key == "mask"
    with pytest.raises(ValueError, match="names the input"):
        Geometry(MASK, on=("image",), param="mask")
    with pytest.raises(ValueError, match="only a mask"):
        Geometry("square", on=("image",), param="p", input="mask")


def test_a_stroke_paints_in_place_what_painted_line_paints_and_knows_if_it_changed_anything():
    from weft.core.geometry import MaskStroke

    base = Mask.empty(40, 30).painted_line((5, 5), (20, 5), radius=2)
    stroke = MaskStroke(base)
    assert stroke.shape == (30, 40) and not stroke.changed
    assert stroke.line((6, 5), (12, 5), 1) is None and not stroke.changed  # over painted pixels only
    box = stroke.line((10, 10), (30, 20), 3)
    expected = base.painted_line((10, 10), (30, 20), 3)
    assert stroke.changed and np.array_equal(stroke.bits, expected.bits)
    changed = expected.bits != base.bits
    rows, cols = np.flatnonzero(changed.any(axis=1)), np.flatnonzero(changed.any(axis=0))
    assert box == (cols[0], rows[0], cols[-1] + 1, rows[-1] + 1)  # exactly the pixels it changed
    assert base == Mask.empty(40, 30).painted_line((5, 5), (20, 5), radius=2)  # the base is untouched
    assert not stroke.bits.flags.writeable
    snap = stroke.snapshot()
    stroke.line((0, 29), (0, 29), 0, value=True)
    erased = stroke.line((12, 12), (12, 12), 1, value=False)  # the eraser
    assert erased is not None and not stroke.bits[12, 12] and snap.bits[12, 12]  # the snapshot stays
    assert np.array_equal(stroke.cut(8, 9, 15, 14), stroke.bits[9:14, 8:15])
    assert stroke.cut(-5, -5, 3, 2).shape == (2, 3)  # clipped to the mask
    final = stroke.mask()
    assert final == Mask(stroke.bits) and not final.bits.flags.writeable
    with pytest.raises(GeometryError, match="ended"):
        stroke.line((1, 1), (2, 2), 1)
    fresh = MaskStroke(None, 7, 5)
    assert fresh.shape == (5, 7) and not fresh.bits.any()
    assert fresh.line((100, 100), (120, 100), 2) is None  # outside the mask: nothing
