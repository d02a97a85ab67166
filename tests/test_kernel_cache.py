"""The compiled kernel's on-disk cache follows every compiled source (issue 18, "a correct
cache").

numba checks a cached function only against its own file: a change to a callee in another
module (kernel_rk.py, detmath.py) once left the cached run_kernel in use, and
needs_compile() said nothing needed compiling. Here a copy of the package is run in
subprocesses (the copy first on PYTHONPATH, numba's cache in a fresh folder): once as it
is, once after a callee's constant is changed in the copy, and once more unchanged. The
change must show (another step count, needs_compile True before the run), and an unchanged
copy must load its cache (needs_compile False, the same step count). Two compiles of the
kernel: about 40 s, more under load.

The other tests are quick: which files key the cache (found here by parsing every module
for compiled functions, independently of the glob and text scan of
rbm_cli.base.compile_cache), that the digest moves with them and not with other files,
and that every compiled function of the package carries it.
"""

from __future__ import annotations

import ast
import importlib
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from rbm_cli.base import compile_cache

PACKAGE = Path(__file__).resolve().parents[1] / "rbm_cli"

#: One run of a rigid block under a harmonic pulse train through the compiled kernel:
#: enough adaptive steps that the step-size controller's safety factor changes their count.
DRIVER = """
import json, sys
import rbm_cli
from rbm_cli.models.rbm.kernel import needs_compile
before = needs_compile()
from rbm_cli.api import run
cfg = {"name": "block", "column": {"height": 2.0, "base_width": 0.5},
       "excitation": {"type": "harmonic", "duration": 4.0},
       "solver": {"method": "DOP853", "implementation": "compiled", "rtol": 1e-9,
                  "atol": 1e-11}}
cell = run(cfg, amplitude_g=0.4, frequency_hz=2.0, record=False)
print(json.dumps({"file": rbm_cli.__file__, "before": before, "after": needs_compile(),
                  "n_steps": int(cell.result.n_steps), "status": cell.status}))
"""


def _run(copy: Path, cache: Path, cwd: Path) -> dict:
    env = dict(os.environ, PYTHONPATH=str(copy), NUMBA_CACHE_DIR=str(cache))
    res = subprocess.run([sys.executable, "-c", DRIVER], env=env, cwd=cwd, capture_output=True,
                         text=True, timeout=900)  # fmt: skip
    assert res.returncode == 0, res.stderr[-3000:]
    out = json.loads(res.stdout.strip().splitlines()[-1])
    assert Path(out["file"]).resolve().is_relative_to(copy.resolve()), out["file"]  # the copy
    return out


def _edit_safety(path: Path, new: str) -> None:
    """The step-size controller's safety factor (0.9, scipy's) of the Runge-Kutta module."""
    text = path.read_text()
    edited, n = re.subn(r"^(_SAFETY\b[^=\n]*=\s*)0\.9\b", rf"\g<1>{new}", text, flags=re.M)
    assert n == 1, f"no '_SAFETY ... = 0.9' in {path}"
    path.write_text(edited)


@pytest.mark.slow
@pytest.mark.timeout(1800)
def test_a_change_to_a_compiled_callee_invalidates_the_cache(tmp_path):
    copy = tmp_path / "src"
    shutil.copytree(PACKAGE, copy / "rbm_cli", ignore=shutil.ignore_patterns("__pycache__"))
    cache = tmp_path / "numba-cache"

    first = _run(copy, cache, tmp_path)
    assert first["before"] is True and first["after"] is False  # compiled, then cached
    indexes = sorted(p.name for p in cache.rglob("*.nbi"))

    # same length, same size on disk: only the contents differ
    _edit_safety(copy / "rbm_cli" / "models" / "rbm" / "kernel_rk.py", "0.8")
    edited = _run(copy, cache, tmp_path)
    assert edited["before"] is True, "needs_compile() missed a change to kernel_rk.py"
    assert edited["n_steps"] != first["n_steps"], "the stale cached kernel ran"
    assert edited["after"] is False
    assert sorted(p.name for p in cache.rglob("*.nbi")) == indexes  # rewritten, not added

    again = _run(copy, cache, tmp_path)  # nothing changed: the cache is used as it is
    assert again["before"] is False
    assert again["n_steps"] == edited["n_steps"]


# --------------------------------------------------------------------------- quick checks


def _compiled_modules(root: Path) -> set[Path]:
    """Modules with a function decorated by numba's njit or jit (parsed here)."""
    found = set()
    for path in root.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            for dec in getattr(node, "decorator_list", []):
                target = dec.func if isinstance(dec, ast.Call) else dec
                name = getattr(target, "attr", None) or getattr(target, "id", None)
                if isinstance(node, ast.FunctionDef) and name in ("njit", "jit"):
                    found.add(path)
    return found


def test_the_key_covers_every_compiled_module():
    sources = set(compile_cache.compiled_sources())
    compiled = _compiled_modules(PACKAGE)
    assert len(compiled) >= 7  # detmath and the kernel's modules today
    assert compiled <= sources
    # run_kernel reads EVENT_EPS and BIG of models/events.py: frozen into its code
    assert PACKAGE / "models" / "events.py" in sources
    # a module no compiled function reads from does not make the kernel compile again
    assert PACKAGE / "cli" / "main.py" not in sources
    assert PACKAGE / "physics" / "equations.py" not in sources


def test_the_digest_moves_with_the_compiled_sources_only(tmp_path):
    root = tmp_path / "rbm_cli"
    shutil.copytree(PACKAGE, root, ignore=shutil.ignore_patterns("__pycache__"))
    digests = [compile_cache.source_digest(root)]

    def changed(path: Path, text: str) -> bool:
        path.write_text(text)
        compile_cache.source_digest.cache_clear()
        digests.append(compile_cache.source_digest(root))
        return digests[-1] != digests[-2]

    cli = root / "cli" / "main.py"
    assert not changed(cli, cli.read_text() + "\n# a comment\n")
    rk = root / "models" / "rbm" / "kernel_rk.py"
    assert changed(rk, rk.read_text().replace("_SAFETY, _MIN_FACTOR", "_SAFETY,  _MIN_FACTOR"))
    events = root / "models" / "events.py"
    assert changed(events, events.read_text() + "\n# EVENT_EPS is read by run_kernel\n")
    new = root / "models" / "rbm" / "kernel_new.py"  # a new kernel module, named nowhere
    assert changed(new, "from numba import njit\n\n\n@njit(cache=True)\ndef f(x):\n    return x\n")
    assert new in compile_cache.compiled_sources(root)
    compile_cache.source_digest.cache_clear()


def test_every_compiled_function_carries_the_key():
    for path in _compiled_modules(PACKAGE):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        importlib.import_module(".".join(parts))
    dispatchers = compile_cache.package_dispatchers()
    assert len(dispatchers) >= 20
    unkeyed = [
        d.py_func.__qualname__
        for d in dispatchers
        if not compile_cache.is_keyed(d._cache._cache_file._source_stamp)
    ]
    assert not unkeyed, f"compiled before rbm_cli.base.compile_cache.key_numba_cache(): {unkeyed}"
