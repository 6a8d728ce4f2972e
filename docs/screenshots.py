"""Render the README's screenshots from the real app: ``.venv/bin/python docs/screenshots.py [NAME ...]``.

Runs offscreen (``QT_QPA_PLATFORM=offscreen``); each shot opens the real main window with private
settings, sets up a method the way a user would (inputs, parameters, prototype, lines), waits for the
full-size result and grabs the window into ``docs/images/studio-<name>.png``.
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from PySide6.QtCore import QSettings  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402
from weft.app.gui.document import DocumentState, InputImage  # noqa: E402
from weft.app.gui.main_window import MainWindow  # noqa: E402
from weft.core import registry  # noqa: E402
from weft.core.examples import RESOURCES, example  # noqa: E402
from weft.core.image import load_image  # noqa: E402

OUT = Path(__file__).resolve().parent / "images"
sys.path.insert(0, str(OUT.parent.parent))  # the fill shot builds its photo with benchmarks/fill.py


def _wait(app, condition, timeout: float = 60.0) -> None:
    end = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > end:
            raise RuntimeError("timed out waiting for the window")
        app.processEvents()
        time.sleep(0.005)


def _input(name: str) -> InputImage:
    path = example(name)
    return InputImage(str(path), load_image(path).image)


def shoot(app, name: str, setup) -> Path:
    with tempfile.TemporaryDirectory() as tmp:
        os.environ["WEFT_RECOVERY_DIR"] = tmp  # never touch the user's recovery file
        window = MainWindow(
            settings=QSettings(os.path.join(tmp, "s.ini"), QSettings.Format.IniFormat), load_defaults=False
        )
        window.resize(1440, 860)
        window.show()
        app.processEvents()
        setup(window)
        window.doc.undo_stack.clear()
        window.renderer.final(now=True)
        _wait(
            app,
            lambda: (
                window.renderer.last is not None
                and window.renderer.last.final
                and not window.renderer.runner.busy("final")
            ),
        )
        for _ in range(5):
            app.processEvents()
        path = OUT / f"studio-{name}.png"
        window.grab().save(str(path))
        window.doc.undo_stack.setClean()
        window.close()
    return path


def fast(window) -> None:
    doc = window.doc
    doc.restore(DocumentState(inputs={"texture": _input("hatching"), "target": _input("chelsea")}, method="fast"))
    doc.set_param("metric", "artistic")
    doc.set_param("p", 0.2)
    doc.set_param("colour", "source")


def quilt(window) -> None:
    doc = window.doc
    doc.restore(DocumentState(inputs={"texture": _input("brick")}, method="quilt"))
    doc.set_square((0, 0, 128))
    doc.set_param("mode", "mincut")
    doc.set_param("size", (384, 384))
    window.method_panel.compare_button.setChecked(False)


def nfpt(window) -> None:
    import json

    doc = window.doc
    doc.restore(DocumentState(inputs={"photo": _input("perspective")}, method="nfpt"))
    data = json.loads((RESOURCES / "perspective-lines.json").read_text())
    doc.set_lines(data["image_lines"], data["frontal_lines"], frontal_size=data["frontal_size"])
    doc.set_param("size", (640, 480))
    window.inputs_pane.tabs.setCurrentIndex(0)


def fill(window) -> None:
    """Fill and extend on issue 15's photo (``benchmarks/fill.py``: the spoon pasted over the saucer's
    rim), its silhouette painted as the mask (*structure* auto: the rim continued)."""
    import atexit
    import shutil

    from weft.core.geometry import Mask
    from weft.core.image import save_image

    from benchmarks.fill import by_name

    case = by_name()["fill-object"].build()
    folder = tempfile.mkdtemp(prefix="weft-shot-")  # the image's file, while the window reads it
    atexit.register(shutil.rmtree, folder, ignore_errors=True)
    path = Path(folder) / "saucer.png"
    save_image(path, case.known_part.astype("float32") / 255.0)
    doc = window.doc
    doc.restore(DocumentState(inputs={"image": InputImage(str(path), load_image(path).image)}, method="fill"))
    doc.set_mask(doc.mask_geometry("mask").key, Mask(case.hole), "Brush")


def affine(window) -> None:
    doc = window.doc
    doc.restore(DocumentState(inputs={"texture": _input("cat-fur")}, method="affine"))
    doc.set_square((20, 20, 64))
    doc.set_param("block", 16)


SHOTS = {"fast": fast, "quilt": quilt, "affine": affine, "nfpt": nfpt, "fill": fill}


def main(argv: list[str] | None = None) -> int:
    """Every shot, or those named: ``docs/screenshots.py fill``."""
    names = list(sys.argv[1:] if argv is None else argv) or list(SHOTS)
    unknown = [n for n in names if n not in SHOTS]
    if unknown:
        print(f"screenshots.py: no shot named {', '.join(unknown)} (shots: {', '.join(SHOTS)})", file=sys.stderr)
        return 2
    app = QApplication.instance() or QApplication(sys.argv[:1])
    OUT.mkdir(parents=True, exist_ok=True)
    for name in names:
        if name in registry.methods():
            print(shoot(app, name, SHOTS[name]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
