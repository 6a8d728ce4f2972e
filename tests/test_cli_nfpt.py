"""`weft rectify` and `weft nfpt` as a user runs them: outputs, reports, recipes, bad input."""

import json
from pathlib import Path

import numpy as np
import pytest
from weft.app.cli import main
from weft.core.examples import example
from weft.core.image import load_image, read_recipe

PHOTO = example("perspective")
LINES = PHOTO.parent / "perspective-lines.json"


def run(argv, capsys):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_rectify_writes_the_frontal_image_and_reports_the_homography(tmp_path, capsys):
    out = tmp_path / "frontal.png"
    code, stdout, err = run(["rectify", PHOTO, "--lines", LINES, "-o", out, "--report"], capsys)
    assert code == 0, err
    report = json.loads(stdout)
    assert report["method"] == "rectify" and report["size"] == [512, 384] and report["points"] == 8
    truth = np.array(json.loads(LINES.read_text())["homography"])
    assert np.allclose(np.array(report["homography"]), truth, rtol=1e-3, atol=1e-3)
    frontal = load_image(example("perspective-frontal")).image
    assert np.corrcoef(frontal.ravel(), load_image(out).image.ravel())[0, 1] > 0.99
    half = tmp_path / "half.png"
    assert run(["rectify", PHOTO, "--lines", LINES, "--size", "256x192", "--warp", "lines", "-o", half], capsys)[0] == 0
    assert load_image(half).image.shape == (192, 256, 3)


def test_nfpt_synthesizes_reprojects_and_reproduces_its_recipe(tmp_path, capsys):
    out = tmp_path / "wall.png"
    code, stdout, err = run(
        [
            "nfpt",
            PHOTO,
            "--lines",
            LINES,
            "--size",
            "160x128",
            "--block",
            "32",
            "--overlap",
            "8",
            "-o",
            out,
            "--seed",
            "3",
            "--report",
        ],
        capsys,
    )
    assert code == 0, err
    report = json.loads(stdout)
    assert report["size"] == [160, 128] and report["patches"] == 35 and report["repaired_pixels"] >= 0
    recipe = json.loads(read_recipe(out))
    # the lines are read once, at the edge, and the recipe holds them (their JSON object): no other file
    assert recipe["params"]["lines"]["frontal_size"] == json.loads(Path(LINES).read_text())["frontal_size"]
    assert recipe["seed"] == 3
    again = tmp_path / "again.png"
    assert run(["run", out, "-o", again], capsys)[0] == 0
    assert np.array_equal(load_image(out).image, load_image(again).image)

    into = tmp_path / "into.png"
    code, stdout, err = run(
        [
            "nfpt",
            PHOTO,
            "--lines",
            LINES,
            "--size",
            "640x480",
            "--block",
            "32",
            "--overlap",
            "8",
            "--into-photo",
            "true",
            "-o",
            into,
            "--seed",
            "3",
            "--report",
        ],
        capsys,
    )
    assert code == 0, err
    assert load_image(into).image.shape == (360, 480, 3) and json.loads(stdout)["photo_replaced_fraction"] > 0.5

    view = tmp_path / "view.json"
    view.write_text(json.dumps({"quad": [[10, 20], [200, 5], [210, 150], [5, 140]], "size": [220, 160]}))
    viewed = tmp_path / "viewed.png"
    code, _, err = run(
        [
            "nfpt",
            PHOTO,
            "--lines",
            LINES,
            "--size",
            "160x128",
            "--block",
            "32",
            "--overlap",
            "8",
            "--view",
            view,
            "-o",
            viewed,
            "--seed",
            "3",
        ],
        capsys,
    )
    assert code == 0, err
    assert load_image(viewed).image.shape == (160, 220, 3)


def test_nfpt_without_lines_synthesizes_the_photo_as_it_is(tmp_path, capsys):
    out = tmp_path / "gravel.png"
    code, _, err = run(
        [
            "nfpt",
            example("gravel"),
            "--size",
            "96x64",
            "--block",
            "24",
            "--overlap",
            "6",
            "--smooth",
            "true",
            "-o",
            out,
            "--seed",
            "1",
        ],
        capsys,
    )
    assert code == 0, err
    assert load_image(out).image.shape == (64, 96)


