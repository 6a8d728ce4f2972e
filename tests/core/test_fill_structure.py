"""``weft fill --structure`` (``weft.core.fill.structure``): the edges entering a hole paired and
continued along curves, as a guide the ``patchmatch`` engine matches. The guide's curve lies where a
drawn circle runs, a channel per edge, nothing when no edges pair up (then the same pixels as
without it); the fill keeps a circle's edge and the benchmark photo's saucer rim on their sides;
known pixels untouched, seeds deterministic, the guide's bad shapes and the option's bad
combinations one-line errors, on the command line too."""

import json

import cv2
import numpy as np
import pytest
from weft.app.cli import main
from weft.core.errors import ImageError, InvalidParameter
from weft.core.fill import FillParams, fill, fill_image
from weft.core.fill.band import band_region
from weft.core.fill.patchmatch import fill_patchmatch
from weft.core.fill.structure import REACH, structure_guide
from weft.core.image import load_image, save_image

SIZE, CENTRE = 128, (120.0, 120.0)


def _picture(radii=(80,), seed=0):
    """Pale wood-like ground, a red disc of the first radius centred off the picture's lower right
    corner (only its arc is seen), dark brown inside each further radius; mild noise. Returns the
    image and the index of the region each pixel is in (0 ground, 1 red, 2 dark)."""
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[:SIZE, :SIZE]
    r2 = (yy - CENTRE[0]) ** 2 + (xx - CENTRE[1]) ** 2
    region = sum((r2 <= r * r).astype(int) for r in radii)
    colours = np.array([[0.8, 0.65, 0.5], [0.6, 0.12, 0.08], [0.25, 0.1, 0.05]])
    img = colours[region] + rng.normal(0.0, 0.02, (SIZE, SIZE, 3))
    return np.clip(img, 0, 1).astype(np.float32), region


def _hole_on(radius, degrees, hole_radius):
    """A round hole centred on the circle of ``radius`` at ``degrees`` (225: up and left)."""
    yy, xx = np.mgrid[:SIZE, :SIZE]
    a = np.radians(degrees)
    py, px = CENTRE[0] + radius * np.sin(a), CENTRE[1] + radius * np.cos(a)
    return (yy - py) ** 2 + (xx - px) ** 2 <= hole_radius**2


def _distance_to_circle(radius):
    yy, xx = np.mgrid[:SIZE, :SIZE]
    return np.abs(np.hypot(yy - CENTRE[0], xx - CENTRE[1]) - radius)


def test_the_guide_continues_a_circles_edge_across_the_hole_with_its_sides():
    img, region = _picture()
    hole = _hole_on(80, 225, 16)
    guide, n = structure_guide(img, hole)
    assert n == 1 and guide.shape == (SIZE, SIZE, 1) and guide.dtype == np.float32
    g = guide[..., 0]
    assert np.abs(g).max() <= 1.0
    # in the hole, on either side of the true arc (2..12 px from it), the guide's sign tells the disc
    # from the ground: the curve lies where the circle runs, though the hole hides it
    d = _distance_to_circle(80)
    near = hole & (d > 2) & (d < 12)
    inside = region[near] > 0
    sign = np.sign(g[near])
    assert near.sum() > 300 and np.all(sign != 0)
    assert np.all(sign == np.where(inside, sign[inside][0], -sign[inside][0]))
    # 1 on the structure, fading to 0 at REACH px from it
    assert np.abs(g[hole & (d < 0.5)]).min() > 0.9
    assert np.all(g[d > REACH + 3] == 0)


def test_two_parallel_edges_get_a_channel_each():
    img, region = _picture(radii=(80, 66))  # a red ring with a dark inside: two arcs 14 px apart
    hole = _hole_on(73, 225, 18)
    guide, n = structure_guide(img, hole)
    assert n == 2 and guide.shape == (SIZE, SIZE, 2)
    # each channel is 1 on its own arc: one the outer circle, the other the inner
    on_outer = hole & (_distance_to_circle(80) < 0.5)
    on_inner = hole & (_distance_to_circle(66) < 0.5)
    outer = int(np.argmax([np.abs(guide[..., k][on_outer]).mean() for k in range(2)]))
    assert np.abs(guide[..., outer][on_outer]).min() > 0.9
    assert np.abs(guide[..., 1 - outer][on_inner]).min() > 0.9


def test_no_edges_to_pair_no_guide_and_the_same_pixels_as_without():
    yy, xx = np.mgrid[:96, :96]
    img = np.dstack([0.3 + 0.004 * yy, 0.5 + 0.002 * xx, 0.4 + 0 * xx]).astype(np.float32)  # smooth ramps
    img += np.random.default_rng(1).normal(0, 0.01, img.shape).astype(np.float32)
    hole = np.zeros((96, 96), bool)
    hole[30:60, 35:65] = True
    assert structure_guide(img, hole) == (None, 0)
    a, fa = fill_image(img, hole, params=FillParams(structure="yes"), rng=2)
    b, fb = fill_image(img, hole, params=FillParams(engine="patchmatch", structure="no"), rng=2)
    assert np.array_equal(a, b)
    assert fa["edges_continued"] == 0 and fa["engine"] == "patchmatch" and "edges_continued" not in fb


