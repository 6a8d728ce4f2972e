"""The methods weft offers, as the CLI and GUI see them.

A method module (``core/quilting.py``, ...) builds one :class:`Method` and the registry lists the
modules to import; the CLI turns each into a subcommand (inputs become positionals or options,
parameters become options generated from the ``Params`` specs) and ``weft run`` finds a recipe's
method here. Adding a method = writing its module + one line in ``_MODULES`` (or, at run time,
:func:`register`). A method the studio offers says so, and what it needs, in ``Method.studio``
(:class:`weft.core.studio.Studio`).
"""

from __future__ import annotations

import importlib
import threading
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .compiles import (  # re-exported: front ends read compiles through the registry
    CompileWatch,
    compile_ended,
    compile_started,
    compiling,
    kernel_cache_notice,
    kernel_cache_repairs,
    note_kernel_cache,
    note_kernel_cache_repair,
    watch_compiles,
)
from .errors import WeftError
from .params import Params
from .studio import Studio

# The public names, those of weft.core.compiles included (documented here).
__all__ = [
    "InputSpec",
    "Result",
    "Method",
    "register",
    "unregister",
    "studio_methods",
    "names",
    "methods",
    "get",
    "PREPARING",
    "LOADING",
    "preparing_text",
    "loading_text",
    "is_warm",
    "warm_up",
    "warm_up_all",
    "warm_up_report",
    "CompileWatch",
    "watch_compiles",
    "compiling",
    "compile_started",
    "compile_ended",
    "note_kernel_cache",
    "note_kernel_cache_repair",
    "kernel_cache_repairs",
    "kernel_cache_notice",
]

