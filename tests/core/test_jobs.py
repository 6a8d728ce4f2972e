"""Behaviour of weft.core.jobs: results, errors, cancellation, latest-wins slots, progress, shutdown.

No timing assertions: threads are orchestrated with ``threading.Event``; timeouts are hang guards.
"""

from __future__ import annotations

import dataclasses
import logging
import random
import threading
import time
from collections import defaultdict

import numpy as np
import pytest
import weft.core.errors
from weft.core.errors import WeftError
from weft.core.jobs import Cancelled, CancelToken, JobResult, JobRunner, Progress, ProgressReporter

WAIT = 20.0  # hang guard only, never a timing assertion


class Recorder:
    """Thread-safe collector of on_result / on_progress calls."""

    def __init__(self):
        self.lock = threading.Lock()
        self.results: list[JobResult] = []
        self.progress: list[tuple[int, str, Progress]] = []

    def on_result(self, result):
        with self.lock:
            self.results.append(result)

    def on_progress(self, job_id, slot, progress):
        with self.lock:
            self.progress.append((job_id, slot, progress))


@pytest.fixture
def make_runner():
    runners = []

    def make(max_workers=2, **kwargs):
        runner = JobRunner(max_workers, **kwargs)
        runners.append(runner)
        return runner

    yield make
    for runner in runners:
        runner.shutdown(wait=True, cancel=True)


@pytest.fixture
def rec():
    return Recorder()


def wait_for(event: threading.Event):
    assert event.wait(WAIT), "hang guard: event never set"


def spin_until_cancelled(started=None):
    """A job that checks its token in a loop, like an algorithm's row loop."""

    def fn(*, progress, cancel):
        if started is not None:
            started.set()
        deadline = time.monotonic() + WAIT
        while time.monotonic() < deadline:
            cancel.raise_if_cancelled()
            time.sleep(0.001)
        return "never cancelled"

    return fn


def blocked_until(release, started=None, value="old"):
    """A job that ignores cancellation and finishes only when ``release`` is set."""

    def fn(*, progress, cancel):
        if started is not None:
            started.set()
        wait_for(release)
        return value

    return fn


def returns(value):
    def fn(*, progress, cancel):
        return value

    return fn


# -- small types ---------------------------------------------------------------------------------


def test_cancelled_is_reexported_from_errors():
    assert Cancelled is weft.core.errors.Cancelled


def test_progress_fraction():
    assert Progress("s", 5, 10).fraction == 0.5
    assert Progress("s", 10, 10).fraction == 1.0
    assert Progress("s", 3, 0).fraction == 0.0
    assert Progress("s", 3, -1).fraction == 0.0
    assert Progress("s", 0, 10).preview is None


def test_cancel_token():
    token = CancelToken()
    assert not token.cancelled
    token.raise_if_cancelled()
    token.cancel()
    token.cancel()
    assert token.cancelled
    with pytest.raises(Cancelled):
        token.raise_if_cancelled()


def test_job_result_ok_and_frozen():
    assert JobResult(1, "a", value=3).ok
    assert not JobResult(1, "a", error=ValueError("x")).ok
    assert not JobResult(1, "a", cancelled=True).ok
    with pytest.raises(dataclasses.FrozenInstanceError):
        JobResult(1, "a").value = 2


# -- ProgressReporter ----------------------------------------------------------------------------


