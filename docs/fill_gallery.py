"""Render the fill gallery of the README into docs/images/fill-*.png: weft next to the peers.

    WEFT_PEERS_PYTHON=/path/to/peers/bin/python .venv/bin/python docs/fill_gallery.py

One picture per case of ``python -m benchmarks 'fill-*'`` (``benchmarks/fill.py`` builds them from
scikit-image's data): the input with the hole outlined in red, the ground truth, weft's fill (the
default engine, seed 1; on the photo also ``--engine patchmatch --structure no``, the default
without its edge guide), then G'MIC
``inpaint_matchpatch``, OpenCV's shift-map, ``pypatchmatch``, the PyPI Resynthesizer and (but on
the photo) OpenCV Telea, each captioned with its coherence / detail / seam (the
truth's own under the truth) and, when it changed known pixels, the largest change within 2 px of the
hole and beyond. Every tool runs as in the benchmark, as its own process on the same files; a tool
that is not installed gets a grey panel that says so.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import cv2
import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "docs" / "gallery"))

from panels import grid, label, rgb  # noqa: E402
from weft.core.image import save_image  # noqa: E402

from benchmarks import fill as bench  # noqa: E402

OUT = ROOT / "docs" / "images"
SHOWN = ["weft", bench.GMIC, bench.SHIFTMAP, "pypatchmatch", "Resynthesizer (PyPI)", "OpenCV Telea"]
# on the photo, weft without its edge guide takes the place of Telea (the smear reference; its figures stay in
# the table)
NO_GUIDE = "weft --engine patchmatch --structure no"
SHOWN_OBJECT = ["weft", NO_GUIDE, bench.GMIC, bench.SHIFTMAP, "pypatchmatch", "Resynthesizer (PyPI)"]
SHORT = {
    "weft": "weft fill (default engine)",
    NO_GUIDE: "weft fill --structure no",
    bench.GMIC: "G'MIC inpaint_matchpatch",
    bench.SHIFTMAP: "OpenCV shift-map",
    "pypatchmatch": "pypatchmatch",
    "Resynthesizer (PyPI)": "Resynthesizer",
    "OpenCV Telea": "OpenCV Telea",
}


def outlined(img: np.ndarray, hole: np.ndarray) -> np.ndarray:
    """The image (float RGB) with the hole's outline drawn in red, 1 px outside it."""
    out = rgb(img.astype(np.float32) / 255.0).copy()
    ring = cv2.dilate(hole.astype(np.uint8), np.ones((3, 3), np.uint8)).astype(bool) & ~hole
    out[ring] = (0.9, 0.1, 0.1)
    return out


def caption(name: str, figs: dict) -> str:
    if "error" in figs:
        return f"{name}|failed"
    text = f"{name}|coh {figs['coherence']:.1f}  detail {figs['detail']:.2f}  seam {figs['seam']:.2f}"
    if figs.get("known_max", 0) > 0:
        text += f"|known px moved: {figs['band_max']} levels within 2 px, {figs['known_max']} beyond"
    elif figs.get("band_max", 0) > 0:
        text += f"|known px moved: {figs['band_max']} levels within 2 px"
    return text


def blank(shape: tuple[int, ...], text: str) -> np.ndarray:
    panel = np.full((*shape[:2], 3), 0.85, np.float32)
    return label(panel, text)


def render(case: bench.FillCase, tools: dict[str, bench.Tool]) -> np.ndarray:
    inputs = case.build()
    truth = bench.truth_figures(inputs)
    panels = [
        label(outlined(inputs.image, inputs.hole), f"input, hole outlined|{int(inputs.hole.sum())} px to fill"),
        label(
            rgb(inputs.truth.astype(np.float32) / 255.0),
            f"ground truth|coh {truth['coherence']:.1f}  detail {truth['detail']:.2f}  seam {truth['seam']:.2f}",
        ),
    ]
    with tempfile.TemporaryDirectory(prefix="weft-fill-gallery-") as tmp:
        files = bench.write_inputs(inputs, Path(tmp))
        for name in SHOWN_OBJECT if case.name == "fill-object" else SHOWN:
            tool = tools[name]
            why = tool.missing()
            if why:
                panels.append(blank(inputs.truth.shape, f"{SHORT[name]}|not run: {why[:40]}"))
                continue
            out = Path(tmp) / f"{bench.slug(name)}.png"
            _, _, err = bench.run_tool_once(tool, case, inputs, files, out)
            if err:
                print(f"{case.name}: {name} failed: {err}", file=sys.stderr)
                panels.append(blank(inputs.truth.shape, f"{SHORT[name]}|failed: {err[:40]}"))
                continue
            result = bench.read_output(out, inputs.truth)
            panels.append(
                label(rgb(result.astype(np.float32) / 255.0), caption(SHORT[name], bench.figures(result, inputs)))
            )
    return grid(panels, cols=4)


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    tools = {t.name: t for t in bench.TOOLS}
    for case in bench.CASES:
        if case.preview:
            continue
        path = OUT / f"{case.name}.png"
        save_image(path, render(case, tools))
        print(path)


if __name__ == "__main__":
    main()
