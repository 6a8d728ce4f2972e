"""What crosses to a batch's worker and back (plain, picklable values): an item, its outcome, the
plan of a batch, its summary and its progress.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any


@dataclass(frozen=True)
class Item:
    """One output of a batch: everything a worker needs, with absolute paths.

    ``inputs`` are the files to read (``shipped`` holds their bytes when the client sends them);
    ``recipe`` is the JSON text the output carries (paths relative to the output's folder, as
    ``weft run`` writes it); ``write`` says whether the worker writes ``output`` itself or returns the
    encoded bytes for the client to write.
    """

    index: int
    label: str
    method: str
    params: Mapping[str, Any]
    inputs: Mapping[str, str]
    seed: int
    region: tuple[int, int, int] | None
    output: str
    recipe: str
    bit_depth: int = 8
    write: bool = True
    shipped: Mapping[str, bytes] | None = None
    #: OpenCV threads in the worker process (local pool: the cores shared out among the workers, so
    #: two workers on two cores do not each start two threads); None leaves OpenCV's default. The
    #: pixels do not depend on it (checked for every method: 1 and 2 threads give the same bytes).
    threads: int | None = None


@dataclass(frozen=True)
class Outcome:
    """What became of one item: ``status`` is ``"written"``, ``"skipped"`` (its output already
    exists with this recipe) or ``"failed"`` (``error`` says why, in one line)."""

    index: int
    label: str
    output: str
    status: str
    error: str | None = None
    seconds: float = 0.0
    figures: Mapping[str, Any] = field(default_factory=dict)
    worker: str = ""
    data: bytes | None = None
    #: The item's whole time on its worker: reading, running, encoding, writing (``seconds`` is the
    #: method's compute alone, as ``weft run --report`` gives it), and the CPU time its process used
    #: meanwhile (all its threads).
    elapsed: float = 0.0
    cpu: float = 0.0

    def report(self) -> dict:
        """The item's ``--report`` line (without the encoded bytes)."""
        line = {"index": self.index, "input": self.label, "output": self.output, "status": self.status}
        if self.error is not None:
            line["error"] = self.error
        if self.status == "written":
            line["seconds"] = round(self.seconds, 6)
            line["elapsed"] = round(self.elapsed, 6)
            line["cpu"] = round(self.cpu, 6)
            line["worker"] = self.worker
            line.update(self.figures)
        return line


@dataclass(frozen=True)
class Plan:
    """A checked batch: every item in order, and which of them are already done."""

    items: tuple[Item, ...]
    skipped: tuple[Item, ...]
    method: str
    seed: int
    ship_inputs: bool = False  # read each item's inputs here and send their bytes (just before it is submitted)

    @property
    def todo(self) -> tuple[Item, ...]:
        done = {i.index for i in self.skipped}
        return tuple(i for i in self.items if i.index not in done)


@dataclass
class Summary:
    """The end of a batch: counts, failures (index, label, reason) in item order, wall time."""

    total: int
    written: int = 0
    skipped: int = 0
    failed: list[tuple[int, str, str]] = field(default_factory=list)
    cancelled: bool = False
    seconds: float = 0.0

    @property
    def done(self) -> int:
        return self.written + self.skipped + len(self.failed)

    def line(self, most: int = 3) -> str:
        """``898 written, 2 failed: frame_0312.png: truncated PNG …``"""
        parts = [f"{self.written} written"]
        if self.skipped:
            parts.append(f"{self.skipped} already done")
        if self.cancelled:
            parts.append(f"{self.total - self.done} not done (cancelled)")
        text = ", ".join(parts)
        if self.failed:
            reasons = "; ".join(f"{label}: {reason}" for _, label, reason in self.failed[:most])
            more = f"; and {len(self.failed) - most} more" if len(self.failed) > most else ""
            text += f", {len(self.failed)} failed: {reasons}{more}"
        return text

    def report(self) -> dict:
        """The summary ``--report`` line."""
        return {
            "summary": True,
            "total": self.total,
            "written": self.written,
            "skipped": self.skipped,
            "failed": len(self.failed),
            "cancelled": self.cancelled,
            "seconds": round(self.seconds, 3),
            "items_per_second": round(self.written / self.seconds, 4) if self.seconds > 0 else None,
        }


class BatchProgress:
    """Progress of a running batch, handed to :func:`run`'s ``progress`` after each item."""

    __slots__ = ("total", "done", "failed", "started", "_timed", "_first")
    _first: float | None

    def __init__(self, total: int, skipped: int):
        self.total, self.done, self.failed = total, skipped, 0
        self.started = time.monotonic()
        self._timed, self._first = 0, None

    def _add(self, outcome: Outcome) -> None:
        self.done += 1
        self.failed += outcome.status == "failed"
        if outcome.status != "skipped":
            self._timed += 1
            if self._first is None:
                self._first = time.monotonic()

    @property
    def seconds_left(self) -> float | None:
        """Time left at the rate items have completed since the first one (so the workers' start-up
        does not count); None before two are done."""
        if self._timed < 2 or self._first is None:
            return None
        rate = (self._timed - 1) / max(1e-9, time.monotonic() - self._first)
        return (self.total - self.done) / rate
