"""The registered benchmark cases. Each method's issue adds its cases here.

An input is ``Input(example, crop=(x, y, w, h) | None, resize=(w, h) | None, grey=False)`` over a
bundled example of ``resources/``. ``metrics`` names the figures of ``core.metrics`` to compute on
the output: ``coherence`` / ``completeness`` against the ``texture`` input, ``fidelity`` against the
``target`` input, ``snr_db`` against the ``texture`` input. ``gmic`` is a G'MIC command line run on
the texture input in the same run (whole process against whole ``weft`` process) when ``gmic`` is
installed; ``quick`` overrides parameters for ``--quick`` runs.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any


@dataclass(frozen=True)
class Input:
    example: str
    crop: tuple[int, int, int, int] | None = None
    resize: tuple[int, int] | None = None
    grey: bool = False


@dataclass(frozen=True)
class Case:
    name: str
    method: str
    inputs: dict[str, Input]
    params: dict[str, Any]
    metrics: tuple[str, ...] = ()
    gmic: tuple[str, ...] | None = None
    quick: dict[str, Any] = field(default_factory=dict)
    seed: int = 1
    note: str = ""


CASES: list[Case] = [
    Case(
        name="quilt-random-512",
        method="quilt",
        inputs={"texture": Input("brick", crop=(0, 0, 128, 128))},
        params={"mode": "random", "block": 32, "size": (512, 512)},
        metrics=("coherence", "completeness"),
        gmic=("syntexturize_matchpatch", "512,512"),
        quick={"size": (256, 256)},
        note="random block tiling (no overlap); G'MIC runs its patch-matching synthesis on the same input",
    ),
]


def by_name() -> dict[str, Case]:
    return {c.name: c for c in CASES}
