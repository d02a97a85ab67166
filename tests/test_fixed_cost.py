"""No fixed cost a user waits for: a sweep starts a worker pool only when the
pool saves more time than it costs; the rows do not depend on where a chunk ran; a pool
is stopped, its workers reaped, once its chunks are done; workers and the CLI import only
what they need."""

from __future__ import annotations

import dataclasses
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from rbm_cli.api import run_sweep
from rbm_cli.config.load import load_config
from rbm_cli.config.types import GridConfig
from rbm_cli.study import parallel
from rbm_cli.study.cells import grid_cells, grid_points
from rbm_cli.study.store import JOURNAL

from .paths import CONFIGS
from .processes import parent_modules

pytestmark = pytest.mark.timeout(240)


def rigid(amps=(0.2, 0.3, 0.5, 0.8, 1.2), freqs=(0.5, 1.0, 2.0)):
    """The slender rigid block of Spanos and Koh: ~1 ms a cell, a cheap sweep."""
    cfg = load_config(CONFIGS / "spanos_koh_slender.yaml")
    return dataclasses.replace(cfg, grid=GridConfig(amplitudes_g=amps, frequencies_hz=freqs))


@pytest.fixture
def workers(monkeypatch) -> list[int]:
    """The pids of the loky workers each pool had when it was stopped."""
    pids: list[int] = []
    real = parallel._stop

    def stop(executor):
        pids.extend(executor._processes)
        real(executor)

    monkeypatch.setattr(parallel, "_stop", stop)
    return pids


def reaped(pid: int) -> bool:
    """No process pid is left: not running, and not a zombie waiting to be reaped."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    return False


# ------------------------------------------------------------------- the rule


@pytest.mark.parametrize(
    ("time_left", "jobs", "cpus", "pays"),
    [
        (2.1, 2, 2, True),  # 2.1 s x (1 - 1/2) = 1.05 s saved > 1 s
        (1.9, 2, 2, False),  # 0.95 s saved < 1 s
        (1.6, 4, 4, True),  # 1.6 x 3/4 = 1.2 s > 1 s
        (1.6, 4, 2, False),  # 4 jobs on 2 processors: 1.6 x 1/2 = 0.8 s
        (1e6, 1, 2, False),  # one worker never saves anything
        (1e6, 8, 1, False),  # nor one processor
    ],
)
def test_a_pool_is_used_when_it_saves_more_than_it_costs(monkeypatch, time_left, jobs, cpus, pays):
    monkeypatch.setattr(parallel, "POOL_COST_S", 1.0)
    monkeypatch.setattr(os, "cpu_count", lambda: cpus)
    assert parallel.pool_pays(time_left, jobs) is pays


def _record_pool(monkeypatch) -> list:
    """Replace the pool by a recorder of the items handed to it (not run)."""
    handed: list = []

    def fake_loky(fn, args, jobs, placed=None):
        handed.extend(args)
        yield from [None] * len(args)

    monkeypatch.setattr(parallel, "_loky", fake_loky)
    return handed


class Clock:
    """parallel's clock, advanced only by the work of the items (exact binary times)."""

    def __init__(self):
        self.now = 0.0

    def perf_counter(self) -> float:
        return self.now

    def work(self, seconds: float) -> None:
        self.now += seconds


@pytest.fixture
def clock(monkeypatch) -> Clock:
    fake = Clock()
    monkeypatch.setattr(parallel, "time", fake)
    monkeypatch.setattr(parallel, "POOL_COST_S", 1.0)
    monkeypatch.setattr(parallel, "PROBE_S", 0.25)
    monkeypatch.setattr(os, "cpu_count", lambda: 2)
    return fake


STEP = 2.0**-6  # s of work an item (0.015625 s: sums of it are exact)


def test_cheap_items_stay_here(monkeypatch, clock):
    """15 items of STEP: 0.23 s in all, less than PROBE_S, and 0.12 s saved on 2 workers
    would not pay for a pool of 1 s anyway."""
    handed = _record_pool(monkeypatch)
    items = [(STEP,)] * 15
    assert list(parallel.run_chunks(clock.work, items, 2, "loky", None)) == [None] * 15
    assert handed == [] and clock.now == 15 * STEP


