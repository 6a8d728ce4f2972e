"""Sphinx configuration of weft's documentation site.

Build: ``.venv/bin/python -m sphinx -W -b html docs docs/_build/html`` (after
``.venv/bin/pip install -e '.[docs]'``). The gallery scripts run at build time; the performance
tables are read from ``benchmarks/results/*.json``; the command-line reference is generated from
the parameter specs.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path[:0] = [str(ROOT), str(DOCS / "_ext"), str(DOCS / "gallery")]
os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

project = "weft"
author = "the weft developers"
copyright = "the weft developers"  # noqa: A001 (Sphinx's name)
try:
    from importlib.metadata import version as _version

    release = _version("weft")
except Exception:  # an uninstalled checkout still builds
    release = ""

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.intersphinx",
    "numpydoc",
    "sphinx_gallery.gen_gallery",
    "weft_docs",
]

exclude_patterns = ["_build", "images/README*", "gallery/*.rst", "**/sg_execution_times.rst"]
html_theme = "furo"
html_title = "weft"
html_static_path = []
templates_path = []
nitpicky = False
suppress_warnings: list[str] = []

# The API reference: one page per public module of weft.core, from its docstrings.
autosummary_generate = True
autodoc_default_options = {"members": True, "undoc-members": False, "show-inheritance": False}
autodoc_typehints = "none"
autodoc_mock_imports: list[str] = []
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_validation_checks: set[str] = set()
intersphinx_mapping: dict = {}

sphinx_gallery_conf = {
    "examples_dirs": "gallery",
    "gallery_dirs": "auto_gallery",
    "filename_pattern": r"/plot_",
    "ignore_pattern": r"(__init__|panels)\.py",
    "image_scrapers": ("weft_scraper",),
    "reset_modules": (),  # the default resets matplotlib, which weft does not use
    "download_all_examples": False,
    "remove_config_comments": True,
    "show_memory": False,
    "default_thumb_file": str(DOCS / "images" / "quilt-modes.png"),
    "within_subsection_order": "FileNameSortKey",
    "min_reported_time": 0,
    "write_computation_times": False,
}
