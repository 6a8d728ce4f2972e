"""The `weft` command as a user runs it: outputs, reports, recipes, and one-line errors."""

import json
import subprocess
import sys

import numpy as np
import pytest
from weft.app.cli import main
from weft.core.image import load_image, read_recipe, save_image


@pytest.fixture
def texture_path(tmp_path):
    rng = np.random.default_rng(0)
    img = rng.random((48, 40, 3)).astype(np.float32)
    path = tmp_path / "tex.png"
    save_image(path, img)
    return path


def run(argv, capsys):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_quilt_writes_image_and_report(texture_path, tmp_path, capsys):
    out_path = tmp_path / "out.png"
    code, out, err = run(
        [
            "quilt",
            texture_path,
            "-o",
            out_path,
            "--size",
            "64x50",
            "--block",
            "16",
            "--mode",
            "random",
            "--seed",
            "3",
            "--report",
        ],
        capsys,
    )
    assert code == 0, err
    assert err == ""  # not a terminal: no progress bar
    lines = out.strip().splitlines()
    assert len(lines) == 1
    report = json.loads(lines[0])
    assert report["method"] == "quilt" and report["size"] == [64, 50] and report["seed"] == 3
    assert report["seconds"] >= 0 and report["blocks"] == 4 * 4
    image = load_image(out_path).image
    assert image.shape == (50, 64, 3)


def test_same_seed_same_output_and_recipe_reproduces(texture_path, tmp_path, capsys):
    a, b, c = tmp_path / "a.png", tmp_path / "b.png", tmp_path / "c.png"
    assert run(["quilt", texture_path, "-o", a, "--size", "40x40", "--block", "8", "--seed", "9"], capsys)[0] == 0
    assert run(["quilt", texture_path, "-o", b, "--size", "40x40", "--block", "8", "--seed", "9"], capsys)[0] == 0
    assert np.array_equal(load_image(a).image, load_image(b).image)
    recipe = json.loads(read_recipe(a))
    assert recipe["weft"] == 1 and recipe["method"] == "quilt" and recipe["seed"] == 9
    assert recipe["params"]["block"] == 8 and recipe["params"]["size"] == [40, 40]
    assert recipe["inputs"] == {"texture": "tex.png"}  # relative to the output's folder
    # `weft run` on the exported PNG, and on the recipe as a JSON file, give the same pixels.
    assert run(["run", a, "-o", c], capsys)[0] == 0
    assert np.array_equal(load_image(a).image, load_image(c).image)
    rj = tmp_path / "recipe.json"
    rj.write_text(json.dumps(recipe))
    d = tmp_path / "d.png"
    assert run(["run", rj, "-o", d], capsys)[0] == 0
    assert np.array_equal(load_image(a).image, load_image(d).image)


def test_without_seed_the_chosen_seed_is_recorded(texture_path, tmp_path, capsys):
    a, b = tmp_path / "a.png", tmp_path / "b.png"
    run(["quilt", texture_path, "-o", a, "--block", "8"], capsys)
    seed = json.loads(read_recipe(a))["seed"]
    assert isinstance(seed, int)
    run(["quilt", texture_path, "-o", b, "--block", "8", "--seed", seed], capsys)
    assert np.array_equal(load_image(a).image, load_image(b).image)


def test_sixteen_bit_tiff_output(texture_path, tmp_path, capsys):
    out_path = tmp_path / "out.tif"
    code, _, err = run(["quilt", texture_path, "-o", out_path, "--bit-depth", "16", "--seed", "1"], capsys)
    assert code == 0, err
    assert load_image(out_path).info.bit_depth == 16


@pytest.mark.parametrize(
    "extra, fragment",
    [
        (["--block", "1"], "parameter 'block' = 1 is outside 2..1024"),
        (["--block", "abc"], "parameter 'block' = 'abc' must be an integer"),
        (["--block", "41"], "parameter 'block' = 41 is outside 2..40 (must fit in the texture, 40x48)"),
        (["--size", "0x5"], "parameter 'size' = 0x5 has a side outside 1..16384"),
        (["--mode", "wild"], "parameter 'mode' = 'wild' is not one of random, overlap, mincut"),
        (["--seed", "-4"], "parameter 'seed' = -4 is outside"),
        (["--bit-depth", "12"], "'bit-depth' = 12 must be 8 or 16"),
        (["--frobnicate"], "unrecognized arguments: --frobnicate"),
    ],
)
def test_bad_parameters_exit_2_with_one_line(texture_path, tmp_path, capsys, extra, fragment):
    out_path = tmp_path / "out.png"
    code, out, err = run(["quilt", texture_path, "-o", out_path] + extra, capsys)
    assert code == 2
    assert err.count("\n") == 1 and err.startswith("weft: ") and fragment in err
    assert out == "" and not out_path.exists()


