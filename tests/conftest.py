"""Test setup: nothing is written into the working tree (Agg backend, no caches here); the
tests that fork run in a fresh interpreter; on Linux a skipped test is a failed one.

- ``@pytest.mark.fresh_interpreter``: the test runs in a pytest process of its own, a
  fresh interpreter with no thread that other tests left running (a Dask cluster's, a
  joblib pool's, a server's). Such tests fork (the figure child of
  rbm_cli.report.figure_process), which is refused while other threads run: in a full run
  they skipped, and the forked child was never exercised. The marked tests of one module
  run together in one such process when the first of them is reached (its duration is
  theirs); each reports its own outcome, a failure with the fresh interpreter's report.
- A run of many tests (:data:`WARM_UP_ITEMS` or more: the whole suite) first compiles the
  package's compiled code (the step kernel, the exact integrator, the rigid block's closed
  form, the run in two directions) into numba's cache, each once: the longest compiles
  are shared out first so that the workers finish together (:func:`warm_up_order`), and
  each takes its share, then the others', through
  rbm_cli.models.compile_ahead.compile_once, whose lock makes a worker that needs a target
  another one compiles wait for it and load it. Without it each worker compiled what its
  first tests needed, the same kernel in both at once (tests call the integrators directly,
  not through the lock), and a test's duration held a compile.
- On Linux, where CI runs, a skipped test fails: a test that skips where it must run tests
  nothing. A test that may skip there says why, ``@pytest.mark.may_skip(reason="...")``
  (an opt-in environment variable not set, a test that cannot work as root, ...).
"""

import os
import signal
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

import matplotlib
import pytest

matplotlib.use("Agg")

from hypothesis import configuration, settings  # noqa: E402

# hypothesis keeps its example database under a home directory: move it out of the tree
configuration.set_hypothesis_home_dir(tempfile.mkdtemp(prefix="rbm-hypothesis-"))
settings.register_profile("rbm", database=None, derandomize=True, deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "rbm"))

#: Set in the fresh interpreter: the marked tests run there as any other test.
FRESH_ENV = "RBM_TESTS_FRESH_INTERPRETER"
#: The outcomes of marked tests whose fresh interpreter has run, not yet reported.
_OUTCOMES = pytest.StashKey[dict]()
#: The end of the fresh interpreter's output quoted when a test has no result from it.
_TAIL = 6000
#: A run of at least this many tests compiles every target first (see the module).
WARM_UP_ITEMS = 200


@pytest.fixture(scope="session", autouse=True)
def _compiled_once(request):
    """Every compiled target in numba's cache before the first test of a large run, each
    compiled once across the workers (see the module)."""
    if len(request.session.items) < WARM_UP_ITEMS or os.environ.get(FRESH_ENV) == "1":
        return
    from rbm_cli.models.compile_ahead import ABOUT_S, TARGETS, compile_once

    worker = os.environ.get("PYTEST_XDIST_WORKER", "gw0").removeprefix("gw")
    count = int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "1"))
    for target in warm_up_order(TARGETS, ABOUT_S, int(worker) if worker.isdigit() else 0, count):
        compile_once(target)


def warm_up_order(targets, about: dict, worker: int, count: int) -> list:
    """The order in which a worker of `count` takes the compiled targets: the longest
    compiles shared out first, each to the worker with the least compile time so far
    (ABOUT_S), so that the workers finish together; a worker takes its own share first
    (longest first), then the others' (loaded from the cache, or waited for)."""
    load, share = [0.0] * max(count, 1), [[] for _ in range(max(count, 1))]
    for target in sorted(targets, key=lambda t: -about[t]):
        k = min(range(len(load)), key=lambda j: load[j])
        share[k].append(target)
        load[k] += about[target]
    own = share[worker % len(share)]
    return own + [t for part in share for t in part if t not in own]


def pytest_configure(config):
    # A shell starts a background job with SIGINT ignored, and children inherit that: the
    # tests that press Ctrl-C on a run they start would see it ignored. Python's own handler
    # here, so every child starts as it would from a terminal.
    if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)
    config.addinivalue_line(
        "markers",
        "fresh_interpreter: run in a pytest process of its own (the test forks; see conftest)",
    )
    config.addinivalue_line(
        "markers", "may_skip(reason): the test may skip on Linux, for the reason given"
    )


