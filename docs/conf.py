"""Sphinx configuration of rbm's documentation site.

Build (warnings are errors), from the repository's root:

    pip install -e '.[docs]'
    python -m sphinx -W --keep-going -b html docs docs/_build/html

The reference pages (commands, config keys) are generated from the code at build time by
docs/_ext/rbm_reference.py; the tutorials in docs/tutorials/ are run by sphinx-gallery at
every build.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE / "_ext"))
sys.path.insert(0, str(ROOT))  # the rbm of this tree, whatever else is installed
os.environ.setdefault("MPLBACKEND", "Agg")

import rbm_cli  # noqa: E402

project = "rbm"
author = "the rbm authors"
copyright = "the rbm authors"  # noqa: A001
release = rbm_cli.__version__
version = release

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinx_gallery.gen_gallery",
    "rbm_reference",
    "rbm_math",
    "rbm_docstrings",
]

# maths: MathJax from the site's own _static/mathjax/ (docs/_ext/rbm_math.py copies it from
# the sphinx-mathjax-offline package), not from a CDN: the equations render offline
mathjax_path = "mathjax/tex-chtml.js"

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = [
    "_build",
    "examples",
    "engine_data",
    "tutorials/README.rst",
    "auto_tutorials/*.ipynb",
    "auto_tutorials/*.py",
    "auto_tutorials/*.zip",
    "auto_tutorials/*.md5",
    "auto_tutorials/*.codeobj.json",
]

# MyST: the existing Markdown pages as they are ($...$ maths, heading anchors for links)
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_heading_anchors = 3

# autodoc + napoleon: the numpydoc-style docstrings of the public API, as
# docs/_ext/rbm_docstrings.py reads them first (fields on one line, |x| as text)
autodoc_default_options = {"members": True, "member-order": "bysource"}
autodoc_typehints = "none"
napoleon_numpy_docstring = True
napoleon_google_docstring = False
napoleon_use_rtype = False

# sphinx-gallery: the tutorials are run at each build (small grids, short runs)
sphinx_gallery_conf = {
    "examples_dirs": ["tutorials"],
    "gallery_dirs": ["auto_tutorials"],
    "filename_pattern": r"tutorial_",
    "within_subsection_order": "FileNameSortKey",
    "download_all_examples": False,
    "remove_config_comments": True,
    "abort_on_example_error": True,
    "matplotlib_animations": False,
    "show_memory": False,
    # no page of computation times: sphinx-gallery's loads its table's scripts from CDNs,
    # and the site loads nothing from a network (each tutorial states its own run time)
    "write_computation_times": False,
    # two examples at a time (2 cores): the multi-drum tutorial compiles the step
    # integrator on a cold numba cache while the others run
    "parallel": 2,
}

html_theme = "pydata_sphinx_theme"
html_title = f"rbm {release}"
html_static_path: list[str] = []
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
}
html_show_sourcelink = False
