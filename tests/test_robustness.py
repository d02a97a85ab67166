"""A sweep that never loses work, never hangs, never gives a wrong answer quietly.

A test (or a few) per way a sweep can be interrupted or fed bad input, through the command
line (click's CliRunner, or a subprocess where a hang or a signal is the point), each bounded by a
timeout. Each would fail if its defect came back: the checks are on what the defect did
(files deleted, rows trusted, a loop that does not end, a traceback, an answer with no
word). Files only under tmp_path.
"""

from __future__ import annotations

import contextlib
import dataclasses
import http.server
import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
from click.testing import CliRunner

from rbm_cli.api import run_sweep
from rbm_cli.base.errors import RbmError
from rbm_cli.cli.main import cli
from rbm_cli.config.load import load_config
from rbm_cli.study.store import JOURNAL, STATE, SweepStore

from .processes import LONG

pytestmark = pytest.mark.timeout(120)

SMALL = """\
name: small
column: {height: 4.0, base_width: 1.0, depth: 1.0}
interface: {stiffness: rigid}
excitation: {type: harmonic, duration: 3.0}
grid:
  amplitudes: [0.2, 0.3, 0.5, 0.8, 1.2]
  frequencies: [0.5, 1.0, 2.0]
"""
FINALS = ("domain.csv", "boundary.csv", "domain.png", "meta.json")
N_CELLS = 15


def invoke(*args, **kwargs):
    return CliRunner().invoke(cli, [str(a) for a in args], **kwargs)


def rbm(*args, timeout: float = 60, **kwargs) -> subprocess.CompletedProcess:
    """`rbm ...` in a subprocess, bounded."""
    cmd = [sys.executable, "-m", "rbm_cli", *(str(a) for a in args)]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, **kwargs)


def one_line_error(res, *needles, code: int = 2) -> str:
    """The result is exit status `code` and a single line 'Error: ...' with the needles,
    no traceback."""
    output = res.output if hasattr(res, "output") else res.stdout + res.stderr
    lines = [line for line in output.splitlines() if line.strip()]
    status = res.exit_code if hasattr(res, "exit_code") else res.returncode
    assert status == code, output
    assert "Traceback" not in output, output
    errors = [line for line in lines if line.startswith("Error:")]
    assert len(errors) == 1, output
    for needle in needles:
        assert needle in errors[0], (needle, errors[0])
    return errors[0]


@pytest.fixture
def small(tmp_path) -> Path:
    path = tmp_path / "small.yaml"
    path.write_text(SMALL)
    return path


@pytest.fixture
def straight(tmp_path, small) -> bytes:
    """domain.csv of an uninterrupted sweep of SMALL."""
    return (
        run_sweep(load_config(small), tmp_path / "straight", jobs=1).folder / "domain.csv"
    ).read_bytes()


def partial(small, out: Path, chunks: int) -> Path:
    """A sweep of SMALL stopped after `chunks` one-cell chunks: its folder."""
    with pytest.raises(RbmError, match="stopped after"):
        run_sweep(load_config(small), out, jobs=1, stop_after=chunks)
    return out / "small"


def journal_rows(folder: Path) -> int:
    lines = (folder / JOURNAL).read_bytes().split(b"\n")
    return sum(1 for line in lines if b'"amplitude_g"' in line)


def snapshot(folder: Path) -> dict:
    return {p.name: (p.read_bytes(), p.stat().st_mtime_ns) for p in folder.iterdir() if p.is_file()}


# ----------------------------------------------------------------- finished work lost
def test_case01_resume_on_a_finished_folder_changes_nothing(small, tmp_path):
    """Defect: --resume on a finished folder deleted domain.csv, the PNG and meta.json,
    then ran every cell again."""
    res = invoke("sweep", small, "-o", tmp_path / "out", "--jobs", "1", "--quiet")
    assert res.exit_code == 0, res.output
    folder = tmp_path / "out" / "small"
    before = snapshot(folder)
    res = invoke("sweep", small, "-o", tmp_path / "out", "--jobs", "1", "--resume")
    assert res.exit_code == 0, res.output
    assert "already finished" in res.output and "nothing to resume" in res.output
    assert snapshot(folder) == before  # same bytes, not even rewritten


def test_case01_a_finished_domain_of_another_config_is_never_replaced_quietly(small, tmp_path):
    out = tmp_path / "out"
    assert invoke("sweep", small, "-o", out, "--jobs", "1", "--quiet").exit_code == 0
    before = (out / "small" / "domain.csv").read_bytes()
    other = tmp_path / "other.yaml"
    other.write_text(SMALL.replace("duration: 3.0", "duration: 2.0"))
    res = invoke("sweep", other, "-o", out, "--jobs", "1", "--quiet")
    one_line_error(res, "finished domain of another config", "--force")
    assert (out / "small" / "domain.csv").read_bytes() == before
    res = invoke("sweep", other, "-o", out, "--jobs", "1", "--quiet", "--force")
    assert res.exit_code == 0, res.output
    (kept,) = (out / "small" / "superseded").iterdir()  # set aside, not deleted
    assert (kept / "domain.csv").read_bytes() == before


