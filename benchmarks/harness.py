"""Run benchmark cases: compute time, peak memory, quality figures, and G'MIC side by side.

Timing: one untimed warm-up run (numba kernels compile or load from cache, OpenCV initialises),
then ``repeats`` timed runs of the method's compute only (inputs already decoded); the table shows
the median and the minimum. Peak memory is measured in one extra run under ``tracemalloc`` (so its
overhead never touches the timings): it counts numpy's and Python's allocations during compute, not
the interpreter or libraries already loaded. Quality figures come from ``weft.core.metrics`` on the output
of the last timed run. A case with a G'MIC counterpart, when ``gmic`` is on the PATH, also times the
whole ``weft`` process against the whole ``gmic`` process on the same input file, alternating the two
so that machine noise hits both alike.
"""

from __future__ import annotations

import json
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path
from typing import Any

import numpy as np
from weft.core import metrics, registry
from weft.core.examples import example
from weft.core.image import load_image, luminance, resize, save_image

from .cases.base import Case


def prepare_inputs(case: Case) -> dict[str, np.ndarray]:
    """Decode, crop, resize and (optionally) grey each input of ``case``."""
    out = {}
    for name, spec in case.inputs.items():
        if spec.example.startswith("skimage:"):  # the peers' inputs, rebuilt from scikit-image's data
            from skimage import data

            img = np.asarray(getattr(data, spec.example.split(":", 1)[1])(), dtype=np.float32) / 255.0
        else:
            img = load_image(example(spec.example)).image
        if spec.crop is not None:
            x, y, w, h = spec.crop
            img = img[y : y + h, x : x + w]
        if spec.resize is not None:
            img = resize(img, spec.resize, interpolation="area")
        if spec.grey:
            img = luminance(img)
        out[name] = np.ascontiguousarray(img, dtype=np.float32)
    return out


def case_params(case: Case, quick: bool) -> dict[str, Any]:
    params = dict(case.params)
    if quick:
        params.update(case.quick)
    return params


def _figures(case: Case, out: np.ndarray, inputs: dict[str, np.ndarray]) -> dict[str, float]:
    figs = dict(case.figures(inputs, out)) if case.figures is not None else {}
    for m in case.metrics:
        if m in ("coherence", "completeness", "snr_db"):
            ref = inputs["texture"]
        elif m == "fidelity":
            ref = inputs["target"]
        else:
            raise ValueError(f"benchmark case {case.name}: unknown metric {m!r}")
        figs[m] = float(getattr(metrics, m)(out, ref))
    return figs


def _cli_args(params: dict[str, Any]) -> list[str]:
    args = []
    for k, v in params.items():
        if isinstance(v, (tuple, list)):
            v = f"{v[0]}x{v[1]}"
        args += ["--" + k.replace("_", "-"), str(v)]
    return args


def _time_process(cmd: list[str]) -> float:
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    seconds = time.perf_counter() - t0
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed: {proc.stderr.strip()[-300:]}")
    return seconds


def weft_command(case: Case, input_files: dict[str, Path], output: Path, params: dict[str, Any]) -> list[str]:
    """The ``weft`` command line that runs ``case`` on the given input files."""
    method = registry.get(case.method)
    cmd = [sys.executable, "-m", "weft.app.cli", case.method]
    for spec in method.inputs:
        if spec.name in input_files:
            path = str(input_files[spec.name])
            cmd += [path] if spec.is_positional else ["--" + spec.name.replace("_", "-"), path]
    return cmd + ["-o", str(output), "--seed", str(case.seed), "--quiet"] + _cli_args(params)


def time_processes(case: Case, inputs: dict[str, np.ndarray], params: dict[str, Any], repeats: int) -> dict[str, float]:
    """Median whole-process seconds of ``weft`` (and of ``gmic``, when the case has a counterpart
    and it is installed) on the same input files, the two alternated so noise hits both alike."""
    gmic = shutil.which("gmic") if case.gmic is not None else None
    if not case.process and gmic is None:
        return {}
    with tempfile.TemporaryDirectory(prefix="weft-bench-") as tmp:
        files = {}
        for name, image in inputs.items():
            files[name] = Path(tmp) / f"{name}.png"
            save_image(files[name], image)
        weft_cmd = weft_command(case, files, Path(tmp) / "weft.png", params)
        gmic_cmd = (
            [gmic, "-v", "-", str(files["texture"]), *case.gmic, "-o", str(Path(tmp) / "gmic.png")] if gmic else None
        )
        _time_process(weft_cmd)  # warm caches (numba's on-disk cache, the OS file cache) for both
        if gmic_cmd:
            _time_process(gmic_cmd)
        w, g = [], []
        for _ in range(repeats):
            w.append(_time_process(weft_cmd))
            if gmic_cmd:
                g.append(_time_process(gmic_cmd))
    row = {"weft_process_s": statistics.median(w)}
    if g:
        row["gmic_process_s"] = statistics.median(g)
        row["weft_over_gmic"] = row["weft_process_s"] / row["gmic_process_s"]
    return row


