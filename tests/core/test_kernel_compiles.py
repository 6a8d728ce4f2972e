"""A method's ``warm_up()`` compiles every numba specialisation its real runs use, and no
kernel compiles more than one specialisation (literal arguments or C/F layouts multiplying a cold
run's compiles must not come back silently).

Each method runs in a fresh interpreter (in this one other tests have already compiled kernels for
their own inputs): ``warm_up()``, then the signatures of every kernel in ``weft.core._kernels``, then
representative runs (the README's commands on smaller inputs, and the options that take other code
paths), then the signatures again. A kernel loaded from numba's on-disk cache counts like a compiled
one, so the check holds with a warm cache or a cold one. No timing here (that is
``benchmarks/``)."""

import json
import subprocess
import sys

import pytest

_SCRIPT = r"""
import json, pkgutil, sys

import numpy as np

import weft.core._kernels
from weft.core import registry
from weft.core.examples import example
from weft.core.image import load_image

def image(name, h=None, w=None):
    return np.ascontiguousarray(load_image(example(name)).image[:h, :w])

LINES = str(example("perspective").parent / "perspective-lines.json")
RUNS = {
    "quilt": [
        ({"texture": image("gravel", 96, 96), "target": image("camera", 64, 80)}, {"iterations": 3}),
        ({"texture": image("gravel", 96, 96), "target": image("camera", 48, 48)}, {"rule": "sampled", "tile": True}),
        ({"texture": image("brick", 80, 80)}, {"size": [96, 96], "block": 16, "poisson": True, "rule": "epsilon"}),
        ({"texture": image("brick", 80, 80)}, {"size": [96, 96], "block": 16, "poisson": True, "rule": "sampled"}),
        ({"texture": image("chelsea", 80, 80)}, {"size": [96, 96], "block": 16, "poisson": True, "tol": 40}),
        ({"texture": image("brick", 80, 80)}, {"size": [96, 96], "block": 16, "mode": "overlap", "tol": 3}),
    ],
    "nfpt": [({"photo": image("perspective")}, {"lines": LINES, "size": [160, 120]}),
             ({"photo": image("perspective")}, {"lines": LINES, "size": [96, 96], "warp": "lines"})],
    "affine": [({"texture": image("brick")}, {"boundary": "shaker"}),
               ({"texture": image("chelsea", 96, 96)}, {"boundary": "partial", "block": 16})],
    "fast": [({"texture": image("gravel"), "target": image("camera", 64, 64)}, {}),
             ({"texture": image("hatching", 64, 64), "target": image("chelsea", 48, 48)},
              {"metric": "artistic", "p": 0.2}),
             ({"texture": image("cat-fur", 64, 64)}, {"size": [80, 80]})],
    "rectify": [({"photo": image("perspective")}, {"lines": LINES, "warp": "lines"})],
    "fill": [({"image": image("gravel", 64, 64), "mask": np.pad(np.ones((20, 24), np.float32), ((20, 24), (16, 24)))},
              {}),
             ({"image": image("chelsea", 48, 48)}, {"extend": [8, 0, 8, 4], "engine": "quilt"}),
             ({"image": np.dstack([image("brick", 48, 48), np.pad(np.zeros((16, 16), np.float32), 16,
                                                                  constant_values=1)])}, {"patch": 9, "band": 3}),
             ({"image": image("gravel", 48, 48), "mask": np.pad(np.ones((16, 16), np.float32), 16),
               "texture": image("brick", 40, 40)}, {"engine": "hybrid", "patch": 8}),
             ({"image": image("chelsea", 64, 64), "mask": np.pad(np.ones((16, 20), np.float32), ((20, 28), (20, 24)))},
              {"engine": "patchmatch"})],
    "blend": [({"foreground": image("gravel", 64, 64), "background": image("camera", 64, 64),
                "mask": np.pad(np.ones((32, 32), np.float32), 16)}, {"mode": "poisson"})],
}

def signatures():
    from numba.core.registry import CPUDispatcher
    out = {}
    for info in pkgutil.iter_modules(weft.core._kernels.__path__):
        module = sys.modules.get("weft.core._kernels." + info.name)
        if module is None:  # not imported by this method
            continue
        for name, obj in vars(module).items():
            if isinstance(obj, CPUDispatcher) and obj.py_func.__module__ == module.__name__:
                out[f"{info.name}.{name}"] = sorted(str(s) for s in obj.signatures)
    return out

method = registry.get(sys.argv[1])
method.warm_up()
before = signatures()
for inputs, params in RUNS[method.name]:
    method.run(inputs, method.params.from_dict(params), rng=1)
print(json.dumps({"before": before, "after": signatures()}))
"""


def _signatures(method: str) -> tuple[dict, dict]:
    proc = subprocess.run([sys.executable, "-c", _SCRIPT, method], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    return out["before"], out["after"]


@pytest.mark.slow
def test_fill_runs_no_kernel_at_all():
    """Every fill engine runs in numpy and OpenCV: warm-up and the runs load no numba kernel."""
    before, after = _signatures("fill")
    assert before == {} and after == {}


@pytest.mark.slow
@pytest.mark.parametrize("method", ["quilt", "nfpt", "affine", "fast", "rectify", "blend"])
def test_a_run_after_warm_up_compiles_nothing_and_each_kernel_once(method):
    before, after = _signatures(method)
    assert before, "warm_up() loaded no kernel"
    new = {name: sorted(set(sigs) - set(before.get(name, []))) for name, sigs in after.items()}
    assert {name: sigs for name, sigs in new.items() if sigs} == {}
    several = {name: sigs for name, sigs in after.items() if len(sigs) > 1}
    assert several == {}