def test_case01_a_domain_stored_under_the_earlier_hash_is_this_configs(small, tmp_path):
    """A finished domain whose meta.json is rbm 0.1's (schema 1: no schema written, the
    settings that came later left out at their defaults, the hash of that form) and holds
    this config's settings is recognised: --resume does nothing. With a setting that
    differs it is another config's."""
    from .test_fingerprint import schema1_digest

    out = tmp_path / "out"
    assert invoke("sweep", small, "-o", out, "--jobs", "1", "--quiet").exit_code == 0
    meta_path = out / "small" / "meta.json"
    meta = json.loads(meta_path.read_text())
    del meta["schema"], meta["config"]["dimensions"]
    for section, key in [("column", "capital"), ("column", "top_mass"),
                         ("interface", "friction_limit"), ("interface", "damping")]:  # fmt: skip
        del meta["config"][section][key]
    meta["config_hash"] = schema1_digest(meta["config"])
    meta_path.write_text(json.dumps(meta))
    res = invoke("sweep", small, "-o", out, "--jobs", "1", "--resume")
    assert res.exit_code == 0 and "already finished" in res.output, res.output
    meta["config"]["excitation"]["duration"] = 5.0  # a setting that differs: another config
    meta["config_hash"] = schema1_digest(meta["config"])
    meta_path.write_text(json.dumps(meta))
    one_line_error(invoke("sweep", small, "-o", out, "--resume"), "another config")


@pytest.mark.parametrize("damage", ["missing", "garbled", "empty"])
def test_case02_a_lost_state_file_is_recovered_from_the_journal(small, tmp_path, straight, damage):
    """Defect: a corrupt or missing domain.partial.json made --resume print '0 resumed'
    and wipe the journal."""
    folder = partial(small, tmp_path / "out", 6)
    state = folder / STATE
    {"missing": state.unlink, "garbled": lambda: state.write_bytes(b"\x00{not json"),
     "empty": lambda: state.write_text("")}[damage]()  # fmt: skip
    res = invoke("sweep", small, "-o", tmp_path / "out", "--jobs", "1", "--resume")
    assert res.exit_code == 0, res.output
    assert f"({N_CELLS - 6} run, 6 resumed)" in res.output
    assert "recovered from the journal" in res.output
    assert (folder / "domain.csv").read_bytes() == straight


def test_case03_a_rerun_without_resume_keeps_the_journal(small, tmp_path, straight):
    """Defect: re-running without --resume emptied a journal of finished cells."""
    folder = partial(small, tmp_path / "out", 7)
    journal = (folder / JOURNAL).read_bytes()
    res = invoke("sweep", small, "-o", tmp_path / "out", "--jobs", "1", "--quiet")
    one_line_error(res, "unfinished sweep of this config (7 finished cells)", "--resume")
    assert (folder / JOURNAL).read_bytes() == journal
    assert not (folder / "domain.csv").exists()
    # --force starts again, but sets the journal aside instead of deleting it
    res = invoke("sweep", small, "-o", tmp_path / "out", "--jobs", "1", "--force")
    assert res.exit_code == 0, res.output
    assert "moved to" in res.output
    (kept,) = (folder / "superseded").iterdir()
    assert (kept / JOURNAL).read_bytes() == journal
    assert (folder / "domain.csv").read_bytes() == straight


def test_case04_one_sweep_writes_a_folder(small, tmp_path):
    """Defect: nothing locked the folder; two sweeps shared (and mixed) one journal."""
    out = tmp_path / "out"
    with SweepStore(out / "small"):
        res = invoke("sweep", small, "-o", out, "--jobs", "1", "--quiet")
        one_line_error(res, "is being written by another sweep", f"pid {os.getpid()}")
    # the lock is released with its holder: the same sweep now runs
    res = invoke("sweep", small, "-o", out, "--jobs", "1", "--quiet")
    assert res.exit_code == 0, res.output


def test_case04_another_config_of_the_same_name_does_not_mix_rows(small, tmp_path):
    """Defect: a resume after a kill mixed the rows of two configs with one name."""
    folder = partial(small, tmp_path / "out", 5)
    journal = (folder / JOURNAL).read_bytes()
    other = tmp_path / "other.yaml"
    other.write_text(SMALL.replace("duration: 3.0", "duration: 2.0"))
    res = invoke("sweep", other, "-o", tmp_path / "out", "--jobs", "1", "--quiet", "--resume")
    one_line_error(res, "made with a different config")
    res = invoke("sweep", other, "-o", tmp_path / "out", "--jobs", "1", "--quiet")
    one_line_error(res, "unfinished sweep of another config")
    assert (folder / JOURNAL).read_bytes() == journal


def test_case04_rows_of_another_config_in_one_journal_are_not_trusted(small, tmp_path, straight):
    folder = partial(small, tmp_path / "out", 5)
    row = json.loads((folder / JOURNAL).read_text().splitlines()[1])
    row.update(config_hash="0123456789abcdef", status="survived", collapsed=0)
    with (folder / JOURNAL).open("a") as fh:
        fh.write(json.dumps(row) + "\n")
    res = invoke("sweep", small, "-o", tmp_path / "out", "--jobs", "1", "--resume")
    assert res.exit_code == 0 and "made by another config" in res.output, res.output
    assert (folder / "domain.csv").read_bytes() == straight


BAD_LINES = {
    "hand-made row": b'{"amplitude_g": 0.5, "frequency_hz": 1.0, "status": "survived"}',
    "status pwned": None,  # made from a real row below
    "amplitude abc": None,
    "collapsed disagrees": None,
    "cell not in the grid": None,
    "not UTF-8": b"\xff\xfe\x00garbage",
    "not JSON": b"{amplitude_g: 1",
}


