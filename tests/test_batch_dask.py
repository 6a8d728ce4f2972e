"""`weft batch` on a real Dask cluster: a LocalCluster of two worker processes on loopback.

The same items as the local pool, the same bytes; a worker killed mid-batch loses no item.
"""

from __future__ import annotations

import json
import os
import signal
import threading

import pytest

distributed = pytest.importorskip("distributed")

from weft.app.cli import main  # noqa: E402
from weft.core import batch  # noqa: E402
from weft.core.image import load_image, read_recipe  # noqa: E402

from .test_batch import make_frames, scene, slow_scene  # noqa: E402,F401  (fixtures)


@pytest.fixture(scope="module")
def cluster():
    with distributed.LocalCluster(
        processes=True, n_workers=2, threads_per_worker=1, host="127.0.0.1", dashboard_address=None, silence_logs=50
    ) as c:
        yield c


@pytest.mark.slow
def test_dask_gives_the_local_pools_bytes(scene, cluster, capsys, monkeypatch):
    tmp, frames = scene
    base = ["batch", str(tmp / "look.json"), "--over", "target", str(tmp / "frames")]
    assert main([*base, "-o", str(tmp / "local" / "{stem}.png")]) == 0
    # The address from the environment, as a user of a cluster would set it once.
    monkeypatch.setenv("DASK_SCHEDULER_ADDRESS", cluster.scheduler_address)
    assert main([*base, "-o", str(tmp / "dask" / "{stem}.png"), "--report"]) == 0
    out, err = capsys.readouterr()
    lines = [json.loads(line) for line in out.splitlines()]
    assert lines[-1]["written"] == 5 and err.strip().endswith("5 written")
    workers = {d["worker"] for d in lines[:-1]}
    with distributed.Client(cluster.scheduler_address) as client:
        pids = set(client.run(os.getpid).values())
    assert {int(w.rsplit(":", 1)[1]) for w in workers} <= pids  # run by the cluster's processes
    # Shipped inputs and outputs too (workers that share no folder with the client).
    assert (
        main(
            [
                *base,
                "-o",
                str(tmp / "shipped" / "{stem}.png"),
                "--scheduler",
                cluster.scheduler_address,
                "--ship-inputs",
                "--ship-outputs",
            ]
        )
        == 0
    )
    for f in frames:
        local = (tmp / "local" / f.name).read_bytes()
        assert (tmp / "dask" / f.name).read_bytes() == local
        assert (tmp / "shipped" / f.name).read_bytes() == local


@pytest.mark.slow
def test_a_bad_frame_fails_alone_on_dask(scene, cluster, capsys):
    tmp, frames = scene
    frames[0].write_bytes(frames[0].read_bytes()[:100])
    code = main(
        [
            "batch",
            str(tmp / "look.json"),
            "--over",
            "target",
            str(tmp / "frames"),
            "-o",
            str(tmp / "o" / "{stem}.png"),
            "--scheduler",
            cluster.scheduler_address,
        ]
    )
    err = capsys.readouterr().err
    assert code == 1
    assert err.strip().splitlines()[-1].startswith("4 written, 1 failed: frame_1.png: truncated or corrupt PNG data")


def test_workers_without_scheduler_is_a_usage_error(scene, capsys):
    tmp, _ = scene
    code = main(
        [
            "batch",
            str(tmp / "look.json"),
            "--over",
            "target",
            str(tmp / "frames"),
            "-o",
            str(tmp / "o" / "{stem}.png"),
            "--scheduler",
            "tcp://127.0.0.1:1",
            "--workers",
            "2",
        ]
    )
    assert code == 2 and "--workers sets local processes" in capsys.readouterr().err


def test_an_unreachable_scheduler_is_one_line(scene, capsys, monkeypatch):
    tmp, _ = scene
    monkeypatch.setattr("weft.core.batch.dask_pool.CONNECT_TIMEOUT", "1s")
    code = main(
        [
            "batch",
            str(tmp / "look.json"),
            "--over",
            "target",
            str(tmp / "frames"),
            "-o",
            str(tmp / "o" / "{stem}.png"),
            "--scheduler",
            "tcp://127.0.0.1:9",
        ]
    )
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("weft: cannot reach the Dask scheduler at tcp://127.0.0.1:9")
    assert len(err.strip().splitlines()) == 1


@pytest.fixture
def client(cluster):
    with distributed.Client(cluster.scheduler_address) as c:
        yield c


@pytest.mark.slow
def test_a_worker_killed_mid_batch_loses_no_item(slow_scene, cluster, client):
    tmp, frames = slow_scene
    p = batch.plan(str(tmp / "look.json"), [("target", str(tmp / "frames"))], str(tmp / "o" / "{stem}.png"))
    first_done = threading.Event()
    resume = threading.Event()
    killed = {}

    def on_outcome(o):  # the client's loop waits here after the first item, until the kill is done
        first_done.set()
        resume.wait(60)

    box = {}
    thread = threading.Thread(
        target=lambda: box.update(summary=batch.run(p, scheduler=cluster.scheduler_address, on_outcome=on_outcome))
    )
    thread.start()
    try:
        assert first_done.wait(120)
        # A worker with items of the batch on it, killed without warning: preferably one running or
        # queued, else one holding a finished item the client has not collected yet (the client
        # waits here, so the other items in flight are still on the workers, in one state or the other).
        ours = lambda keys: [k for k in keys if str(k).startswith("weft-item-")]  # noqa: E731
        processing = {a: ours(k) for a, k in client.processing().items() if ours(k)}
        held = {a: ours(k) for a, k in client.has_what().items() if ours(k)}
        assert processing or held, "the kill must land mid-batch"
        addr = sorted(processing or held)[0]
        pid = client.run(os.getpid, workers=[addr])[addr]
        killed.update(addr=addr, pid=pid, items=len((processing or held)[addr]), running=bool(processing))
        os.kill(pid, signal.SIGKILL)
    finally:
        resume.set()
        thread.join(180)
    assert not thread.is_alive()
    summary = box["summary"]
    assert summary.written == 8 and not summary.failed, summary.line()
    assert killed["items"] >= 1
    assert addr not in client.scheduler_info()["workers"]  # that worker is gone; its items ran elsewhere
    for f in frames:
        out = tmp / "o" / f.name
        assert load_image(out).image.shape[:2] == (96, 96)
        assert json.loads(read_recipe(out))["inputs"]["target"] == f"../frames/{f.name}"
    # Identical to the local pool's outputs.
    assert (
        batch.run(
            batch.plan(str(tmp / "look.json"), [("target", str(tmp / "frames"))], str(tmp / "ref" / "{stem}.png")),
            workers=1,
        ).written
        == 8
    )
    for f in frames:
        assert (tmp / "o" / f.name).read_bytes() == (tmp / "ref" / f.name).read_bytes()
