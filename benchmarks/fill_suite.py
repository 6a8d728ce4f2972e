"""The public fill suite: ``python -m benchmarks.fill_suite [--quick] [--repeats N] [CASE ...]``.

Every case of :mod:`benchmarks.fill_suite_cases` (a crop of a shipped or installable picture with a
hole cut from it, so the truth is known) is filled by ``weft fill`` with its defaults and by the
peers, each tool a process of its own, the tools interleaved per case (one round runs each once,
in turn, so machine noise hits them alike; the time is the median of ``--repeats`` rounds):

* ``weft`` -- ``weft fill`` (the command line, its default engine);
* G'MIC ``inpaint_matchpatch`` (Debian's ``gmic``);
* OpenCV xphoto shift-map (opencv-contrib, this interpreter);
* pypatchmatch and Resynthesizer from PyPI, run by ``benchmarks/fill_peers.py`` under
  ``$WEFT_PEERS_PYTHON`` (``benchmarks/peers_env.sh`` makes such an environment); a peer that is not
  installed gets a row saying so.

``--variants`` adds in-process rows of weft's engines (``engine[:structure]``, e.g.
``patchmatch:no``), figures only, to compare designs on the same cases.

Per case and tool: ``coherence`` (:func:`weft.core.metrics.fill_coherence` against the input),
``detail`` and ``seam`` (:func:`~weft.core.metrics.fill_detail`, :func:`~weft.core.metrics.fill_seam`)
with the truth's beside them, ``known_max`` (the largest change, in 8-bit levels, of a known pixel
more than ``BAND`` px from the hole: weft's promise is 0) and ``process_s``. A *defect*: detail
below 0.8x or above 1.25x the truth's, a seam more than 0.15 from the truth's, or coherence more
than 1.2x the best peer's. Aggregates per half (tuning / check) and tool: median and worst
coherence, defect count, known-pixel violations, cases at most G'MIC's time.

Writes ``benchmarks/results/fill_suite.json`` and a contact sheet per case (input, weft, best peer,
truth: cropped around the hole and enlarged) to ``benchmarks/results/fill_suite/``.
"""

from __future__ import annotations

import argparse
import datetime
import fnmatch
import json
import os
import platform
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from .fill import GMIC, _cv2_missing, _gmic_command, _importable, _peer_command, _run, peers_python, read_output
from .fill_suite_cases import CASES, SuiteCase, SuiteInputs, by_name

BAND = 2  # weft's default blend band: known pixels within it may change
RESULTS = Path(__file__).resolve().parent / "results"
PEERS = ("G'MIC inpaint_matchpatch", "OpenCV xphoto shift-map", "pypatchmatch", "Resynthesizer (PyPI)")


# ---------------------------------------------------------------------------------------------- files


def write_inputs(inputs: SuiteInputs, folder: Path) -> dict[str, Path]:
    """``canvas`` and ``mask`` (the peers': the whole canvas, white = fill), ``image`` (weft's: the
    canvas less an uncrop's margins; RGBA with the hole transparent for an alpha case) and
    ``wmask`` (weft's mask, when it needs one)."""
    from PIL import Image

    folder.mkdir(parents=True, exist_ok=True)
    files = {"canvas": folder / "canvas.png", "mask": folder / "mask.png", "image": folder / "image.png"}
    Image.fromarray(inputs.image).save(files["canvas"])
    Image.fromarray(inputs.hole.astype(np.uint8) * 255).save(files["mask"])
    known = np.ascontiguousarray(inputs.part(inputs.image))
    inner = inputs.part(inputs.hole)
    if inputs.alpha:
        rgb = known if known.ndim == 3 else np.repeat(known[..., None], 3, axis=2)
        known = np.concatenate([rgb, np.where(inner, 0, 255).astype(np.uint8)[..., None]], axis=2)
    Image.fromarray(known).save(files["image"])
    if inner.any() and not inputs.alpha:
        files["wmask"] = folder / "wmask.png"
        Image.fromarray(inner.astype(np.uint8) * 255).save(files["wmask"])
    return files


def weft_command(files: dict[str, Path], out: Path, inputs: SuiteInputs, seed: int = 1) -> list[str]:
    cmd = [sys.executable, "-m", "weft.app.cli", "fill", str(files["image"])]
    if "wmask" in files:
        cmd += ["--mask", str(files["wmask"])]
    if inputs.extend is not None:
        cmd += ["--extend", ",".join(str(v) for v in inputs.extend)]
    return cmd + ["-o", str(out), "--seed", str(seed), "--quiet"]


