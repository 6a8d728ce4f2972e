"""`weft fill` as a user runs it: grey, colour, 16-bit, RGBA, --extend, --size/--anchor, --source-mask,
--texture; `weft run` on the output's recipe reproduces it; every bad input is one
line naming the file or parameter, exit 2, nothing written."""

import json

import numpy as np
import pytest
from weft.app.cli import main
from weft.core.examples import example
from weft.core.fill.band import band_region
from weft.core.image import load_image, read_recipe, save_image


@pytest.fixture
def files(tmp_path):
    gravel = load_image(example("gravel")).image[:72, :72]
    chelsea = load_image(example("chelsea")).image[:72, :72]
    paths = {}
    for name, img in (("grey", gravel), ("colour", chelsea)):
        paths[name] = tmp_path / f"{name}.png"
        save_image(paths[name], img)
    paths["grey16"] = tmp_path / "grey16.png"
    save_image(paths["grey16"], gravel, bit_depth=16)
    hole = np.zeros((72, 72), dtype=np.float32)
    hole[24:44, 20:48] = 1
    paths["mask"] = tmp_path / "mask.png"
    save_image(paths["mask"], hole)
    rgba = np.dstack([chelsea, np.where(hole > 0, 0.0, 1.0).astype(np.float32)])
    paths["rgba"] = tmp_path / "rgba.png"
    save_image(paths["rgba"], rgba)
    paths["black"] = tmp_path / "black.png"
    save_image(paths["black"], np.zeros((72, 72), np.float32))
    paths["white"] = tmp_path / "white.png"
    save_image(paths["white"], np.ones((72, 72), np.float32))
    paths["small"] = tmp_path / "small.png"
    save_image(paths["small"], hole[:40, :50])
    paths["texture"] = tmp_path / "texture.png"
    save_image(paths["texture"], load_image(example("brick")).image[:60, :60])
    src = np.zeros((72, 72), np.float32)
    src[50:, :] = 1
    paths["source"] = tmp_path / "source.png"
    save_image(paths["source"], src)
    return paths, hole > 0


def run(argv, capsys):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def _untouched(out, image, hole, band=2):
    keep = ~hole & ~band_region(hole, band)
    return np.array_equal(out[keep], image[keep])


@pytest.mark.parametrize("which", ["grey", "colour", "grey16"])
def test_fill_a_mask(files, tmp_path, capsys, which):
    paths, hole = files
    out_path = tmp_path / "out.png"
    code, out, err = run(
        ["fill", paths[which], "--mask", paths["mask"], "-o", out_path, "--seed", "3", "--report", "-q"], capsys
    )
    assert code == 0, err
    line = json.loads(out)
    assert line["hole_pixels"] == int(hole.sum()) and line["size"] == [72, 72]
    assert line["engine"] == "hybrid"  # auto
    image, result = load_image(paths[which]), load_image(out_path)
    assert result.info.bit_depth == (16 if which == "grey16" else 8)  # the output keeps the image's depth
    assert result.image.shape == image.image.shape
    assert _untouched(result.image, image.image, hole)
    assert json.loads(read_recipe(out_path))["inputs"]["mask"] == "mask.png"
    # weft run on the output reproduces its pixels
    again = tmp_path / "again.png"
    code, _, err = run(["run", out_path, "-o", again, "-q"], capsys)
    assert code == 0, err
    assert np.array_equal(load_image(again).image, result.image)


def test_rgba_transparent_region_is_the_hole(files, tmp_path, capsys):
    paths, hole = files
    out_path = tmp_path / "out.png"
    code, out, err = run(["fill", paths["rgba"], "-o", out_path, "--seed", "1", "--report", "-q"], capsys)
    assert code == 0, err
    assert json.loads(out)["hole_pixels"] == int(hole.sum())
    result = load_image(out_path, alpha=True).image
    source = load_image(paths["rgba"], alpha=True).image
    assert result.shape == (72, 72, 4) and np.all(result[..., 3] == 1.0)  # filled pixels are opaque
    assert _untouched(result, source, hole)


@pytest.mark.parametrize("engine", ["quilt", "hybrid"])
def test_extend_uncrops(files, tmp_path, capsys, engine):
    paths, _ = files
    out_path = tmp_path / "out.png"
    code, out, err = run(
        [
            "fill",
            paths["colour"],
            "--extend",
            "8,0,24,4",
            "--engine",
            engine,
            "--patch",
            "9",
            "-o",
            out_path,
            "--seed",
            "2",
            "--report",
            "-q",
        ],
        capsys,
    )
    assert code == 0, err
    line = json.loads(out)
    assert line["size"] == [104, 76] and line["hole_pixels"] == 104 * 76 - 72 * 72 and line["extend"] == [8, 0, 24, 4]
    result, image = load_image(out_path).image, load_image(paths["colour"]).image
    assert np.array_equal(result[:70, 10:78], image[:70, 2:70])
    assert json.loads(read_recipe(out_path))["params"]["extend"] == [8, 0, 24, 4]