def test_costly_items_go_to_the_pool_once_probe_s_is_timed(monkeypatch, clock):
    """1,000 items of STEP: after 16 (PROBE_S = 0.25 s timed) the 984 left would take
    15.4 s here, 7.7 s saved on 2 workers > 1 s: the pool gets all 984."""
    handed = _record_pool(monkeypatch)
    results = list(parallel.run_chunks(clock.work, [(STEP,)] * 1000, 2, "loky", None))
    assert len(results) == 1000 and len(handed) == 984 and clock.now == 16 * STEP


def test_sizes_weigh_the_estimate(monkeypatch, clock):
    """A first item of 1 cell that took 0.25 s: 400 cells left in one item are 100 s here,
    the pool pays; 1 cell left is 0.25 s here (0.125 s saved): it does not."""
    handed = _record_pool(monkeypatch)
    items = [(0.25,), (0.25,)]
    list(parallel.run_chunks(clock.work, items, 2, "loky", None, sizes=[1, 400]))
    assert len(handed) == 1
    handed.clear()
    list(parallel.run_chunks(clock.work, items, 2, "loky", None, sizes=[1, 1]))
    assert handed == []


def test_jobs_1_never_starts_a_pool(monkeypatch, clock):
    handed = _record_pool(monkeypatch)
    monkeypatch.setattr(parallel, "POOL_COST_S", 0.0)
    list(parallel.run_chunks(clock.work, [(1.0,)] * 5, 1, "loky", None))
    assert handed == [] and clock.now == 5.0


# ------------------------------------------------------------------- sweeps


def test_a_cheap_sweep_with_two_jobs_starts_no_pool(tmp_path, monkeypatch):
    def no_pool(*args, **kwargs):
        raise AssertionError("a pool was started for a cheap sweep")

    monkeypatch.setattr(parallel, "_loky", no_pool)
    cfg = rigid()
    two = run_sweep(cfg, tmp_path / "two", jobs=2)
    one = run_sweep(cfg, tmp_path / "one", jobs=1)
    assert (two.folder / "domain.csv").read_bytes() == (one.folder / "domain.csv").read_bytes()
    assert two.workers == 0 and one.workers == 0  # both ran here, whatever --jobs said


def test_the_summary_line_says_where_the_cells_ran(tmp_path):
    from click.testing import CliRunner

    from rbm_cli.cli.main import cli

    path = tmp_path / "cheap.yaml"
    path.write_text((CONFIGS / "spanos_koh_slender.yaml").read_text())
    res = CliRunner().invoke(cli, ["sweep", str(path), "-o", str(tmp_path / "o"), "-j", "2"])
    assert res.exit_code == 0, res.output
    assert " in this process" in res.output and "worker" not in res.output


def test_rows_are_the_same_here_and_on_the_pool(tmp_path, monkeypatch, workers):
    """A pool that always pays (cost 0, no probe): every chunk after the first piece
    runs on the workers; domain.csv is byte-identical to the sweep in this process, and the workers
    are stopped and reaped when the sweep returns."""
    cfg = rigid(amps=(0.2, 0.3, 0.5, 0.8, 1.2, 1.5), freqs=(0.5, 1.0, 2.0, 3.0))
    here = run_sweep(cfg, tmp_path / "here", jobs=1)
    monkeypatch.setattr(parallel, "POOL_COST_S", 0.0)
    monkeypatch.setattr(parallel, "PROBE_S", 0.0)
    monkeypatch.setattr(os, "cpu_count", lambda: 2)
    started = []
    real = parallel._loky

    def counted(fn, args, jobs, placed=None):
        started.append(len(args))
        yield from real(fn, args, jobs, placed)

    monkeypatch.setattr(parallel, "_loky", counted)
    pool = run_sweep(cfg, tmp_path / "pool", jobs=2)
    assert started and started[0] > 1  # the pool ran most of the chunks
    assert pool.workers == 2 and here.workers == 0
    assert (pool.folder / "domain.csv").read_bytes() == (here.folder / "domain.csv").read_bytes()
    assert workers and all(reaped(pid) for pid in workers)


