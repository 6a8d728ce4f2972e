"""Fill and extend (issue 15) against the peers that do only this: ``python -m benchmarks 'fill-*'``.

Every case is built in code from scikit-image's data (deterministic, nothing to download), with its
ground truth:

* ``fill-gravel``: stochastic texture. ``gravel()[96:416, 96:416]`` (320x320, grey); the hole is a
  "bolt" (a disc of radius 30) and a "wire" (a 10-px stroke across the picture), painted white.
* ``fill-brick``: regular texture. ``brick()[64:384, 64:384]`` (320x320, grey); the hole is a
  100x60 "signature" box across two mortar lines, painted white.
* ``fill-object``: an object in a photo. The spoon of ``coffee()`` (cut out along an ellipse for its
  bowl and a 9-px line for its handle) pasted into ``coffee()[80:400, 0:320]`` (320x320, colour)
  over the saucer's rim and the wooden table; the mask is its silhouette grown by 4 px, as a loose
  brush would paint it. The ground truth is that crop before the spoon was pasted in: a real photo
  behind a real object, so every figure below has a truth to compare with.
* ``fill-uncrop``: uncrop 256 -> 384. ``brick()[64:448, 64:448]`` (384x384) is the truth; its
  centre 256x256 is the input; weft extends it by ``--extend 64,64,64,64``; the peers, which cannot
  grow a canvas, get the 384x384 canvas with a black border and the border as their mask.

Each tool is a separate process (its whole-process time and peak resident memory, ``ru_maxrss`` of
the child from ``wait4``, are its own): ``weft fill`` with its default engine, with each
``--engine`` and with ``--engine patchmatch --structure no`` (the engine without its edge guide);
G'MIC's ``inpaint_matchpatch`` (``gmic`` on the PATH); OpenCV's shift-map (``cv2.xphoto``), Telea
and Navier-Stokes (``cv2.inpaint``, the smear reference) run by ``benchmarks/fill_peers.py``;
``pypatchmatch`` and the PyPI ``resynthesizer`` run by the same script under ``$WEFT_PEERS_PYTHON``
(default: this interpreter) when that environment has them. The peers are never dependencies of
weft: a peer that is not installed gets a row saying so.

Per case: one untimed warm-up run per tool (numba's and the OS's caches), then ``repeats`` rounds
that run every tool once each, in turn, so that machine noise hits them alike; the table gives the
median whole-process seconds and peak memory, and the figures of ``weft.core.metrics`` on the last
output: ``fill_coherence`` (against the input), ``fill_detail``, ``fill_seam``, next to the ground
truth's own; "band Δ" is the largest change, in 8-bit levels, of a known pixel within 2 px of the
hole (where weft's blend band may change it too; distances in 8-connected steps, as the band is
measured), "known Δ" the largest change of a known pixel further away (weft: none), "reach" the
distance in px of the farthest known pixel changed at all, and "unfilled" the share of the hole
still holding the input's placeholder (white, or black for the
uncrop border). ``goals`` checks each weft row against the issue's goals for that case.
"""

from __future__ import annotations

import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

PEERS_SCRIPT = Path(__file__).resolve().with_name("fill_peers.py")
WEFT_ENGINES = ("patchmatch", "quilt", "hybrid")
BAND = 2  # px around the hole inside which weft may change known pixels (the method's default band)


# ---------------------------------------------------------------------------------------------- cases


@dataclass(frozen=True)
class FillInputs:
    """A built case: ``truth`` (uint8, the whole canvas), ``hole`` (bool, the canvas's unknown
    pixels), ``image`` (uint8, what the peers get: the truth with the hole overwritten by
    ``placeholder``), and for an uncrop ``extend`` (L, T, R, B): weft then gets only the known
    centre and grows the canvas itself."""

    truth: np.ndarray
    hole: np.ndarray
    image: np.ndarray
    placeholder: int
    extend: tuple[int, int, int, int] | None = None

    @property
    def known_part(self) -> np.ndarray:
        """What weft is given: the whole input, or for an uncrop its known centre."""
        if self.extend is None:
            return self.image
        left, top, right, bottom = self.extend
        h, w = self.image.shape[:2]
        return self.image[top : h - bottom, left : w - right]


