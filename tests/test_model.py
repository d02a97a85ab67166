"""The Rigid Beam Model against closed forms, invariants and limits."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from rbm_cli.config.types import (
    ColumnConfig,
    Config,
    ExcitationConfig,
    InitialConfig,
    InterfaceConfig,
    SolverConfig,
    StiffnessConfig,
)
from rbm_cli.models.rbm.runner import RbmRunner
from rbm_cli.structures.column import build_column
from rbm_cli.study.simulate import model_from_config, simulate

from .closed_form import LinearRocking

G = 9.81


def block(height=4.0, width=1.0, kind="harmonic", duration=None, **interface):
    duration = duration or (10.0 if kind == "harmonic" else 20.0)
    return Config(
        name="block",
        column=ColumnConfig(
            height=height, base_width=width, top_width=width, depth=1.0, drum_heights=(height,)
        ),
        interface=InterfaceConfig(**interface),
        excitation=ExcitationConfig(type=kind, duration=duration),
    )


def linear_reference(height, width, kind, amplitude_g, frequency_hz, duration):
    """The closed form with the RBM's n = 1 mapping, from the geometry alone:
    alpha = B/H, p^2 = m g (H/2) / (I_G + m H^2/4), I_G = m (H^2 + B^2)/12."""
    m = 2700.0 * height * width * 1.0
    i_g = m * (height**2 + width**2) / 12.0
    p = math.sqrt(m * G * height / 2.0 / (i_g + m * height**2 / 4.0))
    w = 2.0 * math.pi * frequency_hz
    pulse_end = duration if kind == "harmonic" else 0.5 / frequency_hz
    return LinearRocking(width / height, p, amplitude_g, w, 0.0, pulse_end, duration).solve()


CASES = [
    ("harmonic", 0.3, 0.5),  # collapses after one impact
    ("harmonic", 0.5, 1.0),  # the paper's fig. 3/4 case: collapses
    ("harmonic", 0.4, 1.0),
    ("harmonic", 1.4, 2.0),
    ("harmonic", 1.0, 2.0),  # survives, 24 impacts
    ("harmonic", 0.6, 1.5),  # survives
    ("harmonic", 0.26, 1.0),  # just above uplift: 33 impacts, survives
    ("half-sine", 0.35, 0.3),  # collapses during the pulse
    ("half-sine", 1.5, 2.5),  # collapses after the pulse
    ("half-sine", 0.5, 1.0),  # survives; peak after the pulse
    ("half-sine", 0.6, 1.0),  # survives with a peak near 0.77 theta_u
]


@pytest.mark.parametrize("kind,amplitude,frequency", CASES)
def test_rigid_block_matches_closed_form(kind, amplitude, frequency):
    """Rigid n = 1 RBM (xi = 1, e = 1) against the cosh/sinh closed form:
    collapse time within 1e-3 s, peak rotation within 0.1 %."""
    duration = 10.0 if kind == "harmonic" else 20.0
    ref = linear_reference(4.0, 1.0, kind, amplitude, frequency, duration)
    res = simulate(block(kind=kind), amplitude, frequency)
    assert res.collapsed == ref.collapsed
    if ref.collapsed:
        assert abs(res.t_collapse_s - ref.t_collapse) < 1e-3
    else:
        assert res.max_rotation_ratio == pytest.approx(ref.peak_ratio, rel=1e-3)
        assert res.n_impacts == ref.n_impacts or kind == "half-sine"


def test_closed_form_outcomes_are_mixed():
    """Guards the test above against a set of cases that all collapse or all survive."""
    outcomes = [
        linear_reference(4.0, 1.0, k, a, f, 10.0 if k == "harmonic" else 20.0).collapsed
        for k, a, f in CASES
    ]
    assert 3 <= sum(outcomes) <= len(outcomes) - 3


def test_rigid_below_static_multiplier_spends_no_step():
    """A rigid column below the uplift level (B/H = 0.25 g) never moves and
    is not integrated at all."""
    for amplitude in (0.0, 0.1, 0.2499):
        res = simulate(block(), amplitude, 1.0)
        assert res.status == "survived"
        assert res.n_steps == 0 and res.n_rhs == 0
        assert res.max_rotation_ratio == 0.0 and res.n_uplifts == 0
    res = simulate(block(), 0.26, 1.0)
    assert res.n_uplifts >= 1 and res.n_steps > 0


def multidrum(formulation="relative", drums=4, k_n=1e8, xi=0.8, velocities=None, duration=20.0):
    return Config(
        name="stack",
        column=ColumnConfig(
            height=4.0, base_width=0.8, top_width=0.8, drum_heights=(4.0 / drums,) * drums
        ),
        interface=InterfaceConfig(
            stiffness=StiffnessConfig("normal", (k_n,)), xi=xi, formulation=formulation
        ),
        excitation=ExcitationConfig(
            type="free",
            duration=duration,
            initial=InitialConfig(velocities=velocities or (0.15,) * (drums - 1) + (0.3,)),
        ),
        solver=SolverConfig(rtol=1e-10, atol=1e-13),
    )


@pytest.mark.parametrize("formulation", ["relative", "geometric"])
def test_energy_conserved_in_free_motion(formulation):
    """Elastic 4-drum column, e = 1, initial velocity, 20 s: kinetic + law
    potential (+ gravity for geometric) constant to 1e-6 relative, while the
    joints open and close hundreds of times (kinks crossed)."""
    cfg = multidrum(formulation)
    res = simulate(cfg, 0.0, 0.0, record=True, output_dt=0.005)
    model = model_from_config(cfg)
    h = res.history
    energy = model.energy(h.rotations, h.rates)
    assert h.t[-1] == pytest.approx(20.0, abs=0.01)
    assert res.n_uplifts > 50 and res.n_impacts > 50
    assert np.max(np.abs(energy - energy[0])) / energy[0] < 1e-6


def test_absolute_formulation_does_not_conserve_energy():
    """The paper's literal wording (M_i = -f(theta_i)) is not conservative."""
    cfg = multidrum("absolute")
    res = simulate(cfg, 0.0, 0.0, record=True, output_dt=0.005)
    model = model_from_config(cfg)
    energy = model.energy(res.history.rotations, res.history.rates)
    assert np.max(np.abs(energy - energy[0])) / energy[0] > 0.1


