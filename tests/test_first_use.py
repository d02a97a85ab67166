"""First use without the wait (issue 18, "first use"): the switch and the
one-compile-at-a-time rule of rbm_cli.models.rbm.compile_ahead.

The whole first-use flow (on an empty compile cache `rbm run` answers with the Python
integrator while the kernel compiles in the background, a sweep waits for that compile,
then the compiled kernel agrees with the Python run) is the first half of
tests/test_kernel_cache.py's slow test, whose cache check reuses that compile.
"""

from __future__ import annotations

import subprocess
import sys

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