@dataclass(frozen=True)
class FillCase:
    name: str
    build: Callable[[], FillInputs]
    note: str
    method: str = "fill"
    seed: int = 1
    uncrop: bool = False
    preview: bool = False


def _skimage(name: str) -> np.ndarray:
    from skimage import data

    return np.asarray(getattr(data, name)())


def _disc(shape, cx, cy, r) -> np.ndarray:
    yy, xx = np.mgrid[: shape[0], : shape[1]]
    return (xx - cx) ** 2 + (yy - cy) ** 2 <= r * r


def _stroke(shape, points, width) -> np.ndarray:
    import cv2

    m = np.zeros(shape, np.uint8)
    cv2.polylines(m, [np.array(points, np.int32)], False, 1, thickness=width, lineType=cv2.LINE_8)
    return m.astype(bool)


def _painted(truth: np.ndarray, hole: np.ndarray, value: int) -> np.ndarray:
    img = truth.copy()
    img[hole] = value
    return img


def build_gravel() -> FillInputs:
    truth = _skimage("gravel")[96:416, 96:416].copy()
    hole = _disc(truth.shape, 170, 120, 30) | _stroke(truth.shape, [(20, 250), (150, 228), (300, 270)], 10)
    return FillInputs(truth, hole, _painted(truth, hole, 255), 255)


def build_brick() -> FillInputs:
    truth = _skimage("brick")[64:384, 64:384].copy()
    hole = np.zeros(truth.shape, bool)
    hole[130:190, 110:210] = True
    return FillInputs(truth, hole, _painted(truth, hole, 255), 255)


SPOON_BOWL = (365, 280, 40, 46)  # centre x, y and half axes of the spoon's bowl in coffee()
SPOON_HANDLE = [(412, 72), (395, 160), (378, 238)]  # its handle, a 9-px line
SPOON_SHIFT = (285, -55)  # coffee() pixel (x + 285, y + 80 - 55) is pasted at (x, y) of the crop


def build_object() -> FillInputs:
    import cv2

    photo = _skimage("coffee")
    truth = photo[80:400, 0:320].copy()
    spoon = np.zeros(photo.shape[:2], np.uint8)
    cx, cy, ax, ay = SPOON_BOWL
    cv2.ellipse(spoon, (cx, cy), (ax, ay), 0, 0, 360, 1, thickness=-1)
    cv2.polylines(spoon, [np.array(SPOON_HANDLE, np.int32)], False, 1, thickness=9)
    dx, dy = SPOON_SHIFT
    move = np.float32([[1, 0, -dx], [0, 1, -(80 + dy)]])  # coffee() pixel (x, y) -> crop (x - dx, y - 80 - dy)
    sil = cv2.warpAffine(spoon, move, (320, 320), flags=cv2.INTER_NEAREST).astype(bool)
    moved = cv2.warpAffine(photo, move, (320, 320), flags=cv2.INTER_NEAREST)
    image = truth.copy()
    image[sil] = moved[sil]
    hole = cv2.dilate(sil.astype(np.uint8), cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (9, 9))).astype(bool)
    return FillInputs(truth, hole, image, -1)


def build_uncrop() -> FillInputs:
    truth = _skimage("brick")[64:448, 64:448].copy()
    hole = np.ones(truth.shape, bool)
    hole[64:320, 64:320] = False
    return FillInputs(truth, hole, _painted(truth, hole, 0), 0, extend=(64, 64, 64, 64))


CASES: list[FillCase] = [
    FillCase("fill-gravel", build_gravel, "stochastic: gravel 320x320 (grey), a bolt (disc r 30) and a 10-px wire"),
    FillCase("fill-brick", build_brick, "regular: brick 320x320 (grey), a 100x60 box across two mortar lines"),
    FillCase("fill-object", build_object, "object: coffee's spoon pasted over saucer rim and wood, 320x320 colour"),
    FillCase("fill-uncrop", build_uncrop, "uncrop 256 -> 384: brick, --extend 64,64,64,64", uncrop=True),
    FillCase(
        "fill-preview-128",
        build_gravel,
        "the studio's reduced preview: 128x128 around a stroke of fill-gravel, in-process, median of 20 per engine",
        preview=True,
    ),
]


def by_name() -> dict[str, FillCase]:
    return {c.name: c for c in CASES}