# Method name -> the module that defines it as a module-level ``METHOD``; imported on first use, one
# at a time where possible (``weft quilt`` need not import the affine model's FFT machinery).
_MODULES = {
    "quilt": "weft.core.quilting",
    "fast": "weft.core.fast",
    "blend": "weft.core.blending",
    "rectify": "weft.core.rectify",
    "nfpt": "weft.core.nfpt",
    "affine": "weft.core.affine",
    "fill": "weft.core.fill",
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
    #: Keep an alpha channel when the file has one (``load_image(..., alpha=True)``): the method then
    #: gets (H, W, 2) grey+alpha or (H, W, 4) RGBA. Off for every method but ``fill`` (a transparent
    #: region is its hole); the others get alpha dropped.
    alpha: bool = False

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
    ``studio``, when given, puts the method in the studio (:class:`weft.core.studio.Studio`).
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
    #: a batch multiplies it by its workers to refuse up front (:mod:`weft.core.batch`). None: no estimate.
    #: It is called with this method's own ``params`` class, hence ``Any`` (Callable is contravariant).
    memory: Callable[[Mapping[str, tuple[int, ...]], Any], float] | None = None
    studio: Studio | None = None
    #: The input whose bit depth (8 or 16) the command line's output keeps when ``--bit-depth`` is not
    #: given (``fill``: a 16-bit photo stays 16-bit; its known pixels come back unchanged). None: 8.
    depth_from: str | None = None
    #: Whether a run may crop the first input to a source square (``--region X,Y,S``, a recipe's
    #: ``region``). ``fill`` does not: its first input is the image whose hole it fills, not a source.
    takes_region: bool = True


_loaded: dict[str, Method] = {}


def register(method: Method) -> None:
    """Add a method at run time (a plug-in, a test).

    The CLI, ``weft run`` and, with a ``studio`` description, the studio offer it like the built-in ones.

    Parameters
    ----------
    method : Method
        The method; its ``name`` must be new.

    Raises
    ------
    WeftError
        A method of that name is registered already.
    """
    if method.name in _MODULES:
        raise WeftError(f"a method called {method.name!r} is registered already")
    _MODULES[method.name] = ""
    _loaded[method.name] = method


def unregister(name: str) -> None:
    """Remove a method added by :func:`register`.

    Parameters
    ----------
    name : str
        The method's name; a built-in method or an unknown name is left alone.
    """
    if _MODULES.get(name) == "":
        del _MODULES[name]
        _loaded.pop(name, None)


def studio_methods() -> dict[str, Method]:
    """The methods the studio offers, in its order (``Studio.rank``, then registration)."""
    offered = [m for m in methods().values() if m.studio is not None]
    return {m.name: m for m in sorted(offered, key=lambda m: m.studio.rank if m.studio else 0)}


def names() -> tuple[str, ...]:
    """The registered method names, without importing any method module."""
    return tuple(_MODULES)


def methods() -> dict[str, Method]:
    """All registered methods by name, in registration order (imports every method module)."""
    return {name: get(name) for name in _MODULES}


def get(name: str) -> Method:
    """The method called ``name``, importing its module only.

    Parameters
    ----------
    name : str
        A registered method's name (``weft`` + name on the command line).

    Returns
    -------
    Method

    Raises
    ------
    WeftError
        No such method; the message lists the known ones.
    """
    if name not in _MODULES:
        raise WeftError(f"unknown method {name!r} (known: {', '.join(_MODULES)})")
    if name not in _loaded:
        method = importlib.import_module(_MODULES[name]).METHOD
        if method.name != name:
            raise RuntimeError(f"{_MODULES[name]} defines method {method.name!r}, registered as {name!r}")
        _loaded[name] = method
    return _loaded[name]


# --- warm-up: loading (or compiling) the methods' kernels ahead of their first run -------------------
#
# ``warm_up(name)`` runs a method's ``warm_up`` at most once per process (concurrent callers wait for
# the one running it); ``is_warm(name)`` then tells a front end that the method's kernels are loaded,
# so a render can be timed without them. Whether a real compile is happening (a first run: numba's
# cache is cold) is known from numba's compile events (:mod:`weft.core.compiles`, re-exported here).

#: What a front end shows while a method's kernels compile (``{name}`` is the method's name) ...
PREPARING = "preparing the {name} method — first run only"
#: ... and while they load, before it is known whether they compile (numba's import alone takes a while).
LOADING = "loading the {name} method"

_warm: set[str] = set()
_warm_locks: dict[str, threading.Lock] = {}
_warm_lock = threading.Lock()


def preparing_text(name: str) -> str:
    """The words a front end shows while ``name``'s kernels compile.

    Parameters
    ----------
    name : str
        The method's name.

    Returns
    -------
    str
    """
    return PREPARING.format(name=get(name).name)


def loading_text(name: str) -> str:
    """The words a front end shows while ``name``'s kernels load (from the cache or compiled: not known yet).

    Parameters
    ----------
    name : str
        The method's name.

    Returns
    -------
    str
    """
    return LOADING.format(name=get(name).name)


def is_warm(name: str) -> bool:
    """Whether ``name``'s kernels are loaded in this process.

    Parameters
    ----------
    name : str
        The method's name.

    Returns
    -------
    bool
        True once its ``warm_up`` has run here, or when it has none.
    """
    return name in _warm or get(name).warm_up is None


def warm_up(name: str) -> bool:
    """Run ``name``'s ``warm_up`` unless it already ran in this process.

    Thread-safe: a second caller waits for the first one to finish rather than warming up twice.

    Parameters
    ----------
    name : str
        The method's name.

    Returns
    -------
    bool
        True if it ran here (in this call).
    """
    method = get(name)
    if method.warm_up is None or name in _warm:
        return False
    with _warm_lock:
        lock = _warm_locks.setdefault(name, threading.Lock())
    with lock:
        if name in _warm:
            return False
        method.warm_up()
        _warm.add(name)
    return True


def warm_up_all(first: str | None = None, cancel=None) -> list[str]:
    """Warm up every method not yet warm, for a background thread in the studio.

    Parameters
    ----------
    first : str, optional
        The method warmed up before the others (the rest in registration order).
    cancel : CancelToken, optional
        Checked between methods.

    Returns
    -------
    list of str
        The names warmed up here.
    """
    order = ([first] if first in _MODULES else []) + [n for n in _MODULES if n != first]
    done = []
    for name in order:
        if cancel is not None:
            cancel.raise_if_cancelled()
        if warm_up(name):
            done.append(name)
    return done


def warm_up_report(name: str) -> dict[str, Any]:
    """Warm ``name`` up in this process and say what happened, for ``weft warm-up``'s worker processes.

    Parameters
    ----------
    name : str
        The method's name.

    Returns
    -------
    dict
        ``{"method", "seconds", "compiled", "notice"}`` with ``compiled`` the number of kernels
        compiled (0: all loaded from the cache) and ``notice`` what the kernel cache said, if anything.
    """
    import time

    t0 = time.perf_counter()
    with watch_compiles() as watch:
        warm_up(name)
    return {
        "method": name,
        "seconds": time.perf_counter() - t0,
        "compiled": watch.count,
        "notice": kernel_cache_notice(),
        "repairs": kernel_cache_repairs(),
    }
