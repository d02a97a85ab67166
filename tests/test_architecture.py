"""The structure of rbm_cli keeps its rule (docs/architecture.md): imports only go down the
levels base -> config -> physics -> models -> study -> report -> api -> cli, no two modules
import each other round a circle, no module is over 400 lines and no function over 80 lines
(the compiled stepper aside). Imports inside functions count: a lazy import up a level is
still an import up a level."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "rbm_cli"
LEVELS = {"base": 0, "config": 1, "physics": 2, "models": 3, "study": 4, "report": 5,
          "api": 6, "cli": 7, "__main__": 8}  # fmt: skip
MAX_MODULE_LINES = 400
MAX_FUNCTION_LINES = 80
#: numba compiles each of these as one body (docs/architecture.md)
COMPILED_STEPPERS = {"models/rbm/kernel_step.py:run_kernel"}


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


@pytest.mark.parametrize("module", sorted(modules()))
def test_module_and_function_sizes(module):
    path = modules()[module]
    text = path.read_text()
    rel = path.relative_to(PACKAGE).as_posix()
    assert len(text.splitlines()) <= MAX_MODULE_LINES, f"{rel}: {len(text.splitlines())} lines"
    for node in ast.walk(ast.parse(text)):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            n = node.end_lineno - node.lineno + 1
            if f"{rel}:{node.name}" not in COMPILED_STEPPERS:
                assert n <= MAX_FUNCTION_LINES, f"{rel}:{node.name} is {n} lines"
