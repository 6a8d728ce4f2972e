"""What a benchmark case is. The cases themselves live in one module per method beside this one.

An input is ``Input(example, crop=(x, y, w, h) | None, resize=(w, h) | None, grey=False)`` over a
bundled example of ``resources/``, or over ``skimage.data``'s image NAME with ``example="skimage:NAME"``
(the peers' inputs, rebuilt exactly). ``metrics`` names the figures of ``weft.core.metrics`` to compute on
the output: ``coherence`` / ``completeness`` against the ``texture`` input, ``fidelity`` against the
``target`` input, ``snr_db`` against the ``texture`` input. ``gmic`` is a G'MIC command line run on
the texture input in the same run (whole process against whole ``weft`` process) when ``gmic`` is
installed; ``process`` also times the whole ``weft`` process without G'MIC; ``parallel`` also runs
two copies on two threads at once and reports the speed-up over running them one after the other;
``figures`` is a function ``(inputs, output) -> {name: value}`` for figures particular to the case;
``quick`` overrides parameters for ``--quick`` runs.
"""

from __future__ import annotations

from collections.abc import Callable
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
    process: bool = False
    parallel: bool = False
    figures: Callable[[dict, Any], dict[str, float]] | None = None
    quick: dict[str, Any] = field(default_factory=dict)
    seed: int = 1
    note: str = ""
