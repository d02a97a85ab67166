"""First use without the wait (issue 18, "first use"): on an empty compile cache `rbm run`
starts the kernel's compile in a background process and answers with the Python
integrator; a sweep started meanwhile waits for that compile instead of compiling again;
once it is done the compiled kernel runs and agrees with the Python run.

Independent reasons: the Python loop and the compiled kernel are two implementations of
one method held to the same steps (tests/test_kernel.py), so their collapse times agree
far below the solver's tolerance (rtol 1e-10 here; checked to 1e-8 relative); the lock is
read by this test with its own flock, not through the module under test.

One compile of the kernel in a fresh numba cache: about 20 s, more under load.
"""

from __future__ import annotations

import fcntl
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from rbm_cli.models.rbm import compile_ahead

CONFIG = """name: block
column: {height: 4.0, base_width: 1.0}
excitation: {type: harmonic, duration: 6.0}
solver: {method: DOP853}
grid:
  amplitudes: [0.3, 0.5]
  frequencies: [1.0]
"""


def _rbm(args: list[str], env: dict, cwd: Path) -> subprocess.CompletedProcess:
    cmd = [sys.executable, "-c", "from rbm_cli.cli.main import main; main()", *args]
    return subprocess.run(cmd, env=env, cwd=cwd, capture_output=True, text=True, timeout=900)


def _locked(path: Path) -> bool:
    """Whether some process holds an exclusive flock on path (read with our own flock)."""
    fd = os.open(path, os.O_RDWR)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        return True
    finally:
        os.close(fd)
    return False


def _summary(folder: Path) -> dict:
    return json.loads((folder / "summary.json").read_text())


@pytest.mark.slow
def test_first_run_answers_while_the_kernel_compiles(tmp_path):
    cache = tmp_path / "numba-cache"
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache), MPLBACKEND="Agg")
    env.pop(compile_ahead.ENV_SWITCH, None)
    (tmp_path / "block.yaml").write_text(CONFIG)
    run_args = ["run", "block.yaml", "-a", "0.5", "-f", "1"]

    first = _rbm([*run_args, "-o", "first"], env, tmp_path)
    assert first.returncode == 0, first.stderr
    assert "compiling in the background" in first.stderr, first.stderr
    s1 = _summary(tmp_path / "first/block/run_A0.5_f1")
    assert s1["config"]["solver"]["implementation"] == "python"
    assert s1["status"] == "collapsed"

    locks = list(cache.rglob(compile_ahead.LOCK_NAME))
    assert len(locks) == 1, locks
    # a sweep now waits for that compile (unless it finished already: then it loads it)
    sweep = _rbm(["sweep", "block.yaml", "-o", "swept"], env, tmp_path)
    assert sweep.returncode == 0, sweep.stderr
    assert "note: compiling the integrator" not in sweep.stderr  # never a second compile
    deadline = time.monotonic() + 900
    while _locked(locks[0]):  # the background compile still runs (sweep's notes aside)
        assert time.monotonic() < deadline, "the background compile did not end"
        time.sleep(0.5)
    log = (locks[0].parent / compile_ahead.LOG_NAME).read_text()
    assert "kernel compiled" in log, log

    second = _rbm([*run_args, "-o", "second"], env, tmp_path)
    assert second.returncode == 0, second.stderr
    assert "note:" not in second.stderr, second.stderr  # compiled kernel, from the cache
    s2 = _summary(tmp_path / "second/block/run_A0.5_f1")
    assert s2["config"]["solver"]["implementation"] == "compiled"
    assert s2["status"] == s1["status"]
    assert s2["t_collapse_s"] == pytest.approx(s1["t_collapse_s"], rel=1e-8)


def test_the_switch_keeps_the_compile_in_the_foreground(monkeypatch):
    """RBM_BACKGROUND_COMPILE=0: no process is started; the caller compiles."""
    monkeypatch.setenv(compile_ahead.ENV_SWITCH, "0")
    started = []
    monkeypatch.setattr(compile_ahead.subprocess, "Popen", lambda *a, **k: started.append(a))
    assert compile_ahead.start() is False
    assert started == []


def test_one_compile_at_a_time(tmp_path, monkeypatch):
    """While a process holds the lock, start() starts nothing and says a compile runs;
    wait() returns once the lock is released."""
    monkeypatch.delenv(compile_ahead.ENV_SWITCH, raising=False)
    monkeypatch.setattr(compile_ahead, "cache_folder", lambda: tmp_path)
    holder = subprocess.Popen(
        [sys.executable, "-c",
         "import fcntl, os, sys, time\n"
         f"fd = os.open({str(tmp_path / compile_ahead.LOCK_NAME)!r}, os.O_RDWR | os.O_CREAT)\n"
         "fcntl.flock(fd, fcntl.LOCK_EX)\nprint('held', flush=True)\ntime.sleep(1.0)\n"],
        stdout=subprocess.PIPE, text=True)  # fmt: skip
    assert holder.stdout.readline().strip() == "held"
    started = []
    monkeypatch.setattr(compile_ahead.subprocess, "Popen", lambda *a, **k: started.append(a))
    assert compile_ahead.compiling_elsewhere() is True
    assert compile_ahead.start() is True and started == []
    waited = compile_ahead.wait(poll_s=0.05)
    holder.wait(timeout=30)
    assert waited > 0.0 and compile_ahead.compiling_elsewhere() is False
