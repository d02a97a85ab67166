"""What the documentation site shows a reader: its equations without a network, every public
name of `import rbm` with its docstring, each command's help once, links that lead
somewhere, tutorials that use only what `import rbm` gives, and the README's list of them.
Each is read from the site's sources (docs/), without a Sphinx build; the build itself
(python -m sphinx -W ...) runs the tutorials."""

from __future__ import annotations

import ast
import importlib.util
import inspect
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
TUTORIALS = sorted((DOCS / "tutorials").glob("tutorial_*.py"))


def _load(name: str, path: Path):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def ref():
    return _load("rbm_reference", DOCS / "_ext" / "rbm_reference.py")


@pytest.fixture(scope="module")
def math_ext():
    return _load("rbm_math", DOCS / "_ext" / "rbm_math.py")


def _conf() -> str:
    return (DOCS / "conf.py").read_text()


# ------------------------------------------------------------------------ maths offline
def test_the_maths_are_loaded_from_the_site_itself(math_ext):
    """Defect: MathJax came from a CDN (sphinx.ext.mathjax's default), and offline the
    equations showed as raw TeX. conf.py names a path inside the site's _static folder,
    the extension that puts MathJax there is on, and the package that holds it is in the
    docs extra."""
    conf = _conf()
    (path,) = re.findall(r'^mathjax_path = "([^"]+)"', conf, re.M)
    assert path == math_ext.ENTRY and "://" not in path
    assert '"rbm_math"' in conf
    pyproject = (ROOT / "pyproject.toml").read_text()
    (docs_extra,) = re.findall(r"^docs = \[(.*?)\]", pyproject, re.M | re.S)
    assert f'"{math_ext.PACKAGE}' in docs_extra


@pytest.mark.may_skip(reason="sphinx-mathjax-offline comes with the docs extra")
def test_mathjax_and_its_fonts_are_copied_into_the_site(math_ext, tmp_path):
    """What the pages load is there after the copy: the TeX-to-HTML component, the fonts
    of its output, and the TeX extensions it loads on demand."""
    if importlib.util.find_spec(math_ext.PACKAGE) is None:
        pytest.skip(f"{math_ext.PACKAGE} is not installed")
    math_ext.copy_mathjax(math_ext.mathjax_folder(), tmp_path)
    root = tmp_path / "mathjax"
    assert (tmp_path / math_ext.ENTRY).is_file()
    fonts = {p.name for p in (root / "output" / "chtml" / "fonts" / "woff-v2").iterdir()}
    assert {"MathJax_Main-Regular.woff", "MathJax_Math-Italic.woff"} <= fonts
    assert (root / "input" / "tex" / "extensions" / "boldsymbol.js").is_file()
    size = sum(p.stat().st_size for p in root.rglob("*") if p.is_file())
    assert size < 8e6  # the parts a page loads, not the package's 24 MB


# ------------------------------------------------------------------------ references
def _documented(markdown: str) -> set[str]:
    return set(re.findall(r"^\.\. auto(?:function|class|exception|data):: rbm\.(\w+)", markdown,
                          re.M))  # fmt: skip


def test_every_public_name_has_its_docstring_in_the_python_reference():
    """Defect: info, motion_from_arrays, compare, Motion, CellResult and DomainComparison
    were named on the page (in the module's docstring) but their own docstrings were not
    on it."""
    import rbm

    page = (DOCS / "reference" / "python.md").read_text()
    missing = set(rbm.__all__) - {"__version__"} - _documented(page)
    assert not missing, sorted(missing)
    for name in _documented(page):
        assert getattr(rbm, name).__doc__, name


@pytest.mark.may_skip(reason="sphinx comes with the docs extra (pip install -e '.[docs]')")
def test_the_python_reference_builds_every_docstring_without_a_warning(tmp_path):
    """Defect: the page failed the build with warnings as errors: DomainComparison lists
    its attributes as fields under no title (an unexpected indentation), and |T/N|
    (CellResult), |acceleration| (Motion) and |boundary shift| are absolute values that
    reStructuredText read as substitutions. The page's directives, built alone by Sphinx
    with the site's reading of docstrings (docs/_ext/rbm_docstrings.py), with -W."""
    pytest.importorskip("sphinx")
    page = (DOCS / "reference" / "python.md").read_text()
    blocks = re.findall(r"```\{eval-rst\}\n(.*?)```", page, re.S)
    src = tmp_path / "src"
    src.mkdir()
    (src / "index.rst").write_text("Reference\n=========\n\n" + "\n".join(blocks))
    (src / "conf.py").write_text(
        f"import sys\nsys.path.insert(0, {str(DOCS / '_ext')!r})\n"
        "extensions = ['sphinx.ext.autodoc', 'sphinx.ext.napoleon', 'rbm_docstrings']\n"
        "autodoc_typehints = 'none'\nnapoleon_google_docstring = False\n"
    )
    res = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "-q", "-b", "html", str(src), str(tmp_path / "out")],
        capture_output=True, text=True, timeout=300, env={**os.environ, "MPLBACKEND": "Agg"},
    )  # fmt: skip
    assert res.returncode == 0, res.stderr
    html = (tmp_path / "out" / "index.html").read_text()
    for text in ("|T/N|", "Peak |acceleration| [g]", "Largest |boundary shift| [g]",
                 "Cells in both (matched on amplitude"):  # fmt: skip
        assert text in html, text