def _bad_line(kind: str, real: dict) -> bytes:
    if BAD_LINES[kind] is not None:
        return BAD_LINES[kind]
    row = dict(real)
    if kind == "status pwned":
        row["status"] = "pwned"
    elif kind == "amplitude abc":
        row["amplitude_g"] = "abc"
    elif kind == "collapsed disagrees":
        row["collapsed"] = 1 - row["collapsed"]
    else:
        row["frequency_hz"] = 4.0
    return json.dumps(row).encode()


@pytest.mark.parametrize("kind", sorted(BAD_LINES))
def test_case05_journal_rows_are_validated(small, tmp_path, straight, kind):
    """Defect: journal rows were not validated: a hand-made row went into domain.csv,
    'pwned' made the domain unreadable, a non-UTF-8 line or 'abc' ended in a traceback.
    A bad line replaces a real one, whose cell must be run again."""
    folder = partial(small, tmp_path / "out", 6)
    lines = (folder / JOURNAL).read_bytes().split(b"\n")
    lines[3] = _bad_line(kind, json.loads(lines[3]))  # row 3 of 6, not the last one
    (folder / JOURNAL).write_bytes(b"\n".join(lines))
    res = invoke("sweep", small, "-o", tmp_path / "out", "--jobs", "1", "--resume")
    assert res.exit_code == 0, res.output
    assert "Traceback" not in res.output
    assert "not trusted" in res.output and "line 4" in res.output
    assert f"({N_CELLS - 5} run, 5 resumed)" in res.output
    assert (folder / "domain.csv").read_bytes() == straight
    assert invoke("plot-domain", folder / "domain.csv", "-o", tmp_path / "d.png").exit_code == 0


def _no_result(folder: Path) -> None:
    for name in FINALS:
        assert not (folder / name).exists(), name
    assert not list(folder.glob(".publish.*"))


def test_case06_a_plot_failure_publishes_nothing(small, tmp_path, straight, monkeypatch):
    """Defect: domain.csv, boundary.csv and meta.json were written before the PNG: a plot
    failure left files that looked finished."""
    import rbm_cli.api.sweeps

    def broken(*args, **kwargs):
        raise ValueError("the figure cannot be drawn")

    monkeypatch.setattr(rbm_cli.api.sweeps, "domain_figure", broken)
    res = invoke("sweep", small, "-o", tmp_path / "out", "--jobs", "1", "--quiet")
    one_line_error(res, "cannot draw domain.png", "--resume")
    folder = tmp_path / "out" / "small"
    _no_result(folder)
    assert journal_rows(folder) == N_CELLS  # every finished cell kept
    monkeypatch.undo()
    res = invoke("sweep", small, "-o", tmp_path / "out", "--jobs", "1", "--resume")
    assert res.exit_code == 0 and f"(0 run, {N_CELLS} resumed)" in res.output, res.output
    assert (folder / "domain.csv").read_bytes() == straight


def test_case06_ctrl_c_while_drawing_publishes_nothing(small, tmp_path, monkeypatch):
    import rbm_cli.api.sweeps

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(rbm_cli.api.sweeps, "domain_figure", interrupted)
    res = invoke("sweep", small, "-o", tmp_path / "out", "--jobs", "1", "--quiet")
    one_line_error(res, f"{N_CELLS} of {N_CELLS} cells are kept", "--resume", code=130)
    _no_result(tmp_path / "out" / "small")


def test_case06_a_full_disk_publishes_nothing(small, tmp_path, straight):
    """Defect: a full disk (ENOSPC) ended in a traceback and left files that looked
    finished. The sweep runs with a file-size limit below the PNG's size (RLIMIT_FSIZE:
    writes beyond it fail with EFBIG, as a full disk fails them with ENOSPC; the
    fault-injection suite fills a real tmpfs where it can mount one)."""
    import resource

    def limit():
        resource.setrlimit(resource.RLIMIT_FSIZE, (40_000, 40_000))

    out = tmp_path / "out"
    res = rbm("sweep", small, "-o", out, "--jobs", "1", "--quiet", preexec_fn=limit)
    one_line_error(res, "cannot write the result", "File too large", "--resume")
    folder = out / "small"
    _no_result(folder)
    assert journal_rows(folder) == N_CELLS
    res = rbm("sweep", small, "-o", out, "--jobs", "1", "--quiet", "--resume")
    assert res.returncode == 0, res.stderr
    assert (folder / "domain.csv").read_bytes() == straight


# ----------------------------------------------------------------- hangs
NAN_KERNEL = """
import numpy as np
from rbm_cli.structures.column import build_column
from rbm_cli.config.types import ColumnConfig, InterfaceConfig, SolverConfig
from rbm_cli.inputs.excitation import GroundMotion
from rbm_cli.models.rbm.step import integrate
from rbm_cli.structures.equations import build_model
with np.errstate(all="ignore"):
    geometry = ColumnConfig(height=4.0, base_width=1.0, top_width=1.0, depth=1.0,
                            density=1e308, drum_heights=(4.0,))
    model = build_model(build_column(geometry, InterfaceConfig()))
    motion = GroundMotion("harmonic", 0.5 * 9.81, 2 * np.pi, 0.0, 10.0, 10.0)
    out = integrate(model, motion, np.zeros(1), np.zeros(1), SolverConfig())
print(out.status, out.message)
"""


def test_case07_a_nan_in_the_kernel_ends_the_run():
    """Defect: a NaN inside the compiled kernel looped forever (the step-rejection loop
    ended only when the step fell below its minimum, never true for NaN). The model is
    built past validation (density 1e308: infinite masses)."""
    res = subprocess.run(
        [sys.executable, "-c", NAN_KERNEL], capture_output=True, text=True, timeout=100
    )
    assert res.returncode == 0, res.stderr
    assert res.stdout.startswith("failed"), res.stdout


