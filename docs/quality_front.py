"""T2's quality front: weft's transfer settings against the peers, as a plot and a table.

    .venv/bin/python docs/quality_front.py

T2 renders ``camera_256`` (``skimage.data.camera()`` box-downscaled 2x) in ``gravel_128``
(``gravel()[0:256, 0:256]`` box-downscaled 2x), the peers' own inputs (issue 17). For each weft
setting below it runs the real code, measures fidelity (higher is better) and coherence (lower is
better) with ``weft.core.metrics``, prints a markdown table (with, for each peer, the first setting that
beats it on both) and draws ``docs/images/quality-front.png``: fidelity against coherence, weft's
settings as a line, the peers (measured on the project's machine, same inputs; figures from the
issue) as points. Drawn with OpenCV (no plotting library).
"""

from __future__ import annotations

import itertools
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from weft.core.metrics import coherence, fidelity  # noqa: E402

OUT = ROOT / "docs" / "images" / "quality-front.png"

#: (label, method, parameters): the documented settings, from faithful to coherent; the last two
#: are the issue's reference points (not on the front).
SETTINGS = [
    (
        "quilt block 4/2, α 0.1, 3 passes, luminance",
        "quilt",
        dict(block=4, overlap=2, alpha=0.1, iterations=3, correspondence="luminance"),
    ),
    ("quilt block 5/2, α 0.1, 3 passes", "quilt", dict(block=5, overlap=2, alpha=0.1, iterations=3)),
    ("quilt block 4/2, α 0.1, 3 passes", "quilt", dict(block=4, overlap=2, alpha=0.1, iterations=3)),
    ("quilt block 9/3, α 0.1, 3 passes", "quilt", dict(block=9, overlap=3, alpha=0.1, iterations=3)),
    ("fast --metric target --p 0.05", "fast", dict(metric="target", p=0.05)),
]

#: The peers on T2, (fidelity, coherence), measured on the project's machine (issue 17).
PEERS = {
    "Resynthesizer": (0.996, 0.54),
    "numpy quilting (axu2)": (0.984, 0.41),
    "Ashikhmin C++": (0.94, 0.50),
    "G'MIC stylize": (0.54, 0.35),
}


def inputs() -> tuple[np.ndarray, np.ndarray]:
    """gravel_128 and camera_256, float32 grey in [0, 1]."""
    from skimage import data

    def box2(a):
        a = a.astype(np.float32) / 255.0
        return ((a[0::2, 0::2] + a[1::2, 0::2] + a[0::2, 1::2] + a[1::2, 1::2]) / 4).astype(np.float32)

    return box2(data.gravel()[0:256, 0:256]), box2(data.camera())


def measure(seed: int = 1) -> list[tuple[str, float, float]]:
    """(label, fidelity, coherence) of every setting."""
    from weft.core import fast, quilting

    gravel, camera = inputs()
    rows = []
    for label, method, kw in SETTINGS:
        if method == "quilt":
            out = quilting.transfer(gravel, camera, rng=seed, **kw)
        else:
            out = fast.transfer(gravel, camera, rng=seed, **kw)
        rows.append((label, fidelity(out, camera), coherence(out, gravel)))
        print(f"{label}: fidelity {rows[-1][1]:.4f}, coherence {rows[-1][2]:.4f}", file=sys.stderr, flush=True)
    return rows


def pareto(rows: list[tuple[str, float, float]]) -> list[tuple[str, float, float]]:
    """The settings no other setting beats on both fidelity and coherence."""
    return [r for r in rows if not any(o[1] >= r[1] and o[2] <= r[2] and o != r for o in rows)]


def table(rows: list[tuple[str, float, float]]) -> str:
    lines = [
        "| | T2 setting or peer | fidelity (higher is better) | coherence (lower is better) | beats on both |",
        "| --- | --- | --- | --- | --- |",
    ]
    front = pareto(rows)
    for k, row in enumerate(rows):
        label, fid, coh = row
        beaten = [p for p, (pf, pc) in PEERS.items() if fid > pf and coh < pc]
        lines.append(
            f"| {k + 1}{' (front)' if row in front else ''} | weft {label} | {fid:.4f} | {coh:.3f} | "
            f"{', '.join(beaten) or '—'} |"
        )
    for p, (pf, pc) in PEERS.items():
        lines.append(f"| | {p} (peer) | {pf:.3f} | {pc:.2f} | |")
    return "\n".join(lines)