@pytest.mark.parametrize("kind", ["missing", "corrupt", "text", "directory"])
def test_bad_input_files_exit_2_naming_the_file(tmp_path, capsys, kind):
    bad = tmp_path / "bad.png"
    if kind == "corrupt":
        bad.write_bytes(b"\x89PNG\r\n\x1a\n" + b"\x00" * 40)
    elif kind == "text":
        bad.write_text("hello, not an image")
    elif kind == "directory":
        bad.mkdir()
    out_path = tmp_path / "out.png"
    code, out, err = run(["quilt", bad, "-o", out_path], capsys)
    assert code == 2
    assert err.count("\n") == 1 and "bad.png" in err
    assert not out_path.exists()


def test_refuses_to_overwrite_input_and_bad_outputs(texture_path, tmp_path, capsys):
    before = texture_path.read_bytes()
    code, _, err = run(["quilt", texture_path, "-o", texture_path], capsys)
    assert code == 2 and "refusing to overwrite the input file" in err
    assert texture_path.read_bytes() == before
    code, _, err = run(["quilt", texture_path, "-o", tmp_path / "out.gif"], capsys)
    assert code == 2 and "cannot save this format" in err
    code, _, err = run(["quilt", texture_path, "-o", tmp_path / "nope" / "out.png"], capsys)
    assert code == 2 and "does not exist" in err


def test_run_errors(tmp_path, capsys, texture_path):
    code, _, err = run(["run", tmp_path / "none.json", "-o", tmp_path / "x.png"], capsys)
    assert code == 2 and "none.json" in err
    bad = tmp_path / "r.json"
    bad.write_text(json.dumps({"weft": 1, "method": "teleport", "params": {}, "inputs": {}}))
    code, _, err = run(["run", bad, "-o", tmp_path / "x.png"], capsys)
    assert code == 2 and "unknown method 'teleport'" in err
    bad.write_text(json.dumps({"weft": 1, "method": "quilt", "params": {"block": 0}, "inputs": {"texture": "tex.png"}}))
    code, _, err = run(["run", bad, "-o", tmp_path / "x.png"], capsys)
    assert code == 2 and "parameter 'block' = 0" in err
    bad.write_text(json.dumps({"weft": 1, "method": "quilt", "params": {}, "inputs": {"texture": "gone.png"}}))
    code, _, err = run(["run", bad, "-o", tmp_path / "x.png"], capsys)
    assert code == 2 and "gone.png" in err
    code, _, err = run(["run", texture_path, "-o", tmp_path / "x.png"], capsys)
    assert code == 2 and "carries no weft recipe" in err


def test_usage_errors(capsys):
    code, _, err = run(["teleport"], capsys)
    assert code == 2 and err.count("\n") == 1 and "invalid choice" in err
    code, _, err = run(["quilt"], capsys)
    assert code == 2 and err.count("\n") == 1 and "required" in err


def test_version(capsys):
    with pytest.raises(SystemExit) as e:
        main(["--version"])
    assert e.value.code == 0
    assert capsys.readouterr().out.startswith("weft 0.")


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["missing", "truncated"])
def test_real_process_prints_one_line_and_no_traceback(tmp_path, texture_path, kind):
    """A separate process, so that C libraries' own stderr output would show: one line, status 2."""
    bad = tmp_path / "input.png"
    if kind == "truncated":
        bad.write_bytes(texture_path.read_bytes()[:600])
    out_path = tmp_path / "out.png"
    proc = subprocess.run(
        [sys.executable, "-m", "weft.app.cli", "quilt", str(bad), "-o", str(out_path)], capture_output=True, text=True
    )
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr and "input.png" in proc.stderr
    assert not out_path.exists()


def test_region_restricts_the_source_and_is_recorded(texture_path, tmp_path, capsys):
    out = tmp_path / "r.png"
    code, _, err = run(
        ["quilt", texture_path, "-o", out, "--region", "4,8,24", "--block", "8", "--mode", "random", "--seed", "1"],
        capsys,
    )
    assert code == 0, err
    recipe = json.loads(read_recipe(out))
    assert recipe["region"] == [4, 8, 24]
    tex = load_image(texture_path).image[8:32, 4:28]
    result = load_image(out).image
    assert result.shape == (48, 48, 3)  # twice the region, the default size
    # Every pixel comes from the region (random blocks are verbatim copies).
    region_pixels = {tuple(np.round(p, 4)) for p in tex.reshape(-1, 3)}
    assert all(tuple(np.round(p, 4)) in region_pixels for p in result.reshape(-1, 3)[::7])
    again = tmp_path / "again.png"
    assert run(["run", out, "-o", again], capsys)[0] == 0
    assert np.array_equal(result, load_image(again).image)
    code, _, err = run(["quilt", texture_path, "-o", tmp_path / "x.png", "--region", "30,30,30"], capsys)
    assert code == 2 and "parameter 'region' = 30,30,30 leaves the texture (40x48)" in err
    code, _, err = run(["quilt", texture_path, "-o", tmp_path / "x.png", "--region", "a,b"], capsys)
    assert code == 2 and "must be X,Y,SIDE" in err
