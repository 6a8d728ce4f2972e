"""First run against second: ``python -m benchmarks.cold [--runs 3] [--only NAME...] [--json PATH]``.

What a newcomer meets. Every command of the table runs as its own ``weft`` process, with stderr on a
pseudo-terminal (as in a shell, so the progress bar and the "preparing" line are drawn), ``runs``
times *cold* — each in a fresh, empty ``NUMBA_CACHE_DIR``, so every kernel compiles — and ``runs``
times *warm* — in the folder the last cold run filled. Per command it reports the median wall time
of each, their ratio, and the longest stretch the terminal stayed silent (from the start to the
first byte on stderr, between two writes, or from the last write to the exit), cold.

The studio row is the time from starting the process to the first full result shown (offscreen
Qt, the bundled examples, the real main window); ``warm-up`` is ``weft warm-up`` itself (every
method's kernels, in parallel processes). Prints a Markdown table (the README's) and writes the
rows as JSON.
"""

from __future__ import annotations

import argparse
import json
import os
import pty
import select
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RES = ROOT / "resources"


def commands(tmp: Path, python: str = sys.executable) -> dict[str, list[str]]:
    """The timed commands (the issue's table, plus blend and rectify in their kernel modes), run by
    ``python`` (another checkout's interpreter measures that checkout: a baseline)."""
    out = str(tmp / "out.png")
    weft = [python, "-c", "import sys; from weft.app.cli import main; sys.exit(main())"]

    return {
        "studio": [python, str(Path(__file__).resolve()), "--probe-studio"],
        "quilt --target, 3 passes": [
            *weft,
            "quilt",
            str(RES / "gravel.png"),
            "--target",
            str(RES / "camera.png"),
            "--iterations",
            "3",
            "-o",
            out,
        ],
        "nfpt 1024x768": [
            *weft,
            "nfpt",
            str(RES / "perspective.png"),
            "--lines",
            str(RES / "perspective-lines.json"),
            "--size",
            "1024x768",
            "-o",
            out,
        ],
        "affine": [*weft, "affine", str(RES / "brick.png"), "-o", out],
        "fast --target": [*weft, "fast", str(RES / "gravel.png"), "--target", str(RES / "camera.png"), "-o", out],
        "blend --mode poisson": [
            *weft,
            "blend",
            str(tmp / "fg.png"),
            str(tmp / "bg.png"),
            "--mask",
            str(tmp / "mask.png"),
            "--mode",
            "poisson",
            "-o",
            out,
        ],
        "rectify --warp lines": [
            *weft,
            "rectify",
            str(RES / "perspective.png"),
            "--lines",
            str(RES / "perspective-lines.json"),
            "--warp",
            "lines",
            "-o",
            out,
        ],
        "warm-up (all methods)": [*weft, "warm-up"],
    }


def _blend_inputs(tmp: Path) -> None:
    import numpy as np
    from weft.core.image import load_image, save_image

    fg = load_image(RES / "brick.png").image[:256, :256]
    bg = load_image(RES / "gravel.png").image[:256, :256]
    if bg.shape != fg.shape:
        bg = np.resize(bg, fg.shape)
    y, x = np.mgrid[:256, :256]
    save_image(tmp / "fg.png", fg)
    save_image(tmp / "bg.png", bg)
    save_image(tmp / "mask.png", (((x - 128) ** 2 + (y - 128) ** 2) < 80**2).astype(np.float32))


def timed_run(cmd: list[str], cache: str, timeout: float = 600.0, cwd: Path = ROOT) -> dict:
    """Run ``cmd`` with stderr on a pseudo-terminal; wall seconds (or, for the studio probe, seconds
    to its first result), the longest silence on that terminal, and what it printed there."""
    env = dict(os.environ, NUMBA_CACHE_DIR=cache, QT_QPA_PLATFORM="offscreen", COLUMNS="100")
    master, slave = pty.openpty()
    t0 = time.time()
    proc = subprocess.Popen(
        cmd, cwd=cwd, env=env, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=slave, close_fds=True
    )
    os.close(slave)
    writes, text = [t0], b""
    out_chunks = []
    open_fds = {master, proc.stdout.fileno()}
    while open_fds:
        ready, _, _ = select.select(list(open_fds), [], [], 0.05)
        for fd in ready:
            try:
                chunk = os.read(fd, 65536)
            except OSError:  # the child closed the terminal (EIO)
                chunk = b""
            if not chunk:
                open_fds.discard(fd)
            elif fd == master:
                writes.append(time.time())
                text += chunk
            else:  # stdout: in a shell it is the same terminal
                writes.append(time.time())
                out_chunks.append(chunk)
        if time.time() - t0 > timeout:
            proc.kill()
            raise TimeoutError(f"{' '.join(cmd)} took over {timeout} s")
    proc.wait()
    end = time.time()
    os.close(master)
    stdout = b"".join(out_chunks).decode(errors="replace")
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd[-6:])} exited {proc.returncode}: {text.decode(errors='replace')[-400:]}")
    seconds = end - t0
    if "--probe-studio" in cmd:  # the probe prints when its first result was shown
        probe = json.loads(stdout.strip().splitlines()[-1])
        seconds = probe["shown_at"] - t0
        end = probe["shown_at"]
        writes = [t0, end]  # the studio says what it does in its window, not on a terminal
    gaps = [b - a for a, b in zip(writes, writes[1:] + [end], strict=True)]
    return {"seconds": seconds, "silent": max(gaps), "first_words": gaps[0], "stderr": text.decode(errors="replace")}


