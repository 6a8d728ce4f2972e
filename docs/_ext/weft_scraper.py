"""sphinx-gallery scraper for weft's gallery: the pictures an example writes into its folder.

A gallery script saves its pictures as plain files (``save_image("quilt-modes.png", ...)``), as a
reader would run it. After each code block this scraper moves every new PNG or JPEG from the
example's folder to the gallery's image path (as PNG) and shows it under the block.
"""

from __future__ import annotations

import os
from pathlib import Path

from PIL import Image
from sphinx_gallery.scrapers import figure_rst

SUFFIXES = (".png", ".jpg", ".jpeg")


class PictureScraper:
    """Collect the pictures a code block wrote into the current folder."""

    def __call__(self, block, block_vars, gallery_conf):
        here = Path(os.getcwd())
        written = sorted(
            (p for p in here.iterdir() if p.suffix.lower() in SUFFIXES and p.is_file()),
            key=lambda p: p.stat().st_mtime_ns,
        )
        paths = []
        for picture in written:
            target = Path(next(block_vars["image_path_iterator"]))
            with Image.open(picture) as img:
                img.convert("RGB").save(target.with_suffix(".png"))
            picture.unlink()
            paths.append(str(target.with_suffix(".png")))
        return figure_rst(paths, gallery_conf["src_dir"])

    def __repr__(self) -> str:  # a stable text, so Sphinx's environment is not rebuilt each time
        return "PictureScraper"


def _get_sg_image_scraper():
    return PictureScraper()
