"""Sphinx configuration of the femehl documentation.

Build (warnings are errors)::

    python -m sphinx -W --keep-going -b html docs docs/_build/html

Quick build (the example gallery is not executed)::

    python -m sphinx -W --keep-going -b html -D plot_gallery=0 docs docs/_build/html
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path.insert(0, str(ROOT))  # the femehl of this checkout, before any installed one
sys.path.insert(0, str(DOCS / "_ext"))
os.environ.setdefault("MPLBACKEND", "Agg")

from femehl_docs import GALLERY_EXECUTED, prepare_gallery_sources  # noqa: E402

import femehl  # noqa: E402

project = "femehl"
author = "the femehl authors"
copyright = "2026, the femehl authors"
release = femehl.__version__
version = femehl.__version__

extensions = [
    "myst_parser",
    "numpydoc",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "sphinx_gallery.gen_gallery",
    "sphinxarg.ext",
    "femehl_docs",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "_ext", "Thumbs.db", ".DS_Store", "auto_examples/*.ipynb"]

# -- MyST: the Markdown pages (README sections, design notes, benchmark tables) --------
myst_enable_extensions = ["colon_fence", "dollarmath"]
myst_heading_anchors = 3

# -- autodoc + numpydoc --------------------------------------------------------------
autodoc_default_options = {"members": True, "member-order": "bysource"}
autodoc_typehints = "none"  # numpydoc's Parameters sections state the types
autosummary_generate = False
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_validation_checks: set[str] = set()

# -- the example gallery -------------------------------------------------------------
# sphinx-gallery runs each example in the folder of its source file, and the examples
# write their output to ``femehl-out/...`` there: so the gallery is built from a copy of
# ``examples/`` under ``docs/_build``, and nothing is written into the source tree.
GALLERY_SRC = prepare_gallery_sources(ROOT / "examples", DOCS / "_build" / "gallery-src")

sphinx_gallery_conf = {
    "examples_dirs": str(GALLERY_SRC),
    "gallery_dirs": "auto_examples",
    # run only the examples that take seconds (textured_sphere: 40 min, paper_figures: 15 min)
    "filename_pattern": r"(^|[/\\])(" + "|".join(GALLERY_EXECUTED) + r")\.py$",
    "image_scrapers": ("matplotlib", "femehl_docs.written_png_scraper"),
    "reset_modules": ("matplotlib", "femehl_docs.snapshot_pngs"),
    "reset_argv": "femehl_docs.example_argv",
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "min_reported_time": 1,
    "show_memory": False,
    "matplotlib_animations": False,
}

# -- HTML ----------------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = f"femehl {release}"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
}
html_show_sourcelink = False
smartquotes_action = "qe"  # no -- to en dash: CLI options stay --tol