def peer_tools() -> list[tuple[str, Any, str | None]]:
    """``(name, command(files, out), why it cannot run or None)`` for each peer."""

    def gmic(f, o):
        return _gmic_command(f, o, None, None)

    return [
        (PEERS[0], gmic, None if shutil.which("gmic") else "gmic is not on the PATH (Debian: apt-get install gmic)"),
        (PEERS[1], lambda f, o: _peer_command("shiftmap", lambda: sys.executable)(f, o, None, None), _cv2_missing()),
        (
            PEERS[2],
            lambda f, o: _peer_command("pypatchmatch", peers_python)(f, o, None, None),
            _importable(peers_python(), "patchmatch"),
        ),
        (
            PEERS[3],
            lambda f, o: _peer_command("resynthesizer", peers_python)(f, o, None, None),
            _importable(peers_python(), "resynthesizer"),
        ),
    ]


# -------------------------------------------------------------------------------------------- figures


def figures(out: np.ndarray, inputs: SuiteInputs) -> dict[str, float]:
    """The judges of one filled canvas ``out`` (uint8, the truth's shape)."""
    from scipy.ndimage import distance_transform_cdt
    from weft.core.metrics import fill_coherence, fill_detail, fill_seam

    if out.shape != inputs.truth.shape:
        return {
            "error": f"output is {out.shape[1]}x{out.shape[0]}, expected "
            f"{inputs.truth.shape[1]}x{inputs.truth.shape[0]}"
        }
    f = out.astype(np.float32) / 255.0
    hole = inputs.hole
    row = {
        "coherence": fill_coherence(f, hole, inputs.image.astype(np.float32) / 255.0),
        "detail": fill_detail(f, hole),
        "seam": fill_seam(f, hole),
    }
    dist = distance_transform_cdt(~hole, metric="chessboard")
    diff = np.abs(out.astype(np.int16) - inputs.image.astype(np.int16))
    diff = diff.max(axis=2) if diff.ndim == 3 else diff
    row["known_max"] = int(diff[~hole & (dist > BAND)].max(initial=0))
    return row


def truth_figures(inputs: SuiteInputs) -> dict[str, float]:
    from weft.core.metrics import fill_detail, fill_seam

    f = inputs.truth.astype(np.float32) / 255.0
    return {"detail": fill_detail(f, inputs.hole), "seam": fill_seam(f, inputs.hole)}


def judge(row: dict[str, Any], truth: dict[str, float], best_peer: float | None) -> list[str]:
    """The defects of one row, as words (empty: none)."""
    out = []
    ratio = row["detail"] / truth["detail"] if truth["detail"] > 0 else 1.0
    row["detail_ratio"] = ratio
    row["seam_diff"] = row["seam"] - truth["seam"]
    if not 0.8 <= ratio <= 1.25:
        out.append(f"detail {ratio:.2f}x")
    if abs(row["seam_diff"]) > 0.15:
        out.append(f"seam {row['seam_diff']:+.2f}")
    if best_peer is not None and row["coherence"] > 1.2 * best_peer:
        out.append(f"coherence {row['coherence'] / best_peer:.2f}x best peer")
    return out


# ---------------------------------------------------------------------------------------------- run


def run_variant(inputs: SuiteInputs, variant: str, seed: int = 1) -> tuple[np.ndarray, float]:
    """In-process weft fill with ``variant`` = ``engine[:structure]``: (uint8 canvas, seconds)."""
    from weft.core.fill import FillParams
    from weft.core.fill.method import fill_image
    from weft.core.geometry import Margins

    engine, _, structure = variant.partition(":")
    params = FillParams(
        engine=engine, structure=structure or "auto", extend=None if inputs.extend is None else Margins(*inputs.extend)
    )
    image = inputs.part(inputs.image).astype(np.float32) / 255.0
    inner = inputs.part(inputs.hole)
    mask = None
    if inputs.alpha:
        rgb = image if image.ndim == 3 else np.repeat(image[..., None], 3, axis=2)
        image = np.concatenate([rgb, (~inner).astype(np.float32)[..., None]], axis=2)
    elif inner.any():
        mask = inner
    t0 = time.perf_counter()
    out, _fig = fill_image(image, mask, params=params, rng=seed)
    seconds = time.perf_counter() - t0
    out = out[..., :3] if out.ndim == 3 and out.shape[2] == 4 else out
    if inputs.truth.ndim == 2 and out.ndim == 3:
        out = out.mean(axis=2)
    return np.clip(np.rint(out * 255), 0, 255).astype(np.uint8), seconds