def _worker_modules(cfg, workers: list[int]) -> set[str]:
    """The modules a loky worker holds after running two cells of cfg (above uplift)."""
    cells = grid_cells(cfg, grid_points(cfg))[-2:]
    code = (
        "(__import__('rbm_cli.study.sweep', fromlist=['run_chunk']).run_chunk(cfg, cells),"
        " sorted(__import__('sys').modules))[1]"
    )
    (modules,) = [m for m in parallel._loky(eval, [(code, {"cfg": cfg, "cells": cells})], 1) if m]
    assert workers and all(reaped(pid) for pid in workers)  # stopped and reaped
    return set(modules)


def test_a_worker_does_not_import_plotting(workers):
    modules = _worker_modules(rigid(), workers)
    assert "rbm_cli.models.block.closed_form" in modules  # the compiled path ran there
    assert "rbm_cli.models.rbm.step" not in modules  # a rigid block's: not the kernel
    assert not {m for m in modules if m.split(".")[0] == "matplotlib"}
    assert "rbm_cli.report.domain_figure" not in modules


def test_a_worker_imports_no_scipy_solver(workers):
    """The compiled path's tableaux are written out (base/rk_tableaux.py) and
    Brent's method is imported where the Python paths call it: a worker never imports
    scipy.integrate or scipy.optimize (numba itself imports scipy.linalg for its BLAS)."""
    modules = _worker_modules(rigid(), workers)
    assert not {"scipy.integrate", "scipy.optimize"} & modules


def test_a_worker_imports_only_what_the_compiled_path_needs(workers):
    modules = _worker_modules(rigid(), workers)
    assert not {"pandas", "scipy.integrate", "scipy.optimize"} & modules


def test_the_cli_imports_no_plotting_before_a_command_draws():
    code = "import sys, rbm_cli.cli.main, rbm_cli.api; print('matplotlib' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.stdout.strip() == "False", out.stderr


SMALL = """\
name: small
column: {height: 4.0, base_width: 1.0, drums: 1}
interface: {stiffness: rigid, xi: 1.0, restitution: 1.0}
excitation: {type: harmonic, duration: 10.0}
grid: {amplitudes: [0.2, 0.5, 1.2], frequencies: [0.5, 2.0]}
"""

#: `rbm sweep ARGS`: at exit its own process prints whether it imported pandas and ran
#: the sweep's module.
PARENT_MODULES = parent_modules("pandas", "rbm_cli.study.sweep")


@pytest.mark.parametrize(
    "extra",
    [[], pytest.param(["--ensemble", "2"], marks=pytest.mark.slow)],
    ids=["plain", "ensemble"],
)
def test_the_sweep_process_never_imports_pandas(tmp_path, extra):
    """`rbm sweep` writes domain.csv and boundary.csv from its rows and sends them to the
    figure's child, which builds the DataFrame: pandas is not imported in the
    sweep's own process, a ~0.15 s import."""
    config = tmp_path / "small.yaml"
    config.write_text(SMALL)
    args = [sys.executable, "-c", PARENT_MODULES, "sweep", str(config), "-o", str(tmp_path)]
    env = {k: v for k, v in os.environ.items() if k != "RBM_FIGURE_PROCESS"}
    out = subprocess.run([*args, "--quiet", *extra], capture_output=True, text=True, env=env)
    assert out.returncode == 0, out.stderr
    assert (tmp_path / "small" / "domain.png").is_file()  # the figure was drawn (the child)
    assert "MODULES False True" in out.stdout.splitlines(), out.stdout + out.stderr


# ------------------------------------------------------------------- Ctrl-C on a pool

COSTLY = """\
name: costly
column: {height: 5.0, base_width: 0.96, top_width: 0.66, drums: 8}
interface: {stiffness: {normal: 5e9}}
excitation: {type: harmonic, duration: 10.0}
grid:
  amplitudes: {start: 0.1, stop: 1.0, num: 20}
  frequencies: {start: 0.5, stop: 4.0, num: 20}
"""


def _group(pgid: int) -> list[str]:
    ps = subprocess.run(
        ["ps", "-ww", "-eo", "pgid=,pid=,stat=,args="], capture_output=True, text=True
    )
    return [line for line in ps.stdout.splitlines() if line.split()[0] == str(pgid)]


def _rows(journal: Path) -> int:
    return journal.read_bytes().count(b'"amplitude_g"') if journal.is_file() else 0