def test_case07_density_1e308_is_refused_in_one_line(tmp_path):
    path = tmp_path / "dense.yaml"
    path.write_text(SMALL.replace("depth: 1.0}", "depth: 1.0, density: 1e308}"))
    res = invoke("run", path, "-a", 0.5, "-f", 1, "-o", tmp_path)
    one_line_error(res, "column.density must be in [1, 100000]")


@pytest.fixture(scope="module")
def compiled():
    """The kernel compiled (or loaded) once, so a subprocess only loads it."""
    from rbm_cli.models.rbm.step import warm_up

    warm_up()


def _cpu_s(pid: int) -> float:
    """CPU time [s] a live process has used (user + system, all its threads)."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def _wait_cpu(proc: subprocess.Popen, seconds: float, limit: float = 150) -> None:
    """Until the process has used `seconds` of CPU: a point of its work that no load of
    the machine moves (a wall-clock sleep lands in its imports on a loaded machine)."""
    deadline = time.monotonic() + limit
    while _cpu_s(proc.pid) < seconds:
        if proc.poll() is not None:
            pytest.fail(f"the process ended at {seconds} s of CPU: " + proc.communicate()[1])
        if time.monotonic() > deadline:
            pytest.fail(f"{seconds} s of CPU not used in {limit} s")
        time.sleep(0.005)


def _cpu_of(cmd: list[str], **kwargs) -> float:
    """CPU time [s] of a command run to its end (with the children it waited for)."""
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, **kwargs)
    _, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    assert proc.returncode == 0, cmd
    return usage.ru_utime + usage.ru_stime


@pytest.fixture(scope="module")
def cpu_to_kernel(compiled, tmp_path_factory) -> float:
    """CPU time [s] of a whole `rbm run` of LONG's column for 0.5 s (start, imports, the
    compiled kernel loaded, the run, its folder written): by that much CPU, a run of LONG
    is inside its kernel."""
    folder = tmp_path_factory.mktemp("short")
    path = folder / "short.yaml"
    path.write_text(LONG.replace("duration: 10000", "duration: 0.5"))
    return _cpu_of([sys.executable, "-m", "rbm_cli", "run", str(path), "-a", "0.05", "-f", "2",
                    "-o", str(folder)])  # fmt: skip


@pytest.fixture(scope="module")
def cpu_to_main() -> float:
    """CPU time [s] of a Python that imports rbm_cli.cli.main and ends: the `rbm` command
    has installed its SIGINT handler well before twice that (main's first statement)."""
    return _cpu_of([sys.executable, "-c", "import rbm_cli.cli.main"])


def _ctrl_c(proc: subprocess.Popen, again_after: float | None = 0.1) -> None:
    """Ctrl-C as a terminal sends it, to the process's group; again after `again_after` s."""
    os.killpg(proc.pid, signal.SIGINT)
    if again_after is not None:
        time.sleep(again_after)
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGINT)


def _one_interrupted_line(err: str) -> str:
    """stderr holds one line 'Error: interrupted ...', no traceback, no 'Exception
    ignored' of a finalizer; that line."""
    assert "Traceback" not in err and "Exception ignored" not in err, err
    (line,) = [x for x in err.splitlines() if x.startswith("Error:")]
    assert line.startswith("Error: interrupted"), err
    return line


@pytest.mark.timeout(300)
def test_case07_ctrl_c_stops_a_long_compiled_run(tmp_path, cpu_to_kernel):
    """Defect: Ctrl-C could not stop the compiled kernel (a run of minutes or hours). The
    signal comes once the run has used a second of CPU more than a whole short run (inside
    the kernel, whatever the load), twice: the second must not cut the stop short."""
    path = tmp_path / "long.yaml"
    path.write_text(LONG)
    cmd = [sys.executable, "-m", "rbm_cli", "run", str(path), "-a", "0.05", "-f", "2",
           "-o", str(tmp_path)]  # fmt: skip
    proc = subprocess.Popen(
        cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True
    )
    _wait_cpu(proc, cpu_to_kernel + 1.0)
    sent = time.monotonic()
    _ctrl_c(proc)
    out, err = proc.communicate(timeout=60)
    assert time.monotonic() - sent < 20
    assert proc.returncode == 130, err
    assert _one_interrupted_line(err) == "Error: interrupted (Ctrl-C): no run folder was written"
    assert not (tmp_path / "long").exists() or not any((tmp_path / "long").iterdir())


@pytest.mark.slow
@pytest.mark.timeout(600)
def test_case07_ctrl_c_at_any_instant_exits_130_in_one_line(tmp_path, cpu_to_main, cpu_to_kernel):
    """Defect: a Ctrl-C during the imports (seconds on a loaded machine) ended in a
    KeyboardInterrupt traceback, and one that landed in code numba or dataclasses build by
    exec ended `python -m rbm_cli run` by SIGINT (-2), not 130. Twice to the group, at
    instants of the run's CPU time from just after main() starts to inside the kernel."""
    path = tmp_path / "long.yaml"
    path.write_text(LONG)
    cmd = [sys.executable, "-m", "rbm_cli", "run", str(path), "-a", "0.05", "-f", "2",
           "-o", str(tmp_path)]  # fmt: skip
    first, last = 2 * cpu_to_main, cpu_to_kernel + 0.5
    instants = [first * (last / first) ** (k / 9) for k in range(10)]
    for at in instants:
        proc = subprocess.Popen(
            cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True
        )
        _wait_cpu(proc, at)
        _ctrl_c(proc, again_after=0.02)
        _, err = proc.communicate(timeout=60)
        assert proc.returncode == 130, (at, err)
        _one_interrupted_line(err)