def run_case(
    case: SuiteCase, *, repeats: int, variants: list[str], cache: Path, reuse: bool, sheets: Path | None
) -> list[dict[str, Any]]:
    inputs = case.build()
    folder = cache / case.name
    files = write_inputs(inputs, folder)
    truth = truth_figures(inputs)
    base = {"case": case.name, "half": case.half, "note": case.note}
    peers_file = folder / "peers.json"
    cached = json.loads(peers_file.read_text()) if reuse and peers_file.exists() else None
    tools = [("weft", lambda f, o: weft_command(f, o, inputs), None)]
    if cached is None:
        tools += peer_tools()
    times: dict[str, list[float]] = {name: [] for name, _, why in tools if why is None}
    errors: dict[str, str] = {}
    for _ in range(max(1, repeats)):
        for name, command, why in tools:
            if why is not None or name in errors:
                continue
            s, _rss, err = _run(command(files, folder / f"{_slug(name)}.png"))
            if err:
                errors[name] = err
            else:
                times[name].append(s)
    rows: list[dict[str, Any]] = []
    outputs: dict[str, np.ndarray] = {}
    for name, _command, why in tools:
        row = {**base, "tool": name}
        if why is not None:
            row["missing"] = why
        elif name in errors:
            row["error"] = errors[name]
        else:
            row["process_s"] = statistics.median(times[name])
            outputs[name] = read_output(folder / f"{_slug(name)}.png", inputs.truth)
            row.update(figures(outputs[name], inputs))
        rows.append(row)
    if cached is not None:
        for row in cached:
            rows.append({**base, **{k: v for k, v in row.items() if k not in base}})
            if "coherence" in row:
                outputs[row["tool"]] = read_output(folder / f"{_slug(row['tool'])}.png", inputs.truth)
    else:
        peers_file.write_text(json.dumps([r for r in rows if r["tool"] in PEERS], indent=1))
    for variant in variants:
        row = {**base, "tool": f"weft {variant}", "in_process": True}
        try:
            out, seconds = run_variant(inputs, variant)
            row.update(figures(out, inputs), in_process_s=seconds)
            outputs[row["tool"]] = out
        except Exception as e:  # a benchmark reports a failing variant and goes on
            row["error"] = f"{type(e).__name__}: {e}"
        rows.append(row)
    peer_coh = [r["coherence"] for r in rows if r["tool"] in PEERS and "coherence" in r]
    best = min(peer_coh) if peer_coh else None
    best_name = next((r["tool"] for r in rows if r["tool"] in PEERS and r.get("coherence") == best), None)
    gmic = next((r.get("process_s") for r in rows if r["tool"] == GMIC), None)
    for row in rows:
        if "coherence" in row:
            row["defects"] = judge(row, truth, best)
            row["truth_detail"], row["truth_seam"] = truth["detail"], truth["seam"]
            if gmic is not None and "process_s" in row:
                row["within_gmic_time"] = row["process_s"] <= gmic
    if sheets is not None and "weft" in outputs:
        from .fill_suite_sheets import contact_sheet

        contact_sheet(
            sheets / f"{case.name}.png",
            inputs,
            outputs["weft"],
            outputs.get(best_name),
            best_name or "no peer",
            case.note,
        )
    return rows


def _slug(name: str) -> str:
    return "".join(ch if ch.isalnum() else "-" for ch in name.lower()).strip("-")


def aggregate(rows: list[dict[str, Any]]) -> dict[str, dict[str, dict[str, Any]]]:
    """Per half and tool: cases, median / worst coherence, median detail ratio and |seam diff|,
    defect count, known-pixel violations, cases at most G'MIC's time."""
    out: dict[str, dict[str, dict[str, Any]]] = {}
    for part in ("tuning", "check", "all"):
        picked = [r for r in rows if part == "all" or r["half"] == part]
        out[part] = {}
        for tool in dict.fromkeys(r["tool"] for r in picked):
            rs = [r for r in picked if r["tool"] == tool and "coherence" in r]
            n_all = sum(1 for r in picked if r["tool"] == tool)
            if not rs:
                why = next((r.get("missing") or r.get("error") for r in picked if r["tool"] == tool), "")
                out[part][tool] = {"cases": n_all, "not_run": why}
                continue
            timed = [r for r in rs if "within_gmic_time" in r]
            out[part][tool] = {
                "cases": len(rs),
                "failed": n_all - len(rs),
                "coherence_median": statistics.median(r["coherence"] for r in rs),
                "coherence_worst": max(r["coherence"] for r in rs),
                "detail_ratio_median": statistics.median(r["detail_ratio"] for r in rs),
                "seam_diff_abs_median": statistics.median(abs(r["seam_diff"]) for r in rs),
                "defects": sum(1 for r in rs if r["defects"]),
                "known_changed_cases": sum(1 for r in rs if r["known_max"] > 0),
                "time_median_s": statistics.median(r.get("process_s", r.get("in_process_s", 0.0)) for r in rs),
                **(
                    {"within_gmic_time": sum(r["within_gmic_time"] for r in timed), "timed": len(timed)}
                    if timed
                    else {}
                ),
            }
    return out


