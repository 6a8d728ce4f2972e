"""Ctrl-C at any moment of a batch's start: the terminal sends SIGINT to every process of the group
(the client and the workers it is starting); the batch says "weft: cancelled" in one line, exit 130,
with no worker's traceback."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from weft.core.image import load_image, save_image

ROOT = Path(__file__).resolve().parents[1]
WEFT = [sys.executable, "-c", "import sys; from weft.app.cli import main; sys.exit(main())"]


def _group_workers(pgid: int) -> list[int]:
    """Processes of the group ``pgid`` that are multiprocessing workers half-way through starting (or
    later): numpy is loaded, weft's modules are being imported."""
    found = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            if os.getpgid(int(entry)) != pgid:
                continue
            with open(f"/proc/{entry}/cmdline", "rb") as f:
                if b"--multiprocessing-fork" not in f.read():
                    continue
            with open(f"/proc/{entry}/maps", "rb") as f:
                if b"_multiarray_umath" in f.read():
                    found.append(int(entry))
        except OSError:
            continue
    return found


@pytest.mark.slow
@pytest.mark.skipif(not os.path.isdir("/proc") or os.name != "posix", reason="needs /proc and process groups")
@pytest.mark.parametrize("workers_seen", [1, 2])
def test_ctrl_c_as_workers_start_is_one_line(tmp_path, workers_seen):
    photo = load_image(ROOT / "resources" / "astronaut.png").image
    (tmp_path / "frames").mkdir()
    for i in range(6):
        save_image(tmp_path / "frames" / f"f{i}.png", photo[:64, 2 * i : 2 * i + 64])
    save_image(tmp_path / "gravel.png", load_image(ROOT / "resources" / "gravel.png").image[:64, :64])
    (tmp_path / "look.json").write_text(
        json.dumps(
            {
                "weft": 1,
                "method": "fast",
                "params": {"n": 5},
                "inputs": {"texture": "gravel.png", "target": "frames/f0.png"},
                "seed": 1,
            }
        )
    )
    batch = subprocess.Popen(
        [*WEFT, "batch", "look.json", "--over", "target", "frames", "-o", "out/{stem}.png", "--workers", "2", "-q"],
        cwd=tmp_path,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    deadline = time.monotonic() + 120
    while len(_group_workers(batch.pid)) < workers_seen and batch.poll() is None and time.monotonic() < deadline:
        time.sleep(0.005)
    os.killpg(batch.pid, signal.SIGINT)  # as the terminal does: the whole group, as a worker starts
    err = batch.communicate(timeout=120)[1]
    assert batch.returncode in (130, 0), err
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
