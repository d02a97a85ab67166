"""Paths of the shipped configs and stored results (read-only in tests), and the scripts of
tools/ as modules."""

import importlib.util
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CONFIGS = ROOT / "configs"
RESULTS = ROOT / "results"
TOOLS = ROOT / "tools"


def tool_script(name: str):
    """A script or module of tools/ as a module (its functions, without running it as a
    script). tools/ is on the module path while it loads, as when the script is run
    (`python tools/NAME.py`): the modules beside it import as they do then. The module is
    in sys.modules under its name while it runs (its dataclasses look themselves up there)
    and after, so a tool that imports another finds the one already loaded."""
    if name in sys.modules and getattr(sys.modules[name], "__file__", None) == str(
        TOOLS / f"{name}.py"
    ):
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, TOOLS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    sys.path.insert(0, str(TOOLS))
    try:
        spec.loader.exec_module(module)
    except BaseException:
        del sys.modules[name]
        raise
    finally:
        sys.path.remove(str(TOOLS))
    return module


def docs_extension(name: str):
    """A Sphinx extension of docs/_ext (e.g. rbm_reference) as a module, in sys.modules
    under its name, without Sphinx."""
    spec = importlib.util.spec_from_file_location(name, ROOT / "docs" / "_ext" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module
