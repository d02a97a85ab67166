"""Paths of the shipped configs and stored results (read-only in tests), and the scripts of
docs/ as modules."""

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CONFIGS = ROOT / "configs"
RESULTS = ROOT / "results"


def docs_script(name: str):
    """A script of docs/ as a module (its functions, without running it)."""
    spec = importlib.util.spec_from_file_location(name, ROOT / "docs" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module
