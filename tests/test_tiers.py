"""The two test tiers: a plain `pytest` (the README's command) runs the fast tier, the tests
not marked slow; `pytest -m slow` runs the slow tier, `pytest -m ""` both (a -m on the
command line replaces the one of pyproject's addopts). `.ci/run` runs both, each with its
slowest tests listed, and the README names both commands.

Checked on pytest's own collection of one file that holds tests of both tiers
(tests/test_bench.py: its scoring is quick, its bench run is slow)."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest

from .paths import ROOT

FILE = "tests/test_bench.py"
QUICK = "test_targets_fail_when_the_default_misses_them"
SLOW = "test_quick_bench_meets_the_accuracy_targets"


def _collected(*args: str) -> set[str]:
    """The names of the tests pytest collects from FILE with args, as from the repository's
    root with its configuration (one process: -n 0)."""
    cmd = [sys.executable, "-m", "pytest", "--collect-only", "-q", "-n", "0", *args, FILE]
    res = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stdout[-2000:] + res.stderr[-2000:]
    return {line.split("::")[1].split("[")[0] for line in res.stdout.splitlines() if "::" in line}


@pytest.mark.parametrize(
    ("args", "quick", "slow"),
    [((), True, False), (("-m", "slow"), False, True), (("-m", ""), True, True)],
    ids=["plain", "slow", "both"],
)
def test_a_plain_pytest_runs_the_fast_tier_and_a_given_m_replaces_it(args, quick, slow):
    names = _collected(*args)
    assert (QUICK in names, SLOW in names) == (quick, slow), sorted(names)


def test_ci_runs_the_fast_tier_then_the_slow_one_with_their_slowest_tests():
    text = (ROOT / ".ci" / "run").read_text()
    runs = [line.strip() for line in text.splitlines() if re.match(r"\s*python -m pytest", line)]
    assert len(runs) == 2, runs
    fast, slow = (run.split("pytest", 1)[1] for run in runs)  # its options
    assert " -m " not in fast and "--durations=25" in fast
    assert " -m slow " in slow and "--durations=25" in slow


def test_the_readme_names_both_tiers():
    text = (ROOT / "README.md").read_text()
    assert "pip install -e '.[test]' && pytest\n" in text
    assert "pytest -m slow" in text
