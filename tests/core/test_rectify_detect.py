"""Suggested feature lines on synthetic perspective photos with a known homography."""

import numpy as np
import pytest
from weft.core.errors import GeometryError
from weft.core.rectify import REFUSAL, rectify, suggest_lines

from benchmarks.rectify_suggest import Case, photograph, residual, text, tiles


@pytest.fixture(scope="module")
def tile_texture():
    return tiles()


@pytest.mark.parametrize("tilt, phi", [(20.0, 35.0), (40.0, -55.0)])
def test_suggestion_rectifies_a_tiled_floor_up_to_a_similarity(tile_texture, tilt, phi):
    case = Case("t", "tiles", "straight", tilt, phi, 4.0, 1.1, 0.8, 0.015, seed=7)
    photo, truth = photograph(case, tile_texture)
    s = suggest_lines(photo)
    angle, aspect = residual(s.homography, truth, s.lines.frontal_size)
    assert angle <= 1.0 and aspect <= 0.02
    assert s.aspect == "camera" and s.source == "lines" and 0.5 < s.confidence <= 1.0
    # the lines are the suggestion: rectifying with them reproduces its homography
    out = rectify(photo, s.lines.image_lines, s.lines.frontal_lines, s.lines.frontal_size)
    a2, s2 = residual(out.homography, truth, s.lines.frontal_size)
    assert a2 <= 1.0 and s2 <= 0.02
    assert out.mask.mean() > 0.99  # the frontal frame lies inside the photo


def test_a_steep_view_of_a_checkerboard_is_rectified_up_to_a_similarity():
    # at 60 degrees the squares' edges are a few reduced pixels long: their directions must come
    # from the photo's full resolution, or the two vanishing points miss by degrees
    from benchmarks.rectify_suggest import checkerboard

    case = Case("c", "checkerboard", "straight", 60.0, 30.0, 3.0, 1.2, 0.8, 0.02, seed=5)
    photo, truth = photograph(case, checkerboard())
    s = suggest_lines(photo)
    angle, aspect = residual(s.homography, truth, s.lines.frontal_size)
    assert angle <= 1.0 and aspect <= 0.02


def test_suggestion_is_deterministic_and_reports_the_angle_between_directions():
    case = Case("t", "text", "straight", 30.0, 50.0, -3.0, 1.0, 0.8, 0.015, seed=3)
    photo, truth = photograph(case, text())
    a, b = suggest_lines(photo), suggest_lines(photo)
    assert a.lines == b.lines
    # the truth's two frontal directions at the photo's centre
    h = truth
    centre = np.linalg.inv(h) @ np.array([575.5, 431.5, 1.0])
    centre = centre[:2] / centre[2]
    from weft.core.rectify.homography import apply_homography

    p = apply_homography(h, np.array([centre, centre + [1, 0], centre + [0, 1]]))
    d1, d2 = p[1] - p[0], p[2] - p[0]
    true_angle = np.degrees(np.arccos(abs(d1 @ d2) / np.linalg.norm(d1) / np.linalg.norm(d2)))
    assert a.angle_deg == pytest.approx(true_angle, abs=3.0)
    assert a.report()["suggest_confidence"] == round(a.confidence, 3)


def test_parallel_stripes_are_refused_in_one_line():
    yy, xx = np.mgrid[0:480, 0:640].astype(np.float32)
    stripes = (0.5 + 0.4 * np.sign(np.sin((xx * 0.8 + yy * 0.3) / 6.0))).astype(np.float32)
    with pytest.raises(GeometryError) as e:
        suggest_lines(stripes)
    assert str(e.value) == REFUSAL


def test_a_photo_without_structure_is_refused_in_one_line():
    rng = np.random.default_rng(1)
    flat = np.clip(0.5 + 0.05 * rng.standard_normal((300, 400, 3)), 0, 1).astype(np.float32)
    with pytest.raises(GeometryError, match="^no two families of straight lines found: draw feature lines$"):
        suggest_lines(flat)


def test_a_repeating_texture_without_lines_is_rectified_from_its_repeats():
    from benchmarks.rectify_suggest import gravel

    case = Case("g", "gravel", "without", 35.0, 40.0, 2.0, 1.0, 0.8, 0.015, seed=11)
    photo, truth = photograph(case, gravel())
    s = suggest_lines(photo)
    assert s.source == "repeats"
    angle, aspect = residual(s.homography, truth, s.lines.frontal_size)
    assert angle <= 1.0 and aspect <= 0.02
    with pytest.raises(GeometryError, match=REFUSAL):
        suggest_lines(photo, repeats=False)
