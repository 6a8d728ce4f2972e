"""GUI latency: ``python -m benchmarks.gui_latency [--values 30] [--hz 60]`` and, for painting a mask,
``python -m benchmarks.gui_latency --paint [--method M] [--values 60] [--hz 60] [--side 512]``.

The real main window, offscreen, the fast method on a 640x500 target (astronaut) with a 192 px
gravel texture. The p slider is held down and moved through ``--values`` values at ``--hz``; for every
preview that reaches the screen, the latency is the time from the slider's value change (of the value
that preview was computed for) to the end of the result view's next paint. A 5 ms heartbeat timer on
the GUI thread measures the longest stall. Prints one JSON line:
``{"median_ms", "p95_ms", "max_stall_ms", "previews", "values"}``.

``--paint``: the first studio method whose description previews a stroke (``Studio.preview_around``;
or ``--method``) on its bundled example (or gravel; ``--example NAME``: that one, e.g. coffee, a colour
photo) resized to ``--side`` px; a brush stroke of ``--values`` mouse moves at ``--hz`` is painted on
the canvas with real mouse events. For every preview around the stroke that reaches the screen, the
latency is the time from the mouse move of the latest dab it includes to the end of the result view's
next paint. Same JSON line, plus ``"method"``.

``--open [--side 4096] [--runs 5] [--method fill]``: the longest GUI-thread stall (the 5 ms heartbeat)
while a large picture (``--side`` px square) reaches the views, each step in a fresh window with the
method's kernels loaded: ``session`` opening a session of it (nothing drawn: the result view shows
the picture too), ``open`` File > Open of it as the canvas input, ``result`` the method's full-size
result of it (with a small painted mask for a method that fills one) from its arrival until both
views show it, ``export`` exporting that result. Prints one JSON line with each step's median over
the runs (ms) and every run's figure.

``--variations [--side 4096] [--runs 5] [--method fill]``: the longest GUI-thread stall (the 5 ms
heartbeat) from the Variations dialog's Render grid click until its last cell arrives (a 3 x 3 grid
over the method's first two numeric parameters, its default ranges), on a large picture (``--side``
px square, with a painted stroke for a method that fills a mask), every method's kernels loaded
and the main window idle; a fresh dialog per run. Prints one JSON line with the median over the runs
(ms), every run's figure and the grid's time (click to last cell, s).
"""

from __future__ import annotations

import argparse
import itertools
import json
import os
import statistics
import sys
import tempfile
import time

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from PySide6.QtCore import QEvent, QObject, QSettings, QTimer  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402


class _PaintWatch(QObject):
    def __init__(self, on_paint):
        super().__init__()
        self.on_paint = on_paint

    def eventFilter(self, obj, event):  # noqa: N802
        if event.type() == QEvent.Type.Paint:
            QTimer.singleShot(0, self.on_paint)  # after the paint has finished
        return False


def _window(tmp: str, ini: str = "weft.ini"):
    """A shown 1400x900 main window with its settings in ``tmp`` and its recovery file there too
    (never the user's)."""
    from weft.app.gui.main_window import MainWindow

    os.environ["WEFT_RECOVERY_DIR"] = tmp
    window = MainWindow(settings=QSettings(os.path.join(tmp, ini), QSettings.Format.IniFormat), load_defaults=False)
    window.resize(1400, 900)
    window.show()
    return window