def _sections(text: str) -> dict[str, str]:
    parts = re.split(r"^\.\. _cli-([\w-]+):$", text, flags=re.M)
    return dict(zip(parts[1::2], parts[2::2], strict=True))


def test_the_cli_reference_says_each_help_once(ref):
    """Defect: each command's help came twice, its options in click's text and again in a
    table (that table clipped: four columns, and a choice's ``[a|b|c]`` beside its flag)."""
    import click

    from rbm_cli.cli.main import cli

    sections = _sections(ref.cli_rst())
    ctx = click.Context(cli, info_name="rbm")
    assert set(sections) == set(cli.list_commands(ctx))
    for name, text in sections.items():
        cmd = cli.get_command(ctx, name)
        assert "Options:" not in text, name
        first = inspect.cleandoc(cmd.help).split("\n\n")[0]  # its first paragraph
        assert text.count(ref.esc(first)) == 1, name
        for param in cmd.params:
            if isinstance(param, click.Option) and param.help:
                assert text.count(ref.esc(param.help)) == 1, (name, param.name)
            if isinstance(param, click.Option) and isinstance(param.type, click.Choice):
                assert "|" not in text.split(param.opts[-1], 1)[1].split("\n", 1)[0], name
        assert ":widths: 32 68" in text  # two columns: the flags, and what they mean


# ------------------------------------------------------------------------ the API guide
def _slug(title: str) -> str:
    return re.sub(r"[^\w\- ]", "", title.strip().lower()).replace(" ", "-")


def test_the_api_guide_links_to_pages_and_sections_that_exist():
    """Defect: the guide sent readers to the README's Configuration section, which no
    longer exists."""
    page = DOCS / "api.md"
    for target in re.findall(r"\]\(([^)\s]+)\)", page.read_text()):
        if "://" in target:
            continue
        path, _, anchor = target.partition("#")
        file = (page.parent / path).resolve()
        assert file.exists(), target
        if anchor:
            titles = re.findall(r"^#+ (.+)$", file.read_text(), re.M)
            assert anchor in {_slug(t) for t in titles}, target


def test_the_api_guide_gives_the_angle_of_a_motion_in_degrees(ref):
    """Defect: the guide said that angles in a config are in rad; excitation.angle, the
    direction of a motion in plan, is in degrees, as the config reference says."""
    assert ref.KEY_DOCS["excitation.angle"][0] == "deg"
    units = (DOCS / "api.md").read_text().split("## Units", 1)[1].split("\n## ", 1)[0]
    text = " ".join(units.split())
    assert "angles in rad" not in text
    assert "(`excitation.angle`) in degrees" in text


# ------------------------------------------------------------------------ tutorials
def _imports(path: Path) -> set[str]:
    names = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names |= {a.name.split(".")[0] for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            names.add((node.module or "").split(".")[0])
    return names


@pytest.mark.parametrize("path", TUTORIALS, ids=lambda p: p.stem)
def test_a_tutorial_uses_what_import_rbm_gives(path):
    """Defect: tutorials ran `rbm info` through subprocess and called a module of
    rbm_cli where `import rbm` has the function."""
    allowed = {"rbm", "numpy", "pandas", "matplotlib", "pathlib", "tempfile"}
    assert _imports(path) <= allowed, sorted(_imports(path) - allowed)


def test_there_is_a_tutorial_in_three_dimensions():
    """Defect: no tutorial (nor the getting-started page) showed a model in three
    dimensions. One runs a column under record pairs with rbm-3d and its planar
    counterpart with rbm, and fits both fragilities."""
    text = "\n".join(p.read_text() for p in TUTORIALS)
    assert '"rbm-3d"' in text and "file_y" in text and "rbm.fragility(" in text
    assert "rbm-3d" in (DOCS / "getting_started.md").read_text()


def test_the_readme_lists_every_tutorial():
    """The README's row of tutorials names one study per tutorial file, and says how many
    run at every build."""
    readme = (ROOT / "README.md").read_text()
    (row,) = [line for line in readme.splitlines() if line.startswith("| Tutorials")]
    studies = [s for s in row.split("|")[2].split(";") if s.strip()]
    assert len(studies) == len(TUTORIALS), studies
    words = {3: "three", 4: "four", 5: "five", 6: "six"}
    assert f"its {words[len(TUTORIALS)]} tutorials run at every build" in readme
