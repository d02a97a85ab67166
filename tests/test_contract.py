"""Every registered model keeps the one Runner contract (rbm_cli.models.contract) and answers
the same case alike.

The case is a rigid monolithic rectangle (H 4 m, B 1 m; a cylinder 1 m across for a model in
three dimensions, with the same alpha) under a half-sine pulse, where the
physics leaves no doubt: at 0.1 g, below every model's uplift level (B/H = 0.25 g for the
RBM and housner-linear, tan(alpha) = 0.25 g for Housner's block, min(tan alpha, friction)
for the engine) nothing moves; at 3 g and 1 Hz, twelve times the uplift level over a
half-second pulse, every model's block overturns (Housner's approximate threshold at
w/p = 2 pi / 1.9 is sqrt(1 + 11) ~ 3.5 alpha, far below 12 alpha). A model added to the
registry is run here without a line of this file changing.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from rbm_cli.base.errors import RbmError
from rbm_cli.config import parse_config
from rbm_cli.config.types import MODELS
from rbm_cli.inputs.excitation import make_ground_motion
from rbm_cli.models.contract import Runner
from rbm_cli.models.outcome import Outcome
from rbm_cli.models.registry import make_runner, model_names, runner_class
from rbm_cli.study.simulate import simulate


def _block_dict(model: str) -> dict:
    interface = {"stiffness": "rigid", "restitution": 0.9}
    solver = {"time_step": 2e-4} if model == "bullet" else {}
    column = {"height": 4.0, "base_width": 1.0, "density": 2700}
    if MODELS[model].three_d:  # a cylinder: its uplift level is tan(alpha) = 0.25 g too
        column["section"] = "circular"
    return {
        "name": f"contract_{model}",
        "model": model,
        "column": column,
        "interface": interface,
        "excitation": {"type": "half-sine", "duration": 3.0},
        "solver": solver,
    }


def block(model: str):
    return parse_config(_block_dict(model))


def test_the_config_takes_every_registered_model_and_refuses_others():
    """A registry line is all a model needs to be accepted by the config, and a name
    without one is refused in one line that lists the registered names."""
    for name in model_names():
        assert block(name).model == name
        assert issubclass(runner_class(name), object) and callable(runner_class(name).run)
    with pytest.raises(RbmError) as err:
        parse_config({**_block_dict("rbm"), "model": "not-a-model"})
    message = str(err.value)
    assert "\n" not in message and "not-a-model" in message
    for name in model_names():
        assert name in message


@pytest.mark.parametrize("name", model_names())
def test_a_registry_line_says_whether_the_model_takes_drums(name):
    """`multi_drum` in a model's registry line decides what the config accepts: a model
    for monolithic blocks refuses two drums in one line naming itself; a multi-drum model
    builds a runner with one interface per drum."""
    cfg = _block_dict(name)
    cfg["column"]["drums"] = 2
    cfg["interface"] = {"stiffness": {"rotational": 1e9}, "restitution": 0.9}
    if MODELS[name].multi_drum:
        runner = make_runner(parse_config(cfg))
        assert runner.n_interfaces == 2
    else:
        with pytest.raises(RbmError, match=f"model '{name}' needs a monolithic column"):
            parse_config(cfg)


@pytest.mark.parametrize("name", model_names())
def test_every_model_keeps_the_contract(name):
    cfg = block(name)
    runner = make_runner(cfg)
    assert isinstance(runner, Runner)
    assert runner.config is cfg and runner.n_interfaces == 1
    motion = make_ground_motion(cfg.excitation, 3.0, 1.0)
    out = runner.run(motion, cfg.solver, record=True, output_dt=0.01, early_stop=False)
    assert isinstance(out, Outcome)
    assert out.status == "collapsed", out.message
    assert 0.0 < out.t_collapse <= motion.t_end
    h = out.history
    assert h is not None and h.t.size > 10 and h.t[0] == 0.0
    assert h.rotations.shape == (h.t.size, 1) and h.node_displacements.shape == (h.t.size, 2)
    # the top moves further than the base (which slides only in the engine)
    assert np.max(np.abs(h.node_displacements[:, 1])) > np.max(np.abs(h.node_displacements[:, 0]))
    # the history's ground acceleration is the motion's own
    np.testing.assert_allclose(h.ground_acceleration, motion.accel(h.t), rtol=0, atol=1e-12)


@pytest.mark.parametrize("name", model_names())
def test_every_model_answers_the_same_case_alike(name):
    cfg = block(name)
    runner = make_runner(cfg)
    below = simulate(cfg, 0.1, 1.0, runner=runner)
    above = simulate(cfg, 3.0, 1.0, runner=runner)
    assert below.status == "survived" and below.max_rotation_ratio < 1e-3, below
    assert below.n_uplifts == 0
    assert above.status == "collapsed" and above.collapse_interface == 1, above
    # the same runner gives the same answer on the same cell (nothing kept between runs)
    again = simulate(cfg, 3.0, 1.0, runner=runner)
    assert again.t_collapse_s == above.t_collapse_s
    assert math.isfinite(above.t_collapse_s)