def measure(values: int = 30, hz: float = 60.0) -> dict:
    from weft.app.gui.document import DocumentState, InputImage
    from weft.core.examples import example
    from weft.core.image import load_image, resize

    app = QApplication.instance() or QApplication(sys.argv[:1])
    with tempfile.TemporaryDirectory() as tmp:
        window = _window(tmp)
        doc = window.doc
        doc.restore(
            DocumentState(
                inputs={
                    "texture": InputImage(None, load_image(example("gravel")).image[:192, :192]),
                    "target": InputImage(None, resize(load_image(example("astronaut")).image, (640, 500))),
                },
                method="fast",
            )
        )
        window.renderer.final(now=True)
        _wait(app, lambda: window.renderer.last is not None and window.renderer.last.final, 30)

        value_of_job: dict[int, float] = {}

        def recording_submit(job_id, slot):
            if slot == "preview":  # the render after release is not a preview
                value_of_job[job_id] = doc.current_params.p

        window.renderer.submitted.connect(recording_submit)
        changed_at: dict[float, float] = {}
        latencies: list[float] = []
        pending: list[int] = []
        window.renderer.shown.connect(lambda s: pending.append(s.job_id))

        def painted():
            now = time.perf_counter()
            while pending:
                job = pending.pop(0)
                p = value_of_job.get(job)
                if p in changed_at:
                    latencies.append((now - changed_at[p]) * 1000)

        watch = _PaintWatch(painted)
        window.result_view.viewport().installEventFilter(watch)

        heartbeat, beats = _heartbeat()

        slider = window.method_panel.params_panel.row("p").editor
        slider.setSliderDown(True)
        series = [round(0.02 + 0.5 * i / (values - 1), 3) for i in range(values)]
        step = 1.0 / hz
        start = time.perf_counter()
        for i, v in enumerate(series):
            _wait(app, lambda i=i: time.perf_counter() - start >= i * step, 5)
            changed_at[v] = time.perf_counter()
            slider.setValue(v)
        _wait(app, lambda: time.perf_counter() - start >= values * step + 0.3, 5)
        slider.setSliderDown(False)
        slider.sliderReleased.emit()
        _wait(app, lambda: window.renderer.last.final and doc.current_params.p == series[-1], 30)
        _wait(app, lambda: False, 0.2)
        heartbeat.stop()
        window.doc.undo_stack.setClean()  # the slider moves are not work to save: close without asking
        window.close()
    return _summary(latencies, beats, values)