def _junit_key(nodeid: str) -> tuple[str, str]:
    """(classname, name) of a test in pytest's JUnit XML, from its node id."""
    path, *classes, name = nodeid.split("::")
    module = path.removesuffix(".py").replace("/", ".")
    return ".".join([module, *classes]), name


def _outcomes(xml: Path) -> dict[tuple[str, str], tuple[str, str]]:
    """{(classname, name): (outcome, text)} of a JUnit XML report; outcome 'passed',
    'failed' (a failure or an error, with its report) or 'skipped' (with its reason)."""
    found = {}
    for case in ET.parse(xml).getroot().iter("testcase"):
        outcome, texts = "passed", []
        for child in case:
            if child.tag in ("failure", "error"):
                outcome = "failed"
                texts.append(f"{child.get('message', '')}\n{child.text or ''}")
            elif child.tag == "skipped" and outcome == "passed":
                outcome = "skipped"
                texts.append(child.get("message", ""))
        found[(case.get("classname"), case.get("name"))] = (outcome, "\n".join(texts))
    return found


def _run_fresh(items: list, rootpath: Path) -> dict[str, tuple[str, str]]:
    """Run items in one fresh pytest process; {nodeid: (outcome, text)}."""
    with tempfile.TemporaryDirectory(prefix="rbm-fresh-") as tmp:
        xml = Path(tmp) / "report.xml"
        cmd = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
               f"--junitxml={xml}", *(item.nodeid for item in items)]  # fmt: skip
        env = dict(os.environ, **{FRESH_ENV: "1"})
        proc = subprocess.run(cmd, cwd=rootpath, env=env, capture_output=True, text=True)
        found = _outcomes(xml) if xml.is_file() else {}
    missing = ("failed", "no result from the fresh interpreter (exit status"
               f" {proc.returncode}):\n{(proc.stdout + proc.stderr)[-_TAIL:]}")  # fmt: skip
    return {item.nodeid: found.get(_junit_key(item.nodeid), missing) for item in items}


@pytest.hookimpl(tryfirst=True)
def pytest_pyfunc_call(pyfuncitem):
    """A fresh_interpreter test: its outcome in the fresh interpreter (see the module)."""
    if os.environ.get(FRESH_ENV) == "1" or not pyfuncitem.get_closest_marker("fresh_interpreter"):
        return None
    pending = pyfuncitem.config.stash.setdefault(_OUTCOMES, {})
    if pyfuncitem.nodeid not in pending:
        group = [item for item in pyfuncitem.session.items
                 if item.path == pyfuncitem.path and item.get_closest_marker("fresh_interpreter")
                 and item.nodeid not in pending]  # fmt: skip
        pending.update(_run_fresh(group, pyfuncitem.config.rootpath))
    outcome, text = pending.pop(pyfuncitem.nodeid)
    if outcome == "failed":
        pytest.fail(f"in a fresh interpreter:\n{text}", pytrace=False)
    if outcome == "skipped":
        pytest.skip(text)
    return True


@pytest.hookimpl(wrapper=True)
def pytest_runtest_makereport(item, call):
    """On Linux a skip is a failure, unless the test is marked may_skip with a reason."""
    report = yield
    if not (report.skipped and sys.platform.startswith("linux")) or hasattr(report, "wasxfail"):
        return report
    allowed = item.get_closest_marker("may_skip")
    if allowed is not None and (allowed.args or allowed.kwargs.get("reason")):
        return report
    reason = report.longrepr[2] if isinstance(report.longrepr, tuple) else report.longrepr
    report.outcome = "failed"
    report.longrepr = (
        f"skipped on Linux, where it must run: {reason} (a test that may skip here says why:"
        " @pytest.mark.may_skip(reason=...))"
    )
    return report


@pytest.fixture(scope="module")
def pair_dir(tmp_path_factory):
    """Two synthetic records of the project (the same sampling), and a record of zeros
    sampled as they are: the records of a pair (models in three dimensions)."""
    import numpy as np

    from rbm_cli.inputs.records import read_record

    records = Path(__file__).resolve().parents[1] / "configs" / "records" / "synthetic"
    folder = tmp_path_factory.mktemp("pair")
    for name in ("rdk_01", "rdk_02"):
        (folder / f"{name}.AT2").write_bytes((records / f"{name}.AT2").read_bytes())
    t = read_record(str(folder / "rdk_01.AT2")).t
    np.savetxt(folder / "zero.csv", np.c_[t, np.zeros_like(t)], delimiter=",",
               header="time_s,acc_g", comments="")  # fmt: skip
    return folder