def test_size_and_anchor(files, tmp_path, capsys):
    paths, _ = files
    out_path = tmp_path / "out.png"
    code, _, err = run(
        [
            "fill",
            paths["grey"],
            "--size",
            "100x80",
            "--anchor",
            "top-left",
            "--band",
            "0",
            "-o",
            out_path,
            "--seed",
            "2",
            "-q",
        ],
        capsys,
    )
    assert code == 0, err
    result, image = load_image(out_path).image, load_image(paths["grey"]).image
    assert result.shape == (80, 100) and np.array_equal(result[:72, :72], image)


def test_source_mask_and_texture(files, tmp_path, capsys):
    paths, hole = files
    out_path = tmp_path / "out.png"
    code, _, err = run(
        [
            "fill",
            paths["grey"],
            "--mask",
            paths["mask"],
            "--source-mask",
            paths["source"],
            "-o",
            out_path,
            "--seed",
            "2",
            "-q",
            "--patch",
            "12",
        ],
        capsys,
    )
    assert code == 0, err
    assert _untouched(load_image(out_path).image, load_image(paths["grey"]).image, hole)
    out2 = tmp_path / "out2.png"
    code, _, err = run(
        [
            "fill",
            paths["grey"],
            "--mask",
            paths["mask"],
            "--texture",
            paths["texture"],
            "-o",
            out2,
            "--seed",
            "2",
            "-q",
            "--band",
            "0",
        ],
        capsys,
    )
    assert code == 0, err
    result = load_image(out2).image
    brick = load_image(paths["texture"]).image
    # the hole now holds brick: its values are the brick's (dark bricks, light mortar), not gravel's
    assert (
        abs(result[hole].mean() - brick.mean())
        < abs(result[hole].mean() - load_image(paths["grey"]).image.mean()) + 0.02
    )
    assert np.array_equal(result[~hole], load_image(paths["grey"]).image[~hole])


def _refused(capsys, argv, out_path, *needles):
    code, out, err = run(argv, capsys)
    lines = err.strip().splitlines()
    assert code == 2, err
    assert len(lines) == 1 and "Traceback" not in err, err
    for needle in needles:
        assert str(needle) in lines[0], lines[0]
    assert not out_path.exists()
    return lines[0]


def test_bad_inputs(files, tmp_path, capsys):
    paths, _ = files
    o = tmp_path / "out.png"
    base = ["-o", o, "-q", "--seed", "1"]
    # mask size differs from the image
    _refused(
        capsys,
        ["fill", paths["grey"], "--mask", paths["small"], *base],
        o,
        "small.png",
        "the mask is 50x40 but the image is 72x72",
    )
    # empty mask: nothing to fill, nothing written, exit 2
    _refused(
        capsys,
        ["fill", paths["grey"], "--mask", paths["black"], *base],
        o,
        "black.png",
        "nothing to fill: the mask has no white pixel",
    )
    # mask covering everything
    _refused(
        capsys,
        ["fill", paths["grey"], "--mask", paths["white"], *base],
        o,
        "white.png",
        "covers the whole image: nothing is left to copy from",
        "whole 24x24 patch",
    )
    # too little to copy from for the patch size given (the hole leaves a 72x8 strip; with no --patch
    # the default block shrinks to the 8x8 the strip holds)
    strip = np.ones((72, 72), np.float32)
    strip[:8] = 0
    save_image(tmp_path / "strip.png", strip)
    _refused(
        capsys,
        ["fill", paths["grey"], "--mask", tmp_path / "strip.png", "--patch", "24", *base],
        o,
        "grey.png",
        "needs at least one whole 24x24 patch of known pixels",
        "largest is 8x8",
    )
    # a patch larger than the image allows
    _refused(
        capsys,
        ["fill", paths["grey"], "--mask", paths["mask"], "--patch", "100", *base],
        o,
        "grey.png",
        "parameter 'patch' = 100 is outside 3..72 (the image is 72x72)",
    )
    # extend negative, malformed or beyond the pixel limit
    _refused(
        capsys,
        ["fill", paths["grey"], "--extend", "0,-4,0,0", *base],
        o,
        "parameter 'extend'",
        "the top margin -4 is outside",
    )
    _refused(capsys, ["fill", paths["grey"], "--extend", "1,2,3", *base], o, "parameter 'extend'", "L,T,R,B")
    _refused(
        capsys,
        ["fill", paths["grey"], "--extend", "0,0,16000,16000", *base],
        o,
        "parameter 'extend'",
        "exceeds the limit of",
        "megapixels",
    )
    # --size smaller than the image
    _refused(
        capsys,
        ["fill", paths["grey"], "--size", "64x64", *base],
        o,
        "parameter 'size' = 64x64 is smaller than the 72x72 image",
    )
    # --texture with a --source-mask of the wrong size (it must be the texture's)
    _refused(
        capsys,
        [
            "fill",
            paths["grey"],
            "--mask",
            paths["mask"],
            "--texture",
            paths["texture"],
            "--source-mask",
            paths["source"],
            *base,
        ],
        o,
        "source.png",
        "the source mask is 72x72 but the texture is 60x60",
    )
    # no mask, no alpha, no extend
    _refused(
        capsys,
        ["fill", paths["grey"], *base],
        o,
        "nothing to fill: give a mask (--mask MASK), margins (--extend L,T,R,B) or a canvas size",
    )


