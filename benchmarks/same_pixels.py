"""Do refactors leave the pixels alone? Runs a fixed list of commands, one or more per method and
mode, and prints a SHA-256 of each output's decoded pixels (not the file bytes: a PNG also carries
its recipe). ``--write FILE`` keeps the hashes; ``--check FILE`` compares against kept ones and
exits 1 naming each command whose pixels changed.

    python benchmarks/same_pixels.py --write /tmp/before.json
    ... refactor ...
    python benchmarks/same_pixels.py --check /tmp/before.json
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
R = ROOT / "resources"
E = ROOT / "docs" / "examples"

#: name -> weft arguments (the output is appended as ``-o OUT``).
COMMANDS: dict[str, list[str]] = {
    "quilt-synth": ["quilt", f"{R}/brick.png", "--size", "160x128", "--seed", "7"],
    "quilt-transfer": ["quilt", f"{R}/grass.png", "--target", f"{E}/frames/frame_0.png", "--seed", "2"],
    "fast-artistic": [
        "fast",
        f"{R}/hatching.png",
        "--target",
        f"{R}/chelsea.png",
        "--metric",
        "artistic",
        "--p",
        "0.2",
        "--colour",
        "source",
        "--seed",
        "5",
    ],
    "fast-synth": ["fast", f"{R}/gravel.png", "--size", "96x96", "--seed", "3"],
    "affine-synth": ["affine", f"{R}/brick.png", "--seed", "4"],
    "affine-swirl": ["affine", f"{R}/brick.png", "--field", "swirl", "--size", "128x128", "--seed", "4"],
    "rectify-lines": ["rectify", f"{R}/perspective.png", "--lines", f"{R}/perspective-lines.json"],
    "rectify-auto": ["rectify", f"{R}/perspective.png", "--auto"],
    "nfpt-into-photo": [
        "nfpt",
        f"{R}/perspective.png",
        "--lines",
        f"{R}/perspective-lines.json",
        "--size",
        "256x192",
        "--into-photo",
        "true",
        "--seed",
        "1",
    ],
    "fill-hole-auto": ["fill", f"{R}/coffee.png", "--mask", f"{E}/coffee-spoon-mask.png", "--seed", "1"],
    "fill-hole-patchmatch": [
        "fill",
        f"{R}/coffee.png",
        "--mask",
        f"{E}/coffee-spoon-mask.png",
        "--engine",
        "patchmatch",
        "--seed",
        "1",
    ],
    "fill-uncrop": ["fill", f"{R}/brick.png", "--extend", "0,0,96,32", "--seed", "1"],
    "blend-laplacian": ["blend", f"{R}/grass.png", f"{R}/gravel.png", "--mask", f"{E}/oval-mask.png"],
}


def pixel_hash(path: Path) -> str:
    import cv2

    image = np.ascontiguousarray(cv2.imread(str(path), cv2.IMREAD_UNCHANGED))
    return hashlib.sha256(f"{image.dtype}{image.shape}".encode() + image.tobytes()).hexdigest()


def run_all(names: list[str]) -> dict[str, str]:
    from weft.app.cli import main

    hashes = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name in names:
            out = Path(tmp) / f"{name}.png"
            code = main([*COMMANDS[name], "-o", str(out)])
            hashes[name] = pixel_hash(out) if code == 0 and out.exists() else f"exit {code}"
            print(f"{name:24s} {hashes[name]}", flush=True)
    return hashes


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    group = parser.add_mutually_exclusive_group()
    group.add_argument("--write", type=Path, help="keep the hashes in this JSON file")
    group.add_argument("--check", type=Path, help="compare with hashes kept by --write")
    parser.add_argument("names", nargs="*", help=f"commands to run (default: all of {', '.join(COMMANDS)})")
    args = parser.parse_args()
    hashes = run_all(args.names or list(COMMANDS))
    if args.write:
        args.write.write_text(json.dumps(hashes, indent=1) + "\n")
    if args.check:
        kept = json.loads(args.check.read_text())
        changed = [n for n, h in hashes.items() if kept.get(n) != h]
        for name in changed:
            print(f"changed: {name} ({' '.join(COMMANDS[name])})")
        print(f"{len(hashes) - len(changed)} of {len(hashes)} identical")
        return 1 if changed else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
