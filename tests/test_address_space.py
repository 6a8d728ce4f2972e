"""Under a low address-space limit (``ulimit -v``) weft says "out of memory" in one line and never
hangs: below the floor it needs to load its libraries it refuses at once; above it, a job runs, or
fails saying out of memory."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from weft.core.image import load_image, save_image

resource = pytest.importorskip("resource")
ROOT = Path(__file__).resolve().parents[1]
WEFT = [sys.executable, "-c", "import sys; from weft.app.cli import main; sys.exit(main())"]


def _weft_under(limit: int, argv: list, cwd: Path) -> subprocess.CompletedProcess:
    def cap():
        resource.setrlimit(resource.RLIMIT_AS, (limit, resource.RLIM_INFINITY))

    return subprocess.run(
        [*WEFT, *map(str, argv)], cwd=cwd, preexec_fn=cap, capture_output=True, text=True, timeout=240
    )


@pytest.fixture
def files(tmp_path):
    save_image(tmp_path / "gravel.png", load_image(ROOT / "resources" / "gravel.png").image[:64, :64])
    save_image(tmp_path / "photo.png", load_image(ROOT / "resources" / "astronaut.png").image[:64, :64])
    return tmp_path


@pytest.mark.slow
@pytest.mark.parametrize("mb", [400, 650])
@pytest.mark.parametrize("job", [["fast", "gravel.png", "--target", "photo.png"], ["nfpt", "photo.png"]])
def test_below_the_floor_weft_says_out_of_memory_at_once(files, mb, job):
    done = _weft_under(mb * 2**20, [*job, "-o", "o.png", "-q"], files)
    assert (done.returncode, done.stderr.count("\n")) == (2, 1), done.stderr
    assert done.stderr.startswith(f"weft: out of memory: the address-space limit (ulimit -v) of {mb} MiB")
    assert not (files / "o.png").exists()


@pytest.mark.slow
def test_above_the_floor_a_small_job_runs(files):
    done = _weft_under(1536 * 2**20, ["fast", "gravel.png", "--target", "photo.png", "-o", "o.png", "-q"], files)
    assert done.returncode == 0 and done.stderr == "", done.stderr