# ---------------------------------------------------------------------------------------------- tools


@dataclass(frozen=True)
class Tool:
    """One row of a case: ``name``; ``command(files, out)`` -> argv; ``missing()`` -> why it cannot
    run here, or None."""

    name: str
    command: Callable[[dict[str, Path], Path, FillCase, FillInputs], list[str]]
    missing: Callable[[], str | None] = lambda: None
    weft: bool = False
    engine: str | None = None


def peers_python() -> str:
    return os.environ.get("WEFT_PEERS_PYTHON") or sys.executable


_IMPORTABLE: dict[tuple[str, str], str | None] = {}


def _importable(python: str, module: str) -> str | None:
    key = (python, module)
    if key not in _IMPORTABLE:
        try:
            proc = subprocess.run([python, "-c", f"import {module}"], capture_output=True, text=True, timeout=120)
            err = proc.stderr.strip().splitlines()[-1:] if proc.returncode else []
            _IMPORTABLE[key] = f"not installed for {python} ({err[0] if err else 'import failed'})" if err else None
        except (OSError, subprocess.TimeoutExpired) as e:
            _IMPORTABLE[key] = f"{python}: {e}"
    return _IMPORTABLE[key]


def _weft_command(engine: str | None, *options: str):
    def command(files, out, case, inputs):
        cmd = [sys.executable, "-m", "weft.app.cli", "fill", str(files["image"])]
        if inputs.extend is None:
            cmd += ["--mask", str(files["mask"])]
        else:
            cmd += ["--extend", ",".join(str(v) for v in inputs.extend)]
        if engine is not None:
            cmd += ["--engine", engine]
        return cmd + [*options, "-o", str(out), "--seed", str(case.seed), "--quiet"]

    return command


def _peer_command(peer: str, python: Callable[[], str]):
    def command(files, out, case, inputs):
        return [python(), str(PEERS_SCRIPT), peer, str(files["canvas"]), str(files["mask"]), str(out)]

    return command


def _gmic_command(files, out, case, inputs):
    return [
        shutil.which("gmic") or "gmic",
        "-v",
        "-",
        str(files["canvas"]),
        str(files["mask"]),
        "inpaint_matchpatch[0]",
        "[1]",
        "keep[0]",
        "-o",
        str(out),
    ]


def _cv2_missing() -> str | None:
    try:
        import cv2

        cv2.xphoto.inpaint  # noqa: B018 (opencv-contrib's module)
    except (ImportError, AttributeError) as e:
        return f"OpenCV contrib missing: {e}"
    return None


TOOLS: list[Tool] = [
    Tool("weft", _weft_command(None), weft=True),
    *[Tool(f"weft --engine {e}", _weft_command(e), weft=True, engine=e) for e in WEFT_ENGINES],
    Tool(
        "weft --engine patchmatch --structure no",
        _weft_command("patchmatch", "--structure", "no"),
        weft=True,
        engine="patchmatch",
    ),
    Tool(
        "G'MIC inpaint_matchpatch",
        _gmic_command,
        lambda: None if shutil.which("gmic") else "gmic is not on the PATH (Debian: apt-get install gmic)",
    ),
    Tool("OpenCV xphoto shift-map", _peer_command("shiftmap", lambda: sys.executable), _cv2_missing),
    Tool(
        "pypatchmatch", _peer_command("pypatchmatch", peers_python), lambda: _importable(peers_python(), "patchmatch")
    ),
    Tool(
        "Resynthesizer (PyPI)",
        _peer_command("resynthesizer", peers_python),
        lambda: _importable(peers_python(), "resynthesizer"),
    ),
    Tool("OpenCV Telea", _peer_command("telea", lambda: sys.executable), _cv2_missing),
    Tool("OpenCV NS", _peer_command("ns", lambda: sys.executable), _cv2_missing),
]
GMIC = "G'MIC inpaint_matchpatch"
SHIFTMAP = "OpenCV xphoto shift-map"


def tools_named(names: list[str] | None) -> list[Tool]:
    """The tools whose names start with one of ``names`` (all for None): "weft" selects every weft row."""
    if not names:
        return list(TOOLS)
    picked = [t for t in TOOLS if any(t.name.lower().startswith(n.lower()) for n in names)]
    if not picked:
        raise ValueError(f"no tool matches {', '.join(names)} (tools: {', '.join(t.name for t in TOOLS)})")
    return picked