def test_a_mask_painted_on_a_transparent_layer_is_read_with_its_alpha(tmp_path):
    """White strokes on a transparent layer (RGB white everywhere): only the opaque strokes are the
    hole (review: the alpha was dropped and the mask 'covered the whole image')."""
    from PIL import Image

    img = (load_image(example("gravel")).image[:64, :64] * 255).astype(np.uint8)
    Image.fromarray(img).save(tmp_path / "img.png")
    layer = np.zeros((64, 64, 4), np.uint8)
    layer[..., :3] = 255
    layer[20:30, 20:40, 3] = 255
    Image.fromarray(layer, "RGBA").save(tmp_path / "mask.png")
    out = tmp_path / "out.png"
    assert (
        main(["fill", str(tmp_path / "img.png"), "--mask", str(tmp_path / "mask.png"), "--band", "0", "-o", str(out)])
        == 0
    )
    res = np.asarray(Image.open(out))
    keep = np.ones((64, 64), bool)
    keep[20:30, 20:40] = False
    assert np.array_equal(res[keep], img[keep]) and not np.array_equal(res[~keep], img[~keep])


def test_fill_takes_no_region(files, tmp_path, capsys):
    """--region crops a method's source; fill's first input is the image it heals, so fill has no
    --region (it cropped the image, then refused the mask's size or silently filled a crop)."""
    paths, _ = files
    o = tmp_path / "out.png"
    code, _, err = run(["fill", paths["grey"], "--mask", paths["mask"], "--region", "0,0,40", "-o", o], capsys)
    assert code == 2 and "--region" in err and len(err.strip().splitlines()) == 1 and not o.exists()
    from weft.core import registry
    from weft.core.errors import WeftError
    from weft.core.fill import FillParams
    from weft.core.geometry import Square
    from weft.core.request import RenderRequest

    with pytest.raises(WeftError, match="weft fill takes no --region"):
        RenderRequest(
            registry.get("fill"),
            FillParams(),
            {"image": str(paths["grey"]), "mask": str(paths["mask"])},
            1,
            region=Square(0, 0, 40),
        ).run()


def test_a_photo_given_as_the_mask_is_refused(files, tmp_path, capsys):
    """A colour photo passed as --mask (or --source-mask) is one line and exit 2; a painted mask
    with soft (anti-aliased) edges is still a mask."""
    import cv2

    paths, hole = files
    o = tmp_path / "out.png"
    _refused(
        capsys,
        ["fill", paths["colour"], "--mask", paths["colour"], "-o", o, "-q"],
        o,
        "colour.png",
        "the mask is not black and white",
        "% of its pixels are grey or coloured",
    )
    _refused(
        capsys,
        ["fill", paths["colour"], "--mask", paths["mask"], "--source-mask", paths["grey"], "-o", o, "-q"],
        o,
        "grey.png",
        "the source mask is not black and white",
    )
    soft = cv2.GaussianBlur(hole.astype(np.float32), (9, 9), 2.0)
    assert ((soft > 0.1) & (soft < 0.9)).any()
    save_image(tmp_path / "soft.png", soft)
    code, _, err = run(["fill", paths["colour"], "--mask", tmp_path / "soft.png", "-o", o, "-q"], capsys)
    assert code == 0, err
