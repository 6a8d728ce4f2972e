"""Render a benchmark results file (``benchmarks/results/<suite>.json``) as an RST table.

A results file is one JSON object (``benchmarks/record.py`` writes it): ``suite``, ``command``,
``date``, ``machine`` (a mapping, or a line of text), ``quick``, ``note`` and ``rows``, a list of
objects. A bare list of rows is read too. :func:`render` makes a paragraph saying where and how the
figures were taken, then one table: the columns the suite's :data:`SUITES` entry names, or, for a
suite without an entry, every key whose values are numbers or text. Adding a suite's page is one
entry here and one ``.. weft-results:: SUITE`` line on a page.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

RESULTS = Path(__file__).resolve().parents[2] / "benchmarks" / "results"


@dataclass(frozen=True)
class Column:
    """One column: the row key, its header, and how a value reads (a format string or a function)."""

    key: str
    header: str
    fmt: str | Callable[[Any], str] = "{}"

    def cell(self, row: dict) -> str:
        if self.key not in row or row[self.key] is None:
            return ""
        value = row[self.key]
        if callable(self.fmt):
            return self.fmt(value)
        try:
            return self.fmt.format(value)
        except (ValueError, TypeError, IndexError, KeyError):
            return str(value)


@dataclass(frozen=True)
class Suite:
    """How a suite's table reads: its columns, the command to run it, and a sentence about it."""

    columns: tuple[Column, ...]
    command: str = ""
    about: str = ""
    keep: Callable[[dict], bool] | None = None


def _size(v) -> str:
    return f"{v[0]}x{v[1]}" if isinstance(v, (list, tuple)) and len(v) == 2 else str(v)


def _pct(v) -> str:
    return f"{100 * v:.0f} %"


def _yes(v) -> str:
    return "yes" if v else "**no**"


_METHOD_TIMES = (
    Column("case", "case"), Column("size", "output", _size), Column("median_s", "median s", "{:.3f}"),
    Column("min_s", "min s", "{:.3f}"), Column("peak_mib", "peak MiB (numpy)", "{:.0f}"),
    Column("speedup_2_threads", "2 jobs at once", "{:.2f}x"),
    Column("weft_process_s", "whole weft process s", "{:.2f}"),
    Column("gmic_process_s", "whole G'MIC process s", "{:.2f}"),
)
_QUALITY = (
    Column("case", "case"), Column("coherence", "coherence", "{:.4f}"),
    Column("completeness", "completeness", "{:.4f}"), Column("fidelity", "fidelity", "{:.3f}"),
    Column("coherence_median", "coherence, median of seeds", "{:.4f}"),
    Column("completeness_median", "completeness, median of seeds", "{:.4f}"),
    Column("verbatim_max", "largest verbatim copy (of the sample)", "{:.3f}"),
    Column("snr_db", "SNR dB", "{:.1f}"), Column("psnr_db", "PSNR dB", "{:.1f}"),
    Column("psnr_cubic_db", "cubic PSNR dB", "{:.1f}"),
)

SUITES: dict[str, Suite] = {
    "methods": Suite(_METHOD_TIMES, "python -m benchmarks 'quilt-*' 'fast-*' 'rectify-*' 'nfpt-*' 'affine-*'",
                     "Compute time of one run with the inputs decoded (the studio's and the batch's cost); "
                     "the whole-process columns time the ``weft`` command against G'MIC on the same file."),
    "methods/quality": Suite(_QUALITY, "python -m benchmarks 'quilt-*' 'fast-*' 'nfpt-*' 'affine-*'",
                             "Quality figures of the same runs (``weft.core.metrics``): coherence and "
                             "completeness lower is better, fidelity, SNR and PSNR higher."),
    "batch": Suite((
        Column("recipe", "recipe"), Column("pool", "pool"), Column("items_per_s", "items/s", "{:.2f}"),
        Column("vs_one_worker", "vs 1 worker", "{:.2f}x"), Column("item_s", "s per item on its worker", "{:.3f}"),
        Column("item_cpu_s", "CPU s per item", "{:.3f}"), Column("busy", "workers busy", _pct),
        Column("startup_s", "pool start s", "{:.1f}"), Column("load_avg", "load average", "{:.1f}")),
        "python -m benchmarks.batch",
        "``weft batch`` over frames of 640x480 on local worker processes and on a local Dask cluster."),
    "memory": Suite((
        Column("job", "job"), Column("peak_mib", "peak resident memory MiB", "{:.0f}"),
        Column("seconds", "wall s", "{:.1f}"), Column("under_2_gib", "under 2 GiB", _yes)),
        "python -m benchmarks.memory", "Peak resident memory of the whole ``weft`` process on large jobs."),
    "cold": Suite((
        Column("command", "command"), Column("cold_s", "first run s", "{:.1f}"), Column("warm_s", "later runs s", "{:.1f}"),
        Column("ratio", "first / later", "{:.1f}x"), Column("cold_first_words_s", "first words s", "{:.1f}"),
        Column("cold_silent_s", "longest silence s", "{:.1f}")),
        "python -m benchmarks.cold",
        "A first run compiles the method's kernels into numba's cache; later runs load them "
        "(``weft warm-up`` does the first run ahead of time)."),
    "gui_latency": Suite((
        Column("measure", "what"), Column("median_ms", "median latency ms", "{:.0f}"),
        Column("p95_ms", "95th percentile ms", "{:.0f}"), Column("max_stall_ms", "longest GUI stall ms", "{:.0f}"),
        Column("previews", "previews shown"), Column("values", "values / moves"), Column("method", "method")),
        "python -m benchmarks.gui_latency",
        "From a slider's change (or a brush's mouse move) to the preview on screen, in the real window."),
}


