"""Nothing lost: an output never replaces a file the run reads, whatever path names it (a second mount
of its folder, a link to the folder, the recipe itself); a re-run never keeps a damaged output as done.

The bind-mount cases run the command inside a private mount namespace (``unshare -m``: the mount is
seen by that command alone and vanishes with it); they are skipped only where the machine allows no
mount namespace (not root, or no ``unshare``).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from weft.app.cli import main
from weft.core.image import load_image, read_recipe, save_image

ROOT = Path(__file__).resolve().parents[1]
WEFT = [sys.executable, "-c", "import sys; from weft.app.cli import main; sys.exit(main())"]
QUILT = ["--size", "24x24", "--block", "8", "--overlap", "2", "-q"]


def _mount_namespaces() -> str | None:
    """Why bind mounts cannot be tested here, or None when they can."""
    if shutil.which("unshare") is None or shutil.which("mount") is None:
        return "no unshare/mount command on this machine"
    probe = subprocess.run(["unshare", "-m", "true"], capture_output=True)
    return None if probe.returncode == 0 else "no private mount namespace allowed (needs root / CAP_SYS_ADMIN)"


def _in_namespace_with_bind(src: Path, dst: Path, argv: list) -> subprocess.CompletedProcess:
    """``weft argv`` with ``dst`` a bind mount of ``src``, in a mount namespace of its own."""
    script = 'mount --bind "$1" "$2" && shift 2 && exec "$@"'
    return subprocess.run(
        ["unshare", "-m", "sh", "-c", script, "sh", str(src), str(dst), *WEFT, *map(str, argv)],
        capture_output=True,
        text=True,
        timeout=300,
    )


def _texture(path: Path) -> Path:
    save_image(path, load_image(ROOT / "resources" / "gravel.png").image[:40, :40])
    return path


def _run(argv, capsys):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture
def bind():
    reason = _mount_namespaces()
    if reason:
        pytest.skip(reason)


@pytest.mark.slow
def test_an_input_reached_through_a_bind_mount_is_not_overwritten(tmp_path, bind):
    src, dst = tmp_path / "src", tmp_path / "dst"
    src.mkdir(), dst.mkdir()
    texture = _texture(src / "in.png")
    before = texture.read_bytes()
    done = _in_namespace_with_bind(src, dst, ["quilt", texture, *QUILT, "-o", dst / "in.png"])
    assert done.returncode == 2, done.stderr
    assert done.stderr.strip().splitlines() == [
        f"weft: {dst / 'in.png'}: refusing to overwrite the input file {texture}"
    ]
    assert texture.read_bytes() == before


@pytest.mark.slow
def test_a_batch_never_overwrites_its_frames_through_a_bind_mount(tmp_path, bind):
    src, dst = tmp_path / "src", tmp_path / "dst"
    (src / "frames").mkdir(parents=True), dst.mkdir()
    texture = _texture(tmp_path / "gravel.png")
    frames = [_texture(src / "frames" / f"f{i}.png") for i in range(3)]
    before = [f.read_bytes() for f in frames]
    recipe = tmp_path / "look.json"
    recipe.write_text(
        json.dumps(
            {
                "weft": 1,
                "method": "fast",
                "params": {"n": 5},
                "inputs": {"texture": str(texture), "target": str(frames[0])},
                "seed": 1,
            }
        )
    )
    done = _in_namespace_with_bind(
        src, dst, ["batch", recipe, "--over", "target", src / "frames", "-o", str(dst / "frames" / "{stem}.png"), "-q"]
    )
    assert done.returncode == 2, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "refusing to overwrite the input file" in lines[0] and "f0.png" in lines[0], lines
    assert [f.read_bytes() for f in frames] == before


def test_an_input_reached_through_a_linked_folder_is_not_overwritten(tmp_path, capsys):
    src = tmp_path / "src"
    src.mkdir()
    (tmp_path / "dst").symlink_to(src, target_is_directory=True)
    texture = _texture(src / "in.png")
    before = texture.read_bytes()
    code, out, err = _run(["quilt", texture, *QUILT, "-o", tmp_path / "dst" / "in.png"], capsys)
    assert code == 2 and "refusing to overwrite the input file" in err and err.count("\n") == 1
    assert texture.read_bytes() == before


def _export(tmp_path, capsys) -> Path:
    texture = _texture(tmp_path / "tex.png")
    look = tmp_path / "look.png"
    assert _run(["quilt", texture, *QUILT, "--seed", "3", "-o", look], capsys)[0] == 0
    return look


def test_weft_run_never_overwrites_the_recipe_it_reproduces(tmp_path, capsys):
    look = _export(tmp_path, capsys)
    before = look.read_bytes()
    code, out, err = _run(["run", look, "-o", look, "--seed", "5"], capsys)
    assert code == 2 and err == f"weft: {look}: refusing to overwrite the input file {look}\n"
    assert look.read_bytes() == before
    (tmp_path / "alias").symlink_to(tmp_path, target_is_directory=True)
    code, out, err = _run(["run", look, "-o", tmp_path / "alias" / "look.png"], capsys)
    assert code == 2 and "refusing to overwrite the input file" in err and look.read_bytes() == before


@pytest.mark.slow
def test_a_batch_never_overwrites_its_recipe_png(tmp_path, capsys):
    look = _export(tmp_path, capsys)
    before = look.read_bytes()
    frames = tmp_path / "frames"
    frames.mkdir()
    for i in range(2):
        _texture(frames / f"look{'' if i == 0 else i}.png")  # item 0's output would be look.png
    code, out, err = _run(
        ["batch", look, "--over", "texture", frames, "-o", str(tmp_path / "{stem}.png"), "-q"], capsys
    )
    assert code == 2 and "refusing to overwrite the recipe file" in err and err.count("\n") == 1, err
    assert look.read_bytes() == before


def _fast_batch(tmp_path, n=3):
    frames = tmp_path / "frames"
    frames.mkdir()
    for i in range(n):
        save_image(
            frames / f"f{i}.png", load_image(ROOT / "resources" / "astronaut.png").image[4 * i : 4 * i + 40, :48]
        )
    _texture(tmp_path / "gravel.png")
    (tmp_path / "look.json").write_text(
        json.dumps(
            {
                "weft": 1,
                "method": "fast",
                "params": {"n": 5},
                "inputs": {"texture": "gravel.png", "target": "frames/f0.png"},
                "seed": 2,
            }
        )
    )
    return [
        "batch",
        tmp_path / "look.json",
        "--over",
        "target",
        frames,
        "-o",
        str(tmp_path / "out" / "{stem}.png"),
        "--workers",
        "1",
        "-q",
    ]


@pytest.mark.slow
def test_a_rerun_redoes_an_output_cut_short_or_damaged(tmp_path, capsys):
    argv = _fast_batch(tmp_path)
    assert _run(argv, capsys)[0] == 0
    outs = sorted((tmp_path / "out").iterdir())
    whole = [p.read_bytes() for p in outs]
    outs[0].write_bytes(whole[0][: len(whole[0]) // 2])  # an interrupted copy: the recipe chunk is still there
    damaged = bytearray(whole[1])
    damaged[-20] ^= 0x40  # one flipped bit in the pixels
    outs[1].write_bytes(bytes(damaged))
    assert read_recipe(outs[0]) is not None and read_recipe(outs[1]) is not None
    code, out, err = _run(argv, capsys)
    assert code == 0 and err == "2 written, 1 already done\n"
    assert [p.read_bytes() for p in outs] == whole


def _bomb_png(path: Path, width: int, height: int) -> None:
    """A small PNG whose header claims ``width`` x ``height`` pixels (a decompression bomb's header)."""
    import struct
    import zlib

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    path.write_bytes(
        b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(b"\0" * 64)) + chunk(b"IEND", b"")
    )