def table(agg: dict[str, dict[str, Any]]) -> str:
    lines = [
        "| tool | cases | coherence median | worst | detail ratio median | abs seam diff median | defects | "
        "known px changed (cases) | time median s | <= G'MIC time |",
        "|---" * 10 + "|",
    ]
    for tool, a in agg.items():
        if "not_run" in a:
            lines.append(f"| {tool} | not run: {a['not_run']} |" + " |" * 8)
            continue
        g = f"{a['within_gmic_time']}/{a['timed']}" if "timed" in a else ""
        lines.append(
            f"| {tool} | {a['cases']} | {a['coherence_median']:.2f} | {a['coherence_worst']:.2f} | "
            f"{a['detail_ratio_median']:.2f} | {a['seam_diff_abs_median']:.2f} | {a['defects']} | "
            f"{a['known_changed_cases']} | {a['time_median_s']:.2f} | {g} |"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.fill_suite", description=__doc__.split("\n\n")[0])
    ap.add_argument("cases", nargs="*", metavar="CASE", help="case names or shell patterns (default: all)")
    ap.add_argument("--quick", action="store_true", help="one round, no contact sheets, JSON to a temporary file")
    ap.add_argument("--repeats", type=int, default=3, help="interleaved timed rounds per case (default 3)")
    ap.add_argument("--variants", default="", help="in-process weft rows, comma-separated engine[:structure]")
    ap.add_argument("--half", choices=("tuning", "check", "all"), default="all")
    ap.add_argument("--reuse-peers", action="store_true", help="take the peers' rows from the cache's last run")
    ap.add_argument("--cache", type=Path, default=Path(tempfile.gettempdir()) / "weft-fill-suite")
    ap.add_argument("--json", type=Path, default=None)
    ap.add_argument("--sheets", type=Path, default=None, help="contact sheets' folder (default: beside the JSON)")
    args = ap.parse_args(argv)
    known = by_name()
    picked = []
    for pattern in args.cases or ["*"]:
        names = [n for n in known if fnmatch.fnmatchcase(n, pattern)]
        if not names:
            print(f"fill_suite: unknown case {pattern} (known: {', '.join(known)})", file=sys.stderr)
            return 2
        picked += [n for n in names if n not in picked]
    cases = [known[n] for n in picked if args.half == "all" or known[n].half == args.half]
    full = not args.cases and args.half == "all" and not args.quick
    path = args.json or (RESULTS / "fill_suite.json" if full else Path(tempfile.gettempdir()) / "fill_suite.json")
    sheets = None if args.quick else (args.sheets or (RESULTS / "fill_suite" if full else args.cache / "sheets"))
    variants = [v for v in args.variants.split(",") if v]
    rows: list[dict[str, Any]] = []
    partial = args.cache / "rows.jsonl"  # each case's rows as it ends, for a run that is cut short
    args.cache.mkdir(parents=True, exist_ok=True)
    partial.write_text("")
    for case in cases:
        print(f"{case.name} ({case.half}) ...", file=sys.stderr, flush=True)
        new = run_case(
            case,
            repeats=1 if args.quick else args.repeats,
            variants=variants,
            cache=args.cache,
            reuse=args.reuse_peers,
            sheets=sheets,
        )
        rows += new
        with partial.open("a") as f:
            f.write("".join(json.dumps(r, default=float) + "\n" for r in new))
    agg = aggregate(rows)
    machine = {
        "platform": platform.platform(),
        "processor": platform.processor() or platform.machine(),
        "cores": os.cpu_count(),
        "python": platform.python_version(),
        "load_average_end": os.getloadavg()[0],
        "shared": "2 cores shared by several engineers",
    }
    doc = {
        "suite": "fill_suite",
        "date": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
        "machine": machine,
        "command": "python -m benchmarks.fill_suite " + " ".join(argv or sys.argv[1:]),
        "repeats": 1 if args.quick else args.repeats,
        "split": {h: [c.name for c in CASES if c.half == h] for h in ("tuning", "check")},
        "rows": rows,
        "aggregates": agg,
    }
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(doc, indent=1, default=float) + "\n", encoding="utf-8")
    for part in ("tuning", "check"):
        if any(r["half"] == part for r in rows):
            print(f"\n{part} half ({sum(1 for c in cases if c.half == part)} cases)")
            print(table(agg[part]))
    weft_defects = [(r["case"], r["defects"]) for r in rows if r["tool"] == "weft" and r.get("defects")]
    if weft_defects:
        print("\nweft's defects by the figures:")
        for name, d in weft_defects:
            print(f"  {name}: {', '.join(d)}")
    print(f"(written to {path}{'; contact sheets in ' + str(sheets) if sheets else ''})", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
