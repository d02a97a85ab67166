"""The site's equations without a network: MathJax 3 from a Python package, served from
the site's own ``_static/mathjax/``.

``sphinx.ext.mathjax`` loads MathJax from a CDN by default, and a reader offline (or behind
a firewall) saw raw TeX. The package ``sphinx-mathjax-offline`` (PyPI, the ``docs`` extra)
holds MathJax 3.2.2's files; conf.py points ``mathjax_path`` at ``mathjax/tex-chtml.js``
and this extension copies, once the HTML is written, the parts a page loads: the TeX to
CommonHTML component, the TeX extensions it loads when a formula needs them (autoload:
``\\boldsymbol``, ``\\cancel``...), the fonts of its output, and the modules of its
right-click menu and accessibility (about 4 MB of the package's 24 MB). An equation wider
than the page's text scrolls sideways instead of being cut at the text's edge
(``_static/rbm_math.css``).
"""

from __future__ import annotations

import importlib.util
import shutil
from pathlib import Path

#: The package that holds MathJax (its import name has hyphens).
PACKAGE = "sphinx-mathjax-offline"
#: What conf.py's ``mathjax_path`` names, relative to ``_static``.
ENTRY = "mathjax/tex-chtml.js"
#: The parts of MathJax a page loads (paths under the package's ``static/mathjax``).
PARTS = (
    "tex-chtml.js",
    "input/tex/extensions",
    "output/chtml/fonts/woff-v2",
    "ui",
    "a11y",
    "sre/mathmaps/base.json",
    "sre/mathmaps/en.json",
)


#: The site's style of displayed equations: one wider than the text scrolls.
CSS = "rbm_math.css"
CSS_TEXT = """\
/* an equation wider than the text scrolls sideways (docs/_ext/rbm_math.py) */
mjx-container[jax="CHTML"][display="true"] {
  overflow-x: auto;
  overflow-y: hidden;
  max-width: 100%;
}
"""


def mathjax_folder() -> Path:
    """The package's MathJax folder; an error naming the package if it is not installed."""
    spec = importlib.util.find_spec(PACKAGE)
    if spec is None or not spec.submodule_search_locations:
        raise RuntimeError(f"{PACKAGE} is not installed: pip install -e '.[docs]'")
    folder = Path(next(iter(spec.submodule_search_locations))) / "static" / "mathjax"
    if not (folder / "tex-chtml.js").is_file():
        raise RuntimeError(f"{PACKAGE} holds no MathJax at {folder}")
    return folder


def copy_mathjax(source: Path, static: Path) -> list[Path]:
    """Copy :data:`PARTS` of MathJax from ``source`` into ``static / 'mathjax'``; the paths
    written."""
    written = []
    for part in PARTS:
        src, dst = source / part, static / "mathjax" / part
        if src.is_dir():
            shutil.copytree(src, dst, dirs_exist_ok=True)
        else:
            dst.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, dst)
        written.append(dst)
    return written


def _check_config(app, config) -> None:
    if config.mathjax_path != ENTRY:
        raise RuntimeError(
            f"conf.py must set mathjax_path = {ENTRY!r} (got {config.mathjax_path!r})"
        )
    mathjax_folder()  # fails at the start of the build, not at its end


def _copy(app, exc) -> None:
    if exc is None and app.builder.format == "html":
        static = Path(app.outdir) / "_static"
        copy_mathjax(mathjax_folder(), static)
        (static / CSS).write_text(CSS_TEXT)


def setup(app):  # pragma: no cover - exercised by the docs build
    app.setup_extension("sphinx.ext.mathjax")
    app.connect("config-inited", _check_config)
    app.connect("build-finished", _copy)
    app.add_css_file(CSS)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
