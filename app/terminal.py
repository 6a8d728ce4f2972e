"""What ``weft METHOD`` writes on a terminal while it runs: a progress bar, and a line saying that
kernels are compiling (a first run). Both write only when stderr is a terminal."""

from __future__ import annotations

import sys
import threading
import time


class TerminalProgress:
    """A one-line progress bar on stderr, drawn only when stderr is a terminal. It owns that line:
    a :class:`PreparingLine` ticking on it is ended (kept, with a newline) as the bar first draws."""

    wants_preview = False  # it draws the fraction only: algorithms need not build partial images

    def __init__(self, enabled: bool):
        self.enabled = enabled and sys.stderr.isatty()
        self.drawn = False
        self.lock = threading.Lock()  # the preparing line ticks from its own thread
        self.line_open = False  # a preparing line without its newline yet

    def __call__(self, p) -> None:
        if not self.enabled:
            return
        width = 30
        filled = int(round(p.fraction * width))
        with self.lock:
            self._end_line()
            sys.stderr.write(f"\r{p.stage:<14} [{'#' * filled}{' ' * (width - filled)}] {p.fraction * 100:3.0f}%")
            sys.stderr.flush()
            self.drawn = True

    def _end_line(self) -> None:
        if self.line_open:
            sys.stderr.write("\n")
            self.line_open = False

    def close(self) -> None:
        with self.lock:
            self._end_line()
            if self.drawn:
                sys.stderr.write("\n")
                self.drawn = False
            sys.stderr.flush()


class PreparingLine:
    """Says on stderr that kernels are being compiled — the first run's long silent stretch (a cold
    quilting transfer compiled for 39 s before its first progress report) — and keeps the line alive
    with the seconds spent, every ``TICK`` s (never a second of silence), until the progress bar takes
    over or the run ends.

    Called from numba's compile events (``registry.watch_compiles``), i.e. only when a kernel really
    compiles: a run that loads every kernel from numba's cache says nothing. Like the progress bar it
    writes to a terminal only: stderr that is a file or a pipe belongs to scripts, for which weft
    promises silence on success and exactly one line on failure (a ticking ``\r`` line would be
    noise in a log); installers, render nodes and CI run ``weft warm-up`` first, which prints on
    stdout what it compiled. ``wait(seconds) -> stopped`` is injectable for tests.
    """

    TICK = 0.5

    def __init__(self, method: str, bar: TerminalProgress, wait=None):
        self.method = method
        self.bar = bar
        self.said = False
        self._stop = threading.Event()
        self._wait = wait if wait is not None else self._stop.wait
        self.thread: threading.Thread | None = None

    def text(self) -> str:
        from weft.core import registry

        if registry.kernel_cache_notice() is not None:
            return f"weft: compiling the {self.method} method's kernels (no cache: every run)"
        return f"weft: {registry.preparing_text(self.method)} (compiling kernels)"  # < 80 columns

    def __call__(self) -> None:
        with self.bar.lock:
            if self.said or not self.bar.enabled:
                return
            self.said = True
            text = self.text()
            if self.bar.drawn:  # a bar already drawn keeps its line; this one goes below it
                sys.stderr.write("\n")
                self.bar.drawn = False
            sys.stderr.write(text)
            sys.stderr.flush()
            self.bar.line_open = True
        self.thread = threading.Thread(
            target=self._tick, args=(text, time.monotonic()), daemon=True, name="weft-preparing"
        )
        self.thread.start()

    def _tick(self, text: str, since: float) -> None:
        while not self._wait(self.TICK):
            with self.bar.lock:
                if not self.bar.line_open:
                    return  # the bar took over, or the run ended
                sys.stderr.write(f"\r{text} {time.monotonic() - since:.0f} s")
                sys.stderr.flush()

    def stop(self) -> None:
        self._stop.set()
        if self.thread is not None and self.thread is not threading.current_thread():
            self.thread.join()
