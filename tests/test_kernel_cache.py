"""The compiled kernel's on-disk cache follows every compiled source, and its first use
answers as every later use (first use and a correct cache).

numba checks a cached function only against its own file: a change to a callee in another
module (numerics/rk.py, then step/rk.py; detmath.py) once left the cached run_kernel in use, and
needs_compile() said nothing needed compiling. Here a copy of the package is run in
subprocesses (the copy first on PYTHONPATH, numba's cache in a fresh folder):

1. first use: on the empty cache `rbm run` of the README's first-use example (the 8-drum
   column at 0.3 g, 2 Hz, a chaotic cell) says that it compiles the integrator, waits, and
   answers with the compiled kernel; a sweep started while it compiles says that it waits
   for that compile and does not compile a second time; the second `rbm run` (the kernel
   from the cache) writes the same run folder as the first. The first run once answered
   from the Python integrator while the kernel compiled in the background: collapse at
   3.41 s at interface 8 the first time, 2.28 s at interface 7 every time after;
2. that compile is the cache a run now loads (needs_compile False); then a constant of a
   compiled callee in another module is changed in the copy (the rigid block's closed form,
   run_block in block/closed_form.py, and its scan step in block/piece.py): the change must
   show (another count of closed-form evaluations, needs_compile True before the run, for the
   closed form and for the kernel alike: the key covers every compiled source at once); and
   an unchanged copy must load its cache again (needs_compile False, the same count).

One compile of the kernel (the first run's: about 40 s at low load, 60-120 s under load) and
two of the closed form (6-10 s each). The first-use flow shares this test's compile of the
kernel instead of making its own, and the change is made to the closed form's callee, whose
compile is the cheapest: one kernel compile in CI instead of three. The kernel's own stamp
is the same key (test_every_compiled_function_carries_the_key); before the key, a change to
step/rk.py left the cached run_kernel in use.

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

from .paths import CONFIGS
from .test_first_use import same_run_folders

PACKAGE = Path(__file__).resolve().parents[1] / "rbm_cli"

#: One run of a rigid block under a harmonic pulse train, through the compiled kernel
#: (DOP853) or the compiled closed form ("closed-form"): whether each needed a compile
#: before and after, and the run's counts (steps; for the closed form, pieces, and its
#: evaluations, which the scan step changes).
DRIVER = """
import json, sys
import rbm_cli
from rbm_cli.models.rbm.step import needs_compile as kernel_stale
from rbm_cli.models.block.closed_form import needs_compile as closed_stale
method = sys.argv[1]
stale = kernel_stale if method == "DOP853" else closed_stale
before, kernel_before = stale(), kernel_stale()
from rbm_cli.api import run
cfg = {"name": "block", "column": {"height": 2.0, "base_width": 0.5},
       "excitation": {"type": "harmonic", "duration": 4.0},
       "solver": {"method": method, "implementation": "compiled", "rtol": 1e-9,
                  "atol": 1e-11}}
cell = run(cfg, amplitude_g=0.4, frequency_hz=2.0, record=False)
print(json.dumps({"file": rbm_cli.__file__, "before": before, "after": stale(),
                  "kernel_before": kernel_before, "n_steps": int(cell.result.n_steps),
                  "n_rhs": int(cell.result.n_rhs), "status": cell.status}))
"""


#: A kernel sweep started while the first run compiles (a rigid block, DOP853).
CONFIG = """name: block
column: {height: 4.0, base_width: 1.0}
excitation: {type: harmonic, duration: 6.0}
solver: {method: DOP853}
grid:
  amplitudes: [0.3, 0.5]
  frequencies: [1.0]
"""
#: The README's first-use example: a chaotic cell of the 8-drum column.
FIRST_RUN = ["run", str(CONFIGS / "harmonic_multidrum.yaml"), "-a", "0.3", "-f", "2"]


def _env(copy: Path, cache: Path) -> dict:
    """A user's environment (no rbm settings of the test session) running the copy."""
    env = {k: v for k, v in os.environ.items() if not k.startswith("RBM_")}
    return dict(env, PYTHONPATH=str(copy), NUMBA_CACHE_DIR=str(cache), MPLBACKEND="Agg")


