"""The rules tests/conftest.py sets for the whole suite: a test that forks runs in a fresh
interpreter (so it runs in a full run too), and on Linux a test that skips fails unless it
says why it may skip.

In a full run the tests that fork the figure child (rbm_cli.report.figure_process) once
skipped, "no fork here (threads running)": other tests had left threads running, and
FigureProcess does not fork then. They passed only when run alone, and CI never
exercised the forked child. Here pytest runs in a process of its own, with a plugin that
starts a thread first (as a full run has), and with test files written here.
"""

from __future__ import annotations

import os
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from .paths import ROOT

linux_only = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux's rule")


def _pytest(args: list[str], tmp_path: Path, env: dict | None = None) -> dict[str, str]:
    """Run pytest with args from the repository's root; {module.test name: outcome}."""
    xml = tmp_path / "report.xml"
    cmd = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
           f"--junitxml={xml}", *args]  # fmt: skip
    proc = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True, timeout=600)
    assert xml.is_file(), proc.stdout[-3000:] + proc.stderr[-3000:]
    outcomes = {}
    for case in ET.parse(xml).getroot().iter("testcase"):
        tags = {child.tag for child in case}
        outcome = "passed"
        if tags & {"failure", "error"}:
            outcome = "failed"
        elif "skipped" in tags:
            outcome = "skipped"
        outcomes[f"{case.get('classname')}.{case.get('name')}"] = outcome
    return outcomes


SKIPS = """
import pytest


def test_skips():
    pytest.skip("nothing to see")


@pytest.mark.skipif(True, reason="a marker says so")
def test_skipped_by_a_marker():
    pass


@pytest.mark.may_skip(reason="opt-in: runs with SOME_VARIABLE set")
def test_may_skip():
    pytest.skip("SOME_VARIABLE not set")


@pytest.mark.may_skip
def test_may_skip_without_a_reason():
    pytest.skip("no reason given for the mark")


def test_runs():
    pass
"""


@linux_only
def test_a_skip_on_linux_fails_unless_the_test_may_skip(tmp_path):
    """A test that skips on Linux is a failing test; one marked may_skip with a reason is
    reported skipped."""
    path = tmp_path / "test_skips.py"
    path.write_text(SKIPS)
    outcomes = _pytest(["-p", "tests.conftest", str(path)], tmp_path)
    assert {name.rsplit(".", 1)[1]: outcome for name, outcome in outcomes.items()} == {
        "test_skips": "failed",
        "test_skipped_by_a_marker": "failed",
        "test_may_skip": "skipped",
        "test_may_skip_without_a_reason": "failed",
        "test_runs": "passed",
    }


#: A pytest plugin that leaves a thread running, as other tests of a full run do.
BUSY = """
import threading
import time


def pytest_configure(config):
    threading.Thread(target=time.sleep, args=(3600,), daemon=True).start()
"""


@pytest.mark.slow
def test_the_forking_tests_run_while_other_threads_run(tmp_path):
    """With a thread running in the test process, the figure-process tests that fork still
    run (in a fresh interpreter) and pass: none skips."""
    (tmp_path / "busy_thread.py").write_text(BUSY)
    env = {k: v for k, v in os.environ.items() if not k.startswith("RBM_")}  # no switches
    env["PYTHONPATH"] = os.pathsep.join([str(tmp_path), *filter(None, [env.get("PYTHONPATH")])])
    files = ["tests/test_figure_process.py", "tests/test_run_figure_process.py"]
    outcomes = _pytest(["-p", "busy_thread", "-m", "fresh_interpreter", *files], tmp_path, env)
    assert len(outcomes) >= 13, outcomes  # every test that forks in its own process
    assert set(outcomes.values()) == {"passed"}, outcomes
