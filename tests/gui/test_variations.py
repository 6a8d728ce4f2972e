"""The variations grid builds its thumbnail inputs on a worker, once per grid, and only then runs its cells."""

import threading

import numpy as np
import pytest
import weft.core.jobs as jobs_module
import weft.core.request as core_request
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QApplication
from weft.app.gui.document import Document, DocumentState
from weft.app.gui.render_job import render_request
from weft.app.gui.variations import THUMB_SIDE
from weft.core.errors import WeftError

from .helpers import no_job_threads


def _dialog(window, p=(0.0, 0.5), w=(0.0, 4.0)):
    window.open_variations()
    dialog = window.variations
    dialog.combo[0].setCurrentText("p")
    dialog.combo[1].setCurrentText("target_weight")
    _ranges(dialog, p, w)
    return dialog


def _ranges(dialog, p, w):
    dialog.lo[0].setValue(p[0])
    dialog.hi[0].setValue(p[1])
    dialog.lo[1].setValue(w[0])
    dialog.hi[1].setValue(w[1])


def _click(qtbot, dialog):
    qtbot.mouseClick(dialog.render_button, Qt.MouseButton.LeftButton)


def _submits(dialog, monkeypatch) -> list:
    """Every job the dialog hands to its workers, in order (their handles)."""
    jobs = []
    real = dialog.runner.submit

    def submit(slot, fn, *args, **kwargs):
        jobs.append(real(slot, fn, *args, **kwargs))
        return jobs[-1]

    monkeypatch.setattr(dialog.runner, "submit", submit)
    return jobs


@pytest.fixture
def held_preparation(monkeypatch):
    """The first thumbnail reduction waits (on its worker) until ``release`` is set; later ones run."""
    started, release, calls = threading.Event(), threading.Event(), []
    real = core_request.reduce_for_preview

    def held(*args, **kwargs):
        calls.append(args[3])
        if len(calls) == 1:
            started.set()
            assert release.wait(30)
        return real(*args, **kwargs)

    monkeypatch.setattr(core_request, "reduce_for_preview", held)
    yield started, release, calls
    release.set()


def test_the_grids_inputs_are_built_once_on_a_worker_not_the_gui_thread(window, qtbot, monkeypatch):
    on_gui: dict[str, list[bool]] = {"inputs": [], "reduce_for_preview": []}
    real_deferred, real_reduce = Document.deferred_inputs, core_request.reduce_for_preview

    def deferred(self, *args, **kwargs):
        build = real_deferred(self, *args, **kwargs)

        def recorded(*a, **k):
            on_gui["inputs"].append(threading.current_thread() is threading.main_thread())
            return build(*a, **k)

        return recorded

    def reduce(*args, **kwargs):
        on_gui["reduce_for_preview"].append(threading.current_thread() is threading.main_thread())
        assert args[3] == THUMB_SIDE
        return real_reduce(*args, **kwargs)

    monkeypatch.setattr(Document, "deferred_inputs", deferred)
    monkeypatch.setattr(core_request, "reduce_for_preview", reduce)
    dialog = _dialog(window)
    done = set()
    dialog.cell_done.connect(lambda i, j: done.add((i, j)))
    _click(qtbot, dialog)
    assert dialog.status.text() == "rendering…"
    qtbot.waitUntil(lambda: len(done) == 9, timeout=30000)
    assert on_gui == {"inputs": [False], "reduce_for_preview": [False]}  # once per grid, on a worker
    assert all(not b.icon().isNull() for b in dialog.cells.values())
    assert dialog.status.text() == "click a cell to adopt its values"
    dialog.close()


def test_a_second_render_during_the_preparation_cancels_the_first_grid(window, qtbot, monkeypatch, held_preparation):
    started, release, calls = held_preparation
    dialog = _dialog(window)
    jobs = _submits(dialog, monkeypatch)
    done = set()
    dialog.cell_done.connect(lambda i, j: done.add((i, j)))
    _click(qtbot, dialog)
    qtbot.waitUntil(started.is_set, timeout=10000)
    first = jobs[-1]
    assert first.slot == "prepare" and not first.done()
    _ranges(dialog, (0.1, 0.3), (1.0, 3.0))
    _click(qtbot, dialog)  # the first preparation is still running (held)
    assert first.token.cancelled
    qtbot.waitUntil(lambda: len(done) == 9, timeout=30000)
    release.set()
    qtbot.waitUntil(first.done, timeout=10000)
    QApplication.processEvents()  # (anything the first preparation delivered is handled by now)
    assert first.result().cancelled
    assert [j.slot for j in jobs].count("prepare") == 2 and len(calls) == 2
    cells = [j for j in jobs if j.slot.startswith("cell-")]
    assert len(cells) == 9 and all(j.id > jobs[1].id for j in cells)  # only the second grid's cells ran
    assert {v for (_, v), _ in dialog.values.values()} == {0.1, 0.2, 0.3}
    assert dialog.cells[(0, 0)].text() == "p=0.1  target_weight=1.0"
    # the cell shows the second grid's values' pixels
    prepared = render_request(window.doc, core_request.Preview(THUMB_SIDE)).prepared()
    inputs, base = prepared.images, prepared.params
    expected = window.doc.current.run(inputs, base.replace(p=0.1, target_weight=1.0), rng=window.doc.seed).image
    assert np.array_equal(dialog.images[(0, 0)], expected)
    assert dialog.status.text() == "click a cell to adopt its values"
    dialog.close()


