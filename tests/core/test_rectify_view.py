"""Re-projection of a frontal texture into a view (a quad or feature lines) and into the photo."""

import json

import numpy as np
import pytest
from weft.core.errors import GeometryError
from weft.core.examples import example
from weft.core.image import load_image
from weft.core.rectify import load_feature_lines, rectify_feature_lines
from weft.core.rectify.homography import apply_homography
from weft.core.rectify.view import into_photo_plan, load_view, parse_view, quad_homography, view_plan

LINES_JSON = example("perspective").parent / "perspective-lines.json"


@pytest.fixture(scope="module")
def checker():
    y, x = np.mgrid[0:120, 0:160]
    return (((x // 20) + (y // 20)) % 2).astype(np.float32) * 0.8 + 0.1


def test_quad_view_puts_the_corners_on_the_quad(checker):
    quad = [[30, 40], [250, 20], [270, 200], [10, 180]]
    view = parse_view({"quad": quad, "size": [300, 220]})
    h = quad_homography(view.quad, (160, 120))  # view -> texture
    corners = apply_homography(h, np.array(quad, float))
    assert np.allclose(corners, [[-0.5, -0.5], [159.5, -0.5], [159.5, 119.5], [-0.5, 119.5]], atol=1e-4)
    out, cover = view_plan(view, (160, 120), (999, 999)).apply(checker, supersample=3, alpha=True)
    assert out.shape == (220, 300) and cover.shape == (220, 300)
    assert cover[110, 140] == 1.0 and cover[5, 295] == 0.0 and out[5, 295] == 0.0
    # the texture's centre lands at the quad's "centre" (intersection of its diagonals)
    centre = apply_homography(np.linalg.inv(h), np.array([[79.5, 59.5]]))[0]
    assert 100 < centre[0] < 160 and 80 < centre[1] < 130


def test_lines_view_matches_the_equivalent_quad(checker):
    quad = np.array([[30, 40], [250, 20], [270, 200], [10, 180]], float)
    tex_corners = np.array([[0, 0], [159, 0], [159, 119], [0, 119]], float)
    h = np.linalg.inv(quad_homography(quad, (160, 120)))  # texture -> view
    view_corners = apply_homography(h, tex_corners)

    def sides(c):
        return np.array([[*c[i], *c[(i + 1) % 4]] for i in range(4)])

    view = parse_view(
        {"image_lines": sides(view_corners).tolist(), "frontal_lines": sides(tex_corners).tolist(), "size": [300, 220]}
    )
    by_lines, _ = view_plan(view, (160, 120), (300, 220)).apply(checker)
    by_quad, _ = view_plan(parse_view({"quad": quad.tolist(), "size": [300, 220]}), (160, 120), (300, 220)).apply(
        checker
    )
    assert np.abs(by_lines - by_quad).mean() < 0.01


def test_view_without_size_takes_the_default(checker):
    view = load_view('{"quad": [[0, 0], [99, 0], [99, 79], [0, 79]]}')
    plan = view_plan(view, (160, 120), (100, 80))
    assert plan.dst_size == (100, 80)


@pytest.mark.parametrize(
    "data, fragment",
    [
        ({"quad": [[0, 0], [10, 0], [10, 10]]}, "quad = .* must be four corners"),
        ({"quad": [[0, 0], [10, 0], [20, 0], [0, 10]]}, "quad corners 0, 1, 2 lie on one line"),
        ({"quad": [[0, 0], [10, 10], [10, 0], [0, 10]]}, "is not convex"),
        ({"image_lines": [[0, 0, 1, 1]]}, 'no "frontal_lines"'),
        ({"image_lines": [[0, 0, 1, 1]], "frontal_lines": []}, "1 image_lines but 0 frontal_lines"),
        ({"size": [10, 10]}, 'a view needs a "quad"'),
        ({"quad": [[0, 0], [10, 0], [10, 10], [0, 10]], "size": [0, 10]}, "size = \\[0, 10\\] has a side outside"),
        (
            {
                "image_lines": [[0, 0, 50, 0], [50, 0, 50, 40], [50, 40, 0, 40], [0, 40, 500, 0]],
                "frontal_lines": [[0, 0, 9, 0], [9, 0, 9, 9], [9, 9, 0, 9], [0, 9, 0, 0]],
                "size": [60, 50],
            },
            r"view line 3 end \(500, 0\) is outside the view \(60x50\)",
        ),
    ],
)
def test_bad_views_give_one_clear_line(tmp_path, checker, data, fragment):
    path = tmp_path / "v.json"
    path.write_text(json.dumps(data))
    with pytest.raises(GeometryError, match=fragment) as e:
        view = load_view(path)
        view_plan(view, (160, 120), (100, 80))
    assert "\n" not in str(e.value)
    with pytest.raises(GeometryError, match="no such view file"):
        load_view(tmp_path / "missing.json")


def test_into_photo_inverts_the_rectification():
    photo = load_image(example("perspective")).image
    lines = load_feature_lines(LINES_JSON)
    rect = rectify_feature_lines(photo, lines)
    plan = into_photo_plan(
        rect.plan, lines.image_lines, lines.frontal_lines, lines.frontal_size, (480, 360), (512, 384)
    )
    back, alpha = plan.apply(rect.image, alpha=True)
    inside = alpha >= 1.0
    # the rectified wall put back where it came from reproduces the photo there
    assert inside.mean() > 0.35
    assert np.abs(back[inside] - photo[inside]).mean() < 0.03
    # a larger texture is centred on the frontal frame: the wall grows on every side
    bigger = into_photo_plan(
        rect.plan, lines.image_lines, lines.frontal_lines, lines.frontal_size, (480, 360), (1024, 768)
    )
    _, alpha2 = bigger.apply(np.zeros((768, 1024), np.float32), alpha=True)
    assert alpha2.mean() > alpha.mean() + 0.2


def test_into_photo_and_views_stop_at_the_horizon():
    # a floor seen from above: the texture's plane has its horizon at view row ~100; the big
    # texture's far part runs up to it, and nothing of it shows above (no mirrored ghost)
    quad = [[140, 120], [160, 120], [300, 199], [0, 199]]
    h = quad_homography(np.array(quad, float), (100, 100))  # view -> texture, in front at the quad
    from weft.core.rectify.warps import homography_maps, homography_plan

    plan = homography_plan(h, (300, 200), (100, 100), positive_at=(150, 160))
    horizon_y = -(plan.homography[2, 0] * 150 + plan.homography[2, 2]) / plan.homography[2, 1]
    assert 60 < horizon_y < 120
    mx, my = homography_maps(plan.homography, (300, 200))
    assert (mx[: int(horizon_y) - 1] < -1e5).all() and (mx[int(horizon_y) + 2 :] > -1e5).all()
    out, alpha = plan.apply(np.full((100, 100), 0.5, np.float32), alpha=True)
    assert np.isfinite(out).all() and alpha[: int(horizon_y)].max() == 0.0 and alpha[190, 150] == 1.0
