"""`weft fast` as a user runs it: transfer, synthesis, super-resolution, novel styles, bad input."""

import json

import numpy as np
import pytest
from weft.app.cli import main
from weft.core.examples import example
from weft.core.image import load_image, read_recipe


def run(argv, capsys):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_transfer_with_report_and_recipe(tmp_path, capsys):
    out = tmp_path / "out.png"
    code, stdout, err = run(
        [
            "fast",
            example("gravel"),
            "--target",
            example("camera"),
            "-o",
            out,
            "--metric",
            "target",
            "--p",
            "0.1",
            "--seed",
            "4",
            "--report",
        ],
        capsys,
    )
    assert code == 0, err
    report = json.loads(stdout)
    assert report["method"] == "fast" and report["size"] == [256, 256]
    assert report["mode"] == "transfer" and report["metric"] == "target" and report["p"] == 0.1
    assert 0 < report["coherent_fraction"] < 1
    recipe = json.loads(read_recipe(out))
    assert set(recipe["inputs"]) == {"texture", "target"} and recipe["params"]["p"] == 0.1
    again = tmp_path / "again.png"
    assert run(["run", out, "-o", again], capsys)[0] == 0
    assert np.array_equal(load_image(out).image, load_image(again).image)


def test_super_resolution_and_novel_style(tmp_path, capsys):
    sr = tmp_path / "sr.png"
    code, stdout, err = run(["fast", example("clouds"), "--magnify", "2", "-o", sr, "--seed", "1", "--report"], capsys)
    assert code == 0, err
    report = json.loads(stdout)
    assert report["mode"] == "superres" and report["p"] == 0.0 and report["p_l"] == 0.03
    assert load_image(sr).image.shape == (512, 512)
    nv = tmp_path / "novel.png"
    code, stdout, err = run(
        [
            "fast",
            example("chelsea"),
            "--mode",
            "novel",
            "--magnify",
            "2",
            "--p",
            "0.2",
            "-o",
            nv,
            "--seed",
            "1",
            "--report",
        ],
        capsys,
    )
    assert code == 0, err
    assert load_image(nv).image.shape == (400, 600, 3)


def test_synthesis_with_size_and_mask(tmp_path, capsys):
    from weft.core.image import save_image

    mask = np.zeros((104, 104), np.float32)
    mask[:, 52:] = 1
    mpath = tmp_path / "mask.png"
    save_image(mpath, mask)
    out = tmp_path / "syn.png"
    code, _, err = run(
        ["fast", example("cat-fur"), "--mask", mpath, "--size", "96x64", "-o", out, "--seed", "2"], capsys
    )
    assert code == 0, err
    assert load_image(out).image.shape == (64, 96, 3)


@pytest.mark.parametrize(
    "extra, fragment",
    [
        (["--n", "6"], "parameter 'n' = 6 must be odd"),
        (["--p", "2"], "parameter 'p' = 2 is outside 0..1"),
        (["--p-l", "x"], "parameter 'p_l' = 'x' must be a number"),
        (["--metric", "target"], "metric 'target' needs a target"),
        (["--mode", "transfer"], "mode 'transfer' needs a target image"),
        (["--target", "nowhere.png"], "nowhere.png: no such file"),
    ],
)
def test_bad_input_exits_2_with_one_line(tmp_path, capsys, extra, fragment):
    out = tmp_path / "out.png"
    code, stdout, err = run(["fast", example("gravel"), "-o", out] + extra, capsys)
    assert code == 2 and err.count("\n") == 1 and fragment in err
    assert not out.exists()
