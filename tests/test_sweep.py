"""Sweeps: determinism across workers and backends, interruption and resume, compare."""

from __future__ import annotations

import dataclasses
import json

import pandas as pd
import pytest

from rbm_cli.api import run_sweep
from rbm_cli.base.errors import RbmError
from rbm_cli.config.load import load_config
from rbm_cli.config.types import GridConfig
from rbm_cli.study.domain import boundary, boundary_table, compare, csv_text, read_domain
from rbm_cli.study.sweep import JOURNAL, config_hash, grid_cells

from .paths import CONFIGS


def small_config(amps=(0.2, 0.3, 0.5, 0.8, 1.2), freqs=(0.5, 1.0, 2.0)):
    cfg = load_config(CONFIGS / "spanos_koh_slender.yaml")
    return dataclasses.replace(cfg, grid=GridConfig(amplitudes_g=amps, frequencies_hz=freqs))


def test_grid_order_is_frequency_major():
    cfg = small_config(amps=(0.1, 0.2), freqs=(1.0, 2.0))
    assert grid_cells(cfg) == [(0.1, 1.0, ()), (0.2, 1.0, ()), (0.1, 2.0, ()), (0.2, 2.0, ())]


def test_jobs_do_not_change_the_csv(tmp_path):
    cfg = small_config()
    one = run_sweep(cfg, tmp_path / "one", jobs=1)
    two = run_sweep(cfg, tmp_path / "two", jobs=2)
    a = (one.folder / "domain.csv").read_bytes()
    b = (two.folder / "domain.csv").read_bytes()
    assert a == b
    for name in ("domain.csv", "boundary.csv", "meta.json", "domain.png"):
        assert (two.folder / name).is_file()
    meta = json.loads((two.folder / "meta.json").read_text())
    assert meta["jobs"] == 2 and meta["n_cells"] == 15 and "wall_time_s" in meta
    assert "wall" not in a.decode()  # wall times go to meta.json only


def test_dask_backend_on_a_local_cluster(tmp_path):
    """The same sweep on a Dask distributed cluster (loopback) gives the same CSV."""
    distributed = pytest.importorskip("dask.distributed")
    cfg = small_config(amps=(0.2, 0.5, 1.2), freqs=(0.5, 2.0))
    ref = run_sweep(cfg, tmp_path / "ref", jobs=1)
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, host="127.0.0.1", dashboard_address=None
    ) as cluster:
        got = run_sweep(
            cfg, tmp_path / "dask", jobs=2, backend="dask", scheduler=cluster.scheduler_address
        )
    assert (got.folder / "domain.csv").read_bytes() == (ref.folder / "domain.csv").read_bytes()


def test_interrupted_then_resumed_equals_uninterrupted(tmp_path):
    cfg = small_config()
    straight = run_sweep(cfg, tmp_path / "straight", jobs=1)
    with pytest.raises(RbmError, match="stopped after"):
        run_sweep(cfg, tmp_path / "cut", jobs=1, stop_after=2)
    folder = tmp_path / "cut" / cfg.name
    assert not (folder / "domain.csv").exists()  # nothing that looks complete
    assert (folder / JOURNAL).is_file()
    # a line cut by the kill is ignored, not trusted
    with (folder / JOURNAL).open("a") as fh:
        fh.write('{"amplitude_g": 1.2, "frequency_hz": 2.0, "sta')
    resumed = run_sweep(cfg, tmp_path / "cut", jobs=2, resume=True)
    assert resumed.n_resumed > 0 and resumed.n_run < resumed.n_cells
    assert (folder / "domain.csv").read_bytes() == (straight.folder / "domain.csv").read_bytes()
    assert not (folder / JOURNAL).exists()


def test_resume_refuses_a_journal_of_another_config(tmp_path):
    cfg = small_config()
    with pytest.raises(RbmError):
        run_sweep(cfg, tmp_path, jobs=1, stop_after=1)
    other = dataclasses.replace(cfg, collapse=dataclasses.replace(cfg.collapse, ratio=0.9))
    with pytest.raises(RbmError, match="different config"):
        run_sweep(other, tmp_path, jobs=1, resume=True)