def test_a_failing_preparation_says_why_and_the_dialog_keeps_working(window, qtbot, monkeypatch):
    real = core_request.reduce_for_preview

    def failing(*args, **kwargs):
        raise WeftError("target: cannot be reduced\n(broken on purpose)")

    monkeypatch.setattr(core_request, "reduce_for_preview", failing)
    dialog = _dialog(window)
    jobs = _submits(dialog, monkeypatch)
    _click(qtbot, dialog)
    expected = "could not prepare the grid: target: cannot be reduced (broken on purpose)"
    qtbot.waitUntil(lambda: dialog.status.text() == expected, timeout=10000)
    assert [j.slot for j in jobs] == ["prepare"]  # no cell ran
    assert all(b.icon().isNull() for b in dialog.cells.values()) and not dialog.export_button.isEnabled()
    monkeypatch.setattr(core_request, "reduce_for_preview", real)
    done = set()
    dialog.cell_done.connect(lambda i, j: done.add((i, j)))
    _click(qtbot, dialog)
    qtbot.waitUntil(lambda: len(done) == 9, timeout=30000)
    assert dialog.isVisible() and dialog.export_button.isEnabled()
    assert dialog.status.text() == "click a cell to adopt its values"
    dialog.cells[(2, 1)].click()
    assert window.doc.current_params.p == 0.5 and window.doc.current_params.target_weight == 2.0
    dialog.close()


def test_closing_during_the_preparation_cancels_it_and_starts_no_cell(window, qtbot, monkeypatch, held_preparation):
    started, release, _ = held_preparation
    dialog = _dialog(window)
    jobs = _submits(dialog, monkeypatch)
    _click(qtbot, dialog)
    qtbot.waitUntil(started.is_set, timeout=10000)
    # the close waits for the running preparation (it cannot be interrupted inside the reduction):
    # the held reduction goes on once the close has cancelled its job, not after a guessed delay
    real_cancel = jobs_module.Job.cancel

    def cancel_then_release(job):
        real_cancel(job)
        release.set()

    monkeypatch.setattr(jobs_module.Job, "cancel", cancel_then_release)
    dialog.close()
    assert jobs[0].done() and jobs[0].result().cancelled
    QApplication.processEvents()
    assert [j.slot for j in jobs] == ["prepare"]
    window.shutdown()
    assert no_job_threads()


def test_missing_inputs_are_said_at_once_and_nothing_is_prepared(window, qtbot, monkeypatch):
    dialog = _dialog(window)
    jobs = _submits(dialog, monkeypatch)
    window.doc.restore(DocumentState(inputs={}, method="fast"))
    _click(qtbot, dialog)
    assert dialog.status.text() == "open the method's inputs first" and jobs == []
    dialog.close()


def test_a_late_result_of_an_earlier_grid_is_dropped(window, qtbot, monkeypatch):
    """What the workers delivered for a grid that a new Render grid replaced (queued to the GUI
    thread before the replacement) neither starts cells nor lands on the new grid's cells."""
    from weft.core.jobs import JobResult

    dialog = _dialog(window)
    jobs = _submits(dialog, monkeypatch)
    done = set()
    dialog.cell_done.connect(lambda i, j: done.add((i, j)))
    _click(qtbot, dialog)
    qtbot.waitUntil(lambda: len(done) == 9, timeout=30000)
    old_prepare, old_cell = jobs[0], next(j for j in jobs if j.slot == "cell-0-0")
    prepared = old_prepare.result().value
    _ranges(dialog, (0.1, 0.3), (1.0, 3.0))
    done.clear()
    _click(qtbot, dialog)
    qtbot.waitUntil(lambda: len(done) == 9, timeout=30000)
    shown = dialog.images[(0, 0)]
    count = len(jobs)
    dialog.runner.result.emit(JobResult(old_prepare.id, "prepare", prepared))
    dialog.runner.result.emit(JobResult(old_cell.id, "cell-0-0", np.zeros_like(shown)))
    QApplication.processEvents()
    assert len(jobs) == count and dialog.images[(0, 0)] is shown
    dialog.close()


