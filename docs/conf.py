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
]

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

# autodoc + napoleon: the numpydoc-style docstrings of the public API
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
    "write_computation_times": True,
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


# ---------------------------------------------------------------------------- hooks
def _split_field_lines(app, what, name, obj, options, lines):
    """The project's docstrings write a numpydoc field on one line, ``name : type  text``
    (two spaces before the description); napoleon wants the description on the next line,
    indented. Split such lines in the Parameters, Returns, Yields and Raises sections."""
    import re

    sections = {"Parameters", "Returns", "Yields", "Raises", "Other Parameters", "Attributes"}
    field = re.compile(r"^(?P<head>\S(?:.*?\S)?)\s{2,}(?P<text>\S.*)$")
    out: list[str] = []
    in_fields = False
    for k, line in enumerate(lines):
        nxt = lines[k + 1] if k + 1 < len(lines) else ""
        if line.strip() in sections and set(nxt.strip()) == {"-"}:
            in_fields = True
            out.append(line)
            continue
        if in_fields and line.strip() and not line.startswith(" ") and set(line.strip()) != {"-"}:
            match = field.match(line)
            if match and nxt.strip() != "" and set(nxt.strip()) == {"-"}:
                in_fields = False  # the next section's title
            elif match:
                out += [match["head"], "    " + match["text"]]
                continue
        if in_fields and line.strip() and not line.startswith(" ") and not field.match(line):
            # a title of another section ends the fields
            if set(nxt.strip()) == {"-"}:
                in_fields = False
        out.append(line)
    lines[:] = out


#: Links of docs/api.md to the README's former Configuration section, read as the page that
#: holds it now.
_MOVED = {"../README.md#configuration": "reference/config.md"}


def _moved_links(app, docname, source):
    if docname == "api":
        for old, new in _MOVED.items():
            source[0] = source[0].replace(old, new)


def setup(app):
    app.connect("autodoc-process-docstring", _split_field_lines, priority=400)
    app.connect("source-read", _moved_links)
