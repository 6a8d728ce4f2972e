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

# Modules that define a module-level ``METHOD``; imported on first use.
_MODULES = ("core.quilting", "core.fast", "core.blending", "core.rectify", "core.nfpt", "core.affine")


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


_registry: dict[str, Method] | None = None


def methods() -> dict[str, Method]:
    """All registered methods by name, in registration order."""
    global _registry
    if _registry is None:
        reg = {}
        for mod in _MODULES:
            m = importlib.import_module(mod).METHOD
            reg[m.name] = m
        _registry = reg
    return _registry


def get(name: str) -> Method:
    """The method called ``name``; ``WeftError`` listing the known ones otherwise."""
    reg = methods()
    if name not in reg:
        raise WeftError(f"unknown method {name!r} (known: {', '.join(reg)})")
    return reg[name]


def warm_up_all() -> None:
    """Run every method's ``warm_up`` (for a background thread at GUI start)."""
    for method in methods().values():
        if method.warm_up is not None:
            method.warm_up()
