"""The compiled kernel (rbm_cli.models.rbm.kernel) against the Python reference loop
(rbm_cli.models.rbm.python) and against closed forms.

The kernel transcribes the Python loop (same Runge-Kutta tableaux, step-size
control and event handling), so on runs that are not chaotic the two give the
same outcome; the kernel's peaks come from the step's dense output (root of the
rate), the Python loop's from a cubic Hermite, so peaks are compared against
the closed form, not against each other.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from rbm_cli.config.load import load_config
from rbm_cli.models.housner_linear import housner_linear_run
from rbm_cli.models.rbm.kernel import integrate_compiled
from rbm_cli.models.rbm.python import integrate
from rbm_cli.models.rbm.runner import RbmRunner
from rbm_cli.physics.closed_forms import linear_rocking_parameters
from rbm_cli.physics.excitation import make_ground_motion
from rbm_cli.study.simulate import model_from_config, simulate

from .paths import CONFIGS

# (config, amplitude g, frequency Hz): rigid and elastic monoliths, a half-sine,
# and 8-drum cells that stay elastic (no rocking, so no chaos)
CASES = [
    ("spanos_koh_slender", 0.3, 1.0),
    ("spanos_koh_slender", 0.5, 2.0),
    ("spanos_koh_slender", 1.0, 3.0),
    ("housner_halfsine", 0.5, 2.0),
    ("harmonic_monolithic", 0.3, 1.0),
    ("harmonic_monolithic", 0.5, 2.0),
    ("harmonic_multidrum", 0.1, 0.5),
    ("harmonic_multidrum", 0.15, 2.0),
]


@pytest.mark.parametrize("method", ["DOP853", "RK45"])
@pytest.mark.parametrize(("study", "amplitude", "frequency"), CASES)
def test_kernel_matches_the_python_loop(study, amplitude, frequency, method):
    cfg = load_config(CONFIGS / f"{study}.yaml")
    solver = dataclasses.replace(cfg.solver, method=method)
    model = model_from_config(cfg)
    motion = make_ground_motion(cfg.excitation, amplitude, frequency)
    zeros = np.zeros(model.n)
    ref = integrate(model, motion, zeros, zeros, solver)
    out = integrate_compiled(model, motion, zeros, zeros, solver)
    assert out.status == ref.status
    assert out.n_impacts == ref.n_impacts and out.n_uplifts == ref.n_uplifts
    if ref.status == "collapsed":
        assert out.collapse_interface == ref.collapse_interface
        assert abs(out.t_collapse - ref.t_collapse) < 1e-6
    else:
        # Hermite peaks (Python) are accurate to ~1e-5 on long DOP853 steps
        np.testing.assert_allclose(out.max_ratio, ref.max_ratio, rtol=1e-4, atol=1e-12)


@pytest.mark.parametrize(("study", "amplitude", "frequency"), CASES[:4])
def test_kernel_history_matches_the_python_loop(study, amplitude, frequency):
    cfg = load_config(CONFIGS / f"{study}.yaml")
    model = model_from_config(cfg)
    motion = make_ground_motion(cfg.excitation, amplitude, frequency)
    zeros = np.zeros(model.n)
    ref = integrate(model, motion, zeros, zeros, cfg.solver, record=True, early_stop=False)
    out = integrate_compiled(model, motion, zeros, zeros, cfg.solver, record=True,
                             early_stop=False)  # fmt: skip
    t_ref = np.array([s[0] for s in ref.samples])
    t_out = np.array([s[0] for s in out.samples])
    np.testing.assert_array_equal(t_out, t_ref)
    th_ref = np.array([s[1] for s in ref.samples])
    th_out = np.array([s[1] for s in out.samples])
    assert np.max(np.abs(th_out - th_ref)) <= 1e-7 * max(np.max(np.abs(th_ref)), 1e-12)


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
    exact = housner_linear_run(alpha, p, motion, restitution=model.restitution)
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
    """Issue 6's energy-jump case (tests/test_stress.py::test_energy_jump_reproducer)
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


def test_silent_impacts_change_nothing_but_the_event_count(monkeypatch):
    """With e = 1 and a law linear through zero, a zero crossing after an excursion
    is no event (events.Pieces.silent) but is still counted. Against the run that
    stops at every such crossing (the earlier rule, kept by the baseline): the same
    impacts, the events fewer by exactly that number, and peaks that differ by less
    than the solver's own spread between rtol 1e-10 and 1e-12 (the 8-drum column
    amplifies round-off fast: 0.4 s, before that spread grows); the kernel counts
    as the Python loop does."""
    import rbm_cli.models.rbm.python as integrate_module
    from rbm_cli.models.events import Pieces

    cfg = load_config(CONFIGS / "harmonic_multidrum.yaml")
    model = model_from_config(cfg)
    n = model.n
    motion = dataclasses.replace(make_ground_motion(cfg.excitation, 0.5, 3.0), t_end=0.4)
    zero = np.zeros(n)
    quiet = integrate(model, motion, zero, zero, cfg.solver)
    compiled = integrate_compiled(model, motion, zero, zero, cfg.solver)
    monkeypatch.setattr(integrate_module, "Pieces", lambda m, silent=False: Pieces(m))
    loud = integrate(model, motion, zero, zero, cfg.solver)
    tight = integrate(model, motion, zero, zero, dataclasses.replace(cfg.solver, rtol=1e-12))
    assert loud.n_impacts > 20
    assert quiet.n_impacts == loud.n_impacts == compiled.n_impacts
    assert quiet.n_events == loud.n_events - loud.n_impacts
    assert compiled.n_events == quiet.n_events
    assert quiet.status == loud.status == compiled.status == "survived"

    def rel(a, b):
        return float(np.max(np.abs(a - b) / np.abs(b)))

    spread = rel(loud.max_ratio, tight.max_ratio)
    assert 0.0 < spread < 1e-4
    assert rel(quiet.max_ratio, loud.max_ratio) <= spread
    assert rel(compiled.max_ratio, quiet.max_ratio) <= spread