def test_reporter_reports_only_on_percentage_change():
    calls = []
    previews = []

    def make_preview():
        previews.append(1)
        return np.zeros((2, 2), np.float32)

    reporter = ProgressReporter(calls.append, "rows", 1000)
    for done in range(1001):
        reporter.update(done, preview=make_preview)
    assert 1 < len(calls) <= 101
    assert len(previews) == len(calls)  # the preview is built only when reported
    assert all(isinstance(p.preview, np.ndarray) for p in calls)
    assert [p.done for p in calls] == sorted(p.done for p in calls)
    assert len({100 * p.done // p.total for p in calls}) == len(calls)  # one per percent
    assert calls[-1] == Progress("rows", 1000, 1000, calls[-1].preview)
    assert all(p.stage == "rows" and p.total == 1000 for p in calls)


def test_reporter_small_total_and_final_always_reported():
    calls = []
    reporter = ProgressReporter(calls.append, "s", 3)
    for done in (1, 2, 3, 3):
        reporter(done)
    assert [p.done for p in calls] == [1, 2, 3, 3]


def test_reporter_skips_previews_for_callbacks_that_do_not_want_them():
    class Bar:
        wants_preview = False

        def __init__(self):
            self.calls = []

        def __call__(self, p):
            self.calls.append(p)

    bar, built = Bar(), []
    reporter = ProgressReporter(bar, "rows", 4)
    for done in range(1, 5):
        reporter.update(done, preview=lambda: built.append(1) or np.zeros(2))
    assert len(bar.calls) == 4 and built == []
    assert all(p.preview is None for p in bar.calls)


def test_reporter_passes_array_preview_through():
    calls = []
    image = np.ones((3, 3), np.float32)
    ProgressReporter(calls.append, "s", 10).update(5, preview=image)
    assert calls[0].preview is image


def test_reporter_without_callback_is_noop():
    built = []
    reporter = ProgressReporter(None, "s", 100)
    for done in range(101):
        assert reporter.update(done, preview=lambda: built.append(1)) is False
    assert built == []


# -- JobRunner: results, errors ------------------------------------------------------------------


def test_job_returns_value(make_runner, rec):
    runner = make_runner(on_result=rec.on_result)

    def double(x, *, factor, progress, cancel):
        assert isinstance(cancel, CancelToken)
        return x * factor

    job = runner.submit("preview", double, 21, factor=2)
    result = job.result(WAIT)
    assert result.ok and result.value == 42 and result.error is None and not result.cancelled
    assert result.job_id == job.id and result.slot == "preview" and result.seconds >= 0
    assert job.done()
    assert rec.results == [result]
    assert runner.latest("preview") is job
    assert not runner.busy()


def test_progress_is_none_without_on_progress(make_runner):
    runner = make_runner()
    seen = []
    job = runner.submit("s", lambda *, progress, cancel: seen.append(progress))
    job.result(WAIT)
    assert seen == [None]


def test_exception_reaches_caller(make_runner, rec):
    runner = make_runner(on_result=rec.on_result)
    error = WeftError("parameter 'block' = 0 is outside 2..512")

    def fail(*, progress, cancel):
        raise error

    job = runner.submit("final", fail)
    result = job.result(WAIT)
    assert result.error is error and not result.ok and not result.cancelled
    assert len(rec.results) == 1 and rec.results[0].error is error
    # the pool still works afterwards
    assert runner.submit("final", returns(1)).result(WAIT).value == 1


@pytest.mark.parametrize("how", ["job", "slot", "all"])
def test_cancel_mid_job(make_runner, rec, how):
    runner = make_runner(on_result=rec.on_result)
    started = threading.Event()
    job = runner.submit("preview", spin_until_cancelled(started))
    wait_for(started)
    assert runner.busy() and runner.busy("preview") and not runner.busy("final")
    {"job": job.cancel, "slot": lambda: runner.cancel("preview"), "all": runner.cancel}[how]()
    result = job.result(WAIT)
    assert result.cancelled and not result.ok and result.error is None and result.value is None
    assert rec.results == []
    assert not runner.busy()


def test_future_cannot_be_cancelled_directly(make_runner):
    runner = make_runner()
    release = threading.Event()
    job = runner.submit("s", blocked_until(release))
    assert job.future.cancel() is False
    release.set()
    assert job.result(WAIT).value == "old"


# -- latest wins per slot ------------------------------------------------------------------------


def test_new_submit_cancels_running_job_and_drops_stale_result(make_runner, rec):
    runner = make_runner(on_result=rec.on_result)
    started, release = threading.Event(), threading.Event()
    old = runner.submit("preview", blocked_until(release, started, "old"))
    wait_for(started)
    new = runner.submit("preview", returns("new"))
    assert old.token.cancelled and not new.token.cancelled
    assert new.result(WAIT).value == "new"
    release.set()  # the old job ignored cancellation and now finishes with a value
    stale = old.result(WAIT)
    assert stale.value == "old" and stale.cancelled
    assert [r.job_id for r in rec.results] == [new.id]
    assert runner.latest("preview") is new


def test_stale_job_finishing_first_is_dropped(make_runner, rec):
    runner = make_runner(on_result=rec.on_result)
    old_started, old_release = threading.Event(), threading.Event()
    new_started, new_release = threading.Event(), threading.Event()
    old = runner.submit("preview", blocked_until(old_release, old_started, "old"))
    wait_for(old_started)
    new = runner.submit("preview", blocked_until(new_release, new_started, "new"))
    wait_for(new_started)
    old_release.set()
    assert old.result(WAIT).cancelled
    assert rec.results == []
    new_release.set()
    assert new.result(WAIT).value == "new"
    assert [r.value for r in rec.results] == ["new"]


def test_different_slots_do_not_cancel_each_other(make_runner, rec):
    runner = make_runner(on_result=rec.on_result)
    started, release = threading.Event(), threading.Event()
    preview = runner.submit("preview", blocked_until(release, started, "p"))
    wait_for(started)
    final = runner.submit("final", returns("f"))
    assert final.result(WAIT).value == "f"
    assert not preview.token.cancelled
    release.set()
    assert preview.result(WAIT).ok
    assert sorted(r.value for r in rec.results) == ["f", "p"]


def test_superseded_queued_job_never_runs(make_runner, rec):
    runner = make_runner(max_workers=1, on_result=rec.on_result)
    started, release = threading.Event(), threading.Event()
    ran = []

    def record(name):
        def fn(*, progress, cancel):
            ran.append(name)
            return name

        return fn

    blocker = runner.submit("other", blocked_until(release, started, "blocker"))
    wait_for(started)
    queued = runner.submit("preview", record("queued"))
    explicitly_cancelled = runner.submit("final", record("final"))
    explicitly_cancelled.cancel()
    newest = runner.submit("preview", record("newest"))
    assert not queued.done()
    release.set()
    assert queued.result(WAIT).cancelled and queued.result().seconds == 0.0
    assert explicitly_cancelled.result(WAIT).cancelled
    assert newest.result(WAIT).value == "newest"
    assert blocker.result(WAIT).ok
    assert ran == ["newest"]
    assert sorted(r.value for r in rec.results) == ["blocker", "newest"]


def test_progress_of_stale_job_not_forwarded(make_runner, rec):
    runner = make_runner(on_result=rec.on_result, on_progress=rec.on_progress)
    started, release = threading.Event(), threading.Event()

    def old_fn(*, progress, cancel):
        progress(Progress("old", 1, 2))
        started.set()
        wait_for(release)
        progress(Progress("old", 2, 2))
        return "old"

    def new_fn(*, progress, cancel):
        reporter = ProgressReporter(progress, "new", 4)
        for done in range(1, 5):
            reporter.update(done)
        return "new"

    old = runner.submit("preview", old_fn)
    wait_for(started)
    new = runner.submit("preview", new_fn)
    new.result(WAIT)
    release.set()
    old.result(WAIT)
    assert [(i, s, p.stage, p.done) for i, s, p in rec.progress] == [
        (old.id, "preview", "old", 1),
        *[(new.id, "preview", "new", d) for d in range(1, 5)],
    ]


def test_on_progress_exception_does_not_fail_job(make_runner, caplog):
    def bad_progress(job_id, slot, progress):
        raise RuntimeError("progress handler broke")

    runner = make_runner(on_progress=bad_progress)

    def fn(*, progress, cancel):
        progress(Progress("s", 1, 1))
        return 5

    with caplog.at_level(logging.ERROR, logger="weft.core.jobs"):
        assert runner.submit("s", fn).result(WAIT).value == 5
    assert "on_progress" in caplog.text


def test_job_ids_increase_monotonically(make_runner):
    runner = make_runner(max_workers=3)
    jobs = [runner.submit(("a", "b", "c")[i % 3], returns(i)) for i in range(30)]
    ids = [job.id for job in jobs]
    assert ids == sorted(ids) and len(set(ids)) == len(ids)
    assert [job.result(WAIT).job_id for job in jobs] == ids


def test_ids_monotonic_from_many_threads(make_runner):
    runner = make_runner()
    ids, lock = [], threading.Lock()

    def submit_many():
        local = [runner.submit(f"s{threading.get_ident()}", returns(None)).id for _ in range(50)]
        assert local == sorted(local)
        with lock:
            ids.extend(local)

    threads = [threading.Thread(target=submit_many) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(WAIT)
    assert len(set(ids)) == len(ids) == 200


# -- callbacks misbehaving, re-entrancy ----------------------------------------------------------


def test_on_result_that_raises_does_not_break_later_jobs(make_runner, caplog):
    delivered = []

    def on_result(result):
        delivered.append(result.value)
        if result.value == "first":
            raise RuntimeError("handler broke")

    runner = make_runner(max_workers=1, on_result=on_result)
    with caplog.at_level(logging.ERROR, logger="weft.core.jobs"):
        first = runner.submit("a", returns("first")).result(WAIT)
        second = runner.submit("a", returns("second")).result(WAIT)
    assert first.ok and second.ok
    assert delivered == ["first", "second"]
    assert "handler broke" in caplog.text


def test_on_result_may_submit_again(make_runner):
    chained = threading.Event()
    results = []
    runner = None

    def on_result(result):
        results.append(result)
        if result.slot == "preview":
            runner.submit("preview-again", returns("chained"))
            runner.submit("final", returns("final"))
            runner.cancel("nothing-here")
        elif result.slot == "final":
            chained.set()

    runner = make_runner(max_workers=1, on_result=on_result)
    runner.submit("preview", returns("p"))
    wait_for(chained)
    runner.shutdown(wait=True, cancel=False)
    assert sorted(r.value for r in results) == ["chained", "final", "p"]


# -- shutdown ------------------------------------------------------------------------------------


def weft_threads():
    return [t for t in threading.enumerate() if t.name.startswith("weft-job") and t.is_alive()]


def shutdown_with_guard(runner, **kwargs):
    thread = threading.Thread(target=runner.shutdown, kwargs=kwargs)
    thread.start()
    thread.join(WAIT)
    assert not thread.is_alive(), "hang guard: shutdown deadlocked"


def test_shutdown_cancels_jobs_and_stops_threads(make_runner, rec):
    runner = make_runner(max_workers=2, on_result=rec.on_result)
    started = threading.Event()
    running = runner.submit("preview", spin_until_cancelled(started))
    wait_for(started)
    queued = [runner.submit(f"slot{i}", spin_until_cancelled()) for i in range(4)]
    assert weft_threads()
    shutdown_with_guard(runner)
    assert weft_threads() == []
    assert running.done() and running.result().cancelled
    assert all(job.done() and job.result().cancelled for job in queued)
    assert rec.results == []
    with pytest.raises(RuntimeError, match="JobRunner is shut down"):
        runner.submit("preview", returns(1))
    runner.shutdown()  # idempotent


def test_shutdown_without_cancel_finishes_jobs(make_runner, rec):
    runner = make_runner(max_workers=1, on_result=rec.on_result)
    jobs = [runner.submit(f"s{i}", returns(i)) for i in range(5)]
    shutdown_with_guard(runner, cancel=False)
    assert [job.result(0).value for job in jobs] == list(range(5))
    assert sorted(r.value for r in rec.results) == list(range(5))
    assert weft_threads() == []


def test_context_manager_shuts_down(rec):
    with JobRunner(on_result=rec.on_result) as runner:
        assert runner.submit("a", returns(3)).result(WAIT).value == 3
    assert weft_threads() == []
    with pytest.raises(RuntimeError, match="shut down"):
        runner.submit("a", returns(1))


# -- stress --------------------------------------------------------------------------------------


def test_stress_random_submit_and_cancel(make_runner):
    rng = random.Random(1234)
    slots = ("preview", "final", "thumb")
    delivered = defaultdict(list)
    lock = threading.Lock()

    def on_result(result):
        with lock:
            delivered[result.slot].append(result)

    def on_progress(job_id, slot, progress):
        assert 0.0 <= progress.fraction <= 1.0

    runner = make_runner(max_workers=2, on_result=on_result, on_progress=on_progress)
    sleeps = [0.0, 0.0002, 0.0005, 0.0]

    def work(kind, steps, *, progress, cancel):
        reporter = ProgressReporter(progress, kind, steps)
        for step in range(1, steps + 1):
            if kind != "stubborn":
                cancel.raise_if_cancelled()
            time.sleep(sleeps[step % len(sleeps)])
            reporter.update(step, preview=lambda: np.zeros((4, 4), np.float32))
        if kind == "fail":
            raise WeftError("boom")
        return kind, steps

    jobs = []
    for _ in range(200):
        op = rng.random()
        if op < 0.7 or not jobs:
            kind = rng.choice(["ok", "ok", "fail", "stubborn"])
            jobs.append(runner.submit(rng.choice(slots), work, kind, rng.randint(0, 20)))
        elif op < 0.8:
            runner.cancel(rng.choice(slots))
        elif op < 0.85:
            runner.cancel()
        else:
            rng.choice(jobs).cancel()
        if rng.random() < 0.1:
            time.sleep(0.001)

    shutdown_with_guard(runner, wait=True, cancel=False)
    assert weft_threads() == []
    assert all(job.done() for job in jobs)
    results = {job.id: job.result(0) for job in jobs}
    assert all(results[job.id].job_id == job.id and results[job.id].slot == job.slot for job in jobs)

    for slot in slots:
        slot_jobs = [job for job in jobs if job.slot == slot]
        got = [r.job_id for r in delivered[slot]]
        assert got == sorted(got) and len(set(got)) == len(got)  # never an older result after a newer
        live = [job.id for job in slot_jobs if not results[job.id].cancelled]
        assert got == live  # exactly the non-cancelled jobs were delivered
        if live:
            assert delivered[slot][-1] is results[live[-1]]
        if slot_jobs and not slot_jobs[-1].token.cancelled:
            assert got and got[-1] == slot_jobs[-1].id  # the slot's final job always arrives
    for job in jobs:
        r = results[job.id]
        if r.cancelled:
            assert job.token.cancelled
        elif r.error is not None:
            assert isinstance(r.error, WeftError)


def test_reporter_builds_previews_at_most_every_preview_interval(monkeypatch):
    import weft.core.jobs as jobs

    clock = [100.0]
    monkeypatch.setattr(jobs.time, "monotonic", lambda: clock[0])

    class Slow:
        preview_interval = 0.5

        def __init__(self):
            self.calls = []

        def __call__(self, p):
            self.calls.append(p)

    cb, built = Slow(), []
    reporter = ProgressReporter(cb, "rows", 10)
    for done in range(1, 11):
        clock[0] += 0.2  # 0.2 s per unit of work
        reporter.update(done, preview=lambda done=done: built.append(done) or np.zeros(1))
    assert len(cb.calls) == 10  # progress itself is not throttled
    # First preview only after 0.5 s (done = 3), then at most every 0.5 s.
    assert built == [3, 6, 9]
