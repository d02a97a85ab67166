"""The structure of rbm_cli keeps its rule (docs/architecture.md): imports only go down the
levels base -> config -> inputs -> numerics -> structures -> models -> study -> report -> api ->
cli, no two modules import each other round a circle, and the CLI stands on the API alone (it
imports no other module of the package). Imports inside functions count: a lazy import up a level is
still an import up a level. Modules are split where their meaning splits, not by a count of
lines: no size is checked here."""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "rbm_cli"
LEVELS = {"base": 0, "config": 1, "inputs": 2, "numerics": 3, "structures": 4, "models": 5,
          "study": 6, "report": 7, "api": 8, "cli": 9, "__main__": 10}  # fmt: skip


def modules() -> dict[str, Path]:
    out = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


def level(module: str) -> int | None:
    parts = module.split(".")
    return LEVELS.get(parts[1]) if len(parts) > 1 else None


def imports(path: Path, module: str, known: set[str]) -> set[str]:
    """rbm_cli modules imported anywhere in a file (resolved to the deepest module known)."""
    found = set()
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    for node in ast.walk(ast.parse(path.read_text())):
        names = []
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                base = ".".join(package.split(".")[: len(package.split(".")) - node.level + 1]
                                + ([base] if base else []))  # fmt: skip
            names = [f"{base}.{a.name}" for a in node.names] + [base]
        for name in names:
            while name and name not in known:
                name = name.rpartition(".")[0]
            if name.startswith("rbm_cli.") and name != module:
                found.add(name)
    return found


def graph() -> dict[str, set[str]]:
    mods = modules()
    return {m: imports(p, m, set(mods)) for m, p in mods.items()}


def test_the_levels_name_every_folder():
    for module in modules():
        if module != "rbm_cli":
            assert level(module) is not None, f"{module}: a folder docs/architecture.md lacks"


def test_no_import_runs_up_a_level():
    upward = [
        f"{m} (level {level(m)}) imports {d} (level {level(d)})"
        for m, deps in graph().items()
        for d in deps
        if level(m) is not None and level(d) is not None and level(d) > level(m)
    ]
    assert not upward, "\n".join(upward)


def test_no_import_circle():
    g = graph()
    state: dict[str, int] = {}
    circles = []

    def visit(node, path):
        state[node] = 1
        for dep in sorted(g.get(node, ())):
            if dep not in g:
                continue
            if state.get(dep) == 1:
                circles.append(" -> ".join(path[path.index(dep) :] + [dep]))
            elif dep not in state:
                visit(dep, path + [dep])
        state[node] = 2

    for node in sorted(g):
        if node not in state:
            visit(node, [node])
    assert not circles, "\n".join(circles)


def test_the_check_sees_an_upward_import(tmp_path):
    """The checker itself finds a lazy import up a level (so the tests above can fail)."""
    path = tmp_path / "x.py"
    path.write_text("def f():\n    from rbm_cli.report.plots import plot_shapes\n")
    found = imports(path, "rbm_cli.structures.x", set(modules()))
    assert "rbm_cli.report.plots" in found and level("rbm_cli.report.plots") > level(
        "rbm_cli.structures.x"
    )


def cli_reaches_past_the_api(graph: dict[str, set[str]]) -> list[str]:
    """'importer imports module' for every module of rbm_cli.cli that imports a module of
    the package outside rbm_cli.api and rbm_cli.cli."""
    allowed = ("rbm_cli.api", "rbm_cli.cli")
    return sorted(
        f"{m} imports {d}"
        for m, deps in graph.items()
        if m == "rbm_cli.cli" or m.startswith("rbm_cli.cli.")
        for d in deps
        if not any(d == a or d.startswith(a + ".") for a in allowed)
    )


def test_the_cli_imports_only_the_api():
    """Every module of rbm_cli/cli imports, of the package, only rbm_cli.api... and
    rbm_cli.cli... (function-level imports included): the CLI stands on the library."""
    found = cli_reaches_past_the_api(graph())
    assert not found, "\n".join(found)