@pytest.mark.parametrize(
    "stiffness,xi", [("rigid", 1.0), (2e6, 1.0), (2e7, 0.6), (5e5, 0.3), (5e8, 0.9)]
)
@pytest.mark.parametrize(
    "kind,amplitude,frequency", [("harmonic", 0.5, 1.5), ("half-sine", 0.6, 1.0)]
)
def test_formulations_identical_for_monolith(stiffness, xi, kind, amplitude, frequency):
    """For n = 1 the three formulations are the same equation."""
    stiff = (
        StiffnessConfig("rigid")
        if stiffness == "rigid"
        else StiffnessConfig("moment", (stiffness,))
    )
    results = [
        simulate(block(kind=kind, stiffness=stiff, xi=xi, formulation=f), amplitude, frequency)
        for f in ("relative", "absolute", "geometric")
    ]
    ref = results[0]
    for other in results[1:]:
        assert other.status == ref.status
        assert other.n_impacts == ref.n_impacts and other.n_uplifts == ref.n_uplifts
        if ref.collapsed:
            assert other.t_collapse_s == pytest.approx(ref.t_collapse_s, abs=1e-6)
        assert other.max_rotation_ratio == pytest.approx(ref.max_rotation_ratio, rel=1e-5)
        assert other.max_top_displacement_m == pytest.approx(ref.max_top_displacement_m, rel=1e-5)


def _stiff_upper_joints(config, factor=1e3):
    """Test-only override: upper joints far stronger (and stiffer) than the base."""
    col = build_column(config.column, config.interface)
    mu = col.moment_capacity.copy()
    tu = col.rotation_capacity.copy()
    k = col.stiffness.copy()
    mu[1:] *= factor
    tu[1:] *= factor
    k[1:] *= 100.0
    return dataclasses.replace(col, moment_capacity=mu, rotation_capacity=tu, stiffness=k)