def test_a_structure_fill_keeps_the_circles_edge_known_pixels_and_its_seed():
    img, region = _picture()
    hole = _hole_on(80, 225, 16)
    out, figures = fill_image(img, hole, params=FillParams(structure="yes"), rng=1)
    assert figures["edges_continued"] == 1 and figures["engine"] == "patchmatch"
    red = out[..., 1] < 0.35  # the disc's pixels (green 0.12; the ground's 0.65)
    wrong = (red != (region > 0)) & hole
    assert wrong.sum() <= 0.03 * hole.sum()
    keep = ~hole & ~band_region(hole, 2)
    assert np.array_equal(out[keep], img[keep])
    again, _ = fill_image(img, hole, params=FillParams(structure="yes"), rng=1)
    other, _ = fill_image(img, hole, params=FillParams(structure="yes"), rng=2)
    assert np.array_equal(out, again) and not np.array_equal(out, other)


def _red(rgb):
    """The saucer's saturated red (HSV), bool (H, W)."""
    a8 = np.clip(np.rint(np.asarray(rgb, np.float32) * 255), 0, 255).astype(np.uint8)
    hsv = cv2.cvtColor(a8, cv2.COLOR_RGB2HSV).astype(int)
    return ((hsv[..., 0] <= 8) | (hsv[..., 0] >= 172)) & (hsv[..., 1] > 150) & (hsv[..., 2] > 90)


@pytest.mark.parametrize("seed", [2, 4])
def test_on_the_benchmark_photo_the_edge_guide_does_not_drip_the_saucer_rim(seed):
    """The benchmark's object case: patchmatch without the guide (``structure="no"``) drips the rim's
    red into the shadow at these seeds; with it (``structure="yes"``) only single pixels along the
    shadow's edge are left."""
    from benchmarks.fill import by_name

    case = by_name()["fill-object"].build()
    truth = case.truth.astype(np.float32) / 255
    near_red = cv2.dilate(_red(truth).astype(np.uint8), np.ones((9, 9), np.uint8)) > 0

    def stray_red(out):
        return int((_red(out) & case.hole & ~near_red).sum())

    assert stray_red(fill(case.known_part, case.hole, seed=seed, structure="yes")) <= 150
    assert stray_red(fill(case.known_part, case.hole, seed=seed, engine="patchmatch", structure="no")) > 300


def test_the_guide_is_checked_by_the_engine():
    img, _ = _picture()
    hole = _hole_on(80, 225, 16)
    with pytest.raises(ImageError, match=r"the guide has shape \(64, 64\); it must be \(H, W\) or \(H, W, 1..8\)"):
        fill_patchmatch(img, hole, guide=np.zeros((64, 64), np.float32))
    bad = np.zeros((SIZE, SIZE), np.float32)
    bad[3, 4] = np.nan
    with pytest.raises(ImageError, match="the guide holds NaN or infinite values"):
        fill_patchmatch(img, hole, guide=bad)


def test_structure_yes_with_another_engine_or_a_texture_is_refused():
    with pytest.raises(
        InvalidParameter, match="parameter 'structure' = yes needs the patchmatch engine .or auto., not 'quilt'"
    ):
        FillParams(engine="quilt", structure="yes")
    with pytest.raises(InvalidParameter, match=r"parameter 'patch' = 64 is outside 3..63 with 'structure'"):
        FillParams(structure="yes", patch=64)
    with pytest.raises(InvalidParameter, match=r"parameter 'structure' = 'on' is not one of auto, yes, no"):
        FillParams(structure="on")
    img, _ = _picture()
    with pytest.raises(InvalidParameter, match="cannot copy from a second texture"):
        fill(img, _hole_on(80, 225, 16), structure=True, texture=img)