def test_a_preparation_that_arrives_as_the_dialog_closes_starts_nothing(window, qtbot, monkeypatch):
    dialog = _dialog(window)
    jobs = _submits(dialog, monkeypatch)
    _click(qtbot, dialog)
    assert jobs[0].result(timeout=30).ok  # done and delivered, its signal not yet handled
    dialog.close()
    QApplication.processEvents()  # (a cell submitted to the closed runner would raise here)
    assert [j.slot for j in jobs] == ["prepare"] and dialog.images == {}


def test_variations_offers_only_parameters_that_matter_and_labels_its_export(window, qtbot, tmp_path):
    """nfpt with the homography warp: a, b and p change nothing (nine identical cells), so they are
    not offered; switching to a line-based warp offers them. The exported grid names the two
    parameters and every row's and column's value (the margins hold text)."""
    import json

    from weft.core.examples import RESOURCES
    from weft.core.image import load_image

    from .helpers import mouse

    doc = window.doc
    doc.set_method("nfpt")
    assert doc.current_params.warp == "homography"
    window.open_variations()
    dialog = window.variations
    offered = [dialog.combo[0].itemText(k) for k in range(dialog.combo[0].count())]
    assert offered and not {"a", "b", "p"} & set(offered)
    dialog.close()
    doc.set_param("warp", "morph")
    window.open_variations()
    dialog = window.variations
    offered = [dialog.combo[0].itemText(k) for k in range(dialog.combo[0].count())]
    assert {"a", "b", "p"} <= set(offered)
    dialog.close()
    # a grid of a method with lines drawn, exported: labelled
    data = json.loads((RESOURCES / "perspective-lines.json").read_text())
    doc.set_param("warp", "homography")
    doc.set_param("size", (96, 64))
    window.inputs_pane.lines_panel.quad_button.setChecked(True)
    for x, y in [line[:2] for line in data["image_lines"][:4]]:
        mouse(window.inputs_pane.canvas_view, "press", (x, y))
        mouse(window.inputs_pane.canvas_view, "release", (x, y))
    window.open_variations()
    dialog = window.variations
    dialog.combo[0].setCurrentText("tol")
    dialog.combo[1].setCurrentText("sigma_s")
    done = set()
    dialog.cell_done.connect(lambda i, j: done.add((i, j)))
    qtbot.mouseClick(dialog.render_button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: len(done) == 9, timeout=120000)
    out = tmp_path / "grid.png"
    assert dialog.export_grid(str(out))
    grid = load_image(out).image
    cells = [im for im in dialog.images.values()]
    h, w = cells[0].shape[:2]
    assert grid.shape[0] > 3 * h + 8 and grid.shape[1] > 3 * w + 8  # room for the labels
    margin_top = grid[: grid.shape[0] - (3 * h + 8), -(3 * w + 8) :]
    margin_left = grid[-(3 * h + 8) :, : grid.shape[1] - (3 * w + 8)]
    for margin in (margin_top, margin_left):
        assert (margin.max(axis=2) > 0.6).sum() > 30  # light text on the dark margin
    dialog.close()


def test_variations_ranges_stay_within_what_the_inputs_allow(window, qtbot, tmp_path):
    """Quilt on a 112x128 texture: the grid's block range ends at 112 (it offered 56..168)."""
    from weft.core.image import save_image

    doc = window.doc
    texture = tmp_path / "small.png"
    save_image(texture, np.random.default_rng(3).random((128, 112, 3), dtype=np.float32))
    doc.set_method("quilt")
    doc.clear_input("target")
    window.open_input("texture", str(texture))
    qtbot.waitUntil(
        lambda: doc.image("texture") is not None and doc.image("texture").shape[:2] == (128, 112), timeout=10000
    )
    doc.set_param("block", 112)
    window.open_variations()
    dialog = window.variations
    dialog.combo[0].setCurrentText("block")
    assert dialog.hi[0].maximum() == 112 and dialog.hi[0].value() <= 112
    dialog.close()


def test_an_odd_only_parameters_grid_has_odd_values(window, qtbot):
    """fast's n must be odd: the grid's range and its values keep to odd sides (it offered even ones,
    each cell then refused)."""
    from weft.app.gui.variations import grid_values
    from weft.core.params import specs

    window.open_variations()
    dialog = window.variations
    dialog.combo[0].setCurrentText("n")
    lo, hi = dialog.lo[0].value(), dialog.hi[0].value()
    assert lo % 2 == 1 and hi % 2 == 1, (lo, hi)
    spec = next(s for s in specs(type(window.doc.current_params)) if s.name == "n")
    assert grid_values(spec, 3, 15, 5) == [3, 7, 9, 13, 15]
    assert grid_values(spec, lo, hi, 5) and all(v % 2 == 1 for v in grid_values(spec, lo, hi, 5))
    dialog.close()