@pytest.mark.timeout(300)
@pytest.mark.parametrize(
    "rows",
    [0, pytest.param(40, marks=pytest.mark.slow)],
    ids=["workers-starting", "workers-at-work"],
)
def test_ctrl_c_on_a_pool_keeps_the_cells_and_leaves_no_process(tmp_path, rows):
    """400 cells of an 8-drum elastic column (~10 s of work at the least) go to a pool; a
    Ctrl-C to the whole group (a terminal's), as soon as the workers exist (still
    importing: they must not print tracebacks) or once `rows` cells are done, ends the
    sweep in one line, exit 130, and no process of the group outlives it."""
    from rbm_cli.models.rbm.step import warm_up

    warm_up()  # the subprocess loads the kernel, it does not compile it
    path = tmp_path / "costly.yaml"
    path.write_text(COSTLY)
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "rbm_cli", "sweep", str(path), "-o", str(out), "-j", "2"]
    proc = subprocess.Popen(
        cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True
    )
    journal = out / "costly" / JOURNAL
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline:
        workers = [line for line in _group(proc.pid) if "popen_loky" in line]
        if workers and _rows(journal) >= rows:
            break
        assert proc.poll() is None, proc.communicate()[1]
        time.sleep(0.02)
    else:
        pytest.fail("no pool at work in time")
    os.killpg(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert "Traceback" not in err and "leaked" not in err, err
    (line,) = [x for x in err.splitlines() if x.startswith("Error:")]
    assert f"interrupted: {_rows(journal)} of 400 cells are kept" in line
    deadline = time.monotonic() + 5
    while _group(proc.pid) and time.monotonic() < deadline:
        time.sleep(0.1)  # (its resource trackers end when they see it gone)
    assert _group(proc.pid) == []


def _sigint_off(pid: int) -> bool:
    """SIGINT blocked or ignored in every thread of process pid (Linux's /proc)."""
    bit = 1 << (signal.SIGINT - 1)
    for task in Path(f"/proc/{pid}/task").iterdir():
        try:
            status = (task / "status").read_text()
        except FileNotFoundError:  # a thread that has just ended
            continue
        fields = dict(line.split(":\t", 1) for line in status.splitlines() if ":\t" in line)
        if not (int(fields["SigBlk"], 16) | int(fields["SigIgn"], 16)) & bit:
            return False
    return True


@pytest.mark.skipif(not Path("/proc/self/task").is_dir(), reason="reads /proc")
@pytest.mark.filterwarnings("error::pytest.PytestUnhandledThreadExceptionWarning")
@pytest.mark.parametrize("launch", [1, 2])
def test_ctrl_c_while_loky_starts_a_worker_is_raised_here(monkeypatch, launch):
    """A Ctrl-C that lands right after loky launched worker `launch` of 2 (the start
    runs in a thread of its own): KeyboardInterrupt in this thread, both workers started
    with SIGINT held (they never see it), stopped and reaped; this thread's handler and
    mask as they were, and the next Ctrl-C raises too (nothing left noted or held); no
    thread of the pool dies on the way (loky's KeyError on chunks not yet dispatched)."""
    from joblib.externals.loky.backend import popen_loky_posix

    real = popen_loky_posix.Popen._launch
    launched: list[int] = []

    def launch_then_ctrl_c(self, process_obj):
        real(self, process_obj)
        launched.append(self.pid)
        if len(launched) == launch:
            os.kill(os.getpid(), signal.SIGINT)  # to the process, as a terminal's
        if len(launched) == 2:
            held.extend(_sigint_off(pid) for pid in launched)

    held: list[bool] = []
    stopped: list[int] = []
    real_stop = parallel._stop

    def stop(executor):
        stopped.extend(executor._processes)
        real_stop(executor)

    monkeypatch.setattr(popen_loky_posix.Popen, "_launch", launch_then_ctrl_c)
    monkeypatch.setattr(parallel, "_stop", stop)
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, [])
    with pytest.raises(KeyboardInterrupt):
        list(parallel._loky(time.sleep, [(5.0,)] * 4, 2))
    assert sorted(stopped) == sorted(launched) and len(launched) == 2
    assert held == [True, True]
    assert all(reaped(pid) for pid in launched)
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    assert signal.pthread_sigmask(signal.SIG_BLOCK, []) == mask
    with pytest.raises(KeyboardInterrupt):
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(1)
