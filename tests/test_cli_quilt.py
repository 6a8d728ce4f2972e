"""`weft quilt` (synthesis modes, transfer) and `weft blend` as a user runs them."""

import json

import numpy as np
import pytest
from weft.app.cli import main
from weft.core.examples import example
from weft.core.image import load_image, read_recipe, save_image


@pytest.fixture
def files(tmp_path):
    brick = load_image(example("brick")).image[:64, :64]
    gravel = load_image(example("gravel")).image[:64, :64]
    camera = load_image(example("camera")).image[::4, ::4]  # 64x64
    paths = {}
    for name, img in (("brick", brick), ("gravel", gravel), ("camera", camera)):
        paths[name] = tmp_path / f"{name}.png"
        save_image(paths[name], img)
    mask = np.zeros((64, 64), dtype=np.float32)
    mask[16:48, 20:44] = 1
    paths["mask"] = tmp_path / "mask.png"
    save_image(paths["mask"], mask)
    paths["white"] = tmp_path / "white.png"
    save_image(paths["white"], np.ones((64, 64), dtype=np.float32))
    paths["small"] = tmp_path / "small.png"
    save_image(paths["small"], mask[:32, :32])
    return paths


def run(argv, capsys):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_mincut_synthesis_tileable_poisson(files, tmp_path, capsys):
    out_path = tmp_path / "out.png"
    code, out, err = run(
        [
            "quilt",
            files["brick"],
            "-o",
            out_path,
            "--mode",
            "mincut",
            "--size",
            "100x90",
            "--block",
            "20",
            "--overlap",
            "5",
            "--tol",
            "3",
            "--tile",
            "true",
            "--poisson",
            "true",
            "--seed",
            "2",
            "--report",
        ],
        capsys,
    )
    assert code == 0, err
    report = json.loads(out)
    assert report["size"] == [100, 90] and report["blocks"] == 7 * 6
    assert 0 < report["verbatim_fraction"] < 1
    assert load_image(out_path).image.shape == (90, 100)
    recipe = json.loads(read_recipe(out_path))
    assert recipe["params"]["tile"] is True and recipe["params"]["mode"] == "mincut"


def test_transfer_with_iterations_and_recipe_reproduces(files, tmp_path, capsys):
    a, b = tmp_path / "a.png", tmp_path / "b.png"
    code, out, err = run(
        [
            "quilt",
            files["gravel"],
            "--target",
            files["camera"],
            "-o",
            a,
            "--block",
            "12",
            "--iterations",
            "2",
            "--seed",
            "5",
            "--report",
        ],
        capsys,
    )
    assert code == 0, err
    assert json.loads(out)["iterations"] == 2 and json.loads(out)["size"] == [64, 64]
    recipe = json.loads(read_recipe(a))
    assert recipe["inputs"] == {"texture": "gravel.png", "target": "camera.png"}
    assert run(["run", a, "-o", b], capsys)[0] == 0
    assert np.array_equal(load_image(a).image, load_image(b).image)


def test_transfer_with_maps(files, tmp_path, capsys):
    out_path = tmp_path / "maps.png"
    code, _, err = run(
        [
            "quilt",
            files["gravel"],
            "--target",
            files["camera"],
            "--source-map",
            files["gravel"],
            "--target-map",
            files["camera"],
            "-o",
            out_path,
            "--seed",
            "1",
        ],
        capsys,
    )
    assert code == 0, err
    assert load_image(out_path).image.shape == (64, 64)


def test_blend_pyramid_and_poisson(files, tmp_path, capsys):
    out_path = tmp_path / "blend.png"
    code, out, err = run(
        [
            "blend",
            files["camera"],
            files["gravel"],
            "--mask",
            files["mask"],
            "-o",
            out_path,
            "--levels",
            "4",
            "--report",
        ],
        capsys,
    )
    assert code == 0, err
    assert json.loads(out)["levels"] == 4
    blended = load_image(out_path).image
    camera, gravel = load_image(files["camera"]).image, load_image(files["gravel"]).image
    assert np.abs(blended[30, 30] - camera[30, 30]) < 0.02 and np.abs(blended[2, 2] - gravel[2, 2]) < 0.02
    # an all-white mask gives the foreground
    code, _, err = run(["blend", files["camera"], files["gravel"], "--mask", files["white"], "-o", out_path], capsys)
    assert code == 0, err
    assert np.abs(load_image(out_path).image - camera).max() <= 1 / 255 + 1e-6
    code, _, err = run(
        ["blend", files["camera"], files["gravel"], "--mask", files["mask"], "-o", out_path, "--mode", "poisson"],
        capsys,
    )
    assert code == 0, err


@pytest.mark.parametrize(
    "argv, fragment",
    [
        (
            ["quilt", "{brick}", "--block", "32", "--overlap", "40"],
            "parameter 'overlap' = 40 is outside 1..31 (must be smaller than block = 32)",
        ),
        (
            ["quilt", "{brick}", "--block", "65", "--mode", "mincut"],
            "'block' = 65 is outside 2..64 (must fit in the texture, 64x64)",
        ),
        (
            ["quilt", "{brick}", "--mode", "random", "--poisson", "true"],
            "'poisson' = true needs mode overlap or mincut",
        ),
        (["quilt", "{brick}", "--iterations", "3"], "more passes need a target"),
        (["quilt", "{brick}", "--source-map", "{gravel}"], "input 'source-map' needs a target"),
        (["quilt", "{gravel}", "--target", "{camera}", "--source-map", "{gravel}"], "'target_map' is required"),
        (["quilt", "{gravel}", "--target", "{camera}", "--size", "10x10"], "'size' cannot be given with a target"),
        (
            ["quilt", "{gravel}", "--target", "{camera}", "--mode", "random"],
            "'mode' = 'random' is not one of overlap, mincut",
        ),
        (
            ["quilt", "{brick}", "--mode", "mincut", "--tile", "true", "--size", "20x20"],
            "too small for a tileable output",
        ),
        (["quilt", "{brick}", "--alpha", "1.5"], "'alpha' = 1.5 is outside 0..1"),
        (["quilt", "{brick}", "--rule", "best"], "'rule' = 'best' is not one of tol, epsilon, sampled"),
        (["blend", "{camera}", "{gravel}", "--mask", "{small}"], "mask is 32x32 but the images are 64x64"),
        (["blend", "{camera}", "{gravel}", "--mask", "{mask}", "--levels", "8"], "'levels' = 8 is outside 1..7"),
        (["blend", "{camera}", "{gravel}"], "the following arguments are required: --mask"),
    ],
)
def test_bad_input_exits_2_with_one_line(files, tmp_path, capsys, argv, fragment):
    out_path = tmp_path / "out.png"
    argv = [a.format(**{k: str(v) for k, v in files.items()}) for a in argv] + ["-o", str(out_path)]
    code, out, err = run(argv, capsys)
    assert code == 2, err
    assert err.count("\n") == 1 and err.startswith("weft") and fragment in err
    assert out == "" and not out_path.exists()