def measure_painting(
    values: int = 60, hz: float = 60.0, method: str | None = None, side: int = 512, picture_name: str | None = None
) -> dict:
    from PySide6.QtCore import QEvent, QPointF, Qt
    from PySide6.QtGui import QMouseEvent
    from weft.app.gui.document import DocumentState, InputImage
    from weft.core import registry
    from weft.core.errors import WeftError
    from weft.core.examples import example
    from weft.core.image import load_image, resize

    app = QApplication.instance() or QApplication(sys.argv[:1])
    offered = registry.studio_methods()
    if method is None:
        method = next((n for n, m in offered.items() if m.studio.preview_around is not None), None)
    if method not in offered or offered[method].studio.preview_around is None:
        raise SystemExit(f"no studio method previews a painted stroke ({method or 'none registered'})")
    studio = offered[method].studio
    with tempfile.TemporaryDirectory() as tmp:
        window = _window(tmp)
        doc = window.doc
        try:
            picture = load_image(example(picture_name or studio.examples.get(studio.canvas, "gravel"))).image
        except WeftError as e:
            if picture_name is not None:  # asked for by name: say so, never measure another picture
                raise SystemExit(f"--example {picture_name}: {e}") from None
            picture = load_image(example("gravel")).image
        picture = resize(picture, (side, side))
        answered: list = []  # the first render: a result, or "nothing to fill" with nothing painted yet
        window.renderer.shown.connect(answered.append)
        window.renderer.failed.connect(answered.append)
        doc.restore(DocumentState(inputs={studio.canvas: InputImage(None, picture)}, method=method))
        window.renderer.final(now=True)
        _wait(app, lambda: bool(answered), 120)
        view = window.inputs_pane.canvas_view
        tool = window.inputs_pane.mask_tool()
        tool.set_size(max(8, side // 24))

        moved_at: list[float] = []
        dab_of_job: dict[int, int] = {}
        window.renderer.submitted.connect(
            lambda job_id, slot: slot == "preview" and dab_of_job.__setitem__(job_id, len(moved_at) - 1)
        )
        latencies: list[float] = []
        pending: list[int] = []
        window.renderer.around_shown.connect(lambda s: pending.append(s.job_id))

        def painted():
            now = time.perf_counter()
            while pending:
                dab = dab_of_job.get(pending.pop(0))
                if dab is not None and dab >= 0:
                    latencies.append((now - moved_at[dab]) * 1000)

        watch = _PaintWatch(painted)
        window.result_view.viewport().installEventFilter(watch)
        heartbeat, beats = _heartbeat()

        def send(kind, x, y):
            pos = view.mapFromScene(QPointF(x, y))
            etype = {
                "press": QEvent.Type.MouseButtonPress,
                "move": QEvent.Type.MouseMove,
                "release": QEvent.Type.MouseButtonRelease,
            }[kind]
            button = Qt.MouseButton.NoButton if kind == "move" else Qt.MouseButton.LeftButton
            held = Qt.MouseButton.NoButton if kind == "release" else Qt.MouseButton.LeftButton
            QApplication.sendEvent(
                view.viewport(),
                QMouseEvent(
                    etype,
                    QPointF(pos),
                    QPointF(view.viewport().mapToGlobal(pos)),
                    button,
                    held,
                    Qt.KeyboardModifier.NoModifier,
                ),
            )

        # a wavy stroke across the middle of the picture
        points = [
            (side * (0.15 + 0.7 * i / (values - 1)), side * (0.5 + 0.15 * ((i // 10) % 2 * 2 - 1) * (i % 10) / 10))
            for i in range(values)
        ]
        step = 1.0 / hz
        moved_at.append(time.perf_counter())
        send("press", *points[0])
        start = time.perf_counter()
        for i, (x, y) in enumerate(points[1:], 1):
            _wait(app, lambda i=i: time.perf_counter() - start >= i * step, 5)
            moved_at.append(time.perf_counter())
            send("move", x, y)
        _wait(app, lambda: time.perf_counter() - start >= values * step + 0.5, 5)
        send("release", *points[-1])
        _wait(
            app,
            lambda: (
                window.renderer.last is not None
                and window.renderer.last.final
                and doc.value(tool.geometry_key) is not None
                and not window.renderer.running()
            ),
            120,
        )
        heartbeat.stop()
        window.doc.undo_stack.setClean()
        window.close()
    return {"method": method, **_summary(latencies, beats, values)}


def _picture_file(folder: str, side: int) -> str:
    """A smooth colour picture of ``side``² px as a PNG (random values bilinearly enlarged)."""
    import numpy as np
    from weft.core.image import resize, save_image

    small = np.random.default_rng(0).random((max(2, side // 16),) * 2 + (3,), dtype=np.float32)
    path = os.path.join(folder, f"picture-{side}.png")
    save_image(path, resize(small, (side, side), interpolation="linear").clip(0, 1))
    return path


def _stall_since(beats: list[float], t0: float) -> float:
    """The longest gap between heartbeats that ends after ``t0`` (ms)."""
    gaps = [(b - a) * 1000 for a, b in itertools.pairwise(beats) if b >= t0]
    return round(max(gaps), 1) if gaps else 0.0


def measure_opening(side: int = 4096, runs: int = 5, method: str = "fill") -> dict:
    from weft.app.gui.document import read_input
    from weft.core import registry

    app = QApplication.instance() or QApplication(sys.argv[:1])
    registry.warm_up(method)  # (the studio loads them at start: no kernel loading in the figures)
    steps: dict[str, list[float]] = {"session": [], "open": [], "result": [], "export": []}
    with tempfile.TemporaryDirectory() as tmp:
        picture = _picture_file(tmp, side)
        item = read_input(picture)
        session = os.path.join(tmp, "big.weft.json")
        for run in range(runs):
            for name, stall in _opening_run(app, tmp, run, method, side, picture, item, session).items():
                steps[name].append(stall)
    return {
        "side": side,
        "method": method,
        "runs": runs,
        **{f"{k}_stall_ms": round(statistics.median(v), 1) for k, v in steps.items()},
        "each": steps,
    }


def _opening_run(app, tmp: str, run: int, method: str, side: int, picture: str, item, session: str) -> dict[str, float]:
    """One run of :func:`measure_opening` in a fresh window: each step's longest stall (ms)."""
    from weft.app.gui.document import DocumentState
    from weft.core.geometry import Mask
    from weft.core.studio import MASK

    stalls: dict[str, float] = {}
    window = _window(tmp, f"weft{run}.ini")
    doc, studio = window.doc, window.doc.methods[method].studio
    canvas = studio.canvas
    doc.restore(DocumentState(inputs={canvas: item}, method=method))
    doc.session().save(session)
    doc.restore(DocumentState(inputs={}, method=method))
    _wait(app, lambda: not window.renderer.running(), 30)
    answered: list[float] = []
    window.renderer.shown.connect(lambda _s: answered.append(time.perf_counter()))
    window.renderer.failed.connect(lambda _m: answered.append(time.perf_counter()))

    def views_show(image) -> bool:
        views = (window.inputs_pane.canvas_view, window.result_view)
        return all(
            v.image is not None and v.image.shape[:2] == image.shape[:2] and not getattr(v, "converting", False)
            for v in views
        )

    def step(name: str, action, done, settle: float = 0.3, since=None) -> None:
        heartbeat, beats = _heartbeat()
        t0 = time.perf_counter()
        action()
        _wait(app, done, 300)
        _wait(app, lambda: False, settle)
        heartbeat.stop()
        stalls[name] = _stall_since(beats, since() if since is not None else t0)

    # a session of the picture (nothing drawn: the result view shows the picture)
    step(
        "session",
        lambda: window.files.open_session(session),
        lambda: answered and views_show(item.image) and window.result_view.image is doc.image(canvas),
    )
    # File > Open of the picture (decoded off the GUI thread, then shown)
    del answered[:]
    step(
        "open",
        lambda: window.open_input(canvas, picture),
        lambda: (
            doc.image(canvas) is not item.image
            and answered
            and views_show(item.image)
            and window.result_view.image is doc.image(canvas)
        ),
    )
    # the method's full-size result (a small painted mask if it fills one): the stall from its arrival
    g = next((g for g in studio.geometry if g.kind == MASK), None)
    del answered[:]
    if g is not None:
        doc.set_mask(
            g.key,
            Mask.empty(side, side).painted_line((side * 0.4, side * 0.4), (side * 0.45, side * 0.42), side / 200, True),
            "stroke",
        )
    else:
        window.renderer.final(now=True)
    step(
        "result",
        lambda: None,
        lambda: (
            bool(answered)
            and window.renderer.last is not None
            and window.renderer.last.final
            and window.result_view.image is window.renderer.last.image
            and not getattr(window.result_view, "converting", False)
        ),
        settle=0.5,
        since=lambda: answered[0],
    )
    out = os.path.join(tmp, f"out{run}.png")
    step("export", lambda: window.files.export_result(out), lambda: os.path.exists(out), settle=0.2)
    doc.undo_stack.setClean()
    window.close()
    return stalls


def measure_variations(side: int = 4096, runs: int = 5, method: str = "fill") -> dict:
    from weft.app.gui.document import DocumentState, read_input
    from weft.core import registry
    from weft.core.geometry import Mask
    from weft.core.studio import MASK

    app = QApplication.instance() or QApplication(sys.argv[:1])
    registry.warm_up_all(first=method)  # (the studio's background warm-up of every method: not during a grid)
    stalls: list[float] = []
    seconds: list[float] = []
    with tempfile.TemporaryDirectory() as tmp:
        item = read_input(_picture_file(tmp, side))
        window = _window(tmp)
        window.renderer.enabled = False  # the main window idle: its full-size render is not measured here
        doc, studio = window.doc, window.doc.methods[method].studio
        doc.restore(DocumentState(inputs={studio.canvas: item}, method=method))
        g = next((g for g in studio.geometry if g.kind == MASK), None)
        if g is not None:
            doc.set_mask(
                g.key,
                Mask.empty(side, side).painted_line(
                    (side * 0.4, side * 0.4), (side * 0.5, side * 0.45), side / 60, True
                ),
                "stroke",
            )
        _wait(app, lambda: not window.renderer.running(), 30)
        for _run in range(runs):
            stall, took = _variations_run(app, window, method)
            stalls.append(stall)
            seconds.append(took)
        doc.undo_stack.setClean()
        window.close()
    return {
        "side": side,
        "method": method,
        "runs": runs,
        "grid_stall_ms": round(statistics.median(stalls), 1),
        "each": stalls,
        "grid_s": seconds,
    }


def _variations_run(app, window, method: str) -> tuple[float, float]:
    """One run of :func:`measure_variations` in a fresh dialog: the longest stall (ms) and the grid's time (s)."""
    from PySide6.QtCore import Qt
    from PySide6.QtTest import QTest

    window.open_variations()
    dialog = window.variations
    _wait(app, dialog.isVisible, 10)
    done: set = set()
    dialog.cell_done.connect(lambda i, j: done.add((i, j)))
    heartbeat, beats = _heartbeat()
    _wait(app, lambda: len(beats) > 2, 5)
    t0 = time.perf_counter()
    QTest.mouseClick(dialog.render_button, Qt.MouseButton.LeftButton)
    _wait(
        app,
        lambda: (
            dialog.cells and done == {k for k, b in dialog.cells.items() if b.isEnabled()} and not dialog.runner.busy()
        ),
        300,
    )
    took = round(time.perf_counter() - t0, 2)
    _wait(app, lambda: False, 0.1)  # the last thumbnail painted
    heartbeat.stop()
    stall = _stall_since(beats, t0)
    if not done:
        raise SystemExit(f"no cell of the {method} grid rendered: {dialog.status.text()}")
    dialog.close()
    dialog.deleteLater()
    return stall, took


def _heartbeat() -> tuple[QTimer, list[float]]:
    """A started 5 ms timer and the times it fired at: a gap between two beats is a GUI-thread stall."""
    beats: list[float] = []
    heartbeat = QTimer()
    heartbeat.setInterval(5)
    heartbeat.timeout.connect(lambda: beats.append(time.perf_counter()))
    heartbeat.start()
    return heartbeat, beats


def _summary(latencies: list[float], beats: list[float], values: int) -> dict:
    """Median and p95 latency (ms), the longest gap between heartbeats, and the counts."""
    latencies = sorted(latencies)
    gaps = [(b - a) * 1000 for a, b in itertools.pairwise(beats)]
    return {
        "median_ms": round(statistics.median(latencies), 1) if latencies else None,
        "p95_ms": round(latencies[min(len(latencies) - 1, int(0.95 * len(latencies)))], 1) if latencies else None,
        "max_stall_ms": round(max(gaps), 1) if gaps else None,
        "previews": len(latencies),
        "values": values,
    }


def _wait(app, condition, timeout: float) -> None:
    end = time.perf_counter() + timeout
    while not condition():
        if time.perf_counter() > end:
            if timeout >= 1:
                raise TimeoutError("the window did not respond in time")
            return
        app.processEvents()
        time.sleep(0.001)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.gui_latency", description=__doc__)
    ap.add_argument("--values", type=int, default=None, help="slider values (30) or mouse moves of the stroke (60)")
    ap.add_argument("--hz", type=float, default=60.0)
    ap.add_argument("--paint", action="store_true", help="paint a mask stroke instead of moving a slider")
    ap.add_argument(
        "--method",
        default=None,
        help="the method: with --paint the first that previews strokes, with --open or --variations fill (defaults)",
    )
    ap.add_argument(
        "--side", type=int, default=None, help="with --paint (512), --open or --variations (4096): the picture's side"
    )
    ap.add_argument("--open", action="store_true", help="open a large picture: the longest GUI-thread stalls")
    ap.add_argument(
        "--variations",
        action="store_true",
        help="render a Variations grid of a large picture: the longest GUI-thread stall",
    )
    ap.add_argument("--runs", type=int, default=5, help="with --open or --variations: the runs (median)")
    ap.add_argument(
        "--example",
        default=None,
        help="with --paint: the bundled example painted on (default: the method's own; coffee: a colour photo)",
    )
    args = ap.parse_args(argv)
    if args.variations:
        kind, row = "variations", measure_variations(args.side or 4096, args.runs, args.method or "fill")
    elif args.open:
        kind, row = "open", measure_opening(args.side or 4096, args.runs, args.method or "fill")
    elif args.paint:
        kind, row = "paint", measure_painting(args.values or 60, args.hz, args.method, args.side or 512, args.example)
    else:
        kind, row = "slider", measure(args.values or 30, args.hz)
    print(json.dumps(row))
    record_row(kind, row, argv)
    return 0


def record_row(kind: str, row: dict, argv: list[str] | None) -> None:
    """Put ``row`` in ``benchmarks/results/gui_latency.json`` in place of that file's row of the same
    kind (slider, paint, open, variations), keeping the others: each kind is its own run."""
    from .record import RESULTS, command, write_results

    path = RESULTS / "gui_latency.json"
    try:
        rows = [r for r in json.loads(path.read_text(encoding="utf-8"))["rows"] if r.get("measure") != kind]
    except (OSError, ValueError, KeyError, TypeError):
        rows = []
    order = ["slider", "paint", "open", "variations"]
    rows.append({"measure": kind, "command": command("benchmarks.gui_latency", argv), **row})
    rows.sort(key=lambda r: order.index(r["measure"]) if r.get("measure") in order else len(order))
    write_results(
        "gui_latency",
        rows,
        command="python -m benchmarks.gui_latency [--paint | --open | --variations]",
        note="the real main window, offscreen; each row is its own run, with its command",
    )


if __name__ == "__main__":
    sys.exit(main())