def test_auto_continues_the_edges_whenever_patchmatch_runs_on_the_picture_itself():
    """``structure`` auto: the patchmatch engine runs the guide (the same pixels as ``yes``); with
    ``no`` the edge is not continued; the default engine (hybrid), the quilt and a fill from a second
    texture run without it, and say nothing of edges."""
    img, region = _picture()
    hole = _hole_on(80, 225, 16)
    auto, fa = fill_image(img, hole, params=FillParams(engine="patchmatch"), rng=1)
    yes, _ = fill_image(img, hole, params=FillParams(structure="yes"), rng=1)
    no, fn = fill_image(img, hole, params=FillParams(engine="patchmatch", structure="no"), rng=1)
    assert fa["engine"] == "patchmatch" and fa["edges_continued"] == 1 and np.array_equal(auto, yes)
    assert fn["engine"] == "patchmatch" and "edges_continued" not in fn and not np.array_equal(auto, no)
    # fill(..., structure=True / False) reads as yes / no
    assert np.array_equal(fill(img, hole, seed=1, engine="patchmatch", structure=False), no)
    _, fq = fill_image(img, hole, params=FillParams(engine="quilt"), rng=1)
    _, fg = fill_image(img[..., 0], hole, params=FillParams(), rng=1)
    _, ft = fill_image(img, hole, params=FillParams(engine="patchmatch"), texture=img, rng=1)
    assert fq["engine"] == "quilt" and fg["engine"] == "hybrid" and ft["engine"] == "patchmatch"
    assert all("edges_continued" not in f for f in (fq, fg, ft))


def test_recipes_of_the_on_off_switch_read_as_yes_and_no():
    """``structure`` was an on/off switch (off by default) for one round: its recipes and sessions
    wrote true / false, and reproduce their pixels as yes / no."""
    assert FillParams.from_dict({"structure": True}).structure == "yes"
    assert FillParams.from_dict({"structure": False, "engine": "quilt"}).structure == "no"
    assert FillParams.from_dict({}).structure == "auto"


def test_the_command_line_option(tmp_path, capsys):
    img, _ = _picture()
    hole = _hole_on(80, 225, 16)
    save_image(tmp_path / "disc.png", img)
    save_image(tmp_path / "mask.png", hole.astype(np.float32))
    out = tmp_path / "out.png"
    code = main(
        [
            "fill",
            str(tmp_path / "disc.png"),
            "--mask",
            str(tmp_path / "mask.png"),
            "--structure",
            "yes",
            "-o",
            str(out),
            "--seed",
            "1",
            "--report",
            "-q",
        ]
    )
    captured = capsys.readouterr()
    assert code == 0, captured.err
    report = json.loads(captured.out)
    assert report["edges_continued"] == 1 and report["engine"] == "patchmatch"
    expected = fill(load_image(tmp_path / "disc.png").image, hole, structure=True, seed=1)
    as8 = lambda a: np.clip(np.rint(a * 255), 0, 255).astype(np.uint8)  # noqa: E731
    assert np.array_equal(as8(load_image(out).image), as8(expected))
    # the recipe beside the output records the option: weft run reproduces the pixels
    again = tmp_path / "again.png"
    assert main(["run", str(out), "-o", str(again), "-q"]) == 0, capsys.readouterr().err
    assert np.array_equal(load_image(again).image, load_image(out).image)
    # with the quilt engine: one line naming the parameter, exit 2, nothing written
    out2 = tmp_path / "out2.png"
    code = main(
        [
            "fill",
            str(tmp_path / "disc.png"),
            "--mask",
            str(tmp_path / "mask.png"),
            "--structure",
            "yes",
            "--engine",
            "quilt",
            "-o",
            str(out2),
            "-q",
        ]
    )
    err = capsys.readouterr().err
    assert code == 2 and not out2.exists()
    assert err.strip().count("\n") == 0 and "parameter 'structure' = yes needs the patchmatch engine" in err


def test_the_studio_shows_the_patch_the_structure_run_takes():
    """With ``structure`` = yes, ``auto`` runs patchmatch whatever the picture: its 7 px patch, not the
    hybrid's block (64, at most a third of a small canvas)."""
    from weft.core.fill.method import STUDIO

    assert STUDIO.auto(FillParams(), {"image": (96, 96)}) == {"patch": 32}
    assert STUDIO.auto(FillParams(structure="yes"), {"image": (96, 96)}) == {"patch": 7}


def test_auto_runs_patchmatch_with_the_guide_where_it_finds_edges_to_continue():
    """``auto`` (the default engine): a colour picture's hole that cuts an edge (the disc's rim) is
    filled by patchmatch with the edge guide (the same pixels as asking for them); a hole inside the
    plain disc, the grey picture's rim, a hole on the border and ``structure`` = no get hybrid."""
    img, _ = _picture()
    rim = _hole_on(80, 225, 16)
    out, f = fill_image(img, rim, params=FillParams(), rng=1)
    asked, _ = fill_image(img, rim, params=FillParams(engine="patchmatch", structure="yes"), rng=1)
    assert f["engine"] == "patchmatch" and f["edges_continued"] == 1 and np.array_equal(out, asked)
    ground = _hole_on(40, 225, 12)
    border = np.zeros(rim.shape, bool)
    border[:, :14] = True
    for image, hole, kw in (
        (img, ground, {}),
        (img[..., 0], rim, {}),
        (img, border, {}),
        (img, rim, {"structure": "no"}),
    ):
        _, f = fill_image(image, hole, params=FillParams(**kw), rng=1)
        assert f["engine"] == "hybrid" and "edges_continued" not in f, kw
