"""One line, in weft's words: damaged JPEGs are refused (never used with a grey half), the codecs'
own lines never reach the terminal, names with control characters are quoted, an output path that
cannot be written is refused before the work, and numbers are written in ASCII digits.

``capfd`` sees what reaches file descriptor 2 itself, where libpng and libjpeg print.
"""

from __future__ import annotations

import os
from pathlib import Path

import cv2
import numpy as np
import pytest
from weft.app.cli import main
from weft.core.errors import ImageError
from weft.core.image import load_image, save_image

ROOT = Path(__file__).resolve().parents[1]
QUILT = ["--size", "24x24", "--block", "8", "--overlap", "2", "-q"]


def _run(argv, capfd):
    code = main([str(a) for a in argv])
    out, err = capfd.readouterr()
    return code, out, err


def _jpeg() -> tuple[bytes, int]:
    photo = cv2.imread(str(ROOT / "resources" / "astronaut.png"))
    data = cv2.imencode(".jpg", photo, [cv2.IMWRITE_JPEG_QUALITY, 90])[1].tobytes()
    return data, data.index(b"\xff\xda")


def test_a_jpeg_whose_scan_stops_halfway_is_refused(tmp_path, capfd):
    data, sos = _jpeg()
    bad = tmp_path / "half.jpg"
    bad.write_bytes(data[: sos + (len(data) - sos) // 2] + b"\xff\xd9")  # cut, but with an end marker
    with pytest.raises(ImageError, match=r"half\.jpg: truncated or corrupt JPEG data \(premature end of data"):
        load_image(bad)
    code, out, err = _run(["quilt", bad, *QUILT, "-o", tmp_path / "o.png"], capfd)
    assert code == 2 and err.count("\n") == 1 and err.startswith(f"weft: {bad}: truncated or corrupt JPEG")
    assert not (tmp_path / "o.png").exists()


def test_a_jpeg_with_bit_rot_in_its_scan_is_refused(tmp_path, capfd):
    data, sos = _jpeg()
    rotten = bytearray(data)
    for k in np.random.default_rng(0).integers(sos + 20, len(data) - 10, 20):
        rotten[k] ^= 0x10
    bad = tmp_path / "rot.jpg"
    bad.write_bytes(bytes(rotten))
    code, out, err = _run(["quilt", bad, *QUILT, "-o", tmp_path / "o.png"], capfd)
    assert code == 2 and err.count("\n") == 1 and "truncated or corrupt JPEG data" in err, err


def test_a_recoverable_jpeg_is_read_silently(tmp_path, capfd):
    data, _ = _jpeg()
    odd = tmp_path / "odd.jpg"
    odd.write_bytes(data[:-2] + b"\0\0\0" + b"\xff\xd9")  # stray bytes before the end marker: pixels whole
    whole = load_image(_write(tmp_path / "whole.jpg", data)).image
    assert np.array_equal(load_image(odd).image, whole)
    code, out, err = _run(["quilt", odd, *QUILT, "-o", tmp_path / "o.png"], capfd)
    assert code == 0 and err == ""


def _write(path: Path, data: bytes) -> Path:
    path.write_bytes(data)
    return path


def test_corrupt_png_data_is_one_line_of_weft(tmp_path, capfd):
    good = tmp_path / "good.png"
    save_image(good, load_image(ROOT / "resources" / "gravel.png").image[:40, :40])
    data = bytearray(good.read_bytes())
    idat = data.index(b"IDAT")
    data[idat + 40] ^= 0xFF  # the pixels' CRC no longer matches
    bad = _write(tmp_path / "bad.png", bytes(data))
    code, out, err = _run(["quilt", bad, *QUILT, "-o", tmp_path / "o.png"], capfd)
    assert code == 2 and err.count("\n") == 1 and err.startswith(f"weft: {bad}: "), err
    assert "libpng" not in err


@pytest.mark.parametrize("name", ["a\nb.png", "\x1b]0;pwned\x07x.png", "\x1b[2Jclear.png", "cr\rover.png"])
def test_names_with_control_characters_are_quoted(tmp_path, capfd, name):
    bad = _write(tmp_path / name, b"not an image")
    code, out, err = _run(["quilt", bad, *QUILT, "-o", tmp_path / "o.png"], capfd)
    assert code == 2 and err.count("\n") == 1 and err.endswith("\n")
    assert "\x1b" not in err and "\r" not in err and "\x07" not in err
    assert repr(str(bad)) in err  # quoted, as Python writes it
    code, out, err = _run(["run", tmp_path / ("missing" + name), "-o", tmp_path / "o.png"], capfd)
    assert code == 2 and err.count("\n") == 1 and "\x1b" not in err and "\r" not in err


def test_a_symlink_loop_as_output_is_refused_before_the_work(tmp_path, capfd, monkeypatch):
    texture = tmp_path / "t.png"
    save_image(texture, load_image(ROOT / "resources" / "gravel.png").image[:40, :40])
    loop = tmp_path / "loop.png"
    os.symlink(loop, loop)
    ran = []
    from weft.core.request import RenderRequest

    real_run = RenderRequest.run
    monkeypatch.setattr(RenderRequest, "run", lambda *a, **k: ran.append(1) or real_run(*a, **k))
    code, out, err = _run(["quilt", texture, *QUILT, "-o", loop], capfd)
    assert code == 2 and ran == [], err
    assert err == f"weft: {loop}: cannot write there (Too many levels of symbolic links)\n"


def test_a_float_tiff_is_refused_for_what_it_is(tmp_path):
    path = tmp_path / "f.tif"
    cv2.imwrite(str(path), np.random.default_rng(0).random((20, 30, 3)).astype(np.float32))
    with pytest.raises(ImageError) as caught:
        load_image(path)
    assert str(caught.value).startswith(f"{path}: unsupported sample type float32 (only 8- and 16-bit")


@pytest.mark.parametrize("text", ["1_000,0,0,0", "\u0661\u0662,0,0,0", "\uff11,0,0,0"])
def test_extend_takes_ascii_digits_only(tmp_path, capfd, text):
    image = tmp_path / "i.png"
    save_image(image, load_image(ROOT / "resources" / "gravel.png").image[:40, :40])
    code, out, err = _run(["fill", image, "--extend", text, "-o", tmp_path / "o.png"], capfd)
    assert code == 2 and err.count("\n") == 1 and "must be L,T,R,B" in err
    code, out, err = _run(["quilt", image, *QUILT[:-1], "--seed", text.split(",")[0], "-o", tmp_path / "o.png"], capfd)
    assert code == 2 and "must be an integer" in err


def test_weft_run_on_a_jpeg_says_only_png_exports_carry_a_recipe(tmp_path, capfd):
    data, _ = _jpeg()
    cat = _write(tmp_path / "cat.jpg", data)
    code, out, err = _run(["run", cat, "-o", tmp_path / "o.png"], capfd)
    assert (code, err) == (
        2,
        f"weft: {cat}: a JPEG image carries no recipe; only PNGs exported by weft (and .json recipe files) do\n",
    )
    plain = tmp_path / "plain.png"
    save_image(plain, np.zeros((8, 8, 3), np.float32))
    code, out, err = _run(["run", plain, "-o", tmp_path / "o.png"], capfd)
    assert (code, err) == (2, f"weft: {plain}: this PNG carries no weft recipe (only PNGs exported by weft do)\n")