@pytest.mark.parametrize(
    "argv, fragment",
    [
        (["rectify", PHOTO, "-o", "{out}"], "needs --lines L.json"),
        (
            ["rectify", PHOTO, "--lines", "{tmp}/nowhere.json", "-o", "{out}"],
            "nowhere.json: no such feature-lines file",
        ),
        (["rectify", PHOTO, "--lines", LINES, "--warp", "morph", "-o", "{out}"], "lie on one plane"),
        (["rectify", PHOTO, "--lines", LINES, "--warp", "affine", "-o", "{out}"], "parameter 'warp' = 'affine'"),
        (
            [
                "rectify",
                PHOTO,
                "--lines",
                '{"image_lines": [[1, 1, 1, 1]], "frontal_lines": [[0, 0, 9, 9]], "frontal_size": [10, 10]}',
                "-o",
                "{out}",
            ],
            "image line 0 has zero length",
        ),
        (
            [
                "rectify",
                PHOTO,
                "--lines",
                '{"image_lines": [[1, 1, 90, 1], [1, 5, 90, 5], [1, 9, 90, 9], [1, 13, 90, 13]], '
                '"frontal_lines": [[0, 0, 9, 0], [0, 3, 9, 3], [0, 6, 9, 6], [0, 9, 9, 9]], '
                '"frontal_size": [10, 10]}',
                "-o",
                "{out}",
            ],
            "feature lines are parallel",
        ),
        (["rectify", PHOTO, "--lines", "{tmp}/bad.json", "-o", "{out}"], "bad.json: not valid JSON"),
        (
            ["nfpt", PHOTO, "--lines", LINES, "--view", "{tmp}/v.json", "--into-photo", "true", "-o", "{out}"],
            "exclude each other",
        ),
        (["nfpt", PHOTO, "--lines", LINES, "--view", "{tmp}/nowhere.json", "-o", "{out}"], "no such view file"),
        (["nfpt", PHOTO, "--into-photo", "true", "-o", "{out}"], "--into-photo needs the feature lines"),
        (
            ["nfpt", PHOTO, "--block", "32", "--overlap", "20", "-o", "{out}"],
            "parameter 'overlap' = 20 is outside 2..16",
        ),
    ],
)
def test_bad_input_exits_2_with_one_line(tmp_path, capsys, argv, fragment):
    (tmp_path / "bad.json").write_text("{nope")
    (tmp_path / "v.json").write_text('{"quad": [[0, 0], [99, 0], [99, 79], [0, 79]]}')  # a good view
    out = tmp_path / "out.png"
    argv = [str(a).replace("{tmp}", str(tmp_path)).replace("{out}", str(out)) for a in argv]
    code, _, err = run(argv, capsys)
    assert code == 2 and err.count("\n") == 1 and fragment in err, err
    assert not out.exists()


def test_recipe_finds_the_lines_file_from_any_folder(tmp_path, monkeypatch):
    """A recipe stores --lines relative to itself, so `weft run` works from another folder."""
    import json
    import shutil

    import numpy as np
    from weft.app.cli import main
    from weft.core.examples import RESOURCES
    from weft.core.image import load_image, read_recipe

    for name in ("perspective.png", "perspective-lines.json"):
        shutil.copy(RESOURCES / name, tmp_path / name)
    monkeypatch.chdir(tmp_path)
    assert (
        main(
            [
                "nfpt",
                "perspective.png",
                "--lines",
                "perspective-lines.json",
                "--size",
                "96x96",
                "-o",
                "out.png",
                "--seed",
                "2",
            ]
        )
        == 0
    )
    lines = json.loads((tmp_path / "perspective-lines.json").read_text())
    assert json.loads(read_recipe(tmp_path / "out.png"))["params"]["lines"]["image_lines"] == lines["image_lines"]
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    assert main(["run", str(tmp_path / "out.png"), "-o", "again.png"]) == 0
    assert np.array_equal(load_image(tmp_path / "out.png").image, load_image(elsewhere / "again.png").image)


def test_lines_given_as_json_text_on_the_command_line(tmp_path):
    """--lines also takes the JSON itself; the recipe keeps it as text (no file to find later)."""
    import json

    from weft.app.cli import main
    from weft.core.examples import RESOURCES
    from weft.core.image import read_recipe

    text = (RESOURCES / "perspective-lines.json").read_text()
    out = tmp_path / "r.png"
    assert main(["rectify", str(RESOURCES / "perspective.png"), "--lines", text, "-o", str(out)]) == 0
    assert json.loads(read_recipe(out))["params"]["lines"]["frontal_size"] == [512, 384]
