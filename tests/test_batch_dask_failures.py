"""Dask failures in one line each: an address weft cannot use (tls:// without certificates, ucx://
without UCX), a scheduler with no workers (a time limit, not a silent wait), and a scheduler killed
mid-batch (the summary of what was written, the rest failed with the reason, no traceback)."""

from __future__ import annotations

import contextlib
import os
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

distributed = pytest.importorskip("distributed")

from weft.app.cli import main  # noqa: E402
from weft.core.batch import dask_pool  # noqa: E402
from weft.core.errors import WeftError  # noqa: E402

from .test_batch import make_frames, scene, slow_scene  # noqa: E402,F401  (fixtures)

DASK = Path(sys.executable).with_name("dask")


def _batch(tmp: Path, out_dir: Path, address: str, capfd, *extra: str) -> tuple[int, str]:
    """``weft batch`` of the scene's recipe over its frames on the scheduler at ``address``: (exit code, stderr)."""
    argv = ["batch", tmp / "look.json", "--over", "target", tmp / "frames", "-o", out_dir / "{stem}.png"]
    code = main([str(a) for a in [*argv, "--scheduler", address, *extra]])
    return code, capfd.readouterr().err


@pytest.mark.parametrize("address", ["tls://127.0.0.1:1", "ucx://127.0.0.1:1"])
def test_an_address_weft_cannot_use_is_one_line(scene, capfd, address):
    tmp, _ = scene
    code, err = _batch(tmp, tmp / "o", address, capfd)
    assert code == 2 and err.count("\n") == 1 and err.startswith(f"weft: cannot reach the Dask scheduler at {address} ")
    assert "internal error" not in err


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _start(args: list[str], tmp: Path) -> subprocess.Popen:
    return subprocess.Popen(
        [str(DASK), *args], cwd=tmp, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True
    )


def _wait_for_scheduler(address: str) -> None:
    host, port = address.removeprefix("tcp://").rsplit(":", 1)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        try:
            socket.create_connection((host, int(port)), timeout=1).close()
            return
        except OSError:
            time.sleep(0.1)
    raise AssertionError("the scheduler did not start")


@contextlib.contextmanager
def _cluster(tmp: Path, workers: int):
    """A local Dask scheduler (and ``workers`` worker processes of one thread each), killed on the
    way out: ``(address, scheduler process, worker process or None)``."""
    address = f"tcp://127.0.0.1:{_free_port()}"
    scheduler = _start(
        ["scheduler", "--host", "127.0.0.1", "--port", address.rsplit(":", 1)[1], "--dashboard-address", ":0"], tmp
    )
    worker = None
    try:
        _wait_for_scheduler(address)
        if workers:
            worker = _start(["worker", address, "--nthreads", "1", "--nworkers", str(workers), "--no-dashboard"], tmp)
            # the tests shorten weft's wait for workers; a worker starting slowly on a busy machine is not that
            with distributed.Client(address, timeout="60s") as client:
                client.wait_for_workers(workers, timeout=120)
        yield address, scheduler, worker
    finally:
        for p in (scheduler, worker):
            if p is not None:
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(p.pid, signal.SIGKILL)
                p.wait()


def _kill_when_one_is_written(out_dir: Path, process: subprocess.Popen) -> threading.Thread:
    """A thread that kills ``process`` once the batch has written its first output."""

    def kill():
        deadline = time.monotonic() + 240
        while time.monotonic() < deadline and not (out_dir.is_dir() and any(out_dir.glob("*.png"))):
            time.sleep(0.05)
        os.killpg(process.pid, signal.SIGKILL)

    killer = threading.Thread(target=kill, daemon=True)
    killer.start()
    return killer


@pytest.mark.slow
@pytest.mark.skipif(not DASK.exists(), reason="no dask command beside this Python")
def test_a_scheduler_without_workers_is_a_time_limit_not_a_silent_wait(scene, capfd, monkeypatch, tmp_path):
    tmp, _ = scene
    with _cluster(tmp_path, workers=0) as (address, _scheduler, _worker):
        monkeypatch.setattr(dask_pool, "WORKER_TIMEOUT", 2.0)
        code, err = _batch(tmp, tmp / "o", address, capfd)
        assert code == 2 and err == (
            f"weft: the Dask scheduler at {address} has no workers (waited 2 s; set "
            "WEFT_DASK_WORKER_TIMEOUT to wait longer)\n"
        )


@pytest.mark.slow
@pytest.mark.skipif(not DASK.exists(), reason="no dask command beside this Python")
def test_a_scheduler_killed_mid_batch_ends_with_the_summary(slow_scene, capfd, tmp_path):
    tmp, _ = slow_scene
    with _cluster(tmp_path, workers=1) as (address, scheduler, _worker):
        out_dir = tmp / "killed"
        killer = _kill_when_one_is_written(out_dir, scheduler)
        code, err = _batch(tmp, out_dir, address, capfd, "-q")
        killer.join()
        lines = err.strip().splitlines()
        assert code == 1 and "Traceback" not in err and "internal error" not in err, err
        assert "written" in lines[-1] and "was lost before it was done" in lines[-1], err


@pytest.mark.slow
@pytest.mark.skipif(not DASK.exists(), reason="no dask command beside this Python")
def test_a_cluster_left_without_workers_mid_batch_ends_with_the_summary(slow_scene, capfd, tmp_path, monkeypatch):
    tmp, _ = slow_scene
    with _cluster(tmp_path, workers=1) as (address, _scheduler, worker):
        monkeypatch.setattr(dask_pool, "WORKER_TIMEOUT", 3.0)
        out_dir = tmp / "orphaned"
        killer = _kill_when_one_is_written(out_dir, worker)
        code, err = _batch(tmp, out_dir, address, capfd, "-q")
        killer.join()
        lines = err.strip().splitlines()
        assert code == 1 and "Traceback" not in err, err
        assert "written" in lines[-1] and "had no workers left for 3 s" in lines[-1], err


@pytest.mark.slow
@pytest.mark.skipif(not DASK.exists(), reason="no dask command beside this Python")
def test_a_result_lost_with_its_worker_fails_instead_of_waiting_forever(tmp_path, monkeypatch):
    # The window the batch can fall into: an item done, its worker killed before the result is fetched.
    with _cluster(tmp_path, workers=1) as (address, _scheduler, worker):
        pool = dask_pool.DaskPool(address, "quilt")  # waits the usual time for the worker to join
        monkeypatch.setattr(dask_pool, "WORKER_TIMEOUT", 2.0)  # the wait for a worker once it is lost
        try:
            future = pool.client.submit(sum, [1, 2], pure=False)
            distributed.wait([future])
            os.killpg(worker.pid, signal.SIGKILL)
            worker.wait()
            raised: list[BaseException] = []

            def fetch():
                try:
                    pool.outcome(future)
                except BaseException as e:  # noqa: BLE001 - handed to the test's thread
                    raised.append(e)

            fetcher = threading.Thread(target=fetch, daemon=True)
            fetcher.start()
            fetcher.join(120)  # a bound on a regression (it would wait forever), not a timing
            assert not fetcher.is_alive(), "fetching a lost result waited for a worker forever"
            assert len(raised) == 1 and isinstance(raised[0], WeftError), raised
            assert str(raised[0]) == f"the Dask scheduler at {address} had no workers left for 2 s"
        finally:
            pool.close()