def _run(copy: Path, cache: Path, cwd: Path, method: str = "DOP853") -> dict:
    res = subprocess.run([sys.executable, "-c", DRIVER, method], env=_env(copy, cache), cwd=cwd,
                         capture_output=True, text=True, timeout=900)  # fmt: skip
    assert res.returncode == 0, res.stderr[-3000:]
    out = json.loads(res.stdout.strip().splitlines()[-1])
    assert Path(out["file"]).resolve().is_relative_to(copy.resolve()), out["file"]  # the copy
    return out


def _rbm(*args: str) -> list[str]:
    """The command line of `rbm args`."""
    return [sys.executable, "-m", "rbm_cli", *args]


def _edit_scan_step(path: Path, new: str) -> None:
    """The closed form's longest scanning interval (SCAN_STEP = 1.0) of block/piece.py."""
    text = path.read_text()
    edited, n = re.subn(r"^(SCAN_STEP\b[^=\n]*=\s*)1\.0\b", rf"\g<1>{new}", text, flags=re.M)
    assert n == 1, f"no 'SCAN_STEP ... = 1.0' in {path}"
    path.write_text(edited)


def _first_use(copy: Path, cache: Path, cwd: Path) -> None:
    """Step 1 of the module's docstring: the first run compiles, a sweep waits for it, and
    the second run answers as the first."""
    env = _env(copy, cache)
    (cwd / "block.yaml").write_text(CONFIG)
    first = subprocess.Popen(_rbm(*FIRST_RUN, "-o", "first"), env=env, cwd=cwd,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)  # fmt: skip
    try:
        note = first.stderr.readline()  # the first line: before the compile starts
        # the first run compiles: a sweep now waits for that compile, then loads it
        sweep = subprocess.run(_rbm("sweep", "block.yaml", "-o", "swept"), env=env, cwd=cwd,
                               capture_output=True, text=True, timeout=900)  # fmt: skip
        _, err = first.communicate(timeout=900)
    finally:
        if first.poll() is None:
            first.kill()
    assert first.returncode == 0, note + err
    second = subprocess.run(_rbm(*FIRST_RUN, "-o", "second"), env=env, cwd=cwd,
                            capture_output=True, text=True, timeout=900)  # fmt: skip
    assert second.returncode == 0, second.stderr

    folder = Path("harmonic_multidrum/run_A0.3_f2")
    same_run_folders(cwd / "first" / folder, cwd / "second" / folder)
    summary = json.loads((cwd / "first" / folder / "summary.json").read_text())
    assert summary["config"]["solver"]["implementation"] == "compiled"
    assert summary["status"] == "collapsed"

    assert note.startswith("note: compiling the integrator (first use only, about"), note
    assert "note:" not in err, err  # one note, the one read above
    assert "note:" not in second.stderr, second.stderr  # compiled kernel, from the cache
    assert sweep.returncode == 0, sweep.stderr
    assert "compiling" not in sweep.stderr  # never a second compile
    waits = "note: waiting for the integrator to compile in another rbm process (first use"
    assert waits in sweep.stderr, sweep.stderr
    assert "s waiting for the integrator to compile)" in sweep.stdout, sweep.stdout


@pytest.mark.slow
@pytest.mark.timeout(1800)
def test_first_use_then_a_change_to_a_compiled_callee_invalidates_the_cache(tmp_path):
    copy = tmp_path / "src"
    shutil.copytree(PACKAGE, copy / "rbm_cli", ignore=shutil.ignore_patterns("__pycache__"))
    cache = tmp_path / "numba-cache"
    _first_use(copy, cache, tmp_path)

    first = _run(copy, cache, tmp_path)
    assert first["before"] is False and first["after"] is False  # the first run's compile
    closed = _run(copy, cache, tmp_path, "closed-form")  # its first use: a compile
    assert closed["before"] is True and closed["after"] is False
    assert closed["kernel_before"] is False
    indexes = sorted(p.name for p in cache.rglob("*.nbi"))

    # same length, same size on disk: only the contents differ
    _edit_scan_step(copy / "rbm_cli" / "models" / "block" / "piece.py", "0.5")
    edited = _run(copy, cache, tmp_path, "closed-form")
    assert edited["before"] is True, "needs_compile() missed a change to block/piece.py"
    assert edited["kernel_before"] is True, "the kernel's key missed a change to a compiled source"
    assert edited["n_rhs"] != closed["n_rhs"], "the stale cached closed form ran"
    assert edited["status"] == closed["status"]  # the same answer, found with more evaluations
    assert edited["after"] is False
    assert sorted(p.name for p in cache.rglob("*.nbi")) == indexes  # rewritten, not added

    again = _run(copy, cache, tmp_path, "closed-form")  # nothing changed: the cache as it is
    assert again["before"] is False
    assert again["n_rhs"] == edited["n_rhs"]


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
    # run_kernel reads EVENT_EPS and BIG of base/events.py: frozen into its code
    assert PACKAGE / "base" / "events.py" in sources
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
    rk = root / "numerics" / "rk.py"
    assert changed(rk, rk.read_text().replace("SAFETY, MIN_FACTOR", "SAFETY,  MIN_FACTOR"))
    events = root / "base" / "events.py"
    assert changed(events, events.read_text() + "\n# EVENT_EPS is read by run_kernel\n")
    new = root / "models" / "rbm" / "step" / "new.py"  # a new kernel module, named nowhere
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