# ---------------------------------------------------------------------------------------------- figures


def _float(img: np.ndarray) -> np.ndarray:
    return img.astype(np.float32) / 255.0


def read_output(path: Path, like: np.ndarray) -> np.ndarray:
    """A tool's output as uint8 with the channel count of ``like`` (a grey result of a colour tool
    averaged; 16-bit scaled to 8)."""
    from PIL import Image

    with Image.open(path) as im:
        if im.mode in ("I;16", "I;16B", "I"):
            arr = np.round(np.asarray(im, dtype=np.float64) / 257.0).astype(np.uint8)
        else:
            arr = np.asarray(
                im.convert(
                    "L"
                    if like.ndim == 2 and im.mode in ("L", "LA", "1", "P")
                    else ("RGB" if like.ndim == 3 else im.mode)
                )
            )
    if like.ndim == 2 and arr.ndim == 3:
        arr = np.round(arr[..., :3].astype(np.float32).mean(axis=2)).astype(np.uint8)
    if like.ndim == 3 and arr.ndim == 2:
        arr = np.repeat(arr[..., None], 3, axis=2)
    return arr


def figures(out: np.ndarray, inputs: FillInputs) -> dict[str, float]:
    """The issue's judges of one filled canvas ``out`` (uint8) and its known-pixel checks."""
    from scipy.ndimage import distance_transform_cdt
    from weft.core.metrics import fill_coherence, fill_detail, fill_seam

    hole = inputs.hole
    if out.shape != inputs.truth.shape:
        return {
            "error": f"output is {out.shape[1]}x{out.shape[0]}, expected "
            f"{inputs.truth.shape[1]}x{inputs.truth.shape[0]}"
        }
    f = _float(out)
    row = {
        "coherence": fill_coherence(f, hole, _float(inputs.image)),
        "detail": fill_detail(f, hole),
        "seam": fill_seam(f, hole),
    }
    # each known pixel's distance to the hole in 8-connected steps (1 = touching, corners included):
    # the method's band is the square neighbourhood, 2 px = every pixel of a 5x5 square around a hole pixel
    dist = distance_transform_cdt(~hole, metric="chessboard")
    diff = np.abs(out.astype(np.int16) - inputs.image.astype(np.int16))
    if diff.ndim == 3:
        diff = diff.max(axis=2)
    known = ~hole
    row["band_max"] = int(diff[known & (dist <= BAND)].max(initial=0))
    row["known_max"] = int(diff[known & (dist > BAND)].max(initial=0))
    changed = known & (diff > 0)
    row["reach_px"] = int(dist[changed].max(initial=0))
    if inputs.placeholder >= 0:
        same = out == inputs.placeholder
        same = same.all(axis=2) if same.ndim == 3 else same
        row["unfilled"] = float(same[hole].mean())
    return row


def truth_figures(inputs: FillInputs) -> dict[str, float]:
    from weft.core.metrics import fill_coherence, fill_detail, fill_seam

    f = _float(inputs.truth)
    return {
        "coherence": fill_coherence(f, inputs.hole, _float(inputs.image)),
        "detail": fill_detail(f, inputs.hole),
        "seam": fill_seam(f, inputs.hole),
    }


def goals(row: dict[str, Any], rows: list[dict[str, Any]], truth: dict[str, float], case: FillCase) -> str:
    """The issue's goals for a weft row, each "name yes/NO" (peer rows that are missing skip theirs)."""
    peer = {r["tool"]: r for r in rows if "error" not in r and "missing" not in r}
    out = []
    g, s = peer.get(GMIC), peer.get(SHIFTMAP)
    if g is not None and s is not None:
        ok = row["coherence"] <= g["coherence"] and row["coherence"] <= 1.2 * s["coherence"]
        out.append(f"coherence {'yes' if ok else 'NO'}")
    lo, hi = 0.8 * truth["detail"], 1.25 * truth["detail"]
    out.append(f"detail {'yes' if lo <= row['detail'] <= hi else 'NO'}")
    out.append(f"seam {'yes' if abs(row['seam'] - truth['seam']) <= 0.15 else 'NO'}")
    out.append(f"known {'yes' if row['known_max'] == 0 else 'NO'}")
    if case.uncrop:
        out.append(f"time {'yes' if row['process_s'] <= 1.5 else 'NO'}")
    elif g is not None:
        out.append(f"time {'yes' if row['process_s'] <= g['process_s'] else 'NO'}")
    return ", ".join(out)


