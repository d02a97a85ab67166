"""The benchmark's baseline (solve_ivp RK45 per cell) solves the same problem:
its outcomes agree with the closed form on rigid monolithic cells, so the
speed-ups `rbm bench` reports compare integrators of one model."""

from __future__ import annotations

import numpy as np
import pytest

from rbm_cli.config.load import load_config
from rbm_cli.inputs.excitation import make_ground_motion
from rbm_cli.models.block.closed_form import linear_run
from rbm_cli.models.outcome import Outcome
from rbm_cli.structures.closed_forms import linear_rocking_parameters
from rbm_cli.study.bench_baseline import baseline_run
from rbm_cli.study.simulate import model_from_config

from .paths import CONFIGS


@pytest.mark.parametrize(("amplitude", "frequency"), [(0.25, 1.0), (0.5, 2.0), (0.3, 1.0),
                                                      (0.2, 0.5)])  # fmt: skip
def test_baseline_agrees_with_the_closed_form(amplitude, frequency):
    cfg = load_config(CONFIGS / "spanos_koh_slender.yaml")
    model = model_from_config(cfg)
    motion = make_ground_motion(cfg.excitation, amplitude, frequency)
    alpha, p = linear_rocking_parameters(model.column)
    exact = linear_run(alpha, p, motion, restitution=model.restitution)
    out = baseline_run(model, motion)
    assert isinstance(out, Outcome)
    assert out.status == exact.status
    if exact.status == "collapsed":
        assert abs(out.t_collapse - exact.t_collapse) < 0.05
    else:
        peak = float(np.max(exact.max_ratio))
        assert abs(float(out.max_ratio[0]) - peak) <= 1e-2 * max(peak, 1e-12)
