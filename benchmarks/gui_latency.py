"""GUI latency: ``python -m benchmarks.gui_latency [--values 30] [--hz 60]``.

The real main window, offscreen, the fast method on a 640x500 target (astronaut) with a 192 px
gravel texture. The p slider is held down and moved through ``--values`` values at ``--hz``; for every
preview that reaches the screen, the latency is the time from the slider's value change (of the value
that preview was computed for) to the end of the result view's next paint. A 5 ms heartbeat timer on
the GUI thread measures the longest stall. Prints one JSON line:
``{"median_ms", "p95_ms", "max_stall_ms", "previews", "values"}``.
"""

from __future__ import annotations

import argparse
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


def measure(values: int = 30, hz: float = 60.0) -> dict:
    from weft.app.gui.document import DocumentState, InputImage
    from weft.app.gui.main_window import MainWindow
    from weft.core.examples import example
    from weft.core.image import load_image, resize

    app = QApplication.instance() or QApplication(sys.argv[:1])
    with tempfile.TemporaryDirectory() as tmp:
        settings = QSettings(os.path.join(tmp, "weft.ini"), QSettings.Format.IniFormat)
        os.environ["WEFT_RECOVERY_DIR"] = tmp  # never touch the user's recovery file
        window = MainWindow(settings=settings, load_defaults=False)
        window.resize(1400, 900)
        window.show()
        doc = window.doc
        doc.restore(DocumentState(inputs={
            "texture": InputImage(None, load_image(example("gravel")).image[:192, :192]),
            "target": InputImage(None, resize(load_image(example("astronaut")).image, (640, 500)))}, method="fast"))
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

        beats: list[float] = []
        heartbeat = QTimer()
        heartbeat.setInterval(5)
        heartbeat.timeout.connect(lambda: beats.append(time.perf_counter()))
        heartbeat.start()

        slider = window.params_panel.row("p").editor
        slider.setSliderDown(True)
        series = [round(0.02 + 0.5 * i / (values - 1), 3) for i in range(values)]
        step = 1.0 / hz
        start = time.perf_counter()
        for i, v in enumerate(series):
            _wait(app, lambda: time.perf_counter() - start >= i * step, 5)
            changed_at[v] = time.perf_counter()
            slider.setValue(v)
        _wait(app, lambda: time.perf_counter() - start >= values * step + 0.3, 5)
        slider.setSliderDown(False)
        slider.sliderReleased.emit()
        _wait(app, lambda: window.renderer.last.final and doc.current_params.p == series[-1], 30)
        _wait(app, lambda: False, 0.2)
        heartbeat.stop()
        gaps = [(b - a) * 1000 for a, b in zip(beats, beats[1:])]
        window.doc.undo_stack.setClean()  # the slider moves are not work to save: close without asking
        window.close()
    latencies.sort()
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
    ap.add_argument("--values", type=int, default=30)
    ap.add_argument("--hz", type=float, default=60.0)
    args = ap.parse_args(argv)
    print(json.dumps(measure(args.values, args.hz)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
