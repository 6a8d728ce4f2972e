"""A failing write (full disk, read-only folder) leaves the old file intact and says why.

The full disk is the real ``/dev/full`` (every write to it fails with ENOSPC): the temporary file's
bytes are sent there. A read-only folder is ``chmod 555`` when not running as root (root writes
anyway), else ``mkstemp`` is made to fail as it would there.
"""

from __future__ import annotations

import errno
import os

import numpy as np
import pytest
from weft.app import cli
from weft.core.errors import ImageError
from weft.core.image import save_image

from tests.data.make_corpus import make_corpus


@pytest.fixture
def texture(tmp_path):
    folder = tmp_path / "c"
    folder.mkdir()
    return make_corpus(folder)["non_ascii"]


def _full_disk(monkeypatch):
    if not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full on this system")

    def to_dev_full(fd, mode="r", *a, **k):
        os.close(fd)
        return open("/dev/full", mode, buffering=0)

    monkeypatch.setattr("weft.core.image.writing.os.fdopen", to_dev_full)


def _read_only(folder, monkeypatch):
    if os.geteuid() != 0:
        folder.chmod(0o555)
        return

    def denied(*_a, **_k):
        raise PermissionError(errno.EACCES, "Permission denied")

    monkeypatch.setattr("weft.core.image.writing.tempfile.mkstemp", denied)


def _quilt(texture, out):
    return cli.main(["quilt", str(texture), "--size", "24x24", "--block", "8", "--overlap", "2", "-o", str(out), "-q"])


def test_full_disk_keeps_the_old_output_and_says_why(texture, tmp_path, capsys, monkeypatch):
    out = tmp_path / "out.png"
    out.write_bytes(b"old result")
    _full_disk(monkeypatch)
    assert _quilt(texture, out) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "out.png" in err[0] and "No space left on device" in err[0], err
    assert out.read_bytes() == b"old result"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c", "out.png"]  # no temporary file left


def test_read_only_folder_keeps_the_old_output_and_says_why(texture, tmp_path, capsys, monkeypatch):
    folder = tmp_path / "ro"
    folder.mkdir()
    out = folder / "out.png"
    out.write_bytes(b"old result")
    _read_only(folder, monkeypatch)
    try:
        assert _quilt(texture, out) == 2
    finally:
        folder.chmod(0o755)
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "out.png" in err[0] and "ermission denied" in err[0], err
    assert out.read_bytes() == b"old result"
    assert [p.name for p in folder.iterdir()] == ["out.png"]


def test_save_image_to_full_disk_raises_image_error(tmp_path, monkeypatch):
    out = tmp_path / "x.png"
    _full_disk(monkeypatch)
    with pytest.raises(ImageError, match="x.png: cannot write"):
        save_image(out, np.zeros((4, 4), np.float32))
    assert not out.exists() and list(tmp_path.iterdir()) == []
