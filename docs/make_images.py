"""Render the README's pictures into docs/images: ``.venv/bin/python docs/make_images.py [NAME ...]``.

Runs the gallery scripts (``docs/gallery/plot_*.py``, the same ones the documentation build runs)
with docs/images as the current folder, so they write their pictures there. With names
(``quilt``, ``fast``, ``affine``, ``nfpt``, ``parameters``), only those scripts.
"""

from __future__ import annotations

import os
import runpy
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent


def main(names: list[str]) -> int:
    sys.path[:0] = [str(DOCS.parent), str(DOCS / "gallery")]
    scripts = sorted((DOCS / "gallery").glob("plot_*.py"))
    if names:
        scripts = [s for s in scripts if s.stem.removeprefix("plot_") in names]
    out = DOCS / "images"
    out.mkdir(exist_ok=True)
    os.chdir(out)
    for script in scripts:
        print(script.name, flush=True)
        runpy.run_path(str(script), run_name="__main__")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
