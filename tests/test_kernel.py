"""The step kernel (rbm_cli.models.rbm.step) against closed forms and physical checks.

Compiled and uncompiled (its own source run by Python) it gives the same bits:
tests/test_jit.py.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from rbm_cli.config.load import load_config
from rbm_cli.inputs.excitation import make_ground_motion
from rbm_cli.models.block.closed_form import linear_run
from rbm_cli.models.rbm.runner import RbmRunner
from rbm_cli.models.rbm.step import integrate
from rbm_cli.structures.closed_forms import linear_rocking_parameters
from rbm_cli.study.simulate import model_from_config, simulate

from .paths import CONFIGS


@pytest.mark.parametrize(("amplitude", "frequency"), [(0.25, 1.0), (0.5, 2.0), (0.8, 2.5),
                                                      (1.2, 3.0), (0.6, 1.5)])  # fmt: skip
def test_kernel_peak_matches_the_closed_form(amplitude, frequency):
    """Rigid n = 1 RBM = the linear rocking equation; its closed form (housner-linear
    with the RBM's inertia) gives the peak to round-off. Short runs (3 s), where
    the peak is well-conditioned."""
    cfg = load_config(CONFIGS / "spanos_koh_slender.yaml")
    cfg = dataclasses.replace(cfg, excitation=dataclasses.replace(cfg.excitation, duration=3.0))
    model = model_from_config(cfg)
    alpha, p = linear_rocking_parameters(model.column)
    motion = make_ground_motion(cfg.excitation, amplitude, frequency)
    exact = linear_run(alpha, p, motion, restitution=model.restitution)
    res = simulate(cfg, amplitude, frequency, runner=RbmRunner(cfg, model=model))
    assert res.status == exact.status
    if res.status == "collapsed":
        assert abs(res.t_collapse_s - exact.t_collapse) < 1e-7
    else:
        peak = float(np.max(exact.max_ratio))
        assert abs(res.max_rotation_ratio - peak) <= 1e-6 * peak


def test_kernel_budgets_stop_a_run_as_failed():
    cfg = load_config(CONFIGS / "harmonic_multidrum.yaml")
    solver = dataclasses.replace(cfg.solver, max_steps=1000)
    res = simulate(dataclasses.replace(cfg, solver=solver), 0.1, 0.5)
    assert res.status == "failed" and "step budget" in res.message
    solver = dataclasses.replace(cfg.solver, max_events=100)
    res = simulate(dataclasses.replace(cfg, solver=solver), 0.5, 1.0)
    assert res.status == "failed" and "event budget" in res.message
    assert math.isfinite(res.max_rotation_ratio)


def test_rigid_block_below_uplift_costs_nothing():
    cfg = load_config(CONFIGS / "spanos_koh_slender.yaml")
    res = simulate(cfg, 0.1, 1.0)  # below the static multiplier B/H
    assert res.status == "survived" and res.n_steps == 0 and res.n_rhs == 0


def test_kernel_energy_jump_reproducer():
    """The property suite's energy-jump case (tests/test_stress.py::test_energy_jump_reproducer)
    through the kernel: 6 drums, ultra-stiff joints, e = 1, free motion, >800
    impacts; the earliest crossing in a step must win, or energy jumps by 5e-4."""
    from rbm_cli.config.load import parse_config

    config = parse_config(
        {
            "name": "energy_jump",
            "column": {"height": 2.00001, "base_width": 0.321197, "top_width": 0.314647,
                       "section": "circular", "density": 2500, "drums": 6},
            "interface": {"stiffness": {"rotational": 744198000.0}, "xi": 0.979606,
                          "formulation": "relative"},
            "excitation": {"type": "free", "duration": 1.85233, "initial": {
                "velocities": [0.822687, -1.5755, 0.0, -0.238652, -0.755901, 1.46421]}},
            "solver": {"rtol": 1e-10, "max_steps": 50000, "max_events": 5000},
        }
    )  # fmt: skip
    res = simulate(config, 0.0, 0.0, record=True, output_dt=0.001)
    assert res.status == "survived" and res.n_impacts > 800
    model = model_from_config(config)
    energy = model.energy(res.history.rotations, res.history.rates)
    drift = np.max(np.abs(energy - energy[0])) / energy[0]
    assert drift <= 1e-6, f"relative energy drift {drift:.3g}"


def test_silent_impacts_change_nothing_but_the_event_count():
    """With e = 1 and a law linear through zero, a zero crossing after an excursion
    is no event (events.Pieces.silent) but is still counted. Against the same column
    with e just below 1 (1 - 1e-12: every such crossing is an impact event, which changes
    the rate by a relative 1e-12): the same impacts, the events fewer by exactly that
    number, and peaks that differ by less than the solver's own spread between rtol 1e-10
    and 1e-12 (the 8-drum column amplifies round-off fast: 0.4 s, before that spread
    grows)."""
    cfg = load_config(CONFIGS / "harmonic_multidrum.yaml")
    model = model_from_config(cfg)
    interface = dataclasses.replace(cfg.interface, restitution=1.0 - 1e-12)
    loud_model = model_from_config(dataclasses.replace(cfg, interface=interface))
    assert model.silent_impacts.any() and not loud_model.silent_impacts.any()
    n = model.n
    motion = dataclasses.replace(make_ground_motion(cfg.excitation, 0.5, 3.0), t_end=0.4)
    zero = np.zeros(n)
    quiet = integrate(model, motion, zero, zero, cfg.solver)
    loud = integrate(loud_model, motion, zero, zero, cfg.solver)
    tight = integrate(loud_model, motion, zero, zero, dataclasses.replace(cfg.solver, rtol=1e-12))
    assert loud.n_impacts > 20
    assert quiet.n_impacts == loud.n_impacts
    assert quiet.n_events == loud.n_events - loud.n_impacts
    assert quiet.status == loud.status == "survived"

    def rel(a, b):
        return float(np.max(np.abs(a - b) / np.abs(b)))

    spread = rel(loud.max_ratio, tight.max_ratio)
    assert 0.0 < spread < 1e-4
    assert rel(quiet.max_ratio, loud.max_ratio) <= spread
