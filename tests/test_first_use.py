"""First use without the wait (issue 18, "first use"): the switch and the
one-compile-at-a-time rule of rbm_cli.models.rbm.compile_ahead.

The whole first-use flow (on an empty compile cache `rbm run` answers with the Python
integrator while the kernel compiles in the background, a sweep waits for that compile,
then the compiled kernel agrees with the Python run) is the first half of
tests/test_kernel_cache.py's slow test, whose cache check reuses that compile. The rigid
block's first use (its compiled closed form compiling in the background) is here.
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


BLOCK = """name: block
column: {height: 4.0, base_width: 1.0}
excitation: {type: harmonic, duration: 6.0}
"""


def _rbm(args: list[str], env: dict, cwd: Path) -> subprocess.CompletedProcess:
    cmd = [sys.executable, "-c", "from rbm_cli.cli.main import main; main()", *args]
    return subprocess.run(cmd, env=env, cwd=cwd, capture_output=True, text=True, timeout=600)


@pytest.mark.slow
def test_first_run_of_a_rigid_block_answers_while_its_closed_form_compiles(tmp_path):
    """The rigid block's default (`auto`) is its compiled closed form: on an empty cache
    the first run starts that compile in the background and answers with the Python step
    integrator (DOP853); the next run is the closed form, and the two agree far below
    DOP853's tolerance (rtol 1e-10: collapse times to 1e-7 relative; an independent
    method, tests/test_closed_form_jit.py holds them together on grids)."""
    cache = tmp_path / "numba-cache"
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache), MPLBACKEND="Agg")
    env.pop(compile_ahead.ENV_SWITCH, None)
    (tmp_path / "block.yaml").write_text(BLOCK)
    run_args = ["run", "block.yaml", "-a", "0.5", "-f", "1"]

    first = _rbm([*run_args, "-o", "first"], env, tmp_path)
    assert first.returncode == 0, first.stderr
    assert "closed form is compiling in the background" in first.stderr, first.stderr
    s1 = json.loads((tmp_path / "first/block/run_A0.5_f1/summary.json").read_text())
    assert (s1["method"], s1["config"]["solver"]["implementation"]) == ("DOP853", "python")
    assert s1["status"] == "collapsed"

    locks = list(cache.rglob(compile_ahead.LOCK_NAME))
    assert len(locks) == 1, locks
    deadline = time.monotonic() + 600
    while _locked(locks[0]):
        assert time.monotonic() < deadline, "the background compile did not end"
        time.sleep(0.2)
    log = (locks[0].parent / compile_ahead.LOG_NAME).read_text()
    assert "closed-form compiled" in log, log

    second = _rbm([*run_args, "-o", "second"], env, tmp_path)
    assert second.returncode == 0, second.stderr
    assert "note:" not in second.stderr, second.stderr  # the closed form, from the cache
    s2 = json.loads((tmp_path / "second/block/run_A0.5_f1/summary.json").read_text())
    assert (s2["method"], s2["config"]["solver"]["implementation"]) == ("closed-form", "compiled")
    assert s2["status"] == s1["status"]
    assert s2["t_collapse_s"] == pytest.approx(s1["t_collapse_s"], rel=1e-7)


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