# ---------------------------------------------------------------------------------------------- running


def write_inputs(inputs: FillInputs, folder: Path) -> dict[str, Path]:
    """The case's files: ``canvas`` (the peers' input), ``mask`` (white = fill) and ``image`` (weft's
    input: the canvas, or for an uncrop its known centre)."""
    from PIL import Image

    folder.mkdir(parents=True, exist_ok=True)
    files = {"canvas": folder / "canvas.png", "mask": folder / "mask.png", "image": folder / "image.png"}
    Image.fromarray(inputs.image).save(files["canvas"])
    Image.fromarray(inputs.hole.astype(np.uint8) * 255).save(files["mask"])
    Image.fromarray(np.ascontiguousarray(inputs.known_part)).save(files["image"])
    return files


GNU_TIME = "/usr/bin/time"


def _run(cmd: list[str], env: dict[str, str] | None = None) -> tuple[float, int, str]:
    """(seconds, peak RSS bytes, error text or '') of one whole process.

    The peak is GNU time's "maximum resident set size" of the command when ``/usr/bin/time`` is
    there: ``ru_maxrss`` from ``wait4`` on a child of this process would not do, since Linux carries
    the parent's resident size at the fork into the child's peak (``/bin/true`` started from a
    benchmark holding 450 MB "peaks" at 450 MB), and this process holds numpy, SciPy and weft. GNU
    time forks from its own 1 MB. Without it, the figure is an upper bound (marked in the row).
    """
    timed = os.path.exists(GNU_TIME)
    with tempfile.NamedTemporaryFile(prefix="weft-rss-", suffix=".txt", delete=False) as f:
        rss_file = f.name
    try:
        argv = [GNU_TIME, "-f", "%M", "-o", rss_file, *cmd] if timed else cmd
        t0 = time.perf_counter()
        proc = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env)
        err = proc.stderr.read()  # read while it runs: a full pipe must not stall the child
        _, status, usage = os.wait4(proc.pid, 0)
        seconds = time.perf_counter() - t0
        proc.returncode = os.waitstatus_to_exitcode(status)
        proc.stderr.close()
        rss = usage.ru_maxrss * 1024
        if timed:
            lines = Path(rss_file).read_text().split()
            rss = int(lines[-1]) * 1024 if lines and lines[-1].isdigit() else -1
    finally:
        os.unlink(rss_file)
    lines = [
        ln
        for ln in err.decode(errors="replace").strip().splitlines()
        if not ln.startswith("Command exited with non-zero status")
    ]
    return seconds, rss, (lines[-1] if lines else f"exit {proc.returncode}") if proc.returncode else ""


def run_tool_once(
    tool: Tool, case: FillCase, inputs: FillInputs, files: dict[str, Path], out: Path, env: dict[str, str] | None = None
) -> tuple[float, int, str]:
    return _run(tool.command(files, out, case, inputs), env)


