"""Make the small inputs the documentation's examples use: ``.venv/bin/python docs/examples/make_examples.py``.

* ``coffee-spoon-mask.png``: a mask of the spoon on the saucer of ``resources/coffee.png`` (white =
  the hole to fill): its bowl and handle, grown by 2 px, as a brush would paint it.
* ``coffee-no-cup-area.png``: a sampling area (white = where fill may copy from): all of
  ``resources/coffee.png`` but the cup, so no piece of the cup is copied into the spoon's place.
* ``frames/frame_0.png`` ... ``frame_3.png``: four 160x120 frames of a slow pan over
  ``resources/perspective-frontal.png``, the clip a batch example renders.
* ``oval-mask.png``: a soft-edged oval over the astronaut's face in ``resources/astronaut.png``
  (white = the foreground of ``weft blend``).
* ``floor.json``: a view for ``weft nfpt --view``: where the synthesized texture's four corners land
  in a 480x360 picture, laid as a floor.
* ``look.json``: a recipe (fast transfer of the gravel example onto a target), the look a batch
  applies to every frame.

Re-running it reproduces every file.
"""

from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np

HERE = Path(__file__).resolve().parent
RESOURCES = HERE.parent.parent / "resources"


def spoon_mask() -> np.ndarray:
    coffee = cv2.imread(str(RESOURCES / "coffee.png"))
    mask = np.zeros(coffee.shape[:2], np.uint8)
    cv2.ellipse(mask, (182, 140), (21, 24), 0, 0, 360, 255, thickness=-1)
    cv2.polylines(mask, [np.array([(206, 36), (197, 80), (189, 119)], np.int32)], False, 255, thickness=4)
    return cv2.dilate(mask, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (5, 5)))


def no_cup_area() -> np.ndarray:
    coffee = cv2.imread(str(RESOURCES / "coffee.png"))
    area = np.full(coffee.shape[:2], 255, np.uint8)
    cv2.ellipse(area, (145, 75), (62, 68), 0, 0, 360, 0, thickness=-1)
    return area


def frames(count: int = 4) -> list[np.ndarray]:
    wall = cv2.imread(str(RESOURCES / "perspective-frontal.png"))
    return [
        cv2.resize(wall[40:280, 24 * i : 24 * i + 320], (160, 120), interpolation=cv2.INTER_AREA) for i in range(count)
    ]


def oval_mask() -> np.ndarray:
    mask = np.zeros((256, 256), np.uint8)
    cv2.ellipse(mask, (120, 78), (40, 52), 0, 0, 360, 255, thickness=-1)
    return cv2.GaussianBlur(mask, (0, 0), 4)


def main() -> None:
    cv2.imwrite(str(HERE / "coffee-spoon-mask.png"), spoon_mask())
    cv2.imwrite(str(HERE / "oval-mask.png"), oval_mask())
    cv2.imwrite(str(HERE / "coffee-no-cup-area.png"), no_cup_area())
    floor = {"quad": [[150, 170], [330, 170], [470, 350], [10, 350]], "size": [480, 360]}
    (HERE / "floor.json").write_text(json.dumps(floor) + "\n")
    (HERE / "frames").mkdir(exist_ok=True)
    for i, frame in enumerate(frames()):
        cv2.imwrite(str(HERE / "frames" / f"frame_{i}.png"), frame)
    recipe = {
        "weft": 1,
        "method": "fast",
        "params": {"metric": "target", "p": 0.05},
        "inputs": {"texture": "../../resources/gravel.png", "target": "frames/frame_0.png"},
        "seed": 1,
    }
    (HERE / "look.json").write_text(json.dumps(recipe, indent=1) + "\n")


if __name__ == "__main__":
    main()
