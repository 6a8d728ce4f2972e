"""Fast texture transfer as a method: its run, warm-up, studio description and figures."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..registry import InputSpec, Method, Result
from ..studio import SQUARE, Figure, Geometry, Studio
from .checks import memory_estimate
from .params import METRICS, FastParams
from .transfer import _transfer, transfer


def _run(inputs: Mapping[str, np.ndarray], params: FastParams, *, rng=None, progress=None, cancel=None) -> Result:
    out, pos, resolved = _transfer(
        inputs["texture"],
        inputs.get("target"),
        params,
        mask=inputs.get("mask"),
        rng=rng,
        progress=progress,
        cancel=cancel,
    )
    # How often a pixel continues its left neighbour's patch (flat source index one further).
    cont = np.mean(pos[:, 1:] == pos[:, :-1] + 1) if pos.shape[1] > 1 else 0.0
    return Result(
        out,
        {
            "mode": resolved.mode,
            "metric": resolved.metric,
            "p": resolved.p,
            "p_l": resolved.p_l,
            "coherent_fraction": round(float(cont), 4),
        },
    )


def warm_up() -> None:
    """Load the compiled kernel for every metric (numba's cache) on a tiny input."""
    tiny = np.linspace(0.0, 1.0, 12 * 12, dtype=np.float32).reshape(12, 12)
    for metric in METRICS:
        transfer(tiny, tiny, metric=metric, n=3, rng=0)
    transfer(tiny, size=(8, 8), n=3, rng=0)


def _auto(params: FastParams, shapes: Mapping[str, tuple]) -> dict:
    """What "auto" resolves to with inputs of these shapes (the studio shows it beside the box)."""
    resolved = params.resolved("target" in shapes)
    return {name: getattr(resolved, name) for name in ("p", "p_l")}


def _limits(params: FastParams, shapes: Mapping[str, tuple]) -> dict:
    """The neighbourhood fits in the source texture (its source region)."""
    return {"n": (3, min(shapes["texture"][:2]))} if "texture" in shapes else {}


def _idle(params: FastParams, shapes: Mapping[str, tuple]) -> set:
    """Parameters that change nothing with these settings: each metric's own weight outside it."""
    idle = set()
    if params.metric != "artistic":
        idle.add("w")
    if params.metric != "full":
        idle.add("target_weight")
    return idle


METHOD = Method(
    name="fast",
    summary="fast texture transfer (Ashikhmin): live artistic styles, synthesis, super-resolution",
    params=FastParams,
    inputs=(
        InputSpec("texture", "the source texture (for superres and novel styles: the picture itself)", min_side=3),
        InputSpec("target", "the picture to render in the texture (transfer)", required=False),
        InputSpec("mask", "source mask: candidates come only from its white part", required=False),
    ),
    run=_run,
    warm_up=warm_up,
    memory=memory_estimate,
    studio=Studio(
        title="Fast texture transfer (Ashikhmin)",
        canvas="texture",
        geometry=(
            Geometry(SQUARE, on=("texture",), help="drag a square: the source region (the method copies only from it)"),
        ),
        preview_inputs=("target",),
        preview_params=("size",),
        auto=_auto,
        limits=_limits,
        idle=_idle,
        compare=("target", "texture"),
        examples={"texture": "wood-grain", "target": "astronaut"},
        rank=0,
        figures={
            "mode": Figure("mode"),
            "metric": Figure("metric"),
            "p": Figure("random candidates", "%", digits=2),
            "p_l": Figure("location candidates", "%", digits=2),
            "coherent_fraction": Figure("coherent pixels", "%", digits=2),
        },
    ),
)
