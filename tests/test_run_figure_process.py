"""`rbm run`'s figures drawn by a child forked as the command starts
(rbm_cli.report.figure_process): the run's own process imports neither matplotlib nor
pandas, the run folder is the same byte for byte as drawn here (history.csv written without
pandas is pandas' file), a dead child is replaced by drawing here, and no child outlives
its run (killed by kill -9, or Ctrl-C to the terminal's process group).

The tests that fork the child in the test's own process (which FigureProcess refuses while
other threads run) run in a fresh interpreter (tests/conftest.py), where they must fork."""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from rbm_cli.api import run as run_cell
from rbm_cli.base.files import write_csv_atomic
from rbm_cli.config.load import load_config
from rbm_cli.models.history import History
from rbm_cli.report.figure_process import RUN_IMPORTS, FigureProcess
from rbm_cli.report.run_folder import history_csv, history_frame, run_summary, write_run
from rbm_cli.structures.column import build_column

from .paths import CONFIGS
from .processes import LONG, parent_modules

pytestmark = [
    pytest.mark.timeout(240),
    pytest.mark.skipif(not hasattr(os, "fork"), reason="forks"),
]


def gone(pid: int) -> bool:
    """No process pid, or only its zombie (it has exited; its new parent reaps it)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except FileNotFoundError:
        return True
    return stat.rsplit(")", 1)[1].split()[0] == "Z"


def started() -> FigureProcess:
    proc = FigureProcess.start(RUN_IMPORTS)
    assert proc is not None, "no figure child was forked (threads running?)"
    return proc


@pytest.fixture(scope="module")
def two_drums():
    """A 2-drum elastic run (the joints' panel drawn too) with its summary and geometry."""
    cfg = load_config(CONFIGS / "ci" / "harmonic_multidrum_ci.yaml")
    result = run_cell(cfg, 0.3, 2.0).result
    summary = run_summary(
        result, cfg, config_path=None, amplitude_g=0.3, frequency_hz=2.0, output_dt=None
    )
    column = build_column(cfg.column, cfg.interface)
    geometry = {"widths": column.widths, "elevations": [*column.bottoms, column.height]}
    return result, summary, geometry


def _write(tmp_path, name, two_drums, figure_process=None) -> dict[str, bytes]:
    result, summary, geometry = two_drums
    folder = write_run(
        tmp_path / name, "c", "run", result, summary, **geometry, figure_process=figure_process
    )
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())}


FILES = ["history.csv", "history.png", "shapes.png", "summary.json"]


@pytest.mark.fresh_interpreter
def test_the_child_draws_the_same_run_folder(tmp_path, two_drums):
    here = _write(tmp_path, "here", two_drums)
    proc = started()
    pid = proc.pid
    child = _write(tmp_path, "child", two_drums, proc)
    assert proc.pid is None and gone(pid)  # reaped once it had sent the figures
    assert sorted(child) == FILES and child == here


@pytest.mark.fresh_interpreter
def test_a_dead_child_is_replaced_by_drawing_here(tmp_path, two_drums):
    here = _write(tmp_path, "here", two_drums)
    proc = started()
    os.kill(proc.pid, signal.SIGKILL)
    assert _write(tmp_path, "child", two_drums, proc) == here
    assert proc.pid is None


@pytest.mark.fresh_interpreter
def test_the_child_runs_a_call_and_raises_its_error_here():
    """One protocol: a module-level function and its arguments, its value or its error."""
    with started() as proc:
        assert proc.call(math.hypot, 3.0, 4.0) == 5.0
    with started() as proc, pytest.raises(ValueError):
        proc.call(math.sqrt, -1.0)  # (ValueError: math domain error, raised in the child)
    assert proc.pid is None


def _whoami(tag: str) -> tuple[str, int, int]:
    return tag, os.getpid(), os.getppid()


def _fail(tag: str) -> None:
    raise KeyError(tag)