def parallel_speedup(method, inputs, params, seed: int, repeats: int) -> float:
    """(time of two runs one after the other) / (time of the same two runs on two threads at once)."""
    import threading

    def one():
        method.run(inputs, params, rng=seed)

    serial, parallel = [], []
    for _ in range(repeats):
        t0 = time.perf_counter()
        one()
        one()
        serial.append(time.perf_counter() - t0)
        threads = [threading.Thread(target=one) for _ in range(2)]
        t0 = time.perf_counter()
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        parallel.append(time.perf_counter() - t0)
    return statistics.median(serial) / statistics.median(parallel)


def run_case(case: Case, *, repeats: int = 5, quick: bool = False) -> dict[str, Any]:
    """Time ``case`` and compute its figures; returns one JSON-serialisable row."""
    method = registry.get(case.method)
    params_dict = case_params(case, quick)
    params = method.params.from_dict(params_dict)
    inputs = prepare_inputs(case)
    method.run(inputs, params, rng=case.seed)  # warm-up
    times = []
    result = None
    for _ in range(repeats):
        t0 = time.perf_counter()
        result = method.run(inputs, params, rng=case.seed)
        times.append(time.perf_counter() - t0)
    tracemalloc.start()
    try:
        method.run(inputs, params, rng=case.seed)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    h, w = result.image.shape[:2]
    row: dict[str, Any] = {
        "case": case.name,
        "method": case.method,
        "size": [w, h],
        "runs": repeats,
        "median_s": statistics.median(times),
        "min_s": min(times),
        "peak_mib": peak / 2**20,
    }
    row.update(_figures(case, result.image, inputs))
    if case.parallel:
        row["speedup_2_threads"] = parallel_speedup(method, inputs, params, case.seed, repeats)
    if not quick:  # G'MIC's command line is written for the full-size case
        row.update(time_processes(case, inputs, params_dict, max(1, min(repeats, 5))))
    return row


_COLUMNS = [
    ("case", "case", "{}"),
    ("size", "output", "{0[0]}x{0[1]}"),
    ("runs", "runs", "{}"),
    ("median_s", "median s", "{:.4f}"),
    ("min_s", "min s", "{:.4f}"),
    ("peak_mib", "peak MiB", "{:.1f}"),
    ("coherence", "coherence", "{:.4f}"),
    ("completeness", "completeness", "{:.4f}"),
    ("fidelity", "fidelity", "{:.3f}"),
    ("coherence_median", "coherence median", "{:.4f}"),
    ("coherence_max", "coherence max", "{:.4f}"),
    ("completeness_median", "completeness median", "{:.4f}"),
    ("completeness_max", "completeness max", "{:.4f}"),
    ("verbatim_max", "largest verbatim (max)", "{:.3f}"),
    ("snr_db", "SNR dB", "{:.2f}"),
    ("psnr_db", "PSNR dB", "{:.2f}"),
    ("psnr_cubic_db", "cubic PSNR dB", "{:.2f}"),
    ("speedup_2_threads", "2-thread speed-up", "{:.2f}x"),
    ("weft_process_s", "weft process s", "{:.3f}"),
    ("gmic_process_s", "G'MIC process s", "{:.3f}"),
    ("weft_over_gmic", "weft / G'MIC", "{:.2f}"),
]


def markdown_table(rows: list[dict[str, Any]]) -> str:
    """The rows as a markdown table with only the columns some row has."""
    cols = [c for c in _COLUMNS if any(c[0] in r for r in rows)]
    lines = ["| " + " | ".join(c[1] for c in cols) + " |", "|" + "|".join("---" for _ in cols) + "|"]
    for r in rows:
        cells = [c[2].format(r[c[0]]) if c[0] in r else "" for c in cols]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def write_json(rows: list[dict[str, Any]], path: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(rows, indent=2) + "\n", encoding="utf-8")
