"""Every file weft reads is a regular file, size-checked before it is read: a named pipe or a device
given as a recipe, feature lines, a view, a session, a batch's fixed input or resumed output is
refused at once in one line (status 2), never waited on or read until memory runs out; a PNG whose
compressed recipe would inflate past the 10 MB limit is refused after inflating no further."""

from __future__ import annotations

import json
import os
import struct
import threading
import zlib
from pathlib import Path

import numpy as np
import pytest
from weft.app.cli import main
from weft.core.errors import WeftError
from weft.core.image import load_image, read_recipe, save_image
from weft.core.session import read_session

ROOT = Path(__file__).resolve().parents[1]
QUILT = ["--size", "24x24", "--block", "8", "--overlap", "2", "-q"]
pytestmark = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no named pipes on this system")


@pytest.fixture
def fifo(tmp_path):
    """A named pipe; should anything open it for reading, it gets an empty write end at once, so a
    test of a reader that waits fails on its message instead of hanging."""
    path = tmp_path / "pipe.json"
    os.mkfifo(path)
    stop = threading.Event()

    def unblock():  # every pipe under tmp_path, wherever a test moves it
        while not stop.wait(0.1):
            for pipe in [p for p in tmp_path.rglob("*") if p.is_fifo()]:
                try:
                    os.close(os.open(pipe, os.O_WRONLY | os.O_NONBLOCK))
                except OSError:
                    pass

    guard = threading.Thread(target=unblock, daemon=True)
    guard.start()
    yield path
    stop.set()
    guard.join()


def _run(argv, capsys):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def _texture(path: Path) -> Path:
    save_image(path, load_image(ROOT / "resources" / "gravel.png").image[:40, :40])
    return path


def test_a_recipe_that_is_a_fifo_is_refused_at_once(fifo, tmp_path, capsys):
    code, out, err = _run(["run", fifo, "-o", tmp_path / "o.png"], capsys)
    assert (code, err) == (2, f"weft: {fifo}: is a named pipe (FIFO), not a recipe file\n")
    png = fifo.with_name("pipe.png")
    os.rename(fifo, png)
    code, out, err = _run(["run", png, "-o", tmp_path / "o.png"], capsys)
    assert (code, err) == (2, f"weft: {png}: is a named pipe (FIFO), not a recipe file\n")


def test_a_session_that_is_a_fifo_is_refused_at_once(fifo):
    with pytest.raises(WeftError, match=r"pipe\.json: is a named pipe \(FIFO\), not a weft session file$"):
        read_session(fifo)


@pytest.mark.parametrize("option", ["--lines", "--view"])
def test_lines_and_views_from_a_fifo_or_a_device(fifo, tmp_path, capsys, option):
    photo = _texture(tmp_path / "p.png")
    argv = ["nfpt", photo, "-o", tmp_path / "o.png", "-q"]
    code, out, err = _run([*argv, option, fifo], capsys)
    assert code == 2 and err.count("\n") == 1 and "is a named pipe (FIFO)" in err, err
    code, out, err = _run([*argv, option, "/dev/zero"], capsys)
    assert (code, err.count("\n")) == (2, 1) and "/dev/zero: is a character device" in err, err


def test_a_recipe_naming_a_device_as_its_lines(tmp_path, capsys):
    _texture(tmp_path / "p.png")
    recipe = tmp_path / "r.json"
    recipe.write_text(
        json.dumps(
            {"weft": 1, "method": "nfpt", "params": {"lines": "/dev/zero"}, "inputs": {"photo": "p.png"}, "seed": 1}
        )
    )
    code, out, err = _run(["run", recipe, "-o", tmp_path / "o.png"], capsys)
    assert code == 2 and err.count("\n") == 1 and "/dev/zero: is a character device" in err, err


@pytest.mark.slow
def test_a_batch_whose_fixed_input_or_resumed_output_is_a_fifo(fifo, tmp_path, capsys):
    _texture(tmp_path / "f0.png")
    os.rename(fifo, tmp_path / "gravel.png")  # the recipe's fixed texture is a pipe
    frames = tmp_path / "frames"
    frames.mkdir()
    _texture(frames / "a.png")
    recipe = tmp_path / "look.json"
    recipe.write_text(
        json.dumps(
            {
                "weft": 1,
                "method": "fast",
                "params": {"n": 5},
                "inputs": {"texture": "gravel.png", "target": "f0.png"},
                "seed": 1,
            }
        )
    )
    code, out, err = _run(
        [
            "batch",
            recipe,
            "--over",
            "target",
            frames,
            "-o",
            str(tmp_path / "out" / "{stem}.png"),
            "--workers",
            "1",
            "-q",
        ],
        capsys,
    )
    assert code == 2 and err == (
        f"weft: {recipe}: the texture image {tmp_path / 'gravel.png'} is a named pipe (FIFO), not an image file\n"
    )
    os.rename(tmp_path / "gravel.png", fifo)
    _texture(tmp_path / "gravel.png")
    (tmp_path / "out").mkdir()
    os.rename(fifo, tmp_path / "out" / "a.png")  # an output left as a pipe: not done, and not replaced
    code, out, err = _run(
        [
            "batch",
            recipe,
            "--over",
            "target",
            frames,
            "-o",
            str(tmp_path / "out" / "{stem}.png"),
            "--workers",
            "1",
            "-q",
        ],
        capsys,
    )
    assert code == 2 and err.count("\n") == 1 and "which is a named pipe (FIFO)" in err, err


def test_an_image_that_is_a_device_is_refused(capsys, tmp_path):
    code, out, err = _run(["quilt", "/dev/zero", *QUILT, "-o", tmp_path / "o.png"], capsys)
    assert (code, err) == (2, "weft: /dev/zero: is a character device, not an image file\n")


def _chunk(kind: bytes, body: bytes) -> bytes:
    return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))


def test_a_recipe_chunk_that_inflates_to_a_gigabyte_is_refused(tmp_path, capsys):
    plain = tmp_path / "plain.png"
    save_image(plain, np.zeros((8, 8, 3), np.float32))
    data = plain.read_bytes()
    inflater = zlib.compressobj(9)
    # 1 GiB of spaces after a valid recipe's first bytes: about 1 MB compressed
    bomb = (
        inflater.compress(b'{"weft": 1, "method": "quilt"')
        + b"".join(inflater.compress(b" " * 2**24) for _ in range(64))
        + inflater.flush()
    )
    png = tmp_path / "bomb.png"
    png.write_bytes(data[:33] + _chunk(b"zTXt", b"weft-recipe\0\0" + bomb) + data[33:])
    import tracemalloc

    tracemalloc.start()
    try:
        with pytest.raises(WeftError, match=r"bomb\.png: recipe is longer than the 10 MB limit"):
            read_recipe(png)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 40 * 2**20  # the 10 MB limit (plus the file's chunk), never the gigabyte
    code, out, err = _run(["run", png, "-o", tmp_path / "o.png"], capsys)
    assert (code, err) == (2, f"weft: {png}: recipe is longer than the 10 MB limit\n")
