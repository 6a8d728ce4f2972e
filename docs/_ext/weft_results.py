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
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

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
    rows: Callable[[dict], list[dict]] | None = None  # the table's rows made from the whole file


def _size(v) -> str:
    return f"{v[0]}x{v[1]}" if isinstance(v, (list, tuple)) and len(v) == 2 else str(v)


def _pct(v) -> str:
    return f"{100 * v:.0f} %"


def _yes(v) -> str:
    return "yes" if v else "**no**"


_METHOD_TIMES = (
    Column("case", "case"),
    Column("size", "output", _size),
    Column("median_s", "median s", "{:.3f}"),
    Column("min_s", "min s", "{:.3f}"),
    Column("peak_mib", "peak MiB (numpy)", "{:.0f}"),
    Column("speedup_2_threads", "2 jobs at once", "{:.2f}x"),
    Column("weft_process_s", "whole weft process s", "{:.2f}"),
    Column("gmic_process_s", "whole G'MIC process s", "{:.2f}"),
)
_QUALITY = (
    Column("case", "case"),
    Column("coherence", "coherence", "{:.4f}"),
    Column("completeness", "completeness", "{:.4f}"),
    Column("fidelity", "fidelity", "{:.3f}"),
    Column("coherence_median", "coherence, median of seeds", "{:.4f}"),
    Column("completeness_median", "completeness, median of seeds", "{:.4f}"),
    Column("verbatim_max", "largest verbatim copy (of the sample)", "{:.3f}"),
    Column("snr_db", "SNR dB", "{:.1f}"),
    Column("psnr_db", "PSNR dB", "{:.1f}"),
    Column("psnr_cubic_db", "cubic PSNR dB", "{:.1f}"),
)

SUITES: dict[str, Suite] = {
    "methods": Suite(
        _METHOD_TIMES,
        "python -m benchmarks 'quilt-*' 'fast-*' 'rectify-*' 'nfpt-*' 'affine-*'",
        "Compute time of one run with the inputs decoded (the studio's and the batch's cost); "
        "the whole-process columns time the ``weft`` command against G'MIC on the same file.",
    ),
    "methods/quality": Suite(
        _QUALITY,
        "python -m benchmarks 'quilt-*' 'fast-*' 'nfpt-*' 'affine-*'",
        "Quality figures of the same runs (``weft.core.metrics``): coherence and "
        "completeness lower is better, fidelity, SNR and PSNR higher.",
    ),
    "batch": Suite(
        (
            Column("recipe", "recipe"),
            Column("pool", "pool"),
            Column("items_per_s", "items/s", "{:.2f}"),
            Column("vs_one_worker", "vs 1 worker", "{:.2f}x"),
            Column("item_s", "s per item on its worker", "{:.3f}"),
            Column("item_cpu_s", "CPU s per item", "{:.3f}"),
            Column("busy", "workers busy", _pct),
            Column("startup_s", "pool start s", "{:.1f}"),
            Column("load_avg", "load average", "{:.1f}"),
        ),
        "python -m benchmarks.batch",
        "``weft batch`` over frames of 640x480 on local worker processes and on a local Dask cluster.",
    ),
    "memory": Suite(
        (
            Column("job", "job"),
            Column("peak_mib", "peak resident memory MiB", "{:.0f}"),
            Column("seconds", "wall s", "{:.1f}"),
            Column("under_2_gib", "under 2 GiB", _yes),
        ),
        "python -m benchmarks.memory",
        "Peak resident memory of the whole ``weft`` process on large jobs.",
    ),
    "cold": Suite(
        (
            Column("command", "command"),
            Column("cold_s", "first run s", "{:.1f}"),
            Column("warm_s", "later runs s", "{:.1f}"),
            Column("ratio", "first / later", "{:.1f}x"),
            Column("cold_first_words_s", "first words s", "{:.1f}"),
            Column("cold_silent_s", "longest silence s", "{:.1f}"),
        ),
        "python -m benchmarks.cold",
        "A first run compiles the method's kernels into numba's cache; later runs load them "
        "(``weft warm-up`` does the first run ahead of time).",
    ),
    "gui_latency": Suite(
        (
            Column("measure", "what"),
            Column("median_ms", "median latency ms", "{:.0f}"),
            Column("p95_ms", "95th percentile ms", "{:.0f}"),
            Column("max_stall_ms", "longest GUI stall ms", "{:.0f}"),
            Column("previews", "previews shown"),
            Column("values", "values / moves"),
            Column("method", "method"),
        ),
        "python -m benchmarks.gui_latency",
        "From a slider's change (or a brush's mouse move) to the preview on screen, in the real window.",
    ),
}


def _fill_aggregates(half: str) -> Callable[[dict], list[dict]]:
    def rows(data: dict) -> list[dict]:
        return [{"tool": tool, **figures} for tool, figures in data["aggregates"][half].items()]

    return rows


def _fill_cases(data: dict) -> list[dict]:
    return [
        {**r, "defects": ", ".join(r.get("defects") or []) or "none"}
        for r in data["rows"]
        if r.get("tool") == "weft" and r.get("half") == "check"
    ]


def _rectify_rows(data: dict) -> list[dict]:
    parts = {"all": data["aggregates"], **{k: v for k, v in data.get("aggregates_by_half", {}).items() if k == "check"}}
    return [
        {"detector": who, "kind": kind, "part": part, **figures}
        for part, aggregates in parts.items()
        for who, kinds in aggregates.items()
        for kind, figures in kinds.items()
    ]


