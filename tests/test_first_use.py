"""First use: the compiled code is compiled before the first run, one compile at a time
(rbm_cli.models.compile_ahead), and the first run answers as every later run does.

The first `rbm run` on an empty compile cache once answered from the Python integrator
while the compiled code compiled in the background: a cell in chaotic motion then got
another answer the first time than every time after, and the user was not told. Here:

- the rigid block (its compiled closed form, the default there) on an empty cache: the
  first run says that it compiles, waits, and writes the same run folder as the second
  (slow: one compile of the closed form);
- the 8-drum column of the README's first-use example, a chaotic cell, with a sweep started
  while the first run compiles: the first half of tests/test_kernel_cache.py's slow test,
  which shares that compile;
- quick: a compile another process runs is waited for and loaded, not repeated (and
  compiled here if that process died); a sweep says what it compiles before it waits, and
  names it in its last line; a run in Python compiles nothing.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
import types
from pathlib import Path

import pytest
from click.testing import CliRunner

from rbm_cli.cli.main import cli
from rbm_cli.models import compile_ahead

from .paths import CONFIGS


def invoke(*args):
    return CliRunner().invoke(cli, [str(a) for a in args])


def _user_env(**extra) -> dict:
    """A user's environment (no rbm settings of the test session), with extra."""
    env = {k: v for k, v in os.environ.items() if not k.startswith("RBM_")}
    return dict(env, MPLBACKEND="Agg", **extra)


def _rbm(args: list[str], env: dict, cwd: Path) -> subprocess.CompletedProcess:
    cmd = [sys.executable, "-m", "rbm_cli", *args]
    return subprocess.run(cmd, env=env, cwd=cwd, capture_output=True, text=True, timeout=900)


def same_run_folders(first: Path, second: Path) -> None:
    """The two run folders hold the same answer: summary.json equal but for the wall time,
    history.csv byte for byte."""
    s1, s2 = (json.loads((f / "summary.json").read_text()) for f in (first, second))
    s1.pop("wall_time_s")
    s2.pop("wall_time_s")
    assert s1 == s2
    assert (first / "history.csv").read_bytes() == (second / "history.csv").read_bytes()


BLOCK = """name: block
column: {height: 4.0, base_width: 1.0}
excitation: {type: harmonic, duration: 6.0}
"""


@pytest.mark.slow
def test_the_first_run_of_a_rigid_block_answers_as_every_later_run(tmp_path):
    """The rigid block's default (`auto`) is its compiled closed form. On an empty cache its
    first run once answered with the Python step integrator (DOP853) while the closed form
    compiled in the background, and the next run with the closed form: two answers. Now
    the first run says it compiles, waits, and answers with the closed form: the same run
    folder as the second run, whose closed form comes from the cache."""
    env = _user_env(NUMBA_CACHE_DIR=str(tmp_path / "numba-cache"))
    (tmp_path / "block.yaml").write_text(BLOCK)
    run_args = ["run", "block.yaml", "-a", "0.5", "-f", "1"]

    first = _rbm([*run_args, "-o", "first"], env, tmp_path)
    assert first.returncode == 0, first.stderr
    second = _rbm([*run_args, "-o", "second"], env, tmp_path)
    assert second.returncode == 0, second.stderr

    folder = Path("block/run_A0.5_f1")
    same_run_folders(tmp_path / "first" / folder, tmp_path / "second" / folder)
    summary = json.loads((tmp_path / "first" / folder / "summary.json").read_text())
    assert summary["method"] == "closed-form" and summary["status"] == "collapsed"
    assert summary["config"]["solver"]["implementation"] == "compiled"
    note = "note: compiling the rigid block's closed form (first use only, about"
    assert first.stderr.startswith(note), first.stderr
    assert "note:" not in second.stderr, second.stderr  # the closed form, from the cache


# --------------------------------------------------------------------------- quick checks


def _holder(lock: Path, seconds: float) -> subprocess.Popen:
    """A process that holds the compile lock for seconds (as a compile there would)."""
    code = (
        "import fcntl, os, sys, time\n"
        f"fd = os.open({str(lock)!r}, os.O_RDWR | os.O_CREAT)\n"
        "fcntl.flock(fd, fcntl.LOCK_EX)\n"
        "print('held', flush=True)\n"
        f"time.sleep({seconds})\n"
    )
    holder = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    assert holder.stdout.readline().strip() == "held"
    return holder


