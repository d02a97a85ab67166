"""The compiled run loops of the planar RBM and of rbm-3d return one named record,
numerics.loop.RunEnd, compiled and with `solver.implementation: python` alike.

Independent reasons for the figures checked on it:

- a recorded run writes a sample every output_dt from t = 0 to its end: floor(t_end / dt) + 1
  rows;
- the energy account closes: the energy at the end less the one at the start is the ground's
  work less what the damping and the impacts took (to the integration's accuracy, here a
  millionth of the work);
- a planar run has no azimuth and no swept angles; an rbm-3d run along x stays in its plane
  (no wobble, so no swept angle) and, collapsing, leans along its motion (azimuth 0 or pi).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import rbm_cli.models.rbm.step as step
import rbm_cli.models.rbm3d.runner as runner3d
from rbm_cli.config import parse_config
from rbm_cli.inputs.excitation import make_ground_motion
from rbm_cli.models.registry import make_runner
from rbm_cli.models.status import COLLAPSED, SURVIVED
from rbm_cli.numerics.loop import RunEnd

COLUMN = {"height": 5.0, "base_width": 0.96, "top_width": 0.66, "density": 2700}


def _config(model, section, drums=1, duration=3.0):
    return parse_config({
        "name": "run_end", "model": model,
        "column": {**COLUMN, "section": section, "drums": drums},
        "interface": {"stiffness": "rigid" if drums == 1 else {"normal": 5e9},
                      "restitution": 0.9},
        "excitation": {"type": "harmonic", "duration": duration},
        "solver": {"method": "DOP853", "rtol": 1e-10, "atol": 1e-12},
    })  # fmt: skip


def _ends(monkeypatch, module, name, cfg, cell, implementation):
    """What the loop returned to the runner (module.name wrapped), and the Outcome."""
    seen = []
    loop = getattr(module, name)
    plain = module.plain

    def wrapped(*args):
        run = loop if implementation == "compiled" else plain(loop)
        seen.append(run(*args))
        return seen[-1]

    monkeypatch.setattr(module, name, wrapped)
    monkeypatch.setattr(module, "plain", lambda f: f)  # the wrapper runs the uncompiled loop
    solver = dataclasses.replace(cfg.solver, implementation=implementation)
    out = make_runner(cfg).run(make_ground_motion(cfg.excitation, *cell), solver, record=True)
    assert len(seen) == 1
    return seen[0], out


def _balance(res):
    start, end, work, damping, impacts = res.ledger
    assert work > 0.0
    assert abs((end - start) - (work - damping - impacts)) < 1e-6 * work


@pytest.mark.parametrize("implementation", ["compiled", "python"])
def test_the_planar_loop_returns_a_run_end(monkeypatch, implementation):
    cfg = _config("rbm", "rectangular", duration=2.0)
    res, out = _ends(monkeypatch, step, "run_kernel", cfg, (0.4, 1.0), implementation)
    assert isinstance(res, RunEnd)
    assert res.code == SURVIVED and res.n_impacts > 0
    assert res.n_samples == math.floor(2.0 / 0.002 + 1e-9) + 1 == len(out.samples)
    assert math.isnan(res.azimuth) and res.swept.size == 0
    assert (res.n_steps, res.n_events, res.n_impacts) == (out.n_steps, out.n_events,
                                                          out.n_impacts)  # fmt: skip
    _balance(res)


@pytest.mark.parametrize("implementation", ["compiled", "python"])
def test_the_3d_loop_returns_a_run_end(monkeypatch, implementation):
    cfg = _config("rbm-3d", "circular", drums=2, duration=2.0)
    res, out = _ends(monkeypatch, runner3d, "run3d", cfg, (0.6, 1.5), implementation)
    assert isinstance(res, RunEnd)
    assert res.swept.shape == (2,)
    assert res.code == COLLAPSED or np.all(res.swept == 0.0)
    assert res.n_samples == len(out.samples) > 0
    if res.code == COLLAPSED:
        assert min(abs(res.azimuth), abs(abs(res.azimuth) - math.pi)) < 1e-9
        assert out.collapse_interface == res.collapsed + 1
    _balance(res)
