"""``weft rectify|nfpt PHOTO --auto``: suggested lines, --save-lines, --report, and `weft run`."""

import json

import numpy as np
from weft.app.cli import main
from weft.core.examples import RESOURCES
from weft.core.image import load_image, read_recipe

PHOTO = str(RESOURCES / "perspective.png")


def test_rectify_auto_saves_lines_reports_and_reproduces_with_run(tmp_path, capsys):
    out, lines = tmp_path / "frontal.png", tmp_path / "lines.json"
    assert main(["rectify", PHOTO, "--auto", "-o", str(out), "--save-lines", str(lines), "--report"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert 0.5 < report["suggest_confidence"] <= 1 and 60 < report["suggest_angle_deg"] < 90
    saved = json.loads(lines.read_text())
    assert len(saved["image_lines"]) >= 4 and saved["frontal_size"] == report["size"]
    # the recipe records the suggested lines themselves, not "auto"
    recipe = json.loads(read_recipe(out))
    assert recipe["params"]["lines"]["image_lines"] == saved["image_lines"]
    again = tmp_path / "again.png"
    assert main(["run", str(out), "-o", str(again)]) == 0
    assert np.array_equal(load_image(out).image, load_image(again).image)
    # the saved lines, passed back with --lines, give the same pixels
    edited = tmp_path / "edited.png"
    assert main(["rectify", PHOTO, "--lines", str(lines), "-o", str(edited)]) == 0
    assert np.array_equal(load_image(out).image, load_image(edited).image)


def test_nfpt_auto_runs_and_its_recipe_reproduces(tmp_path):
    out = tmp_path / "n.png"
    assert main(["nfpt", PHOTO, "--auto", "-o", str(out), "--seed", "3", "--size", "160x120"]) == 0
    again = tmp_path / "n2.png"
    assert main(["run", str(out), "-o", str(again)]) == 0
    assert np.array_equal(load_image(out).image, load_image(again).image)


def test_auto_refuses_in_one_line_and_writes_nothing(tmp_path, capsys):
    out, lines = tmp_path / "x.png", tmp_path / "x.json"
    code = main(["rectify", str(RESOURCES / "gravel.png"), "--auto", "-o", str(out), "--save-lines", str(lines)])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1
    assert err.strip().endswith("no two families of straight lines found: draw feature lines")
    assert not out.exists() and not lines.exists()


def test_auto_with_lines_or_save_lines_without_lines_are_usage_errors(tmp_path, capsys):
    lines = RESOURCES / "perspective-lines.json"
    assert main(["rectify", PHOTO, "--auto", "--lines", str(lines), "-o", str(tmp_path / "a.png")]) == 2
    assert "give --lines or --auto, not both" in capsys.readouterr().err
    assert main(["rectify", PHOTO, "--save-lines", str(tmp_path / "l.json"), "-o", str(tmp_path / "b.png")]) == 2
    assert "--save-lines needs --lines or --auto" in capsys.readouterr().err
    assert not any(tmp_path.iterdir())