def _parts(name: str) -> tuple[str, str, str]:
    """``FILE[/VIEW][:KEY=VALUE]`` -> (file stem, description name, filter)."""
    head, _, flt = name.partition(":")
    base, _, view = head.partition("/")
    return base, head if view else base, flt


def results_path(name: str) -> Path:
    return RESULTS / f"{_parts(name)[0]}.json"


def load(suite: str) -> dict | None:
    """The results file of ``suite`` as a dict with ``rows``, or None when there is none (or it is unreadable)."""
    path = results_path(suite)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if isinstance(data, list):
        data = {"rows": data}
    if not isinstance(data, dict) or not isinstance(data.get("rows"), list):
        return None
    data["rows"] = [r for r in data["rows"] if isinstance(r, dict)]
    return data


def _machine(m) -> str:
    if isinstance(m, dict):
        bits = [m.get("cpu"), f"{m['cores']} cores" if m.get("cores") else None,
                f"{m['memory_gib']} GiB" if m.get("memory_gib") else None, m.get("system"),
                f"Python {m['python']}" if m.get("python") else None,
                f"load average {m['load_average']}" if m.get("load_average") is not None else None]
        return ", ".join(str(b) for b in bits if b)
    return str(m) if m else "not recorded"


def _generic_columns(rows: list[dict]) -> tuple[Column, ...]:
    keys: list[str] = []
    for r in rows:
        for k, v in r.items():
            if k not in keys and (isinstance(v, (str, bool, int)) or (isinstance(v, float) and math.isfinite(v))):
                keys.append(k)

    def fmt(v):
        return f"{v:.4g}" if isinstance(v, float) else str(v)

    return tuple(Column(k, k.replace("_", " "), fmt) for k in keys)


def _rst_escape(text: str) -> str:
    return str(text).replace("\\", "\\\\").replace("*", "\\*").replace("|", "\\|").replace("`", "\\`")


def render(name: str) -> list[str]:
    """RST lines for ``name``: ``FILE[/VIEW][:KEY=VALUE]``. FILE is the results file's stem, VIEW
    picks another table description of the same file (:data:`SUITES` under ``FILE/VIEW``), and
    ``KEY=VALUE`` keeps the rows whose ``KEY`` reads ``VALUE``."""
    base, described, flt = _parts(name)
    suite = SUITES.get(described) or SUITES.get(base)
    data = load(base)
    command = (data or {}).get("command") or (suite.command if suite else f"python -m benchmarks.{base}")
    if data is None:
        return [f".. note:: No results file ``benchmarks/results/{base}.json`` yet: "
                f"run ``{command}`` to make it.", ""]
    rows = data["rows"]
    if flt and "=" in flt:
        key, value = flt.split("=", 1)
        rows = [r for r in rows if str(r.get(key)) == value]
    columns = suite.columns if suite else _generic_columns(rows)
    columns = tuple(c for c in columns if any(c.key in r for r in rows))
    lines = []
    if suite and suite.about:
        lines += [suite.about, ""]
    quick = " A quick run (smaller inputs, fewer repeats)." if data.get("quick") else ""
    note = f" {_rst_escape(data['note'])[0].upper()}{_rst_escape(data['note'])[1:]}." if data.get("note") else ""
    lines += [f"Measured {data.get('date', 'at an unrecorded date')} on {_rst_escape(_machine(data.get('machine')))}."
              f"{note}{quick} Reproduce with ``{command}`` "
              f"(file ``benchmarks/results/{base}.json``).", ""]
    if not rows or not columns:
        return lines + ["The file has no rows to show.", ""]
    from weft_docs import list_table

    table = [[_rst_escape(c.cell(r)) for c in columns] for r in rows]
    return lines + list_table([c.header for c in columns], table)
