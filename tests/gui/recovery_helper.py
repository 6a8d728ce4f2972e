"""A studio process for the kill -9 recovery test (tests/gui/test_no_lost_work.py).

``python tests/gui/recovery_helper.py TARGET_IMAGE SETTINGS_INI`` opens the studio (offscreen, with
the recovery folder from ``WEFT_RECOVERY_DIR``), opens TARGET_IMAGE as the target, makes the edits in
:data:`EDITS`, waits until the autosave has written all of them, prints ``AUTOSAVED`` and keeps
running until it is killed.
"""

import json
import os
import sys
from pathlib import Path

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from PySide6.QtCore import QSettings, QTimer  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402
from weft.app.gui.main_window import MainWindow  # noqa: E402

EDITS = {
    "p": 0.37,
    "prototype": [3, 4, 20],
    "image_lines": [[1.0, 2.0, 30.0, 3.0], [2.0, 20.0, 31.0, 22.0]],
    "frontal_lines": [[0.0, 0.0, 32.0, 0.0], [0.0, 20.0, 32.0, 20.0]],
    "seed": 4242,
}


def main() -> int:
    target, ini = sys.argv[1], sys.argv[2]
    app = QApplication(sys.argv[:1])
    window = MainWindow(settings=QSettings(ini, QSettings.Format.IniFormat))
    window.questions.confirm = lambda question: False  # never block
    window.questions.ask_restore = lambda question: False
    window.show()
    window.open_input("target", target)
    state = {"edited": False}

    def step() -> None:
        doc = window.doc
        if not state["edited"]:
            if doc.inputs.get("target") is None or doc.inputs["target"].path != target:
                return  # the target is still being decoded
            window.method_panel.seed_box.setValue(EDITS["seed"])
            doc.set_param("p", EDITS["p"])
            doc.set_square(tuple(EDITS["prototype"]))  # fast's source region
            doc.set_method("nfpt")  # feature lines belong to the method that uses them
            doc.set_lines(EDITS["image_lines"], EDITS["frontal_lines"])
            doc.set_method("fast")
            state["edited"] = True
            return
        try:
            saved = json.loads(window.files.recovery_file.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            return
        geometry = saved.get("geometry", {})
        if (
            saved["params"]["fast"]["p"] == EDITS["p"]
            and geometry.get("fast", {}).get("region") == EDITS["prototype"]
            and geometry.get("nfpt", {}).get("lines", {}).get("image_lines") == EDITS["image_lines"]
            and saved["seed"] == EDITS["seed"]
            and saved["method"] == "fast"
            and saved["inputs"].get("target") == target
        ):
            print("AUTOSAVED", flush=True)
            timer.stop()

    timer = QTimer(interval=50)
    timer.timeout.connect(step)
    timer.start()
    return app.exec()


if __name__ == "__main__":
    sys.exit(main())