@pytest.mark.parametrize("formulation", ["relative", "geometric"])
@pytest.mark.parametrize("amplitude,frequency", [(0.5, 1.0), (0.3, 0.5), (0.7, 1.5)])
def test_strong_upper_joints_behave_as_monolith(formulation, amplitude, frequency):
    """A 4-drum prismatic column whose upper joints never open collapses like
    the monolithic column with the same base law (collapse time within 1 %)."""
    k_base = 2e8
    mono = Config(
        name="mono",
        column=ColumnConfig(
            height=4.0, base_width=1.0, top_width=1.0, depth=1.0, drum_heights=(4.0,)
        ),
        interface=InterfaceConfig(
            stiffness=StiffnessConfig("moment", (k_base,)), formulation=formulation
        ),
    )
    stack = dataclasses.replace(
        mono,
        column=dataclasses.replace(mono.column, drum_heights=(1.0,) * 4),
    )
    ref = simulate(mono, amplitude, frequency)
    assert ref.collapsed
    model = model_from_config(stack, column=_stiff_upper_joints(stack))
    res = simulate(stack, amplitude, frequency, runner=RbmRunner(stack, model=model))
    assert res.collapsed and res.collapse_interface == 1
    assert res.t_collapse_s == pytest.approx(ref.t_collapse_s, rel=0.01)


@pytest.mark.parametrize(
    "config",
    [
        block(),
        block(stiffness=StiffnessConfig("moment", (5e6,)), xi=0.7, restitution=0.8),
        dataclasses.replace(multidrum("relative", drums=3), excitation=ExcitationConfig()),
        dataclasses.replace(multidrum("geometric", drums=3), excitation=ExcitationConfig()),
    ],
    ids=["rigid", "trilinear-e0.8", "3drum-relative", "3drum-geometric"],
)
def test_mirror_symmetry(config):
    """Reversing the sign of the excitation (phase + pi) mirrors the response."""
    phase_cfg = dataclasses.replace(
        config, excitation=dataclasses.replace(config.excitation, phase=math.pi)
    )
    a = simulate(config, 0.45, 1.2, record=True, output_dt=0.01)
    b = simulate(phase_cfg, 0.45, 1.2, record=True, output_dt=0.01)
    assert a.status == b.status and a.n_impacts == b.n_impacts
    if a.collapsed:
        assert a.t_collapse_s == pytest.approx(b.t_collapse_s, abs=1e-6)
        assert a.collapse_interface == b.collapse_interface
    k = min(len(a.history.t), len(b.history.t)) - 1
    scale = np.abs(a.history.rotations[:k]).max()
    np.testing.assert_allclose(a.history.rotations[:k], -b.history.rotations[:k], atol=1e-5 * scale)


def test_restitution_removes_energy_and_block_comes_to_rest():
    """e < 1 on a rigid block: after a half-sine pulse the rocking decays, the
    impacts end (rest detection) and the run does not take millions of steps."""
    cfg = block(kind="half-sine", restitution=0.85)
    res = simulate(cfg, 0.4, 1.0, record=True, output_dt=0.01)  # no early stop
    assert res.status == "survived"
    assert res.n_impacts > 10
    assert res.n_steps < 20_000
    h = res.history
    assert h.t[-1] == pytest.approx(20.0, abs=0.011)
    late = h.t > 15.0
    assert np.all(h.rotations[late] == 0.0)  # at rest, exactly
    model = model_from_config(cfg)
    energy = model.energy(h.rotations, h.rates)
    after = h.t > 0.5  # pulse over
    assert np.all(np.diff(energy[after]) <= 1e-9 * energy[after][0])


def test_housner_restitution_value():
    """restitution: housner gives 1 - 1.5 sin^2(alpha) for a rectangle."""
    cfg = block(restitution="housner")
    model = model_from_config(cfg)
    sin2 = 1.0 / (1.0 + 16.0)  # tan(alpha) = 1/4
    assert model.restitution == pytest.approx(1 - 1.5 * sin2, rel=1e-12)