#: `python -m rbm_harness MODE`: the rbm command with commands that hold a Ctrl-C where a
#: real command meets it by chance (each prints READY where the signal is to come).
HARNESS = """\
import sys
import time


def ready():
    print("READY", flush=True)


mode = sys.argv[1]
if mode == "imports":  # the first command module's import is held
    class HoldImport:
        def find_spec(self, name, path=None, target=None):
            if name == "rbm_cli.cli.bench":
                ready()
                time.sleep(30)
            return None

    sys.meta_path.insert(0, HoldImport())
    from rbm_cli.cli.main import main

    main(["--version"])

from rbm_cli.cli.common import Interrupted
from rbm_cli.cli.main import cli as group
from rbm_cli.cli.main import main


@group.command()
def generated():  # code built by exec, as numba's and dataclasses' is
    exec("ready()\\nwhile True: time.sleep(0.01)", {"ready": ready, "time": time})


@group.command()
def cleanup():  # a stop that takes a while, as a sweep's stops its workers
    try:
        ready()
        while True:
            time.sleep(0.01)
    except KeyboardInterrupt:
        print("STOPPING", flush=True)
        time.sleep(1.0)
        raise Interrupted("interrupted: 3 of 9 cells are kept; resume with: rbm x") from None


class Half:
    def __init__(self):
        ready()
        time.sleep(30)
        self.handle = 1

    def __del__(self):
        self.handle  # half-built: AttributeError


@group.command()
def half():  # a constructor interrupted: its finalizer fails once the object is freed
    try:
        Half()
    except KeyboardInterrupt as stop:
        stop.__traceback__ = None  # (which held the object)
        raise


class Named:
    def __set_name__(self, owner, name):
        ready()
        time.sleep(30)


@group.command()
def named():  # the Ctrl-C lands in a class's __set_name__, as a dataclass's fields are built
    class Built:
        field = Named()


class Slow:
    def __del__(self):
        ready()
        time.sleep(1.0)


@group.command()
def swallowed():  # the Ctrl-C lands in a finalizer, which swallows it
    Slow()
    for _ in range(300):
        time.sleep(0.01)
    print("NOT STOPPED", flush=True)


main([mode])
"""


@pytest.mark.parametrize(
    "mode, line",
    [
        ("imports", "Error: interrupted (Ctrl-C)"),
        ("generated", "Error: interrupted (Ctrl-C)"),
        ("cleanup", "Error: interrupted: 3 of 9 cells are kept; resume with: rbm x"),
        ("half", "Error: interrupted (Ctrl-C)"),
        ("named", "Error: interrupted (Ctrl-C)"),
        ("swallowed", "Error: interrupted (Ctrl-C)"),
    ],
)
def test_case07_ctrl_c_where_a_command_meets_it_by_chance(tmp_path, mode, line):
    """Defects, each where a real command met a Ctrl-C by chance under load: in the
    imports, a KeyboardInterrupt traceback (and SIGINT's -2); in code built by exec,
    `python -m` ended by SIGINT (-2) after saying its line; a second Ctrl-C during the
    stop replaced the line that says what is kept by a bare 'interrupted'; the finalizer of
    an object the Ctrl-C left half-built printed a traceback; a Ctrl-C inside a class's
    __set_name__ (a dataclass built during the imports) ended in a RuntimeError traceback,
    exit 1; a Ctrl-C that a finalizer swallowed let the command go on. Each: exit 130 and
    the one line."""
    (tmp_path / "rbm_harness").mkdir()
    (tmp_path / "rbm_harness" / "__main__.py").write_text(HARNESS)
    proc = subprocess.Popen(
        [sys.executable, "-m", "rbm_harness", mode],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert proc.stdout.readline() == "READY\n", proc.communicate()
    proc.send_signal(signal.SIGINT)
    if mode == "cleanup":
        assert proc.stdout.readline() == "STOPPING\n", proc.communicate()
        proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, (proc.returncode, out, err)
    assert _one_interrupted_line(err) == line
    assert "NOT STOPPED" not in out


def test_case07_the_wall_clock_budget_ends_a_long_run(tmp_path, compiled):
    path = tmp_path / "long.yaml"
    path.write_text(LONG.replace("max_events: 1e9}", "max_events: 1e9, max_wall_time: 1}"))
    start = time.monotonic()
    res = invoke("run", path, "-a", 0.05, "-f", 2, "-o", tmp_path)
    assert time.monotonic() - start < 30
    assert res.exit_code == 1, res.output
    assert "wall-clock budget exceeded (1 s, solver.max_wall_time)" in res.output


def _merge_bomb(levels: int) -> str:
    lines = ["name: bomb", "column: {height: 4, base_width: 1}", "x0: &x0 {a: 1, b: 2}"]
    for i in range(1, levels):
        lines.append(f"x{i}: &x{i} {{<<: [*x{i - 1}], c{i}: {{<<: *x{i - 1}}}}}")
    return "\n".join(lines) + "\n"


def _alias_bomb(levels: int) -> str:
    lines = ["name: bomb", "column: {height: 4, base_width: 1}", "l0: &l0 [lol, lol]"]
    lines += [f"l{i}: &l{i} [*l{i - 1}, *l{i - 1}, *l{i - 1}]" for i in range(1, levels)]
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize(
    "text",
    [_merge_bomb(26), _merge_bomb(40), _alias_bomb(30)],
    ids=["merge26", "merge40", "alias30"],
)
def test_case08_yaml_bombs_are_refused_fast(tmp_path, text):
    """Defect: a merge-key bomb hung the parser (26 levels, ~1 kB: 74 s; 40: no end)."""
    path = tmp_path / "bomb.yaml"
    path.write_text(text)
    start = time.monotonic()
    res = rbm("info", path, timeout=60)
    assert time.monotonic() - start < 20
    one_line_error(res, "aliases and merge keys", "expand")


def test_case08_a_few_aliases_are_fine(tmp_path):
    path = tmp_path / "alias.yaml"
    path.write_text(
        "name: a\ncolumn: {height: 4, base_width: &w 1, depth: *w}\n"
        "grid: {amplitudes: &g [0.1, 0.2], frequencies: *g}\n"
    )
    assert invoke("info", path).exit_code == 0


class _Http(http.server.BaseHTTPRequestHandler):
    def do_GET(self):  # pragma: no cover - Dask never sends a request line
        self.send_response(200)
        self.end_headers()

    def log_message(self, *args):
        pass


def test_case09_a_scheduler_that_is_not_dask_is_refused_in_bounded_time(
    small, tmp_path, monkeypatch
):
    """Defect: --scheduler tcp://host:<an HTTP port> blocked forever (the 10 s timeout
    covered only the connection)."""
    pytest.importorskip("dask.distributed")
    import rbm_cli.study.parallel

    monkeypatch.setattr(rbm_cli.study.parallel, "DASK_PROBE_TIMEOUT_S", 2.0)
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), _Http)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    try:
        address = f"tcp://127.0.0.1:{server.server_address[1]}"
        start = time.monotonic()
        res = invoke("sweep", small, "-o", tmp_path / "out", "--backend", "dask",
                     "--scheduler", address, "--quiet")  # fmt: skip
        assert time.monotonic() - start < 30
    finally:
        server.shutdown()
        server.server_close()
    one_line_error(res, "cannot reach the Dask scheduler", "no Dask handshake")
    assert not (tmp_path / "out").exists()


