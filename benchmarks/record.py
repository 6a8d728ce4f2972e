"""The results file every benchmark suite writes: ``benchmarks/results/<suite>.json``.

One JSON object per suite: the suite's name, the command that reproduces it, the machine and the
date it ran, whether it was a quick run, and its rows (one object per measured configuration). The
documentation renders its performance tables from these files (``docs/_ext/weft_results.py``).
"""

from __future__ import annotations

import datetime
import json
import os
import platform
import shlex
import sys
from pathlib import Path
from typing import Any

RESULTS = Path(__file__).resolve().parent / "results"


def machine() -> dict[str, Any]:
    """The machine a suite ran on: processor, cores, memory, system, Python, the load average."""
    info: dict[str, Any] = {
        "cpu": _cpu_name(),
        "cores": os.cpu_count(),
        "system": f"{platform.system()} {platform.release()}",
        "python": platform.python_version(),
    }
    try:
        pages, size = os.sysconf("SC_PHYS_PAGES"), os.sysconf("SC_PAGE_SIZE")
        info["memory_gib"] = round(pages * size / 2**30, 1)
    except (ValueError, OSError, AttributeError):
        pass
    if hasattr(os, "getloadavg"):
        info["load_average"] = round(os.getloadavg()[0], 2)
    return info


def _cpu_name() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def command(module: str, argv: list[str] | None) -> str:
    """The command line that ran this suite (``python -m MODULE ARGS``)."""
    args = sys.argv[1:] if argv is None else list(argv)
    return " ".join(["python", "-m", module, *(shlex.quote(a) for a in args)])


def write_results(
    suite: str,
    rows: list[dict[str, Any]],
    *,
    command: str,
    quick: bool = False,
    note: str = "",
    path: Path | None = None,
) -> Path:
    """Write ``rows`` with the machine, the date and ``command`` to ``benchmarks/results/<suite>.json``.

    ``note`` says what the figures mean or under which conditions they were taken (e.g. a machine
    shared with other work); the environment variable ``WEFT_BENCH_NOTE`` adds to it. Returns the
    path written.
    """
    extra = os.environ.get("WEFT_BENCH_NOTE", "").strip()
    note = "; ".join(n for n in (note, extra) if n)
    path = RESULTS / f"{suite}.json" if path is None else Path(path)
    payload = {
        "suite": suite,
        "command": command,
        "date": datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M UTC"),
        "machine": machine(),
        "quick": quick,
        "note": note,
        "rows": rows,
    }
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(payload, indent=1) + "\n", encoding="utf-8")
    tmp.replace(path)
    return path