def measure(
    names: list[str] | None = None, runs: int = 3, python: str = sys.executable, root: Path = ROOT
) -> list[dict]:
    rows = []
    with tempfile.TemporaryDirectory(prefix="weft-cold-") as tmp_s:
        tmp = Path(tmp_s)
        _blend_inputs(tmp)
        for name, cmd in commands(tmp, python).items():
            if names and name not in names:
                continue
            print(f"running {name} ...", file=sys.stderr, flush=True)
            cold, silent, first = [], [], []
            cache = ""
            try:
                for _ in range(runs):
                    cache = tempfile.mkdtemp(prefix="cache-", dir=tmp)
                    r = timed_run(cmd, cache, cwd=root)
                    cold.append(r["seconds"])
                    silent.append(r["silent"])
                    first.append(r["first_words"])
                warm = [timed_run(cmd, cache, cwd=root)["seconds"] for _ in range(runs)]
            except RuntimeError as e:  # e.g. a command the measured checkout does not have
                print(f"  {name}: {e}", file=sys.stderr)
                continue
            rows.append(
                {
                    "command": name,
                    "runs": runs,
                    "cold_s": round(statistics.median(cold), 2),
                    "warm_s": round(statistics.median(warm), 2),
                    "ratio": round(statistics.median(cold) / statistics.median(warm), 2),
                    "cold_silent_s": round(max(silent), 2),
                    "cold_first_words_s": round(max(first), 2),
                    "cold_range": [round(min(cold), 2), round(max(cold), 2)],
                    "warm_range": [round(min(warm), 2), round(max(warm), 2)],
                }
            )
            shutil.rmtree(cache, ignore_errors=True)
    return rows


def markdown_table(rows: list[dict]) -> str:
    lines = [
        "| command | cold s | warm s | cold / warm | first words on the terminal (cold) | longest silence (cold) |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for r in rows:
        studio = r["command"] == "studio"
        first = "—" if studio else f"{r['cold_first_words_s']:.1f} s"
        silent = "—" if studio else f"{r['cold_silent_s']:.1f} s"
        lines.append(
            f"| {r['command']} | {r['cold_s']:.1f} ({r['cold_range'][0]:.1f}–{r['cold_range'][1]:.1f}) | "
            f"{r['warm_s']:.1f} ({r['warm_range'][0]:.1f}–{r['warm_range'][1]:.1f}) | {r['ratio']:.1f}x | "
            f"{first} | {silent} |"
        )
    return "\n".join(lines)


def probe_studio() -> int:
    """Open the studio as ``weft`` does (examples loaded, offscreen) and print, as one JSON line, the
    wall-clock time its first full result was shown, with the render and kernel-preparation times."""
    from PySide6.QtCore import QSettings, QTimer
    from PySide6.QtWidgets import QApplication
    from weft.app.gui.main_window import MainWindow

    app = QApplication.instance() or QApplication(sys.argv[:1])
    with tempfile.TemporaryDirectory() as tmp:
        os.environ["WEFT_RECOVERY_DIR"] = tmp  # never touch the user's recovery file
        settings = QSettings(os.path.join(tmp, "weft.ini"), QSettings.Format.IniFormat)
        window = MainWindow(settings=settings)
        window.show()
        seen = {}

        def shown(s) -> None:
            if s.final and not seen:
                seen.update(shown_at=time.time(), render_s=s.seconds, prepared_s=getattr(s, "prepared", None))
                QTimer.singleShot(0, app.quit)

        window.renderer.shown.connect(shown)
        window.renderer.failed.connect(lambda m: (seen.update(error=m), app.quit()))
        QTimer.singleShot(300_000, app.quit)
        app.exec()
        window.doc.undo_stack.setClean()
        window.close()
    if "shown_at" not in seen:
        print(f"no result: {seen.get('error', 'timed out')}", file=sys.stderr)
        return 1
    print(json.dumps(seen), flush=True)
    return 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        prog="python -m benchmarks.cold", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--runs", type=int, default=3, help="cold runs and warm runs per command (default 3)")
    ap.add_argument("--only", nargs="*", metavar="NAME", help="only these commands (names as in the table)")
    ap.add_argument(
        "--json", type=Path, default=None, help="where to write the results (default benchmarks/results/cold.json)"
    )
    ap.add_argument(
        "--python",
        default=sys.executable,
        help="the interpreter whose weft is measured (e.g. another checkout's .venv/bin/python)",
    )
    ap.add_argument("--root", type=Path, default=ROOT, help="that checkout's folder (the commands run there)")
    ap.add_argument("--probe-studio", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.probe_studio:
        return probe_studio()
    rows = measure(args.only, args.runs, args.python, args.root)
    print(f"{os.cpu_count()} cores, cold = a fresh NUMBA_CACHE_DIR per run, median of {args.runs}")
    print(markdown_table(rows))
    from .record import command, write_results

    write_results(
        "cold",
        rows,
        command=command("benchmarks.cold", argv),
        path=args.json,
        note=f"cold: a fresh NUMBA_CACHE_DIR per run; median of {args.runs} runs",
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
