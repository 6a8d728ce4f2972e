"""`weft affine` as a user runs it: synthesis with figures, shaker box, transfer, fields, bad input."""

import itertools
import json

import numpy as np
import pytest
from weft.app.cli import main
from weft.core.examples import example
from weft.core.image import load_image, read_recipe, save_image

from benchmarks.fixtures.procedural import cells


def run(argv, capsys):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def scales_png(tmp_path_factory):
    path = tmp_path_factory.mktemp("affine") / "scales.png"
    save_image(path, cells(160))
    return path


def test_synthesis_reports_snr_and_reproduces_from_its_recipe(tmp_path, capsys, scales_png):
    out = tmp_path / "out.png"
    code, stdout, err = run(["affine", scales_png, "-o", out, "--seed", "5", "--report"], capsys)
    assert code == 0, err
    report = json.loads(stdout)
    assert report["method"] == "affine" and report["size"] == [160, 160]
    assert report["snr_db"] > 12 and report["snr_lowpass_db"] < 1
    assert report["boundary"] == "none" and report["prototype"] == [48, 48, 64]
    assert "boundary_error" not in report
    recipe = json.loads(read_recipe(out))
    assert recipe["method"] == "affine" and recipe["params"]["block"] == 32
    again = tmp_path / "again.png"
    assert run(["run", out, "-o", again], capsys)[0] == 0
    assert np.array_equal(load_image(out).image, load_image(again).image)


def test_shaker_box_reports_iterations_and_errors(tmp_path, capsys):
    out = tmp_path / "shaker.png"
    code, stdout, err = run(
        ["affine", example("brick"), "-o", out, "--boundary", "shaker", "--block", "16", "--seed", "2", "--report"],
        capsys,
    )
    assert code == 0, err
    report = json.loads(stdout)
    errs = report["boundary_error"]
    assert report["shaker_iterations"] == len(errs) - 1 >= 1
    assert all(b <= a for a, b in itertools.pairwise(errs))
    assert len(stdout) < 2000  # short enough to read


def test_transfer_with_a_prototype_from_another_picture(tmp_path, capsys, scales_png):
    out = tmp_path / "transfer.png"
    code, stdout, err = run(
        [
            "affine",
            example("chelsea"),
            "--prototype-image",
            scales_png,
            "--prototype",
            "20,30,64",
            "--boundary",
            "partial",
            "-o",
            out,
            "--seed",
            "1",
            "--report",
        ],
        capsys,
    )
    assert code == 0, err
    report = json.loads(stdout)
    assert report["prototype"] == [20, 30, 64] and report["boundary"] == "partial"
    assert load_image(out).image.shape == (200, 300, 3)
    # re-render the texture's own transforms with the swapped prototype (absorb: its colour)
    out2 = tmp_path / "swap.png"
    code, stdout, err = run(
        [
            "affine",
            scales_png,
            "--prototype-image",
            example("cat-fur"),
            "--prototype",
            "0,0,64",
            "--reuse-transforms",
            "true",
            "--lowpass",
            "absorb",
            "-o",
            out2,
            "--seed",
            "1",
            "--report",
        ],
        capsys,
    )
    assert code == 0, err
    report = json.loads(stdout)
    assert report["analysis_prototype"] == [48, 48, 64]
    assert load_image(out2).image.shape == (160, 160, 3)


def test_parametric_field(tmp_path, capsys, scales_png):
    out = tmp_path / "field.png"
    code, stdout, err = run(
        ["affine", scales_png, "--field", "swirl", "--size", "96x64", "-o", out, "--seed", "3", "--report"], capsys
    )
    assert code == 0, err
    report = json.loads(stdout)
    assert report["boundary"] == "shaker" and "snr_db" not in report  # another size: nothing to compare
    assert load_image(out).image.shape == (64, 96)


@pytest.mark.parametrize(
    "extra, fragment",
    [
        (["--prototype", "200,10,64"], "parameter 'prototype' = 200,10,64 does not fit"),
        (["--prototype", "0,0,300"], "larger than the texture (256x256)"),
        (["--prototype", "10,10,33"], "the side 33 must be even"),
        (["--prototype", "ten"], "must be X,Y,S"),
        (["--block", "33"], "parameter 'block' = 33 must be even"),
        (["--segments", "5"], "parameter 'segments' = 5 must be even"),
        (["--lowpass", "keep"], "parameter 'lowpass' = 'keep' is not one of add, absorb"),
        (["--boundary", "shake"], "is not one of auto, none, partial, shaker"),
        (["--size", "64x64"], "parameter 'size' only applies with a field"),
        (["--analysis-prototype", "0,0,64"], "only applies with reuse_transforms"),
        (["--field", "swirl", "--reuse-transforms", "true"], "has no meaning with field"),
        (["--prototype-image", "nowhere.png"], "nowhere.png: no such file"),
    ],
)
def test_bad_input_exits_2_with_one_line(tmp_path, capsys, extra, fragment):
    out = tmp_path / "out.png"
    code, stdout, err = run(["affine", example("brick"), "-o", out] + extra, capsys)
    assert code == 2 and err.count("\n") == 1 and fragment in err, err
    assert not out.exists()
