"""JobRunner under 500 random submit/cancel/shutdown sequences.

No deadlock (every wait has a timeout), no 'weft-job' thread left after shutdown, the last result
delivered per slot is the newest job of the slot that was not cancelled, and memory returns near
its baseline.
"""

from __future__ import annotations

import random
import threading
import time
import tracemalloc

import numpy as np
from weft.core.jobs import JobRunner

HANG = 10.0  # seconds: far beyond any sequence here; only a deadlock reaches it
SLOTS = ("preview", "final", "other")


def _job(kind: str, pause: float, *, progress=None, cancel=None):
    """Short jobs of four kinds: cooperative, raising, ignoring cancel, instant."""
    if kind == "raise":
        raise ValueError("job failed on purpose")
    steps = 3
    for _ in range(steps):
        time.sleep(pause / steps)
        if kind == "cooperative":
            cancel.raise_if_cancelled()
    return np.ones(2048, np.float32)  # 8 KB per result: a leak of results shows in tracemalloc


def _job_threads() -> set[threading.Thread]:
    return {t for t in threading.enumerate() if t.name.startswith("weft-job") and t.is_alive()}


def _sequence(rng: random.Random) -> None:
    delivered: dict[str, list[int]] = {s: [] for s in SLOTS}
    lock = threading.Lock()

    def on_result(result):
        with lock:
            delivered[result.slot].append(result.job_id)

    runner = JobRunner(max_workers=rng.randint(1, 3), on_result=on_result)
    jobs = []
    for _ in range(rng.randint(1, 12)):
        op = rng.random()
        if op < 0.7:
            kind = rng.choice(["cooperative", "raise", "ignore", "instant"])
            jobs.append(
                runner.submit(rng.choice(SLOTS), _job, kind, 0.0 if kind == "instant" else rng.uniform(0, 0.003))
            )
        elif op < 0.85:
            runner.cancel(rng.choice(SLOTS))
        elif op < 0.9:
            runner.cancel()
        else:
            time.sleep(rng.uniform(0, 0.002))
    # shutdown (which joins the workers) on a helper thread: a deadlock fails, it does not hang
    stopper = threading.Thread(target=runner.shutdown, kwargs={"wait": True, "cancel": rng.random() < 0.5})
    stopper.start()
    stopper.join(HANG)
    assert not stopper.is_alive(), "JobRunner.shutdown deadlocked"

    results = {job.id: job.result(timeout=HANG) for job in jobs}  # every future resolves
    for slot in SLOTS:
        ids = delivered[slot]
        assert ids == sorted(ids), f"slot {slot}: results delivered out of order {ids}"
        not_cancelled = [jid for jid, r in results.items() if r.slot == slot and not r.cancelled]
        assert set(ids) == set(not_cancelled)
        if not_cancelled:
            assert ids[-1] == max(not_cancelled)
            # nothing newer than the shown result completed without being cancelled
            newer = [j for j in jobs if j.slot == slot and j.id > ids[-1]]
            assert all(results[j.id].cancelled for j in newer)
    assert runner.busy() is False


def test_random_submit_cancel_shutdown_sequences():
    rng = random.Random(8)
    before = _job_threads()
    for _ in range(50):  # warm up: imports, caches, the executor's first threads
        _sequence(rng)
    tracemalloc.start()
    try:
        baseline = tracemalloc.get_traced_memory()[0]
        for _ in range(450):
            _sequence(rng)
        grown = tracemalloc.get_traced_memory()[0] - baseline
    finally:
        tracemalloc.stop()
    assert grown < 2_000_000, f"{grown} bytes still allocated after 450 sequences"
    deadline = time.monotonic() + HANG
    while _job_threads() - before and time.monotonic() < deadline:
        time.sleep(0.01)
    assert not (_job_threads() - before), "worker threads left after shutdown"


def test_cancel_from_callbacks_does_not_deadlock():
    """Callbacks may submit and cancel (they run without the runner's lock)."""
    seen = []

    def on_result(result):
        seen.append(result.job_id)
        if len(seen) < 50:
            runner.submit(result.slot, _job, "instant", 0.0)
        runner.cancel("other")

    runner = JobRunner(max_workers=2, on_result=on_result)
    runner.submit("final", _job, "instant", 0.0)
    deadline = time.monotonic() + HANG
    while len(seen) < 50 and time.monotonic() < deadline:
        time.sleep(0.005)
    stopper = threading.Thread(target=runner.shutdown)
    stopper.start()
    stopper.join(HANG)
    assert not stopper.is_alive()
    assert len(seen) >= 50 and seen == sorted(seen)
