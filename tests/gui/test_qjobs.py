"""The Qt adapter over core.jobs (QtJobs): results, progress and completions arrive on the GUI thread;
a job superseded in its slot delivers no result but still says it finished."""

import threading

from weft.app.gui.qjobs import QtJobs
from weft.core.jobs import Progress

from .helpers import no_job_threads


def test_results_and_progress_arrive_on_the_gui_thread_and_the_latest_wins(qtbot):
    jobs = QtJobs(max_workers=2, progress=True)
    results, progress, finished, threads = [], [], [], []
    jobs.result.connect(lambda r: (results.append(r), threads.append(threading.current_thread())))
    jobs.progressed.connect(lambda jid, slot, p: progress.append((jid, slot, p.done)))
    jobs.finished.connect(lambda jid, slot: finished.append((jid, slot)))
    release = threading.Event()

    def held(*, progress=None, cancel=None):
        assert release.wait(10)
        cancel.raise_if_cancelled()
        return "stale"

    def work(*, progress=None, cancel=None):
        progress(Progress("work", 1, 2))
        return "latest"

    first = jobs.submit("render", held)
    second = jobs.submit("render", work)  # cancels the first
    qtbot.waitUntil(lambda: (second.id, "render") in finished, timeout=10000)
    release.set()
    qtbot.waitUntil(lambda: (first.id, "render") in finished, timeout=10000)
    assert [(r.job_id, r.value) for r in results] == [(second.id, "latest")]
    assert progress == [(second.id, "render", 1)]
    assert threads == [threading.main_thread()]
    assert first.result().cancelled
    jobs.shutdown()
    assert no_job_threads()


def test_an_error_is_a_result_with_its_exception(qtbot):
    jobs = QtJobs()

    def failing(*, progress=None, cancel=None):
        raise ValueError("broken on purpose")

    with qtbot.waitSignal(jobs.result, timeout=10000) as got:
        jobs.submit("x", failing)
    assert str(got.args[0].error) == "broken on purpose" and got.args[0].value is None
    jobs.shutdown()


def test_a_job_that_ends_after_its_window_is_gone_tells_nobody_and_fails_nothing(qtbot, caplog):
    import shiboken6

    jobs = QtJobs()
    runner = jobs.runner
    release = threading.Event()

    def held(*, progress=None, cancel=None):
        assert release.wait(10)
        return "late"

    job = jobs.submit("x", held)
    shiboken6.delete(jobs)  # the dialog that owned it was closed and deleted
    release.set()
    assert job.result(timeout=10).value == "late"
    assert "callback failed" not in caplog.text
    runner.shutdown()