@pytest.mark.fresh_interpreter
def test_calls_side_by_side_run_in_the_child_and_its_grandchildren():
    """submit_all: the first call in the child, each other one in a grandchild of it (at
    the same time), values in order; every grandchild reaped by the child."""
    with started() as proc:
        child = proc.pid
        proc.submit_all([(_whoami, ("a",)), (_whoami, ("b",)), (_whoami, ("c",))])
        values = proc.result()
    assert [v[0] for v in values] == ["a", "b", "c"]
    assert values[0][1] == child  # the first: the child itself
    grandchildren = [pid for _, pid, _ in values[1:]]
    assert len(set(grandchildren)) == 2 and child not in grandchildren
    assert all(ppid == child for _, _, ppid in values[1:])
    assert gone(child) and all(gone(pid) for pid in grandchildren)


def _pid_then_sleep(path: str) -> None:
    Path(path).write_text(str(os.getpid()))
    time.sleep(60)


@pytest.mark.fresh_interpreter
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="PR_SET_PDEATHSIG")
def test_a_grandchild_dies_with_the_child(tmp_path):
    """The command kills the child while a grandchild draws (Ctrl-C): the grandchild, in a
    call of 60 s, is gone within seconds, not when its call ends."""
    path = tmp_path / "pid"
    proc = started()
    proc.submit_all([(time.sleep, (60.0,)), (_pid_then_sleep, (str(path),))])
    deadline = time.monotonic() + 30
    while not (path.is_file() and path.read_text()) and time.monotonic() < deadline:
        time.sleep(0.02)
    grandchild = int(path.read_text())
    assert not gone(grandchild)
    proc.close()
    deadline = time.monotonic() + 5
    while not gone(grandchild) and time.monotonic() < deadline:
        time.sleep(0.02)
    assert gone(grandchild)


@pytest.mark.fresh_interpreter
@pytest.mark.parametrize("where", [0, 1], ids=["child", "grandchild"])
def test_an_error_side_by_side_is_raised_here(where):
    calls = [(_whoami, ("a",)), (_whoami, ("b",))]
    calls[where] = (_fail, ("boom",))
    with started() as proc:
        proc.submit_all(calls)
        with pytest.raises(KeyError, match="boom"):
            proc.result()


def test_calls_side_by_side_without_a_child_run_here(monkeypatch):
    monkeypatch.setenv("RBM_FIGURE_PROCESS", "0")
    assert FigureProcess.start(RUN_IMPORTS) is None
    proc = FigureProcess(None, -1, -1)  # what a child that died leaves: pid None
    proc.submit_all([(_whoami, ("a",)), (_whoami, ("b",))])
    assert [v[:2] for v in proc.result()] == [("a", os.getpid()), ("b", os.getpid())]


@pytest.mark.fresh_interpreter
def test_the_child_ignores_sigint():
    with started() as proc:
        status = Path(f"/proc/{proc.pid}/status")
        deadline = time.monotonic() + 10
        bit = 1 << (signal.SIGINT - 1)
        while time.monotonic() < deadline:
            fields = dict(x.split(":\t", 1) for x in status.read_text().splitlines() if ":\t" in x)
            if int(fields["SigIgn"], 16) & bit:
                break
            time.sleep(0.01)
        assert int(fields["SigIgn"], 16) & bit