def run_fill_case(
    case: FillCase,
    *,
    repeats: int = 5,
    quick: bool = False,
    tools: list[Tool] | None = None,
    keep: Path | None = None,
    cold: bool = True,
) -> list[dict[str, Any]]:
    """Every tool on ``case``: the rows (one per tool, then the ground truth's)."""
    if case.preview:
        if tools is not None and not any(t.weft for t in tools):
            return []
        rows = preview_times(2 if quick else max(20, repeats))
        rows[0]["load"] = os.getloadavg()[0]
        return rows
    tools = TOOLS if tools is None else tools
    inputs = case.build()
    size = [inputs.truth.shape[1], inputs.truth.shape[0]]
    rows: list[dict[str, Any]] = []
    with tempfile.TemporaryDirectory(prefix="weft-fill-bench-") as tmp:
        folder = Path(tmp)
        files = write_inputs(inputs, folder)
        live = []
        for i, tool in enumerate(tools):
            row: dict[str, Any] = {"case": case.name, "tool": tool.name, "size": size}
            why = tool.missing()
            if why:
                row["missing"] = why
            rows.append(row)
            if not why:
                live.append((tool, row, folder / f"out{i}.png"))
        if cold and not quick:  # a newcomer's first run: every kernel compiles
            for tool, row, out in live:
                if tool.weft and tool.engine is None:
                    with tempfile.TemporaryDirectory(prefix="weft-numba-") as cache:
                        s, _, err = run_tool_once(
                            tool, case, inputs, files, out, {**os.environ, "NUMBA_CACHE_DIR": cache}
                        )
                    if not err:
                        row["cold_s"] = s
        if not quick:  # warm-up: numba's cache, the OS's file cache
            for tool, row, out in live:
                _, _, err = run_tool_once(tool, case, inputs, files, out)
                if err:
                    row["error"] = err
        times: dict[str, list[float]] = {t.name: [] for t, _, _ in live}
        peaks: dict[str, list[int]] = {t.name: [] for t, _, _ in live}
        for _ in range(max(1, repeats)):
            for tool, row, out in live:
                if "error" in row:
                    continue
                s, rss, err = run_tool_once(tool, case, inputs, files, out)
                if err:
                    row["error"] = err
                    continue
                times[tool.name].append(s)
                peaks[tool.name].append(rss)
        for tool, row, out in live:
            if "error" in row:
                continue
            row.update(
                runs=len(times[tool.name]),
                process_s=statistics.median(times[tool.name]),
                min_s=min(times[tool.name]),
                peak_mib=statistics.median(peaks[tool.name]) / 2**20,
            )
            if not os.path.exists(GNU_TIME):
                row["peak_upper_bound"] = True
            result = read_output(out, inputs.truth)
            row.update(figures(result, inputs))
            if keep is not None:
                keep.mkdir(parents=True, exist_ok=True)
                shutil.copy(out, keep / f"{case.name}--{slug(tool.name)}.png")
    truth = truth_figures(inputs)
    for row in rows:
        if row.get("tool", "").startswith("weft") and "coherence" in row:
            row["goals"] = goals(row, rows, truth, case)
    rows.append({"case": case.name, "tool": "ground truth", "size": size, **truth})
    rows[0]["load"] = os.getloadavg()[0]  # the 1-minute load average as the case ends
    return rows


def slug(name: str) -> str:
    return "".join(ch if ch.isalnum() else "-" for ch in name.lower()).strip("-").replace("--", "-")


def preview_times(repeats: int = 20, engines: tuple[str | None, ...] = (None, *WEFT_ENGINES)) -> list[dict[str, Any]]:
    """The studio's figure: a reduced preview, a 128x128 crop around one brush stroke of the gravel
    case, filled in-process through the Python API; median (and max) of ``repeats`` runs after one
    warm-up, per engine (None = the default)."""
    import time

    inputs = build_gravel()
    crop = (slice(160, 288), slice(40, 168))  # around the wire's left part
    image = _float(inputs.image[crop])
    hole = inputs.hole[crop]
    rows = []
    try:
        from weft.core.fill import fill
    except ImportError as e:
        return [{"case": "fill-preview-128", "tool": "weft", "size": [128, 128], "error": f"weft.core.fill: {e}"}]
    for engine in engines:
        row: dict[str, Any] = {
            "case": "fill-preview-128",
            "tool": "weft" + (f" --engine {engine}" if engine else ""),
            "size": [128, 128],
        }
        try:
            fill(image, hole, engine=engine, seed=1)
            t = []
            for _ in range(repeats):
                t0 = time.perf_counter()
                out = fill(image, hole, engine=engine, seed=1)
                t.append(time.perf_counter() - t0)
            row.update(
                runs=repeats, median_ms=1000 * statistics.median(t), max_ms=1000 * max(t), hole_px=int(hole.sum())
            )
            from weft.core.metrics import fill_detail

            row["detail"] = fill_detail(out, hole)
        except Exception as e:  # a benchmark reports a failing engine and goes on
            row["error"] = f"{type(e).__name__}: {e}"
        rows.append(row)
    return rows


