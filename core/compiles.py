"""numba compilations as they happen, and what became of the kernel cache.

``weft.core._kernels`` forwards numba's compile events here (:func:`compile_started`,
:func:`compile_ended`) and the cache's troubles (:func:`note_kernel_cache`,
:func:`note_kernel_cache_repair`); :func:`watch_compiles` counts the compilations of a block and
their time, :func:`compiling` tells whether one is under way. A cache load is no compilation.
This module imports neither numba nor any method, so a front end can ask it at any time.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from contextlib import contextmanager

_watchers: list[CompileWatch] = []
_watch_lock = threading.Lock()
_compiles_running = 0
_cache_notes: list[str] = []


class CompileWatch:
    """numba compilations seen while a :func:`watch_compiles` block runs: ``count`` (every function
    compiled, the kernels a kernel calls included) and ``seconds`` (wall time of the outermost
    compiles, which contain the nested ones)."""

    def __init__(self, thread: int | None, on_start: Callable[[], None] | None) -> None:
        self.thread = thread
        self.on_start = on_start
        self.count = 0
        self.seconds = 0.0
        self._started: dict[int, float] = {}

    def _start(self, thread: int, now: float, outermost: bool) -> None:
        self.count += 1
        if outermost:
            self._started[thread] = now
            if self.on_start is not None:
                self.on_start()

    def _end(self, thread: int, now: float, outermost: bool) -> None:
        started = self._started.pop(thread, None) if outermost else None
        if started is not None:
            self.seconds += now - started


@contextmanager
def watch_compiles(*, this_thread: bool = False, on_start: Callable[[], None] | None = None):
    """Count numba compilations (and their time) while the block runs.

    A cache load is no compilation: a warm run sees none.

    Parameters
    ----------
    this_thread : bool, default False
        Count only the calling thread's compilations (else any thread's).
    on_start : callable, optional
        Called with no arguments, on the compiling thread, as each one starts.

    Yields
    ------
    object
        A watcher with ``count`` and ``seconds``, updated as compilations end.
    """
    watch = CompileWatch(threading.get_ident() if this_thread else None, on_start)
    with _watch_lock:
        _watchers.append(watch)
    try:
        yield watch
    finally:
        with _watch_lock:
            _watchers.remove(watch)


def compiling() -> bool:
    """Whether a numba compilation is under way in some thread of this process."""
    return _compiles_running > 0


def _notify(started: bool, outermost: bool) -> None:
    import time

    global _compiles_running
    now = time.perf_counter()
    me = threading.get_ident()
    with _watch_lock:
        if outermost:
            _compiles_running += 1 if started else -1
        watchers = [w for w in _watchers if w.thread is None or w.thread == me]
    for w in watchers:
        (w._start if started else w._end)(me, now, outermost)


def compile_started(outermost: bool = True) -> None:
    """Called by ``weft.core._kernels`` when a thread starts compiling a function (a cache miss).

    Parameters
    ----------
    outermost : bool, default True
        Not a function compiled inside another one's compile.
    """
    _notify(True, outermost)


def compile_ended(outermost: bool = True) -> None:
    """Called by ``weft.core._kernels`` when that compilation ends.

    Parameters
    ----------
    outermost : bool, default True
        As given to :func:`compile_started`.
    """
    _notify(False, outermost)


def note_kernel_cache(message: str) -> None:
    """Called by ``weft.core._kernels`` when numba's cache cannot be used (the first message is kept).

    Parameters
    ----------
    message : str
        One line for the front ends to show.
    """
    if message not in _cache_notes:
        _cache_notes.append(message)


_cache_repairs: list[str] = []


def note_kernel_cache_repair(message: str) -> None:
    """Called by ``weft.core._kernels`` when it dropped a damaged cache entry (the first message is kept).

    Parameters
    ----------
    message : str
        One line for the front ends to show.
    """
    if message not in _cache_repairs:
        _cache_repairs.append(message)


def kernel_cache_repairs() -> list[str]:
    """One-line notices of damaged kernel cache entries dropped (and compiled again) in this process."""
    return list(_cache_repairs)


def kernel_cache_notice() -> str | None:
    """A one-line notice if the kernels run without numba's on-disk cache (no writable folder)."""
    return _cache_notes[0] if _cache_notes else None
