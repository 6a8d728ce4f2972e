"""The bad-input corpus through every CLI subcommand that takes an image.

The GUI side is tests/gui/test_open_bad_files.py.

Broken files: exit 2, exactly one stderr line naming the file, no traceback, no output file. Valid
but odd images: they work (exit 0, output written) or are refused the same way, in one line.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from weft.app import cli
from weft.core.image import load_image

from tests.data.make_corpus import BROKEN, ODD, make_corpus

ROOT = Path(__file__).resolve().parents[1]
# A convex quadrilateral's four sides, drawn inside a 40x40 photo, and their frontal square.
LINES = json.dumps(
    {
        "image_lines": [[4, 4, 34, 6], [34, 6, 36, 35], [36, 35, 5, 33], [5, 33, 4, 4]],
        "frontal_lines": [[0, 0, 31, 0], [31, 0, 31, 31], [31, 31, 0, 31], [0, 31, 0, 0]],
        "frontal_size": [32, 32],
    }
)
SUBCOMMANDS = ("quilt", "fast", "affine", "nfpt", "rectify", "blend", "fill")


def argv(method: str, image: str, out: str) -> list[str]:
    """The smallest useful command line of ``method`` with ``image`` as every image input."""
    tail = ["-o", out, "-q", "--seed", "1"]
    return {
        "quilt": ["quilt", image, "--size", "24x24", "--block", "8", "--overlap", "2"],
        "fast": ["fast", image],
        "affine": ["affine", image],
        "nfpt": ["nfpt", image, "--size", "24x24", "--block", "8", "--overlap", "2"],
        "rectify": ["rectify", image, "--lines", LINES],
        "blend": ["blend", image, image, "--mask", image],
        "fill": ["fill", image, "--extend", "0,0,4,0", "--patch", "3"],
    }[method] + tail


@pytest.fixture(scope="module")
def corpus(tmp_path_factory):
    return make_corpus(tmp_path_factory.mktemp("corpus"))


def check_refusal(err: str, path: Path, code: int, out: Path) -> None:
    lines = err.strip().splitlines()
    assert code == 2, err
    assert len(lines) == 1, err
    assert "Traceback" not in err
    assert str(path) in lines[0] or path.name in lines[0], lines[0]
    assert not out.exists()


@pytest.mark.parametrize("method", SUBCOMMANDS)
@pytest.mark.parametrize("item", BROKEN)
def test_broken_file_is_refused_in_one_line(corpus, tmp_path, capsys, method, item):
    path = corpus[item]
    out = tmp_path / "out.png"
    code = cli.main(argv(method, str(path), str(out)))
    captured = capsys.readouterr()
    check_refusal(captured.err, path, code, out)
    assert captured.out == ""


@pytest.mark.parametrize("method", SUBCOMMANDS)
@pytest.mark.parametrize("item", ODD)
def test_odd_image_works_or_is_refused_in_one_line(corpus, tmp_path, capsys, method, item):
    path = corpus[item]
    out = tmp_path / "out.png"
    code = cli.main(argv(method, str(path), str(out)))
    err = capsys.readouterr().err
    assert "Traceback" not in err
    if code == 0:
        assert out.is_file() and out.stat().st_size > 0
        assert err == ""
    else:
        assert code == 2, err
        assert len(err.strip().splitlines()) == 1, err
        assert not out.exists()
        # the line names the file and its size (too small for the method, or for a parameter)
        h, w = load_image(path).image.shape[:2]
        assert path.name in err and f"{w}x{h}" in err, err


@pytest.mark.parametrize("method", SUBCOMMANDS)
def test_unreadable_file_is_refused_in_one_line(corpus, tmp_path, capsys, monkeypatch, method):
    """We may run as root (``chmod 000`` changes nothing): reading the file raises PermissionError."""
    path = corpus["non_ascii"]
    real_stat = os.stat

    def denied(p, *a, **k):
        if os.fsdecode(p) == str(path):
            raise PermissionError(13, "Permission denied", str(path))
        return real_stat(p, *a, **k)

    monkeypatch.setattr("weft.core.image.files.os.stat", denied)
    out = tmp_path / "out.png"
    code = cli.main(argv(method, str(path), str(out)))
    err = capsys.readouterr().err
    check_refusal(err, path, code, out)
    assert "permission denied" in err


def test_bomb_is_refused_without_decoding(corpus, tmp_path, capsys, monkeypatch):
    import cv2

    def no_decode(*_a, **_k):
        raise AssertionError("the bomb's pixels were decoded")

    monkeypatch.setattr(cv2, "imdecode", no_decode)
    monkeypatch.setattr("weft.core.image.files._decode_pillow", no_decode)
    out = tmp_path / "out.png"
    code = cli.main(argv("quilt", str(corpus["bomb"]), str(out)))
    err = capsys.readouterr().err
    check_refusal(err, corpus["bomb"], code, out)
    assert "megapixels exceeds the limit" in err


@pytest.mark.slow
@pytest.mark.parametrize(
    "method,item",
    [
        ("quilt", "empty"),
        ("fast", "truncated_jpeg"),
        ("blend", "bomb"),
        ("rectify", "directory"),
        ("nfpt", "text_as_png"),
    ],
)
def test_real_process_refuses_broken_file(corpus, tmp_path, method, item):
    path = corpus[item]
    out = tmp_path / "out.png"
    proc = subprocess.run(
        [sys.executable, "-m", "weft.app.cli", *argv(method, str(path), str(out))],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    check_refusal(proc.stderr, path, proc.returncode, out)


@pytest.mark.slow
def test_real_process_reads_non_ascii_path(corpus, tmp_path):
    out = tmp_path / "sortie ü.png"
    proc = subprocess.run(
        [sys.executable, "-m", "weft.app.cli", *argv("quilt", str(corpus["non_ascii"]), str(out))],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stderr
    assert out.is_file()


@pytest.mark.parametrize("method, minimum", [("quilt", 2), ("fast", 3), ("affine", 8), ("nfpt", 8)])
def test_too_small_texture_names_file_size_and_minimum(corpus, tmp_path, capsys, method, minimum):
    path = corpus["tiny_1x1"]
    out = tmp_path / "out.png"
    code = cli.main(argv(method, str(path), str(out)))
    err = capsys.readouterr().err.strip()
    assert code == 2 and not out.exists()
    assert err.startswith(f"weft: {path}: ") and "1x1" in err, err
    assert f"at least {minimum}x{minimum} pixels" in err, err


def test_parameter_that_does_not_fit_names_the_file(corpus, tmp_path, capsys):
    path = corpus["thin_2x3000"]  # wide enough for quilting's minimum block (2), not for block 8
    out = tmp_path / "out.png"
    code = cli.main(["quilt", str(path), "--size", "24x24", "--block", "8", "-o", str(out), "-q"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and not out.exists()
    assert err == f"weft: {path}: parameter 'block' = 8 is outside 2..2 (must fit in the texture, 2x3000)"


def test_default_block_fits_a_thin_sample(corpus, tmp_path):
    """The synthesis block defaults to a share of the sample's shorter side, so a sample 2 px wide
    quilts with the defaults (a fixed default block refused it)."""
    from weft.core.image import load_image

    out = tmp_path / "out.png"
    assert cli.main(["quilt", str(corpus["thin_2x3000"]), "--size", "24x24", "-o", str(out), "-q"]) == 0
    assert load_image(out).image.shape[:2] == (24, 24)
