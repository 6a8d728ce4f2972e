"""The studio's Renderer under 100 rapid parameter changes and cancels."""

import random

from .helpers import no_job_threads, settle


def test_rapid_changes_and_cancels_show_only_newer_results(window, qtbot):
    doc, renderer = window.doc, window.renderer
    assert doc.method == "fast"
    shown_ids, view_followed = [], []

    def on_shown(shown):  # connected after the window's own slot: the view has been updated
        shown_ids.append(shown.job_id)
        view_followed.append(window.result_view.image is shown.image)

    renderer.shown.connect(on_shown)
    rng = random.Random(8)
    for i in range(100):
        doc.set_param("p", round(rng.random(), 3))
        r = rng.random()
        if r < 0.5:
            renderer.preview()
        elif r < 0.8:
            renderer.final(now=rng.random() < 0.5)
        else:
            renderer.cancel()
        if i % 10 == 0:
            qtbot.wait(rng.randint(0, 20))
    renderer.final(now=True)
    last_final = renderer.latest_final
    qtbot.waitUntil(lambda: renderer.last is not None and renderer.last.job_id == last_final, timeout=30000)
    settle(qtbot, window)  # any straggler has arrived
    assert shown_ids == sorted(shown_ids), shown_ids
    assert all(view_followed)
    assert renderer.last.job_id == last_final and renderer.last.final
    assert window.result_view.image is renderer.last.image
    window.close()
    assert no_job_threads()