def test_the_check_sees_a_cli_import_past_the_api(tmp_path):
    """The checker itself finds a lazy import of a lower floor in a CLI module, and lets an
    import of the API through."""
    path = tmp_path / "x.py"
    path.write_text(
        "from rbm_cli.api.configs import load_config\n"
        "def f():\n    from rbm_cli.study.domain import read_domain\n"
        "def g():\n    import rbm_cli.base.files\n"
    )
    deps = imports(path, "rbm_cli.cli.x", set(modules()))
    assert cli_reaches_past_the_api({"rbm_cli.cli.x": deps}) == [
        "rbm_cli.cli.x imports rbm_cli.base.files",
        "rbm_cli.cli.x imports rbm_cli.study.domain",
    ]


def private_imports() -> set[tuple[str, str, str]]:
    """(importer, imported module, name) of every private name (one leading underscore)
    that a module of rbm_cli imports from another."""
    found = set()
    for module, path in modules().items():
        package = module if path.name == "__init__.py" else module.rpartition(".")[0]
        for node in ast.walk(ast.parse(path.read_text())):
            if not isinstance(node, ast.ImportFrom):
                continue
            base = node.module or ""
            if node.level:
                base = ".".join(package.split(".")[: len(package.split(".")) - node.level + 1]
                                + ([base] if base else []))  # fmt: skip
            if not base.startswith("rbm_cli") or base == module:
                continue
            for alias in node.names:
                if alias.name.startswith("_") and not alias.name.startswith("__"):
                    found.add((module, base, alias.name))
    return found


def test_no_new_private_import_across_modules():
    """A module uses another's public names only. The imports of private names that are
    still there are listed in tests/private_imports.txt: a new one fails, and so does an
    entry that is gone (the list may only shrink)."""
    listed = set()
    for line in (Path(__file__).with_name("private_imports.txt")).read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            listed.add(tuple(line.split()))
    found = private_imports()
    new = sorted(" ".join(t) for t in found - listed)
    gone = sorted(" ".join(t) for t in listed - found)
    assert not new, "private names imported across modules:\n" + "\n".join(new)
    assert not gone, "no longer imported: delete from tests/private_imports.txt:\n" + "\n".join(
        gone
    )


def test_the_check_sees_a_private_import(tmp_path, monkeypatch):
    """The checker itself finds `from rbm_cli.x import _y` in another module."""
    path = tmp_path / "rbm_cli" / "structures" / "x.py"
    path.parent.mkdir(parents=True)
    path.write_text("from rbm_cli.base.files import _fsync\nfrom .law import _piece\n")
    monkeypatch.setattr("tests.test_architecture.modules", lambda: {"rbm_cli.structures.x": path})
    assert private_imports() == {
        ("rbm_cli.structures.x", "rbm_cli.base.files", "_fsync"),
        ("rbm_cli.structures.x", "rbm_cli.structures.law", "_piece"),
    }


# ------------------------------------------------------ tools beside the package, not in it

ROOT = PACKAGE.parent
TOOLS = ROOT / "tools"
#: Modules of rbm_cli that no entry point reaches, read only by a tool: developer tooling
#: still inside the package. The list may only shrink (a module listed that is reached, or
#: gone, fails too).
NOT_REACHED = {
    "rbm_cli.models.bullet.convergence",  # tools/make_engine.py's step-convergence tables
    "rbm_cli.models.bullet.normals",  # tools/make_engine.py's census of contact normals
}


def entry_points() -> set[str]:
    """The modules a user starts from: the console scripts (pyproject.toml), what
    `import rbm` imports, `python -m rbm_cli` and every module with a main guard (run as
    `python -m`)."""
    import tomllib

    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    found = {target.split(":")[0] for target in project["scripts"].values()}
    found |= {m for m in imports(ROOT / "rbm" / "__init__.py", "rbm", set(modules()))}
    for module, path in modules().items():
        if path.name == "__main__.py" or '__name__ == "__main__"' in path.read_text():
            found.add(module)
    return found