@pytest.mark.parametrize("compiled_there", [True, False], ids=["done-there", "died-there"])
def test_a_compile_in_another_process_is_waited_for_not_repeated(
    tmp_path, monkeypatch, compiled_there
):
    """While another process holds the compile lock, compile_once says it waits, waits,
    then loads what that process compiled (one warm_up here, which loads it); if that
    process ended without compiling (killed), it compiles here and says so."""
    monkeypatch.setattr(compile_ahead, "cache_folder", lambda target="kernel": tmp_path)
    holder = _holder(tmp_path / compile_ahead.LOCK_NAME, 1.0)
    warmed = []
    fake = types.ModuleType("fake_target")
    fake.needs_compile = lambda: holder.poll() is None or not compiled_there
    fake.warm_up = lambda: warmed.append(holder.poll())
    monkeypatch.setitem(sys.modules, "fake_target", fake)
    monkeypatch.setitem(compile_ahead.TARGETS, "fake", ("fake_target", "f"))
    monkeypatch.setitem(compile_ahead.NAMES, "fake", "the fake code")
    monkeypatch.setitem(compile_ahead.ABOUT_S, "fake", 7)
    notes = []
    start = time.monotonic()
    seconds, what = compile_ahead.compile_once("fake", notes.append, poll_s=0.02)
    holder.wait(timeout=30)
    assert time.monotonic() - start >= 0.5  # it waited for the lock
    assert warmed == [0]  # once, after the other process had ended
    waiting = "waiting for the fake code to compile in another rbm process (first use only," \
        " about 7 s on an idle machine)"  # fmt: skip
    if compiled_there:
        assert notes == [waiting]
        assert what == "waiting for the fake code to compile"
    else:
        assert notes == [
            waiting,
            "compiling the fake code (first use only, about 7 s on an idle machine)",
        ]
        assert what == "compiling the fake code"
    assert seconds > 0.0
    # the lock is free again: a compile now starts at once
    fake.needs_compile = lambda: True
    notes.clear()
    assert compile_ahead.compile_once("fake", notes.append)[1] == "compiling the fake code"
    assert notes == ["compiling the fake code (first use only, about 7 s on an idle machine)"]


SMALL_BLOCK = """name: small_block
column: {height: 4.0, base_width: 1.0}
excitation: {type: harmonic, duration: 2.0}
grid: {amplitudes: [0.2, 0.6], frequencies: [1.0]}
"""


def test_a_sweep_says_what_it_compiles_before_it_waits_and_after(tmp_path, monkeypatch):
    """A first sweep of a rigid block (its closed form not in the cache) was silent while
    the closed form compiled, then called that time "loading the integrator". It now says
    "compiling the rigid block's closed form" on stderr before the compile, and its last
    line names the compile. (The cache is there: the compile is made to look needed and
    to take a second.)"""
    import rbm_cli.models.block.closed_form as closed_form

    real = closed_form.warm_up

    def slow_warm_up():
        time.sleep(1.2)
        real()

    monkeypatch.setattr(closed_form, "needs_compile", lambda: True)
    monkeypatch.setattr(closed_form, "warm_up", slow_warm_up)
    path = tmp_path / "small_block.yaml"
    path.write_text(SMALL_BLOCK)
    res = invoke("sweep", path, "-o", tmp_path / "out", "--jobs", "1")
    assert res.exit_code == 0, res.output
    note = "note: compiling the rigid block's closed form (first use only, about"
    assert res.stderr.startswith(note), res.stderr  # before the progress lines
    assert "s compiling the rigid block's closed form)" in res.stdout, res.stdout
    assert "loading the integrator" not in res.stdout


def test_a_run_in_python_compiles_nothing(tmp_path, monkeypatch):
    """`solver.implementation: python` is what the user asked for: no compile, no note,
    the Python integrator's answer."""
    import rbm_cli.models.rbm.step as kernel

    def no_compile():
        raise AssertionError("the kernel was compiled for a run in Python")

    monkeypatch.setattr(kernel, "needs_compile", lambda: True)
    monkeypatch.setattr(kernel, "warm_up", no_compile)
    text = (CONFIGS / "harmonic_monolithic.yaml").read_text()
    path = tmp_path / "python.yaml"
    path.write_text(text + "\nsolver: {implementation: python}\n")
    res = invoke("run", path, "-a", 0.5, "-f", 1, "-o", tmp_path / "out")
    assert res.exit_code == 0, res.output
    assert "note:" not in res.stderr
    (summary,) = (tmp_path / "out").rglob("summary.json")
    assert json.loads(summary.read_text())["config"]["solver"]["implementation"] == "python"


def test_a_first_exact_run_compiles_the_exact_integrator(tmp_path, monkeypatch):
    """`solver.method: exact` runs the compiled exact integrator, not the step kernel: its
    first use compiles that (and says so), where it once compiled the step kernel, which
    the run does not use."""
    import rbm_cli.models.rbm.exact.integrate as exact_integrate
    import rbm_cli.models.rbm.step as kernel

    def no_compile():
        raise AssertionError("the step kernel was compiled for an exact run")

    monkeypatch.setattr(kernel, "needs_compile", lambda: True)
    monkeypatch.setattr(kernel, "warm_up", no_compile)
    monkeypatch.setattr(exact_integrate, "needs_compile", lambda: True, raising=False)
    text = (CONFIGS / "harmonic_monolithic.yaml").read_text()
    path = tmp_path / "exact.yaml"
    path.write_text(text + "\nsolver: {method: exact}\n")
    res = invoke("run", path, "-a", 0.5, "-f", 1, "-o", tmp_path / "out")
    assert res.exit_code == 0, res.output
    assert res.stderr.startswith("note: compiling the exact integrator (first use only,")
    (summary,) = (tmp_path / "out").rglob("summary.json")
    summary = json.loads(summary.read_text())
    assert summary["method"] == "exact"
    assert summary["config"]["solver"]["implementation"] == "compiled"