def _limits_rows(data: dict) -> list[dict]:
    out = []
    for case in ("uncrop_colour", "uncrop_grey", "hole"):
        for run in data["fill"].get(case, []):
            out.append(
                {
                    "job": f"fill, {case.replace('_', ' ')}",
                    "side": run["side"],
                    "seconds": run["seconds"],
                    "added_mib": run["added_bytes"] / 2**20,
                }
            )
    for kind, runs in data.get("quilting", {}).items():
        for run in runs if isinstance(runs, list) else ():
            out.append(
                {
                    "job": f"quilting {kind}, block {run.get('block')}",
                    "seconds": run["seconds"],
                    "added_mib": run["peak_bytes"] / 2**20,
                }
            )
    return out


_FILL_AGG = (
    Column("tool", "tool"),
    Column("cases", "cases"),
    Column("coherence_median", "coherence, median", "{:.2f}"),
    Column("coherence_worst", "coherence, worst", "{:.2f}"),
    Column("defects", "cases with a defect"),
    Column("known_changed_cases", "cases with known pixels changed beyond the band"),
    Column("time_median_s", "whole process s, median", "{:.2f}"),
    Column("within_gmic_time", "cases within G'MIC's time"),
)

SUITES.update(
    {
        "fill_suite": Suite(
            _FILL_AGG,
            "python -m benchmarks.fill_suite",
            "The fill suite's check half (cases the defaults were not chosen on): each tool's "
            "coherence (lower is better), its defects (detail below 0.8x or above 1.25x the "
            "truth's, a seam more than 0.15 from the truth's, coherence over 1.2x the best "
            "peer's) and its whole-process time.",
            rows=_fill_aggregates("check"),
        ),
        "fill_suite/tuning": Suite(
            _FILL_AGG,
            "python -m benchmarks.fill_suite",
            "The tuning half, on which the defaults were chosen.",
            rows=_fill_aggregates("tuning"),
        ),
        "fill_suite/cases": Suite(
            (
                Column("case", "case"),
                Column("note", "what it is"),
                Column("coherence", "coherence", "{:.2f}"),
                Column("detail_ratio", "detail / truth's", "{:.2f}"),
                Column("seam_diff", "seam - truth's", "{:+.2f}"),
                Column("process_s", "s", "{:.2f}"),
                Column("defects", "defects"),
            ),
            "python -m benchmarks.fill_suite",
            "weft's default on each case of the check half.",
            rows=_fill_cases,
        ),
        "rectify_suggest": Suite(
            (
                Column("detector", "detector"),
                Column("kind", "cases"),
                Column("part", "half"),
                Column("cases", "n"),
                Column("success", "success", _pct),
                Column("wrong_warps", "wrong warps"),
                Column("refused", "refused"),
                Column("median_angle_err_deg", "angle error, median deg", "{:.2f}"),
                Column("worst_angle_err_deg", "worst deg", "{:.2f}"),
                Column("median_aspect_err", "aspect error, median", "{:.1%}"),
                Column("worst_aspect_err", "worst", "{:.1%}"),
                Column("median_cpu_ms_per_mp", "CPU ms per megapixel", "{:.0f}"),
                Column("median_ms_per_mp", "wall ms per megapixel", "{:.0f}"),
                Column("first_run_ms", "first call ms", "{:.0f}"),
            ),
            "python -m benchmarks.rectify_suggest",
            "Suggested feature lines on perspective views with a known homography (straight structure, textures "
            "without straight lines, and noise that must be refused), against a plain baseline (Hough lines and "
            "the two largest clusters). Success: the rectified result is within a similarity of the truth (right "
            "angle within 1 deg, aspect within 2 %). The detector's constants are chosen on the tuning half (the "
            "SHA-1 of the case's name); the table gives the whole suite and the check half. The CPU time is the "
            "process's own; it exceeds the wall time where OpenCV runs two threads.",
            rows=_rectify_rows,
        ),
        "limits": Suite(
            (
                Column("job", "job"),
                Column("side", "canvas side px"),
                Column("seconds", "s", "{:.1f}"),
                Column("added_mib", "memory added MiB", "{:.0f}"),
            ),
            "python -m benchmarks.limits",
            "The runs the up-front memory and time checks are fitted to.",
            rows=_limits_rows,
        ),
    }
)


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
    if not isinstance(data, dict):
        return None
    data.setdefault("rows", [])  # a suite whose table is made from other keys (Suite.rows)
    if not isinstance(data["rows"], list):
        return None
    data["rows"] = [r for r in data["rows"] if isinstance(r, dict)]
    return data


def _machine(m) -> str:
    if isinstance(m, dict):
        bits = [
            m.get("cpu"),
            f"{m['cores']} cores" if m.get("cores") else None,
            f"{m['memory_gib']} GiB" if m.get("memory_gib") else None,
            m.get("system"),
            f"Python {m['python']}" if m.get("python") else None,
            f"load average {m['load_average']}" if m.get("load_average") is not None else None,
        ]
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
        return [f".. note:: No results file ``benchmarks/results/{base}.json`` yet: run ``{command}`` to make it.", ""]
    try:
        rows = suite.rows(data) if suite and suite.rows else data["rows"]
    except (KeyError, TypeError, ValueError, AttributeError):
        return [
            f".. note:: ``benchmarks/results/{base}.json`` does not have the figures this table "
            f"shows: run ``{command}`` again.",
            "",
        ]
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
    lines += [
        f"Measured {data.get('date', 'at an unrecorded date')} on {_rst_escape(_machine(data.get('machine')))}."
        f"{note}{quick} Reproduce with ``{command}`` "
        f"(file ``benchmarks/results/{base}.json``).",
        "",
    ]
    if not rows or not columns:
        return lines + ["The file has no rows to show.", ""]
    from weft_docs import list_table

    table = [[_rst_escape(c.cell(r)) for c in columns] for r in rows]
    return lines + list_table([c.header for c in columns], table)