# ----------------------------------------------------------------- wrong answers
@pytest.mark.parametrize("density", ["1e307", "3e306", "1e-30"])
def test_case10_density_outside_the_sound_range_is_refused(tmp_path, density):
    """Defect: density 1e307 reported 'survived' (exit 0) where the column collapses
    at 4.28 s; 3e306 ended in ZeroDivisionError."""
    path = tmp_path / "c.yaml"
    path.write_text(SMALL.replace("depth: 1.0}", f"depth: 1.0, density: {density}}}"))
    for command in (
        ["run", path, "-a", 0.5, "-f", 1, "-o", tmp_path],
        ["sweep", path, "-o", tmp_path],
    ):
        one_line_error(invoke(*command), "column.density must be in [1, 100000]")


def test_case10_the_same_column_at_a_stone_density_collapses(tmp_path):
    path = tmp_path / "c.yaml"
    path.write_text(SMALL.replace("duration: 3.0", "duration: 10.0"))
    res = invoke("run", path, "-a", 0.5, "-f", 1, "-o", tmp_path)
    assert res.exit_code == 0 and "collapsed" in res.output and "4.28" in res.output


def test_case10_every_derived_quantity_is_checked_before_a_run():
    """A column whose masses overflow is refused by model_from_config, not run."""
    from rbm_cli.config.load import parse_config
    from rbm_cli.study.simulate import model_from_config

    cfg = parse_config({"name": "c", "column": {"height": 4.0, "base_width": 1.0}})
    huge = dataclasses.replace(cfg, column=dataclasses.replace(cfg.column, density=1e308))
    with pytest.raises(RbmError, match="not finite"):
        model_from_config(huge)


def _domain(tmp_path, name: str, freqs=(0.5, 1.0, 2.0), edit=None) -> Path:
    rows = ["amplitude_g,frequency_hz,status,collapsed"]
    for f in freqs:
        for a, c in ((0.2, 0), (0.4, 1)):
            rows.append(f"{a},{f},{'collapsed' if c else 'survived'},{c}")
    if edit:
        rows = edit(rows)
    path = tmp_path / f"{name}.csv"
    path.write_text("\n".join(rows) + "\n")
    return path


def test_case11_compare_refuses_an_incomplete_domain(tmp_path):
    """Defect: B holding 3 of 16 frequencies passed ('OK')."""
    a = _domain(tmp_path, "a", freqs=(0.5, 1.0, 1.5, 2.0))
    b = _domain(tmp_path, "b", freqs=(0.5,))
    res = invoke("compare", a, b, "--max-cells", 0.5, "--max-shift", 1)
    one_line_error(res, "do not cover the same cells", "6 only in")
    assert "OK" not in res.output


def test_case11_compare_refuses_status_and_collapsed_that_disagree(tmp_path):
    """Defect: compare counted differing cells from collapsed but drew the boundary from
    status (197/240 cells 'differed' with a 0 g boundary shift)."""
    a = _domain(tmp_path, "a")
    b = _domain(
        tmp_path, "b", edit=lambda rows: [r.replace("survived,0", "survived,1") for r in rows]
    )
    one_line_error(invoke("compare", a, b), "line 2", "status 'survived' but collapsed 1")


