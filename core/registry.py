"""The methods weft offers, as the CLI and GUI see them.

A method module (``core/quilting.py``, ...) builds one :class:`Method` and the registry lists the
modules to import; the CLI turns each into a subcommand (inputs become positionals or options,
parameters become options generated from the ``Params`` specs) and ``weft run`` finds a recipe's
method here. Adding a method = writing its module + one line in ``_MODULES``.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping

import numpy as np

from .errors import WeftError
from .params import Params

# Method name -> the module that defines it as a module-level ``METHOD``; imported on first use, one
# at a time where possible (``weft quilt`` need not import the affine model's FFT machinery).
_MODULES = {
    "quilt": "core.quilting",
    "fast": "core.fast",
    "blend": "core.blending",
    "rectify": "core.rectify",
    "nfpt": "core.nfpt",
    "affine": "core.affine",
}


@dataclass(frozen=True)
class InputSpec:
    """One image a method takes.

    On the command line a required input is positional unless ``positional=False`` (then it is a
    required ``--name IMAGE`` option, e.g. ``weft blend FG BG --mask MASK``); an optional input is
    always an option.
    """

    name: str
    help: str
    required: bool = True
    positional: bool | None = None
    #: The smallest width and height the method can use at all (with its most permissive
    #: parameters); front ends refuse a smaller image up front, naming its file.
    min_side: int = 1

    @property
    def is_positional(self) -> bool:
        return self.required if self.positional is None else (self.positional and self.required)


@dataclass(frozen=True)
class Result:
    """What a method returns: the image and cheap figures for ``--report`` (JSON-serialisable)."""

    image: np.ndarray
    figures: Mapping[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class Method:
    """A runnable method.

    ``run(inputs, params, *, rng, progress, cancel) -> Result`` where ``inputs`` maps input names
    to float32 images; it must honour ``cancel`` and report through ``progress``. ``warm_up()``, when
    given, loads the method's compiled kernels (from numba's on-disk cache, or compiling them) on
    tiny inputs, so that the first real run is not charged with it; the GUI calls it once in a
    background thread at start, the CLI before timing unless ``warm_up_in_cli`` is false (a method
    that can avoid its kernels on small inputs, such as quilting's numpy engine, would only pay).
    """

    name: str
    summary: str
    params: type[Params]
    inputs: tuple[InputSpec, ...]
    run: Callable[..., Result]
    warm_up: Callable[[], None] | None = None
    warm_up_in_cli: bool = True
    #: ``memory(shapes, params) -> bytes``: the estimated peak memory of one run on inputs of these
    #: shapes (input name -> array shape), the figure the run checks against the memory available;
    #: a batch multiplies it by its workers to refuse up front (:mod:`core.batch`). None: no estimate.
    memory: Callable[[Mapping[str, tuple[int, ...]], Params], float] | None = None


_loaded: dict[str, Method] = {}


def names() -> tuple[str, ...]:
    """The registered method names, without importing any method module."""
    return tuple(_MODULES)


def methods() -> dict[str, Method]:
    """All registered methods by name, in registration order (imports every method module)."""
    return {name: get(name) for name in _MODULES}


def get(name: str) -> Method:
    """The method called ``name`` (importing its module only); ``WeftError`` listing the known ones."""
    if name not in _MODULES:
        raise WeftError(f"unknown method {name!r} (known: {', '.join(_MODULES)})")
    if name not in _loaded:
        method = importlib.import_module(_MODULES[name]).METHOD
        if method.name != name:
            raise RuntimeError(f"{_MODULES[name]} defines method {method.name!r}, registered as {name!r}")
        _loaded[name] = method
    return _loaded[name]


def warm_up_all() -> None:
    """Run every method's ``warm_up`` (for a background thread at GUI start)."""
    for method in methods().values():
        if method.warm_up is not None:
            method.warm_up()