@pytest.mark.slow
def test_one_bomb_frame_fails_alone_and_the_rest_are_written(tmp_path, capsys):
    argv = _fast_batch(tmp_path)
    _bomb_png(tmp_path / "frames" / "f9.png", 60000, 60000)
    code, out, err = _run(argv, capsys)
    lines = err.strip().splitlines()
    assert code == 1, err
    assert lines[-1] == (
        "3 written, 1 failed: f9.png: 60000x60000 = 3600.0 megapixels exceeds the limit of "
        "50 megapixels (set WEFT_MAX_PIXELS to raise it)"
    )
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["f0.png", "f1.png", "f2.png"]


@pytest.mark.slow
def test_a_frame_too_large_for_memory_fails_alone(tmp_path, capsys, monkeypatch):
    argv = _fast_batch(tmp_path)
    save_image(tmp_path / "frames" / "f3.png", np.zeros((400, 400, 3), np.float32))
    # the good frames (40x48) fit in this much memory by the fast method's estimate; the 400x400 one does not
    monkeypatch.setattr("weft.core.batch.memory.available_memory", lambda: 1_000_000)
    code, out, err = _run(argv[:-3] + ["-q"], capsys)  # default workers: as many as fit
    assert code == 1, err
    assert err.strip().splitlines()[-1].startswith("3 written, 1 failed: f3.png: needs about")
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["f0.png", "f1.png", "f2.png"]


@pytest.mark.slow
def test_a_killed_writers_temporary_files_are_removed_on_the_next_run(tmp_path, capsys):
    from weft.core.image.temporaries import _writer_tag

    argv = _fast_batch(tmp_path)
    assert _run(argv, capsys)[0] == 0
    out = tmp_path / "out"
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()  # a process of this machine that no longer runs
    host = _writer_tag().split("-")[0]
    killed = out / f".f0.png.ab12CD_9.{host}-{dead.pid}.tmp"  # what a batch killed mid-write leaves
    older = out / ".f1.png.zz8Yq1Xw.tmp"  # an older weft's name, untouched for an hour
    alive = out / f".f2.png.Qw3rTy7u.{host}-{os.getpid()}.tmp"  # a writer still at work: kept
    foreign = out / ".notes.txt.ab12CD_9.tmp"  # not one of this batch's outputs: kept
    for p in (killed, older, alive, foreign):
        p.write_bytes(b"half an image")
    os.utime(older, (1e9, 1e9))
    os.utime(foreign, (1e9, 1e9))
    code, _, err = _run(argv, capsys)
    assert code == 0 and err == "0 written, 3 already done\n"
    assert sorted(p.name for p in out.iterdir()) == sorted([alive.name, foreign.name, "f0.png", "f1.png", "f2.png"])
