"""``weft quilt``: the method the registry, the command line and the studio run (see the package)."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..errors import InvalidParameter
from ..params import out_of_range
from ..registry import InputSpec, Method, Result
from ..studio import SQUARE, Figure, Geometry, Studio
from .checks import _blocks, _transfer_passes, memory_estimate
from .params import QuiltParams, synth_block, synth_tol
from .synthesis import _synthesize, synthesize
from .transfer import _transfer, transfer

# --------------------------------------------------------------------------------------------
# the `weft quilt` command


def _run(inputs: Mapping[str, np.ndarray], params: QuiltParams, *, rng=None, progress=None, cancel=None) -> Result:
    texture = inputs["texture"]
    target = inputs.get("target")
    maps = {k: inputs.get(k) for k in ("source_map", "target_map")}
    if target is None:
        for name in ("source_map", "target_map"):
            if maps[name] is not None:
                raise InvalidParameter(f"input '{name.replace('_', '-')}' needs a target (--target)", name=name)
        if params.iterations > 1:
            raise out_of_range("iterations", params.iterations, 1, 1, "more passes need a target (--target)")
        mode = params.mode
        block = params.block or synth_block(texture.shape)
        record: dict = {}
        image = _synthesize(texture, params, rng=rng, progress=progress, cancel=cancel, record=record)
        h, w = image.shape[:2]
        if mode == "random":
            blocks = -(-h // block) * -(-w // block)
        else:
            ov = params.overlap if params.overlap is not None else max(1, -(-block // 6))
            blocks = _blocks(h, w, block, ov, params.tile)
        from ..metrics import verbatim_fraction

        return Result(
            image,
            {
                "block": block,
                "blocks": blocks,
                "verbatim_fraction": round(verbatim_fraction(record["sources"], texture.shape), 4),
            },
        )
    if params.size is not None:
        raise InvalidParameter(
            "parameter 'size' cannot be given with a target: the transfer has the target's size",
            name="size",
            value=params.size,
        )
    images = _transfer(
        texture,
        target,
        params,
        source_map=maps["source_map"],
        target_map=maps["target_map"],
        return_all=True,
        rng=rng,
        progress=progress,
        cancel=cancel,
    )
    image = images[-1]
    return Result(image, {"iterations": len(images)})


def _auto(params: QuiltParams, shapes: Mapping[str, tuple]) -> dict:
    """What "auto" block, overlap and tol resolve to with inputs of these shapes (the studio shows
    them beside their box, and unticking "auto" starts from them): a transfer's first pass, or the
    synthesis defaults (the block from the sample's size; nothing for it before a sample is open)."""
    if "target" in shapes:
        block, overlap, _alpha = _transfer_passes(params)[0]
        return {"block": block, "overlap": overlap, "tol": params.tol or 1}
    if params.block is None and "texture" not in shapes:
        return {}
    block = params.block or synth_block(shapes["texture"])
    return {
        "block": block,
        "overlap": params.overlap if params.overlap is not None else max(1, -(-block // 6)),
        "tol": params.tol or synth_tol(block),
    }


def _limits(params: QuiltParams, shapes: Mapping[str, tuple]) -> dict:
    """The ranges block and overlap accept with inputs of these shapes: a block fits in the sample
    (its source region), an overlap is smaller than the block (given or resolved)."""
    out = {}
    if "texture" in shapes:
        out["block"] = (2, min(shapes["texture"][:2]))
    block = params.block or _auto(params, shapes).get("block")
    if block:
        out["overlap"] = (1, max(1, block - 1))
    return out


def _idle(params: QuiltParams, shapes: Mapping[str, tuple]) -> set:
    """Parameters that change nothing with these settings: epsilon outside its rule, the Poisson
    band without Poisson, a transfer's alpha and passes without a target."""
    idle = set()
    if params.rule != "epsilon":
        idle.add("epsilon")
    if not params.poisson or params.mode == "random":
        idle.add("band")
    if "target" not in shapes:
        idle |= {"alpha", "iterations"}
    return idle


def warm_up() -> None:
    """Load (or compile) every numba kernel a run can use, on tiny inputs, so that no run compiles:
    the four selection kernels (tol, tol 1, epsilon, sampled), the seam rule's (candidates and the
    error along a cut), the cut and paste, the Poisson band and the templates of a transfer.

    For the GUI's background start-up; ``METHOD.warm_up_in_cli`` is False: a small synthesis on the
    command line (the numpy engine, see ``NUMPY_ENGINE_MAX_BLOCKS``) would otherwise pay numba's
    start-up for nothing, and a larger run compiles only the kernels it uses. A CLI run's reported
    ``seconds`` therefore include that load.
    """
    rng = np.random.default_rng(0)
    tex = rng.random((12, 12), dtype=np.float32)
    # Poisson: always the numba engine (which loads numba, so the next calls use it too)
    synthesize(tex, size=(16, 16), block=6, overlap=2, mode="mincut", poisson=True, rng=0)
    for rule in ("epsilon", "sampled"):
        synthesize(tex, size=(16, 16), block=6, overlap=2, mode="mincut", rule=rule, rng=0)
    synthesize(tex, size=(16, 16), block=6, overlap=2, mode="overlap", rng=0)  # the tol rule itself
    transfer(tex, tex, block=6, overlap=2, rng=0)


METHOD = Method(
    name="quilt",
    summary="image quilting (Efros & Freeman): synthesize a larger texture from blocks of a sample, "
    "or transfer it onto a target",
    params=QuiltParams,
    inputs=(
        InputSpec("texture", "the sample texture image", min_side=2),
        InputSpec("target", "transfer: the picture to re-render with the texture", required=False),
        InputSpec("source_map", "transfer: the texture's correspondence map (with --target-map)", required=False),
        InputSpec("target_map", "transfer: the target's correspondence map (with --source-map)", required=False),
    ),
    run=_run,
    warm_up=warm_up,
    warm_up_in_cli=False,
    memory=memory_estimate,
    studio=Studio(
        title="Image quilting (Efros & Freeman)",
        canvas="texture",
        geometry=(
            Geometry(SQUARE, on=("texture",), help="drag a square: the source region (blocks come only from it)"),
        ),
        preview_inputs=("target", "target_map"),
        preview_params=("size",),
        auto=_auto,
        limits=_limits,
        idle=_idle,
        compare=("target", "texture"),
        examples={"texture": "wood-grain", "target": "astronaut"},
        rank=1,
        figures={
            "block": Figure("block", "px"),
            "blocks": Figure("blocks"),
            "verbatim_fraction": Figure("largest verbatim copy", "%", "of the sample", digits=2),
            "iterations": Figure("passes"),
        },
    ),
)
