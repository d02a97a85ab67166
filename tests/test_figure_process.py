"""domain.png drawn by a child forked as `rbm sweep` starts
(rbm_cli.report.figure_process): the same file as drawn in the sweep's own process, a
child that is not asked is killed and reaped, one that died is replaced by drawing here,
and a drawing error is the sweep's error.

Each test forks the child in the test's own process, which FigureProcess refuses while
other threads run: they run in a fresh interpreter (tests/conftest.py), where they must
fork."""

from __future__ import annotations

import dataclasses
import os
import signal

import pandas as pd
import pytest

from rbm_cli.api import run_sweep
from rbm_cli.config.load import load_config
from rbm_cli.config.types import GridConfig
from rbm_cli.report.figure_process import FigureProcess

from .paths import CONFIGS

pytestmark = [
    pytest.mark.timeout(240),
    pytest.mark.skipif(not hasattr(os, "fork"), reason="forks"),
    pytest.mark.fresh_interpreter,
]


def rigid():
    cfg = load_config(CONFIGS / "spanos_koh_slender.yaml")
    grid = GridConfig(amplitudes_g=(0.2, 0.5, 1.2), frequencies_hz=(0.5, 2.0))
    return dataclasses.replace(cfg, grid=grid)


def gone(pid: int) -> bool:
    """No process pid (not running, not a zombie): it was reaped."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    return False


def started() -> FigureProcess:
    proc = FigureProcess.start()
    assert proc is not None, "no figure child was forked (threads running?)"
    return proc


def test_the_child_draws_the_same_domain_png(tmp_path):
    cfg = rigid()
    here = run_sweep(cfg, tmp_path / "here", jobs=1)
    proc = started()
    pid = proc.pid
    child = run_sweep(cfg, tmp_path / "child", jobs=1, figure=proc.figure)
    assert proc.pid is None and gone(pid)  # reaped once it had drawn
    for name in ("domain.png", "domain.csv", "boundary.csv"):
        assert (child.folder / name).read_bytes() == (here.folder / name).read_bytes(), name


def test_a_child_not_asked_is_killed_and_reaped():
    proc = started()
    pid = proc.pid
    with proc:
        pass
    assert gone(pid)


def test_a_dead_child_is_replaced_by_drawing_here(tmp_path):
    cfg = rigid()
    here = run_sweep(cfg, tmp_path / "here", jobs=1)
    proc = started()
    os.kill(proc.pid, signal.SIGKILL)
    child = run_sweep(cfg, tmp_path / "child", jobs=1, figure=proc.figure)
    assert proc.pid is None
    assert (child.folder / "domain.png").read_bytes() == (here.folder / "domain.png").read_bytes()


def test_a_drawing_error_is_raised_here(tmp_path):
    """A domain without its columns: the child's error, the same type as drawn here."""
    bad = pd.DataFrame({"x": [1.0]})
    with pytest.raises(Exception) as here:
        from rbm_cli.report.domain_figure import domain_figure

        domain_figure(bad, None).savefig(tmp_path / "here.png")
    proc = started()
    pid = proc.pid
    with pytest.raises(type(here.value)):
        proc.figure(bad, None).savefig(tmp_path / "child.png")
    assert gone(pid) and not (tmp_path / "child.png").exists()


def test_the_api_hands_the_child_only_its_own_figure(tmp_path, monkeypatch):
    """run_sweep(figure_process=...) has the child draw rbm_cli.api's domain figure; any
    other figure (a caller's, or a test's replacement of it) is drawn here, and the child,
    not asked, is killed and reaped when closed."""
    import rbm_cli.api.sweeps

    cfg = rigid()
    real = rbm_cli.api.sweeps.domain_figure
    with started() as proc:
        pid = proc.pid
        run_sweep(cfg, tmp_path / "child", jobs=1, figure_process=proc)
        assert proc.pid is None and gone(pid)  # it drew, replied and exited
    drawn = []

    def mine(df, config):
        drawn.append(len(df))
        return real(df, config)

    with started() as proc:
        pid = proc.pid
        run_sweep(cfg, tmp_path / "mine", jobs=1, figure=mine, figure_process=proc)
        assert drawn == [6] and proc.pid == pid  # drawn here, the child not asked
    assert gone(pid)
    monkeypatch.setattr(rbm_cli.api.sweeps, "domain_figure", mine)
    with started() as proc:
        run_sweep(cfg, tmp_path / "patched", jobs=1, figure_process=proc)
    assert drawn == [6, 6]