@pytest.mark.parametrize("value", ["yes", "2", "0.5", ""])
def test_case11_a_bad_collapsed_column_is_one_line(tmp_path, value):
    a = _domain(tmp_path, "a")
    b = _domain(
        tmp_path,
        "b",
        edit=lambda rows: [rows[0], rows[1].rsplit(",", 1)[0] + f",{value}", *rows[2:]],
    )
    one_line_error(invoke("compare", a, b), "line 2: collapsed must be 0 or 1")


def test_case12_a_bare_stiffness_is_refused_naming_both_forms(tmp_path):
    """Defect: stiffness 5e9 was taken as K_M [N m/rad]; meant as k_n [Pa/m] it is a
    column 20x stiffer, with no word."""
    path = tmp_path / "c.yaml"
    path.write_text(SMALL.replace("stiffness: rigid", "stiffness: 5e9"))
    one_line_error(invoke("info", path), "{rotational: K_M} [N m/rad]", "{normal: k_n} [Pa/m]")


def test_case12_info_prints_both_stiffnesses(tmp_path):
    # a 1 m square joint: K_M = k_n B^4 / 12 (depth = B = 1 m)
    for form, k_m, k_n in (("{normal: 1.2e10}", "1e+09", "1.2e+10"),
                           ("{rotational: 1e9}", "1e+09", "1.2e+10")):  # fmt: skip
        path = tmp_path / "c.yaml"
        path.write_text(SMALL.replace("stiffness: rigid", f"stiffness: {form}"))
        res = invoke("info", path)
        assert res.exit_code == 0, res.output
        header, units, row = [line.split() for line in res.output.splitlines()[-3:]]
        assert "K_M,i" in header and "k_n,i" in header
        assert row[header.index("K_M,i")] == k_m and row[header.index("k_n,i")] == k_n


@pytest.mark.parametrize("value", ["1:30", "1:30:00", "012", "0x10"])
def test_case13_yaml_11_numbers_are_refused(tmp_path, value):
    """Defect: YAML 1.1 sexagesimal integers were accepted (height: 1:30 read as 90)."""
    path = tmp_path / "c.yaml"
    path.write_text(SMALL.replace("height: 4.0", f"height: {value}"))
    one_line_error(invoke("info", path), "column.height", repr(value))


@pytest.mark.parametrize("command", ["sweep", "run"])
@pytest.mark.parametrize("output", ["", " "])
def test_case13_an_empty_output_folder_is_refused(small, tmp_path, monkeypatch, command, output):
    """Defect: -o '' wrote into the current folder."""
    monkeypatch.chdir(tmp_path)
    before = sorted(os.listdir(tmp_path))
    extra = ["-a", 0.5, "-f", 1] if command == "run" else ["--quiet"]
    one_line_error(invoke(command, small, "-o", output, *extra), "--output must name a folder")
    assert sorted(os.listdir(tmp_path)) == before


# ----------------------------------------------------------------- tracebacks
@pytest.mark.parametrize(
    ("label", "text", "needles"),
    [
        ("SOH", "name: a\x01\n", ["control character (U+0001)", "line 1"]),
        ("NUL", "name: a\ncolumn: {height: 4\x00}\n", ["control character (U+0000)", "line 2"]),
        ("ESC", "name: \x1b[31ma\n", ["control character (U+001B)"]),
        ("max_steps 1e300", SMALL + "solver: {max_steps: 1e300}\n", ["solver.max_steps"]),
        ("density 3e306", SMALL.replace("depth: 1.0}", "depth: 1.0, density: 3e306}"), ["density"]),
    ],
)
def test_case14_bad_configs_are_one_line(tmp_path, label, text, needles):
    """Defect: tracebacks (the YAML loader was built outside the try; a numba
    TypingError in every cell; ZeroDivisionError)."""
    path = tmp_path / "c.yaml"
    path.write_text(text)
    for command in (["info", path], ["sweep", path, "-o", tmp_path / "out", "--quiet"]):
        one_line_error(invoke(*command), *needles)
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["-a", 0.5, "-f", "1e200"], "--frequency must be in [0.001, 1000] [Hz]"),
        (["-a", "1e200", "-f", 1], "--amplitude must be in [0, 1000] [g]"),
        (["-a", 0.5, "-f", 1, "--dt", "1e-9"], "use a larger --dt"),
    ],
)
def test_case14_bad_run_options_are_one_line(small, tmp_path, args, needle):
    """Defect: rbm run -f 1e200 (OverflowError), --dt 1e-9 (MemoryError)."""
    one_line_error(invoke("run", small, *args, "-o", tmp_path / "out"), needle)
    assert not (tmp_path / "out").exists()


# ----------------------------------------------------------------- progress, interruption
def test_case15_progress_lines_without_a_terminal(small, tmp_path):
    """Defect: without a TTY a sweep printed nothing until it ended."""
    res = rbm("sweep", small, "-o", tmp_path / "out", "--jobs", "1")
    assert res.returncode == 0, res.stderr
    lines = [line for line in res.stderr.splitlines() if line.startswith("progress:")]
    assert lines and lines[-1].startswith(f"progress: small: {N_CELLS}/{N_CELLS} cells (100 %)")
    assert "cells/s" in lines[-1] and "ETA" in lines[-1]


