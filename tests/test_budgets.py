"""A run's step and event budgets follow the column and the motion (solver.max_steps and
max_events `auto`: so many a second of motion and a joint, never fewer than the fixed budgets
of earlier versions), so that a tall column under a long record runs; a budget written stays
as written; a budget that runs out says which one and how to raise it."""

from __future__ import annotations

import pytest

import rbm
from rbm_cli.base.errors import ConfigError
from rbm_cli.config.load import load_config
from rbm_cli.config.types import BUDGET_FLOOR, BUDGET_PER_JOINT_SECOND, SolverConfig

from .paths import CONFIGS


def test_auto_budgets_scale_with_duration_and_joints_above_a_floor():
    auto = SolverConfig()
    assert (auto.max_steps, auto.max_events) == (None, None)
    short = auto.for_run(10.0, 1)  # a block under 10 s: the floors
    assert (short.max_steps, short.max_events) == (2_000_000, 200_000)
    assert (short.max_steps, short.max_events) == tuple(BUDGET_FLOOR.values())
    tall = auto.for_run(35.0, 16)  # a 16-drum column under a 30 s record and 5 s free
    assert tall.max_steps == 35 * 16 * BUDGET_PER_JOINT_SECOND["max_steps"] == 11_200_000
    assert tall.max_events == 35 * 16 * BUDGET_PER_JOINT_SECOND["max_events"] == 1_120_000
    written = SolverConfig(max_steps=5000, max_events=300).for_run(35.0, 16)
    assert (written.max_steps, written.max_events) == (5000, 300)
    one = SolverConfig(max_events=300).for_run(35.0, 16)  # the other one still scales
    assert (one.max_steps, one.max_events) == (11_200_000, 300)
    assert tall.for_run(1.0, 1) == tall  # a run's budgets are final


def test_budgets_are_auto_or_integers_in_range():
    cfg = {"name": "b", "column": {"height": 2.0, "base_width": 0.5}}
    assert rbm.load_config({**cfg, "solver": {"max_events": "auto"}}).solver.max_events is None
    assert rbm.load_config({**cfg, "solver": {"max_steps": 2e6}}).solver.max_steps == 2_000_000
    for bad in ("many", -1, 10, 2.5, None):
        with pytest.raises(ConfigError, match=r"solver\.max_events must be an integer"):
            rbm.load_config({**cfg, "solver": {"max_events": bad}})


def test_a_budget_that_runs_out_names_itself_and_how_to_raise_it():
    cfg = load_config(CONFIGS / "ci" / "harmonic_multidrum_ci.yaml")
    few = rbm.with_value(cfg, "solver", {"max_events": 100})
    run = rbm.run(few, amplitude_g=0.4, frequency_hz=2.0, record=False)
    assert run.status == "failed"
    assert "event budget exceeded (100 events" in run.result["message"]
    assert "raise solver.max_events" in run.result["message"]
    short = rbm.with_value(cfg, "solver", {"max_steps": 1000})
    run = rbm.run(short, amplitude_g=0.4, frequency_hz=2.0, record=False)
    assert run.status == "failed" and "raise solver.max_steps" in run.result["message"]


@pytest.mark.slow
def test_a_16_drum_column_runs_a_30_s_record():
    """The paper's column in 16 drums under a 30 s record (and 5 s of free motion) at 0.1 g
    needs more events than the fixed budget of 200,000 it once had (it failed at 27.5 s);
    with the budgets that scale it runs to the end."""
    cfg = load_config(CONFIGS / "ci" / "suite_multidrum_ci.yaml")
    cfg = rbm.with_values(cfg, {"column.drums": 16,
                                "excitation.file": "../records/synthetic/rdk_01.AT2"})  # fmt: skip
    run = rbm.run(cfg, amplitude_g=0.1, record=False)
    assert run.status == "survived", run.result["message"]
    events = run.result["n_uplifts"] + run.result["n_impacts"]
    assert events > BUDGET_FLOOR["max_events"]
    fixed = rbm.with_value(cfg, "solver", {"max_events": BUDGET_FLOOR["max_events"]})
    assert rbm.run(fixed, amplitude_g=0.1, record=False).status == "failed"
