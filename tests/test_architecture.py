"""The structure of rbm_cli keeps its rule (docs/architecture.md): imports only go down the
levels base -> config -> physics -> models -> study -> report -> api -> cli, no two modules
import each other round a circle, and the CLI stands on the API alone (it imports no other
module of the package). Imports inside functions count: a lazy import up a level is
still an import up a level. Modules are split where their meaning splits, not by a count of
lines: no size is checked here."""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "rbm_cli"
LEVELS = {"base": 0, "config": 1, "physics": 2, "models": 3, "study": 4, "report": 5,
          "api": 6, "cli": 7, "__main__": 8}  # fmt: skip


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
    found = imports(path, "rbm_cli.physics.x", set(modules()))
    assert "rbm_cli.report.plots" in found and level("rbm_cli.report.plots") > level(
        "rbm_cli.physics.x"
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
    path = tmp_path / "rbm_cli" / "physics" / "x.py"
    path.parent.mkdir(parents=True)
    path.write_text("from rbm_cli.base.files import _fsync\nfrom .law import _piece\n")
    monkeypatch.setattr("tests.test_architecture.modules", lambda: {"rbm_cli.physics.x": path})
    assert private_imports() == {
        ("rbm_cli.physics.x", "rbm_cli.base.files", "_fsync"),
        ("rbm_cli.physics.x", "rbm_cli.physics.law", "_piece"),
    }