def test_case15_the_eta_counts_only_this_sessions_cells(monkeypatch):
    """Defect: the ETA was 10x off (resumed cells counted as done in no time, the
    compile left in): 100 resumed of 200, then 10 cells in 2 s -> 5 cells/s, 18 s left."""
    import io

    import rbm_cli.cli.progress as progress

    clock = iter([1000.0, 1002.0, 1002.0])
    monkeypatch.setattr(progress.time, "monotonic", lambda: next(clock))
    out = io.StringIO()
    bar = progress.Progress("x", stream=out, tty=False)
    bar(100, 200)  # the first call: after the compile, before the first cell
    bar(110, 200)
    assert bar.rate(1002.0) == pytest.approx(5.0)
    assert "5 cells/s, ETA 18 s" in bar.text(1002.0)


def _group_alive(pgid: int) -> list[str]:
    ps = subprocess.run(["ps", "-eo", "pgid=,pid=,args="], capture_output=True, text=True)
    return [line for line in ps.stdout.splitlines() if line.split()[0] == str(pgid)]


MULTI = """\
name: multi
column: {height: 5.0, base_width: 0.96, top_width: 0.66, drums: 8}
interface: {stiffness: {normal: 5e9}}
excitation: {type: harmonic, duration: 10.0}
grid:
  amplitudes: {start: 0.1, stop: 1.0, step: 0.1}
  frequencies: {start: 0.5, stop: 4.0, num: 8}
"""


def _start_sweep(path: Path, out: Path, *extra) -> subprocess.Popen:
    cmd = [sys.executable, "-m", "rbm_cli", "sweep", str(path), "-o", str(out), *extra]
    return subprocess.Popen(
        cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True
    )


def _wait_rows(journal: Path, n: int, proc: subprocess.Popen, limit: float = 90) -> None:
    deadline = time.monotonic() + limit
    while time.monotonic() < deadline:
        if journal.is_file() and journal.read_bytes().count(b'"amplitude_g"') >= n:
            return
        if proc.poll() is not None:
            pytest.fail("the sweep ended before the signal: " + proc.communicate()[1])
        time.sleep(0.05)
    pytest.fail("no journal rows in time")


@pytest.mark.timeout(240)
@pytest.mark.slow
def test_case15_ctrl_c_says_what_is_kept_and_how_to_resume(tmp_path, compiled):
    """Defect: Ctrl-C printed only 'Aborted!' and left loky's 'leaked semlock' warnings;
    workers outlived the sweep; Ctrl-C pressed again during the stop could cut short the
    line that says what is kept."""
    path = tmp_path / "multi.yaml"
    path.write_text(MULTI)
    out = tmp_path / "out"
    proc = _start_sweep(path, out)
    _wait_rows(out / "multi" / JOURNAL, 8, proc)
    os.killpg(proc.pid, signal.SIGINT)  # as a terminal's Ctrl-C: the whole group
    for _ in range(20):  # and again, while the sweep stops its workers and counts its cells
        time.sleep(0.05)
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert "Traceback" not in err and "leaked" not in err and "Aborted" not in err
    (line,) = [x for x in err.splitlines() if x.startswith("Error:")]
    kept = journal_rows(out / "multi")
    assert f"interrupted: {kept} of 80 cells are kept" in line
    command = line.split("resume with: ")[1]
    assert command == f"rbm sweep {path} -o {out} --resume"
    deadline = time.monotonic() + 5
    while _group_alive(proc.pid) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert _group_alive(proc.pid) == []  # no worker left behind
    res = rbm(*command.split()[1:], timeout=200)
    assert res.returncode == 0, res.stderr
    assert f"({80 - kept} run, {kept} resumed)" in res.stdout


@pytest.mark.timeout(240)
def test_case15_kill_9_leaves_no_worker_and_no_staging(tmp_path, compiled):
    """Defect: after kill -9, loky workers and hidden staging folders stayed behind."""
    path = tmp_path / "multi.yaml"
    path.write_text(MULTI)
    out = tmp_path / "out"
    proc = _start_sweep(path, out, "--quiet")
    _wait_rows(out / "multi" / JOURNAL, 8, proc)
    proc.kill()  # the sweep alone, as kill -9 <pid>: its workers must notice
    proc.communicate(timeout=30)
    deadline = time.monotonic() + 15
    while _group_alive(proc.pid) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert _group_alive(proc.pid) == []
    with SweepStore(out / "multi"):  # the lock died with its holder: not stale
        pass


def test_case15_staging_left_by_a_killed_publication_is_removed(small, tmp_path, straight):
    folder = partial(small, tmp_path / "out", 4)
    stale = folder / ".publish.999999.abc"  # a publication killed half-way
    stale.mkdir()
    (stale / "domain.csv").write_text("half")
    res = invoke("sweep", small, "-o", tmp_path / "out", "--jobs", "1", "--resume", "--quiet")
    assert res.exit_code == 0, res.output
    assert not stale.exists() and (folder / "domain.csv").read_bytes() == straight
    assert sorted(p.name for p in folder.iterdir()) == sorted(FINALS)  # no lock, no tmp


def test_case15_a_killed_run_leaves_no_staging_behind(small, tmp_path):
    """`rbm run` killed while writing leaves .run_*.<pid>.* behind; the next run of the
    same cell removes it (its process is gone), and a live one's is left alone."""
    folder = tmp_path / "out" / "small"
    folder.mkdir(parents=True)
    dead = folder / ".run_A0.5_f1.999999.xyz"  # no process 999999 here
    dead.mkdir()
    live = folder / f".run_A0.5_f1.{os.getppid()}.xyz"
    live.mkdir()
    assert invoke("run", small, "-a", 0.5, "-f", 1, "-o", tmp_path / "out").exit_code == 0
    assert not dead.exists() and live.exists()