def test_rigid_cells_below_uplift_are_not_integrated(tmp_path):
    cfg = small_config(amps=(0.1, 0.2, 0.24), freqs=(0.5, 3.0))
    s = run_sweep(cfg, tmp_path, jobs=1)
    df = read_domain(s.folder / "domain.csv")
    assert (df["n_steps"] == 0).all() and (df["status"] == "survived").all()


def test_boundary_and_compare_on_synthetic_domains():
    def dom(flags):
        rows = [
            {
                "amplitude_g": a,
                "frequency_hz": f,
                "status": "collapsed" if c else "survived",
                "collapsed": c,
            }
            for f, col in flags.items()
            for a, c in zip((0.1, 0.2, 0.3, 0.4), col, strict=True)
        ]
        return pd.DataFrame(rows)

    a = dom({1.0: (0, 0, 1, 1), 2.0: (0, 0, 0, 1)})
    b = dom({1.0: (0, 1, 1, 1), 2.0: (0, 0, 0, 0)})
    bnd = boundary(a)
    assert list(bnd["lowest_unsafe_g"]) == [0.3, 0.4]
    assert list(bnd["highest_safe_g"]) == [0.2, 0.3]
    cmp = compare(a, b)
    assert cmp.n_common == 8 and cmp.n_differ == 2
    # at 2 Hz b has no collapse: its boundary is one step above the grid (0.5)
    assert cmp.max_shift_g == pytest.approx(0.1)
    assert compare(a, a).n_differ == 0 and compare(a, a).max_shift_g == 0.0


def test_boundary_from_rows_without_pandas():
    """boundary.csv from a sweep's rows in plain Python: one line per point and
    frequency, sorted, empty where nothing collapses or nothing survives below; a failed
    cell is neither; a record's (no frequency) is one line. boundary(df) is the same rule."""

    def cell(size, f, a, status):
        return {"column.size": size, "frequency_hz": f, "amplitude_g": a, "status": status}

    rows = [
        cell(2.0, 2.0, a, s)
        for a, s in ((0.1, "survived"), (0.2, "collapsed"), (0.3, "survived"), (0.4, "collapsed"))
    ]
    rows += [
        cell(2.0, 1.0, a, s) for a, s in ((0.4, "survived"), (0.2, "failed"), (0.1, "survived"))
    ]
    rows += [cell(1.0, 1.0, 0.3, "collapsed"), cell(1.0, 1.0, 0.1, "failed")]
    fields = ("column.size", "frequency_hz", "amplitude_g", "status")
    expected = (
        "column.size,frequency_hz,lowest_unsafe_g,highest_safe_g\n"
        "1,1,0.3,\n"  # nothing survived below 0.3 g (0.1 g failed)
        "2,1,,0.4\n"  # nothing collapsed
        "2,2,0.2,0.1\n"  # the 0.3 g survivor above the lowest collapse is not safe
    )
    columns, lines = boundary_table(rows, fields)
    assert csv_text(lines, columns) == expected
    bnd = boundary(pd.DataFrame(rows, columns=list(fields)))
    assert csv_text(bnd.to_dict("records"), tuple(bnd.columns)) == expected
    record = [
        {"frequency_hz": None, "amplitude_g": a, "status": s}
        for a, s in ((0.3, "collapsed"), (0.1, "survived"), (0.2, "survived"))
    ]
    columns, lines = boundary_table(record, ("frequency_hz", "amplitude_g", "status"))
    assert csv_text(lines, columns) == "frequency_hz,lowest_unsafe_g,highest_safe_g\n,0.3,0.2\n"
    read = pd.DataFrame(record).astype({"frequency_hz": float})  # as read: NaN, not None
    assert boundary(read)["lowest_unsafe_g"].tolist() == [0.3]


