"""File > Apply to Folder…: the studio's recipe over a folder, off the GUI thread, with Cancel."""

from __future__ import annotations

import json
import threading
from pathlib import Path

import pytest
from PySide6.QtCore import Qt
from PySide6.QtGui import QAction
from weft.app.cli import main as cli_main
from weft.app.gui.batch_dialog import BatchDialog
from weft.core.image import load_image, read_recipe, save_image

ROOT = Path(__file__).resolve().parents[2]


def make_frames(folder: Path, n: int) -> list[Path]:
    photo = load_image(ROOT / "resources" / "astronaut.png").image
    folder.mkdir(parents=True, exist_ok=True)
    out = []
    for i in range(n):
        p = folder / f"frame_{i:02d}.png"
        save_image(p, photo[4 * i : 4 * i + 60, 3 * i : 3 * i + 80])
        out.append(p)
    return out


def open_dialog(window, qtbot) -> BatchDialog:
    action = next(a for a in window.findChildren(QAction) if a.text() == "Apply to &Folder…")
    action.trigger()
    dialog = window.findChild(BatchDialog)
    assert dialog is not None and dialog.isVisible()
    return dialog


@pytest.mark.slow
def test_apply_to_folder_writes_what_weft_run_writes(window, qtbot, tmp_path):
    frames = make_frames(tmp_path / "frames", 4)
    seed = window.doc.seed
    dialog = open_dialog(window, qtbot)
    # The folder's images replace an input other than the source: the picture the look is applied to.
    assert dialog.over.currentData() == window.doc.current.inputs[1].name
    qtbot.keyClicks(dialog.folder, str(tmp_path / "frames"))
    with qtbot.waitSignal(dialog.batch_finished, timeout=120000) as done:
        qtbot.mouseClick(dialog.run_button, Qt.MouseButton.LeftButton)
        assert dialog.running and dialog.cancel_button.isEnabled() and not dialog.run_button.isEnabled()
        window.method_panel.new_seed()  # the studio stays usable; the running batch keeps the recipe it started with
    assert done.args == ["4 written", 0, False]
    assert dialog.status.text() == "4 written" and dialog.progress.value() == 4
    assert dialog.run_button.isEnabled() and not dialog.cancel_button.isEnabled()
    for f in frames:
        out = tmp_path / "frames" / "weft" / f.name
        recipe = json.loads(read_recipe(out))
        assert recipe["method"] == window.doc.method and recipe["seed"] == seed
        assert recipe["inputs"][dialog.over.currentData()] == f"../{f.name}"
        again = out.with_name("again.png")
        assert cli_main(["run", str(out), "-o", str(again)]) == 0
        assert again.read_bytes() == out.read_bytes()
        again.unlink()
    # Run again once the new seed's result is shown: its recipe has the new seed, so every frame is
    # redone with it...
    qtbot.waitUntil(
        lambda: window.renderer.last.final and window.renderer.last.recipe.seed == window.doc.seed, timeout=60000
    )
    with qtbot.waitSignal(dialog.batch_finished, timeout=120000) as done:
        qtbot.mouseClick(dialog.run_button, Qt.MouseButton.LeftButton)
    assert done.args[0] == "4 written" and window.doc.seed != seed
    assert json.loads(read_recipe(tmp_path / "frames" / "weft" / frames[0].name))["seed"] == window.doc.seed
    # ...and once more: everything is already done.
    with qtbot.waitSignal(dialog.batch_finished, timeout=120000) as done:
        qtbot.mouseClick(dialog.run_button, Qt.MouseButton.LeftButton)
    assert done.args[0] == "0 written, 4 already done"


@pytest.mark.slow
def test_cancel_stops_between_items_and_keeps_finished_ones(window, qtbot, tmp_path):
    make_frames(tmp_path / "frames", 12)
    dialog = open_dialog(window, qtbot)
    dialog.workers.setValue(1)
    counted = threading.Event()
    release = threading.Event()
    calls = []

    def hold_after_first_item(done, total, failed, left):  # runs on the batch thread (direct connection)
        calls.append(done)
        if done >= 1 and not counted.is_set():
            counted.set()
            release.wait(60)  # the batch waits here until the test has clicked Cancel

    dialog.progressed.connect(hold_after_first_item, Qt.ConnectionType.DirectConnection)
    qtbot.keyClicks(dialog.folder, str(tmp_path / "frames"))
    with qtbot.waitSignal(dialog.batch_finished, timeout=120000) as done:
        qtbot.mouseClick(dialog.run_button, Qt.MouseButton.LeftButton)
        qtbot.waitUntil(counted.is_set, timeout=120000)
        qtbot.mouseClick(dialog.cancel_button, Qt.MouseButton.LeftButton)
        assert dialog.status.text() == "cancelling…"
        release.set()
    line, failed, cancelled = done.args
    assert cancelled and failed == 0
    written = sorted(p.name for p in (tmp_path / "frames" / "weft").glob("*.png"))
    assert 1 <= len(written) < 12
    assert line == f"{len(written)} written, {12 - len(written)} not done (cancelled)"
    for name in written:  # whole files
        assert load_image(tmp_path / "frames" / "weft" / name).image.shape[:2] == (60, 80)


def test_a_refused_batch_says_why_in_one_line(window, qtbot, tmp_path):
    dialog = open_dialog(window, qtbot)
    qtbot.mouseClick(dialog.run_button, Qt.MouseButton.LeftButton)
    assert dialog.status.text() == "choose a folder of images first" and not dialog.running
    (tmp_path / "empty").mkdir()
    qtbot.keyClicks(dialog.folder, str(tmp_path / "empty"))
    before = set(threading.enumerate())
    with qtbot.waitSignal(dialog.batch_finished, timeout=60000) as done:
        qtbot.mouseClick(dialog.run_button, Qt.MouseButton.LeftButton)
    assert done.args[1] == -1
    assert "the folder holds no image files" in dialog.status.text()
    assert "\n" not in dialog.status.text() and dialog.run_button.isEnabled()
    # the batch's worker thread ends with the batch (none left behind by the dialog)
    qtbot.waitUntil(lambda: not (set(threading.enumerate()) - before), timeout=10000)


def test_nothing_to_apply_before_a_full_size_result(qtbot, settings):
    from weft.app.gui.main_window import MainWindow

    w = MainWindow(settings=settings, load_defaults=False)
    qtbot.addWidget(w)
    with qtbot.waitSignal(w.message, timeout=5000) as msg:
        w.open_batch_dialog()
    assert msg.args == ["nothing to apply yet: wait for the full-size result"]
    assert w.findChild(BatchDialog) is None
    w.shutdown()