class _Gone:
    """A type a cache index names, then removed (as a renamed record of arrays is)."""


def test_an_index_naming_a_type_that_no_longer_exists_is_stale(tmp_path, monkeypatch):
    """An index written by another version of the package may name a type this version
    does not have; numba unpickles it before it compares the stamp. Read as empty (the
    function is compiled again), not raised (this once stopped every run of the exact
    integrator after its record of arrays was renamed)."""
    import pickle

    import numba
    from numba.core import caching

    import rbm_cli.base.jit  # noqa: F401  (keys numba's cache when imported)

    index = caching.IndexDataCacheFile(str(tmp_path), "gone-1.py311", ("stamp", 1))
    with open(index._index_path, "wb") as f:
        pickle.dump(numba.__version__, f)
        f.write(pickle.dumps((("stamp", 1), {(_Gone(),): "an overload"})))
    assert index._load_index() != {}  # readable while the type exists
    monkeypatch.delattr(sys.modules[__name__], "_Gone")
    assert index._load_index() == {}


def test_a_cache_that_cannot_be_written_leaves_the_function_running(tmp_path):
    """A compiled function whose cache cannot be written (here a file size limit of 512
    bytes, as a full disk) still runs: numba's cache is keyed by rbm (its import), and a
    failed write is skipped instead of raised (a sweep on a full disk once ended in numba's
    traceback before it could say what it could not write)."""
    import resource

    (tmp_path / "tiny.py").write_text(
        "import numba\n\n\n@numba.njit(cache=True)\ndef add_one(x):\n    return x + 1\n"
    )
    code = "import rbm_cli.base.jit, tiny; print(tiny.add_one(41))"

    def limit():
        resource.setrlimit(resource.RLIMIT_FSIZE, (512, 512))

    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), *sys.path])}
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=env, preexec_fn=limit, timeout=120)  # fmt: skip
    assert res.returncode == 0, res.stderr
    assert res.stdout.strip() == "42"


def test_a_function_that_cannot_be_cached_still_runs(tmp_path):
    """A keyed function numba cannot cache (here one reading a large global array, which
    numba keeps outside the compiled code) gets numba's warning and runs: the warning names
    the source file, which numba asks of the cache's locator (a first use under NUMBA_OPT=0
    once ended in an AttributeError there instead of the run)."""
    (tmp_path / "big.py").write_text(
        "import numba\nimport numpy as np\n\nBIG = np.arange(2_000_000.0)\n\n\n"
        "@numba.njit(cache=True)\ndef fifth():\n    return BIG[5]\n"
    )
    code = (
        "import pathlib, rbm_cli.base.compile_cache as cc\n"
        f"cc.PACKAGE = pathlib.Path({str(tmp_path)!r})\n"
        "import rbm_cli.base.jit, big\nprint(big.fifth())"
    )
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), *sys.path]),
           "NUMBA_CACHE_DIR": str(tmp_path / "cache")}  # fmt: skip
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=env, timeout=120)  # fmt: skip
    assert res.returncode == 0, res.stderr
    assert res.stdout.strip() == "5.0"
    assert "Cannot cache compiled function" in res.stderr