def test_sweep_killed_with_sigkill_then_resumed(tmp_path):
    """A real kill: `rbm sweep` in a subprocess, SIGKILL once the journal holds
    some rows, then --resume: same bytes as a straight run, no complete-looking
    file in between.

    The slender block's default (the compiled closed form) does its 468 cells in
    well under the poll interval, so the test runs a 120-cell grid of it with the
    Python step integrator (~30 ms a cell): the kill lands mid-sweep on any load."""
    import os
    import signal
    import subprocess
    import sys
    import time

    import yaml

    doc = yaml.safe_load((CONFIGS / "spanos_koh_slender.yaml").read_text())
    doc["grid"]["amplitudes"] = {"start": 0.1, "stop": 2.0, "step": 0.2}
    doc["solver"] = {"method": "DOP853", "implementation": "python"}
    cfg_path = tmp_path / "slow_slender.yaml"
    cfg_path.write_text(yaml.safe_dump(doc))
    n_cells = len(grid_cells(load_config(cfg_path)))
    assert n_cells == 120
    cmd = [sys.executable, "-m", "rbm_cli", "sweep", str(cfg_path), "-o", str(tmp_path / "cut")]
    proc = subprocess.Popen([*cmd, "--jobs", "1", "--quiet"], start_new_session=True)
    journal = tmp_path / "cut" / "spanos_koh_slender" / JOURNAL
    deadline = time.monotonic() + 120
    try:
        while time.monotonic() < deadline:
            if journal.is_file() and journal.read_text().count("\n") >= 17:
                break
            if proc.poll() is not None:
                pytest.fail("the sweep ended before it could be killed")
            time.sleep(0.05)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    folder = journal.parent
    assert not (folder / "domain.csv").exists()
    n_before = journal.read_text().count("\n") - 1  # complete lines, less the header
    assert 0 < n_before < n_cells
    resumed = subprocess.run([*cmd, "--resume", "--quiet"], capture_output=True, text=True)
    assert resumed.returncode == 0, resumed.stderr
    # complete journal lines are kept; a line cut by the kill is redone
    assert f"({n_cells - n_before} run, {n_before} resumed)" in resumed.stdout
    straight = run_sweep(load_config(cfg_path), tmp_path / "straight", jobs=2)
    assert (folder / "domain.csv").read_bytes() == (straight.folder / "domain.csv").read_bytes()


@pytest.mark.parametrize("started, resumed", [("DOP853", "auto"), ("auto", "DOP853")])
def test_a_journal_is_resumed_only_by_the_method_it_ran(tmp_path, started, resumed):
    """The config's hash holds the method that runs: on the rigid block `auto` runs the
    closed form and `DOP853` the step kernel, whose peaks differ in the last digits, so the
    two are two configs, and a journal started under one is refused (in one line, kept) by
    a resume under the other. meta.json names the method that ran."""
    base = load_config(CONFIGS / "spanos_koh_slender.yaml")

    def method(name):
        return dataclasses.replace(base, solver=dataclasses.replace(base.solver, method=name))

    first, second = method(started), method(resumed)
    assert config_hash(first) != config_hash(second)
    straight = {m: run_sweep(method(m), tmp_path / m, jobs=1).folder for m in (started, resumed)}
    domains = {m: (folder / "domain.csv").read_bytes() for m, folder in straight.items()}
    assert domains[started] != domains[resumed]  # the two methods tell apart
    for m, folder in straight.items():
        ran = json.loads((folder / "meta.json").read_text())["solver_method"]
        assert ran == ("closed-form" if m == "auto" else "DOP853")
    with pytest.raises(RbmError, match="stopped after 2 chunks"):
        run_sweep(first, tmp_path / "cut", jobs=1, stop_after=2)
    journal = (tmp_path / "cut" / base.name / JOURNAL).read_bytes()
    with pytest.raises(RbmError, match="made with a different config") as err:
        run_sweep(second, tmp_path / "cut", jobs=1, resume=True)
    assert "\n" not in str(err.value)
    assert (tmp_path / "cut" / base.name / JOURNAL).read_bytes() == journal
    summary = run_sweep(first, tmp_path / "cut", jobs=1, resume=True)
    assert 0 < summary.n_resumed < summary.n_cells
    assert (summary.folder / "domain.csv").read_bytes() == domains[started]