def named_modules(path: Path, known: set[str]) -> set[str]:
    """Modules of rbm_cli a file names in a string to import later ("rbm_cli.a.b" or
    "rbm_cli.a.b:function": the model registry, the method table, the compiled targets)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            name = node.value.split(":")[0]
            if name in known and name.startswith("rbm_cli."):
                found.add(name)
    return found


def unreached(roots: set[str], graph: dict[str, set[str]], named: dict[str, set[str]]) -> set:
    """The modules of graph that no import (or name in a string) leads to from roots; a
    module imported imports its packages too."""
    seen, stack = set(), list(roots)
    while stack:
        module = stack.pop()
        if module in seen:
            continue
        seen.add(module)
        for dep in graph.get(module, set()) | named.get(module, set()):
            parts = dep.split(".")
            stack += [".".join(parts[:k]) for k in range(1, len(parts) + 1)]
    return set(graph) - seen


def test_every_module_is_reached_from_an_entry_point():
    """A module of rbm_cli that no user's entry point reaches is run only by a developer's
    tool: it belongs in tools/ (docs/architecture.md), beside the scripts that read it."""
    mods = modules()
    named = {m: named_modules(p, set(mods)) for m, p in mods.items()}
    left = unreached(entry_points(), graph(), named)
    assert not left - NOT_REACHED, "reached by no entry point (tools/ holds these):\n" + "\n".join(
        sorted(left - NOT_REACHED)
    )
    assert not NOT_REACHED - left, "reached now, or gone: delete from NOT_REACHED:\n" + "\n".join(
        sorted(NOT_REACHED - left)
    )


def test_the_check_sees_a_module_no_entry_point_reaches(tmp_path):
    """The checker itself: a module that only a tool imports is left over, one named in a
    string (as the registry names its runners) is reached."""
    graph = {"rbm_cli.cli.main": {"rbm_cli.api"}, "rbm_cli.api": set(), "rbm_cli.models.x": set(),
             "rbm_cli.study.tooling": set(), "rbm_cli": set()}  # fmt: skip
    path = tmp_path / "x.py"
    path.write_text('RUNNERS = {"x": "rbm_cli.models.x:run"}\n')
    named = {"rbm_cli.api": named_modules(path, set(graph))}
    assert unreached({"rbm_cli.cli.main"}, graph, named) == {"rbm_cli.study.tooling"}


def test_nothing_of_the_package_imports_a_tool():
    """tools/ is not installed with the package: no module of rbm_cli imports one."""
    tools = {path.stem for path in TOOLS.glob("*.py")}
    found = []
    for module, path in modules().items():
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and not node.level:
                names = [node.module or ""]
            else:
                continue
            found += [
                f"{module} imports {n}" for n in names if n.split(".")[0] in tools | {"tools"}
            ]
    assert not found, "\n".join(found)


def test_docs_holds_the_site_and_no_script():
    """The scripts that make the docs' figures and measurements are in tools/: the only
    Python directly in docs/ is the site's configuration (its extensions are in docs/_ext,
    the tutorials and the API example are run by the build and the tests)."""
    assert sorted(p.name for p in (ROOT / "docs").glob("*.py")) == ["conf.py"]
    assert (TOOLS / "make_validation.py").is_file()


def unexplained_lazy_imports(path: Path) -> list[int]:
    """Lines of the imports inside functions of a file that no `# lazy:` comment explains
    (on the import's line or the line above it, or above the first of a run of imports)."""
    lines = path.read_text().splitlines()
    found = []
    for node in ast.walk(ast.parse("\n".join(lines))):
        if not isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            continue
        for inner in ast.walk(node):
            if not isinstance(inner, ast.Import | ast.ImportFrom):
                continue
            k = inner.lineno - 1
            while k > 0 and lines[k - 1].lstrip().startswith(("from ", "import ")):
                k -= 1  # the first of a run of imports
            if not any("# lazy:" in lines[j] for j in (inner.lineno - 1, k - 1) if j >= 0):
                found.append(inner.lineno)
    return sorted(set(found))


def test_every_import_inside_a_function_says_why():
    """Imports sit at the top of a module; one inside a function is there for start-up time
    and says why in a `# lazy:` comment (docs/architecture.md, Start-up)."""
    found = [
        f"{path.relative_to(PACKAGE.parent)}:{line}"
        for path in sorted(PACKAGE.rglob("*.py"))
        for line in unexplained_lazy_imports(path)
    ]
    assert not found, "imports inside functions with no '# lazy:' reason:\n" + "\n".join(found)


def test_the_check_sees_an_unexplained_lazy_import(tmp_path):
    """The checker itself finds an import inside a function with no reason, and takes one
    with its reason above it (on its own or at the head of a run of imports)."""
    path = tmp_path / "x.py"
    path.write_text("def f():\n    import json\n\n\ndef g():\n    # lazy: heavy\n"
                    "    import pandas\n    import scipy\n")  # fmt: skip
    assert unexplained_lazy_imports(path) == [2]