_COLUMNS = [
    ("tool", "tool", "{}"),
    ("process_s", "process s", "{:.2f}"),
    ("cold_s", "first run s", "{:.1f}"),
    ("peak_mib", "peak MiB", "{:.0f}"),
    ("hole_px", "hole px", "{}"),
    ("median_ms", "median ms", "{:.1f}"),
    ("max_ms", "max ms", "{:.1f}"),
    ("coherence", "coherence", "{:.2f}"),
    ("detail", "detail", "{:.2f}"),
    ("seam", "seam", "{:.2f}"),
    ("band_max", "band Δ", "{}"),
    ("known_max", "known Δ", "{}"),
    ("reach_px", "reach px", "{}"),
    ("unfilled", "unfilled", "{:.1%}"),
    ("goals", "goals", "{}"),
]


def markdown_table(rows: list[dict[str, Any]]) -> str:
    """One table per case (its name and size as a heading line), columns some row has."""
    out = []
    for name in dict.fromkeys(r["case"] for r in rows):
        part = [r for r in rows if r["case"] == name]
        cols = [c for c in _COLUMNS if any(c[0] in r for r in part)]
        if len(cols) == 1:  # only notes: give them a column
            cols.append(("note", "", "{}"))
        w, h = part[0].get("size", ("?", "?"))
        load = f", load average {part[0]['load']:.1f}" if "load" in part[0] else ""
        out.append(f"{name} ({w}x{h}{load})")
        out.append("| " + " | ".join(c[1] for c in cols) + " |")
        out.append("|" + "|".join("---" for _ in cols) + "|")
        for r in part:
            if "missing" in r or "error" in r:
                note = ("not run: " + r["missing"]) if "missing" in r else ("failed: " + r["error"])
                out.append(f"| {r['tool']} | {note} |" + " |" * (len(cols) - 2))
                continue
            cells = [c[2].format(r[c[0]]) if c[0] in r else "" for c in cols]
            out.append("| " + " | ".join(cells) + " |")
        out.append("")
    return "\n".join(out).rstrip()


def seed_medians(
    names: list[str], seeds: range, engine: str | None = None, patch: int | None = None
) -> list[dict[str, Any]]:
    """Per case, in-process through ``weft.core.fill.fill`` (default band): the median over ``seeds``
    of coherence, of detail as a ratio to the truth's and of seam as a difference from the truth's,
    and the seed-by-seed coherences (the README's "over seeds 0-4" line)."""
    from weft.core.fill import fill

    cases = by_name()
    out = []
    for name in names:
        inputs = cases[name].build()
        truth = truth_figures(inputs)
        rows = []
        for seed in seeds:
            kw = {} if inputs.extend is None else {"extend": inputs.extend}
            filled = fill(
                inputs.known_part,
                None if inputs.extend is not None else inputs.hole,
                seed=seed,
                engine=engine,
                patch=patch,
                **kw,
            )
            rows.append(figures(np.clip(np.rint(filled * 255), 0, 255).astype(np.uint8), inputs))
        med = {key: statistics.median(r[key] for r in rows) for key in ("coherence", "detail", "seam")}
        out.append(
            {
                "case": name,
                "coherence": med["coherence"],
                "detail": med["detail"] / truth["detail"],
                "seam": med["seam"] - truth["seam"],
                "each": [round(r["coherence"], 2) for r in rows],
            }
        )
    return out


if __name__ == "__main__":  # python -m benchmarks.fill [--seeds 0-4] [--engine E] [--patch P] [CASE...]
    import argparse

    ap = argparse.ArgumentParser(description="fill figures over several seeds, in-process (medians)")
    ap.add_argument("cases", nargs="*", default=[c.name for c in CASES if not c.preview])
    ap.add_argument("--seeds", default="0-4", help="first-last (inclusive)")
    ap.add_argument("--engine", default=None)
    ap.add_argument("--patch", type=int, default=None)
    args = ap.parse_args()
    first, last = (int(v) for v in args.seeds.split("-"))
    for r in seed_medians(args.cases, range(first, last + 1), args.engine, args.patch):
        print(
            f"{r['case']}: coherence {r['coherence']:.2f}, detail {r['detail']:.2f} of the truth's, seam "
            f"{r['seam']:+.2f} from the truth's (seeds {args.seeds}: {r['each']})"
        )