def draw(rows: list[tuple[str, float, float]], path: Path = OUT) -> None:
    """Fidelity (y) against coherence (x): weft's settings as a line, the peers as points."""
    import cv2

    w, h, left, right, top, bottom = 960, 560, 80, 320, 40, 60
    img = np.full((h, w, 3), 255, np.uint8)
    pts = [(c, f) for _, f, c in rows] + [(c, f) for f, c in PEERS.values()]
    c_lo, c_hi = 0.30, 0.58
    f_lo, f_hi = min(0.5, min(f for _, f in pts) - 0.02), 1.0

    def xy(c, f):
        return (
            int(left + (c - c_lo) / (c_hi - c_lo) * (w - left - right)),
            int(h - bottom - (f - f_lo) / (f_hi - f_lo) * (h - top - bottom)),
        )

    grey, black, font = (200, 200, 200), (0, 0, 0), cv2.FONT_HERSHEY_SIMPLEX
    for c in np.arange(c_lo, c_hi + 1e-9, 0.04):
        x, _ = xy(c, f_lo)
        cv2.line(img, (x, top), (x, h - bottom), grey, 1)
        cv2.putText(img, f"{c:.2f}", (x - 16, h - bottom + 20), font, 0.45, black, 1, cv2.LINE_AA)
    for f in np.arange(0.5, 1.0 + 1e-9, 0.05):
        if f < f_lo:
            continue
        _, y = xy(c_lo, f)
        cv2.line(img, (left, y), (w - right, y), grey, 1)
        cv2.putText(img, f"{f:.2f}", (left - 46, y + 5), font, 0.45, black, 1, cv2.LINE_AA)
    cv2.rectangle(img, (left, top), (w - right, h - bottom), black, 1)
    cv2.putText(img, "coherence (lower is better)", (left + 150, h - 18), font, 0.55, black, 1, cv2.LINE_AA)
    cv2.putText(img, "fidelity (higher is better)", (8, 24), font, 0.55, black, 1, cv2.LINE_AA)
    blue, red = (200, 90, 20), (30, 30, 210)  # BGR
    front = sorted(pareto(rows), key=lambda r: r[2])
    for a, b in itertools.pairwise(front):
        cv2.line(img, xy(a[2], a[1]), xy(b[2], b[1]), blue, 2, cv2.LINE_AA)
    for k, row in enumerate(rows):
        _, fid, coh = row
        cv2.circle(img, xy(coh, fid), 5, blue, -1 if row in front else 2, cv2.LINE_AA)
        cv2.putText(img, str(k + 1), (xy(coh, fid)[0] + 7, xy(coh, fid)[1] - 6), font, 0.45, blue, 1, cv2.LINE_AA)
    for name, (fid, coh) in PEERS.items():
        x, y = xy(coh, fid)
        cv2.rectangle(img, (x - 5, y - 5), (x + 5, y + 5), red, -1)
        size = cv2.getTextSize(name, font, 0.42, 1)[0][0]
        tx = x + 8 if x + 8 + size < w - right else x - 8 - size
        cv2.putText(img, name, (tx, y + 16), font, 0.42, red, 1, cv2.LINE_AA)
    ly = top + 10
    cv2.putText(img, "weft (line: the front)", (w - right + 12, ly), font, 0.45, blue, 1, cv2.LINE_AA)
    for k, (label, _, _) in enumerate(rows):
        ly += 22
        text = f"{k + 1} {label}".replace("α", "alpha")  # Hershey fonts have no Greek
        cv2.putText(img, text, (w - right + 12, ly), font, 0.36, blue, 1, cv2.LINE_AA)
    ly += 34
    cv2.putText(img, "peers (squares)", (w - right + 12, ly), font, 0.45, red, 1, cv2.LINE_AA)
    path.parent.mkdir(parents=True, exist_ok=True)
    cv2.imwrite(str(path), img)


def main() -> int:
    rows = measure()
    draw(rows)
    print(table(rows))
    print(f"(plot written to {OUT.relative_to(ROOT)})", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