def test_history_csv_is_pandas_file_byte_for_byte(tmp_path):
    """history.csv without pandas against pandas' to_csv (base.files.write_csv_atomic) on
    values that format differently: NaN (empty), +-inf, -0.0, tiny, huge, 12 digits."""
    odd = [np.nan, np.inf, -np.inf, -0.0, 1e-300, 123456789012345.0, 0.1, -1.5e-7, 5e20, 1 / 3]
    n = len(odd)
    history = History(
        t=np.linspace(0.0, 1.0, n),
        ground_acceleration=np.array(odd),
        ground_displacement=-np.array(odd[::-1]),
        node_displacements=np.column_stack([np.zeros(n), np.array(odd), np.arange(n) * 0.7]),
        rotations=np.column_stack([np.array(odd[3:] + odd[:3]), -np.arange(n) / 7.0]),
    )
    write_csv_atomic(tmp_path / "pandas.csv", history_frame(history))
    for rows in (3, 4096):  # NaN rows and finite rows in the same chunk or not
        text = "".join(history_csv(history, rows_per_chunk=rows))
        assert text.encode() == (tmp_path / "pandas.csv").read_bytes()


#: `rbm ARGS`: at exit its own process prints whether it imported matplotlib and pandas.
PARENT_MODULES = parent_modules("matplotlib", "pandas")


@pytest.mark.parametrize(("switch", "drawn_here"), [(None, False), ("0", True)])
def test_the_run_process_imports_no_matplotlib_nor_pandas(tmp_path, switch, drawn_here):
    """The figures are drawn by the child: the run's process never imports matplotlib (nor
    pandas, history.csv is written without it); RBM_FIGURE_PROCESS=0 draws them here."""
    env = {k: v for k, v in os.environ.items() if k != "RBM_FIGURE_PROCESS"}
    if switch is not None:
        env["RBM_FIGURE_PROCESS"] = switch
    args = ["run", str(CONFIGS / "spanos_koh_slender.yaml"), "-a", "0.5", "-f", "1"]
    cmd = [sys.executable, "-c", PARENT_MODULES, *args, "-o", str(tmp_path)]
    out = subprocess.run(cmd, capture_output=True, text=True, env=env)
    assert out.returncode == 0, out.stderr
    folder = tmp_path / "spanos_koh_slender" / "run_A0.5_f1"
    assert sorted(p.name for p in folder.iterdir()) == FILES
    assert f"MODULES {drawn_here} False" in out.stdout.splitlines(), out.stdout + out.stderr


def _children(pid: int) -> list[int]:
    ps = subprocess.run(["ps", "-eo", "pid=,ppid="], capture_output=True, text=True)
    pairs = [line.split() for line in ps.stdout.splitlines()]
    return [int(p) for p, pp in pairs if int(pp) == pid]


@pytest.mark.timeout(180)
@pytest.mark.parametrize("how", ["kill-9", "ctrl-c"])
def test_no_child_outlives_its_run(tmp_path, how):
    """A run of minutes, its child forked: kill -9 of the run (its child sees the pipe
    close and exits), or Ctrl-C to the whole group (the child ignores it, the run kills
    it): the child is gone, and no run folder was written."""
    from rbm_cli.models.rbm.step import warm_up

    warm_up()  # the subprocess loads the kernel, it does not compile it
    path = tmp_path / "long.yaml"
    path.write_text(LONG)
    cmd = [sys.executable, "-m", "rbm_cli", "run", str(path), "-a", "0.05", "-f", "2",
           "-o", str(tmp_path)]  # fmt: skip
    env = {k: v for k, v in os.environ.items() if k != "RBM_FIGURE_PROCESS"}
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=env, start_new_session=True)  # fmt: skip
    deadline = time.monotonic() + 60
    while not (kids := _children(proc.pid)) and time.monotonic() < deadline:
        assert proc.poll() is None, proc.communicate()
        time.sleep(0.02)
    assert kids, "no figure child"
    time.sleep(3)  # the run is loading or inside the kernel
    assert proc.poll() is None, proc.communicate()
    if how == "kill-9":
        os.kill(proc.pid, signal.SIGKILL)
    else:
        os.killpg(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == (-signal.SIGKILL if how == "kill-9" else 130), err
    deadline = time.monotonic() + 10
    while not all(gone(pid) for pid in kids) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert all(gone(pid) for pid in kids)
    assert not (tmp_path / "long").exists() or not any((tmp_path / "long").iterdir())
